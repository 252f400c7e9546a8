//! A metal (`material_kind::CONDUCTOR`): a GGX microfacet mirror (Walter et al. 2007; the
//! visible normals sampled by `microfacet`), or a perfect one below `DELTA_ALPHA`, with a
//! conductor's Fresnel reflectance: exact for a complex index eta + i k, or a constant.

use super::fresnel::conductor_rgb;
use super::inputs::BsdfNumbers;
use super::microfacet::{
    ggx_g1, normal_angle, pdf_reflected, reflection, sample_visible_normal_v3,
};
use super::{reflect, BsdfFlags, BsdfSampleV3, DELTA_ALPHA};
use crate::features;
use crate::real::{Real, V3};
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
#[inline(always)]
fn fresnel<R: Real<Bits = u32>>(m: &impl BsdfNumbers<R>, cos: R) -> V3<R> {
    if m.is_complex_conductor() {
        conductor_rgb(cos, m.eta(), m.k())
    } else {
        m.specular()
    }
}

/// `bsdf::eval` of a rough conductor: F(wo . h) D G / (4 cos_o); zero for a smooth one (a
/// delta lobe) and where `wo` is not above `n`.
#[inline]
pub fn eval<R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    wi: V3<R>,
) -> (V3<R>, R) {
    let zero = R::splat(0.0);
    let cos_o = n.dot(wo);
    let cos_i = n.dot(wi);
    if cos_o.greater_than(zero) == 0
        || m.alpha().less_than(R::splat(DELTA_ALPHA)) != 0
        || cos_i.greater_than(zero) == 0
    {
        return (V3::splat(Vec3::ZERO), zero);
    }
    let r = reflection(n, wo, wi, cos_o, cos_i, m.alpha());
    (fresnel(m, wo.dot(r.h)) * r.value, r.pdf)
}

/// `bsdf::sample` of a conductor: the mirror direction when smooth, else a visible normal's;
/// weight F G1(wi).
#[inline]
pub fn sample<R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    u1: R,
    u2: R,
) -> BsdfSampleV3<R> {
    let zero = R::splat(0.0);
    let cos_o = n.dot(wo);
    if cos_o.greater_than(zero) == 0 {
        return BsdfSampleV3::none();
    }
    if m.alpha().less_than(R::splat(DELTA_ALPHA)) != 0 {
        return BsdfSampleV3::mirror(n, reflect(wo, n), fresnel(m, cos_o));
    }
    let h = sample_visible_normal_v3(n, wo, m.alpha(), u1, u2);
    let wi = reflect(wo, h);
    let cos_i = n.dot(wi);
    if cos_i.greater_than(zero) == 0 {
        return BsdfSampleV3::none();
    }
    let weight = fresnel(m, wo.dot(h)) * ggx_g1(cos_i, m.alpha());
    BsdfSampleV3::reflected(
        wi,
        weight,
        pdf_reflected(cos_o, normal_angle(n, h), m.alpha()),
    )
}
