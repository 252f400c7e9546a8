//! Sixteen paths at a time (`cpu::packet_paths`) against one path at a time over the BVH: the
//! same kernel state machine and bit-identical intersections, so the same images, bit for bit,
//! with every kernel variant, several lights, a background, and adaptive sampling. (Two
//! primitives hit at exactly the same t may be reported differently by the two tracers, e.g.
//! along a quad's diagonal; none is in these renders, and one would show up here as a
//! difference of a pixel or two.)

use twinpath::cpu::{CpuRenderer, TileStrategy};
use twinpath::render::Backend;
use twinpath::scene::Scene;
use twinpath::settings::{LightSampling, Mis, Roulette, Sampler};
use twinpath_tests::{assert_films_identical, render_film, repo_root};

fn small(name: &str) -> Scene {
    let mut s = Scene::load(&repo_root().join("scenes").join(name)).unwrap();
    s.camera.width = 48;
    s.camera.height = 48;
    s
}

fn scenes() -> Vec<(&'static str, Scene)> {
    let mut half = small("cornell.toml");
    half.render.mis = Mis::Half;
    half.render.light_sampling = LightSampling::Area;
    let mut constant = small("cornell.toml");
    constant.render.roulette = Roulette::Constant;
    let mut throughput = small("cornell.toml");
    throughput.render.rr_start_depth = Some(3);
    let mut generic = small("cornell.toml");
    generic.render.specialize = false;
    let mut independent = small("cornell.toml");
    independent.render.sampler = Sampler::Independent;
    let mut adaptive = small("cornell.toml");
    adaptive.render.adaptive_target = 0.05;
    let mut sky = small("many_lights.toml");
    sky.background = glam::Vec3::new(0.2, 0.3, 0.5);
    vec![
        ("cornell", small("cornell.toml")),
        ("cornell, constant roulette", constant),
        ("cornell, throughput roulette from depth 3", throughput),
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
            matches!(CpuRenderer::new(&scene).tiles, TileStrategy::Packets(_)),
            "{name}: small enough for packets, yet the renderer would not use them"
        );
        let mut one_path = scene.clone();
        one_path.render.packets = false;
        assert!(matches!(
            CpuRenderer::new(&one_path).tiles,
            TileStrategy::OnePath
        ));
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
    assert!(matches!(
        CpuRenderer::new(&scene).tiles,
        TileStrategy::OnePath
    ));
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

/// The light samples and BRDF directions the packets compute for sixteen paths at once
/// (`packet_vertices`, on SIMD lanes) are, bit for bit, what the kernel's samplers give the
/// vertex one path at a time (`VertexSampler`'s provided methods on `SampleRng`), and are
/// computed ahead exactly where a vertex will ask for them: at a surface that is not a light,
/// the light sample only under cone sampling from outside the chosen light. Lanes mix misses,
/// light hits, an empty lane, a lane without extension, receivers inside a light, one light
/// and several (many_lights' alias table), cone and area sampling. A vertex that asks with
/// other arguments (a moved receiver) gets them computed anew.
#[test]
fn vertex_samples_computed_for_sixteen_paths_are_the_kernel_samples() {
    use glam::Vec3;
    use kernel::light::uses_cone;
    use kernel::path::{
        PathState, BRDF_DIMENSION, CAMERA_DIMENSIONS, DIMENSIONS_PER_VERTEX,
        LIGHT_CHOICE_DIMENSION, LIGHT_POINT_DIMENSION,
    };
    use kernel::rng::{pcg4d, u32_to_unit_f32, SampleRng, SampleStream};
    use kernel::scene::{light_sampling, sampler, NONE};
    use kernel::vertex_sampler::VertexSampler;
    use kernel::SurfaceHit;
    use twinpath::cpu::packet::LANES;
    use twinpath::cpu::packet_numbers::{prefetch_vertices, PrefetchedStream};
    use twinpath::cpu::packet_vertices::presample_vertices;

    let many = small("many_lights.toml").lights;
    let one = small("cornell.toml").lights;
    assert!(many.len() > 1 && one.len() == 1);
    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
    let mut computed = [0usize; 2];
    for round in 0..256u32 {
        let h = |lane: usize, k: u32| pcg4d([round, lane as u32, k, 0x7e58])[0];
        let unit = |lane: usize, k: u32| u32_to_unit_f32(h(lane, k));
        let lights = if round % 2 == 0 { &one } else { &many };
        let light_count = lights.len() as u32;
        let mode = if round % 8 == 7 {
            light_sampling::AREA
        } else {
            light_sampling::CONE
        };
        let kind = |lane: usize| {
            if h(lane, 0) % 3 == 0 {
                sampler::INDEPENDENT
            } else {
                sampler::SOBOL
            }
        };
        let rngs: [Option<SampleRng>; LANES] = std::array::from_fn(|lane| {
            (lane != 3).then(|| {
                SampleRng::with_sampler(h(lane, 1), h(lane, 2), h(lane, 3) % 4096, kind(lane))
            })
        });
        let mut slots: [Option<((), PathState<PrefetchedStream>)>; LANES] =
            std::array::from_fn(|lane| {
                rngs[lane].map(|rng| {
                    let dir = Vec3::new(unit(lane, 4) - 0.5, unit(lane, 5) - 0.5, -1.0);
                    let mut path =
                        PathState::new(Vec3::ZERO, dir.normalize(), PrefetchedStream::new(rng));
                    path.depth = h(lane, 6) % 12;
                    path.extend = lane != 5;
                    ((), path)
                })
            });
        let hits: [SurfaceHit; LANES] = std::array::from_fn(|lane| {
            let kind = h(lane, 7) % 8;
            if kind == 0 {
                return SurfaceHit::miss();
            }
            let l = &lights[(h(lane, 8) % light_count) as usize];
            let c = Vec3::from(l.center);
            let position = match kind {
                // Inside a light: no cone from there.
                1 => c + 0.5 * l.radius * Vec3::new(unit(lane, 9), -unit(lane, 10), 0.1),
                _ => Vec3::new(
                    2.0 * unit(lane, 9) - 1.0,
                    2.0 * unit(lane, 10),
                    unit(lane, 11) - 1.0,
                ),
            };
            let normal = Vec3::new(
                unit(lane, 12) - 0.5,
                unit(lane, 13) - 0.5,
                unit(lane, 14) - 0.5,
            )
            .try_normalize()
            .unwrap_or(Vec3::Y);
            SurfaceHit {
                position,
                t: 1.0,
                normal,
                material: 0,
                light: if kind == 2 { 0 } else { NONE },
                error: 1e-6,
                arrived_behind: unit(lane, 15) < 0.5,
            }
        });
        prefetch_vertices(&mut slots, light_count > 1);
        presample_vertices(&mut slots, &hits, lights, light_count, mode);
        for (lane, slot) in slots.iter_mut().enumerate() {
            let Some((_, path)) = slot else { continue };
            let hit = hits[lane];
            let block = CAMERA_DIMENSIONS + path.depth * DIMENSIONS_PER_VERTEX;
            let at_surface = path.extend && hit.is_hit() && hit.light == NONE;
            let x = hit.position;
            let mut expected = rngs[lane].unwrap();
            // The vertex's light choice, as the kernel draws it.
            let u_select = if light_count > 1 {
                expected.seek(block + LIGHT_CHOICE_DIMENSION);
                expected.next_f32()
            } else {
                0.0
            };
            let chosen = kernel::light::choose_light(lights, light_count, u_select);
            let cone = mode == light_sampling::CONE && uses_cone(mode, &lights[chosen as usize], x);
            let d = block + LIGHT_POINT_DIMENSION;
            assert_eq!(
                path.rng.holds_light_sample(d),
                at_surface && cone,
                "round {round} lane {lane}: light sample computed ahead?"
            );
            computed[0] += path.rng.holds_light_sample(d) as usize;
            let mut twin = path.rng;
            expected.seek(d);
            path.rng.seek(d);
            let want = expected.sample_light_from(lights, light_count, mode, x, u_select);
            let got = path
                .rng
                .sample_light_from(lights, light_count, mode, x, u_select);
            assert_eq!(
                (
                    bits(got.point.position),
                    bits(got.point.normal),
                    got.light,
                    got.pdf_solid_angle.to_bits()
                ),
                (
                    bits(want.point.position),
                    bits(want.point.normal),
                    want.light,
                    want.pdf_solid_angle.to_bits()
                ),
                "round {round} lane {lane}: light sample"
            );
            assert_eq!(path.rng.rng.dimension, expected.dimension);
            // Asked from elsewhere, the stream computes the sample for the receiver asked about.
            let moved = x + Vec3::splat(0.25);
            let mut again = rngs[lane].unwrap();
            again.seek(d);
            twin.seek(d);
            let want = again.sample_light_from(lights, light_count, mode, moved, u_select);
            let got = twin.sample_light_from(lights, light_count, mode, moved, u_select);
            assert_eq!(
                bits(got.point.position),
                bits(want.point.position),
                "moved receiver"
            );

            let d = block + BRDF_DIMENSION;
            assert_eq!(
                path.rng.holds_brdf_direction(d),
                at_surface,
                "round {round} lane {lane}: BRDF direction computed ahead?"
            );
            computed[1] += path.rng.holds_brdf_direction(d) as usize;
            let n = hit.facing_normal();
            expected.seek(d);
            path.rng.seek(d);
            assert_eq!(
                bits(path.rng.sample_brdf(n)),
                bits(expected.sample_brdf(n)),
                "round {round} lane {lane}: BRDF direction"
            );
            assert_eq!(path.rng.rng.dimension, expected.dimension);
        }
    }
    println!(
        "computed ahead: {} light samples, {} BRDF directions",
        computed[0], computed[1]
    );
    assert!(computed[0] > 500 && computed[1] > 1000, "{computed:?}");
}
