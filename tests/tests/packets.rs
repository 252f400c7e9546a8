//! Sixteen paths at a time (`cpu::packet_paths`) against one path at a time over the BVH: the
//! same kernel state machine and bit-identical intersections, so the same images, bit for bit,
//! with every kernel variant, several lights, a background, and adaptive sampling. (Two
//! primitives hit at exactly the same t may be reported differently by the two tracers, e.g.
//! along a quad's diagonal; none is in these renders, and one would show up here as a
//! difference of a pixel or two.)

use twinpath::cpu::CpuRenderer;
use twinpath::render::Backend;
use twinpath::scene::Scene;
use twinpath_tests::{assert_films_identical, render_film, repo_root};

fn small(name: &str) -> Scene {
    let mut s = Scene::load(&repo_root().join("scenes").join(name)).unwrap();
    s.camera.width = 48;
    s.camera.height = 48;
    s
}

fn scenes() -> Vec<(&'static str, Scene)> {
    let mut half = small("cornell.toml");
    half.render.mis_mode = kernel::scene::mis::HALF;
    half.render.light_sampling = kernel::scene::light_sampling::AREA;
    let mut throughput = small("cornell.toml");
    throughput.render.rr_mode = kernel::scene::roulette::THROUGHPUT;
    throughput.render.rr_start_depth = 3;
    let mut generic = small("cornell.toml");
    generic.render.specialize = false;
    let mut independent = small("cornell.toml");
    independent.render.sampler = kernel::scene::sampler::INDEPENDENT;
    let mut adaptive = small("cornell.toml");
    adaptive.render.adaptive_target = 0.05;
    let mut sky = small("many_lights.toml");
    sky.background = glam::Vec3::new(0.2, 0.3, 0.5);
    vec![
        ("cornell", small("cornell.toml")),
        ("cornell, throughput roulette", throughput),
        ("cornell, half weights + area sampling", half),
        ("cornell, generic path", generic),
        ("cornell, independent sampler", independent),
        ("cornell, adaptive 0.05", adaptive),
        ("many_lights", small("many_lights.toml")),
        ("many_lights with a background", sky),
    ]
}

#[test]
fn packets_of_paths_give_the_one_path_images() {
    for (name, scene) in scenes() {
        assert!(
            CpuRenderer::new(&scene).small.is_some(),
            "{name}: small enough for packets, yet the renderer would not use them"
        );
        let mut one_path = scene.clone();
        one_path.render.packets = false;
        assert!(CpuRenderer::new(&one_path).small.is_none());
        let spp = if scene.render.adaptive_target > 0.0 {
            32
        } else {
            8
        };
        let a = render_film(&scene, Backend::Cpu, spp);
        let b = render_film(&one_path, Backend::Cpu, spp);
        assert_films_identical(&a, &b, name);
        println!("{name}: packets and one path identical at {spp} spp");
    }
}

#[test]
fn large_scenes_keep_the_bvh() {
    let scene = small("sky_meshes.toml");
    assert!(
        scene.spheres.len() + scene.triangles.len() > twinpath::cpu::packet::MAX_PRIMITIVES,
        "the test needs a scene above the packet limit"
    );
    assert!(CpuRenderer::new(&scene).small.is_none());
}

/// The numbers the packets compute for sixteen paths at once (`cpu::packet_numbers`, the
/// kernel's sampler on SIMD lanes) are exactly `SampleRng`'s, for both samplers mixed in one
/// packet, at the camera and at vertices of any depth; and they really are computed ahead
/// (a stream that fell back to `SampleRng` for everything would pass the first check alone).
#[test]
fn numbers_computed_for_sixteen_paths_are_sample_rng_numbers() {
    use kernel::path::{
        PathState, BRDF_DIMENSION, CAMERA_DIMENSIONS, DIMENSIONS_PER_VERTEX,
        LIGHT_CHOICE_DIMENSION, LIGHT_POINT_DIMENSION, ROULETTE_DIMENSION,
    };
    use kernel::rng::{pcg4d, SampleRng, SampleStream};
    use kernel::scene::sampler;
    use twinpath::cpu::packet::LANES;
    use twinpath::cpu::packet_numbers::{camera_streams, prefetch_vertices, PrefetchedStream};

    for round in 0..64u32 {
        let h = |lane: usize, k: u32| pcg4d([round, lane as u32, k, 0x7e57])[0];
        let rng = |lane: usize| {
            // Lane 3 has no path; the others mix the samplers (round 0: all Sobol).
            let kind = if round == 0 || h(lane, 0) % 3 != 0 {
                sampler::SOBOL
            } else {
                sampler::INDEPENDENT
            };
            (lane != 3)
                .then(|| SampleRng::with_sampler(h(lane, 1), h(lane, 2), h(lane, 3) % 4096, kind))
        };
        let rngs: [Option<SampleRng>; LANES] = std::array::from_fn(rng);
        let streams = camera_streams(&rngs);
        for (lane, (stream, rng)) in streams.iter().zip(&rngs).enumerate() {
            assert_eq!(stream.is_some(), rng.is_some(), "lane {lane}");
            let (Some(mut stream), Some(mut rng)) = (*stream, *rng) else {
                continue;
            };
            assert!(stream.holds(0, true), "camera pair not computed ahead");
            assert_eq!(
                stream.next_2d(),
                SampleStream::next_2d(&mut rng),
                "camera, lane {lane}"
            );
        }

        let choose_light = round % 2 == 1;
        let mut slots: [Option<((), PathState<PrefetchedStream>)>; LANES] =
            std::array::from_fn(|lane| {
                rngs[lane].map(|rng| {
                    let mut path =
                        PathState::new(glam::Vec3::ZERO, glam::Vec3::Z, PrefetchedStream::new(rng));
                    path.depth = h(lane, 4) % 40;
                    // Lane 5 waits for no extension ray: nothing is computed for it.
                    path.extend = lane != 5;
                    ((), path)
                })
            });
        prefetch_vertices(&mut slots, choose_light);
        for (lane, slot) in slots.iter_mut().enumerate() {
            let Some((_, path)) = slot else { continue };
            let block = CAMERA_DIMENSIONS + path.depth * DIMENSIONS_PER_VERTEX;
            let reads = [
                (LIGHT_CHOICE_DIMENSION, false, choose_light),
                (LIGHT_POINT_DIMENSION, true, true),
                (ROULETTE_DIMENSION, false, true),
                (BRDF_DIMENSION, true, true),
            ];
            for (offset, pair, computed) in reads {
                let d = block + offset;
                assert_eq!(
                    path.rng.holds(d, pair),
                    computed && lane != 5,
                    "lane {lane}, dimension {d}: computed ahead?"
                );
                let mut expected = rngs[lane].unwrap();
                expected.seek(d);
                path.rng.seek(d);
                if pair {
                    assert_eq!(
                        path.rng.next_2d(),
                        expected.next_2d(),
                        "lane {lane}, pair {d}"
                    );
                } else {
                    assert_eq!(
                        path.rng.next_f32(),
                        expected.next_f32(),
                        "lane {lane}, single {d}"
                    );
                }
                assert_eq!(path.rng.rng.dimension, expected.dimension);
            }
        }
    }
}
