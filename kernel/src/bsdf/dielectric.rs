//! Glass (`material_kind::DIELECTRIC`): GGX (Walter et al. 2007) or, below `DELTA_ALPHA`,
//! smooth reflection and refraction between the outside (index 1) and the inside (index `ior`)
//! of a closed surface; `eta` is the index beyond the surface over the index on `wo`'s side.

use super::fresnel::{dielectric, dielectric_transmittance, refract};
use super::microfacet::{
    ggx_d, ggx_g1, normal_angle, pdf_reflected, reflection, sample_visible_normal,
};
use super::{reflect, BsdfFlags, BsdfSample, DELTA_ALPHA, DELTA_PDF};
use crate::features;
use crate::scene::Material;
use spirv_std::glam::Vec3;

/// The feature bit of a scene with this kind.
pub const FEATURES: u32 = features::DIELECTRIC;

/// Reflection or refraction, chosen by `u_lobe`; a delta distribution when smooth.
#[inline]
pub fn flags(m: &Material) -> BsdfFlags {
    BsdfFlags {
        delta: m.alpha < DELTA_ALPHA,
        chooses_lobe: true,
    }
}

/// `bsdf::eval` of a rough dielectric: Walter et al. 2007, eqs. 20-21 (radiance transport);
/// zero for a smooth one (delta lobes) and where `wo` is not above `n`.
#[inline]
pub fn eval(m: &Material, n: Vec3, wo: Vec3, wi: Vec3, eta: f32) -> (Vec3, f32) {
    let cos_o = n.dot(wo);
    let cos_i = n.dot(wi);
    if !(cos_o > 0.0) || m.alpha < DELTA_ALPHA {
        return (Vec3::ZERO, 0.0);
    }
    if cos_i > 0.0 {
        let r = reflection(n, wo, wi, cos_o, cos_i, m.alpha);
        let (fresnel, _) = dielectric(wo.dot(r.h), eta);
        return (Vec3::splat(fresnel * r.value), fresnel * r.pdf);
    }
    if !(cos_i < 0.0) {
        return (Vec3::ZERO, 0.0);
    }
    // The generalised half vector of a refraction (Walter et al. 2007, eq. 16), on n's side.
    let sum = wo + eta * wi;
    if !(sum.dot(sum) > 0.0) {
        // wi = -wo through an index-matched interface (eta 1): no half vector, measure zero.
        return (Vec3::ZERO, 0.0);
    }
    let mut h = sum.normalize();
    if n.dot(h) < 0.0 {
        h = -h;
    }
    let (cos_oh, cos_ih) = (wo.dot(h), wi.dot(h));
    // Only microfacets that face wo and that wi leaves from behind refract between them.
    if !(cos_oh > 0.0 && cos_ih < 0.0) {
        return (Vec3::ZERO, 0.0);
    }
    // h being the half vector of this refraction, Snell's cos_t is |wi . h| itself: taken from
    // the geometry, it keeps its digits where Snell's 1 - sin_t^2 would cancel.
    let transmitted = dielectric_transmittance(cos_oh, eta, -cos_ih);
    let (cos_h, sin2_h) = normal_angle(n, h);
    let d = ggx_d(cos_h, sin2_h, m.alpha);
    let g1o = ggx_g1(cos_o, m.alpha);
    let g = g1o * ggx_g1(cos_i, m.alpha);
    let denom2 = refraction_denominator(eta, cos_ih, cos_oh);
    // f |cos_i| = D (1 - F) G |wi.h| |wo.h| / ((eta wi.h + wo.h)^2 |cos_o|), radiance mode.
    let f = (d * transmitted * g * (-cos_ih) * cos_oh / (denom2 * cos_o)).min(f32::MAX);
    // (1 - F) D_wo(h) |dh/dwi|, |dh/dwi| = eta^2 |wi.h| / (eta wi.h + wo.h)^2.
    let pdf = transmitted * g1o * cos_oh * d / cos_o * (eta * eta * (-cos_ih) / denom2);
    (Vec3::splat(f), pdf.min(f32::MAX))
}

/// `bsdf::sample` of a dielectric: a microfacet normal (n itself when smooth), then reflection
/// with the probability F of its Fresnel reflectance, else refraction.
#[inline]
pub fn sample(
    m: &Material,
    n: Vec3,
    wo: Vec3,
    eta: f32,
    u_lobe: f32,
    u1: f32,
    u2: f32,
) -> BsdfSample {
    let cos_o = n.dot(wo);
    if !(cos_o > 0.0) {
        return BsdfSample::NONE;
    }
    let smooth = m.alpha < DELTA_ALPHA;
    let h = if smooth {
        n
    } else {
        sample_visible_normal(n, wo, m.alpha, u1, u2)
    };
    let cos_oh = wo.dot(h);
    let (fresnel, cos_t) = dielectric(cos_oh, eta);
    if u_lobe < fresnel {
        let wi = reflect(wo, h);
        if smooth {
            return BsdfSample::mirror(n, wi, Vec3::ONE);
        }
        let cos_i = n.dot(wi);
        if !(cos_i > 0.0) {
            return BsdfSample::NONE;
        }
        let pdf = fresnel * pdf_reflected(cos_o, normal_angle(n, h), m.alpha);
        return BsdfSample::reflected(wi, Vec3::splat(ggx_g1(cos_i, m.alpha)), pdf);
    }
    let wi = refract(wo, h, cos_oh, eta, cos_t);
    let eta2 = eta * eta;
    if smooth {
        if !(n.dot(wi) < 0.0) {
            // A grazing wo refracts to a grazing wi, which rounding may put on wo's side.
            return BsdfSample::NONE;
        }
        return BsdfSample {
            wi,
            weight: Vec3::splat(1.0 / eta2),
            pdf: DELTA_PDF,
            eta2,
            transmitted: true,
        };
    }
    let cos_i = n.dot(wi);
    if !(cos_i < 0.0) {
        return BsdfSample::NONE;
    }
    let cos_ih = wi.dot(h);
    let denom2 = refraction_denominator(eta, cos_ih, cos_oh);
    let (cos_h, sin2_h) = normal_angle(n, h);
    let d = ggx_d(cos_h, sin2_h, m.alpha);
    let transmitted = dielectric_transmittance(cos_oh, eta, cos_t);
    let pdf =
        transmitted * ggx_g1(cos_o, m.alpha) * cos_oh * d / cos_o * (eta2 * (-cos_ih) / denom2);
    BsdfSample {
        wi,
        weight: Vec3::splat(ggx_g1(cos_i, m.alpha) / eta2),
        pdf: pdf.min(f32::MAX),
        eta2,
        transmitted: true,
    }
}

/// (eta wi . h + wo . h)^2, the refraction's Jacobian denominator (Walter et al. 2007, eq. 17),
/// kept off zero: it vanishes as eta -> 1, where every microfacet refracts wo to -wo and the
/// rough lobe becomes a spike. Its density and value then stay finite (at most f32::MAX):
/// unbounded in the limit, they are what MIS and next-event estimation weigh, while the
/// sample's weight, G1(wi) / eta^2, needs neither.
#[inline]
fn refraction_denominator(eta: f32, cos_ih: f32, cos_oh: f32) -> f32 {
    let d = eta * cos_ih + cos_oh;
    (d * d).max(f32::MIN_POSITIVE)
}
