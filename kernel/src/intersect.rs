//! The ray/triangle and ray/sphere tests, written once over [`Real`]: on `f32` for the GPU's
//! sphere intersection shader and the one-ray code, on SIMD lanes for the CPU's BVH (one ray
//! against four primitives) and packets (sixteen rays against one primitive). A lane performs
//! the `f32` operations in the same order, with no fused multiply-add, so every instantiation
//! gives the `f32` result bit for bit (`tests/tests/properties.rs`). Both tests are branch-free:
//! a miss is a lane whose result is masked to -1.

use crate::real::{select, Real, V3};

/// Moller-Trumbore (Moller and Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection",
/// JGT 1997): the ray `origin + t dir` against the triangle `p0 + u edge1 + v edge2`. Returns
/// (t, u, v): t in (t_min, t_max) where the ray hits, else -1; u, v are meaningful where it
/// hits. A zero or non-finite determinant (a ray in the triangle's plane, a degenerate
/// triangle) and any NaN on the way are misses: every test is written so that NaN fails it.
#[inline(always)]
pub fn triangle<R: Real>(
    origin: V3<R>,
    dir: V3<R>,
    p0: V3<R>,
    edge1: V3<R>,
    edge2: V3<R>,
    t_min: R,
    t_max: R,
) -> (R, R, R) {
    let zero = R::splat(0.0);
    let one = R::splat(1.0);
    let pvec = dir.cross(edge2);
    let det = edge1.dot(pvec);
    let mut hit = det.not_equal(zero) & det.finite();
    let inv_det = one / det;
    let tvec = origin - p0;
    let u = tvec.dot(pvec) * inv_det;
    hit = hit & u.at_least(zero) & u.at_most(one);
    let qvec = tvec.cross(edge1);
    let v = dir.dot(qvec) * inv_det;
    hit = hit & v.at_least(zero) & (u + v).at_most(one);
    let t = edge2.dot(qvec) * inv_det;
    hit = hit & t.greater_than(t_min) & t.less_than(t_max) & t.finite();
    (select(hit, t, R::splat(-1.0)), u, v)
}

/// Closest root t in (t_min, t_max) of |o + t d - c|^2 = r^2, else -1. `dir` need not be unit
/// length. The discriminant is computed as a (r^2 - |f - (f.d / a) d|^2) with f = o - c, which
/// avoids the b^2 - 4ac cancellation, and the roots by the stable quadratic formula
/// q = -(b + sign(b) sqrt(disc)), t0 = q / a, t1 = c / q (Haines, Guenther, Akenine-Moller,
/// "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems, ch. 7, 2019).
/// A NaN centre or radius (a SIMD block's padding) never hits.
#[inline(always)]
pub fn sphere<R: Real>(
    origin: V3<R>,
    dir: V3<R>,
    center: V3<R>,
    radius: R,
    t_min: R,
    t_max: R,
) -> R {
    let zero = R::splat(0.0);
    let miss = R::splat(-1.0);
    let f = origin - center;
    let a = dir.dot(dir);
    let b = f.dot(dir); // half of the usual b
    let k = b / a;
    let perp = f - dir * k;
    let r2 = radius * radius;
    let disc = a * (r2 - perp.dot(perp));
    let real_roots = disc.at_least(zero) & a.greater_than(zero);
    let c = f.dot(f) - r2;
    let sq = disc.sqrt();
    let q = select(b.at_least(zero), -(b + sq), -(b - sq));
    let t_a = q / a;
    let t_b = select(q.not_equal(zero), c / q, t_a);
    let t_near = t_a.min(t_b);
    let t_far = t_a.max(t_b);
    let near_ok = t_near.greater_than(t_min) & t_near.less_than(t_max);
    let far_ok = t_far.greater_than(t_min) & t_far.less_than(t_max);
    let t = select(near_ok, t_near, select(far_ok, t_far, miss));
    select(real_roots, t, miss)
}
