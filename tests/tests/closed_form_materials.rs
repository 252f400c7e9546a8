//! Closed forms for the materials, on both backends: a sphere alone in a uniform environment
//! of radiance L (no lights), with throughput roulette from the first vertex.
//!
//! 1. Smooth glass (index 1.5): every path leaves the sphere again (inside a sphere the angle of
//!    incidence repeats, so total internal reflection never traps it) with weight
//!    F/F = 1 per reflection and 1/eta^2 eta^2 = 1 per pair of refractions, and roulette, reading
//!    the throughput times eta^2, never draws: every pixel is exactly L.
//! 2. A perfect mirror (conductor, reflectance 1): likewise exactly L.
//! 3. A rough mirror (reflectance 1, GGX): a convex object reflects once, so a pixel is L times
//!    the directional albedo A(theta_o) = integral of f cos over the hemisphere, averaged over
//!    the pixel: A by adaptive cubature of the f64 reference BSDF, the pixel by 16 x 16
//!    camera rays meeting the sphere in f64. z-tested pixel by pixel.

use glam::{DVec3, Vec3};
use std::f64::consts::PI;
use twinpath::film::Film;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::cubature::integrate;
use twinpath_tests::reference_bsdf::RefMaterial;
use twinpath_tests::{render_film, scene_from_toml, z_critical};

const L: f32 = 0.7;
const SIZE: u32 = 24;

fn sphere_in_environment(material: &str) -> SceneFile {
    scene_from_toml(&format!(
        r#"
[camera]
eye = [0.0, 0.0, 3.2]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
width = {SIZE}
height = {SIZE}

[render]
seed = 3
roulette = "throughput"
rr_start_depth = 1
sampler = "independent"

[materials]
m = {material}

[[sphere]]
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "m"

[background]
radiance = [{L}, {L}, {L}]
"#
    ))
}

/// The renders of a scene the closed forms are checked on: CPU by packets and one path at a
/// time, and the GPU, each at `spp`.
fn renders(scene: &SceneFile, spp: u32) -> Vec<(&'static str, Film)> {
    let mut one_path = scene.clone();
    one_path.settings.packets = false;
    vec![
        ("cpu packets", render_film(scene, Backend::Cpu, spp)),
        ("cpu one path", render_film(&one_path, Backend::Cpu, spp)),
        ("gpu", render_film(scene, Backend::Gpu, spp)),
    ]
}

#[test]
fn smooth_glass_and_mirror_spheres_are_exactly_the_environment() {
    for material in [
        "{ dielectric = { ior = 1.5 } }",
        "{ conductor = { reflectance = [1.0, 1.0, 1.0] } }",
    ] {
        let scene = sphere_in_environment(material);
        for (label, film) in renders(&scene, 16) {
            assert_eq!(film.discarded, 0);
            let worst = film
                .mean()
                .iter()
                .flatten()
                .map(|&c| ((c - L) / L).abs())
                .fold(0f32, f32::max);
            println!("{material} ({label}): worst relative deviation from L {worst:.2e}");
            // 1/eta^2 and eta^2 each rounded once per crossing, over a handful of crossings.
            assert!(worst <= 1e-6, "{material} ({label}): {worst:e}");
        }
    }
}

/// The directional albedo of the rough mirror of roughness `alpha` at cos_o: the integral of
/// f cos over the upper hemisphere, f from the f64 reference, by adaptive cubature in
/// (cos theta_i, phi_i).
fn albedo(alpha: f64, cos_o: f64) -> f64 {
    let m = RefMaterial::Conductor {
        eta: DVec3::ZERO,
        k: DVec3::ZERO,
        reflectance: Some(DVec3::ONE),
        alpha,
    };
    let n = DVec3::Z;
    let wo = DVec3::new((1.0 - cos_o * cos_o).max(0.0).sqrt(), 0.0, cos_o);
    let f = |c: f64, phi: f64| {
        let s = (1.0 - c * c).max(0.0).sqrt();
        let wi = DVec3::new(s * phi.cos(), s * phi.sin(), c);
        m.f(n, wo, wi).x * c
    };
    // The lobe is symmetric about the plane of wo: twice the half phi in [0, pi].
    2.0 * integrate(&f, (0.0, 1.0), (0.0, PI), 1e-9, 12)
}

#[test]
fn rough_mirror_sphere_shows_the_directional_albedo() {
    const ALPHA: f64 = 0.3;
    const QUAD: u32 = 16;
    let scene = sphere_in_environment(&format!(
        "{{ conductor = {{ reflectance = [1.0, 1.0, 1.0] }}, alpha = {ALPHA} }}"
    ));
    // A(cos_o) tabulated at 257 points in (0, 1], interpolated linearly.
    let table: Vec<f64> = (0..=256)
        .map(|i| albedo(ALPHA, (i as f64 / 256.0).max(1e-4)))
        .collect();
    let a_of = |c: f64| {
        let x = (c * 256.0).clamp(0.0, 256.0);
        let i = (x as usize).min(255);
        let t = x - i as f64;
        table[i] * (1.0 - t) + table[i + 1] * t
    };
    println!(
        "albedo at normal incidence {:.5}, at 60 deg {:.5}, at 85 deg {:.5}",
        a_of(1.0),
        a_of(0.5),
        a_of(0.087)
    );
    let camera = scene.scene.camera.to_kernel();
    let eye = Vec3::from_slice(&camera.eye[..3]).as_dvec3();
    let exact: Vec<Option<f64>> = (0..SIZE * SIZE)
        .map(|i| {
            let (px, py) = (i % SIZE, i / SIZE);
            let mut sum = 0.0;
            for k in 0..QUAD * QUAD {
                let (u, v) = (
                    ((k % QUAD) as f32 + 0.5) / QUAD as f32,
                    ((k / QUAD) as f32 + 0.5) / QUAD as f32,
                );
                let d = kernel::camera::camera_ray_direction(&camera, SIZE, SIZE, px, py, u, v)
                    .as_dvec3()
                    .normalize();
                // The unit sphere at the origin: |eye + t d| = 1.
                let b = eye.dot(d);
                let disc = b * b - (eye.length_squared() - 1.0);
                if disc <= 0.0 {
                    return None;
                }
                let p = eye + (-b - disc.sqrt()) * d;
                let cos_o = -d.dot(p.normalize());
                if cos_o < 0.1 {
                    return None;
                }
                sum += L as f64 * a_of(cos_o);
            }
            Some(sum / (QUAD * QUAD) as f64)
        })
        .collect();
    let tested = exact.iter().flatten().count();
    assert!(
        tested > 150,
        "{tested} pixels inside the sphere's silhouette"
    );
    for (label, film) in renders(&scene, 256) {
        assert_eq!(film.discarded, 0);
        let (mean, var) = (film.mean(), film.variance_of_mean());
        let z_max = z_critical(1e-3, tested);
        let (mut sum_d, mut sum_v, mut worst) = (0.0, 0.0, 0f64);
        for ((want, m), v) in exact.iter().zip(&mean).zip(&var) {
            let Some(want) = want else { continue };
            let (d, v) = (m[0] as f64 - want, v[0] as f64);
            let z = d / v.sqrt();
            worst = worst.max(z.abs());
            assert!(
                z.abs() < z_max,
                "{label}: pixel reads {} vs {want:.5} (z = {z:.2})",
                m[0]
            );
            sum_d += d;
            sum_v += v;
        }
        let z_all = sum_d / sum_v.sqrt();
        println!("rough mirror alpha {ALPHA} ({label}): {tested} pixels, worst |z| {worst:.2}, all pixels together z = {z_all:+.2}");
        assert!(z_all.abs() < z_critical(1e-3, 1), "{label}: z = {z_all:.2}");
    }
}
