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
