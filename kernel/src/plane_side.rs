//! Whether a ray certainly moves away from a triangle's plane: its origin strictly on one side
//! and its direction not toward it, decided only where no rounding can change the answer. Such a
//! ray cannot meet the triangle at any t > 0, so a hit that a device's triangle test reports on
//! it is that test's rounding, not the surface (`docs/robustness.md`, "Hits a ray cannot
//! make"), which a tracer may reject. The GPU's tracer does not yet: a first version that did
//! cost the ray-generation shader too much (robustness.md); the tests hold the function to its
//! bounds under every arithmetic and on the device (`kernel::probe`).
//!
//! The triangle is the one the device holds: vertices p0, p1 = fl(p0 + edge1) and
//! p2 = fl(p0 + edge2), as the host writes them into the acceleration structure (in IEEE
//! arithmetic, round to nearest; `edge1` itself is fl(v1 - p0) of the scene's vertex v1), so
//! p1 - p0 is edge1 off by at most [`vertex_rounding`] per component. With N = (p1 - p0) x (p2 - p0), the points o + t d meet the plane where
//! (o - p0) . N + t d . N = 0, which has no root t > 0 where s = (o - p0) . N is not 0 and
//! d . N is 0 or of s's sign. Both are computed from the record's edges in `f32` and decided
//! only beyond a bound of their error under any conformant Vulkan device's arithmetic (derived
//! term by term in the doc comments of the constants below); the test is the orientation
//! predicate's static filter (Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast
//! Robust Geometric Predicates", 1997, `orient3d` with bound A), re-derived for rounding in
//! either direction, fused operations, flushed denormals and the vertices' own rounding.

use crate::real::{abs, select, Real, V3};
use spirv_std::glam::Vec3;

/// The rounding of s = (o - p0) . (edge1 x edge2), computed as the dot product of o - p0 with
/// the cross product, per eps of sum_j |o_j - p0_j| P_j, P_j = |e1_k e2_l| + |e1_l e2_k| (the
/// permanent of the cross product's component j). A unit roundoff of eps per operation (a
/// device may round toward zero; fusing a product into a sum only removes a rounding): the
/// difference o - p0 rounds once, each cross component twice relative to P_j (its two products,
/// then their difference), the product with it once, the dot product's two sums at most twice:
/// 6 roundings, first order (1 + eps)^6 - 1 < 6.0001 eps. One more eps covers the rounding of the
/// bound itself (computed toward zero in at most ten operations).
pub const SIDE_ROUNDING_EPS: f32 = 7.0;

/// The rounding of d . (edge1 x edge2), per eps of sum_j |d_j| P_j: as
/// [`SIDE_ROUNDING_EPS`] without the difference (d is given), 5 roundings, plus one for the bound.
pub const DIRECTION_ROUNDING_EPS: f32 = 6.0;

/// The weight of the vertices' rounding: with p1 - p0 = edge1 + r1 and p2 - p0 = edge2 + r2,
/// N - edge1 x edge2 = r1 x edge2 + edge1 x r2 + r1 x r2, whose component j is at most
/// |r1_k| |e2_l| + |r1_l| |e2_k| + |e1_k| |r2_l| + |e1_l| |r2_k| + |r1_k| |r2_l| + |r1_l| |r2_k|;
/// since |r2| <= |edge2| per component the last two are at most the first two, so 2 times the
/// sum of the first four bounds it, and 2.5 leaves room for rounding that bound.
pub const VERTEX_ROUNDING_FACTOR: f32 = 2.5;

/// Whether the ray `origin + t dir` certainly meets no point of the plane of the triangle
/// (`p0`, `edge1`, `edge2`, as `scene::Triangle` stores it) at t > 0: `origin` is on one side
/// beyond every rounding and `dir` does not point toward the plane beyond every rounding
/// (module doc). `false` where either is uncertain, degenerate, overflowing or NaN: the
/// hit then stands.
#[inline]
pub fn ray_leaves_triangle_plane(
    origin: Vec3,
    dir: Vec3,
    p0: Vec3,
    edge1: Vec3,
    edge2: Vec3,
) -> bool {
    ray_leaves_triangle_plane_v3(
        V3::from(origin),
        V3::from(dir),
        V3::from(p0),
        V3::from(edge1),
        V3::from(edge2),
    )
}

/// [`ray_leaves_triangle_plane`] over any scalar [`Real`].
#[inline]
pub fn ray_leaves_triangle_plane_v3<R: Real<Bits = u32>>(
    origin: V3<R>,
    dir: V3<R>,
    p0: V3<R>,
    edge1: V3<R>,
    edge2: V3<R>,
) -> bool {
    let from_p0 = origin - p0;
    let normal = edge1.cross(edge2);
    let side = from_p0.dot(normal);
    let toward = dir.dot(normal);
    // Both beyond bounds of their own sign are needed: a ray toward the plane (every hit not
    // made by rounding) is decided here, before the bounds are formed.
    let zero = R::splat(0.0);
    let one_sign = (side.greater_than(zero) & toward.greater_than(zero))
        | (side.less_than(zero) & toward.less_than(zero));
    if one_sign == 0 {
        return false;
    }
    let (e1, e2) = (magnitudes(edge1), magnitudes(edge2));
    let permanent = V3::new(
        e1.y * e2.z + e1.z * e2.y,
        e1.z * e2.x + e1.x * e2.z,
        e1.x * e2.y + e1.y * e2.x,
    );
    let r1 = vertex_rounding(p0, edge1);
    let r2 = vertex_rounding(p0, edge2);
    let vertices = V3::new(
        r1.y * e2.z + r1.z * e2.y + e1.y * r2.z + e1.z * r2.y,
        r1.z * e2.x + r1.x * e2.z + e1.z * r2.x + e1.x * r2.z,
        r1.x * e2.y + r1.y * e2.x + e1.x * r2.y + e1.y * r2.x,
    );
    let side_bound = bound(magnitudes(from_p0), permanent, vertices, SIDE_ROUNDING_EPS);
    let toward_bound = bound(magnitudes(dir), permanent, vertices, DIRECTION_ROUNDING_EPS);
    let above = side.greater_than(side_bound) & toward.at_least(toward_bound);
    let below = side.less_than(-side_bound) & toward.at_most(-toward_bound);
    (above | below) != 0
}

/// |v| per component.
#[inline]
fn magnitudes<R: Real>(v: V3<R>) -> V3<R> {
    V3::new(abs(v.x), abs(v.y), abs(v.z))
}

/// How far the host's vertex fl(p0 + edge) may lie from p0 + edge, per component. The edge is
/// fl(v - p0) of a scene vertex v (`flat_scene::triangle`). Where |edge| <= 0.49 |p0|, v lies
/// within a factor of 2 of p0 (the edge's rounding is eps / 2 of it), so v - p0 is exact
/// (Sterbenz's lemma) and fl(p0 + edge) = v: 0. Elsewhere min(eps / 2 (|p0| + |edge|), |edge|)
/// (round to nearest: half an ULP of the sum, and p0 is a float within |edge| of it), which is
/// then at most 1.53 eps |edge|.
#[inline]
fn vertex_rounding<R: Real<Bits = u32>>(p0: V3<R>, edge: V3<R>) -> V3<R> {
    let half = R::splat(0.5 * f32::EPSILON);
    let one = |p: R, e: R| {
        let (p, e) = (abs(p), abs(e));
        let exact = e.at_most(R::splat(0.49) * p);
        select(exact, R::splat(0.0), (half * (p + e)).min(e))
    };
    V3::new(one(p0.x, edge.x), one(p0.y, edge.y), one(p0.z, edge.z))
}

/// The error bound of a dot product of `factor` (its magnitudes) with the computed cross
/// product: `eps_count` eps of the permanent, [`VERTEX_ROUNDING_FACTOR`] times the vertices'
/// rounding, and what flushed denormals may lose (each at most the smallest normal, times what
/// multiplies it: the factor's components times the permanent, the cross product's three
/// operations times the factor, the last five operations alone, rounded up to 16).
#[inline]
fn bound<R: Real>(factor: V3<R>, permanent: V3<R>, vertices: V3<R>, eps_count: f32) -> R {
    let tiny = R::splat(f32::MIN_POSITIVE);
    let flushed =
        tiny * (R::splat(16.0) + R::splat(3.0) * factor.element_sum() + permanent.element_sum());
    R::splat(eps_count * f32::EPSILON) * factor.dot(permanent)
        + R::splat(VERTEX_ROUNDING_FACTOR) * factor.dot(vertices)
        + flushed
}
