//! Chi-square goodness-of-fit tests of every sampler against the pdf the estimator divides by.
//! Expected bin counts come from integrating the *pdf functions* numerically over each bin, so
//! a sampler and its pdf that disagree fail, whichever of the two is wrong.

use glam::Vec3;
use kernel::bsdf::lambert::{pdf_brdf, sample_brdf};
use kernel::light::choose_light;
use kernel::light::sphere::{pdf_area, sample_area};
use kernel::rng::{u32_to_unit_f32, SampleRng};
use kernel::sampling::{
    pdf_sphere_area, pdf_sphere_cone, sample_lobe, sample_sphere, sample_sphere_cone,
};
use kernel::scene::light_selection;
use std::f64::consts::PI;
use twinpath::scene::light_table::{assign_light_selection, sphere_light};
use twinpath_tests::chi_square;

/// Family-wise significance of all chi-square tests in this file (Sidak-style split below).
const ALPHA: f64 = 0.01;
const TESTS: f64 = 11.0;
const SAMPLES: u32 = 1_000_000;

fn assert_fits(name: &str, observed: &[f64], expected: &[f64]) {
    twinpath_tests::assert_chi_square_fits(name, observed, expected, ALPHA, TESTS);
}

/// Bins over (cos theta in [-1, 1], phi in [0, 2pi)) around the frame of axis `n`.
const THETA_BINS: usize = 20;
const PHI_BINS: usize = 40;

fn spherical_bin(n: Vec3, w: Vec3) -> usize {
    let (t, b) = kernel::frame::orthonormal_basis(n);
    let c = w.dot(n).clamp(-1.0, 1.0) as f64;
    let phi = (w.dot(b) as f64)
        .atan2(w.dot(t) as f64)
        .rem_euclid(2.0 * PI);
    let i = (((c + 1.0) / 2.0 * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
    let j = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    i * PHI_BINS + j
}

/// Expected counts: the integral of `pdf` (solid-angle density) over each bin, by midpoint
/// quadrature in (cos theta, phi), where dw = d(cos theta) dphi.
fn expected_spherical(n: Vec3, pdf: impl Fn(Vec3) -> f64, samples: f64) -> Vec<f64> {
    let (t, b) = kernel::frame::orthonormal_basis(n);
    let q = 8; // quadrature points per bin side
    let mut expected = vec![0.0; THETA_BINS * PHI_BINS];
    let dc = 2.0 / THETA_BINS as f64 / q as f64;
    let dphi = 2.0 * PI / PHI_BINS as f64 / q as f64;
    for i in 0..THETA_BINS * q {
        let c = -1.0 + (i as f64 + 0.5) * dc;
        let s = (1.0 - c * c).max(0.0).sqrt();
        for j in 0..PHI_BINS * q {
            let phi = (j as f64 + 0.5) * dphi;
            let w = t * (s * phi.cos()) as f32 + b * (s * phi.sin()) as f32 + n * c as f32;
            expected[(i / q) * PHI_BINS + j / q] += pdf(w) * dc * dphi * samples;
        }
    }
    let total: f64 = expected.iter().sum::<f64>() / samples;
    assert!(
        (total - 1.0).abs() < 1e-3,
        "pdf integrates to {total}, not 1"
    );
    expected
}

fn rng(stream: u32) -> SampleRng {
    SampleRng::new(12345, stream, 0)
}

#[test]
fn sample_brdf_follows_pdf_brdf() {
    for (k, n) in [
        Vec3::Z,
        -Vec3::Z,
        Vec3::new(0.3, -0.5, 0.81).normalize(),
        Vec3::new(-1e-4, 1e-4, -1.0).normalize(),
    ]
    .into_iter()
    .enumerate()
    {
        let mut observed = vec![0.0; THETA_BINS * PHI_BINS];
        let mut r = rng(k as u32);
        for _ in 0..SAMPLES {
            let w = sample_brdf(n, r.next_f32(), r.next_f32());
            assert!((w.length() - 1.0).abs() < 1e-5);
            observed[spherical_bin(n, w)] += 1.0;
        }
        let expected = expected_spherical(n, |w| pdf_brdf(n, w) as f64, SAMPLES as f64);
        assert_fits(&format!("sample_brdf, n = {n}"), &observed, &expected);
    }
}

#[test]
fn sample_lobe_has_the_requested_cosine_and_uniform_azimuth() {
    // The seed's contract: cos(angle to A) = c exactly, phi the azimuth around A.
    let a = Vec3::new(0.2, 0.9, -0.3).normalize();
    let mut observed = vec![0.0; PHI_BINS];
    let mut r = rng(99);
    for _ in 0..SAMPLES {
        let c = 2.0 * r.next_f32() - 1.0;
        let phi = 2.0 * std::f32::consts::PI * r.next_f32();
        let w = sample_lobe(a, c, phi);
        assert!((w.dot(a) - c).abs() < 2e-6, "cosine {} != {c}", w.dot(a));
        observed[spherical_bin(a, w) % PHI_BINS] += 1.0;
    }
    let expected = vec![SAMPLES as f64 / PHI_BINS as f64; PHI_BINS];
    assert_fits("sample_lobe azimuth", &observed, &expected);
}

#[test]
fn sample_brdf_is_never_tangent_for_any_number_the_root_gives() {
    // Every uniform number is in [2^-24, 1 - 2^-24] (`rng::u32_to_unit_f32`, the midpoints of
    // 2^23 intervals): the smallest, from the all-zero word, gives cos(theta) = sqrt(2^-24) =
    // 2^-12 exactly and a pdf far above 0; every u1 keeps cos(theta) = sqrt(u1).
    let normals = [
        Vec3::Z,
        -Vec3::Z,
        Vec3::new(0.6, 0.0, 0.8),
        Vec3::new(0.0, -0.6, 0.8),
    ];
    let smallest = u32_to_unit_f32(0);
    assert_eq!(smallest, 2f32.powi(-24));
    for n in normals {
        for k in 0..64u32 {
            let u2 = u32_to_unit_f32(k << 26);
            let w = sample_brdf(n, smallest, u2);
            let cos = n.dot(w);
            assert!(
                (cos - 2f32.powi(-12)).abs() < 1e-6,
                "u1 = 2^-24, n {n}: cos {cos}"
            );
            assert!(pdf_brdf(n, w) > 7e-5);
            // The largest number is not the normal itself: sin(theta) = sqrt(2^-24) = 2^-12
            // (from sqrt(1 - u1); sqrt(1 - cos^2) cancelled to 0 there).
            let top = sample_brdf(n, u32_to_unit_f32(u32::MAX), u2);
            let sin = (top - n * n.dot(top)).length();
            assert!((sin - 2f32.powi(-12)).abs() < 1e-6, "n {n}: sin {sin}");
            for word in [0, 1 << 9, 2 << 9, 1 << 30, u32::MAX] {
                let u1 = u32_to_unit_f32(word);
                let cos = n.dot(sample_brdf(n, u1, u2));
                assert!(
                    (cos - u1.sqrt()).abs() < 2e-6,
                    "u1 {u1}, u2 {u2}, n {n}: cos {cos}"
                );
            }
        }
    }
}

#[test]
fn sample_sphere_is_uniform_in_area() {
    let (center, radius) = (Vec3::new(1.0, -2.0, 0.5), 0.7f32);
    let mut observed = vec![0.0; THETA_BINS * PHI_BINS];
    let mut r = rng(7);
    for _ in 0..SAMPLES {
        let p = sample_sphere(center, radius, r.next_f32(), r.next_f32());
        assert!(((p.position - center).length() - radius).abs() < 1e-5);
        assert!((p.normal - (p.position - center) / radius).length() < 1e-5);
        observed[spherical_bin(Vec3::Z, p.normal)] += 1.0;
    }
    // Area of a bin on the sphere is r^2 d(cos) dphi, times the area density.
    let area_pdf = pdf_sphere_area(radius) as f64;
    let r2 = (radius * radius) as f64;
    let expected = expected_spherical(Vec3::Z, |_| area_pdf * r2, SAMPLES as f64);
    assert_fits("sample_sphere", &observed, &expected);
}

/// `sample_sphere`'s normal is within 3 eps of the exact one for every random number the kernel
/// draws (all 2^23 values of u1, u2 fixed): the latitude's radius 2 sqrt(u1 (1 - u1)) carries
/// a product's and a root's rounding (under 1 eps), the azimuth `cos_sin_turns` 2^-23 = 1 eps,
/// and their product one more rounding. sqrt(1 - z^2) lost z^2's rounding, magnified by
/// 1 / (2 r) near the poles: 6.7 eps off at u1 = 8.6e-5 (measured once in f32 over all values).
#[test]
fn sample_sphere_normals_are_accurate_to_the_poles() {
    let mut worst = (0f64, 0f32);
    for k in 0..1u32 << 23 {
        let u1 = u32_to_unit_f32(k << 9);
        let u2 = 0.3f32;
        let n = sample_sphere(Vec3::ZERO, 1.0, u1, u2).normal.as_dvec3();
        let z = 2.0 * u1 as f64 - 1.0;
        let r = (1.0 - z * z).sqrt();
        let (s, c) = (2.0 * PI * u2 as f64).sin_cos();
        let exact = glam::DVec3::new(r * c, r * s, z);
        let err = (n - exact).abs().max_element() / f32::EPSILON as f64;
        if err > worst.0 {
            worst = (err, u1);
        }
    }
    println!(
        "sample_sphere: normals within {:.2} eps (at u1 = {:e})",
        worst.0, worst.1
    );
    assert!(worst.0 <= 3.0, "{worst:?}");
}

#[test]
fn sample_light_selects_by_pmf_and_pdf_light_matches() {
    let mk = |x: f32, radius: f32| sphere_light(Vec3::new(x, 0.0, 0.0), radius, [1.0; 3]);
    let mut lights = vec![mk(0.0, 0.5), mk(3.0, 1.0), mk(-3.0, 0.25)];
    let n = lights.len();
    assign_light_selection(&mut lights, light_selection::UNIFORM);
    let mut observed = vec![0.0; n];
    let mut r = rng(3);
    for _ in 0..SAMPLES {
        let light = choose_light(&lights, n as u32, r.next_f32());
        let s = sample_area(&lights[light as usize], light, r.next_f32(), r.next_f32());
        observed[s.light as usize] += 1.0;
        let l = lights[s.light as usize];
        assert!(((s.point.position - Vec3::from(l.position)).length() - l.radius).abs() < 1e-5);
        assert_eq!(s.pdf_area, pdf_area(&lights[s.light as usize]));
        let want = 1.0 / (n as f64 * 4.0 * PI * (l.radius as f64).powi(2));
        assert!((s.pdf_area as f64 / want - 1.0).abs() < 1e-6);
    }
    let expected = vec![SAMPLES as f64 / n as f64; n];
    assert_fits("sample_light selection", &observed, &expected);
}

#[test]
fn chi_square_detects_a_wrong_pdf() {
    // Power check: cosine samples tested against the *uniform hemisphere* pdf must fail.
    let n = Vec3::Z;
    let mut observed = vec![0.0; THETA_BINS * PHI_BINS];
    let mut r = rng(11);
    for _ in 0..SAMPLES {
        observed[spherical_bin(n, sample_brdf(n, r.next_f32(), r.next_f32()))] += 1.0;
    }
    let wrong = expected_spherical(
        n,
        |w| if w.z > 0.0 { 1.0 / (2.0 * PI) } else { 0.0 },
        SAMPLES as f64,
    );
    let (_, _, p) = chi_square(&observed, &wrong);
    assert!(
        p < 1e-6,
        "the chi-square test cannot tell cosine from uniform (p = {p})"
    );
}

#[test]
fn sample_sphere_cone_follows_its_pdf() {
    // Large, medium and tiny cones (the last below the Taylor-branch threshold of 1.5 degrees).
    for (k, (center, radius)) in [
        (Vec3::new(0.0, 1.0, 0.5), 0.8f32),
        (Vec3::new(3.0, -2.0, 1.0), 0.5),
        (Vec3::new(0.0, 0.0, 40.0), 0.5),
    ]
    .into_iter()
    .enumerate()
    {
        let p = Vec3::ZERO;
        let axis = (center - p).normalize();
        let mut observed = vec![0.0; THETA_BINS * PHI_BINS];
        let mut r = rng(100 + k as u32);
        // Bins in the cone's own (cos theta, phi) coordinates, cos theta rescaled to the cone.
        let one_minus_cos_max =
            kernel::sampling::cone_one_minus_cos(radius, (center - p).length_squared()) as f64;
        let bin = |w: Vec3| {
            let (t, b) = kernel::frame::orthonormal_basis(axis);
            let c = w.dot(axis) as f64;
            let x = ((1.0 - c) / one_minus_cos_max).clamp(0.0, 1.0);
            let phi = (w.dot(b) as f64)
                .atan2(w.dot(t) as f64)
                .rem_euclid(2.0 * PI);
            let i = ((x * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
            let j = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
            i * PHI_BINS + j
        };
        for _ in 0..SAMPLES {
            let s = sample_sphere_cone(center, radius, p, r.next_f32(), r.next_f32());
            let y = s.point.position;
            // On the sphere, facing the receiver, and the pdf matches pdf_sphere_cone.
            assert!(
                ((y - center).length() / radius - 1.0).abs() < 1e-4,
                "{y} not on the sphere"
            );
            let w = (y - p).normalize();
            assert!(s.point.normal.dot(w) <= 1e-3, "sampled point faces away");
            assert_eq!(s.pdf_solid_angle, pdf_sphere_cone(center, radius, p));
            observed[bin(w)] += 1.0;
        }
        // The pdf is constant in solid angle over the cone, so each bin (equal steps in
        // 1 - cos theta and phi) holds the same solid angle: uniform expected counts. That the
        // constant is right is checked by pdf * cone solid angle = 1.
        let pdf = pdf_sphere_cone(center, radius, p) as f64;
        assert!((pdf * 2.0 * PI * one_minus_cos_max - 1.0).abs() < 1e-5);
        let expected = vec![SAMPLES as f64 / (THETA_BINS * PHI_BINS) as f64; THETA_BINS * PHI_BINS];
        assert_fits(
            &format!(
                "sample_sphere_cone, radius {radius}, distance {}",
                center.length()
            ),
            &observed,
            &expected,
        );
    }
}

/// `cos_sin_turns` over every value the samplers pass it (u = k / 2^24, all 2^24 of them) and
/// around its reduction points against f64: both components within the error its doc derives
/// (a few roundings of values <= 1 after an exact reduction: 2^-23 absolute), and every
/// quadrant right (a swapped or negated quadrant is off by up to 2).
#[test]
fn cos_sin_turns_matches_f64_on_every_sampler_value() {
    use kernel::turns::cos_sin_turns;
    let mut worst = (0.0f64, 0.0f32);
    let mut check = |u: f32| {
        let (c, s) = cos_sin_turns(u);
        let (s64, c64) = (2.0 * PI * u as f64).sin_cos();
        let err = (c as f64 - c64).abs().max((s as f64 - s64).abs());
        if err > worst.0 {
            worst = (err, u);
        }
    };
    for k in 0..1u32 << 24 {
        check(k as f32 / 16_777_216.0);
    }
    // From both sides of u = j / 8: the reduction's edges (q changes at odd j) and the quarter
    // turns (even j), over two turns and one negative one.
    for j in -8..=16 {
        let edge = j as f32 / 8.0;
        let mut below = edge;
        let mut above = edge;
        for _ in 0..64 {
            check(below);
            check(above);
            below = below.next_down();
            above = above.next_up();
        }
    }
    println!(
        "cos_sin_turns: max error {:.3e} at u = {}",
        worst.0, worst.1
    );
    assert!(
        worst.0 <= 1.0 / 8_388_608.0,
        "cos_sin_turns: error {:.3e} at u = {} exceeds 2^-23",
        worst.0,
        worst.1
    );
}

/// `atan2_turns` against f64 over every octant and its reduction points: within the error its
/// doc derives (2^-24 turn plus 2 ulp of the result), and small angles within a few ulp.
#[test]
fn atan2_turns_matches_f64() {
    use kernel::turns::atan2_turns;
    let mut r = rng(77);
    let mut worst = (0.0f64, 0.0f32, 0.0f32);
    let mut check = |y: f32, x: f32| {
        let got = atan2_turns(y, x) as f64;
        let want = (y as f64).atan2(x as f64) / (2.0 * PI);
        let allowed = 1.0 / 16_777_216.0 + 2.0 * (f32::EPSILON as f64) * want.abs();
        let err = (got - want).abs() / allowed;
        if err > worst.0 {
            worst = (err, y, x);
        }
    };
    for _ in 0..2_000_000 {
        let (a, b) = (r.next_f32(), r.next_f32());
        let scale = 10f32.powf(12.0 * r.next_f32() - 6.0);
        check(scale * a, scale * (2.0 * b - 1.0));
    }
    // The reduction's edges: tan(pi/8), the diagonal, the axes; and tiny angles.
    for (y, x) in [
        (0.414_213_57f32, 1.0f32),
        (1.0, 1.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (0.0, -1.0),
    ] {
        let (mut y1, mut y2) = (y, y);
        for _ in 0..64 {
            check(y1, x);
            check(y2, x);
            check(y1, -x);
            check(x.abs(), y1);
            y1 = y1.next_up();
            y2 = y2.next_down().max(0.0);
        }
    }
    // Down to 1e-36 (below f32's normal range the result's own precision goes).
    for k in 0..180 {
        let y = 10f32.powf(-(k as f32) / 5.0);
        check(y, 1.0);
        check(y, -1.0);
        let got = atan2_turns(y, 1.0) as f64;
        let want = (y as f64).atan2(1.0) / (2.0 * PI);
        assert!(
            (got / want - 1.0).abs() < 4.0 * f32::EPSILON as f64,
            "small angle {y}: relative error {:.1e}",
            got / want - 1.0
        );
    }
    assert_eq!(atan2_turns(0.0, 0.0), 0.0);
    println!(
        "atan2_turns: worst error {:.2} of its bound at (y, x) = ({}, {})",
        worst.0, worst.1, worst.2
    );
    assert!(worst.0 <= 1.0, "atan2_turns beyond its bound at {worst:?}");
}

/// The thin lens's concentric disk map is uniform on the unit disk: bins equal in r^2 and in the
/// angle hold equal areas, so equal expected counts; no point leaves the disk.
#[test]
fn sample_concentric_disk_is_uniform_on_the_disk() {
    use kernel::sampling::sample_concentric_disk;
    let mut observed = vec![0.0; THETA_BINS * PHI_BINS];
    let mut r = rng(41);
    for _ in 0..SAMPLES {
        let (x, y) = sample_concentric_disk(r.next_f32(), r.next_f32());
        let r2 = (x as f64).powi(2) + (y as f64).powi(2);
        assert!(r2 <= 1.0 + 1e-6, "({x}, {y}) outside the disk");
        let phi = (y as f64).atan2(x as f64).rem_euclid(2.0 * PI);
        let i = ((r2 * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
        let j = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
        observed[i * PHI_BINS + j] += 1.0;
    }
    let expected = vec![SAMPLES as f64 / (THETA_BINS * PHI_BINS) as f64; THETA_BINS * PHI_BINS];
    assert_fits("sample_concentric_disk", &observed, &expected);
}
