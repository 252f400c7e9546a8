//! Closed-form scenes, z-tested against each estimate's own sample variance.
//!
//! 1. A diffuse plane (albedo kd) under one sphere light (radius r, radiance L): the radiance
//!    leaving plane point x is kd * L * (r/D)^2 * cos(theta) exactly (D: distance from x to the
//!    light's centre, theta: angle between the normal and the direction to it) while the sphere
//!    is entirely above the plane. A flat plane cannot see itself, so there is no other light.
//! 2. A white furnace: no lights, background Lb, every albedo 1, concave geometry (the Cornell
//!    box): every pixel is exactly Lb.

use glam::Vec3;
use kernel::path::trace_path;
use kernel::rng::SampleRng;
use rayon::prelude::*;
use twinpath::cpu::{BvhTracer, CpuRenderer};
use twinpath::film::Film;
use twinpath::scene::SceneFile;
use twinpath::settings::{Mis, Roulette};
use twinpath_tests::stats::mean_and_variance_of_mean;
use twinpath_tests::{scene_from_toml, z_critical};

const KD: f32 = 0.6;
const H: f32 = 2.0; // light centre height above the plane

/// A sphere light: radius and radiance.
#[derive(Clone, Copy)]
struct Lamp {
    r: f32,
    l: f32,
}
const LAMP: Lamp = Lamp { r: 0.5, l: 5.0 };
/// A light of radius 1e-4 of the scene (its radiance scaled so it still lights the plane).
const TINY_LAMP: Lamp = Lamp { r: 2e-4, l: 2.5e7 };
/// Paths per batch; a test point takes batches until its estimate can resolve a 2% bias.
const BATCH: u32 = 1_000_000;
const MAX_BATCHES: u32 = 32;

fn plane_scene(mis_mode: &str, roulette: &str, lamp: Lamp) -> SceneFile {
    let Lamp { r, l } = lamp;
    let mut s = twinpath_tests::plane_under_light(
        "eye = [0, 5, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 8\nheight = 8",
        &format!("mis = \"{mis_mode}\"\nroulette = \"{roulette}\""),
        KD,
        H,
        r,
        l,
    );
    // Roulette from the first vertex on, so its division is exercised at every step.
    s.settings.rr_start_depth = Some(1);
    s
}

/// Radiance estimates leaving plane point `x`, seen along a ray arriving from `view_dir` (unit,
/// pointing from the viewer to x).
fn estimate_at(scene: &SceneFile, x: Vec3, view_dir: Vec3, stream: u32, batch: u32) -> Vec<f64> {
    let cpu = CpuRenderer::new(&scene.scene, &scene.settings);
    let params = scene.params(0, 1);
    let origin = x - 3.0 * view_dir;
    // The viewing ray must reach x itself (not the light sphere).
    let first = cpu.bvh.closest_hit(origin, view_dir, f32::INFINITY);
    assert!(
        (first.position - x).length() < 1e-4,
        "view ray hits {:?}, not {x}",
        first.position
    );
    (batch * BATCH..(batch + 1) * BATCH)
        .into_par_iter()
        .map(|s| {
            let mut tracer = BvhTracer::new(&cpu.bvh);
            let mut rng = SampleRng::new(params.samples.seed, stream, s);
            rng.seek(kernel::vertex_samples::CAMERA_DIMENSIONS);
            let l = trace_path(
                &mut tracer,
                kernel::features::Dynamic(cpu.features),
                &cpu.view(&params),
                origin,
                view_dir,
                &mut rng,
            );
            l.x as f64
        })
        .collect()
}

fn exact(x: Vec3, lamp: Lamp) -> f64 {
    let Lamp { r, l } = lamp;
    let c = Vec3::new(0.0, H, 0.0);
    let d = (c - x).length() as f64;
    let cos = (H as f64) / d;
    KD as f64 * l as f64 * (r as f64 / d).powi(2) * cos
}

/// (variant name, mis, roulette, light)
const VARIANTS: [(&str, &str, &str, Lamp); 4] = [
    (
        "seed weights 1/2, constant roulette 0.8",
        "half",
        "constant",
        LAMP,
    ),
    (
        "power heuristic, constant roulette 0.8",
        "power",
        "constant",
        LAMP,
    ),
    (
        "power heuristic, throughput roulette",
        "power",
        "throughput",
        LAMP,
    ),
    (
        "tiny light (radius 1e-4 of the scene)",
        "power",
        "throughput",
        TINY_LAMP,
    ),
];
const ANGLES_DEG: [f32; 5] = [0.0, 30.0, 45.0, 60.0, 75.0];

#[test]
fn plane_under_sphere_light_matches_closed_form() {
    let z_max = z_critical(1e-3, VARIANTS.len() * ANGLES_DEG.len());
    for (k, &(name, m, rr, lamp)) in VARIANTS.iter().enumerate() {
        let scene = plane_scene(m, rr, lamp);
        assert_eq!(
            scene.settings.mis,
            if m == "half" { Mis::Half } else { Mis::Power }
        );
        assert_eq!(
            scene.settings.roulette,
            if rr == "constant" {
                Roulette::Constant
            } else {
                Roulette::Throughput
            }
        );
        for (j, deg) in ANGLES_DEG.iter().enumerate() {
            // x at horizontal distance H tan(theta) from the foot of the light.
            let s = H * deg.to_radians().tan();
            let x = Vec3::new(s * 0.6, 0.0, s * 0.8);
            // View from the side away from the light so the viewing ray misses the sphere.
            let away = Vec3::new(0.6, 0.0, 0.8);
            let view_dir = (-(away * 0.5 + Vec3::Y)).normalize();
            let want = exact(x, lamp);
            // Batches until a 2% bias would stand at 1.5 z_max standard errors; the stopping
            // rule looks only at the variance, never at the mean.
            let mut samples = Vec::new();
            let (mut mean, mut var) = (0.0, f64::INFINITY);
            for batch in 0..MAX_BATCHES {
                samples.extend(estimate_at(&scene, x, view_dir, (k * 16 + j) as u32, batch));
                (mean, var) = mean_and_variance_of_mean(&samples);
                if 0.02 * want > z_max * var.sqrt() * 1.5 {
                    break;
                }
            }
            let z = (mean - want) / var.sqrt();
            println!(
                "{name}, theta {deg:>4} deg: estimate {mean:.6} +- {:.6}, exact {want:.6}, z = {z:+.2}, relative error {:+.1e} ({} paths)",
                var.sqrt(),
                (mean - want) / want,
                samples.len()
            );
            // An estimate whose samples (nearly) all agree has no statistical error to speak
            // of: it must then match to the f32 precision of the path computation (a few dozen
            // roundings of ~6e-8: 1e-5 relative). Otherwise the z-test decides.
            let f32_floor = 1e-5 * want;
            if var.sqrt() < f32_floor {
                assert!(
                    (mean - want).abs() <= f32_floor,
                    "{name}, theta {deg}: deterministic estimate {mean} vs {want}"
                );
            } else {
                assert!(
                    z.abs() < z_max,
                    "{name}, theta {deg}: |z| = {:.2} >= {z_max:.2}",
                    z.abs()
                );
            }
            // Power: a 2% bias would stand at more than 1.5 z_max standard errors.
            assert!(
                0.02 * want > z_max * var.sqrt() * 1.5,
                "estimate too noisy to detect a 2% bias ({:.2e} vs {:.2e})",
                0.02 * want,
                var.sqrt()
            );
        }
    }
}

fn furnace_scene(roulette: &str, q: f32) -> SceneFile {
    let mut text =
        std::fs::read_to_string(twinpath_tests::repo_root().join("scenes/cornell.toml")).unwrap();
    // Every albedo 1, no light (the light sphere becomes a white diffuse sphere), background Lb.
    for name in ["white", "red", "green", "blue"] {
        let start = text.find(&format!("\n{name} = {{")).unwrap() + 1;
        let end = start + text[start..].find('\n').unwrap();
        text.replace_range(start..end, &format!("{name} = {{ kd = [1.0, 1.0, 1.0] }}"));
    }
    text = text.replace(
        "light = { emission = [10.0, 10.0, 10.0] }",
        "light = { kd = [1.0, 1.0, 1.0] }",
    );
    text = text.replace(
        "seed = 1",
        &format!("seed = 1\nrussian_roulette = {q}\nroulette = \"{roulette}\""),
    );
    text = text
        .replace("width = 256", "width = 48")
        .replace("height = 256", "height = 48");
    text.push_str("\n[background]\nradiance = [0.7, 0.7, 0.7]\n");
    // Independent samples: the constant-roulette test takes its variance from the samples.
    let s = twinpath_tests::with_independent_samples(scene_from_toml(&text));
    assert!(s.scene.lights.is_empty());
    s
}

#[test]
fn white_furnace_is_exact_with_throughput_roulette() {
    // Throughput stays exactly 1 (Kd = 1), so roulette never ends a path: every path bounces
    // until it leaves through the open side and reads Lb. Exact, not statistical.
    let scene = furnace_scene("throughput", 1.0);
    let cpu = CpuRenderer::new(&scene.scene, &scene.settings);
    let mut film = Film::new(scene.scene.camera.width, scene.scene.camera.height);
    cpu.render_into(&scene.params(0, 16), 0, 16, &mut film, None);
    assert_eq!(film.discarded, 0);
    for (i, p) in film.mean().iter().enumerate() {
        for c in p {
            assert_eq!(*c, 0.7, "pixel {i} reads {c}, not exactly 0.7");
        }
    }
}

#[test]
fn white_furnace_z_test_with_constant_roulette() {
    // With constant q, each surviving step multiplies the throughput by 1/q: unbiased but
    // noisy. q = 0.95 keeps the variance finite here (the per-bounce chance of staying in the
    // box, about 5/6, is below q^3, so even the fourth moment is finite).
    let scene = furnace_scene("constant", 0.95);
    let cpu = CpuRenderer::new(&scene.scene, &scene.settings);
    let spp = 256;
    let mut film = Film::new(scene.scene.camera.width, scene.scene.camera.height);
    cpu.render_into(&scene.params(0, spp), 0, spp, &mut film, None);
    assert_eq!(film.discarded, 0);
    let mean = film.mean();
    let var = film.variance_of_mean();
    // The image mean over all pixels: one z-test with the summed per-pixel variances.
    let n = mean.len() as f64;
    let m = mean.iter().map(|p| p[0] as f64).sum::<f64>() / n;
    let v = var.iter().map(|p| p[0] as f64).sum::<f64>() / (n * n);
    let z = (m - 0.7) / v.sqrt();
    println!(
        "furnace (q = 0.95): image mean {m:.5} +- {:.5}, z = {z:+.2}",
        v.sqrt()
    );
    assert!(z.abs() < z_critical(1e-3, 1), "|z| = {:.2}", z.abs());
    // And pixel by pixel (pixels whose paths all escape at once have zero variance and must read
    // exactly Lb).
    let z_max = z_critical(1e-2, mean.len());
    for (i, (p, v)) in mean.iter().zip(&var).enumerate() {
        if v[0] > 0.0 {
            let z = (p[0] as f64 - 0.7) / (v[0] as f64).sqrt();
            assert!(
                z.abs() < z_max,
                "pixel {i}: {} with |z| = {:.2}",
                p[0],
                z.abs()
            );
        } else {
            assert_eq!(p[0], 0.7, "pixel {i}");
        }
    }
}
