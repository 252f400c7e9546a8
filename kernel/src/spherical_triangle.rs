//! Triangles as seen from a point: their solid angle, and directions sampled uniformly within
//! it (the spherical triangle they project to), for next-event estimation on triangle lights.
//! Angles are computed in turns by `turns::atan2_turns` and turned into sines and cosines by
//! `turns::cos_sin_turns`, so nothing a pdf depends on rests on the driver's `atan2` or `acos`.
//! Written over [`Real`] (the kernel's instance is `f32`), so that
//! `tests/tests/vulkan_precision.rs` can run the same arithmetic under the liberties a Vulkan
//! device may take.

use crate::real::{abs, select, Real, V3};
use crate::turns::{atan2_turns, cos_sin_turns};
use core::f32::consts::PI;
use spirv_std::glam::Vec3;

/// Smallest solid angle (sr) sampled as a spherical triangle: below it the triangle is sampled
/// by area, whose density in solid angle is then nearly constant anyway, and the spherical
/// construction would lose its digits (its 1 - cos of the triangle's arcs cancel). pbrt-v4's
/// threshold (`MinSphericalSampleArea`).
pub const MIN_SOLID_ANGLE: f32 = 3e-4;
/// Largest solid angle (sr) sampled as a spherical triangle: near a hemisphere (a receiver
/// almost on the triangle's plane inside it) the triangle's angles approach pi and the
/// construction is ill-conditioned. pbrt-v4's threshold (`MaxSphericalSampleArea`).
pub const MAX_SOLID_ANGLE: f32 = 6.22;

/// A triangle as seen from a receiver: the unit directions toward its vertices, their triple
/// product and the solid angle they span, computed once for the sampler's decision, the sample
/// and its density.
#[derive(Clone, Copy, Debug)]
pub struct SphericalTriangle<R: Real = f32> {
    /// Unit directions from the receiver to p0, p1, p2.
    dir: [V3<R>; 3],
    /// The triple product of the unit directions, A . (B x C) = (p0 - x) . ((p1 - x) x (p2 - x))
    /// over the three distances, computed as A . (edge1 x edge2) / (|p1 - x| |p2 - x|): the
    /// identity (p0 - x) . ((p1 - x) x (p2 - x)) = (p0 - x) . (edge1 x edge2) leaves no nearly
    /// parallel vectors to cancel (the first form loses the digits of a distant triangle), and
    /// dividing before the dot product keeps every intermediate below f32's range at the
    /// scene's largest coordinates (1e15: a product of three lengths would overflow).
    volume: R,
    /// The solid angle divided by 2 pi (an angle in turns, as `atan2_turns` gives), by Van
    /// Oosterom and Strackee's formula (1983, "The Solid Angle of a Plane Triangle", IEEE Trans.
    /// Biomed. Eng. 30(2)): with a, b, c the vectors to the vertices,
    /// tan(omega / 2) = |a . (b x c)| / (|a||b||c| + (a . b)|c| + (a . c)|b| + (b . c)|a|), here
    /// divided through by |a||b||c|. It keeps its relative precision for small and distant
    /// triangles, where Girard's alpha + beta + gamma - pi cancels.
    omega_turns: R,
}

impl<R: Real> SphericalTriangle<R> {
    /// The triangle p0, p0 + `edge1`, p0 + `edge2` seen from `x`, in any [`Real`].
    #[inline]
    pub fn view(x: V3<R>, p0: V3<R>, edge1: V3<R>, edge2: V3<R>) -> Self {
        let a = p0 - x;
        let b = a + edge1;
        let c = a + edge2;
        let len = [a.length(), b.length(), c.length()];
        let dir = [a / len[0], b / len[1], c / len[2]];
        let volume = dir[0].dot(edge1.cross(edge2) / (len[1] * len[2]));
        let [a, b, c] = dir;
        let one = R::splat(1.0);
        Self {
            dir,
            volume,
            omega_turns: R::splat(2.0)
                * atan2_turns(abs(volume), one + a.dot(b) + b.dot(c) + c.dot(a)),
        }
    }

    /// [`Self::solid_angle`] in any [`Real`].
    #[inline]
    pub fn solid_angle_real(&self) -> R {
        R::splat(2.0 * PI) * self.omega_turns
    }
}

impl<R: Real> SphericalTriangle<R> {
    /// The unit directions to the vertices in the order the sampler names them A, B, C: the
    /// view's p0, p1, p2 rotated cyclically (which keeps the triple product) so that A is at
    /// the spherical triangle's largest angle. That angle lies opposite the longest arc (in a
    /// spherical triangle the larger side faces the larger angle), so A is the vertex whose two
    /// neighbours have the smallest dot product; ties keep the earlier order.
    ///
    /// Why: Arvo's construction keeps the angle at A and sweeps C' along the arc AC, so a
    /// rounding of the solid angle moves C' by that rounding over the rate at which the
    /// sub-triangle's area grows along the arc. Seen from near its plane a triangle has one
    /// angle near pi and two thin ones; with A at a thin corner that rate is small near u1 = 0
    /// or 1 and C' moves far, with A at the wide corner it is not (docs/robustness.md gives
    /// the measured errors of each choice).
    #[inline]
    pub fn sampling_order(&self) -> [V3<R>; 3] {
        let [a, b, c] = self.dir;
        let (ab, bc, ca) = (a.dot(b), b.dot(c), c.dot(a));
        let a_first = bc.at_most(ca) & bc.at_most(ab);
        let b_first = ca.at_most(ab);
        let rotated = |yes_a: V3<R>, yes_b: V3<R>, otherwise: V3<R>| {
            V3::select(a_first, yes_a, V3::select(b_first, yes_b, otherwise))
        };
        [rotated(a, b, c), rotated(b, c, a), rotated(c, a, b)]
    }
}

impl SphericalTriangle {
    /// The triangle p0, p0 + `edge1`, p0 + `edge2` seen from `x`.
    #[inline]
    pub fn of(x: Vec3, p0: Vec3, edge1: Vec3, edge2: Vec3) -> Self {
        Self::view(x.into(), p0.into(), edge1.into(), edge2.into())
    }

    /// The solid angle (steradians): 0 if the receiver lies in the triangle's plane or the
    /// triangle is degenerate.
    #[inline]
    pub fn solid_angle(&self) -> f32 {
        self.solid_angle_real()
    }

    /// Whether the triangle is sampled as a spherical triangle ([`Self::sample`], density
    /// 1 / [`Self::solid_angle`]): a solid angle within [`MIN_SOLID_ANGLE`] and
    /// [`MAX_SOLID_ANGLE`], and not seen edge-on ([`MIN_VOLUME_PER_SOLID_ANGLE`]).
    #[inline]
    pub fn sampled(&self) -> bool {
        let omega = self.solid_angle();
        uses_solid_angle(omega) && self.volume.abs() >= MIN_VOLUME_PER_SOLID_ANGLE * omega
    }
}

/// The solid angle (steradians) the triangle p0, p0 + `edge1`, p0 + `edge2` subtends at `x`
/// (0 if `x` lies in its plane or the triangle is degenerate).
#[inline]
pub fn solid_angle(x: Vec3, p0: Vec3, edge1: Vec3, edge2: Vec3) -> f32 {
    SphericalTriangle::of(x, p0, edge1, edge2).solid_angle()
}

/// The smallest triple product of the unit directions to the vertices, relative to the solid
/// angle, at which a triangle is sampled as a spherical triangle. Seen from (nearly) within its
/// own plane the three directions are (nearly) coplanar: the spherical triangle degenerates
/// into arcs of one great circle, its angles (and the construction's divisions by their sines)
/// lose every digit, and the solid angle itself is rounding noise (pi from a point on an edge
/// line); the area sampler is exact there. A small triangle seen at any angle has a triple
/// product of about twice its solid angle, so only such edge-on views fall back.
pub const MIN_VOLUME_PER_SOLID_ANGLE: f32 = 1e-3;

/// The solid angle (steradians) the triangle p0, p0 + `edge1`, p0 + `edge2` subtends at `x` if
/// it is to be sampled as a spherical triangle ([`SphericalTriangle::sampled`]), else 0.
#[inline]
pub fn sampled_solid_angle(x: Vec3, p0: Vec3, edge1: Vec3, edge2: Vec3) -> f32 {
    let t = SphericalTriangle::of(x, p0, edge1, edge2);
    if t.sampled() {
        t.solid_angle()
    } else {
        0.0
    }
}

/// Whether a triangle of solid angle `omega` (sr) is sampled as a spherical triangle.
/// (Not `RangeInclusive::contains`: its references made rust-gpu load through an invalid
/// pointer.)
#[inline]
#[allow(clippy::manual_range_contains)]
pub fn uses_solid_angle(omega: f32) -> bool {
    omega >= MIN_SOLID_ANGLE && omega <= MAX_SOLID_ANGLE
}

/// A direction uniformly distributed over the solid angle the triangle p0, p0 + `edge1`,
/// p0 + `edge2` subtends at `x`, from two uniform numbers (Arvo 1995, "Stratified Sampling of
/// Spherical Triangles", SIGGRAPH; pbrt-v4 `SampleSphericalTriangle` implements Arvo's
/// formula as he states it). The density is 1 / [`solid_angle`] of the same arguments; for a
/// triangle that subtends none (or that [`SphericalTriangle::sampled`] refuses) the direction is
/// meaningless, but finite or caught by [`barycentrics_along`].
///
/// # Derivation
/// Let A, B, C be the unit directions to the vertices, A at the largest angle
/// ([`SphericalTriangle::sampling_order`]), alpha the spherical triangle's angle at A and c
/// the arc AB (cos c = A . B). u1 chooses the area A' = u1 omega of a sub-triangle
/// A B C' with C' on the arc AC: uniform in area, as the whole is. Sharing A, the
/// sub-triangle keeps the angle alpha there, and Girard's theorem gives its other two angles
/// beta' + gamma' = pi + phi with phi = A' - alpha. Writing gamma' = pi + phi - beta' into the
/// cosine rule for angles, cos gamma' = -cos alpha cos beta' + sin alpha sin beta' cos c,
/// gives u cos beta' + v sin beta' = 0 with u = cos phi - cos alpha and
/// v = sin phi + sin alpha cos c, so (cos beta', sin beta') = k (v, -u) for some k != 0. The
/// same rule at B, cos beta' = -cos gamma' cos alpha + sin gamma' sin alpha cos b', solved for
/// the arc b' = AC' with those values (k cancels), is Arvo's
/// q = cos b' = ((v cos phi - u sin phi) cos alpha - v) / ((v sin phi + u cos phi) sin alpha).
///
/// As written it cancels catastrophically for thin or grazing spherical triangles (u is a
/// difference of nearly equal cosines when alpha and A' are small: docs/lights.md). With
/// s = sin(A'/2), psi = A'/2 - alpha and m = 1 - cos c, the sum-to-product identities give
/// u = -2 s sin psi, sin phi + sin alpha = 2 s cos psi, 1 - cos alpha cos phi = s^2 + sin^2 psi and
/// sin alpha sin phi + s^2 + sin^2 psi = 2 s^2, and with them (sin alpha cancels)
/// 1 - q = 2 s^2 (1 + cos c) / (2 s^2 - m sin alpha sin phi): a product and a quotient of
/// quantities without cancellation, so 1 - q and sin b' = sqrt((1 - q)(1 + q)) keep their
/// digits (m = |A - B|^2 / 2 exactly where A . B rounds to 1). C' lies at arc length b' from
/// A toward C. u2 then chooses the point on the arc from B to C' with
/// cos theta = 1 - u2 (1 - B . C') measured from B: Arvo shows this conditional choice makes
/// the joint density uniform (his section 3); 1 - B . C' is computed as |B - C'|^2 / 2.
#[inline]
pub fn sample(x: Vec3, p0: Vec3, edge1: Vec3, edge2: Vec3, u1: f32, u2: f32) -> Vec3 {
    SphericalTriangle::of(x, p0, edge1, edge2).sample(u1, u2)
}

impl SphericalTriangle {
    /// [`sample`] of the triangle this view holds: the unit direction of (u1, u2).
    #[inline]
    pub fn sample(&self, u1: f32, u2: f32) -> Vec3 {
        self.sample_real(u1, u2).into()
    }
}

impl<R: Real> SphericalTriangle<R> {
    /// [`Self::sample`] in any [`Real`].
    #[inline]
    pub fn sample_real(&self, u1: R, u2: R) -> V3<R> {
        self.sample_in_order(self.sampling_order(), u1, u2)
    }

    /// The unit directions from the receiver to p0, p1, p2.
    #[inline]
    pub fn directions(&self) -> [V3<R>; 3] {
        self.dir
    }

    /// [`Self::sample_real`] with the vertices taken as A, B, C in `order`, a cyclic rotation
    /// of [`Self::directions`]: every rotation samples the same distribution with different
    /// roundings (the sampler takes [`Self::sampling_order`]; `vulkan_precision.rs` compares
    /// them).
    #[inline]
    pub fn sample_in_order(&self, order: [V3<R>; 3], u1: R, u2: R) -> V3<R> {
        let k = R::splat;
        let omega_turns = self.omega_turns;
        let [a, b, c] = order;
        // The angle at A, between the planes of (A, B) and (A, C): the cross products' dot is
        // cos alpha |A x B| |A x C|, and the length of their cross product, |A . (B x C)|, the
        // sine's (the triple product of the unit directions).
        let cos_part = a.cross(b).dot(a.cross(c));
        let sin_part = abs(self.volume);
        let alpha_turns = atan2_turns(sin_part, cos_part);
        let sin_alpha = sin_part / (cos_part * cos_part + sin_part * sin_part).sqrt();

        let sub_area_turns = u1 * omega_turns;
        let (_, s) = cos_sin_turns(k(0.5) * sub_area_turns);
        let (_, sin_phi) = cos_sin_turns(sub_area_turns - alpha_turns);
        let chord_ab = a - b;
        let m = k(0.5) * chord_ab.dot(chord_ab);
        let two_s2 = k(2.0) * s * s;
        let one_minus_q = two_s2 * (k(2.0) - m) / (two_s2 - m * sin_alpha * sin_phi);
        // q in [-1, 1]; a degenerate 0 / 0 reads as C' = A.
        let one_minus_q = select(
            one_minus_q.greater_than(k(0.0)),
            one_minus_q.min(k(2.0)),
            k(0.0),
        );
        let c_prime = arc_toward(a, c, one_minus_q);

        let chord = b - c_prime;
        let one_minus_cos = u2 * (k(0.5) * chord.dot(chord));
        arc_toward(b, c_prime, one_minus_cos).normalize()
    }
}

/// The unit vector at angle theta from unit `from` toward `toward`, in their plane, for
/// `one_minus_cos` = 1 - cos(theta) in [0, 2]: the sine as sqrt((1 - cos)(1 + cos)), which
/// keeps its digits for small angles where sqrt(1 - cos^2) would cancel.
#[inline]
fn arc_toward<R: Real>(from: V3<R>, toward: V3<R>, one_minus_cos: R) -> V3<R> {
    let k = R::splat;
    let sin = (one_minus_cos * (k(2.0) - one_minus_cos))
        .max(k(0.0))
        .sqrt();
    from * (k(1.0) - one_minus_cos) + (toward - from * toward.dot(from)).normalize() * sin
}

/// The barycentric coordinates (u, v) of the point where the ray `x + t dir` meets the plane of
/// the triangle p0, p0 + edge1, p0 + edge2 (Moller and Trumbore 1997), moved onto the triangle:
/// negative coordinates become 0 and a sum above 1 is scaled to 1. For a direction sampled in
/// its spherical triangle the point lies inside up to rounding, which this keeps on it. A
/// direction parallel to the plane (or not finite) gives p0's (0, 0): the comparisons below
/// send NaN to 0 on both backends alike (`max` with a NaN has no defined result on the GPU).
#[inline]
pub fn barycentrics_along(x: Vec3, dir: Vec3, p0: Vec3, edge1: Vec3, edge2: Vec3) -> (f32, f32) {
    let pvec = dir.cross(edge2);
    let inv_det = 1.0 / edge1.dot(pvec);
    let tvec = x - p0;
    let u = tvec.dot(pvec) * inv_det;
    let v = dir.dot(tvec.cross(edge1)) * inv_det;
    let u = if u > 0.0 { u } else { 0.0 };
    let v = if v > 0.0 { v } else { 0.0 };
    let sum = u + v;
    if !(sum < f32::INFINITY) {
        (0.0, 0.0)
    } else if sum > 1.0 {
        (u / sum, v / sum)
    } else {
        (u, v)
    }
}
