//! Whether a ray certainly moves away from a triangle's plane: its origin strictly on one side
//! and its direction not toward it, decided only where no rounding can change the answer. Such a
//! ray cannot meet the triangle at any t > 0, so a hit that a device's triangle test reports on
//! it is that test's rounding, not the surface (`docs/robustness.md`, "Hits a ray cannot
//! make"). The GPU's any-hit shaders reject such hits (`crate::shaders`); the tests hold the
//! function to its bounds under every arithmetic and on the device (`kernel::probe`).
//!
//! The triangle is the one the device holds: vertices p0, p1 = fl(p0 + edge1) and
//! p2 = fl(p0 + edge2), as the host writes them into the acceleration structure (in IEEE
//! arithmetic, round to nearest; `edge1` itself is fl(v1 - p0) of the scene's vertex v1), so
//! p1 - p0 is edge1 exactly or nearly ([`edges_exact`]). With N = (p1 - p0) x (p2 - p0), the
//! points o + t d meet the plane where (o - p0) . N + t d . N = 0, which has no root t > 0 where
//! s = (o - p0) . N is not 0 and d . N is 0 or of s's sign. Both are computed from the record's
//! edges in `f32` and decided only beyond a bound of their error under any conformant Vulkan
//! device's arithmetic (derived term by term in the doc comments of the constants below); the
//! test is the orientation predicate's static filter (Shewchuk, "Adaptive Precision
//! Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997, `orient3d` with bound
//! A), re-derived for rounding in either direction, fused operations, flushed denormals and the
//! vertices' own rounding.

use crate::real::{abs, select, Real, V3};
use spirv_std::glam::Vec3;

/// The rounding of s = (o - p0) . (edge1 x edge2), computed as the dot product of o - p0 with
/// the cross product, per eps of sum_j |o_j - p0_j| P_j, P_j = |e1_k e2_l| + |e1_l e2_k| (the
/// permanent of the cross product's component j). A unit roundoff of eps per operation (a
/// device may round toward zero; fusing a product into a sum only removes a rounding): the
/// difference o - p0 rounds once, each cross component twice relative to P_j (its two products,
/// then their difference), the product with it once, the dot product's two sums at most twice:
/// 6 roundings, first order (1 + eps)^6 - 1 < 6.0001 eps. One more eps covers the rounding of the
/// bound itself (computed toward zero in at most a dozen operations). The direction's
/// d . (edge1 x edge2) needs one rounding less (d is given) and takes the same count, so that
/// both bounds weigh the same vector.
pub const ROUNDING_EPS: f32 = 7.0;

/// The count that replaces [`ROUNDING_EPS`] where the host's vertices may not be the scene's
/// (`edges_exact` false). With p1 - p0 = edge1 + r1 and p2 - p0 = edge2 + r2, the device's
/// normal differs from edge1 x edge2 by r1 x edge2 + edge1 x r2 + r1 x r2, whose component j is
/// at most |r1_k| |e2_l| + |r1_l| |e2_k| + |e1_k| |r2_l| + |e1_l| |r2_k| + |r1_k| |r2_l| +
/// |r1_l| |r2_k|; since |r2| <= |edge2| per component, the last two are at most the first two,
/// so 2 (plus 0.5 for rounding this bound) times the first four bound it. Each r is at most
/// 1.53 eps |edge| ([`edges_exact`]), so the four are at most 3.06 eps P_j, and the device
/// triangle's side adds at most 2.5 x 3.06 = 7.65 eps P_j per |o_j - p0_j|: 7 + 7.65 < 15.
pub const INEXACT_ROUNDING_EPS: f32 = 15.0;

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
    let (weights, constant) = weights(p0, edge1, edge2);
    let side_bound = magnitudes(from_p0).dot(weights) + constant;
    let toward_bound = magnitudes(dir).dot(weights) + constant;
    let above = side.greater_than(side_bound) & toward.at_least(toward_bound);
    let below = side.less_than(-side_bound) & toward.at_most(-toward_bound);
    (above | below) != 0
}

/// The bounds' weights W and constant C: the error of f . (edge1 x edge2) for f = o - p0 or d,
/// against the device triangle's exact normal, is at most sum_j |f_j| W_j + C, with
/// W_j = count eps P_j + 3 tiny (count [`ROUNDING_EPS`], or [`INEXACT_ROUNDING_EPS`] where the
/// device's vertices may not be the scene's) and C = tiny (16 + sum_j P_j): what flushed
/// denormals may lose, each at most the smallest normal (tiny) times what multiplies it, is
/// 3 tiny per |f_j| (the cross product's three operations) and tiny (16 + sum_j P_j) (the
/// factor's products with the permanent, the last five operations alone, rounded up). One
/// count per triangle and one vector for both bounds keep the any-hit shader's live values few
/// (it runs inside a GPU's traversal loop).
#[inline]
fn weights<R: Real<Bits = u32>>(p0: V3<R>, edge1: V3<R>, edge2: V3<R>) -> (V3<R>, R) {
    let count = select(
        edges_exact(p0, edge1) & edges_exact(p0, edge2),
        R::splat(ROUNDING_EPS * f32::EPSILON),
        R::splat(INEXACT_ROUNDING_EPS * f32::EPSILON),
    );
    let (e1, e2) = (magnitudes(edge1), magnitudes(edge2));
    let permanent = V3::new(
        e1.y * e2.z + e1.z * e2.y,
        e1.z * e2.x + e1.x * e2.z,
        e1.x * e2.y + e1.y * e2.x,
    );
    let tiny = f32::MIN_POSITIVE;
    let constant = R::splat(tiny) * (R::splat(16.0) + permanent.element_sum());
    let flushed = R::splat(3.0 * tiny);
    let weights = permanent * count + V3::new(flushed, flushed, flushed);
    (weights, constant)
}

/// |v| per component.
#[inline]
fn magnitudes<R: Real>(v: V3<R>) -> V3<R> {
    V3::new(abs(v.x), abs(v.y), abs(v.z))
}

/// Whether the host's vertex fl(p0 + edge) is exactly p0 + edge, by a sufficient condition
/// (a lane mask). The edge is fl(v - p0) of a scene vertex v
/// (`flat_scene::triangle`). Where |edge| <= 0.49 |p0| in a component, v lies within a factor
/// of 2 of p0 there (the edge's rounding is eps / 2 of it), so v - p0 is exact (Sterbenz's
/// lemma) and fl(p0 + edge) = v. Elsewhere |p0| < 2.05 |edge|, and the vertex is off by at
/// most half an ULP of the sum (round to nearest), eps / 2 (|p0| + |edge|) < 1.53 eps |edge|,
/// which [`INEXACT_ROUNDING_EPS`] holds.
#[inline]
fn edges_exact<R: Real<Bits = u32>>(p0: V3<R>, edge: V3<R>) -> u32 {
    let one = |p: R, e: R| abs(e).at_most(R::splat(0.49) * abs(p));
    one(p0.x, edge.x) & one(p0.y, edge.y) & one(p0.z, edge.z)
}
