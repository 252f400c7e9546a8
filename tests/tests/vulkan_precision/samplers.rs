//! The samplers under Vulkan's arithmetic: cosine and cone samples stay in their domains with
//! finite densities, and cone points, phase directions, sphere and lobe samples and
//! `cos_sin_turns` stay within their derived errors of the exact values, under IEEE arithmetic
//! and every Vulkan model.

use super::*;

#[test]
fn cosine_samples_stay_in_the_hemisphere_under_vulkan_arithmetic() {
    set_model(Model::VULKAN);
    seed(6);
    let mut g = Gen(SplitMix(61));
    for case in 0..cases() {
        any_device(case);
        let n = g.dir();
        let u1 = kernel::rng::u32_to_unit_f32((g.0.u64() as u32) & 0x3ff_ffff);
        let (u1, u2) = if g.unit() < 0.5 {
            (u1, g.unit())
        } else {
            (g.unit(), g.unit())
        };
        let w = sample_cosine_hemisphere_v3(v(n), f(u1), f(u2));
        let w = back(w);
        assert!(w.dot(n) > 0.0, "n {n}, u {u1} {u2}: {w}");
        assert!((w.length() - 1.0).abs() < 16.0 * f32::EPSILON, "{w}");
    }
}

#[test]
fn cone_samples_face_the_receiver_with_finite_pdf_under_vulkan_arithmetic() {
    set_model(Model::VULKAN);
    seed(7);
    let mut g = Gen(SplitMix(71));
    for case in 0..cases() {
        any_device(case);
        let (s, t) = g.placement();
        let x = t + g.dir() * s * (1.0 + g.pow10(-5.0, 6.0));
        let sample = sample_sphere_cone_v3(v(t), f(s), v(x), f(g.unit()), f(g.unit()));
        let (p, nrm) = (back(sample.position), back(sample.normal));
        let pdf = sample.pdf_solid_angle.value;
        assert!(pdf.is_finite() && pdf > 0.0, "pdf {pdf}");
        assert!(p.is_finite() && nrm.is_finite());
        assert!((nrm.length() - 1.0).abs() <= 16.0 * f32::EPSILON, "{nrm}");
        // The sampled point faces the receiver, up to the point's rounding (as properties.rs
        // asks under IEEE arithmetic).
        let bound = sphere_point_error(t, s);
        assert!(nrm.dot(x - p) >= -bound, "{p} {nrm} {x}");
    }
}

/// `kernel::frame::orthonormal_basis` (Duff et al.'s frame) in `f64`: the exact frame of the
/// exact direction, for the samplers' exact references.
fn exact_frame(n: glam::DVec3) -> (glam::DVec3, glam::DVec3) {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        glam::DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        glam::DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// The point `sample_sphere_cone_v3` means for sphere (c, r), receiver p and (u1, u2), in
/// `f64` from the same `f32` inputs: the direction at angle theta (1 - cos theta = u1 (1 -
/// cos theta_max)) meets the sphere where alpha = beta - theta, beta = atan2(sin theta /
/// sin theta_max, cos beta), in the frame `orthonormal_basis` builds around the axis.
fn cone_point_exact(c: Vec3, r: f32, p: Vec3, u1: f32, u2: f32) -> glam::DVec3 {
    let (c, r, p, u1, u2) = (c.as_dvec3(), r as f64, p.as_dvec3(), u1 as f64, u2 as f64);
    let axis = (c - p).normalize();
    let sin2_max = (r * r / (c - p).length_squared()).min(1.0);
    let cos_max = (1.0 - sin2_max).sqrt();
    let one_minus_cos = u1 * sin2_max / (1.0 + cos_max);
    let sin = (one_minus_cos * (2.0 - one_minus_cos)).sqrt();
    let rest = 1.0 - u1;
    let cos_beta = (rest * (rest + cos_max * (1.0 + u1)) / (1.0 + cos_max)).sqrt();
    let alpha = (sin / sin2_max.sqrt()).atan2(cos_beta) - sin.atan2(1.0 - one_minus_cos);
    let (t, bt) = exact_frame(axis);
    let (cos_phi, sin_phi) = (
        (std::f64::consts::TAU * u2).cos(),
        (std::f64::consts::TAU * u2).sin(),
    );
    c + (t * (alpha.sin() * cos_phi) + bt * (alpha.sin() * sin_phi) - axis * alpha.cos()) * r
}

/// The cone sampler's point is within its own first-order error of the exact one, under IEEE
/// arithmetic and every Vulkan model (`device_class::cone_normal_error`: the axis, its frame,
/// sin and cos of alpha, the cone's extent with its conditioning tan(theta_max), the azimuth;
/// times r, plus the point's own roundings u (|c| + 2 r)). Under IEEE the measured error is a
/// few eps of the size; the former cos(alpha) = ... + cos(theta) sqrt(1 - sin^2 / sin^2_max)
/// cancelled at the rim and was ~3700 eps off there even on the CPU.
#[test]
fn cone_points_are_within_their_error_of_the_exact_point_under_every_arithmetic() {
    use twinpath_tests::device_class::cone_normal_error;
    let mut g = Gen(SplitMix(17));
    seed(17);
    // IEEE, Vulkan at random, the worst model leaning up and down.
    let (mut worst, mut worst_normal) = ([0f64; 4], [0f64; 4]);
    for case in 0..cases() {
        let (s, t) = g.placement();
        let x = t + g.dir() * s * (1.0 + g.pow10(-5.0, 6.0));
        let (u1, u2) = (g.unit(), g.unit());
        // The frame's branch at axis.z = 0: a rounding may take the other (equally valid) frame.
        if ((t - x).z / (t - x).length()).abs() < 1e-4 {
            continue;
        }
        let exact = cone_point_exact(t, s, x, u1, u2);
        let sin2_max = (s as f64 / (t - x).as_dvec3().length()).powi(2).min(1.0);
        let tan_max = (sin2_max / (1.0 - sin2_max)).sqrt();
        let model = case % 4;
        let (u, q, w) = use_model(model);
        let sample = sample_sphere_cone_v3(v(t), f(s), v(x), f(u1), f(u2));
        let bound = cone_normal_error(u, q, w, tan_max) * s as f64
            + u * (t.abs().max_element() as f64 + 2.0 * s as f64);
        let error = (back(sample.position).as_dvec3() - exact)
            .abs()
            .max_element();
        worst[model] = worst[model].max(error / bound);
        let exact_normal = (exact - t.as_dvec3()) / s as f64;
        let normal_error = (back(sample.normal).as_dvec3() - exact_normal)
            .abs()
            .max_element();
        worst_normal[model] =
            worst_normal[model].max(normal_error / cone_normal_error(u, q, w, tan_max));
    }
    set_model(Model::VULKAN);
    println!("cone points against the exact point, of their bound: IEEE, Vulkan, worst up, worst down {worst:.3?}; normals {worst_normal:.3?}");
    assert!(worst.iter().all(|&w| w <= 1.0), "{worst:?}");
    assert!(worst_normal.iter().all(|&w| w <= 1.0), "{worst_normal:?}");
}

/// The direction `phase::sample_v3` means for (g, wo, u1, u2), in `f64` from the same `f32`
/// inputs: mu and the sine from the exact factors 1 - mu and 1 + mu (the module's inverse CDF),
/// the azimuth 2 pi u2, in the frame `orthonormal_basis` builds around the direction of travel.
fn phase_direction_exact(g: f32, wo: Vec3, u1: f32, u2: f32) -> glam::DVec3 {
    let g = if g.abs() < kernel::phase::ISOTROPIC_G {
        0.0
    } else {
        g as f64
    };
    let (one_minus_mu, one_plus_mu) =
        twinpath_tests::exact::henyey_greenstein_factors(g, u1 as f64);
    let mu = (one_plus_mu - one_minus_mu) / 2.0;
    let sin = (one_minus_mu * one_plus_mu).sqrt();
    let travel = -wo.as_dvec3();
    let (t, bt) = exact_frame(travel);
    let (sin_phi, cos_phi) = (std::f64::consts::TAU * u2 as f64).sin_cos();
    (travel * mu + (t * cos_phi + bt * sin_phi) * sin).normalize()
}

/// Phase-sampled directions under IEEE arithmetic and every Vulkan model are within their
/// first-order error of the exact direction (`device_class::phase_direction_error`), and a
/// device's within `phase_directions_apart` of the CPU's (the bound `gpu_functions.rs` holds a
/// device that is not IEEE to). Inputs: g over (-1, 1) with its ends and the isotropic range,
/// u1 at its extremes, unit directions of travel (the frame's branch at z = 0 excluded: a
/// rounding may take the other, equally valid, frame).
#[test]
fn phase_directions_are_within_their_error_under_every_arithmetic() {
    use twinpath_tests::device_class::{phase_direction_error, phase_directions_apart};
    let eps = f32::EPSILON as f64;
    let mut g_ = Gen(SplitMix(23));
    seed(23);
    let (mut worst, mut apart) = ([0f64; 4], 0f64);
    let extremes = [2f32.powi(-24), 1e-4, 1.0 - 1e-4, 1.0 - 2f32.powi(-24)];
    for case in 0..cases() {
        let wo = g_.dir();
        if wo.z.abs() < 1e-4 {
            continue;
        }
        let g = match case % 5 {
            0 => 0.0,
            1 => 5e-4,
            2 => 0.99 * (2.0 * g_.unit() - 1.0).signum(),
            _ => 0.999 * (2.0 * g_.unit() - 1.0),
        };
        let u1 = if case % 7 == 0 {
            extremes[(case / 7) % 4]
        } else {
            g_.unit()
        };
        let u2 = g_.unit();
        let exact = phase_direction_exact(g, wo, u1, u2);
        let run = || back(kernel::phase::sample_v3(f(g), v(wo), f(u1), f(u2)));
        use_model(0);
        let cpu = run();
        for (model, worst) in worst.iter_mut().enumerate() {
            let (u, q, w) = use_model(model);
            let got = if model == 0 { cpu } else { run() };
            let error = (got.as_dvec3() - exact).abs().max_element();
            *worst = worst.max(error / phase_direction_error(u, q, w));
            apart = apart.max((got - cpu).abs().max_element() as f64);
        }
    }
    set_model(Model::VULKAN);
    println!(
        "phase directions against the exact one, of their bound: IEEE, Vulkan, worst up, worst down {worst:.3?}; a device against the CPU {:.2} eps (bound {:.1})",
        apart / eps,
        phase_directions_apart() / eps
    );
    assert!(worst.iter().all(|&w| w <= 1.0), "{worst:?}");
    assert!(apart <= phase_directions_apart(), "{} eps", apart / eps);
}

/// The seed's samplers `sample_sphere` and `sample_lobe` under IEEE arithmetic and every
/// Vulkan model: within their first-order errors of the exact normal and direction
/// (`device_class::sphere_normal_error`, `lobe_direction_error`), and a device's within the sum
/// of an IEEE and a Vulkan computation of the CPU's (the bounds `gpu_functions.rs` holds a
/// device that is not IEEE to). u1 at its extremes, cosines near +-1, azimuths over a turn.
#[test]
fn sphere_and_lobe_samples_are_within_their_error_under_every_arithmetic() {
    use glam::DVec3;
    use kernel::sampling::{sample_lobe_v3, sample_sphere_v3};
    use twinpath_tests::device_class::{
        lobe_direction_error, lobe_directions_apart, sphere_normal_error, sphere_points_apart,
    };
    let mut g = Gen(SplitMix(29));
    seed(29);
    // Per model (IEEE, Vulkan, worst up, worst down): sphere normals, lobe directions.
    let (mut worst, mut apart) = ([[0f64; 2]; 4], [0f64; 3]);
    for case in 0..cases() {
        let (s, t) = g.placement();
        let u1 = if case % 5 == 0 {
            [2f32.powi(-24), 1.0 - 2f32.powi(-24)][case / 5 % 2]
        } else {
            g.unit()
        };
        let u2 = g.unit();
        let z = 2.0 * u1 as f64 - 1.0;
        let r = (1.0 - z * z).sqrt();
        let (sin_phi, cos_phi) = (std::f64::consts::TAU * u2 as f64).sin_cos();
        let sphere_exact = DVec3::new(r * cos_phi, r * sin_phi, z);
        let axis = g.dir();
        let c = if case % 3 == 0 {
            1.0 - 1e-6 * g.unit()
        } else {
            2.0 * g.unit() - 1.0
        };
        let phi = std::f32::consts::TAU * g.unit();
        let lobe_exact = {
            let a = axis.as_dvec3();
            let (tt, bt) = exact_frame(a);
            let (c, sn) = (c as f64, (1.0 - (c as f64).powi(2)).sqrt());
            let (sp, cp) = (phi as f64).sin_cos();
            tt * (sn * cp) + bt * (sn * sp) + a * c
        };
        if axis.z.abs() < 1e-4 {
            continue;
        }
        let run = || {
            let (p, n) = sample_sphere_v3(v(t), f(s), f(u1), f(u2));
            (
                back(p),
                back(n),
                back(sample_lobe_v3(v(axis), f(c), f(phi))),
            )
        };
        use_model(0);
        let cpu = run();
        let (normal_apart, position_apart) = sphere_points_apart(t.into(), s);
        for (model, worst) in worst.iter_mut().enumerate() {
            let (u, q, w) = use_model(model);
            let got = if model == 0 { cpu } else { run() };
            let sphere_error = (got.1.as_dvec3() - sphere_exact).abs().max_element();
            worst[0] = worst[0].max(sphere_error / sphere_normal_error(u, w));
            let lobe_error = (got.2.as_dvec3() - lobe_exact).abs().max_element();
            let lobe_bound = lobe_direction_error(u, q, w, phi as f64);
            worst[1] = worst[1].max(lobe_error / lobe_bound);
            let d = |a: Vec3, b: Vec3| (a - b).abs().max_element() as f64;
            apart[0] = apart[0].max(d(got.1, cpu.1) / normal_apart);
            apart[1] = apart[1].max(d(got.0, cpu.0) / position_apart);
            apart[2] = apart[2].max(d(got.2, cpu.2) / lobe_directions_apart(phi));
        }
    }
    set_model(Model::VULKAN);
    println!("against the exact one, of their bounds, per model (IEEE, Vulkan, worst up, worst down) [sphere normals, lobe directions]: {worst:.3?}; a device against the CPU, of the bounds: sphere normals {:.3}, points {:.3}, lobe directions {:.3}", apart[0], apart[1], apart[2]);
    assert!(worst.iter().flatten().all(|&w| w <= 1.0), "{worst:?}");
    assert!(apart.iter().all(|&a| a <= 1.0), "{apart:?}");
}

/// `cos_sin_turns`, the azimuth of every sampler, is within 4 u of the exact cosine and sine
/// under IEEE arithmetic (u = eps / 2) and every Vulkan model (u = eps), and within 4 u of each
/// relative to its magnitude (plus the smallest normal float, which a model that flushes
/// denormals may lose): the assumptions of the samplers' derived bounds (`device_class`) and of
/// the balls' (`Ball::cos_sin_turns`). Its range reduction is exact in any rounding mode (4 x
/// and the nearest integer are exact, the remainder by Sterbenz's lemma), so the remainder's
/// quarter turn carries one product's rounding relative to itself, and the odd sine
/// polynomial's roundings are relative to its value; the cosine polynomial's lie below a few u
/// of results between cos(pi / 4) and 1. The reference reduces the same way in f64, so that
/// it, too, is accurate relative to values near 0 (at half a turn, f64's sin(2 pi x) is
/// 1.2e-16, the kernel's 0).
#[test]
fn cos_sin_turns_is_within_four_roundings_under_every_arithmetic() {
    use kernel::turns::cos_sin_turns;
    let mut g = SplitMix(43);
    seed(43);
    let (mut worst, mut worst_relative) = ([0f64; 4], [0f64; 4]);
    for k in 0..cases() {
        let x = if k < 1 << 12 {
            // Both sides of every eighth of a turn, where the reduction's quadrant changes.
            let edge = (k >> 6) as f32 / 8.0 - 4.0;
            let step = ((k & 63) as i32 - 32) as f32 * f32::EPSILON;
            edge + step * edge.abs().max(1.0)
        } else if k % 2 == 0 {
            // Within 10^-8..10^-3 of a quarter turn (the zeros of one of the two).
            (g.u64() % 8) as f32 / 4.0 - 1.0
                + 10f32.powf(-8.0 + 5.0 * g.unit()) * if k % 4 == 0 { 1.0 } else { -1.0 }
        } else {
            g.unit()
        };
        let (cos64, sin64) = exact_cos_sin_turns(x as f64);
        for (model, (worst, worst_relative)) in
            worst.iter_mut().zip(&mut worst_relative).enumerate()
        {
            let (u, _, _) = use_model(model);
            let (c, s) = cos_sin_turns(f(x));
            for (computed, exact) in [(c.value as f64, cos64), (s.value as f64, sin64)] {
                let error = (computed - exact).abs();
                *worst = worst.max(error / (4.0 * u));
                let relative = 4.0 * u * exact.abs() + f32::MIN_POSITIVE as f64;
                *worst_relative = worst_relative.max(error / relative);
            }
        }
    }
    set_model(Model::VULKAN);
    println!("cos_sin_turns against f64, of 4 u (IEEE, Vulkan, worst up, worst down): {worst:.3?}; of 4 u relative: {worst_relative:.3?}");
    assert!(worst.iter().all(|&w| w <= 1.0), "{worst:?}");
    assert!(
        worst_relative.iter().all(|&w| w <= 1.0),
        "{worst_relative:?}"
    );
}

/// (cos, sin) of 2 pi `x` turns, accurate relative to each: x less its nearest quarter turn
/// (exact in f64 for an f32 x), its cosine and sine, rotated by the quarters.
fn exact_cos_sin_turns(x: f64) -> (f64, f64) {
    let q = (4.0 * x).round();
    let (s, c) = (std::f64::consts::TAU * (x - 0.25 * q)).sin_cos();
    match (q as i64).rem_euclid(4) {
        0 => (c, s),
        1 => (-s, c),
        2 => (-c, -s),
        _ => (s, -c),
    }
}
