//! The CPU backend's ray counts (`backend::RayCounts`, printed by `twinpath render`), against
//! closed forms and across the CPU's tile strategies.
//!
//! 1. Inside a closed diffuse sphere with constant roulette q from the first vertex, every ray
//!    hits, so a path's closest-hit rays are 1 + a geometric number of extensions: mean
//!    1 / (1 - q), variance q / (1 - q)^2. Without lights no shadow ray is traced; with a point
//!    light at the centre (visible from every point of the inside, never behind it) exactly one
//!    per vertex, i.e. as many as closest-hit rays.
//! 2. Sixteen paths at a time (either packet tracer) trace exactly the rays of the one-path loop,
//!    path by path the same, so their counts are equal.

use twinpath::backend::RayCounts;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::{render_output, scene_from_toml, with_independent_samples, z_critical};

const Q: f64 = 0.5;
const SPP: u32 = 64;
const SIDE: u32 = 32;

/// The camera at the centre of a closed sphere of albedo 0.5, constant roulette `Q` from the
/// first vertex, and `light` (TOML) inside it.
fn closed_sphere(light: &str) -> SceneFile {
    with_independent_samples(scene_from_toml(&format!(
        "[camera]\neye = [0, 0, 0]\nlook_at = [0, 0, -1]\nup = [0, 1, 0]\nvfov = 60\nwidth = {SIDE}\nheight = {SIDE}\n\
         [render]\nroulette = \"constant\"\nrussian_roulette = {Q}\nrr_start_depth = 1\n\
         [materials]\nwall = {{ kd = [0.5, 0.5, 0.5] }}\n\
         [[sphere]]\ncenter = [0, 0, 0]\nradius = 10\nmaterial = \"wall\"\n{light}"
    )))
}

/// Renders `scene` at `spp` on the CPU; its ray counts and sample count.
fn rays_of(scene: &SceneFile, spp: u32) -> (RayCounts, u64) {
    let out = render_output(scene, Backend::Cpu, spp);
    let rays = out.rays.expect("the CPU backend counts rays");
    (rays, out.film.total_samples())
}

/// z of the mean closest-hit count per sample against 1 / (1 - q).
fn geometric_z(rays: &RayCounts, samples: u64) -> f64 {
    let mean = rays.closest as f64 / samples as f64;
    let variance_of_mean = Q / (1.0 - Q).powi(2) / samples as f64;
    (mean - 1.0 / (1.0 - Q)) / variance_of_mean.sqrt()
}

#[test]
fn closed_sphere_traces_a_geometric_number_of_rays() {
    let (rays, samples) = rays_of(&closed_sphere(""), SPP);
    assert_eq!(samples, (SIDE * SIDE * SPP) as u64);
    let z = geometric_z(&rays, samples);
    println!(
        "no light: {:.4} closest-hit rays per sample (want {}), z = {z:+.2}; {} shadow",
        rays.closest as f64 / samples as f64,
        1.0 / (1.0 - Q),
        rays.shadow
    );
    assert!(z.abs() < z_critical(1e-3, 2), "|z| = {:.2}", z.abs());
    assert_eq!(rays.shadow, 0, "no light, yet shadow rays were traced");
}

#[test]
fn a_point_light_in_the_closed_sphere_takes_one_shadow_ray_per_vertex() {
    let light = "[[light]]\nposition = [0, 0, 0]\nintensity = [1, 1, 1]\n";
    let (rays, samples) = rays_of(&closed_sphere(light), SPP);
    let z = geometric_z(&rays, samples);
    println!(
        "point light: {:.4} closest-hit and {:.4} shadow rays per sample, z = {z:+.2}",
        rays.closest as f64 / samples as f64,
        rays.shadow as f64 / samples as f64
    );
    assert!(z.abs() < z_critical(1e-3, 2), "|z| = {:.2}", z.abs());
    assert_eq!(rays.shadow, rays.closest);
}

#[test]
fn packets_trace_the_rays_of_the_one_path_loop() {
    // meshes.toml: BVH packets; cornell.toml: the small scene's packets.
    for name in ["meshes.toml", "cornell.toml"] {
        let path = twinpath_tests::repo_root().join("scenes").join(name);
        let mut scene = SceneFile::load(&path).expect("scene");
        scene.scene.camera.width = 48;
        scene.scene.camera.height = 48;
        let mut one_path = scene.clone();
        one_path.settings.packets = false;
        let (packets, n) = rays_of(&scene, 4);
        let (paths, m) = rays_of(&one_path, 4);
        println!("{name}: {packets:?} in packets, {paths:?} one path at a time ({n} samples)");
        assert_eq!(n, m);
        assert!(packets.closest >= n && packets.shadow > 0);
        assert_eq!(packets, paths, "{name}");
    }
}
