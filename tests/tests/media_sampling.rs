//! The samplers of participating media against their own densities (chi-square, as
//! `sampling.rs` tests the surfaces'): Henyey-Greenstein directions (`kernel::phase`) and free
//! flights in RGB media (`kernel::free_flight`), with the normalisation of each density, and the
//! weights the free flight returns against their definitions.

use glam::{DVec3, Vec3};
use kernel::free_flight::{self, hero_channel};
use kernel::phase;
use kernel::rng::SampleRng;
use std::f64::consts::PI;
use twinpath_tests::chi_square;

/// Family-wise significance of all chi-square tests in this file (Sidak-style split below).
const ALPHA: f64 = 0.01;
const TESTS: f64 = 10.0;
const SAMPLES: u32 = 1_000_000;

fn assert_fits(name: &str, observed: &[f64], expected: &[f64]) {
    twinpath_tests::assert_chi_square_fits(name, observed, expected, ALPHA, TESTS);
}

fn rng(stream: u32) -> SampleRng {
    SampleRng::new(4242, stream, 0)
}

/// Bins over (cos theta in [-1, 1], phi in [0, 2 pi)) about the axis `axis`.
const THETA_BINS: usize = 40;
const PHI_BINS: usize = 16;

fn bin(axis: Vec3, w: Vec3) -> usize {
    let (t, b) = kernel::frame::orthonormal_basis(axis);
    let c = w.dot(axis).clamp(-1.0, 1.0) as f64;
    let phi = (w.dot(b) as f64)
        .atan2(w.dot(t) as f64)
        .rem_euclid(2.0 * PI);
    let i = (((c + 1.0) / 2.0 * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
    let j = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    i * PHI_BINS + j
}

/// Expected counts of a density over directions that depends on cos theta about `axis` alone:
/// the integral of `pdf(cos)` over each bin (midpoint quadrature, 4096 points per bin in
/// cos theta: g = 0.9 peaks within 0.01 of cos 1), 2 pi / PHI_BINS in azimuth; asserts it
/// integrates to 1.
fn expected_by_angle(pdf: impl Fn(f64) -> f64, samples: f64) -> Vec<f64> {
    let q = 4096;
    let dc = 2.0 / THETA_BINS as f64 / q as f64;
    let mut expected = vec![0.0; THETA_BINS * PHI_BINS];
    let mut total = 0.0;
    for i in 0..THETA_BINS * q {
        let c = -1.0 + (i as f64 + 0.5) * dc;
        let mass = pdf(c) * dc * 2.0 * PI;
        total += mass;
        for j in 0..PHI_BINS {
            expected[(i / q) * PHI_BINS + j] += mass / PHI_BINS as f64 * samples;
        }
    }
    assert!(
        (total - 1.0).abs() < 1e-4,
        "pdf integrates to {total}, not 1"
    );
    expected
}

/// The Henyey-Greenstein density in f64, as its definition writes it (module `kernel::phase`).
fn hg(g: f64, cos_theta: f64) -> f64 {
    let g = if g.abs() < phase::ISOTROPIC_G as f64 {
        0.0
    } else {
        g
    };
    (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * cos_theta).powf(1.5))
}

/// Phase samples of asymmetry `g` for the path arriving along `travel`, binned about `travel`
/// (the scattering angle's axis: cos theta = wi . travel).
fn phase_histogram(g: f32, travel: Vec3, stream: u32) -> Vec<f64> {
    let wo = -travel;
    let mut observed = vec![0.0; THETA_BINS * PHI_BINS];
    let mut r = rng(stream);
    for _ in 0..SAMPLES {
        let (u1, u2) = r.next_2d();
        let wi = phase::sample(g, wo, u1, u2);
        assert!((wi.length() - 1.0).abs() < 1e-5, "unit direction");
        observed[bin(travel, wi)] += 1.0;
    }
    observed
}

#[test]
fn henyey_greenstein_sampling_follows_its_density() {
    let travel = Vec3::new(0.3, -0.5, 0.81).normalize();
    for (k, g) in [-0.7f32, 0.0, 0.3, 0.9].into_iter().enumerate() {
        let observed = phase_histogram(g, travel, k as u32);
        let expected = expected_by_angle(|c| hg(g as f64, c), SAMPLES as f64);
        assert_fits(&format!("HG g = {g}"), &observed, &expected);
    }
    // The density the kernel reports is the f64 definition, and the scattering angle is the
    // one between the directions of travel: forward scattering (g > 0) continues along it.
    let wo = -travel;
    for g in [-0.7f32, 0.0005, 0.3, 0.9] {
        for c in [-0.99f32, -0.3, 0.0, 0.5, 0.999] {
            let (t, _) = kernel::frame::orthonormal_basis(travel);
            let wi = (travel * c + t * (1.0 - c * c).sqrt()).normalize();
            let got = phase::eval(g, wo, wi) as f64;
            let want = hg(g as f64, wi.dot(travel) as f64);
            assert!(
                (got - want).abs() <= 2e-5 * want,
                "g {g}, cos {c}: {got} vs {want}"
            );
        }
    }
    assert!(phase::eval(0.9, wo, travel) > 10.0 * phase::eval(0.9, wo, -travel));
}

/// The scattering angle of a phase sample is accurate everywhere, also where the direction
/// nears the axis of travel (u1 near 0 or 1) and for |g| near 1: within 8 eps (radians) of the
/// angle the inputs mean, computed in f64 from the same (g, u1). The bound: the sine's two
/// factors carry a few roundings each (about 4 eps relative in the sine), the frame 2.5 eps and
/// the sum and normalisation a few more. sqrt(1 - mu^2) took the square root of mu's rounding
/// (1804 eps = 2.2e-4 rad off at g = 0.9, u1 = 2^-24; angle 0 instead of 3.5e-5 at
/// u1 = 1 - 2^-24), and 1 - g + 2 g u1 cancelled for g near -1 (63 eps at g = -0.99);
/// `phase::sample` writes 1 - mu and 1 + mu as products of non-negative terms instead.
#[test]
fn phase_samples_keep_their_angle_near_the_axis_of_travel() {
    let travel = Vec3::new(0.3, -0.5, 0.81).normalize();
    let wo = -travel;
    let extremes = [
        2f32.powi(-24),
        3.0 * 2f32.powi(-24),
        1e-4,
        0.5,
        1.0 - 1e-4,
        1.0 - 2f32.powi(-24),
    ];
    let mut r = rng(77);
    let mut worst = 0f64;
    for g in [0.0f32, 0.3, 0.9, 0.99, -0.7, -0.99] {
        for k in 0..20_000 {
            let u1 = if k < extremes.len() {
                extremes[k]
            } else {
                r.next_f32()
            };
            let wi = phase::sample(g, wo, u1, r.next_f32()).as_dvec3();
            let (one_minus_mu, one_plus_mu) =
                twinpath_tests::exact::henyey_greenstein_factors(g as f64, u1 as f64);
            let exact = (one_minus_mu * one_plus_mu)
                .sqrt()
                .atan2((one_plus_mu - one_minus_mu) / 2.0);
            let t = travel.as_dvec3().normalize();
            let angle = wi.cross(t).length().atan2(wi.dot(t));
            worst = worst.max((angle - exact).abs() / f32::EPSILON as f64);
        }
    }
    println!("phase samples: scattering angle within {worst:.2} eps of the exact one");
    assert!(worst <= 8.0, "{worst} eps");
}

#[test]
fn the_phase_chi_square_tells_forward_from_backward() {
    // Power check: samples of g = 0.3 against the density of g = -0.3 must fail.
    let travel = Vec3::Z;
    let observed = phase_histogram(0.3, travel, 9);
    let wrong = expected_by_angle(|c| hg(-0.3, c), SAMPLES as f64);
    let (_, _, p) = chi_square(&observed, &wrong);
    assert!(p < 1e-6, "the test cannot tell g from -g (p = {p})");
}

/// Bins of a free flight's distance over [0, d) (`T_BINS` of equal width) and one for the
/// surface (no collision before d).
const T_BINS: usize = 64;

/// Free flights of extinction `sigma_t` before a surface at `d` (finite), binned; and the
/// expected counts from `collision_pdf` (midpoint quadrature, 32 points per bin) and
/// `pass_probability`, whose sum is asserted to be 1.
fn flights(sigma_t: Vec3, d: f32, stream: u32) -> (Vec<f64>, Vec<f64>) {
    let sigma_s = sigma_t * 0.5;
    let mut observed = vec![0.0; T_BINS + 1];
    let mut r = rng(100 + stream);
    for _ in 0..SAMPLES {
        let (uc, u) = r.next_2d();
        let f = free_flight::sample(sigma_t, sigma_s, d, hero_channel(uc), u, Vec3::ONE);
        if f.scattered {
            assert!(f.t >= 0.0 && f.t < d);
            observed[((f.t / d * T_BINS as f32) as usize).min(T_BINS - 1)] += 1.0;
        } else {
            assert_eq!(f.t, d);
            observed[T_BINS] += 1.0;
        }
    }
    let q = 32;
    let dt = d as f64 / (T_BINS * q) as f64;
    let mut expected = vec![0.0; T_BINS + 1];
    for i in 0..T_BINS * q {
        let t = (i as f64 + 0.5) * dt;
        let pdf: f64 = (0..3)
            .map(|c| sigma_t[c] as f64 * (-(sigma_t[c] as f64) * t).exp())
            .sum::<f64>()
            / 3.0;
        expected[i / q] += pdf * dt * SAMPLES as f64;
    }
    expected[T_BINS] = (0..3)
        .map(|c| (-(sigma_t[c] as f64) * d as f64).exp())
        .sum::<f64>()
        / 3.0
        * SAMPLES as f64;
    let total: f64 = expected.iter().sum::<f64>() / SAMPLES as f64;
    assert!((total - 1.0).abs() < 1e-4, "{total}");
    (observed, expected)
}

#[test]
fn free_flights_follow_the_mean_of_the_channels_densities() {
    for (k, (sigma_t, d)) in [
        (Vec3::splat(1.3), 2.0),
        (Vec3::new(0.2, 1.0, 4.0), 1.5),
        (Vec3::new(0.0, 0.5, 3.0), 2.5),
    ]
    .into_iter()
    .enumerate()
    {
        let (observed, expected) = flights(sigma_t, d, k as u32);
        assert_fits(
            &format!("free flight sigma_t {sigma_t:?} before {d}"),
            &observed,
            &expected,
        );
    }
}

#[test]
fn the_free_flight_chi_square_tells_one_channel_from_three() {
    // Power check: flights of three channels against the density of the first channel alone.
    let sigma_t = Vec3::new(0.2, 1.0, 4.0);
    let (observed, _) = flights(sigma_t, 1.5, 7);
    let mut wrong = vec![0.0; T_BINS + 1];
    let w = 1.5 / T_BINS as f64;
    for (i, e) in wrong.iter_mut().take(T_BINS).enumerate() {
        let (a, b) = (i as f64 * w, (i + 1) as f64 * w);
        *e = ((-0.2 * a).exp() - (-0.2 * b).exp()) * SAMPLES as f64;
    }
    wrong[T_BINS] = (-0.2f64 * 1.5).exp() * SAMPLES as f64;
    let (_, _, p) = chi_square(&observed, &wrong);
    assert!(
        p < 1e-6,
        "the test cannot tell the mixture from one channel (p = {p})"
    );
}

/// The weights are the definitions' (module `kernel::free_flight`): sigma_s T(t) / pdf(t) at
/// a collision and T(d) / P(pass) at the surface, per channel, in f64; and their expectation
/// over the flights is the volume rendering equation's: E[w 1{collision in [a, b)}] =
/// integral over [a, b) of sigma_s exp(-sigma_t t) dt and E[w 1{pass}] = exp(-sigma_t d), per
/// channel, which the one-sample MIS over the channels keeps (z-tests).
#[test]
fn free_flight_weights_are_unbiased_per_channel() {
    let sigma_t = Vec3::new(0.2, 1.0, 4.0);
    let sigma_s = Vec3::new(0.1, 0.9, 1.0);
    let d = 1.5f32;
    let (a, b) = (0.3f64, 0.9f64);
    let mut r = rng(300);
    let n = SAMPLES as usize;
    let (mut in_ab, mut pass) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    for k in 0..n {
        let (uc, u) = r.next_2d();
        let f = free_flight::sample(sigma_t, sigma_s, d, hero_channel(uc), u, Vec3::ONE);
        let w = f.weight.as_dvec3();
        let ratios = f.ratios.as_dvec3();
        assert!(
            ((ratios.x + ratios.y + ratios.z) / 3.0 - 1.0).abs() < 1e-6,
            "{ratios}"
        );
        let t = f.t as f64;
        if f.scattered {
            let tr = DVec3::from_array(
                (0..3)
                    .map(|c| (-(sigma_t[c] as f64) * t).exp())
                    .collect::<Vec<_>>()
                    .try_into()
                    .unwrap(),
            );
            let pdf = (sigma_t.as_dvec3() * tr).element_sum() / 3.0;
            let want = sigma_s.as_dvec3() * tr / pdf;
            assert!(
                (w - want).abs().max_element() <= 1e-5 * want.max_element(),
                "{w} vs {want}"
            );
            assert!(
                w.max_element() <= 3.0 * 1.0001,
                "bounded by 3 sigma_s / sigma_t"
            );
            if (a..b).contains(&t) {
                in_ab[k] = w;
            }
        } else {
            let tr = (-sigma_t.as_dvec3() * d as f64).exp();
            let want = tr / (tr.element_sum() / 3.0);
            assert!(
                (w - want).abs().max_element() <= 1e-5 * want.max_element(),
                "{w} vs {want}"
            );
            pass[k] = w;
        }
    }
    let z_max = twinpath_tests::z_critical(1e-3, 6);
    for c in 0..3 {
        let (st, ss) = (sigma_t[c] as f64, sigma_s[c] as f64);
        let want_ab = ss / st * ((-st * a).exp() - (-st * b).exp());
        let want_pass = (-st * d as f64).exp();
        for (label, values, want) in [
            ("collision in [a, b)", &in_ab, want_ab),
            ("pass", &pass, want_pass),
        ] {
            let mean = values.iter().map(|v| v[c]).sum::<f64>() / n as f64;
            let var = values.iter().map(|v| (v[c] - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
            let z = (mean - want) / (var / n as f64).sqrt();
            println!("channel {c}, {label}: {mean:.5} vs {want:.5} (z = {z:+.2})");
            assert!(
                z.abs() < z_max,
                "channel {c}, {label}: {mean} vs {want} (z = {z:.2})"
            );
        }
    }
}

/// The path-level weight (module `kernel::free_flight`): after several events, the product of
/// the flights' weights is the path's contribution over the mean of the three channels' path
/// densities, F_c / ((1/3) sum_k P_k), computed here directly in f64 from each event's
/// densities, whichever channel drew the distances; and the ratios are P_k over that mean.
#[test]
fn free_flight_weights_compose_to_the_path_level_balance_heuristic() {
    let sigma_t = Vec3::new(0.3, 1.2, 2.5);
    let sigma_s = Vec3::new(0.25, 0.6, 2.0);
    for hero in 0..3u32 {
        let mut throughput = DVec3::ONE;
        let mut ratios = Vec3::ONE;
        let (mut f_path, mut p_path) = (DVec3::ONE, DVec3::ONE);
        // Three collisions then a pass, at these distances' numbers.
        for (u, d) in [(0.3f32, 10.0f32), (0.7, 10.0), (0.1, 10.0), (0.95, 0.2)] {
            let flight = free_flight::sample(sigma_t, sigma_s, d, hero, u, ratios);
            throughput *= flight.weight.as_dvec3();
            ratios = flight.ratios;
            let tr = (-sigma_t.as_dvec3() * flight.t as f64).exp();
            if flight.scattered {
                f_path *= sigma_s.as_dvec3() * tr;
                p_path *= sigma_t.as_dvec3() * tr;
            } else {
                f_path *= tr;
                p_path *= tr;
            }
        }
        let mean = p_path.element_sum() / 3.0;
        let want = f_path / mean;
        assert!(
            (throughput - want).abs().max_element() <= 1e-5 * want.max_element(),
            "hero {hero}: {throughput} vs {want}"
        );
        let want_ratios = p_path / mean;
        assert!(
            (ratios.as_dvec3() - want_ratios).abs().max_element()
                <= 1e-5 * want_ratios.max_element(),
            "hero {hero}: {ratios} vs {want_ratios}"
        );
        // Bounded by 3 F_c / P_c: here F / P = (sigma_s / sigma_t)^3 per channel.
        let own = f_path / p_path;
        assert!(
            (throughput - 3.0 * own).max_element() <= 1e-9,
            "{throughput} vs 3 x {own}"
        );
    }
}
