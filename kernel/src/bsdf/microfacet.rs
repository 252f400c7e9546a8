//! The GGX (Trowbridge-Reitz) microfacet distribution with Smith's masking: its normal
//! density D, the masking G1, and the sampling of visible normals. Isotropic, roughness
//! `alpha` as given (no remapping), as Mitsuba 3's `roughconductor` and pbrt-v4's
//! `TrowbridgeReitzDistribution`. Derivations and sources: `docs/materials.md` ("Microfacets").

use crate::frame::orthonormal_basis_v3;
use crate::real::{self, V3};
use crate::turns::cos_sin_turns;
use core::f32::consts::PI;
use spirv_std::glam::Vec3;

/// D(h), the density of microfacet normals per unit solid angle projected on the mean surface,
/// for a normal at angle theta_h to it: alpha^2 / (pi (sin^2 + alpha^2 cos^2)^2) (Walter,
/// Marschner, Li, Torrance, "Microfacet Models for Refraction through Rough Surfaces", EGSR 2007,
/// eq. 33, with 1 + cos^2 (alpha^2 - 1) written as sin^2 + alpha^2 cos^2); 0 for cos_h <= 0.
/// Normalised: the integral of D(h) cos_h over the hemisphere is 1. Takes sin^2 theta_h
/// itself ([`normal_angle`]): from 1 - cos^2 it would lose all its digits near the peak of a
/// smooth lobe, where sin^2 ~ alpha^2 ~ 1e-6. Over any scalar [`real::Real`], as the other
/// functions here, so that its error under a Vulkan device's arithmetic can be bounded by
/// running it on one (`tests/src/device_class.rs`).
#[inline]
pub fn ggx_d<R: real::Real<Bits = u32>>(cos_h: R, sin2_h: R, alpha: R) -> R {
    if cos_h.greater_than(R::splat(0.0)) == 0 {
        return R::splat(0.0);
    }
    let a2 = alpha * alpha;
    let t = sin2_h + a2 * cos_h * cos_h;
    a2 / (R::splat(PI) * t * t)
}

/// (cos, sin^2) of the angle between unit vectors `n` and `h`: the sine from the cross
/// product, accurate for small angles.
#[inline]
pub fn normal_angle<R: real::Real>(n: V3<R>, h: V3<R>) -> (R, R) {
    let c = n.cross(h);
    (n.dot(h), c.dot(c))
}

/// Smith's masking G1 of GGX for a direction at cosine `cos` to the mean normal:
/// 1 / (1 + Lambda) with Lambda = (sqrt(1 + alpha^2 tan^2) - 1) / 2 (Walter et al. 2007, eq. 34;
/// Heitz, "Understanding the Masking-Shadowing Function", JCGT 3(2), 2014, eq. 86), written as
/// 2 |cos| / (|cos| + sqrt(alpha^2 + (1 - alpha^2) cos^2)), which needs no tangent.
#[inline]
pub fn ggx_g1<R: real::Real>(cos: R, alpha: R) -> R {
    let one = R::splat(1.0);
    let c = cos.abs();
    let a2 = alpha * alpha;
    R::splat(2.0) * c / (c + (a2 + (one - a2) * c * c).max(R::splat(0.0)).sqrt())
}

/// A microfacet normal drawn from the visible normals seen from `wo` (unit, `n . wo` > 0),
/// density D_wo(h) = G1(wo) max(0, wo . h) D(h) / (n . wo) (Heitz 2014, eq. 38), by sampling
/// a spherical cap (Dupuy and Benyoub, "Sampling Visible GGX Normals with Spherical Caps",
/// HPG 2023): in the frame stretched by 1/alpha the visible normals are the directions
/// c + w_s for c uniform on the cap of the unit sphere with z >= -w_s.z, w_s = normalize(wo
/// stretched); unstretching gives h. Only `cos_sin_turns` and square roots: the same bits on
/// both backends. `n` is the mean normal, `u1` the azimuth in turns, `u2` the cap's height.
#[inline]
pub fn sample_visible_normal(n: Vec3, wo: Vec3, alpha: f32, u1: f32, u2: f32) -> Vec3 {
    sample_visible_normal_v3(V3::from(n), V3::from(wo), alpha, u1, u2).into()
}

/// [`sample_visible_normal`] over any scalar [`real::Real`], in the same operations.
#[inline]
pub fn sample_visible_normal_v3<R: real::Real<Bits = u32>>(
    n: V3<R>,
    wo: V3<R>,
    alpha: R,
    u1: R,
    u2: R,
) -> V3<R> {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let (t, b) = orthonormal_basis_v3(n);
    let ws = V3::new(alpha * wo.dot(t), alpha * wo.dot(b), wo.dot(n)).normalize();
    let (cos_phi, sin_phi) = cos_sin_turns(u1);
    let z = (one - u2) * (one + ws.z) - ws.z;
    let sin_theta = (one - z * z).clamp(zero, one).sqrt();
    let hs = V3::new(sin_theta * cos_phi, sin_theta * sin_phi, z) + ws;
    let local = V3::new(alpha * hs.x, alpha * hs.y, hs.z.max(zero));
    let len2 = local.dot(local);
    if len2.greater_than(zero) == 0 {
        // c = -w_s exactly (the cap's rim opposite w_s: measure zero).
        return n;
    }
    let local = local / len2.sqrt();
    t * local.x + b * local.y + n * local.z
}

/// Density per unit solid angle of the direction reflected about a visible normal from
/// [`sample_visible_normal`]: D_wo(h) / (4 wo . h) = G1(wo) D(h) / (4 n . wo), the Jacobian of
/// reflection being 1 / (4 wo . h) (Walter et al. 2007, eq. 14). `cos_o` = n . wo > 0;
/// (`cos_h`, `sin2_h`) the half vector's angle ([`normal_angle`]).
#[inline]
pub fn pdf_reflected<R: real::Real<Bits = u32>>(cos_o: R, (cos_h, sin2_h): (R, R), alpha: R) -> R {
    ggx_g1(cos_o, alpha) * ggx_d(cos_h, sin2_h, alpha) / (R::splat(4.0) * cos_o)
}

/// A microfacet reflection from `wo` to `wi` (unit, both above `n`, cosines `cos_o`, `cos_i`):
/// its half vector, D G / (4 cos_o) (the value times cos_i, without the Fresnel factor), and the
/// density of `wi` from [`sample_visible_normal`] ([`pdf_reflected`]).
#[derive(Clone, Copy, Debug)]
pub struct Reflection<R> {
    pub h: V3<R>,
    pub value: R,
    pub pdf: R,
}

/// The [`Reflection`] from `wo` to `wi` with separable Smith G = G1(wo) G1(wi).
#[inline(always)]
pub fn reflection<R: real::Real<Bits = u32>>(
    n: V3<R>,
    wo: V3<R>,
    wi: V3<R>,
    cos_o: R,
    cos_i: R,
    alpha: R,
) -> Reflection<R> {
    let h = (wo + wi).normalize();
    let angle = normal_angle(n, h);
    let d = ggx_d(angle.0, angle.1, alpha);
    let g = ggx_g1(cos_o, alpha) * ggx_g1(cos_i, alpha);
    Reflection {
        h,
        value: d * g / (R::splat(4.0) * cos_o),
        pdf: pdf_reflected(cos_o, angle, alpha),
    }
}

/// The [`Reflection`] from `wo` to `wi` with the height-correlated Smith masking-shadowing
/// G2 = 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014, eq. 99; glTF 2.0 Appendix B's
/// visibility term and Cycles' microfacet BSDFs use it). With a = sqrt(alpha^2 + (1 - alpha^2)
/// cos^2) per direction, the sum of one and the two Lambdas is (a_o / cos_o + a_i / cos_i) / 2,
/// so D G2 / (4 cos_o) = D cos_i / (2 (a_o cos_i + a_i cos_o)): no tangent, no division by a
/// cosine.
#[inline(always)]
pub fn reflection_height_correlated<R: real::Real<Bits = u32>>(
    n: V3<R>,
    wo: V3<R>,
    wi: V3<R>,
    cos_o: R,
    cos_i: R,
    alpha: R,
) -> Reflection<R> {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let h = (wo + wi).normalize();
    let angle = normal_angle(n, h);
    let d = ggx_d(angle.0, angle.1, alpha);
    let a2 = alpha * alpha;
    let a_o = (a2 + (one - a2) * cos_o * cos_o).max(zero).sqrt();
    let a_i = (a2 + (one - a2) * cos_i * cos_i).max(zero).sqrt();
    Reflection {
        h,
        value: d * cos_i / (R::splat(2.0) * (a_o * cos_i + a_i * cos_o)),
        pdf: pdf_reflected(cos_o, angle, alpha),
    }
}
