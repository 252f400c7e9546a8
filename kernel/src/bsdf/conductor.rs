//! A metal (`material_kind::CONDUCTOR`): a GGX microfacet mirror (Walter et al. 2007; the
//! visible normals sampled by `microfacet`), or a perfect one below `DELTA_ALPHA`, with a
//! conductor's Fresnel reflectance: exact for a complex index eta + i k, or a constant.

use super::fresnel::conductor_rgb;
use super::microfacet::{ggx_g1, normal_angle, pdf_reflected, reflection, sample_visible_normal};
use super::{reflect, BsdfFlags, BsdfSample, DELTA_ALPHA};
use crate::features;
use crate::scene::Material;
use spirv_std::glam::Vec3;

/// The feature bit of a scene with this kind.
pub const FEATURES: u32 = features::CONDUCTOR;

/// One lobe, a delta distribution when smooth.
#[inline]
pub fn flags(m: &Material) -> BsdfFlags {
    BsdfFlags {
        delta: m.alpha < DELTA_ALPHA,
        chooses_lobe: false,
    }
}

/// The Fresnel reflectance at cosine `cos`: exact for the complex index, or the constant
/// reflectance.
#[inline]
fn fresnel(m: &Material, cos: f32) -> Vec3 {
    if m.is_complex_conductor() {
        conductor_rgb(cos, Vec3::from(m.eta), Vec3::from(m.k))
    } else {
        Vec3::from(m.specular)
    }
}

/// `bsdf::eval` of a rough conductor: F(wo . h) D G / (4 cos_o); zero for a smooth one (a
/// delta lobe) and where `wo` is not above `n`.
#[inline]
pub fn eval(m: &Material, n: Vec3, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
    let cos_o = n.dot(wo);
    let cos_i = n.dot(wi);
    if !(cos_o > 0.0) || m.alpha < DELTA_ALPHA || !(cos_i > 0.0) {
        return (Vec3::ZERO, 0.0);
    }
    let r = reflection(n, wo, wi, cos_o, cos_i, m.alpha);
    (fresnel(m, wo.dot(r.h)) * r.value, r.pdf)
}

/// `bsdf::sample` of a conductor: the mirror direction when smooth, else a visible normal's;
/// weight F G1(wi).
#[inline]
pub fn sample(m: &Material, n: Vec3, wo: Vec3, u1: f32, u2: f32) -> BsdfSample {
    let cos_o = n.dot(wo);
    if !(cos_o > 0.0) {
        return BsdfSample::NONE;
    }
    if m.alpha < DELTA_ALPHA {
        return BsdfSample::mirror(n, reflect(wo, n), fresnel(m, cos_o));
    }
    let h = sample_visible_normal(n, wo, m.alpha, u1, u2);
    let wi = reflect(wo, h);
    let cos_i = n.dot(wi);
    if !(cos_i > 0.0) {
        return BsdfSample::NONE;
    }
    let weight = fresnel(m, wo.dot(h)) * ggx_g1(cos_i, m.alpha);
    BsdfSample::reflected(
        wi,
        weight,
        pdf_reflected(cos_o, normal_angle(n, h), m.alpha),
    )
}
