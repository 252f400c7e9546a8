//! Instances: a mesh stored once in object space and seen through an affine transform
//! ([`Instance`]). Here are the maps of points, directions, normals and rays between the two
//! spaces, and the rounding-error bound of a hit point carried into world space, which sizes
//! the offset of rays leaving it (`geometry::offset_ray_origin`).
//!
//! Every map is written out component by component in a fixed order (three products summed left
//! to right, then the translation), so both backends compute the same `f32`s.

use crate::geometry::{
    normal_l1, triangle_offsets_conditioned, triangle_point, triangle_point_error_conditioned,
    TriangleShape, GRAZING_COS, WELL_CONDITIONED_FLOOR, WELL_CONDITIONED_WEIGHTS,
};
use crate::real::{self, V3};
use crate::scene::Instance;
use spirv_std::glam::Vec3;

/// The linear part of the row-major 3 x 4 matrix `m` applied to `v`.
#[inline]
fn linear<R: real::Real>(m: &[f32; 12], v: V3<R>) -> V3<R> {
    let e = |i: usize| R::splat(m[i]);
    V3::new(
        e(0) * v.x + e(1) * v.y + e(2) * v.z,
        e(4) * v.x + e(5) * v.y + e(6) * v.z,
        e(8) * v.x + e(9) * v.y + e(10) * v.z,
    )
}

/// The transpose of `m`'s linear part applied to `v`.
#[inline]
fn linear_transposed<R: real::Real>(m: &[f32; 12], v: V3<R>) -> V3<R> {
    let e = |i: usize| R::splat(m[i]);
    V3::new(
        e(0) * v.x + e(4) * v.y + e(8) * v.z,
        e(1) * v.x + e(5) * v.y + e(9) * v.z,
        e(2) * v.x + e(6) * v.y + e(10) * v.z,
    )
}

/// `m` applied to point `p`: its linear part, then its translation.
#[inline]
fn affine<R: real::Real>(m: &[f32; 12], p: V3<R>) -> V3<R> {
    linear(m, p) + V3::new(R::splat(m[3]), R::splat(m[7]), R::splat(m[11]))
}

/// An `f32` at or above sqrt(3) (1.7320508...): the most a 3-vector's 2-norm exceeds its
/// infinity norm by, and a 3 x 3 matrix's 2-norm its infinity norm by.
pub const SQRT_3_ABOVE: f32 = 1.732_051;

/// The largest absolute translation component of `m` (a 3 x 4 row-major matrix).
#[inline]
pub fn translation_norm(m: &[f32; 12]) -> f32 {
    m[3].abs().max(m[7].abs()).max(m[11].abs())
}

/// Largest absolute component of `v`.
#[inline]
fn max_abs<R: real::Real>(v: V3<R>) -> R {
    real::abs(v.x).max(real::abs(v.y)).max(real::abs(v.z))
}

/// The world-space image of object-space point `p`.
#[inline]
pub fn point_to_world(instance: &Instance, p: Vec3) -> Vec3 {
    point_to_world_v3(instance, V3::from(p)).into()
}

/// [`point_to_world`] over any [`real::Real`] (the tests run the instance maps under a model
/// of Vulkan's arithmetic).
#[inline]
pub fn point_to_world_v3<R: real::Real>(instance: &Instance, p: V3<R>) -> V3<R> {
    affine(&instance.object_to_world, p)
}

/// The world-space image of object-space direction `v` (a tangent: it maps like an edge).
#[inline]
pub fn vector_to_world(instance: &Instance, v: Vec3) -> Vec3 {
    linear(&instance.object_to_world, V3::from(v)).into()
}

/// The world-space normal of a surface whose object-space normal is `n`: the inverse transpose
/// of the linear part, M^-T n = (world_to_object)^T n (PBR 4e, section 3.10.3), not
/// normalised. It points to the side of the surface `n` points to, mirroring or not.
#[inline]
pub fn normal_to_world(instance: &Instance, n: Vec3) -> Vec3 {
    normal_to_world_v3(instance, V3::from(n)).into()
}

/// [`normal_to_world`] over any [`real::Real`].
#[inline]
pub fn normal_to_world_v3<R: real::Real>(instance: &Instance, n: V3<R>) -> V3<R> {
    linear_transposed(&instance.world_to_object, n)
}

/// The object-space ray of world ray `origin + t dir`: origin and direction mapped by
/// `world_to_object` (the direction not normalised, so a hit's `t` is the same in both
/// spaces). The CPU's BVH traces instances this way; the GPU maps rays by its own inverse.
#[inline]
pub fn ray_to_object(instance: &Instance, origin: Vec3, dir: Vec3) -> (Vec3, Vec3) {
    let (o, d) = ray_to_object_v3(instance, V3::from(origin), V3::from(dir));
    (o.into(), d.into())
}

/// [`ray_to_object`] over any [`real::Real`].
#[inline]
pub fn ray_to_object_v3<R: real::Real>(
    instance: &Instance,
    origin: V3<R>,
    dir: V3<R>,
) -> (V3<R>, V3<R>) {
    (
        affine(&instance.world_to_object, origin),
        linear(&instance.world_to_object, dir),
    )
}

/// Bound on the transforms' rounding, in units of eps times the magnitudes of their terms: an
/// affine map rounds each component at most gamma(3) ~ 3 eps of the sum of its terms' magnitudes
/// (three products, three sums), and a stored inverse is within eps/2 of the exact one per
/// entry; a factor of four spare. The device's own inverse adds [`device_inverse_eps`].
pub const INSTANCE_ERROR_EPS: f32 = 16.0;

/// What a device's own inverse of `object_to_world` adds to the round trip's bound, in eps of
/// its magnitudes per unit of the condition number ||M|| ||W||. Vulkan takes only
/// `object_to_world` and does not say how the implementation inverts it: this is an assumption
/// about the device, not a proof. A backward-stable inversion's error is first order in
/// eps ||M|| ||W|| (Higham, "Accuracy and Stability of Numerical Algorithms", 2nd ed., ch. 14:
/// the inverse by Gaussian elimination with partial pivoting satisfies
/// |X^ - X| <= c_n u |X| |L^| |U^| |X^|), so no constant count of eps covers it at every
/// condition. Measured against an `f32` inverse by Gaussian elimination (lavapipe's kind) on
/// maps that stretch or scale space along turned axes by up to 10^4: at most 0.21 eps per unit
/// of condition beyond conditions of 10, and the constant 16 alone falls short
/// (`vulkan_precision.rs`, `the_round_trip_model_holds_a_device_that_inverts_in_f32`); 1 holds
/// that almost five times over. An inverse by the adjugate is not backward stable: what it
/// loses to the determinant is [`DEVICE_INVERSE_EPS_PER_DETERMINANT_CONDITION`]'s term.
pub const DEVICE_INVERSE_EPS_PER_CONDITION: f32 = 1.0;

/// What a device's own inverse of the instance's map adds to the round trip's bound
/// ([`world_point_error_v3`]), in eps of (||W|| |p_w| + |T_w|): [`DEVICE_INVERSE_EPS_PER_CONDITION`]
/// times the condition number, plus [`DEVICE_INVERSE_EPS_PER_DETERMINANT_CONDITION`] times
/// the determinant's condition (`Instance::determinant_condition`).
#[inline]
pub fn device_inverse_eps(instance: &Instance) -> f32 {
    DEVICE_INVERSE_EPS_PER_CONDITION * condition_number(instance)
        + DEVICE_INVERSE_EPS_PER_DETERMINANT_CONDITION * instance.determinant_condition
}

/// What a device that inverts by the adjugate over the determinant adds to the round trip's
/// bound, in eps of (||W|| |p_w| + |T_w|) per unit of the determinant's condition
/// H = perm(|A|) / |det A| (`Instance::determinant_condition`). RADV and ANV invert so, in their
/// acceleration-structure build shaders (GLSL's `inverse()`). The determinant, expanded along a
/// row as sum_k a_2k C_2k with each cofactor a 2 x 2 minor, is formed by at most six roundings
/// of at most eps (Vulkan allows rounding toward zero; a fused multiply-add only removes one),
/// each of a term bounded by perm(|A|): its relative error is at most 6 eps H to first order.
/// That error scales the whole computed inverse, so a point p_w maps to (1 + rho) X p_w with
/// |rho| <= 6 eps H plus the quotient's 2.5 ULP, and |X p_w| <= ||W|| |p_w| + |T_w| up to the
/// stored inverse's rounding: 8 covers it. H is about 1 under a rotation after or before a
/// scale along the axes, where the 2 x 2 minors do not cancel, and grows to about c^2 under a
/// scale along a turned axis, where the determinant's terms cancel: there an adjugate inverse
/// errs, at points the map does not stretch, by up to 47 times the bound without this term
/// (`vulkan_precision.rs`,
/// `the_round_trip_model_holds_a_device_that_inverts_in_f32`; docs/instancing.md).
pub const DEVICE_INVERSE_EPS_PER_DETERMINANT_CONDITION: f32 = 8.0;

/// The largest condition number ||M|| ||W|| of an instance at which the heights of rays leaving
/// its triangles are shown to hold a device's own inverse. The device's object direction is off
/// by about eps ||M|| ||W|| of it too, and a direction that grazes the object triangle (as one
/// refused by [`turns_directions_little`] may) can be turned toward the plane by that much and
/// meet it within the triangle, a drift of up to eps (||M|| ||W||)^2 of its size that no height
/// derived from rounding holds. Measured, not derived: against an `f32` inverse by Gaussian
/// elimination, on maps that stretch a triangle along its normal by up to 10^4, no ray was met
/// below a condition of 3,571, and against the adjugate under Vulkan's arithmetic (RADV's and
/// ANV's kind) without [`DEVICE_INVERSE_EPS_PER_DETERMINANT_CONDITION`]'s term, below 1,168
/// (`tests/tests/reintersection.rs`,
/// `rays_a_map_turns_toward_the_object_plane_start_at_the_grazing_height`; docs/instancing.md).
/// The loaders flatten placements beyond it into world space (`scene::instancing`), and the
/// grazing-domain check names the meshes of any instance beyond it (`scene::grazing_domain`).
pub const DEVICE_INVERSE_CONDITION_LIMIT: f32 = 1000.0;

/// The condition number ||M|| ||W|| of `instance`'s map, in infinity norms
/// (`Instance::forward_norm`, `inverse_norm`): what a device's own inverse's error and the
/// limit of what is shown of it ([`DEVICE_INVERSE_CONDITION_LIMIT`]) are measured against.
#[inline]
pub fn condition_number(instance: &Instance) -> f32 {
    instance.forward_norm * instance.inverse_norm
}

/// Absolute error bound (per component) of the world point `p_world` =
/// [`point_to_world`]`(p_object)`, where `p_object` is known to within `object_error`, as the
/// origin of a ray that will be mapped back into object space to meet this instance again:
/// 1. the object point's own error carried through the linear part, ||M|| e_o;
/// 2. the forward map's rounding, a few eps of ||M|| |p_o| + |T|;
/// 3. the round trip: a ray leaving from `p_world` is mapped back by an inverse (ours, or the
///    device's), which rounds its origin by a few eps of ||W|| |p_w| + |T_w| in object space,
///    and the device's inverse by [`device_inverse_eps`] eps of it more (a term in the
///    condition number ||M|| ||W|| and one in the determinant's condition), up to ||M|| times
///    that in world space. A ray leaving from beyond this bound along the
///    normal starts, once mapped back, on the side it leaves toward (pbrt-v4's
///    `Transform::operator()(Ray)` moves a mapped origin by its error for the same reason).
///
/// Norms are infinity norms (`Instance::forward_norm`, `inverse_norm`); `|.|` is the largest
/// absolute component. For a rigid transform at the origin this is about 16 eps of the point's
/// magnitude on top of the object-space bound; a badly conditioned map (||M|| ||W|| large)
/// widens it in proportion, as it widens the round trip's error.
#[inline]
pub fn world_point_error(
    instance: &Instance,
    p_object: Vec3,
    object_error: f32,
    p_world: Vec3,
) -> f32 {
    world_point_error_v3(
        instance,
        V3::from(p_object),
        object_error,
        V3::from(p_world),
    )
}

/// [`world_point_error`] over any [`real::Real`].
#[inline]
pub fn world_point_error_v3<R: real::Real>(
    instance: &Instance,
    p_object: V3<R>,
    object_error: R,
    p_world: V3<R>,
) -> R {
    let m = R::splat(instance.forward_norm);
    let w = R::splat(instance.inverse_norm);
    let eps = R::splat(INSTANCE_ERROR_EPS * f32::EPSILON);
    let carried = m * object_error * (R::splat(1.0) + eps);
    let forward = m * max_abs(p_object) + R::splat(translation_norm(&instance.object_to_world));
    let round_trip =
        m * (w * max_abs(p_world) + R::splat(translation_norm(&instance.world_to_object)));
    let device = R::splat(device_inverse_eps(instance) * f32::EPSILON);
    carried + eps * (forward + round_trip) + device * round_trip
}

/// The world height along an instance's unit world normal that is at least `object_height`
/// along its object triangle's exact normal n_o, where `normal_length` is the computed length of
/// [`normal_to_world_v3`] of the triangle's computed normal (whose plane weights sum to
/// `weight_sum`), which the world normal n_w is normalised from. A world move H n_w maps back,
/// by X, the exact inverse of the stored `object_to_world` (the map the device places the mesh
/// by), to H n_w . X^T n_o along n_o. The computed vector v is within `deviation` of X^T n_o
/// ([`normal_length_bounds`]), so v . X^T n_o >= |v|^2 - |v| `deviation` and
/// n_w . X^T n_o >= |v| - `deviation`, which the bound L_low of [`normal_length_bounds`] holds
/// with the length's rounding: H = (1 + 4 eps) `object_height` / L_low serves, the spare for
/// the division and the normalisation's rounding. This bounds the projection, not only the
/// length, so a computed normal turned off X^T n_o is paid for, not assumed away.
///
/// Where L_low is not positive (a map or a sliver whose computed world normal may be turned
/// past a right angle), no height along n_w is proven to move the point off the plane; the
/// height is then sqrt(3) ||M||_inf `object_height` (>= `object_height` / |X^T n_o|, as
/// 1 / |X^T n_o| <= ||M||_2), right where the normal is, and the host names such triangles
/// (`grazing_domain`, via [`carries_heights`]).
#[inline]
pub fn world_height_v3<R: real::Real>(
    instance: &Instance,
    normal_length: R,
    weight_sum: R,
    object_height: R,
) -> R {
    let eps = f32::EPSILON;
    let (low, _) = normal_length_bounds(instance, normal_length, weight_sum);
    let loose = R::splat(instance.forward_norm * (SQRT_3_ABOVE * (1.0 + 16.0 * eps)));
    let tight = R::splat(1.0 + 4.0 * eps) / low;
    let factor = real::select(low.greater_than(R::splat(0.0)), tight, loose);
    factor * object_height
}

/// Whether [`world_height_v3`] is proven for a triangle whose plane weights sum to
/// `weight_sum` and whose computed world normal had length `normal_length`: its lower bound
/// L_low of the normal's projection is positive.
#[inline]
pub fn carries_heights(instance: &Instance, normal_length: f32, weight_sum: f32) -> bool {
    normal_length_bounds(instance, normal_length, weight_sum).0 > 0.0
}

/// The height rays leaving an instanced triangle start at, along world normal `n_world`
/// (normalised from a vector of length `normal_length`, [`world_height_v3`]): the world point's
/// bound ([`world_point_error_v3`] of the object point, known to within its error, mapped to
/// `p_world`) times |n_world|_1, plus the object triangle's grazing offset
/// (`geometry::triangle_grazing_offset_v3`) carried to world space ([`world_height_v3`], which
/// reads the triangle's weight sum). It reads `object`'s point, error, grazing offset and weight
/// sum. Every ray lifts by the grazing offset, not only the grazing ones: a map turns
/// directions by up to its condition number ||M|| ||M^-1||, so a world direction at
/// `geometry::GRAZING_COS` or more from the world plane may graze the object triangle, where
/// the device tests it.
#[inline]
pub fn instanced_offset_v3<R: real::Real>(
    instance: &Instance,
    object: &ObjectLeaving<R>,
    (p_world, n_world, normal_length): (V3<R>, V3<R>, R),
) -> R {
    let error = world_point_error_v3(instance, object.point, object.error, p_world);
    error * normal_l1(n_world)
        + world_height_v3(instance, normal_length, object.weight_sum, object.grazing)
}

/// What the offsets of a ray leaving an instanced triangle read of the object triangle: the
/// object point and its per-component bound (`geometry::triangle_point_error_v3`, which
/// [`instanced_offset_v3`] carries), the object triangle's own offset and grazing offset at the
/// point (`geometry::triangle_offsets_v3`), its unit normal, and the sum of its plane weights
/// and its floor (`geometry::triangle_plane_weights_v3`).
#[derive(Clone, Copy)]
pub struct ObjectLeaving<R> {
    pub point: V3<R>,
    pub error: R,
    pub offset: R,
    pub grazing: R,
    pub normal: V3<R>,
    pub weight_sum: R,
    pub floor: R,
}

impl ObjectLeaving<f32> {
    /// What the offsets read of the triangle (`p0`, `edge1`, `edge2`, of shape `shape`) at
    /// barycentrics (`u`, `v`): the point, its bound and its heights as the hit record forms
    /// them (`hit::SurfaceHit::instanced_triangle`).
    #[inline]
    pub fn of_triangle(
        (p0, edge1, edge2): (Vec3, Vec3, Vec3),
        (u, v): (f32, f32),
        shape: &TriangleShape,
    ) -> Self {
        let (offset, grazing) = triangle_offsets_conditioned(p0, edge1, edge2, u, v, shape);
        Self {
            point: V3::from(triangle_point(p0, edge1, edge2, u, v)),
            error: triangle_point_error_conditioned(p0, edge1, edge2, u, v, shape),
            offset,
            grazing,
            normal: V3::from(shape.normal),
            weight_sum: shape.weights.element_sum(),
            floor: shape.floor,
        }
    }
}

/// A lower bound on |X^T n_o|, the length of the exact world normal of the object triangle's
/// exact unit normal n_o under X, the exact inverse of the stored `object_to_world` M (the map
/// the device places the mesh by), from `normal_length`, the computed length of
/// [`normal_to_world_v3`] of the computed normal of a triangle whose plane weights sum to
/// `weight_sum`; and the bound `deviation` on the Euclidean distance between that computed
/// vector and X^T n_o (m, w the infinity norms of M and W, the stored inverse; 2-norms are at
/// most sqrt(3) times them):
/// - W is the rounding of the inverse of the `f64` matrix M rounds from (whose own error, of
///   order 10^-16 m w, the spares hold): its rounding is eps / 2 |W| per entry, at most
///   sqrt(3) eps / 2 w on n_o; and that inverse differs from X by W dM W to first order, with
///   |dM| <= eps / 2 |M| per entry, which applied to n_o is W^T dM^T (X^T n_o): at most
///   1.5 eps m w |X^T n_o|, relative to the length itself;
/// - the computed normal: each component of edge1 x edge2 rounds by at most 2 eps of its
///   permanent P_j, so the cross product is within 2 eps |w_o|_1 of its length, and its
///   direction, normalised (3 eps more), within eps (4 |w_o|_1 + 3) of n_o, which W^T carries by
///   at most sqrt(3) w;
/// - the three products and two sums per component round by at most 3 eps of
///   sum_j |W_ji| |n_j|, whose vector is at most the Frobenius norm of W, 3 w: 9 eps w.
///
/// So `deviation` = eps w (16 + 7 |w_o|_1 + 2 m `normal_length`) holds them (the length for
/// |X^T n_o|, first order), and the length's own rounding (the dot product and the square
/// root) is within 4 eps of it.
#[inline]
fn normal_length_bounds<R: real::Real>(
    instance: &Instance,
    normal_length: R,
    weight_sum: R,
) -> (R, R) {
    let (m, w) = (instance.forward_norm, instance.inverse_norm);
    let eps = f32::EPSILON;
    let deviation = R::splat(16.0 * eps * w)
        + R::splat(7.0 * eps * w) * weight_sum
        + R::splat(2.0 * eps * w * m) * normal_length;
    let low = normal_length * R::splat(1.0 - 4.0 * eps) - deviation;
    (low, deviation)
}

/// Whether a ray leaving an instanced triangle at a world cosine of at least
/// `geometry::GRAZING_COS` (against the computed world normal, whose length was
/// `normal_length`) leaves the object triangle at a direction the plane-side test
/// (`plane_side`) is sure of, as a lane mask: then such a ray needs no grazing offset
/// ([`instanced_offsets_v3`]). Four conditions:
/// 1. The object triangle is well-conditioned (its weights sum to at most
///    `geometry::WELL_CONDITIONED_WEIGHTS`, its floor at most `WELL_CONDITIONED_FLOOR`), so that
///    its offset is the plane height of `geometry::triangle_offsets_v3`.
/// 2. The lower bound L of |X^T n_o| ([`normal_length_bounds`]) is positive.
/// 3. The computed world normal is within 2^-12 of the exact one in angle: 2 `deviation`
///    <= 2^-12 L. So a computed cosine of `GRAZING_COS` is an exact one of at least
///    3/4 `GRAZING_COS`, and the world normal's components are within 2^-12 of the exact ones.
/// 4. The object direction the plane-side test reads, X d mapped by the stored inverse (each
///    component within [`MAPPED_BACK_EPS`] eps w of it, which 16 eps w holds), has
///    X d . n_o >= c |X^T n_o| for a world cosine c, less sqrt(3) 16 eps w; the plane-side test
///    is sure of a direction d_o with d_o . n_o >= 25 eps |w_o|_1 |d_o|_inf plus its denormal
///    terms (`geometry::GRAZING_COS`'s derivation), with |d_o|_inf <= w (1 + 2^-12); those
///    terms are at most floor (1 + w) over |N|'s share. So 3/4 `GRAZING_COS` L >=
///    eps w (32 + 26 |w_o|_1) + floor (1 + w) suffices. On an unscaled instance of a
///    well-shaped triangle the right side is below 10^-5 and the left 7 x 10^-4.
#[inline]
pub fn turns_directions_little<R: real::Real<Bits = u32>>(
    instance: &Instance,
    object: &ObjectLeaving<R>,
    normal_length: R,
) -> u32 {
    let w = instance.inverse_norm;
    let (low, deviation) = normal_length_bounds(instance, normal_length, object.weight_sum);
    let well = object
        .weight_sum
        .at_most(R::splat(WELL_CONDITIONED_WEIGHTS))
        & object.floor.at_most(R::splat(WELL_CONDITIONED_FLOOR));
    let straight = (R::splat(2.0) * deviation).at_most(R::splat(1.0 / 4096.0) * low);
    let needed = R::splat(f32::EPSILON * w) * (R::splat(32.0) + R::splat(26.0) * object.weight_sum)
        + object.floor * R::splat(1.0 + w);
    let sure = needed.at_most(R::splat(0.75 * GRAZING_COS) * low);
    well & low.greater_than(R::splat(0.0)) & straight & sure
}

/// The height rays leaving an instanced triangle start at where the map turns directions
/// little ([`turns_directions_little`]) and the ray does not graze the world plane: the object
/// triangle's own offset h_o (`geometry::triangle_offsets_v3`, which decides the origin's side
/// for the CPU's test and the plane-side test) and the map back's rounding along n_o, carried
/// to world space by the lower bound L of |X^T n_o|, plus the world point's rounding along the
/// world normal:
/// H = (1 + 2^-8) ((h_o + r) / L + sum_i (|n_i| + 2^-10) 8 eps a_i), where
/// - r = [`MAPPED_BACK_EPS`] eps sum_i |n_o_i| (sum_j |W_ij| |p_w_j| + |T_w_i|): the origin
///   mapped back into object space by the stored inverse W (as both backends decide its side)
///   is within that per component i, of which n_o takes |n_o_i|;
/// - a_i = sum_j |M_ij| |p_o_j| + |T_i|: the world point is M p_o + T rounded by at most 4 eps
///   of a_i per component, and the stored inverse pairs with M up to eps / 2 of M's entries and
///   T's, which a move along n_o sees as a world move along the exact world normal (a world
///   vector f moves the object point by X f, whose component along n_o is |X^T n_o| times f's
///   along the exact world normal), and the world normal's components are within 2^-10 of the
///   computed ones (condition 3, with room for the lift's step, 2 eps of a_i along an axis
///   whose sign it may take wrong);
/// - (1 + 2^-8): what the origin's own distance from the point adds to the round trip's and the
///   plane-side test's rounding, at most 10^-3 of the height under conditions 3 and 4.
///
/// On the identity instance of a floor in y = 0 every a_i along y is 0, W's row along y reads
/// only the point's own y, and h_o is its floor: H is the floor's offset, as for the plain
/// floor, wherever the point lies (docs/robustness.md, "Instanced large triangles").
#[inline]
pub fn instanced_plane_height_v3<R: real::Real<Bits = u32>>(
    instance: &Instance,
    object: &ObjectLeaving<R>,
    (p_world, n_world, normal_length): (V3<R>, V3<R>, R),
) -> R {
    let (low, _) = normal_length_bounds(instance, normal_length, object.weight_sum);
    let eps = f32::EPSILON;
    let mapped = magnitude_rows(&instance.world_to_object, p_world);
    let n = object.normal;
    let round_trip = R::splat(MAPPED_BACK_EPS * eps)
        * (real::abs(n.x) * mapped.x + real::abs(n.y) * mapped.y + real::abs(n.z) * mapped.z);
    let placed = magnitude_rows(&instance.object_to_world, object.point);
    let turn = R::splat(1.0 / 1024.0);
    let point = (real::abs(n_world.x) + turn) * placed.x
        + (real::abs(n_world.y) + turn) * placed.y
        + (real::abs(n_world.z) + turn) * placed.z;
    R::splat(1.0 + 1.0 / 256.0) * ((object.offset + round_trip) / low + R::splat(8.0 * eps) * point)
}

/// The rounding of a point mapped back into object space by the stored inverse
/// ([`ray_to_object_v3`]), per eps of sum_j |W_ij| |p_j| + |T_i| in component i: the CPU maps
/// rays so, and the GPU's instanced any-hit shader maps the world ray so before the plane-side
/// test, so that the test decides the side of the same origin on both backends and not of the
/// device's own object ray, whose inverse Vulkan does not specify. Three products and three
/// sums, each rounded by at most one ULP (eps relative; a device may round toward zero, and a
/// fused multiply-add only removes a rounding): (1 + eps)^4 - 1 < 4.01 eps of the terms'
/// magnitudes; the stored inverse's entries are within eps / 2 of the inverse of the `f64`
/// matrix, whose pairing with M the world point's term of [`instanced_plane_height_v3`]
/// counts. 4.5 eps, doubled for the bound's own rounding and the origin's lift.
pub const MAPPED_BACK_EPS: f32 = 8.0;

/// Per row i of the 3 x 4 matrix `m`: sum_j |m_ij| |p_j| + |m_i3|, the magnitudes that the
/// affine map's rounding in component i is a multiple of.
#[inline]
fn magnitude_rows<R: real::Real>(m: &[f32; 12], p: V3<R>) -> V3<R> {
    let p = V3::new(real::abs(p.x), real::abs(p.y), real::abs(p.z));
    let row = |i: usize| {
        R::splat(m[i].abs()) * p.x
            + R::splat(m[i + 1].abs()) * p.y
            + R::splat(m[i + 2].abs()) * p.z
            + R::splat(m[i + 3].abs())
    };
    V3::new(row(0), row(4), row(8))
}

/// The heights rays leaving an instanced triangle start at, as (offset, grazing offset) like
/// `geometry::triangle_offsets_v3`'s: where the map turns directions little
/// ([`turns_directions_little`]), the offset is [`instanced_plane_height_v3`] (or the height of
/// [`instanced_offset_v3`] where that is lower) and the offset plus the grazing offset is at
/// least [`instanced_offset_v3`]'s height, which rays grazing the world plane need (the
/// device's own triangle test decides them); elsewhere every ray starts at
/// [`instanced_offset_v3`]'s height and the grazing offset is 0. The grazing offset carries
/// 4 eps of that height more, so that the sum's rounding cannot fall short of it.
#[inline]
pub fn instanced_offsets_v3<R: real::Real<Bits = u32>>(
    instance: &Instance,
    object: &ObjectLeaving<R>,
    world: (V3<R>, V3<R>, R),
) -> (R, R) {
    let every = instanced_offset_v3(instance, object, world);
    let plane = instanced_plane_height_v3(instance, object, world);
    let steady = turns_directions_little(instance, object, world.2) & plane.at_most(every);
    let offset = real::select(steady, plane, every);
    let grazing = real::select(
        steady,
        every - offset + R::splat(4.0 * f32::EPSILON) * every,
        R::splat(0.0),
    );
    (offset, grazing)
}
