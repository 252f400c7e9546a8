//! Sixteen paths at a time (`cpu::packet_paths`) against one path at a time over the BVH: the
//! same kernel state machine and bit-identical intersections, so the same images, bit for bit,
//! with every kernel variant, several lights, a background, and adaptive sampling, for small
//! scenes (rays against every primitive) and larger ones and scenes with instances (rays
//! through the BVH as packets, two-level with instances). Of primitives hit at exactly the same
//! t every tracer reports the least (instance, id) (`tests/tests/bvh.rs`), so the traversal
//! order cannot change an image.

use twinpath::cpu::{CpuRenderer, TileStrategy};
use twinpath::scene::SceneFile;
use twinpath::settings::{LightSampling, Mis, Roulette, Sampler};
use twinpath_tests::repo_root;

fn small(name: &str) -> SceneFile {
    let mut s = SceneFile::load(&repo_root().join("scenes").join(name)).unwrap();
    s.scene.camera.width = 48;
    s.scene.camera.height = 48;
    s
}

fn scenes() -> Vec<(&'static str, SceneFile)> {
    let mut half = small("cornell.toml");
    half.settings.mis = Mis::Half;
    half.settings.light_sampling = LightSampling::Area;
    let mut constant = small("cornell.toml");
    constant.settings.roulette = Roulette::Constant;
    let mut throughput = small("cornell.toml");
    throughput.settings.rr_start_depth = Some(3);
    let mut generic = small("cornell.toml");
    generic.settings.specialize = false;
    let mut independent = small("cornell.toml");
    independent.settings.sampler = Sampler::Independent;
    let mut adaptive = small("cornell.toml");
    adaptive.settings.adaptive_target = 0.05;
    let mut lens = small("cornell.toml");
    lens.scene.camera.aperture = 0.2;
    lens.scene.camera.focus_distance = 3.5;
    let mut sky = small("many_lights.toml");
    sky.scene.background = glam::Vec3::new(0.2, 0.3, 0.5);
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
        ("materials (every material kind)", small("materials.toml")),
        (
            "cornell with gold and glass",
            small("cornell_materials.toml"),
        ),
        (
            "cornell lit by a panel (triangle lights)",
            small("cornell_panel.toml"),
        ),
        ("textures and a smooth mesh", small_textured()),
    ]
}

/// A scene small enough for packets with every texture slot and a smooth mesh: a checkered
/// floor, a wall of textured roughness, a panel of textured emission, an octahedron with vertex
/// normals (written to a temporary file).
fn small_textured() -> SceneFile {
    let dir = std::env::temp_dir().join(format!("twinpath-packets-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("octahedron.obj");
    let mut text = String::new();
    for v in ["1 0 0", "-1 0 0", "0 1 0", "0 -1 0", "0 0 1", "0 0 -1"] {
        text += &format!("v {v}\nvn {v}\n");
    }
    for f in [
        [1, 3, 5],
        [3, 2, 5],
        [2, 4, 5],
        [4, 1, 5],
        [3, 1, 6],
        [2, 3, 6],
        [4, 2, 6],
        [1, 4, 6],
    ] {
        text += &format!("f {0}//{0} {1}//{1} {2}//{2}\n", f[0], f[1], f[2]);
    }
    std::fs::write(&obj, text).unwrap();
    let mut s = twinpath_tests::scene_from_toml(&format!(
        r#"
        [camera]
        eye = [0.0, 1.2, 3.0]
        look_at = [0.0, 0.4, 0.0]
        up = [0.0, 1.0, 0.0]
        vfov = 45.0
        width = 48
        height = 48
        [materials]
        floor = {{ kd_map = "textures/checker.png" }}
        wall = {{ kd = [0.3, 0.3, 0.3], ks = [0.5, 0.5, 0.5], alpha_map = "textures/roughness.png" }}
        panel = {{ emission = [4.0, 4.0, 4.0], emission_map = "textures/emission.png" }}
        ball = {{ kd = [0.6, 0.5, 0.4], ks = [0.3, 0.3, 0.3], alpha = 0.2 }}
        [[quad]]
        corner = [-2.0, 0.0, 2.0]
        edge1 = [4.0, 0.0, 0.0]
        edge2 = [0.0, 0.0, -4.0]
        material = "floor"
        [[quad]]
        corner = [-2.0, 0.0, -1.0]
        edge1 = [4.0, 0.0, 0.0]
        edge2 = [0.0, 2.0, 0.0]
        material = "wall"
        [[quad]]
        corner = [-0.6, 1.8, -0.3]
        edge1 = [1.2, 0.0, 0.0]
        edge2 = [0.0, 0.0, 0.6]
        material = "panel"
        [[mesh]]
        file = "{}"
        scale = 0.4
        translate = [0.0, 0.4, 0.0]
        material = "ball"
        "#,
        obj.display()
    ));
    s.scene.background = glam::Vec3::splat(0.1);
    s
}

#[test]
fn packets_of_paths_give_the_one_path_images() {
    for (name, scene) in scenes() {
        assert!(
            matches!(
                CpuRenderer::new(&scene.scene, &scene.settings).tiles,
                TileStrategy::Packets(_)
            ),
            "{name}: small enough for packets, yet the renderer would not use them"
        );
        assert_packets_give_the_one_path_image(name, &scene);
    }
}

/// [`twinpath_tests::assert_packets_give_the_one_path_image`] at [`packet_test_spp`].
fn assert_packets_give_the_one_path_image(name: &str, scene: &SceneFile) {
    twinpath_tests::assert_packets_give_the_one_path_image(name, scene, packet_test_spp(scene));
}

/// The samples per pixel of these comparisons: 32 under adaptive sampling, else 8.
fn packet_test_spp(scene: &SceneFile) -> u32 {
    if scene.settings.adaptive_target > 0.0 {
        32
    } else {
        8
    }
}

/// The Cornell room with a generated torus knot of about 12k triangles in place of the left
/// sphere (`bench::rays::knot_mesh`, written to a temporary OBJ file), 48x48.
fn knot_room(lights: &str) -> SceneFile {
    let dir = std::env::temp_dir().join(format!("twinpath-bvh-packets-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("knot.obj");
    let knot = twinpath::bench::rays::knot_mesh(12_000, glam::Vec3::ZERO, 1.0);
    let mut text = String::new();
    for tri in &knot {
        for p in tri {
            text += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
    }
    for k in 0..knot.len() {
        text += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    std::fs::write(&obj, text).unwrap();
    let cornell = std::fs::read_to_string(repo_root().join("scenes/cornell.toml")).unwrap();
    let room = cornell.replace(
        "center = [-0.45, 0.4, -0.3]",
        "center = [-0.45, 0.4, -30.0]",
    );
    let mut s = twinpath_tests::scene_from_toml(&format!(
        "{room}\n[[mesh]]\nfile = \"{}\"\ntranslate = [-0.3, 0.6, -0.2]\nmaterial = \"white\"\n{lights}",
        obj.display()
    ));
    s.scene.camera.width = 48;
    s.scene.camera.height = 48;
    s
}

/// Scenes above the packet limit without instances trace their packets through the BVH
/// (`cpu::bvh_packet`); the images are the one-path loop's, bit for bit: the knot room (12k
/// triangles) with both samplers, adaptive sampling and three more lights, and the shipped mesh,
/// texture, environment-map and glTF scenes.
#[test]
fn packets_through_the_bvh_give_the_one_path_images() {
    let mut independent = knot_room("");
    independent.settings.sampler = Sampler::Independent;
    let mut adaptive = knot_room("");
    adaptive.settings.adaptive_target = 0.05;
    let lamps = r#"
        [[sphere]]
        center = [0.6, 1.5, -0.5]
        radius = 0.1
        material = "light"
        [[sphere]]
        center = [-0.6, 0.2, 0.6]
        radius = 0.05
        material = "light"
        [[quad]]
        corner = [-0.9, 1.99, 0.5]
        edge1 = [0.0, 0.0, 0.3]
        edge2 = [0.3, 0.0, 0.0]
        material = "light"
    "#;
    let scenes = vec![
        ("knot room", knot_room("")),
        ("knot room, independent sampler", independent),
        ("knot room, adaptive 0.05", adaptive),
        ("knot room with four lights", knot_room(lamps)),
        ("meshes", small("meshes.toml")),
        ("textures", small("textures.toml")),
        ("sky_meshes (environment map)", small("sky_meshes.toml")),
        ("showcase", small("showcase.toml")),
        (
            "gltf_showcase (normal map, spot light: the Dynamic path)",
            small("gltf_showcase.toml"),
        ),
        (
            "instances (two meshes placed 15 times, two triangles of its own: the two-level \
             packets, not the small scene's)",
            small("instances.toml"),
        ),
        (
            "instances in a fog (shadow segments' blockers found through instances)",
            instances_in_fog(),
        ),
    ];
    for (name, scene) in scenes {
        twinpath_tests::assert_bvh_packets_give_the_one_path_image(
            name,
            &scene,
            packet_test_spp(&scene),
            "a larger scene or one with instances",
        );
    }
}

/// `scenes/instances.toml` inside a scattering fog (`scenes/cornell_fog.toml`'s), 48 x 48: its
/// shadow segments ask for the surface that blocks them, on instances too.
fn instances_in_fog() -> SceneFile {
    let scenes = repo_root().join("scenes");
    let text = std::fs::read_to_string(scenes.join("instances.toml")).unwrap();
    let text = text
        .replace(
            "[materials]",
            "[media]\nfog = { sigma_a = [0.03, 0.04, 0.06], sigma_s = [0.25, 0.3, 0.4], g = 0.5 }\n\
             [scene]\nmedium = \"fog\"\n[materials]",
        )
        .replace("file = \"", &format!("file = \"{}/", scenes.display()))
        .replace("map = \"", &format!("map = \"{}/", scenes.display()));
    let dir = std::env::temp_dir().join(format!("twinpath-instances-fog-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("instances_fog.toml");
    std::fs::write(&path, text).unwrap();
    let mut s = SceneFile::load(&path).unwrap();
    assert!(!s.scene.instances.is_empty() && s.scene.medium != kernel::scene::NONE);
    s.scene.camera.width = 48;
    s.scene.camera.height = 48;
    s
}

/// The numbers the packets compute for sixteen streams at once (`cpu::packet_numbers`, the
/// kernel's sampler on SIMD lanes) are exactly `SampleRng`'s, for both samplers mixed in one
/// packet, at the camera and at any dimensions, pairs and single numbers, with lanes that ask
/// for nothing in between.
#[test]
fn numbers_computed_for_sixteen_streams_are_sample_rng_numbers() {
    use kernel::rng::{pcg4d, SampleRng};
    use kernel::scene::sampler;
    use twinpath::cpu::internals::{camera_numbers, NumberRequests, EMPTY};
    use twinpath::cpu::LANES;

    for round in 0..64u32 {
        let h = |lane: usize, k: u32| pcg4d([round, lane as u32, k, 0x7e57])[0];
        let rng = |lane: usize| {
            // Lane 3 has no stream; the others mix the samplers (round 0: all Sobol).
            let kind = if round == 0 || h(lane, 0) % 3 != 0 {
                sampler::SOBOL
            } else {
                sampler::INDEPENDENT
            };
            (lane != 3)
                .then(|| SampleRng::with_sampler(h(lane, 1), h(lane, 2), h(lane, 3) % 4096, kind))
        };
        let rngs: [Option<SampleRng>; LANES] = std::array::from_fn(rng);
        let camera = camera_numbers(&rngs);
        let mut requests = NumberRequests::default();
        let mut asked = [([EMPTY; 2], [EMPTY; 2]); LANES];
        for (lane, r) in rngs.iter().enumerate() {
            let Some(r) = r else { continue };
            let mut expected = *r;
            assert_eq!(camera[lane], expected.next_2d(), "camera, lane {lane}");
            // Lane 5 asks for nothing; the others for dimensions up to a depth of 40 vertices,
            // some of them EMPTY.
            let dim = |k: u32| match h(lane, k) % 5 {
                0 => EMPTY,
                _ => h(lane, k + 10) % 242,
            };
            if lane != 5 {
                asked[lane] = ([dim(4), dim(5)], [dim(6), dim(7)]);
            }
            requests.set(lane, r, asked[lane].0, asked[lane].1);
        }
        let numbers = requests.compute();
        for (lane, r) in rngs.iter().enumerate() {
            let Some(r) = r else { continue };
            let (pairs, singles) = asked[lane];
            for p in 0..2 {
                if pairs[p] != EMPTY {
                    let mut expected = *r;
                    expected.seek(pairs[p]);
                    let got = (numbers.pairs[p][0][lane], numbers.pairs[p][1][lane]);
                    assert_eq!(
                        got,
                        expected.next_2d(),
                        "round {round} lane {lane} pair {p}"
                    );
                }
                if singles[p] != EMPTY {
                    let mut expected = *r;
                    expected.seek(singles[p]);
                    let got = numbers.singles[p][lane];
                    assert_eq!(
                        got,
                        expected.next_f32(),
                        "round {round} lane {lane} single {p}"
                    );
                }
            }
        }
    }
}

/// The samples the packets fill for sixteen vertices at once from their queries
/// (`cpu::packet_vertices`: numbers, cone light samples and BRDF directions on SIMD lanes; other
/// light samples left to the vertex) are, bit for bit, what one vertex at a time uses
/// (`VertexSamples::draw`, then the scalar samplers), for every sample the query asks for. Lanes mix: no light
/// sample, one light and several (many_lights' alias table), triangle lights (cornell_panel's,
/// which the packets leave to the vertex), cone and area sampling, receivers
/// inside a light, vertices that may not extend, roulette with survival below 1, at 1 and
/// NaN, an empty lane; both samplers.
#[test]
fn vertex_samples_filled_for_sixteen_vertices_are_the_kernel_samples() {
    use glam::Vec3;
    use kernel::light::LightKinds;
    use kernel::rng::{pcg4d, u32_to_unit_f32, SampleRng};
    use kernel::scene::{light_sampling, sampler};
    use kernel::vertex_samples::{VertexQuery, VertexSamples, NO_DIMENSION};
    use twinpath::cpu::internals::fill_vertex_samples;
    use twinpath::cpu::LANES;

    let many = small("many_lights.toml").scene.lights;
    let one = small("cornell.toml").scene.lights;
    let panel = small("cornell_panel.toml").scene.lights;
    // No environment map in these light tables: its parameters stay unread.
    let params = small("cornell.toml").params(0, 1);
    assert!(many.len() > 1 && one.len() == 1 && panel.len() == 2);
    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
    let mut checked = [0usize; 5];
    // Of those, the light samples and BRDF directions computed on lanes.
    let mut given = [0usize; 2];
    let mut lambertian_extensions = 0;
    // Light samples of sphere lights (the lanes compute those from outside a sphere).
    let mut sphere_samples = 0;
    for round in 0..256u32 {
        let h = |lane: usize, k: u32| pcg4d([round, lane as u32, k, 0x7e58])[0];
        let unit = |lane: usize, k: u32| u32_to_unit_f32(h(lane, k));
        let lights = [&one, &many, &panel][round as usize % 3];
        let queries: [Option<(SampleRng, VertexQuery)>; LANES] = std::array::from_fn(|lane| {
            if lane == 3 {
                return None;
            }
            let kind = if h(lane, 0) % 3 == 0 {
                sampler::INDEPENDENT
            } else {
                sampler::SOBOL
            };
            let mut rng = SampleRng::with_sampler(h(lane, 1), h(lane, 2), h(lane, 3) % 4096, kind);
            // Half the lanes continue a split path (`kernel::split`): their dimensions from
            // the first vertex's roulette on are another sample index's.
            if h(lane, 23) % 2 == 0 {
                rng.continuation = h(lane, 24) % 16384;
            }
            let l = &lights[(h(lane, 8) % lights.len() as u32) as usize];
            let c = Vec3::from(l.position);
            let x = if h(lane, 7) % 6 == 0 {
                // Inside a light: no cone from there.
                c + 0.5 * l.radius * Vec3::new(unit(lane, 9), -unit(lane, 10), 0.1)
            } else {
                Vec3::new(
                    2.0 * unit(lane, 9) - 1.0,
                    2.0 * unit(lane, 10),
                    unit(lane, 11) - 1.0,
                )
            };
            let n = Vec3::new(
                unit(lane, 12) - 0.5,
                unit(lane, 13) - 0.5,
                unit(lane, 14) - 0.5,
            )
            .try_normalize()
            .unwrap_or(Vec3::Y);
            let light_count = match h(lane, 15) % 4 {
                0 => 0,
                _ => lights.len() as u32,
            };
            let survival = match h(lane, 16) % 4 {
                0 => 1.0,
                1 => f32::NAN,
                _ => unit(lane, 17),
            };
            let lambertian = h(lane, 21) % 2 != 0;
            let query = VertexQuery {
                depth: 1 + h(lane, 6) % 40,
                x,
                n,
                ng: n,
                smooth: false,
                light_count,
                mode: if h(lane, 18) % 4 == 0 {
                    light_sampling::AREA
                } else {
                    light_sampling::SOLID_ANGLE
                },
                // A table with triangles needs the bit; a table of spheres runs either way.
                light_kinds: LightKinds {
                    triangles: round % 3 == 2 || h(lane, 23) % 2 == 0,
                    environment: false,
                    delta: false,
                },
                extend: h(lane, 19) % 5 != 0,
                roulette: h(lane, 20) % 3 != 0,
                survival,
                lambertian,
                chooses_lobe: !lambertian && h(lane, 22) % 4 != 0,
            };
            Some((rng, query))
        });
        let filled = fill_vertex_samples(&queries, lights);
        let scene = kernel::SceneView {
            params: &params,
            materials: &[],
            lights,
            environment: &[0.0],
            shading: &[],
            textures: &[],
            instances: &[],
            media: &[kernel::medium::Medium::VACUUM],
            grids: &[0],
            splits: &[1],
        };
        for (lane, entry) in queries.iter().enumerate() {
            let Some((rng, q)) = entry else { continue };
            let want = VertexSamples::draw(q, &mut { *rng });
            let got = filled[lane];
            let pair_bits = |(a, b): (f32, f32)| (a.to_bits(), b.to_bits());
            if q.chooses_light() {
                assert_eq!(got.u_select.to_bits(), want.u_select.to_bits());
            }
            if q.samples_light() {
                assert_eq!(pair_bits(got.u_light), pair_bits(want.u_light));
                // What the vertex uses: the sample given, or the one it computes itself.
                let (g, w) = (got.light_sample(q, &scene), want.light_sample(q, &scene));
                assert_eq!(
                    (
                        bits(g.point.position),
                        bits(g.point.normal),
                        g.light,
                        g.pdf_solid_angle.to_bits()
                    ),
                    (
                        bits(w.point.position),
                        bits(w.point.normal),
                        w.light,
                        w.pdf_solid_angle.to_bits()
                    ),
                    "round {round} lane {lane}: light sample"
                );
                checked[0] += 1;
                given[0] += got.has_light as usize;
                if lights[w.light as usize].kind == kernel::scene::light_kind::SPHERE {
                    sphere_samples += 1;
                }
            }
            if q.draws_roulette() {
                assert_eq!(got.u_roulette.to_bits(), want.u_roulette.to_bits());
                checked[1] += 1;
            }
            if q.extend && q.survives(want.u_roulette) {
                assert_eq!(pair_bits(got.u_brdf), pair_bits(want.u_brdf));
                assert_eq!(
                    bits(got.brdf_direction(q)),
                    bits(want.brdf_direction(q)),
                    "round {round} lane {lane}: BRDF direction"
                );
                checked[2] += 1;
                given[1] += got.has_brdf_dir as usize;
                lambertian_extensions += q.lambertian as usize;
                if q.lobe_dimension() != NO_DIMENSION {
                    assert_eq!(got.u_lobe.to_bits(), want.u_lobe.to_bits());
                    checked[4] += 1;
                }
            }
            checked[3] += 1;
        }
    }
    println!(
        "checked {checked:?} (light samples, roulette numbers, BSDF pairs, vertices, lobe \
         choices); computed on lanes {given:?} (light samples, Lambertian directions)"
    );
    // Every kind of sample was compared many times, and the lanes really computed most: every
    // Lambertian direction (other materials sample their own).
    assert!(
        checked[..3].iter().chain(&checked[4..]).all(|&c| c > 500),
        "{checked:?}"
    );
    assert!(
        given[0] > sphere_samples / 2 && given[1] == lambertian_extensions,
        "{given:?}"
    );
}
