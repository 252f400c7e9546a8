//! Sampling routines: directions around an axis, points on spheres and triangles.

use crate::frame::orthonormal_basis_v3;
// `real::Real` by its path: imported, its f32 methods would clash with `Float`'s on the GPU.
use crate::real::{self, V3};
use crate::turns::cos_sin_turns;
#[cfg(target_arch = "spirv")]
use crate::Float;
use core::f32::consts::PI;
use spirv_std::glam::Vec3;

/// Seed: `SampleLobe(A, c, phi)`. The unit direction whose cosine with the unit axis `a` is `c`
/// (clamped to [-1, 1]) and whose azimuth around `a` is `phi`: `K = (s cos phi, s sin phi, c)`
/// with `s = sqrt(1 - c^2) = sqrt((1 - c)(1 + c))` (the product keeps its precision where |c|
/// nears 1), expressed in an orthonormal frame whose third axis is `a`. The frame is Duff et
/// al.'s (see [`crate::frame::orthonormal_basis`]), which stays accurate near -Z where the
/// seed special-cases the poles. The azimuth is [`cos_sin_turns`] of phi / (2 pi), not the
/// device's `sin` and `cos`, whose precision Vulkan leaves undefined.
#[inline]
pub fn sample_lobe(a: Vec3, c: f32, phi: f32) -> Vec3 {
    sample_lobe_v3(V3::from(a), c, phi).into()
}

/// [`sample_lobe`] for one axis or one per lane ([`real::Real`]).
#[inline]
pub fn sample_lobe_v3<R: real::Real>(a: V3<R>, c: R, phi: R) -> V3<R> {
    let one = R::splat(1.0);
    let c = c.max(-one).min(one);
    let s = ((one - c) * (one + c)).sqrt();
    let (cos_phi, sin_phi) = cos_sin_turns(phi * R::splat(0.5 / PI));
    lobe_direction_cs_v3(a, c, s, cos_phi, sin_phi)
}

/// The direction at cosine `c` and sine `s` from the axis `a`, azimuth (cos_phi, sin_phi) in
/// `a`'s orthonormal frame.
#[inline]
fn lobe_direction_cs_v3<R: real::Real>(a: V3<R>, c: R, s: R, cos_phi: R, sin_phi: R) -> V3<R> {
    let (t, b) = orthonormal_basis_v3(a);
    t * (s * cos_phi) + b * (s * sin_phi) + a * c
}

/// Cosine-weighted direction in the hemisphere around unit `n` from two uniform numbers
/// (cos(theta) = sqrt(u1), phi = 2 pi u2); its solid-angle pdf is [`pdf_cosine_hemisphere`].
///
/// The direction is never tangent: the uniform numbers are in the open interval (0, 1)
/// (`rng::u32_to_unit_f32`), so cos(theta) >= sqrt(2^-24) = 2^-12 and the pdf >= 7.8e-5.
#[inline]
pub fn sample_cosine_hemisphere(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    sample_cosine_hemisphere_v3(V3::from(n), u1, u2).into()
}

/// [`sample_cosine_hemisphere`] for one normal or one per lane ([`real::Real`]).
#[inline]
pub fn sample_cosine_hemisphere_v3<R: real::Real>(n: V3<R>, u1: R, u2: R) -> V3<R> {
    let (cos_phi, sin_phi) = cos_sin_turns(u2);
    // sin(theta) = sqrt(1 - u1), not sqrt(1 - cos^2): the latter cancels as u1 nears 1 (where
    // cos^2 carries a few eps, the root a square root of them: u1 = 1 - 2^-24 gave sin 0, the
    // normal itself, for 2^-12), while 1 - u1 is exact for u1 >= 1/2.
    let one = R::splat(1.0);
    lobe_direction_cs_v3(n, u1.sqrt(), (one - u1).sqrt(), cos_phi, sin_phi)
}

/// Solid-angle density of [`sample_cosine_hemisphere`]: max(0, n . w) / pi.
#[inline]
pub fn pdf_cosine_hemisphere(n: Vec3, w: Vec3) -> f32 {
    pdf_cosine_hemisphere_v3(V3::from(n), V3::from(w))
}

/// [`pdf_cosine_hemisphere`] over any scalar [`real::Real`], in the same operations.
#[inline]
pub fn pdf_cosine_hemisphere_v3<R: real::Real>(n: V3<R>, w: V3<R>) -> R {
    n.dot(w).max(R::splat(0.0)) * R::splat(1.0 / PI)
}

/// A point on a sphere and its outward unit normal.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub position: Vec3,
    pub normal: Vec3,
}

/// Seed: `SampleSphere(C, R)`. A point uniformly distributed over the sphere's area
/// (z = 2 u1 - 1, phi = 2 pi u2; Archimedes' hat-box theorem makes z uniform), with density
/// 1 / (4 pi R^2) per unit area. The radius of its circle of latitude is sqrt(1 - z^2) =
/// 2 sqrt(u1 (1 - u1)): the product keeps its precision toward the poles, where 1 - z^2 lost
/// z^2's rounding (z = 2 u1 - 1 and 1 - u1 are exact for u1 of the form (k + 1/2) 2^-23, `rng`).
#[inline]
pub fn sample_sphere(center: Vec3, radius: f32, u1: f32, u2: f32) -> SurfacePoint {
    let (position, normal) = sample_sphere_v3(V3::from(center), radius, u1, u2);
    SurfacePoint {
        position: position.into(),
        normal: normal.into(),
    }
}

/// [`sample_sphere`] over any [`real::Real`]: (position, normal).
#[inline]
pub fn sample_sphere_v3<R: real::Real>(center: V3<R>, radius: R, u1: R, u2: R) -> (V3<R>, V3<R>) {
    let (one, two) = (R::splat(1.0), R::splat(2.0));
    let z = two * u1 - one;
    let r = two * (u1 * (one - u1)).max(R::splat(0.0)).sqrt();
    let (cos_phi, sin_phi) = cos_sin_turns(u2);
    let normal = V3::new(r * cos_phi, r * sin_phi, z);
    (center + normal * radius, normal)
}

/// Area density of [`sample_sphere`]: 1 / (4 pi R^2).
#[inline]
pub fn pdf_sphere_area(radius: f32) -> f32 {
    1.0 / (4.0 * PI * radius * radius)
}

/// Veach's power heuristic with beta = 2 for two strategies with one sample each:
/// w_a = p_a^2 / (p_a^2 + p_b^2) (Veach's thesis, section 9.2.4), evaluated through the ratio of
/// the smaller pdf to the larger so that no square overflows (p_a = 6e37 gave NaN as inf / inf).
/// Zero when both pdfs are zero.
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    if pdf_a >= pdf_b {
        if pdf_a > 0.0 {
            let r = pdf_b / pdf_a;
            1.0 / (1.0 + r * r)
        } else {
            0.0
        }
    } else {
        let r = pdf_a / pdf_b;
        let r2 = r * r;
        r2 / (1.0 + r2)
    }
}

/// A direction toward a sphere light, the point it reaches, and the solid-angle density.
#[derive(Clone, Copy, Debug)]
pub struct ConeSample {
    pub point: SurfacePoint,
    /// Density per unit solid angle seen from the reference point.
    pub pdf_solid_angle: f32,
}

/// The cone a sphere of `radius` subtends from a point at squared distance `dist2` from its
/// centre: sin^2(theta_max) = r^2 / d^2 (at most 1), cos^2(theta_max) = 1 - sin^2(theta_max) and
/// cos(theta_max). Every quantity of the cone sampler is formed from these without a further
/// difference of nearly equal numbers.
#[inline]
pub fn cone_extent<R: real::Real>(radius: R, dist2: R) -> ConeExtent<R> {
    let one = R::splat(1.0);
    let sin2_max = (radius * radius / dist2).min(one);
    let cos2_max = one - sin2_max;
    ConeExtent {
        sin2_max,
        cos2_max,
        cos_max: cos2_max.sqrt(),
    }
}

/// [`cone_extent`]'s squared sine, squared cosine and cosine of the cone's half-angle.
#[derive(Clone, Copy, Debug)]
pub struct ConeExtent<R> {
    pub sin2_max: R,
    pub cos2_max: R,
    pub cos_max: R,
}

impl<R: real::Real> ConeExtent<R> {
    /// 1 - cos(theta_max) as sin^2 / (1 + cos): the same value as 1 - cos without its
    /// cancellation, accurate for cones of any size (pbrt-v4 switches to a Taylor expansion
    /// below 1.5 degrees instead; this form needs no branch).
    #[inline]
    pub fn one_minus_cos(self) -> R {
        self.sin2_max / (R::splat(1.0) + self.cos_max)
    }
}

/// 1 - cos(theta_max) of the cone a sphere of `radius` subtends from a point at squared
/// distance `dist2` from its centre ([`ConeExtent::one_minus_cos`]).
#[inline]
pub fn cone_one_minus_cos<R: real::Real>(radius: R, dist2: R) -> R {
    cone_extent(radius, dist2).one_minus_cos()
}

/// Samples the sphere (center, radius) as seen from outside point `p`: a direction uniform in
/// the cone the sphere subtends (cos theta = 1 - u1 (1 - cos theta_max), phi = 2 pi u2) and the
/// point where it first meets the sphere (pbrt-v4 6.2.4 `Sphere::Sample`). The point is placed
/// by its angle alpha at the centre, measured from the axis toward `p`, without intersecting a
/// ray with the sphere. In the triangle (p, centre, point) the angle at the point is
/// pi - beta with beta = theta + alpha, and the law of sines gives
/// sin(beta) = (d / r) sin(theta) = sin(theta) / sin(theta_max) (beta <= pi / 2 at the near
/// intersection), so
///
/// - cos(beta) = sqrt(1 - sin^2(theta) / sin^2(theta_max)), and with 1 - cos theta = u1 m,
///   m = 1 - cos theta_max: 1 - sin^2 / sin^2_max = (1 - u1)((1 - u1) + cos theta_max (1 + u1))
///   / (1 + cos theta_max), a product of non-negative terms (the difference cancelled at the
///   cone's rim, u1 near 1, by the square root of a rounding: ~sqrt(eps) of the radius);
/// - cos(alpha) = cos(beta - theta) = sin^2(theta) / sin(theta_max) + cos(theta) cos(beta);
/// - sin(alpha) = sin(beta - theta) = (sin^2 beta - sin^2 theta) / (sin beta cos theta
///   + cos beta sin theta) = sin(theta) cos^2(theta_max) / (sin(theta_max) (cos(theta)
///   + sin(theta_max) cos(beta))) (sqrt(1 - cos^2 alpha) cancelled near the axis).
///
/// Both are sums and products of non-negative terms, accurate to a few eps relative; the
/// smaller of the two is kept and the other taken as sqrt(1 - x^2) of it (no cancellation for
/// x <= 1 / sqrt 2), so the normal is of unit length to the rounding of one root. Density:
/// 1 / (2 pi (1 - cos theta_max)). `p` must be outside the sphere (see [`pdf_sphere_cone`] for
/// the caller's fallback); `u1` in (0, 1) (`rng`).
#[inline]
pub fn sample_sphere_cone(center: Vec3, radius: f32, p: Vec3, u1: f32, u2: f32) -> ConeSample {
    let s = sample_sphere_cone_v3(V3::from(center), radius, V3::from(p), u1, u2);
    ConeSample {
        point: SurfacePoint {
            position: s.position.into(),
            normal: s.normal.into(),
        },
        pdf_solid_angle: s.pdf_solid_angle,
    }
}

/// [`sample_sphere_cone`] for one sphere and point, or one of each per lane ([`real::Real`]).
#[inline]
pub fn sample_sphere_cone_v3<R: real::Real>(
    center: V3<R>,
    radius: R,
    p: V3<R>,
    u1: R,
    u2: R,
) -> ConeSampleV3<R> {
    let (one, two) = (R::splat(1.0), R::splat(2.0));
    let to_center = center - p;
    let dist2 = to_center.dot(to_center);
    let dist = dist2.sqrt();
    let axis = to_center / dist;
    let sin_max = radius / dist;
    let cone = cone_extent(radius, dist2);
    let one_minus_cos_max = cone.one_minus_cos();
    // Uniform in 1 - cos(theta); sin^2 = (1 - cos)(1 + cos) keeps full precision in tiny cones.
    let one_minus_cos = u1 * one_minus_cos_max;
    let cos = one - one_minus_cos;
    let sin2 = one_minus_cos * (two - one_minus_cos);
    let rest = one - u1;
    let cos_beta = (rest * (rest + cone.cos_max * (one + u1)) / (one + cone.cos_max)).sqrt();
    let cos_alpha = sin2 / sin_max + cos * cos_beta;
    let sin_alpha = sin2.sqrt() * cone.cos2_max / (sin_max * (cos + sin_max * cos_beta));
    // The smaller is at most 1 / sqrt(2) (to rounding): 1 - x^2 >= 1 / 2 does not cancel.
    let smaller = sin_alpha.min(cos_alpha);
    let larger = (one - smaller * smaller).sqrt();
    let sin_is_smaller = sin_alpha.less_than(cos_alpha);
    let (cos_alpha, sin_alpha) = (
        real::select(sin_is_smaller, larger, cos_alpha),
        real::select(sin_is_smaller, sin_alpha, larger),
    );
    let (cos_phi, sin_phi) = cos_sin_turns(u2);
    let (t, b) = orthonormal_basis_v3(axis);
    let normal = t * (sin_alpha * cos_phi) + b * (sin_alpha * sin_phi) - axis * cos_alpha;
    ConeSampleV3 {
        position: center + normal * radius,
        normal,
        pdf_solid_angle: one / (two * R::splat(PI) * one_minus_cos_max),
    }
}

/// [`ConeSample`] of one sphere or of one per lane.
#[derive(Clone, Copy, Debug)]
pub struct ConeSampleV3<R> {
    pub position: V3<R>,
    pub normal: V3<R>,
    pub pdf_solid_angle: R,
}

/// Solid-angle density of [`sample_sphere_cone`] from outside point `p`, for any direction
/// that meets the sphere: 1 / (2 pi (1 - cos theta_max)).
#[inline]
pub fn pdf_sphere_cone(center: Vec3, radius: f32, p: Vec3) -> f32 {
    let d = center - p;
    1.0 / (2.0 * PI * cone_one_minus_cos(radius, d.dot(d)))
}

/// Barycentric coordinates (u, v) of a point uniformly distributed over a triangle's area
/// (the point p0 + u edge1 + v edge2, density 1 / area): the sum s = u + v has density 2 s on
/// [0, 1] (the triangle's cross-section at s grows as s), so s = sqrt(u1) by inversion, and
/// given s the point is uniform on its segment, v = s u2 (Turk, "Generating Random Points in
/// Triangles", Graphics Gems, 1990).
#[inline]
pub fn sample_triangle_barycentrics(u1: f32, u2: f32) -> (f32, f32) {
    let s = u1.sqrt();
    (s - s * u2, s * u2)
}

/// A point uniformly distributed on the unit disk, by Shirley and Chiu's concentric map ("A
/// Low Distortion Map Between Disk and Square", 1997): the square [-1, 1]^2 is cut into four
/// triangles by its diagonals, and the one of (a, b) = 2 (u1, u2) - 1 with |a| > |b| maps to
/// radius a and angle (pi/4)(b/a) (the others alike), which preserves areas and keeps strata
/// compact. The angle is in turns for `cos_sin_turns`.
#[inline]
pub fn sample_concentric_disk(u1: f32, u2: f32) -> (f32, f32) {
    let a = 2.0 * u1 - 1.0;
    let b = 2.0 * u2 - 1.0;
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, turns) = if a.abs() > b.abs() {
        (a, 0.125 * (b / a))
    } else {
        (b, 0.25 - 0.125 * (a / b))
    };
    let (c, s) = cos_sin_turns(turns);
    (r * c, r * s)
}
