//! Ray/primitive intersection, the geometry factor, and where a new ray starts.

use crate::intersect;
use crate::real::{self, abs, V3};
use crate::scene::Triangle;
#[cfg(target_arch = "spirv")]
use crate::Float;
use spirv_std::glam::{Vec2, Vec3};

/// Seed: `GeometryFactor(A, B)`. |(n_a . d)(n_b . d)| / (d . d)^2 with d = p_a - p_b: the
/// cosines at both ends over the squared distance, i.e. the Jacobian between the product of the
/// two areas and the projected solid angle (Veach's thesis, eq. 8.4). Zero for coincident points.
#[inline]
pub fn geometry_factor(p_a: Vec3, n_a: Vec3, p_b: Vec3, n_b: Vec3) -> f32 {
    let (p_a, n_a, p_b, n_b) = (V3::from(p_a), V3::from(n_a), V3::from(p_b), V3::from(n_b));
    geometry_factor_v3(p_a, n_a, p_b, n_b)
}

/// [`geometry_factor`] over any scalar [`real::Real`].
#[inline]
pub fn geometry_factor_v3<R: real::Real<Bits = u32>>(
    p_a: V3<R>,
    n_a: V3<R>,
    p_b: V3<R>,
    n_b: V3<R>,
) -> R {
    let zero = R::splat(0.0);
    let d = p_a - p_b;
    let d2 = d.dot(d);
    if d2.greater_than(zero) != 0 {
        let g = abs(n_a.dot(d) * n_b.dot(d)) / (d2 * d2);
        if g.finite() != 0 {
            g
        } else {
            zero
        }
    } else {
        zero
    }
}

/// Converts a density per unit area at light point `p_light` (unit normal `n_light`) into a
/// density per unit solid angle seen from `p`: pdf_A * |d|^2 / |cos theta_light| (pbrt-v4 4.2.3).
/// Only the light's cosine belongs here: the receiver's cosine stays in the integrand.
/// Returns 0 when the conversion is undefined (coincident points, grazing light).
#[inline]
pub fn area_to_solid_angle_pdf(pdf_area: f32, p: Vec3, p_light: Vec3, n_light: Vec3) -> f32 {
    let d = p_light - p;
    let d2 = d.dot(d);
    let cos_light = n_light.dot(d).abs() / d2.sqrt();
    let pdf = pdf_area * d2 / cos_light;
    if d2 > 0.0 && cos_light > 0.0 && pdf.is_finite() {
        pdf
    } else {
        0.0
    }
}

/// Closest root t in (t_min, t_max) of |o + t d - c|^2 = r^2, or a negative value for none:
/// [`intersect::sphere`] on one ray.
#[inline]
pub fn intersect_sphere(
    origin: Vec3,
    dir: Vec3,
    center: Vec3,
    radius: f32,
    t_min: f32,
    t_max: f32,
) -> f32 {
    intersect::sphere(
        origin.into(),
        dir.into(),
        center.into(),
        radius,
        t_min,
        t_max,
    )
}

/// Moves a point computed as o + t d onto the sphere's surface along the radius, removing most
/// of its rounding error (pbrt-v4 `Sphere::InteractionFromIntersection`).
#[inline]
pub fn reproject_to_sphere(p: Vec3, center: Vec3, radius: f32) -> Vec3 {
    reproject_to_sphere_v3(V3::from(p), V3::from(center), radius).into()
}

/// [`reproject_to_sphere`] over any scalar [`real::Real`] (the kernel's `f32`, or a test's model
/// of a device's arithmetic).
#[inline]
pub fn reproject_to_sphere_v3<R: real::Real<Bits = u32>>(
    p: V3<R>,
    center: V3<R>,
    radius: R,
) -> V3<R> {
    let v = p - center;
    let len = v.dot(v).sqrt();
    if len.greater_than(R::splat(0.0)) != 0 {
        center + v * (radius / len)
    } else {
        p
    }
}

/// A ray/triangle hit: distance and barycentric coordinates of p0 + u edge1 + v edge2.
#[derive(Clone, Copy, Debug)]
pub struct TriangleHit {
    /// Ray parameter, negative for a miss.
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

/// Ray/triangle intersection, two-sided, with the barycentric coordinates of the hit:
/// [`intersect::triangle`] on one ray (u = v = 0 for a miss). `t_min` must be at least 0
/// (a miss is t = -1).
#[inline]
pub fn intersect_triangle_uv(
    origin: Vec3,
    dir: Vec3,
    p0: Vec3,
    edge1: Vec3,
    edge2: Vec3,
    t_min: f32,
    t_max: f32,
) -> TriangleHit {
    let (t, u, v) = intersect::triangle(
        origin.into(),
        dir.into(),
        p0.into(),
        edge1.into(),
        edge2.into(),
        t_min,
        t_max,
    );
    if t >= 0.0 {
        TriangleHit { t, u, v }
    } else {
        TriangleHit {
            t: -1.0,
            u: 0.0,
            v: 0.0,
        }
    }
}

/// The barycentrics (and t) where the ray `origin + t dir`, t in (0, inf), meets triangle
/// record `tri`: [`intersect_triangle_uv`] of its corner and edges. The CPU's hit records and
/// its test of holes both ask it, as the GPU's hardware reports them.
#[inline]
pub fn triangle_record_uv(tri: &Triangle, origin: Vec3, dir: Vec3) -> TriangleHit {
    intersect_triangle_uv(
        origin,
        dir,
        Vec3::from(tri.p0),
        Vec3::from(tri.edge1),
        Vec3::from(tri.edge2),
        0.0,
        f32::INFINITY,
    )
}

/// [`intersect_triangle_uv`]'s distance only: t in (t_min, t_max) or a negative value.
#[inline]
pub fn intersect_triangle(
    origin: Vec3,
    dir: Vec3,
    p0: Vec3,
    edge1: Vec3,
    edge2: Vec3,
    t_min: f32,
    t_max: f32,
) -> f32 {
    intersect_triangle_uv(origin, dir, p0, edge1, edge2, t_min, t_max).t
}

/// The point of a triangle at barycentric (u, v): p0 + (u edge1 + v edge2). Computed this way
/// (pbrt-v4 does the same) a hit point lies on the triangle's plane up to the rounding of these
/// few operations, whatever the error of the ray parameter t; `origin + t dir` would carry t's
/// error off the plane, which grows with the distance travelled.
#[inline]
pub fn triangle_point(p0: Vec3, edge1: Vec3, edge2: Vec3, u: f32, v: f32) -> Vec3 {
    triangle_point_v3(V3::from(p0), V3::from(edge1), V3::from(edge2), u, v).into()
}

/// [`triangle_point`] over any [`real::Real`].
#[inline]
pub fn triangle_point_v3<R: real::Real>(
    p0: V3<R>,
    edge1: V3<R>,
    edge2: V3<R>,
    u: R,
    v: R,
) -> V3<R> {
    p0 + (edge1 * u + edge2 * v)
}

/// The barycentrics (u, v) of point `p` of the triangle's plane, p = p0 + u edge1 + v edge2,
/// by least squares on the edges' Gram matrix (0 for a degenerate triangle).
#[inline]
pub fn triangle_barycentrics(p0: Vec3, edge1: Vec3, edge2: Vec3, p: Vec3) -> Vec2 {
    let d = p - p0;
    let (a, b, c) = (edge1.dot(edge1), edge1.dot(edge2), edge2.dot(edge2));
    let (e, f) = (d.dot(edge1), d.dot(edge2));
    let det = a * c - b * b;
    if !(det > 0.0) {
        return Vec2::ZERO;
    }
    Vec2::new((c * e - b * f) / det, (a * f - b * e) / det)
}

/// Barycentric blend of the values `a`, `b`, `c` at p0, p1, p2, at barycentrics (u, v) of p1
/// and p2.
#[inline]
pub fn blend3(a: Vec3, b: Vec3, c: Vec3, bary: Vec2) -> Vec3 {
    blend3_v3(V3::from(a), V3::from(b), V3::from(c), (bary.x, bary.y)).into()
}

/// [`blend3`] over any [`real::Real`], in the same operations.
#[inline]
pub fn blend3_v3<R: real::Real>(a: V3<R>, b: V3<R>, c: V3<R>, (u, v): (R, R)) -> V3<R> {
    a * (R::splat(1.0) - u - v) + b * u + c * v
}

/// [`blend3`] of two-component values (texture coordinates).
#[inline]
pub fn blend2(a: Vec2, b: Vec2, c: Vec2, bary: Vec2) -> Vec2 {
    a * (1.0 - bary.x - bary.y) + b * bary.x + c * bary.y
}

/// Unit geometric normal of a triangle, (edge1 x edge2) normalised.
#[inline]
pub fn triangle_normal(edge1: Vec3, edge2: Vec3) -> Vec3 {
    triangle_normal_v3(V3::from(edge1), V3::from(edge2)).into()
}

/// [`triangle_normal`] over any [`real::Real`]: the cross product normalised as glam normalises
/// ([`V3::normalize`], so the `f32` instance is glam's bit for bit).
#[inline]
pub fn triangle_normal_v3<R: real::Real>(edge1: V3<R>, edge2: V3<R>) -> V3<R> {
    edge1.cross(edge2).normalize()
}

/// Bound on the rounding error of [`triangle_point`], in units of eps times the magnitudes of
/// its terms. Four roundings (two products, two sums) give, per component, to first order,
/// u |p0| plus 3 u times the edge terms |u e1| and |v e2|, with u the unit roundoff: eps / 2
/// under IEEE rounding to nearest, eps under a Vulkan device that may round toward zero (fusing
/// a product into its sum only removes a rounding). So 1 eps |p0| and 3 eps of the terms on any
/// conformant device; 8 leaves more than a factor of two (docs/robustness.md, "Under Vulkan's
/// arithmetic").
pub const TRIANGLE_ERROR_EPS: f32 = 8.0;
/// Bound on the rounding error of a point re-projected onto a sphere, c + v r / |v|, in units
/// of eps (|c| + r), per component. The component v_i r / |v| carries v_i's rounding (u), the
/// dot product's error halved by the root (1.5 u), the square root's, the division's and the
/// product's (u), and the sum with c_i one u of |c_i| + r: under IEEE (u = eps / 2, root and
/// quotient correctly rounded) 3.25 eps r + 0.5 eps |c|; under Vulkan (u = eps for a device
/// that rounds toward zero, sqrt as 1 / inversesqrt within 4.5 eps relative, a quotient within
/// 2.5 ULP) 11.5 eps r + 1 eps |c|, which the IEEE-sized 8 did not cover (with a bound of 3, a
/// tenth of a percent of rays leaving a sphere hit it again under a model of such a device).
/// 16 covers it with a factor of 1.4 to spare (docs/robustness.md, "Under Vulkan's arithmetic").
pub const SPHERE_ERROR_EPS: f32 = 16.0;

/// Largest absolute component of `v`, compared as glam's `max_element` compares (a plain
/// `>`, which compiles to one instruction; `f32::max`'s NaN handling costs five).
#[inline]
fn max_abs<R: real::Real<Bits = u32>>(v: V3<R>) -> R {
    let max = |a: R, b: R| if a.greater_than(b) != 0 { a } else { b };
    max(abs(v.x), max(abs(v.y), abs(v.z)))
}

/// Absolute error bound (per component) of [`triangle_point`]`(p0, edge1, edge2, u, v)` with
/// respect to the triangle's plane as the rest of the kernel sees it. The point's own rounding
/// is a few eps of |p0| and of the edge terms; but the plane of a sliver triangle (edges at
/// angle theta) is itself only known to about eps |edge| / sin(theta), since its normal comes
/// from the cross product of nearly parallel edges, so the edge terms carry 1 / sin(theta)
/// (found by the re-intersection tests: slivers with sin(theta) = 0.002 self-intersected).
/// 1 / sin(theta) is capped at f32::MAX: for a denormal sin(theta) it overflows to infinity,
/// and a hit at u = v = 0 then computed 0 x inf = NaN (found by `properties.rs`). The bound
/// also holds the rounding of the triangle test a GPU runs ([`triangle_watertight_error_v3`]),
/// so that it sizes the offset of rays leaving the point on either backend.
#[inline]
pub fn triangle_point_error(p0: Vec3, edge1: Vec3, edge2: Vec3, u: f32, v: f32) -> f32 {
    let shape = TriangleShape::of(edge1, edge2);
    triangle_point_error_conditioned(p0, edge1, edge2, u, v, &shape)
}

/// The factor of [`triangle_point_error`] that depends on the triangle's shape alone:
/// max(1, min(f32::MAX, 1 / sin(theta))), or 1 for a degenerate triangle. A renderer may
/// compute it once per triangle (the CPU backend does).
#[inline]
pub fn triangle_error_condition(edge1: Vec3, edge2: Vec3) -> f32 {
    triangle_error_condition_v3(V3::from(edge1), V3::from(edge2))
}

/// [`triangle_error_condition`] over any [`real::Real`].
#[inline]
pub fn triangle_error_condition_v3<R: real::Real>(edge1: V3<R>, edge2: V3<R>) -> R {
    let one = R::splat(1.0);
    let c = edge1.cross(edge2);
    let sin_theta = c.length() / (edge1.length() * edge2.length());
    let condition = real::select(
        sin_theta.greater_than(R::splat(0.0)),
        (one / sin_theta).min(R::splat(f32::MAX)),
        one,
    );
    condition.max(one)
}

/// What a triangle's hit records need that depends on its shape alone: its unit normal
/// ([`triangle_normal`]), its [`triangle_error_condition`], its
/// [`triangle_watertight_scale_v3`], its [`triangle_plane_weights_v3`] and its
/// [`triangle_grazing_offset_v3`]. They cost eight square roots and seven divisions, which a
/// renderer may compute once per triangle, as the CPU's BVH does. The `f32` [`ShapeFactors`]
/// computes them, so both are the same numbers bit for bit.
#[derive(Clone, Copy, Debug)]
pub struct TriangleShape {
    pub normal: Vec3,
    pub condition: f32,
    pub watertight_scale: f32,
    /// The plane weights P_j / |edge1 x edge2| ([`triangle_plane_weights_v3`]).
    pub weights: Vec3,
    /// The height that rounding to denormals may take ([`triangle_plane_weights_v3`]).
    pub floor: f32,
    /// What grazing rays add to the offset ([`triangle_grazing_offset_v3`]).
    pub grazing: f32,
}

impl TriangleShape {
    #[inline]
    pub fn of(edge1: Vec3, edge2: Vec3) -> Self {
        let factors = ShapeFactors::<f32>::of(V3::from(edge1), V3::from(edge2));
        Self {
            normal: factors.normal.into(),
            condition: factors.condition,
            watertight_scale: factors.watertight_scale,
            weights: factors.weights.into(),
            floor: factors.floor,
            grazing: factors.grazing,
        }
    }

    /// The shape's factors as [`triangle_offsets_v3`] reads them.
    #[inline]
    pub fn factors(&self) -> ShapeFactors<f32> {
        ShapeFactors {
            normal: V3::from(self.normal),
            condition: self.condition,
            watertight_scale: self.watertight_scale,
            weights: V3::from(self.weights),
            floor: self.floor,
            grazing: self.grazing,
        }
    }
}

/// A [`TriangleShape`] over any [`real::Real`]: the factors [`triangle_offsets_v3`] reads
/// besides the corner, the edges and the barycentrics (the tests build them under a model of
/// Vulkan's arithmetic with [`ShapeFactors::of`]).
#[derive(Clone, Copy)]
pub struct ShapeFactors<R> {
    pub normal: V3<R>,
    pub condition: R,
    pub watertight_scale: R,
    pub weights: V3<R>,
    pub floor: R,
    pub grazing: R,
}

impl<R: real::Real<Bits = u32>> ShapeFactors<R> {
    /// The factors of the triangle with edges `edge1`, `edge2`, computed in `R`
    /// ([`TriangleShape::of`] is the `f32` instance).
    #[inline]
    pub fn of(edge1: V3<R>, edge2: V3<R>) -> Self {
        let (weights, floor) = triangle_plane_weights_v3(edge1, edge2);
        let watertight_scale = triangle_watertight_scale_v3(edge1, edge2);
        Self {
            normal: triangle_normal_v3(edge1, edge2),
            condition: triangle_error_condition_v3(edge1, edge2),
            watertight_scale,
            weights,
            floor,
            grazing: triangle_grazing_offset_v3(edge1, edge2, watertight_scale),
        }
    }
}

/// [`triangle_point_error`] with the factors of the triangle's [`TriangleShape`] given.
#[inline]
pub fn triangle_point_error_conditioned(
    p0: Vec3,
    edge1: Vec3,
    edge2: Vec3,
    u: f32,
    v: f32,
    shape: &TriangleShape,
) -> f32 {
    let (p0, edge1, edge2) = (V3::from(p0), V3::from(edge1), V3::from(edge2));
    triangle_point_error_v3(
        p0,
        edge1,
        edge2,
        u,
        v,
        shape.condition,
        shape.watertight_scale,
    )
}

/// [`triangle_point_error_conditioned`] over any scalar [`real::Real`]: the point's rounding
/// and its plane's (8 eps of the terms, the edge terms times `condition`) plus
/// [`triangle_watertight_error_v3`] (`watertight_scale` its per-triangle factor), the rounding
/// of the triangle test a GPU runs, so that the offset clears both.
#[inline]
pub fn triangle_point_error_v3<R: real::Real<Bits = u32>>(
    p0: V3<R>,
    edge1: V3<R>,
    edge2: V3<R>,
    u: R,
    v: R,
    condition: R,
    watertight_scale: R,
) -> R {
    R::splat(TRIANGLE_ERROR_EPS * f32::EPSILON)
        * (max_abs(p0) + (max_abs(edge1 * u) + max_abs(edge2 * v)) * condition)
        + triangle_watertight_error_v3(edge1, edge2, u, v, watertight_scale)
}

/// The count of the plane weights' term of [`triangle_offsets_v3`], in eps: the hit point's
/// edge terms (3 roundings), the origin's (1), the Moller-Trumbore numerator the CPU signs
/// (6 roundings of u <= eps / 2 under IEEE), and the plane-side test's side bound
/// ([`crate::plane_side::INEXACT_ROUNDING_EPS`], 15, plus 7 for computing s itself), with the
/// rest spare for the origin's own distance from the point (at most 22 eps times the weights'
/// sum, below 4 x 10^-4 of the height on a well-conditioned triangle).
pub const PLANE_OFFSET_EPS: f32 = 32.0;

/// Largest sum of a triangle's plane weights for which [`triangle_offsets_v3`] gives the small
/// height: above it (a sliver whose edges meet at less than about half a degree) rays leave at
/// the bound of [`triangle_point_error`] along the normal, as they did before the weights.
pub const WELL_CONDITIONED_WEIGHTS: f32 = 128.0;

/// Largest [`TriangleShape::floor`] for which [`triangle_offsets_v3`] gives the small height
/// (2^-24; only a triangle whose |edge1 x edge2| is below about 2^-98 exceeds it).
pub const WELL_CONDITIONED_FLOOR: f32 = 5.960_464_5e-8;

/// The cosine between a continuation ray and the leaving side's normal below which the ray
/// starts at the grazing height too ([`continuation_origin`]). On a well-conditioned triangle
/// the plane-side test ([`crate::plane_side`]) is sure of the direction of every ray above it:
/// its direction bound is at most 15 eps sum_j |d_j| P_j plus denormal terms, and with
/// sum_j P_j / |N| <= [`WELL_CONDITIONED_WEIGHTS`] the exact d . N exceeds that bound, its own
/// rounding (7 eps) and the unit normal's (3 eps) for every cosine above
/// 25 x 128 eps = 3.8 x 10^-4 plus at most 2^-24; 2^-10 = 9.8 x 10^-4 leaves a factor of 2.
pub const GRAZING_COS: f32 = 1.0 / 1024.0;

/// A triangle's plane weights and floor: w_j = P_j / |N| with P_j = |e1_k e2_l| + |e1_l e2_k|
/// (the permanent of the cross product's component j) and N = edge1 x edge2, and
/// floor = 4 tiny (16 + sum_j P_j + 3 (|edge1|_1 + |edge2|_1)) / |N| with tiny the smallest
/// normal float. An origin o's height h above the plane sets the sign of (o - p0) . N, exactly
/// h |N|, and both the CPU's Moller-Trumbore numerator and the plane-side test round that
/// product by a few eps of sum_j |o_j - p0_j| P_j (plus what flushed denormals lose, which the
/// floor bounds): so a height of a few eps of sum_j |o_j - p0_j| w_j decides its sign. w_j >=
/// |n_j|, and w_j is 0 along an axis that both edges are normal to (a floor in z = 0 has
/// w = (0, 0, 1)): the weights carry a sliver's 1 / sin(theta) only along the axes where the
/// cross product can tilt. Each is capped at f32::MAX; a degenerate triangle, which no test
/// meets, gets weights 0 and the floor f32::MAX (so it is not well-conditioned).
#[inline]
pub fn triangle_plane_weights_v3<R: real::Real<Bits = u32>>(
    edge1: V3<R>,
    edge2: V3<R>,
) -> (V3<R>, R) {
    let area = edge1.cross(edge2).length();
    let (a, b) = (
        V3::new(abs(edge1.x), abs(edge1.y), abs(edge1.z)),
        V3::new(abs(edge2.x), abs(edge2.y), abs(edge2.z)),
    );
    let permanent = V3::new(
        a.y * b.z + a.z * b.y,
        a.z * b.x + a.x * b.z,
        a.x * b.y + a.y * b.x,
    );
    let big = R::splat(f32::MAX);
    let reach = R::splat(3.0) * (a.element_sum() + b.element_sum());
    let numerator =
        R::splat(4.0 * f32::MIN_POSITIVE) * (R::splat(16.0) + permanent.element_sum() + reach);
    let degenerate = area.greater_than(R::splat(0.0)) == 0;
    if degenerate {
        let zero = R::splat(0.0);
        return (V3::new(zero, zero, zero), big);
    }
    let weights = V3::new(
        (permanent.x / area).min(big),
        (permanent.y / area).min(big),
        (permanent.z / area).min(big),
    );
    (weights, (numerator / area).min(big))
}

/// The heights above a triangle's plane at which rays leaving its point at barycentrics
/// (`u`, `v`) start, as (offset, grazing offset): a ray starts `offset` along the leaving
/// side's unit normal, and a continuation ray or shadow segment within [`GRAZING_COS`] of the
/// plane `offset + grazing offset` ([`continuation_origin`], [`shadow_segment`];
/// docs/robustness.md, "The height a ray leaves at").
///
/// On a well-conditioned triangle (weights summing to at most [`WELL_CONDITIONED_WEIGHTS`],
/// floor at most [`WELL_CONDITIONED_FLOOR`]) the offset is the point's rounding along the
/// normal plus what decides the origin's side: [`TRIANGLE_ERROR_EPS`] eps of
/// sum_j |p0_j| |n_j| over the axes along which an edge is not 0 (along the others the point's
/// component is p0's exactly), plus [`PLANE_OFFSET_EPS`] eps of sum_j (|u e1_j| + |v e2_j|) w_j,
/// plus the floor. There the CPU's Moller-Trumbore test cannot meet the triangle again, and a
/// GPU's any-hit shader rejects every hit on it that the ray's direction is sure to leave
/// (above [`GRAZING_COS`]); the grazing offset, the watertight term
/// ([`triangle_watertight_error_v3`]), covers a device's own test for the rest. On a floor in
/// z = 0 the offset is the floor alone, where the point's bound is 8 eps of its coordinates.
///
/// Elsewhere (slivers, degenerate or denormal triangles) the offset is the bound of
/// [`triangle_point_error_v3`] times |n|_1, as for every triangle before the weights, and the
/// grazing offset the same.
///
/// Always inlined, as [`triangle_offsets_conditioned`] is: both hit records (plain and
/// instanced) call it, and the plain triangle's hit must not pay for a call the instanced one
/// adds (docs/instancing.md, "The plane height").
#[inline(always)]
pub fn triangle_offsets_v3<R: real::Real<Bits = u32>>(
    p0: V3<R>,
    edge1: V3<R>,
    edge2: V3<R>,
    u: R,
    v: R,
    factors: &ShapeFactors<R>,
) -> (R, R) {
    let ShapeFactors {
        normal,
        condition,
        watertight_scale,
        weights,
        floor,
        grazing,
    } = *factors;
    let well = weights
        .element_sum()
        .at_most(R::splat(WELL_CONDITIONED_WEIGHTS))
        & floor.at_most(R::splat(WELL_CONDITIONED_FLOOR));
    if well == 0 {
        let error = triangle_point_error_v3(p0, edge1, edge2, u, v, condition, watertight_scale);
        // |n|_1 <= sqrt(3) for a unit normal; 2 where the normal is not a number (edges whose
        // cross product overflows, beyond the scene's domain), so that the height is one.
        let l1 = normal_l1(normal);
        let l1 = real::select(l1.at_most(R::splat(2.0)), l1, R::splat(2.0));
        return (error * l1, grazing);
    }
    let zero = R::splat(0.0);
    let moved = |a: R, b: R| a.not_equal(zero) | b.not_equal(zero);
    let along = |p: R, n: R, a: R, b: R| real::select(moved(a, b), abs(p) * abs(n), zero);
    let corner = along(p0.x, normal.x, edge1.x, edge2.x)
        + along(p0.y, normal.y, edge1.y, edge2.y)
        + along(p0.z, normal.z, edge1.z, edge2.z);
    let (eu, ev) = (edge1 * u, edge2 * v);
    let edges = (abs(eu.x) + abs(ev.x)) * weights.x
        + (abs(eu.y) + abs(ev.y)) * weights.y
        + (abs(eu.z) + abs(ev.z)) * weights.z;
    let offset = R::splat(TRIANGLE_ERROR_EPS * f32::EPSILON) * corner
        + R::splat(PLANE_OFFSET_EPS * f32::EPSILON) * edges
        + floor;
    (offset.min(R::splat(f32::MAX)), grazing)
}

/// |n|_1, the factor that turns a per-component error bound into a height along unit `n`.
#[inline]
pub(crate) fn normal_l1<R: real::Real>(n: V3<R>) -> R {
    abs(n.x) + abs(n.y) + abs(n.z)
}

/// The rounding of a watertight triangle test, per eps of the product of a ray origin's three
/// distances to the vertices over |edge1 x edge2| (derived in docs/robustness.md,
/// "Needles under a watertight test"): each 2-D edge function is rounded by at most
/// 2 u |P_j| |P_k| (u <= eps on any conformant device), the sheared distances |P| are at most
/// sqrt(3) times the distances, and the three errors are weighed by the vertices' depths.
pub const WATERTIGHT_ERROR_EPS: f32 = 18.0;

/// How far off its triangle's plane (along the normal) a ray leaving the triangle at
/// barycentrics (`u`, `v`) must start so that a GPU's triangle test cannot meet it again:
/// [`WATERTIGHT_ERROR_EPS`] eps |p - p0| |p - p1| |p - p2| / |edge1 x edge2|, `scale` being the
/// triangle's [`triangle_watertight_scale_v3`]. A device decides a hit by three edge functions
/// in the plane normal to the ray (a watertight test, as lavapipe's; Woop, Benthin and Wald,
/// JCGT 2013) and interpolates the vertices' depths with them, so its t errs by their rounding
/// over the triangle's projected area; the ray's cosine cancels against the exact t of the plane
/// behind it, -h / cos. The term is the triangle's elongation: about eps times the longest edge
/// for a well-shaped triangle, but the ratio of its legs times that for a needle, whose angle at
/// p0 ([`triangle_error_condition`]) may be right. Every product is capped at f32::MAX, so the
/// result is never NaN.
#[inline]
pub fn triangle_watertight_error_v3<R: real::Real<Bits = u32>>(
    edge1: V3<R>,
    edge2: V3<R>,
    u: R,
    v: R,
    scale: R,
) -> R {
    let from_p0 = edge1 * u + edge2 * v;
    let big = R::splat(f32::MAX);
    let scaled = (from_p0.length() * scale).min(big);
    let scaled = (scaled * (from_p0 - edge1).length()).min(big);
    (scaled * (from_p0 - edge2).length()).min(big)
}

/// A triangle's factor of [`triangle_watertight_error_v3`]: WATERTIGHT_ERROR_EPS eps /
/// |edge1 x edge2|, capped at f32::MAX; 0 for a degenerate triangle, which no test meets.
#[inline]
pub fn triangle_watertight_scale_v3<R: real::Real<Bits = u32>>(edge1: V3<R>, edge2: V3<R>) -> R {
    let area = edge1.cross(edge2).length();
    real::select(
        area.greater_than(R::splat(0.0)),
        (R::splat(WATERTIGHT_ERROR_EPS * f32::EPSILON) / area).min(R::splat(f32::MAX)),
        R::splat(0.0),
    )
}

/// The count of the vertex moves' term of [`triangle_grazing_offset_v3`], in eps of the
/// longest edge: a watertight test's roundings other than its edge functions are exact tests
/// of vertices moved by at most 13.52 eps of their distances from the origin, which move the
/// plane under a point q by at most that times sum_i lambda_i(q) |p_i - q| <= the longest edge
/// (docs/robustness.md, "The vertex moves, counted").
pub const VERTEX_MOVE_EPS: f32 = 14.0;

/// The heights, in units of a triangle's longest edge E, within which its grazing offset
/// ([`triangle_grazing_offset_v3`]) is derived. A watertight test's rounding grows with the
/// product of the distances from the ray's origin to the vertices, and an origin h above a
/// point of the triangle is up to E + h from them: the offset counts them as (1 +
/// `GRAZING_DOMAIN`) E, which holds while the height the ray leaves at (the offset plus the
/// grazing offset) is at most `GRAZING_DOMAIN` E. Beyond it (a triangle tiny against the
/// rounding of its coordinates, or a needle narrower than about 10^-5 of its length) no height
/// is proven for grazing rays, and a larger one is worse: the height h must exceed the term at
/// distance E + h, which grows as its cube (docs/robustness.md, "Known limits").
pub const GRAZING_DOMAIN: f32 = 0.125;

/// What a ray that grazes a triangle (within [`GRAZING_COS`]) adds to the offset of
/// [`triangle_offsets_v3`]: the watertight term's largest value over the triangle
/// ([`triangle_watertight_error_bound`]) plus [`VERTEX_MOVE_EPS`] eps of the longest edge E,
/// both with the distances from the origin counted as (1 + [`GRAZING_DOMAIN`]) E. A grazing ray
/// is met, if at all, where its backward line crosses the triangle, h / cos from the point it
/// leaves, so the device's rounding there, not at the point, is what the height must clear:
/// anywhere on the triangle. `watertight_scale` is [`triangle_watertight_scale_v3`]; every
/// product is capped at f32::MAX.
#[inline]
pub fn triangle_grazing_offset_v3<R: real::Real<Bits = u32>>(
    edge1: V3<R>,
    edge2: V3<R>,
    watertight_scale: R,
) -> R {
    let big = R::splat(f32::MAX);
    let reach = longest_edge_v3(edge1, edge2) * R::splat(1.0 + GRAZING_DOMAIN);
    let watertight = watertight_bound_of(reach, watertight_scale);
    (watertight + R::splat(VERTEX_MOVE_EPS * f32::EPSILON) * reach).min(big)
}

/// `scale` E^3 for the longest edge E, each product capped at f32::MAX: the largest
/// [`triangle_watertight_error_v3`] over a triangle of factor `scale`
/// ([`triangle_watertight_error_bound`]).
#[inline]
fn watertight_bound_of<R: real::Real>(longest: R, scale: R) -> R {
    let big = R::splat(f32::MAX);
    let scaled = (longest * scale).min(big);
    ((scaled * longest).min(big) * longest).min(big)
}

/// A bound on [`triangle_point_error`] over every point of the triangle (a triangle light's
/// `scene::Light::point_error`): [`triangle_point_error`] at u = v = 1, whose rounding part
/// bounds every point's (its edge terms are the largest there), plus
/// [`triangle_watertight_error_bound`], which bounds every point's watertight part.
#[inline]
pub fn triangle_light_point_error(p0: Vec3, edge1: Vec3, edge2: Vec3) -> f32 {
    triangle_point_error(p0, edge1, edge2, 1.0, 1.0) + triangle_watertight_error_bound(edge1, edge2)
}

/// The largest [`triangle_watertight_error_v3`] over the whole triangle: every distance from a
/// point of it to a vertex is at most its longest edge E, so WATERTIGHT_ERROR_EPS eps
/// E^3 / |edge1 x edge2|.
#[inline]
pub fn triangle_watertight_error_bound(edge1: Vec3, edge2: Vec3) -> f32 {
    let scale = triangle_watertight_scale_v3(V3::from(edge1), V3::from(edge2));
    watertight_bound_of(longest_edge(edge1, edge2), scale)
}

/// The longest edge E of a triangle with edges `edge1` and `edge2` from its first vertex: the
/// length every grazing and watertight bound measures distances on the triangle by (no two of
/// its points are further apart).
#[inline]
pub fn longest_edge(edge1: Vec3, edge2: Vec3) -> f32 {
    longest_edge_v3(V3::from(edge1), V3::from(edge2))
}

/// [`longest_edge`] over any [`real::Real`].
#[inline]
pub fn longest_edge_v3<R: real::Real>(edge1: V3<R>, edge2: V3<R>) -> R {
    edge1
        .length()
        .max(edge2.length())
        .max((edge2 - edge1).length())
}

/// Absolute error bound of a point on a sphere (centre `center`, radius `radius`), re-projected
/// or sampled as c + r n.
#[inline]
pub fn sphere_point_error(center: Vec3, radius: f32) -> f32 {
    sphere_point_error_v3(V3::from(center), radius)
}

/// [`sphere_point_error`] over any scalar [`real::Real`].
#[inline]
pub fn sphere_point_error_v3<R: real::Real<Bits = u32>>(center: V3<R>, radius: R) -> R {
    R::splat(SPHERE_ERROR_EPS * f32::EPSILON) * (max_abs(center) + radius)
}

/// The origin for a ray leaving a surface at `p` toward the side of unit normal `n`, where `p`
/// is known to within `error` (absolute, per component): `p` moved along `n` until the box of
/// half-width `error` around it lies on the leaving side (distance error * |n|_1), then stepped
/// one more ULP per component away from the surface in integer arithmetic on the float bits
/// (the step of Wachter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
/// Ray Tracing Gems, ch. 6). W&B size the step as 256 ULPs of `p` with an absolute 2^-16 below
/// |p| < 1/32, which assumes a scene of size about 1: at 1e-4 the fallback is 7% of a Cornell
/// box, at 1e4 from the origin the 256 ULPs are 12% of it. Sizing the offset by the error bound
/// of how `p` was computed (as pbrt-v4's `OffsetRayOrigin` does) holds at every scale.
/// Rays then start at t = 0 with no epsilon of their own.
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3, error: f32) -> Vec3 {
    offset_ray_origin_v3(V3::from(p), V3::from(n), error).into()
}

/// [`offset_ray_origin`] over any scalar [`real::Real`].
#[inline]
pub fn offset_ray_origin_v3<R: real::Real<Bits = u32>>(p: V3<R>, n: V3<R>, error: R) -> V3<R> {
    lift_ray_origin_v3(p, n, error * normal_l1(n))
}

/// `p` moved `height` along unit normal `n`, then one ULP per component away from the surface
/// (the step of [`offset_ray_origin`]): the origin of a ray leaving a surface point whose
/// distance from the surface is known to within `height`. Rounding the move cannot take a
/// component back past `p` (rounding is monotonic), and the step leaves it at least half the
/// move's rounding beyond.
#[inline]
pub fn lift_ray_origin(p: Vec3, n: Vec3, height: f32) -> Vec3 {
    lift_ray_origin_v3(V3::from(p), V3::from(n), height).into()
}

/// [`lift_ray_origin`] over any scalar [`real::Real`].
#[inline]
pub fn lift_ray_origin_v3<R: real::Real<Bits = u32>>(p: V3<R>, n: V3<R>, height: R) -> V3<R> {
    let q = p + n * height;
    V3::new(
        step_away(q.x, n.x),
        step_away(q.y, n.y),
        step_away(q.z, n.z),
    )
}

/// The origin of a continuation ray along unit `dir` leaving a surface point `p` on the side
/// of unit normal `n_side`, whose hit gave the heights `offset` and `grazing_offset`
/// ([`triangle_offsets_v3`]; a sphere's and an instance's grazing offset is 0): lifted by
/// `offset` where dir . n_side >= [`GRAZING_COS`], else by both.
#[inline]
pub fn continuation_origin(
    p: Vec3,
    n_side: Vec3,
    dir: Vec3,
    offset: f32,
    grazing_offset: f32,
) -> Vec3 {
    continuation_origin_v3(
        V3::from(p),
        V3::from(n_side),
        V3::from(dir),
        offset,
        grazing_offset,
    )
    .into()
}

/// [`continuation_origin`] over any scalar [`real::Real`].
#[inline]
pub fn continuation_origin_v3<R: real::Real<Bits = u32>>(
    p: V3<R>,
    n_side: V3<R>,
    dir: V3<R>,
    offset: R,
    grazing_offset: R,
) -> V3<R> {
    let height = if grazes(dir.dot(n_side), R::splat(1.0)) {
        offset + grazing_offset
    } else {
        offset
    };
    lift_ray_origin_v3(p, n_side, height)
}

/// Whether a ray whose direction has component `along` along the leaving side's unit normal
/// and length `length` leaves within [`GRAZING_COS`] of the plane (or is not a number), where
/// rays start higher by the grazing offset: the one test of [`continuation_origin_v3`] and
/// [`origin_by_angle_v3`].
#[inline]
fn grazes<R: real::Real<Bits = u32>>(along: R, length: R) -> bool {
    along.at_least(R::splat(GRAZING_COS) * length) == 0
}

/// The one rule for where a ray leaving surface point `p` on the side of unit normal `n_side`
/// starts, given `leaving` (`p` lifted by its hit's offset, [`lift_ray_origin`]) and the
/// direction's component `along` `n_side` and its `length` (as a pair): `leaving` where
/// along >= [`GRAZING_COS`] length, else `p` lifted by `grazing_height` (the offset plus the
/// grazing offset, [`triangle_offsets_v3`]). Taking `leaving` made lets a vertex that sends a
/// light sample too lift once ([`continuation_origin_v3`] lifts once by the height it picks).
/// [`shadow_segment`] applies the rule to a segment whose end is formed after its origin.
#[inline]
pub fn origin_by_angle_v3<R: real::Real<Bits = u32>>(
    p: V3<R>,
    n_side: V3<R>,
    leaving: V3<R>,
    (along, length): (R, R),
    grazing_height: R,
) -> V3<R> {
    if grazes(along, length) {
        lift_ray_origin_v3(p, n_side, grazing_height)
    } else {
        leaving
    }
}

/// [`origin_by_angle_v3`] in `f32`.
#[inline]
pub fn origin_by_angle(
    p: Vec3,
    n_side: Vec3,
    leaving: Vec3,
    along_length: (f32, f32),
    grazing_height: f32,
) -> Vec3 {
    origin_by_angle_v3(
        V3::from(p),
        V3::from(n_side),
        V3::from(leaving),
        along_length,
        grazing_height,
    )
    .into()
}

/// A shadow segment leaving surface point `p` on the side of unit normal `n_side` toward the
/// light point `target` (unit normal `target_normal`, error bound `target_error`), as (from,
/// to): from `leaving` (`p` lifted by its hit's offset, [`lift_ray_origin`]), or where the
/// segment may graze the surface from `p` lifted by `grazing_height` (the offset plus the
/// grazing offset), to the [`shadow_ray_end`] of that origin. The rule of
/// [`continuation_origin`] for the segment as it is traced, decided before its end is formed:
/// the end is the target moved by its lift (`target_error` plus 16 eps of the distance L) and
/// shortened (which keeps the direction), so a segment whose target lies at a cosine of at
/// least 2 [`GRAZING_COS`] from `leaving`, with `target_error` at most [`GRAZING_COS`] L / 4,
/// leaves at a cosine of at least 1.5 / (1 + [`GRAZING_COS`] / 2) [`GRAZING_COS`] >=
/// [`GRAZING_COS`]; every other one starts at the grazing height. A hit whose grazing offset
/// is 0 passes `grazing_height` <= `offset` and always leaves from `leaving`.
#[inline]
pub fn shadow_segment(
    p: Vec3,
    n_side: Vec3,
    leaving: Vec3,
    (offset, grazing_height): (f32, f32),
    (target, target_normal, target_error): (Vec3, Vec3, f32),
) -> (Vec3, Vec3) {
    let (from, to) = shadow_segment_v3(
        V3::from(p),
        V3::from(n_side),
        V3::from(leaving),
        (offset, grazing_height),
        (V3::from(target), V3::from(target_normal), target_error),
    );
    (from.into(), to.into())
}

/// [`shadow_segment`] over any scalar [`real::Real`].
#[inline]
pub fn shadow_segment_v3<R: real::Real<Bits = u32>>(
    p: V3<R>,
    n_side: V3<R>,
    leaving: V3<R>,
    (offset, grazing_height): (R, R),
    (target, target_normal, target_error): (V3<R>, V3<R>, R),
) -> (V3<R>, V3<R>) {
    let to_target = target - leaving;
    let distance = to_target.length();
    let steep = to_target
        .dot(n_side)
        .at_least(R::splat(2.0 * GRAZING_COS) * distance)
        & target_error.at_most(R::splat(0.25 * GRAZING_COS) * distance);
    let from = if grazing_height.greater_than(offset) != 0 && steep == 0 {
        lift_ray_origin_v3(p, n_side, grazing_height)
    } else {
        leaving
    };
    (
        from,
        shadow_ray_end_v3(from, target, target_normal, target_error),
    )
}

/// [`triangle_offsets_v3`] of the triangle (`p0`, `edge1`, `edge2`) at (`u`, `v`), its shape
/// computed here ([`TriangleShape::of`]).
#[inline]
pub fn triangle_offsets(p0: Vec3, edge1: Vec3, edge2: Vec3, u: f32, v: f32) -> (f32, f32) {
    triangle_offsets_conditioned(p0, edge1, edge2, u, v, &TriangleShape::of(edge1, edge2))
}

/// [`triangle_offsets_v3`] with the factors of the triangle's [`TriangleShape`] given (as
/// [`triangle_point_error_conditioned`] takes them). Always inlined, for the reason
/// [`triangle_offsets_v3`] gives.
#[inline(always)]
pub fn triangle_offsets_conditioned(
    p0: Vec3,
    edge1: Vec3,
    edge2: Vec3,
    u: f32,
    v: f32,
    shape: &TriangleShape,
) -> (f32, f32) {
    triangle_offsets_v3(
        V3::from(p0),
        V3::from(edge1),
        V3::from(edge2),
        u,
        v,
        &shape.factors(),
    )
}

/// `x` moved one ULP in the direction of the sign of `dir` (unchanged for dir = 0), through the
/// integer representation of the float, as Wachter and Binder step. Below the smallest normal
/// float (zero or denormal) it goes to the smallest normal on `dir`'s side instead: a Vulkan
/// device may flush denormals to zero, which would undo a step that ends on one.
#[inline]
fn step_away<R: real::Real<Bits = u32>>(x: R, dir: R) -> R {
    let zero = R::splat(0.0);
    if dir.not_equal(zero) == 0 {
        return x;
    }
    // Decided on the bits: |x| from the exponent and mantissa, the side from the sign bit.
    let bits = x.to_bits();
    let magnitude = bits & 0x7fff_ffff;
    if magnitude >= 0x7f80_0000 {
        return x; // infinite or NaN
    }
    let toward_positive = dir.greater_than(zero) != 0;
    if magnitude < 0x0080_0000 {
        let smallest = R::splat(f32::MIN_POSITIVE);
        return if toward_positive { smallest } else { -smallest };
    }
    // Away from zero if x and dir have the same sign, toward zero otherwise.
    let positive = bits >> 31 == 0;
    R::from_bits(if positive == toward_positive {
        bits + 1
    } else {
        bits - 1
    })
}

/// Relative shortening of shadow rays: a ray/surface intersection's `t` is only known to a few
/// eps relative to the segment's length (found: points 1000 radii from a sphere light hit it at
/// t = 1 - 6e-8 without it), so the segment stops 32 eps of its length short.
pub const SHADOW_RAY_SHORTENING: f32 = 32.0 * f32::EPSILON;
/// How far off the light's surface the end of a shadow ray is lifted, in eps times the ray's
/// length: an intersector tells a nearly tangent ray from a touching one only to about eps
/// times the distance it comes from (found: grazing samples, cos = 0.001..0.01, from 100 to 4000
/// radii away, hit their light without it).
pub const SHADOW_RAY_LIFT_EPS: f32 = 16.0;

/// Where a shadow ray from `origin` toward light point `target` (unit normal `target_normal`,
/// facing the receiver, position known to within `target_error`) must stop so that the light
/// never occludes its own sample, at any scale, distance and angle: the target lifted off the
/// light's surface (as [`offset_ray_origin`]) by its own error bound plus
/// [`SHADOW_RAY_LIFT_EPS`] eps of the distance, then the segment shortened by the relative
/// [`SHADOW_RAY_SHORTENING`].
#[inline]
pub fn shadow_ray_end(origin: Vec3, target: Vec3, target_normal: Vec3, target_error: f32) -> Vec3 {
    let (origin, target, normal) = (V3::from(origin), V3::from(target), V3::from(target_normal));
    shadow_ray_end_v3(origin, target, normal, target_error).into()
}

/// [`shadow_ray_end`] over any scalar [`real::Real`].
#[inline]
pub fn shadow_ray_end_v3<R: real::Real<Bits = u32>>(
    origin: V3<R>,
    target: V3<R>,
    target_normal: V3<R>,
    target_error: R,
) -> V3<R> {
    let to_target = target - origin;
    let distance = to_target.dot(to_target).sqrt();
    let lift = target_error + R::splat(SHADOW_RAY_LIFT_EPS * f32::EPSILON) * distance;
    let end = offset_ray_origin_v3(target, target_normal, lift);
    end - (end - origin) * R::splat(SHADOW_RAY_SHORTENING)
}
