//! Image-level CPU-vs-GPU equivalence and the closed-form scenes on the GPU (lavapipe in CI),
//! with the Vulkan validation layers on: any validation message fails the test.

use glam::Vec3;
use twinpath::film::Film;
use twinpath::render::Backend;
use twinpath::scene::Scene;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{image_mean_z, render_film, repo_root, scene_from_toml, z_critical};

/// Same scene, seed and spp on both backends: the same samples, so nearly every pixel must be
/// equal; the few others are pixels where one path's ray flips between hit and miss at an edge
/// (the GPU intersects triangles with its own watertight test, the CPU with Moller-Trumbore).
fn assert_backends_agree(path: &str, spp: u32) {
    let scene = Scene::load(&repo_root().join(path)).unwrap();
    let cpu = render_film(&scene, Backend::Cpu, spp);
    let gpu = render_film(&scene, Backend::Gpu, spp);
    assert_eq!((cpu.discarded, gpu.discarded), (0, 0));
    assert_eq!(cpu.count, gpu.count);
    let (a, b) = (cpu.mean(), gpu.mean());
    let mut differing = Vec::new();
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        let close = (0..3).all(|c| (x[c] - y[c]).abs() <= 1e-4 * x[c].abs().max(y[c].abs()));
        if !close {
            differing.push((
                i % scene.camera.width as usize,
                i / scene.camera.width as usize,
                *x,
                *y,
            ));
        }
    }
    let fraction_equal = 1.0 - differing.len() as f64 / a.len() as f64;
    println!(
        "{path}, {spp} spp, same seed: {:.4}% of pixels equal to 1e-4 relative; {} differ:",
        100.0 * fraction_equal,
        differing.len()
    );
    for (x, y, c, g) in differing.iter().take(10) {
        println!("  pixel ({x}, {y}): cpu {c:?} gpu {g:?}");
    }
    assert!(
        fraction_equal >= 0.999,
        "only {:.4}% equal",
        100.0 * fraction_equal
    );

    // Independent seeds: the two backends' image means agree within their noise.
    let mut other = scene.clone();
    other.render.seed = scene.render.seed.wrapping_add(1000);
    let gpu2 = render_film(&other, Backend::Gpu, spp);
    let z = image_mean_z(&cpu, &gpu2);
    println!(
        "{path}: cpu (seed {}) vs gpu (seed {}) image means: z = {z:+.2}",
        scene.render.seed, other.render.seed
    );
    assert!(
        z.abs() < z_critical(1e-3, 1),
        "image means differ: z = {z:.2}"
    );
    assert_validation_clean();
}

#[test]
fn cornell_same_image_on_cpu_and_gpu() {
    assert_backends_agree("scenes/cornell.toml", 16);
}

#[test]
fn mesh_scene_same_image_on_cpu_and_gpu() {
    assert_backends_agree("scenes/meshes.toml", 16);
}

const KD: f32 = 0.6;
const H: f32 = 2.0;
/// The lights of the plane test: (radius, radiance); the second has radius 1e-4 of the scene.
const LAMPS: [(f32, f32); 2] = [(0.5, 5.0), (2e-4, 2.5e7)];

/// The plane-under-a-sphere-light scene seen from above at an angle, covering plane points up
/// to about 80 degrees from the foot of the light.
fn plane_scene((r, l): (f32, f32)) -> Scene {
    twinpath_tests::plane_under_light(
        "eye = [0, 9, 9]\nlook_at = [0, 0, -1]\nup = [0, 1, 0]\nvfov = 70\nwidth = 48\nheight = 48",
        "seed = 3",
        KD,
        H,
        r,
        l,
    )
}

/// The exact pixel values: kd L (r/D)^2 cos(theta) at the plane point each camera ray meets,
/// averaged over the pixel by a 24 x 24 midpoint quadrature (the box filter; 8 x 8 left a
/// quadrature error visible against the tiny light's small per-pixel noise); `None` for pixels
/// any of whose quadrature rays sees the light or misses the plane.
fn plane_exact(scene: &Scene, (r, l): (f32, f32)) -> Vec<Option<f64>> {
    let cam = scene.camera.to_kernel();
    let (w, h) = (scene.camera.width, scene.camera.height);
    let eye = Vec3::new(cam.eye[0], cam.eye[1], cam.eye[2]);
    let centre = Vec3::new(0.0, H, 0.0);
    let q = 24;
    (0..w * h)
        .map(|i| {
            let (px, py) = (i % w, i / w);
            let mut sum = 0.0;
            for sy in 0..q {
                for sx in 0..q {
                    let (u, v) = ((sx as f32 + 0.5) / q as f32, (sy as f32 + 0.5) / q as f32);
                    let d = kernel::camera::camera_ray_direction(&cam, w, h, px, py, u, v);
                    let t_light =
                        kernel::geometry::intersect_sphere(eye, d, centre, r, 0.0, f32::INFINITY);
                    if t_light >= 0.0 || d.y >= 0.0 {
                        return None;
                    }
                    let x = eye + d * (-eye.y / d.y);
                    let dist = (centre - x).length() as f64;
                    sum += KD as f64 * l as f64 * (r as f64 / dist).powi(2) * (H as f64 / dist);
                }
            }
            Some(sum / (q * q) as f64)
        })
        .collect()
}

fn assert_plane_matches(film: &Film, exact: &[Option<f64>], label: &str) {
    let mean = film.mean();
    let var = film.variance_of_mean();
    let tested = exact.iter().filter(|e| e.is_some()).count();
    let z_max = z_critical(1e-3, tested);
    let (mut worst, mut sum_d, mut sum_v) = (0.0f64, 0.0, 0.0);
    for (i, e) in exact.iter().enumerate() {
        let Some(e) = e else { continue };
        let (m, v) = (mean[i][0] as f64, var[i][0] as f64);
        let z = (m - e) / v.sqrt();
        worst = worst.max(z.abs());
        sum_d += m - e;
        sum_v += v;
        assert!(
            z.abs() < z_max,
            "{label}: pixel {i}: {m} vs exact {e}, |z| = {:.2} >= {z_max:.2}",
            z.abs()
        );
    }
    let z_all = sum_d / sum_v.sqrt();
    println!("{label}: {tested} pixels vs closed form: max |z| {worst:.2} (bound {z_max:.2}); all pixels together z = {z_all:+.2}");
    assert!(z_all.abs() < z_critical(1e-3, 1));
}

#[test]
fn plane_under_sphere_light_closed_form_on_both_backends() {
    // The pixel estimates vary with the sample positions inside each pixel even when the light
    // is tiny, so each has a variance and the z-test applies.
    for lamp in LAMPS {
        let scene = plane_scene(lamp);
        let exact = plane_exact(&scene, lamp);
        assert!(exact.iter().filter(|e| e.is_some()).count() > 1500);
        for backend in [Backend::Cpu, Backend::Gpu] {
            let film = render_film(&scene, backend, 256);
            assert_eq!(film.discarded, 0);
            assert_plane_matches(
                &film,
                &exact,
                &format!("{backend:?}, light radius {}", lamp.0),
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
    let mut text = std::fs::read_to_string(repo_root().join("scenes/cornell.toml")).unwrap();
    for (from, to) in [
        ("kd = [0.73, 0.73, 0.73]", "kd = [1.0, 1.0, 1.0]"),
        ("kd = [0.65, 0.05, 0.05]", "kd = [1.0, 1.0, 1.0]"),
        ("kd = [0.12, 0.45, 0.15]", "kd = [1.0, 1.0, 1.0]"),
        ("kd = [0.25, 0.35, 0.75]", "kd = [1.0, 1.0, 1.0]"),
        ("emission = [10.0, 10.0, 10.0]", "kd = [1.0, 1.0, 1.0]"),
        ("russian_roulette = 0.8", "roulette = \"throughput\""),
        ("width = 256", "width = 48"),
        ("height = 256", "height = 48"),
    ] {
        assert!(text.contains(from), "{from}");
        text = text.replace(from, to);
    }
    text.push_str("\n[background]\nradiance = [0.7, 0.7, 0.7]\n");
    let scene = scene_from_toml(&text);
    assert!(scene.lights.is_empty());
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
