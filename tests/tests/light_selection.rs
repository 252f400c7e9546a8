//! Light selection: the alias table chooses each light with exactly its `select_pmf`
//! (chi-square, with a power check), power selection is proportional to power, and a plane
//! under three lights of very different power matches its closed form with either selection on
//! both backends.

use glam::Vec3;
use kernel::light::choose_light;
use kernel::scene::{light_selection, Light};
use twinpath::render::Backend;
use twinpath::scene::light_table::{
    alias_table, assign_light_selection, directional_light, light_power, punctual_light,
    sphere_light, triangle_light,
};
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_film_matches_with_variance, chi_square, plane_exact, plane_under_lamps, render_film,
    variance_of_mean_from, Lamp, SplitMix,
};

const DRAWS: usize = 1_000_000;

fn light(radius: f32, radiance: f32) -> Light {
    sphere_light(Vec3::ZERO, radius, [radiance; 3])
}

/// A light table whose selection follows `weights` through the alias table.
fn table(weights: &[f64]) -> Vec<Light> {
    let total: f64 = weights.iter().sum();
    weights
        .iter()
        .zip(alias_table(weights))
        .map(|(w, (threshold, alias))| Light {
            select_pmf: (w / total) as f32,
            alias_threshold: threshold,
            alias,
            ..light(1.0, 1.0)
        })
        .collect()
}

/// Counts of `choose_light` over `DRAWS` uniform numbers.
fn histogram(lights: &[Light], seed: u64) -> Vec<f64> {
    let mut rng = SplitMix(seed);
    let mut counts = vec![0.0; lights.len()];
    for _ in 0..DRAWS {
        let i = choose_light(lights, lights.len() as u32, rng.unit());
        counts[i as usize] += 1.0;
    }
    counts
}

fn weight_cases() -> Vec<Vec<f64>> {
    let mut rng = SplitMix(7);
    let random: Vec<f64> = (0..17)
        .map(|i| {
            if i % 5 == 0 {
                0.0
            } else {
                (rng.unit() as f64 * 20.0).exp()
            }
        })
        .collect();
    vec![
        vec![1.0],
        vec![1.0, 1.0, 1.0],
        vec![1.0, 0.0, 3.0],
        vec![0.0, 0.0, 1.0],
        vec![1e-6, 1.0, 1e3, 5.0],
        random,
    ]
}

#[test]
fn alias_table_chooses_each_light_with_its_pmf() {
    let cases = weight_cases();
    let threshold = 1.0 - (1.0 - 0.01f64).powf(1.0 / cases.len() as f64);
    for (k, w) in cases.iter().enumerate() {
        let lights = table(w);
        let total: f64 = w.iter().sum();
        let pmf_sum: f64 = lights.iter().map(|l| l.select_pmf as f64).sum();
        assert!(
            (pmf_sum - 1.0).abs() < 1e-6,
            "case {k}: pmfs sum to {pmf_sum}"
        );
        let observed = histogram(&lights, 100 + k as u64);
        let expected: Vec<f64> = w.iter().map(|x| x / total * DRAWS as f64).collect();
        let (stat, dof, p) = chi_square(&observed, &expected);
        println!(
            "alias table case {k} ({} lights): chi2 = {stat:.1}, dof = {dof}, p = {p:.4}",
            w.len()
        );
        assert!(p > threshold, "case {k}: p = {p:.2e}");
    }
}

#[test]
fn alias_chi_square_detects_a_wrong_pmf() {
    // Power check: a table for weights (1, 2, 3, 4) tested against (1, 2, 3, 4.1) must fail.
    let observed = histogram(&table(&[1.0, 2.0, 3.0, 4.0]), 5);
    let wrong = [1.0, 2.0, 3.0, 4.1];
    let total: f64 = wrong.iter().sum();
    let expected: Vec<f64> = wrong.iter().map(|x| x / total * DRAWS as f64).collect();
    let (_, _, p) = chi_square(&observed, &expected);
    assert!(p < 1e-6, "a 2.5% error in one pmf went unnoticed: p = {p}");
}

#[test]
fn power_selection_is_proportional_to_power_and_uniform_is_uniform() {
    let mut lights = vec![light(0.5, 10.0), light(0.05, 10.0), light(1.0, 0.01)];
    assign_light_selection(&mut lights, light_selection::POWER);
    let powers: Vec<f64> = lights.iter().map(light_power).collect();
    let total: f64 = powers.iter().sum();
    for (l, p) in lights.iter().zip(&powers) {
        assert!((l.select_pmf as f64 / (p / total) - 1.0).abs() < 1e-6);
    }
    // Luminance x area: radius 0.05 has 1/100 the power of radius 0.5 at equal radiance.
    assert!((powers[0] / powers[1] - 100.0).abs() < 1e-4);
    assign_light_selection(&mut lights, light_selection::UNIFORM);
    assert!(lights.iter().all(|l| l.select_pmf == 1.0 / 3.0));
}

/// Power selection weighs every kind of light on one scale: a sphere light (pi L 4 pi r^2), a
/// point light (4 pi I), a two-sided triangle (pi L 2 A) and a directional light over the
/// scene's disc (E pi R^2) of the same power are chosen equally often. (Area lights were
/// weighed without their pi until 2026-12-04, so a point light beside an emitter took pi times
/// its share.)
#[test]
fn power_selection_weighs_every_kind_of_light_alike() {
    use std::f32::consts::PI;
    // Power 2 pi^2 each: a sphere of radius 1/2 and radiance 2, a point light of intensity
    // pi / 2, a two-sided right triangle of legs pi and 1 (area pi / 2) and radiance 2, and a
    // directional light of irradiance 2 pi over the unit disc its placeholder bounds give.
    let tri = kernel::scene::Triangle {
        p0: [0.0; 3],
        material: 0,
        edge1: [PI, 0.0, 0.0],
        light: 0,
        edge2: [0.0, 1.0, 0.0],
        shading: kernel::scene::NONE,
    };
    let mut lights = vec![
        sphere_light(Vec3::ZERO, 0.5, [2.0; 3]),
        punctual_light(Vec3::ZERO, [PI / 2.0; 3], None),
        triangle_light(&tri, [2.0; 3], true),
        directional_light(-Vec3::Y, [2.0 * PI; 3]),
    ];
    assign_light_selection(&mut lights, light_selection::POWER);
    let want = 2.0 * (PI as f64).powi(2);
    for l in &lights {
        assert!(
            (light_power(l) / want - 1.0).abs() < 1e-6,
            "kind {}: power {} against {want}",
            l.kind,
            light_power(l)
        );
        assert!(
            (l.select_pmf - 0.25).abs() < 1e-6,
            "kind {}: pmf {}",
            l.kind,
            l.select_pmf
        );
    }
}

/// Three lamps whose powers differ by up to 10^3 (power selection picks the dim one with
/// probability 0.003), far enough apart that none hides another from the plane points the
/// camera sees (`plane_exact` also drops any pixel where they could).
const KD: f32 = 0.5;
fn lamps() -> [Lamp; 3] {
    [
        Lamp {
            center: Vec3::new(-3.0, 2.0, 0.0),
            radius: 0.3,
            radiance: 20.0,
        },
        Lamp {
            center: Vec3::new(3.0, 2.5, -1.0),
            radius: 0.1,
            radiance: 2.0,
        },
        Lamp {
            center: Vec3::new(0.0, 1.5, -3.0),
            radius: 0.05,
            radiance: 2000.0,
        },
    ]
}

#[test]
fn plane_under_three_lights_matches_closed_form_with_either_selection_on_both_backends() {
    for (name, selection) in [("uniform", "uniform"), ("power", "power")] {
        let scene = plane_under_lamps(
            "eye = [0, 10, 8]\nlook_at = [0, 0, -1]\nup = [0, 1, 0]\nvfov = 70\nwidth = 48\nheight = 48",
            &format!("seed = 5\nlight_selection = \"{selection}\""),
            KD,
            &lamps(),
        );
        assert_eq!(scene.scene.lights.len(), 3);
        let exact = plane_exact(&scene.scene, KD, &lamps());
        assert!(exact.iter().filter(|e| e.is_some()).count() > 1500);
        // Per-sample variances from an independent render: the rare light's pixels are heavy
        // tailed under power selection (see assert_film_matches_with_variance).
        let mut other = scene.clone();
        other.settings.seed += 1000;
        let variance_source = render_film(&other, Backend::Cpu, 2048);
        for backend in [Backend::Cpu, Backend::Gpu] {
            let film = render_film(&scene, backend, 256);
            assert_eq!(film.discarded, 0);
            let var = variance_of_mean_from(&variance_source, &film);
            assert_film_matches_with_variance(
                &film,
                &exact,
                var,
                &format!("{backend:?}, {name} selection"),
            );
            let noise: f64 = film.variance_of_mean().iter().map(|v| v[0] as f64).sum();
            println!(
                "{backend:?}, {name} selection: summed variance of the pixel means {noise:.4e}"
            );
        }
    }
    assert_validation_clean();
}
