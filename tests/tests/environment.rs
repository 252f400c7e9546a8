//! Environment maps (`kernel::environment`):
//!
//! 1. The sampler follows the density MIS uses for it (`environment::pdf`): chi-square over
//!    sub-texel bins, expected counts from that pdf function integrated in solid angle, on a map
//!    with one hot texel and on a smooth rotated map, by luminance and uniformly; the density
//!    each sample carries (its texel's) is finite, positive, and the look-up's except within
//!    rounding of a texel's edge.
//! 2. A constant map returns its constant exactly in every direction.
//! 3. A diffuse plane under a map with one bright texel matches the closed form
//!    kd L dphi (sin^2 theta2 - sin^2 theta1) / (2 pi) in every pixel, on both backends, with
//!    either sampler.

use glam::{DVec3, Vec3};
use kernel::environment::{eval, pdf, sample};
use kernel::rng::SampleRng;
use kernel::scene::{light_sampling, RenderParams};
use std::f64::consts::PI;
use twinpath::render::Backend;
use twinpath::scene::environment::EnvironmentMap;
use twinpath::scene::SceneFile;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{assert_film_matches, chi_square, render_film, scene_from_toml, SplitMix};

/// A diffuse plane y = 0 (albedo `KD`, 200 x 200) seen from above, every camera ray on it.
const KD: f32 = 0.6;
const PLANE: &str = r#"
[camera]
eye = [0.0, 5.0, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
width = 32
height = 32
[render]
seed = 9
sampler = "independent"
[materials]
plane = { kd = [0.6, 0.6, 0.6] }
[[quad]]
corner = [-100.0, 0.0, 100.0]
edge1 = [200.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -200.0]
material = "plane"
"#;

/// The plane scene under `map`.
fn plane_under(map: &EnvironmentMap) -> SceneFile {
    let mut scene = scene_from_toml(PLANE);
    scene.scene.set_environment(Some(map.clone()));
    scene
}

/// A map of `w` x `h` texels of `texel(i, j)` (grey).
fn map_of(w: u32, h: u32, texel: impl Fn(u32, u32) -> f32) -> EnvironmentMap {
    let mut m = EnvironmentMap::constant(w, h, [0.0; 3]);
    for j in 0..h {
        for i in 0..w {
            let v = texel(i, j);
            m.texels[(j * w + i) as usize] = [v, 0.9 * v, 0.8 * v];
        }
    }
    m
}

/// Unit direction of map coordinates (u, v) under rotation `degrees`, in f64.
fn direction(u: f64, v: f64, degrees: f64) -> DVec3 {
    let (phi, theta) = (2.0 * PI * u, PI * v);
    let m = DVec3::new(
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    );
    let (s, c) = degrees.to_radians().sin_cos();
    DVec3::new(c * m.x + s * m.z, m.y, c * m.z - s * m.x)
}

/// Map coordinates (u, v) of unit direction `d` under rotation `degrees`, in f64.
fn coordinates(d: DVec3, degrees: f64) -> (f64, f64) {
    let (s, c) = degrees.to_radians().sin_cos();
    let m = DVec3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
    let u = m.z.atan2(m.x).rem_euclid(2.0 * PI) / (2.0 * PI);
    let v = m.y.clamp(-1.0, 1.0).acos() / PI;
    (u, v)
}

/// Sub-texel bins per texel side.
const SUB: u32 = 4;
const SAMPLES: u32 = 1_000_000;

#[test]
fn the_sampler_follows_its_pdf() {
    let hot = map_of(16, 8, |i, j| if (i, j) == (5, 2) { 50.0 } else { 0.01 });
    let smooth = map_of(16, 8, |i, j| {
        let (u, v) = ((i as f64 + 0.5) / 16.0, (j as f64 + 0.5) / 8.0);
        (1.0 + 0.8 * (2.0 * PI * u).sin() * (PI * v).cos()
            + 2.0 * (-((v - 0.3) * 6.0).powi(2)).exp()) as f32
    });
    let mut rotated = smooth.clone();
    rotated.rotation_degrees = 30.0;
    let cases = [
        ("one hot texel", hot),
        ("smooth, rotated 30 degrees", rotated),
    ];
    let tests = 2 * cases.len();
    let threshold = 1.0 - (1.0 - 0.01f64).powf(1.0 / tests as f64);
    for (k, (name, map)) in cases.iter().enumerate() {
        let params = plane_under(map).params(0, 1);
        let table = map.table();
        let (bw, bh) = (map.width * SUB, map.height * SUB);
        let bin = |d: Vec3| {
            let (u, v) = coordinates(d.as_dvec3(), map.rotation_degrees as f64);
            let i = ((u * bw as f64) as u32).min(bw - 1);
            let j = ((v * bh as f64) as u32).min(bh - 1);
            (j * bw + i) as usize
        };
        for mode in [light_sampling::SOLID_ANGLE, light_sampling::AREA] {
            let label = format!(
                "{name}, {}",
                if mode == light_sampling::AREA {
                    "uniform"
                } else {
                    "by luminance"
                }
            );
            let mut observed = vec![0.0; (bw * bh) as usize];
            let mut r = SampleRng::new(2024, (2 * k) as u32 + mode, 0);
            let mut other_texel = 0;
            for _ in 0..SAMPLES {
                let s = sample(&params, &table, mode, r.next_f32(), r.next_f32());
                let d = s.direction;
                assert!((d.length() - 1.0).abs() < 1e-5, "{label}: {d} not unit");
                assert!(
                    s.pdf.is_finite() && s.pdf > 0.0,
                    "{label}: pdf {} drawn at {d}",
                    s.pdf
                );
                // The density drawn is its texel's; the look-up of the direction reads the
                // same texel (the same density within the rounding of sin theta) except where
                // the direction lies within rounding (8 eps of the coordinates, generously) of a
                // texel's edge.
                let p = pdf(&params, &table, mode, d);
                if (p - s.pdf).abs() > 1e-5 * s.pdf {
                    let (u, v) = coordinates(d.as_dvec3(), map.rotation_degrees as f64);
                    let near_edge = |x: f64, n: u32| {
                        let y = x * n as f64;
                        (y - y.round()).abs() <= 8.0 * f32::EPSILON as f64 * n as f64
                    };
                    assert!(
                        near_edge(u, map.width) || near_edge(v, map.height),
                        "{label}: drawn at {d} with density {}, looked up {p}, away from an edge",
                        s.pdf
                    );
                    other_texel += 1;
                }
                observed[bin(d)] += 1.0;
            }
            println!("{label}: {other_texel} of {SAMPLES} looked up in a neighbouring texel");
            // Expected counts: the pdf function integrated over each bin in solid angle, by the
            // midpoint rule on 4 x 4 cells per bin, each weighted by its exact solid angle
            // dphi (cos theta1 - cos theta2).
            let q = 4;
            let mut expected = vec![0.0; (bw * bh) as usize];
            let (du, dv) = (1.0 / (bw * q) as f64, 1.0 / (bh * q) as f64);
            for j in 0..bh * q {
                let (v0, v1) = (j as f64 * dv, (j + 1) as f64 * dv);
                let omega = 2.0 * PI * du * ((PI * v0).cos() - (PI * v1).cos());
                for i in 0..bw * q {
                    let d = direction(
                        (i as f64 + 0.5) * du,
                        (j as f64 + 0.5) * dv,
                        map.rotation_degrees as f64,
                    );
                    let p = pdf(&params, &table, mode, d.as_vec3()) as f64;
                    expected[((j / q) * bw + i / q) as usize] += SAMPLES as f64 * p * omega;
                }
            }
            let total = expected.iter().sum::<f64>() / SAMPLES as f64;
            assert!(
                (total - 1.0).abs() < 2e-3,
                "{label}: the pdf integrates to {total}"
            );
            let (stat, dof, p) = chi_square(&observed, &expected);
            println!("{label}: chi2 = {stat:.1}, dof = {dof}, p = {p:.4}");
            assert!(
                p > threshold,
                "{label}: samples do not follow the pdf (p = {p:.2e})"
            );
        }
    }
}

#[test]
fn a_constant_map_is_its_constant_everywhere() {
    let mut map = EnvironmentMap::constant(64, 32, [0.25, 0.5, 0.75]);
    map.scale = 2.0;
    map.rotation_degrees = 17.0;
    let params: RenderParams = plane_under(&map).params(0, 1);
    let table = map.table();
    let mut g = SplitMix(3);
    for _ in 0..100_000 {
        let d = Vec3::new(g.unit() - 0.5, g.unit() - 0.5, g.unit() - 0.5);
        let Some(d) = d.try_normalize() else { continue };
        assert_eq!(eval(&params, &table, d), Vec3::new(0.5, 1.0, 1.5), "at {d}");
    }
    for d in [Vec3::Y, -Vec3::Y, Vec3::X, -Vec3::Z] {
        assert_eq!(eval(&params, &table, d), Vec3::new(0.5, 1.0, 1.5), "at {d}");
    }
}

/// The map of the plane test: 8 x 4 texels, black but texel (2, 1), of grey radiance `L`
/// (theta from 45 to 90 degrees, phi from 90 to 135 degrees).
const L: f32 = 3.0;

fn one_texel_map() -> EnvironmentMap {
    map_of(8, 4, |i, j| if (i, j) == (2, 1) { L } else { 0.0 })
}

#[test]
fn plane_under_one_bright_texel_matches_its_closed_form_on_both_backends() {
    // The plane (normal +y) sees the texel over dphi = pi/4 and theta in [pi/4, pi/2]:
    // E = L int cos(theta) dw = L dphi (sin^2(pi/2) - sin^2(pi/4)) / 2, radiance kd E / pi.
    let e = L as f64 * (PI / 4.0) * (1.0 - 0.5) / 2.0;
    let want = KD as f64 * e / PI;
    for mode in ["solid_angle", "area"] {
        let mut scene = plane_under(&one_texel_map());
        scene
            .settings
            .set("light_sampling", mode)
            .expect("a light_sampling value");
        let exact = vec![Some(want); scene.scene.pixel_count()];
        for backend in [Backend::Cpu, Backend::Gpu] {
            let film = render_film(&scene, backend, 256);
            assert_eq!(film.discarded, 0);
            assert_film_matches(&film, &exact, &format!("{backend:?}, {mode} sampling"));
        }
    }
    assert_validation_clean();
}

/// A constant map lights the plane as the constant background does: radiance kd L (the plane
/// sees the whole upper hemisphere), every sample exactly that under the uniform background (an
/// escaping path adds it with weight 1), and in the mean under the map (light samples and
/// escaping paths weighted by MIS), per pixel on both backends.
#[test]
fn a_constant_map_lights_like_the_constant_background_on_both_backends() {
    let want = KD as f64 * 0.5;
    let mut uniform = scene_from_toml(PLANE);
    uniform.scene.background = Vec3::splat(0.5);
    let film = render_film(&uniform, Backend::Cpu, 16);
    assert!(
        film.mean()
            .iter()
            .all(|p| (p[0] as f64 - want).abs() < 1e-6),
        "the uniform background is not exactly kd L"
    );
    let map = plane_under(&EnvironmentMap::constant(32, 16, [0.5; 3]));
    let exact = vec![Some(want); map.scene.pixel_count()];
    for backend in [Backend::Cpu, Backend::Gpu] {
        let film = render_film(&map, backend, 64);
        assert_eq!(film.discarded, 0);
        assert_film_matches(&film, &exact, &format!("{backend:?}, constant map"));
    }
    assert_validation_clean();
}
