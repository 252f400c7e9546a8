//! The spherical-triangle sampler of triangle lights (`kernel::spherical_triangle`, written over
//! `Real`) under Vulkan's arithmetic: its solid angle (the density every light sample divides
//! by) and its sampled directions within the first-order bounds derived for the arithmetic
//! (`twinpath_tests::spherical_triangle_error`), and the directions' distribution.

use super::{back, cases, f, use_model, v};
use glam::Vec3;
use kernel::spherical_triangle::SphericalTriangle;
use twinpath_tests::device_class::IEEE_ROUNDOFF;
use twinpath_tests::spherical_triangle_error::{solid_angle_error, solid_angle_exact};
use twinpath_tests::vulkan_arithmetic::{set_model, Model};
use twinpath_tests::SplitMix;

/// A triangle (p0, e1, e2) and a receiver: vertices in a box of size 2 at the origin, receivers
/// from 10^-3 to 10^3 sizes away from its centroid (as `triangle_lights.rs` draws them), every
/// other one moved to just above or below its plane (elevations down to 10^-4 of the distance),
/// where the triple product cancels.
fn triangle_and_receiver(g: &mut SplitMix, k: usize) -> (Vec3, Vec3, Vec3, Vec3) {
    let mut v = |s: f32| Vec3::new(g.unit() - 0.5, g.unit() - 0.5, g.unit() - 0.5) * s;
    let p = [v(2.0), v(2.0), v(2.0)];
    let centroid = (p[0] + p[1] + p[2]) / 3.0;
    let distance = 10f32.powf((k % 7) as f32 - 3.0);
    let mut x = centroid + v(2.0 * distance);
    if k % 2 == 1 {
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        let along = x - centroid;
        x = centroid + along - n * along.dot(n) + n * along.length() * 10f32.powf(-4.0 * g.unit());
    }
    (x, p[0], p[1] - p[0], p[2] - p[0])
}

/// The solid angle under IEEE arithmetic and every Vulkan model is within its first-order
/// relative error of the exact one (`solid_angle_error` for the model's (u, q, w)); the Vulkan
/// models exceed the bound derived for IEEE arithmetic, so the wider one is needed. Cases whose
/// solid angle is 0 to the kernel or exactly (the receiver in the plane) are skipped.
#[test]
fn solid_angles_are_within_their_error_under_every_arithmetic() {
    let mut g = SplitMix(31);
    twinpath_tests::vulkan_arithmetic::seed(31);
    // Per model (IEEE, Vulkan, worst up, worst down): of the model's bound, of IEEE's bound.
    let (mut worst, mut of_ieee) = ([0f64; 4], [0f64; 4]);
    let mut tested = 0;
    for k in 0..cases() {
        let (x, p0, e1, e2) = triangle_and_receiver(&mut g, k);
        let arrays = (x.to_array(), p0.to_array(), e1.to_array(), e2.to_array());
        let exact = solid_angle_exact(arrays.0, arrays.1, arrays.2, arrays.3);
        if !(exact > 0.0) {
            continue;
        }
        tested += 1;
        for model in 0..4 {
            let roundoff = use_model(model);
            let got = SphericalTriangle::view(v(x), v(p0), v(e1), v(e2))
                .solid_angle_real()
                .value as f64;
            let error = (got / exact - 1.0).abs();
            let bound = |r| solid_angle_error(arrays.0, arrays.1, arrays.2, arrays.3, r);
            worst[model] = worst[model].max(error / bound(roundoff));
            of_ieee[model] = of_ieee[model].max(error / bound(IEEE_ROUNDOFF));
        }
    }
    set_model(Model::VULKAN);
    println!("solid angles against the exact ones ({tested} cases), of their bound: IEEE, Vulkan, worst up, worst down {worst:.3?}; of IEEE's bound {of_ieee:.3?}");
    assert!(tested > cases() / 2, "{tested} cases");
    assert!(worst.iter().all(|&w| w <= 1.0), "{worst:?}");
    // The models' liberties move the solid angle further than IEEE arithmetic ever does.
    assert!(
        of_ieee[1..].iter().all(|&w| w > of_ieee[0]),
        "the Vulkan models err no more than IEEE arithmetic: {of_ieee:?}"
    );
}

/// Receivers exactly in the plane of a triangle (one whose vertices share a coordinate, which
/// the receiver shares too: the triple product is all rounding, the solid angle 0 outside the
/// triangle and 2 pi inside it): under IEEE arithmetic and every Vulkan model the kernel's
/// solid angle stays within its absolute error of the exact one (`solid_angle_error_absolute`),
/// which `gpu_functions.rs` holds such records to; and rounding does move it there, so the
/// bound is not vacuous.
#[test]
fn solid_angles_in_the_plane_are_within_their_absolute_error_under_every_arithmetic() {
    use twinpath_tests::spherical_triangle_error::solid_angle_error_absolute;
    let mut g = SplitMix(59);
    twinpath_tests::vulkan_arithmetic::seed(59);
    let (mut worst, mut nonzero) = ([0f64; 4], [0usize; 4]);
    for k in 0..cases() {
        let scale = 10f32.powf(4.0 * g.unit() - 2.0);
        let level = (g.unit() - 0.5) * 4.0 * scale;
        let axis = k % 3;
        let spread = 10f32.powf(3.0 * g.unit() - 1.0);
        let mut point = |spread: f32| {
            let mut c = [0f32; 3];
            for (i, c) in c.iter_mut().enumerate() {
                *c = if i == axis {
                    level
                } else {
                    (g.unit() - 0.5) * 2.0 * spread * scale
                };
            }
            Vec3::from_array(c)
        };
        let p = [point(1.0), point(1.0), point(1.0)];
        let x = point(spread);
        let (p0, e1, e2) = (p[0], p[1] - p[0], p[2] - p[0]);
        let arrays = (x.to_array(), p0.to_array(), e1.to_array(), e2.to_array());
        // 0 outside the triangle, 2 pi inside it (atan2(0, D) of a negative D).
        let exact = solid_angle_exact(arrays.0, arrays.1, arrays.2, arrays.3);
        for model in 0..4 {
            let roundoff = use_model(model);
            let got = SphericalTriangle::view(v(x), v(p0), v(e1), v(e2))
                .solid_angle_real()
                .value as f64;
            let bound =
                solid_angle_error_absolute(arrays.0, arrays.1, arrays.2, arrays.3, roundoff);
            worst[model] = worst[model].max((got - exact).abs() / bound);
            nonzero[model] += (got != exact) as usize;
        }
    }
    set_model(Model::VULKAN);
    println!("solid angles in the plane, of their absolute error (IEEE, Vulkan, worst up, worst down): {worst:.3?}; nonzero in {nonzero:?} of {} cases", cases());
    assert!(worst.iter().all(|&w| w <= 1.0), "{worst:?}");
    assert!(nonzero.iter().all(|&n| n > 0), "{nonzero:?}");
}

/// Samples per case of the chi-square test below (`Vk32` draws a coin per operation).
const SAMPLES: usize = 200_000;

/// The sampler's directions under two Vulkan models (liberties at random, all at their largest)
/// follow its density, uniform in solid angle:
/// a chi-square test of the sub-triangle each direction meets (`triangle_bins`, the point
/// found in `f64`) against each sub-triangle's exact share of the solid angle, on triangles the
/// light samples this way: moderate, close and large (5.6 sr), thin, near the smallest solid
/// angle sampled (3e-4 sr), and seen at 2 degrees above the plane. Every direction is a finite
/// unit vector that meets the triangle's plane within its barycentric bounds (to 1e-4: the
/// light moves such points onto the triangle, `barycentrics_along`). A distribution-level
/// check beside the pointwise bound below: 64 bins and 2 x 10^5 samples see distortions of a
/// few percent of a bin, not rounding.
#[test]
fn sampled_directions_follow_the_solid_angle_under_vulkan_arithmetic() {
    use twinpath_tests::triangle_bins::{barycentrics, bin_of, bins, solid_angle_f64, N};
    use twinpath_tests::{chi_square, SplitMix};
    let right = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let cases = [
        ("moderate", right, Vec3::new(0.2, 0.3, 1.0)),
        ("close, 5.6 sr", right, Vec3::new(0.3, 0.3, 0.01)),
        (
            "thin",
            [Vec3::ZERO, Vec3::X, Vec3::new(0.5, 0.06, 0.0)],
            Vec3::new(0.4, 0.02, 0.3),
        ),
        ("near 3e-4 sr", right, Vec3::new(0.3, 0.3, 28.0)),
        (
            "2 degrees above the plane",
            right,
            Vec3::new(-1.0, 0.3, 0.035),
        ),
    ];
    let tests = 2 * cases.len();
    let threshold = 1.0 - (1.0 - 0.01f64).powf(1.0 / tests as f64);
    let mut g = SplitMix(37);
    twinpath_tests::vulkan_arithmetic::seed(37);
    for (name, p, x) in cases {
        let (p0, e1, e2) = (p[0], p[1] - p[0], p[2] - p[0]);
        assert!(
            SphericalTriangle::of(x, p0, e1, e2).sampled(),
            "{name}: not sampled as a spherical triangle"
        );
        let (x64, p64) = (x.as_dvec3(), p.map(|q| q.as_dvec3()));
        let omega = solid_angle_f64(x64, p64);
        let at = |(u, v): (f64, f64)| p64[0] + u * (p64[1] - p64[0]) + v * (p64[2] - p64[0]);
        let expected: Vec<f64> = bins()
            .iter()
            .map(|b| {
                b.map_or(0.0, |t| {
                    SAMPLES as f64 * solid_angle_f64(x64, t.map(at)) / omega
                })
            })
            .collect();
        for model in 1..3 {
            use_model(model);
            let view = SphericalTriangle::view(v(x), v(p0), v(e1), v(e2));
            let mut observed = vec![0.0; 2 * N * N];
            for _ in 0..SAMPLES {
                let d = back(view.sample_real(f(g.unit()), f(g.unit())));
                let length = d.as_dvec3().length();
                assert!((length - 1.0).abs() < 1e-5, "{name}: |direction| {length}");
                let (u, w) = barycentrics(x64, d.as_dvec3(), p64);
                assert!(
                    u > -1e-4 && w > -1e-4 && u + w < 1.0 + 1e-4,
                    "{name}: direction {d} meets the plane at ({u}, {w})"
                );
                observed[bin_of(u, w)] += 1.0;
            }
            let (stat, dof, p_value) = chi_square(&observed, &expected);
            println!("{name}, model {model}: chi2 {stat:.1}, dof {dof}, p {p_value:.3}");
            assert!(
                p_value > threshold,
                "{name}: directions under Vulkan arithmetic do not follow the solid angle (chi2 {stat:.1}, dof {dof}, p {p_value:.2e})"
            );
        }
    }
    set_model(Model::VULKAN);
}

/// The sampled direction under IEEE arithmetic and every Vulkan model is within its
/// first-order error of the exact direction (`sample_direction_error` for the model's
/// (u, q, w): every rounding of the sampler and of the view it reads, one at a time at its
/// allowance), on the triangles and receivers above that the kernel samples as spherical
/// triangles, with u1 and u2 at their extremes every fifth case; and the Vulkan models go
/// beyond the bound derived for IEEE arithmetic (so the wider one is needed). The bound is per
/// record and carries the record's conditioning: near u1 = 1 for a receiver close to a large
/// light's plane the map from u1 to the arc is steep, and there the bound (and the CPU's own
/// error) is large.
#[test]
fn sampled_directions_are_within_their_error_under_every_arithmetic() {
    use twinpath_tests::spherical_triangle_error::sample_direction_error;
    let mut g = SplitMix(41);
    twinpath_tests::vulkan_arithmetic::seed(41);
    let (mut worst, mut of_ieee) = ([0f64; 4], [0f64; 4]);
    let mut tested = 0;
    let extremes = [2f32.powi(-24), 1e-4, 0.5, 1.0 - 1e-4, 1.0 - 2f32.powi(-24)];
    let mut bounds = Vec::new();
    for k in 0..cases() {
        let (x, p0, e1, e2) = triangle_and_receiver(&mut g, k);
        if !SphericalTriangle::of(x, p0, e1, e2).sampled() {
            continue;
        }
        let (u1, u2) = if k % 5 == 0 {
            (extremes[k / 5 % 5], extremes[k / 25 % 5])
        } else {
            (g.unit(), g.unit())
        };
        let arrays = (x.to_array(), p0.to_array(), e1.to_array(), e2.to_array());
        // The exact direction and the bounds of both arithmetics, per vertex taken as A (each
        // computation's own choice, which a device's roundings may make otherwise near a tie).
        let mut per_first = [None; 3];
        let mut bounds_for = |first: usize| {
            *per_first[first].get_or_insert_with(|| {
                let error = |r| {
                    let (a, b, c, d) = arrays;
                    sample_direction_error(a, b, c, d, first, (u1, u2), r)
                };
                let (exact, ieee_bound) = error(IEEE_ROUNDOFF);
                let (_, vulkan_bound) = error(twinpath_tests::device_class::VULKAN_ROUNDOFF);
                (exact, ieee_bound, vulkan_bound)
            })
        };
        tested += 1;
        for model in 0..4 {
            use_model(model);
            let view = SphericalTriangle::view(v(x), v(p0), v(e1), v(e2));
            let first =
                vertex_taken_as_a(view.directions().map(back), back(view.sampling_order()[0]));
            let (exact, ieee_bound, vulkan_bound) = bounds_for(first);
            if model == 1 {
                bounds.push(vulkan_bound.max_element() / f32::EPSILON as f64);
            }
            let got = back(view.sample_real(f(u1), f(u2))).as_dvec3();
            let bound = if model == 0 { ieee_bound } else { vulkan_bound };
            let off = (got - exact).abs();
            let ratio = |b: glam::DVec3| (off / b.max(glam::DVec3::splat(1e-300))).max_element();
            worst[model] = worst[model].max(ratio(bound));
            of_ieee[model] = of_ieee[model].max(ratio(ieee_bound));
        }
    }
    set_model(Model::VULKAN);
    bounds.sort_by(f64::total_cmp);
    let at = |f: f64| bounds[((bounds.len() - 1) as f64 * f) as usize];
    println!("sampled directions against the exact ones ({tested} cases), of their bound: IEEE, Vulkan, worst up, worst down {worst:.3?}; of IEEE's bound {of_ieee:.3?}; Vulkan bounds, median {:.0} eps, 99th percentile {:.0}, largest {:.0}", at(0.5), at(0.99), at(1.0));
    assert!(tested > cases() / 10, "{tested} cases");
    assert!(worst.iter().all(|&w| w <= 1.0), "{worst:?}");
    // The wider bound is needed: the Vulkan models exceed the one derived for IEEE arithmetic.
    assert!(
        of_ieee[1..].iter().all(|&w| w > 1.0),
        "the Vulkan models stay within IEEE's bound: {of_ieee:?}"
    );
}

/// Which of a view's `directions` (0, 1 or 2 for p0, p1, p2) its `sampling_order` took as A,
/// `a`: one of them bit for bit (the order selects, it computes nothing).
fn vertex_taken_as_a(directions: [Vec3; 3], a: Vec3) -> usize {
    (0..3).find(|&i| directions[i] == a).unwrap()
}

/// Which vertex the sampler takes as A changes its roundings, not its distribution, and A at
/// the largest angle (`SphericalTriangle::sampling_order`) keeps the most digits: the kernel's
/// (`f32`) sampled directions are nearer the exact ones, at their worst, than with A always at
/// p0 (the order before), p1 or p2, or at the smallest or the middle angle; on receivers near
/// and away from the triangle's plane, at u1's extremes and between. Near the plane a triangle
/// has one wide and two thin corners, and with A at a thin one a rounding of the solid angle
/// moves C' far along the arc AC (docs/robustness.md).
#[test]
fn the_largest_angle_first_keeps_the_most_digits() {
    use kernel::real::V3;
    use twinpath_tests::spherical_triangle_error::sample_direction_exact;
    let mut g = SplitMix(43);
    let extremes = [2f32.powi(-24), 1e-4, 0.5, 1.0 - 1e-4, 1.0 - 2f32.powi(-24)];
    // Worst error per order: the kernel's, p0 first, p1 first, p2 first, the smallest angle
    // first, the middle angle first.
    let mut worst = [0f64; 6];
    let mut tested = 0;
    for k in 0..cases() {
        let (x, p0, e1, e2) = triangle_and_receiver(&mut g, k);
        let view = SphericalTriangle::<f32>::view(x.into(), p0.into(), e1.into(), e2.into());
        if !view.sampled() {
            continue;
        }
        tested += 1;
        let (u1, u2) = (
            if k % 3 == 0 {
                g.unit()
            } else {
                extremes[k / 3 % 5]
            },
            g.unit(),
        );
        let dirs = view.directions();
        let exact_dirs = dirs.map(|d| Vec3::from(d).as_dvec3());
        let opposite = |i: usize| exact_dirs[(i + 1) % 3].dot(exact_dirs[(i + 2) % 3]);
        // From the smallest angle to the largest: the opposite arc's dot from largest down.
        let mut by_angle = [0, 1, 2];
        by_angle.sort_by(|&i, &j| opposite(j).total_cmp(&opposite(i)));
        let chosen = vertex_taken_as_a(dirs.map(Vec3::from), view.sampling_order()[0].into());
        let arrays = (x.to_array(), p0.to_array(), e1.to_array(), e2.to_array());
        let error = |first: usize| {
            let order: [V3<f32>; 3] = [0, 1, 2].map(|i| dirs[(first + i) % 3]);
            let got = Vec3::from(view.sample_in_order(order, u1, u2)).as_dvec3();
            let (a, b, c, d) = arrays;
            let exact = sample_direction_exact(a, b, c, d, first, (u1, u2));
            (got - exact).abs().max_element()
        };
        let errors = [0, 1, 2].map(error);
        for (order, first) in [chosen, 0, 1, 2, by_angle[0], by_angle[1]]
            .into_iter()
            .enumerate()
        {
            worst[order] = worst[order].max(errors[first]);
        }
    }
    println!("sampled directions' worst error ({tested} cases) with A at: the largest angle (the kernel's), p0, p1, p2, the smallest angle, the middle angle {:?}", worst.map(|w| format!("{w:.2e}")));
    assert!(tested > cases() / 10, "{tested} cases");
    assert!(
        worst[1..].iter().all(|&w| worst[0] < w),
        "another order keeps more digits: {worst:?}"
    );
}

/// The bound `gpu_functions.rs` holds a non-IEEE device's triangle-light samples to
/// (`spherical_sample_apart`: the directions' bounds carried to the light's point, the solid
/// angle's), checked against the models: the point a model's sampled direction meets on the
/// triangle (`barycentrics_along`, then `triangle_point`, in `f32`) is within it of the
/// CPU's point, and the model's solid angle within it of the CPU's, wherever both take the
/// same vertex as A (records where a tie may let them differ are counted, and rare).
#[test]
fn light_points_are_within_the_carried_bound_under_every_model() {
    use kernel::geometry::triangle_point;
    use kernel::spherical_triangle::barycentrics_along;
    use twinpath_tests::spherical_triangle_error::spherical_sample_apart;
    let mut g = SplitMix(47);
    twinpath_tests::vulkan_arithmetic::seed(47);
    let extremes = [2f32.powi(-24), 1e-4, 0.5, 1.0 - 1e-4, 1.0 - 2f32.powi(-24)];
    let (mut worst_point, mut worst_omega) = ([0f64; 3], [0f64; 3]);
    let (mut tested, mut ties) = (0, 0);
    for k in 0..cases() / 4 {
        let (x, p0, e1, e2) = triangle_and_receiver(&mut g, k);
        let cpu_view = SphericalTriangle::of(x, p0, e1, e2);
        if !cpu_view.sampled() {
            continue;
        }
        let (u1, u2) = if k % 3 == 0 {
            (g.unit(), g.unit())
        } else {
            (extremes[k / 3 % 5], extremes[k / 15 % 5])
        };
        let arrays = (x.to_array(), p0.to_array(), e1.to_array(), e2.to_array());
        let apart = spherical_sample_apart(arrays.0, arrays.1, arrays.2, arrays.3, (u1, u2));
        if apart.order_may_differ {
            ties += 1;
            continue;
        }
        tested += 1;
        let point = |d: Vec3| {
            let (u, v) = barycentrics_along(x, d, p0, e1, e2);
            triangle_point(p0, e1, e2, u, v).as_dvec3()
        };
        let cpu_point = point(cpu_view.sample(u1, u2));
        let cpu_omega = cpu_view.solid_angle() as f64;
        for model in 1..4 {
            use_model(model);
            let view = SphericalTriangle::view(v(x), v(p0), v(e1), v(e2));
            let off = (point(back(view.sample_real(f(u1), f(u2)))) - cpu_point).length();
            worst_point[model - 1] = worst_point[model - 1].max(off / apart.point);
            let omega = view.solid_angle_real().value as f64;
            let relative = (omega / cpu_omega - 1.0).abs();
            worst_omega[model - 1] =
                worst_omega[model - 1].max(relative / apart.solid_angle_relative);
        }
    }
    set_model(Model::VULKAN);
    println!("light points from a model's direction against the CPU's ({tested} cases, {ties} ties of A skipped), of the carried bound: Vulkan, worst up, worst down {worst_point:.3?}; solid angles {worst_omega:.3?}");
    assert!(tested > cases() / 40, "{tested} cases");
    assert!(ties * 1000 <= tested, "{ties} ties in {tested} cases");
    assert!(worst_point.iter().all(|&w| w <= 1.0), "{worst_point:?}");
    assert!(worst_omega.iter().all(|&w| w <= 1.0), "{worst_omega:?}");
}
