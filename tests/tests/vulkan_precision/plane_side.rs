//! The plane-side test (`kernel::plane_side::ray_leaves_triangle_plane_v3`) under every
//! arithmetic: it never says a ray leaves a triangle's plane where the exact ray meets it, and
//! it says so for rays that start clearly off the plane, including every ray the offset starts
//! above a triangle whose plane is normal to an axis.
//!
//! The exact answer is that of the device's triangle (vertices p0, fl(p0 + edge1),
//! fl(p0 + edge2), as the host uploads them), computed in `f64` and kept only where its own
//! rounding (a few 2^-53 of the permanents) cannot decide otherwise; the cases it cannot decide
//! are counted, and are far below anything the `f32` test could be sure of.

use super::{use_model, v};
use glam::Vec3;
use kernel::plane_side::{ray_leaves_triangle_plane_v3, INEXACT_ROUNDING_EPS, ROUNDING_EPS};
use twinpath_tests::placements::Placements as Gen;
use twinpath_tests::plane_side::exact;
use twinpath_tests::vulkan_arithmetic::{seed, set_model, Model};
use twinpath_tests::SplitMix;

/// A triangle with its first vertex within 10^-6 to 10^-1 of its size of the coordinates'
/// origin and the others across it, whose edges fl(v - p0) are not exact, so that the host's
/// vertices fl(p0 + edge) are not the scene's: the case for the vertices' rounding term.
fn straddling(g: &mut Gen) -> (f32, (Vec3, Vec3, Vec3)) {
    let size = g.pow10(-3.0, 3.0);
    let p0 = g.dir() * size * g.pow10(-6.0, -1.0);
    let (v1, v2) = (g.dir() * size, g.dir() * size);
    (size, (p0, v1 - p0, v2 - p0))
}

/// A triangle, an origin near its plane and a direction: the triangle from the re-intersection
/// placements (random, axis-plane, tilted, sliver, needle, a needle's neighbour) or across the
/// coordinates' origin ([`straddling`]), the origin at a point of it moved
/// 10^-9 to 1 of its size along the normal (either side) and along the plane, or not at all (a
/// third: exactly the point, within rounding of the plane), the direction random, or within
/// 10^-6 to 10^-1 of the plane (grazing) a third of the time.
fn case(g: &mut Gen, k: usize) -> Option<(Vec3, Vec3, Vec3, Vec3, Vec3)> {
    let (size, (p0, e1, e2)) = match k % 4 {
        0 => straddling(g),
        k4 => {
            let c = match k4 {
                1 => g.triangle_case(k.is_multiple_of(2))?,
                2 => g.needle_case()?,
                _ => g.needle_neighbour_case()?,
            };
            (c.size, c.loaded()[(k / 4) % c.triangles.len()].1)
        }
    };
    let n = e1.cross(e2).normalize_or_zero();
    if n == Vec3::ZERO {
        return None;
    }
    let (u, w) = (g.unit(), g.unit());
    let (u, w) = if u + w > 1.0 {
        (1.0 - u, 1.0 - w)
    } else {
        (u, w)
    };
    let p = p0 + e1 * u + e2 * w;
    let side = if g.unit() < 0.5 { 1.0 } else { -1.0 };
    let o = if g.unit() < 1.0 / 3.0 {
        p
    } else {
        p + (n * side * g.pow10(-9.0, 0.0) + g.dir() * g.pow10(-9.0, 0.0)) * size
    };
    let d = if g.unit() < 1.0 / 3.0 {
        let t = n.cross(g.dir()).normalize_or(n.any_orthonormal_vector());
        (t + n * side * g.pow10(-6.0, -1.0)).normalize()
    } else {
        g.dir()
    };
    Some((o, d, p0, e1, e2))
}

/// Under IEEE arithmetic and under Vulkan's (at random and at its worst, both ways): no ray
/// the test lets leave meets the exact plane at t > 0; the computed quantities stay within
/// their first-order counts, and beyond the counts IEEE's unit roundoff would give only under
/// Vulkan's arithmetic; and the test is sure of most rays that leave.
#[test]
fn the_plane_side_test_never_rejects_a_ray_that_meets_the_plane() {
    let mut g = Gen(SplitMix(41));
    seed(42);
    let n = super::cases();
    let (mut tested, mut leaving, mut undecided) = (0, 0, 0);
    let (mut sure, mut wrong, mut sure_undecided) = ([0usize; 4], [0usize; 4], [0usize; 4]);
    let mut worst = [0f64; 4];
    for k in 0..n {
        let Some((o, d, p0, e1, e2)) = case(&mut g, k) else {
            continue;
        };
        let Some(x) = exact(o, d, p0, e1, e2) else {
            // Within f64's rounding of the plane (or of parallel to it): far inside the f32
            // test's bound, which must not be sure of these.
            undecided += 1;
            for (model, count) in sure_undecided.iter_mut().enumerate() {
                use_model(model);
                *count += ray_leaves_triangle_plane_v3(v(o), v(d), v(p0), v(e1), v(e2)) as usize;
            }
            continue;
        };
        tested += 1;
        let leaves_exactly = x.leaves();
        leaving += leaves_exactly as usize;
        for model in 0..4 {
            use_model(model);
            let leaves = ray_leaves_triangle_plane_v3(v(o), v(d), v(p0), v(e1), v(e2));
            sure[model] += leaves as usize;
            wrong[model] += (leaves && !leaves_exactly) as usize;
            // How far the computed side and direction came from the exact ones, per their
            // counts (the same sums the kernel forms, in Vk32).
            let a = v(o) - v(p0);
            let nn = v(e1).cross(v(e2));
            let (s, t) = (a.dot(nn).value as f64, v(d).dot(nn).value as f64);
            let ratio =
                ((s - x.side).abs() / x.side_count).max((t - x.toward).abs() / x.toward_count);
            worst[model] = worst[model].max(ratio);
        }
    }
    set_model(Model::VULKAN);
    println!(
        "plane side: {tested} rays decided in f64, {leaving} of them leaving ({undecided} not \
         decided, of which the test was sure of {sure_undecided:?}); sure they leave: {sure:?} \
         (IEEE, Vulkan random, worst up, worst down); wrongly: {wrong:?}; the computed side and \
         direction at most {worst:.3?} of their first-order counts (counts {ROUNDING_EPS} and \
         {INEXACT_ROUNDING_EPS})"
    );
    assert!(tested > n / 2, "{tested} of {n}");
    assert_eq!((wrong, sure_undecided), ([0; 4], [0; 4]));
    // Within their counts under every arithmetic; beyond half of them (the counts for IEEE's
    // unit roundoff, eps / 2) only under Vulkan's.
    for (k, w) in worst.iter().enumerate() {
        assert!(*w <= 1.0, "model {k}: {w:.3} of the count");
    }
    assert!(worst[0] <= 0.5, "IEEE: {:.3} of the count", worst[0]);
    assert!(
        worst[1..].iter().any(|&w| w > 0.5),
        "Vulkan: {worst:?} of the count"
    );
    // The test is sure of most rays that leave: every origin but a third is at least 10^-9
    // sizes off the plane.
    assert!(
        sure.iter().all(|&s| s > leaving / 2),
        "{sure:?} of {leaving}"
    );
}
