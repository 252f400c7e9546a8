//! Image-level CPU-vs-GPU equivalence and the closed-form scenes on the GPU (lavapipe in CI),
//! with the Vulkan validation layers on: any validation message fails the test.

use glam::Vec3;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_film_matches, image_mean_z, plane_exact, plane_under_lamps, render_film, repo_root,
    scene_from_toml, with_independent_samples, z_critical, Lamp,
};

/// Same scene, seed and spp on both backends: the same samples, so nearly every pixel must be
/// equal to `tolerance` relative; the few others are pixels where one path's ray flips between
/// hit and miss at an edge (the GPU intersects triangles with its own watertight test, the CPU
/// with Moller-Trumbore).
fn assert_backends_agree(path: &str, spp: u32, tolerance: f32) {
    let scene = SceneFile::load(&repo_root().join(path)).unwrap();
    assert_scene_backends_agree(&scene, path, spp, tolerance);
}

/// [`assert_backends_agree`] on a scene already loaded (`path` labels it).
fn assert_scene_backends_agree(scene: &SceneFile, path: &str, spp: u32, tolerance: f32) {
    let scene = scene.clone();
    let cpu = render_film(&scene, Backend::Cpu, spp);
    let gpu = render_film(&scene, Backend::Gpu, spp);
    assert_eq!((cpu.discarded, gpu.discarded), (0, 0));
    assert_eq!(cpu.count, gpu.count);
    let (a, b) = (cpu.mean(), gpu.mean());
    let mut differing = Vec::new();
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        let close = (0..3).all(|c| (x[c] - y[c]).abs() <= tolerance * x[c].abs().max(y[c].abs()));
        if !close {
            differing.push((
                i % scene.scene.camera.width as usize,
                i / scene.scene.camera.width as usize,
                *x,
                *y,
            ));
        }
    }
    let fraction_equal = 1.0 - differing.len() as f64 / a.len() as f64;
    println!(
        "{path}, {spp} spp, same seed: {:.4}% of pixels equal to {tolerance:e} relative; {} differ:",
        100.0 * fraction_equal,
        differing.len()
    );
    for (x, y, c, g) in differing.iter().take(10) {
        println!("  pixel ({x}, {y}): cpu {c:?} gpu {g:?}");
    }
    // The same numbers only on a device of the CPU's arithmetic: elsewhere a ray within the
    // rounding of an edge may hit on one backend and miss on the other and its path diverge,
    // so there the images agree in distribution (below), not pixel for pixel.
    if twinpath_tests::gpu::device_is_ieee() {
        assert!(
            fraction_equal >= 0.999,
            "only {:.4}% equal",
            100.0 * fraction_equal
        );
    } else {
        println!("{path}: a Vulkan-class device: pixel equality reported, not asserted");
    }

    // Independent seeds: the two backends' image means agree within their noise (independent
    // samples, so each image's noise is known from its own samples).
    let independent = with_independent_samples(scene.clone());
    let mut other = independent.clone();
    other.settings.seed = scene.settings.seed.wrapping_add(1000);
    let cpu = render_film(&independent, Backend::Cpu, spp);
    let gpu2 = render_film(&other, Backend::Gpu, spp);
    let z = image_mean_z(&cpu, &gpu2);
    println!(
        "{path}: cpu (seed {}) vs gpu (seed {}) image means: z = {z:+.2}",
        scene.settings.seed, other.settings.seed
    );
    assert!(
        z.abs() < z_critical(1e-3, 1),
        "image means differ: z = {z:.2}"
    );
    assert_validation_clean();
}

#[test]
fn cornell_same_image_on_cpu_and_gpu() {
    assert_backends_agree("scenes/cornell.toml", 16, 1e-4);
}

/// Every material kind: the BSDFs' samplers and pdfs differ between the backends by the ULPs
/// `gpu_functions.rs` bounds (contracted multiply-adds), which MIS weights and glossy weights
/// carry into the pixels: 0.22% of the pixels differ by 1e-4 to 3e-4 relative (measured on
/// lavapipe), so pixels are compared to 1e-3.
#[test]
fn materials_same_image_on_cpu_and_gpu() {
    assert_backends_agree("scenes/materials.toml", 16, 1e-3);
}

/// Triangle lights (a ceiling panel, sampled as spherical triangles): their solid angles and
/// samples differ between the backends by the bounds of `gpu_functions.rs`, so pixels are
/// compared to 1e-3, as for materials.
#[test]
fn panel_light_same_image_on_cpu_and_gpu() {
    assert_backends_agree("scenes/cornell_panel.toml", 16, 1e-3);
}

/// An environment map (scenes/sky.hdr) seen directly and on gold, and sampled by luminance: the
/// lookup and the sampler agree between the backends (to 1e-3 as for materials). (With a glass
/// sphere under its sun, the caustics were too heavy-tailed for the image-mean z-test's summed
/// pixel variances: z = -4.95 on a pair whose same-seed images agreed.)
#[test]
fn environment_map_same_image_on_cpu_and_gpu() {
    assert_backends_agree("scenes/sky.toml", 16, 1e-3);
}

#[test]
fn mesh_scene_same_image_on_cpu_and_gpu() {
    assert_backends_agree("scenes/meshes.toml", 16, 1e-4);
}

/// Textures (kd, alpha and emission maps, repeated and clamped) and shading normals (an OBJ
/// sphere, a PLY torus) at half the scene's resolution: the lookup is bit-exact between the
/// backends (`gpu_functions.rs`) and the interpolated normals and coordinates are the same
/// multiply-adds as the BSDFs', so pixels are compared to 1e-3 as for materials.
#[test]
fn textures_and_smooth_normals_same_image_on_cpu_and_gpu() {
    let path = "scenes/textures.toml";
    let mut scene = SceneFile::load(&repo_root().join(path)).unwrap();
    scene.scene.camera.width /= 2;
    scene.scene.camera.height /= 2;
    assert_scene_backends_agree(&scene, path, 8, 1e-3);
}

const KD: f32 = 0.6;
const H: f32 = 2.0;
/// The lights of the plane test: (radius, radiance); the second has radius 1e-4 of the scene.
const LAMPS: [(f32, f32); 2] = [(0.5, 5.0), (2e-4, 2.5e7)];

/// The plane-under-a-sphere-light scene seen from above at an angle, covering plane points up
/// to about 80 degrees from the foot of the light.
fn plane_lamp((r, l): (f32, f32)) -> Lamp {
    Lamp {
        center: Vec3::new(0.0, H, 0.0),
        radius: r,
        radiance: l,
    }
}

fn plane_scene(lamp: Lamp) -> SceneFile {
    plane_under_lamps(
        "eye = [0, 9, 9]\nlook_at = [0, 0, -1]\nup = [0, 1, 0]\nvfov = 70\nwidth = 48\nheight = 48",
        "seed = 3",
        KD,
        &[lamp],
    )
}

#[test]
fn plane_under_sphere_light_closed_form_on_both_backends() {
    // The pixel estimates vary with the sample positions inside each pixel even when the light
    // is tiny, so each has a variance and the z-test applies.
    for lamp in LAMPS.map(plane_lamp) {
        let scene = plane_scene(lamp);
        let exact = plane_exact(&scene.scene, KD, &[lamp]);
        assert!(exact.iter().filter(|e| e.is_some()).count() > 1500);
        for backend in [Backend::Cpu, Backend::Gpu] {
            let film = render_film(&scene, backend, 256);
            assert_eq!(film.discarded, 0);
            assert_film_matches(
                &film,
                &exact,
                &format!("{backend:?}, light radius {}", lamp.radius),
            );
        }
    }
    assert_validation_clean();
}

#[test]
fn white_furnace_exact_on_gpu() {
    // Cornell geometry, every albedo 1, no light, background 0.7, throughput roulette: every
    // sample is exactly 0.7; the GPU's f32 running mean of n equal values stays within
    // n ulp of them (each update rounds once).
    let mut text = twinpath_tests::white_cornell_toml();
    for (from, to) in [
        ("width = 256", "width = 48"),
        ("height = 256", "height = 48"),
    ] {
        assert!(text.contains(from), "{from}");
        text = text.replace(from, to);
    }
    text.push_str("\n[background]\nradiance = [0.7, 0.7, 0.7]\n");
    let scene = scene_from_toml(&text);
    assert!(scene.scene.lights.is_empty());
    let spp = 16;
    let film = render_film(&scene, Backend::Gpu, spp);
    assert_eq!(film.discarded, 0);
    for (i, p) in film.mean().iter().enumerate() {
        for c in p {
            assert!(
                (c - 0.7).abs() <= spp as f32 * f32::EPSILON * 0.7,
                "pixel {i} reads {c}, not 0.7"
            );
        }
    }
    assert_validation_clean();
}
