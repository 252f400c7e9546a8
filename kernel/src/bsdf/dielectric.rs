//! Glass (`material_kind::DIELECTRIC`): GGX (Walter et al. 2007) or, below `DELTA_ALPHA`,
//! smooth reflection and refraction between the outside (index 1) and the inside (index `ior`)
//! of a closed surface; `eta` is the index beyond the surface over the index on `wo`'s side.

use super::fresnel::{dielectric, dielectric_transmittance, refract};
use super::inputs::BsdfNumbers;
use super::microfacet::{
    ggx_d, ggx_g1, normal_angle, pdf_reflected, reflection, sample_visible_normal_v3,
};
use super::{reflect, BsdfFlags, BsdfSampleV3, DELTA_ALPHA, DELTA_PDF};
use crate::features;
use crate::real::{Real, V3};
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
pub fn eval<R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    wi: V3<R>,
    eta: R,
) -> (V3<R>, R) {
    let zero = R::splat(0.0);
    let nothing = (V3::splat(Vec3::ZERO), zero);
    let cos_o = n.dot(wo);
    let cos_i = n.dot(wi);
    if cos_o.greater_than(zero) == 0 || m.alpha().less_than(R::splat(DELTA_ALPHA)) != 0 {
        return nothing;
    }
    if cos_i.greater_than(zero) != 0 {
        let r = reflection(n, wo, wi, cos_o, cos_i, m.alpha());
        let (fresnel, _) = dielectric(wo.dot(r.h), eta);
        let f = fresnel * r.value;
        return (V3::new(f, f, f), fresnel * r.pdf);
    }
    if cos_i.less_than(zero) == 0 {
        return nothing;
    }
    // The generalised half vector of a refraction (Walter et al. 2007, eq. 16), on n's side.
    let sum = wo + wi * eta;
    if sum.dot(sum).greater_than(zero) == 0 {
        // wi = -wo through an index-matched interface (eta 1): no half vector, measure zero.
        return nothing;
    }
    let h = sum.normalize();
    let h = V3::select(n.dot(h).less_than(zero), -h, h);
    let (cos_oh, cos_ih) = (wo.dot(h), wi.dot(h));
    // Only microfacets that face wo and that wi leaves from behind refract between them.
    if cos_oh.greater_than(zero) == 0 || cos_ih.less_than(zero) == 0 {
        return nothing;
    }
    // h being the half vector of this refraction, Snell's cos_t is |wi . h| itself: taken from
    // the geometry, it keeps its digits where Snell's 1 - sin_t^2 would cancel.
    let transmitted = dielectric_transmittance(cos_oh, eta, -cos_ih);
    let (cos_h, sin2_h) = normal_angle(n, h);
    let d = ggx_d(cos_h, sin2_h, m.alpha());
    let g1o = ggx_g1(cos_o, m.alpha());
    let g = g1o * ggx_g1(cos_i, m.alpha());
    let denom2 = refraction_denominator(eta, cos_ih, cos_oh);
    let most = R::splat(f32::MAX);
    // f |cos_i| = D (1 - F) G |wi.h| |wo.h| / ((eta wi.h + wo.h)^2 |cos_o|), radiance mode.
    let f = (d * transmitted * g * (-cos_ih) * cos_oh / (denom2 * cos_o)).min(most);
    // (1 - F) D_wo(h) |dh/dwi|, |dh/dwi| = eta^2 |wi.h| / (eta wi.h + wo.h)^2.
    let pdf = transmitted * g1o * cos_oh * d / cos_o * (eta * eta * (-cos_ih) / denom2);
    (V3::new(f, f, f), pdf.min(most))
}

/// `bsdf::sample` of a dielectric: a microfacet normal (n itself when smooth), then reflection
/// with the probability F of its Fresnel reflectance, else refraction.
#[inline]
pub fn sample<R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    eta: R,
    u_lobe: R,
    u1: R,
    u2: R,
) -> BsdfSampleV3<R> {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let cos_o = n.dot(wo);
    if cos_o.greater_than(zero) == 0 {
        return BsdfSampleV3::none();
    }
    let smooth = m.alpha().less_than(R::splat(DELTA_ALPHA)) != 0;
    let h = if smooth {
        n
    } else {
        sample_visible_normal_v3(n, wo, m.alpha(), u1, u2)
    };
    let cos_oh = wo.dot(h);
    let (fresnel, cos_t) = dielectric(cos_oh, eta);
    if u_lobe.less_than(fresnel) != 0 {
        let wi = reflect(wo, h);
        if smooth {
            return BsdfSampleV3::mirror(n, wi, V3::new(one, one, one));
        }
        let cos_i = n.dot(wi);
        if cos_i.greater_than(zero) == 0 {
            return BsdfSampleV3::none();
        }
        let pdf = fresnel * pdf_reflected(cos_o, normal_angle(n, h), m.alpha());
        let g1 = ggx_g1(cos_i, m.alpha());
        return BsdfSampleV3::reflected(wi, V3::new(g1, g1, g1), pdf);
    }
    let wi = refract(wo, h, cos_oh, eta, cos_t);
    let eta2 = eta * eta;
    if smooth {
        if n.dot(wi).less_than(zero) == 0 {
            // A grazing wo refracts to a grazing wi, which rounding may put on wo's side.
            return BsdfSampleV3::none();
        }
        let w = one / eta2;
        return BsdfSampleV3 {
            wi,
            weight: V3::new(w, w, w),
            pdf: R::splat(DELTA_PDF),
            eta2,
            transmitted: true,
        };
    }
    let cos_i = n.dot(wi);
    if cos_i.less_than(zero) == 0 {
        return BsdfSampleV3::none();
    }
    let cos_ih = wi.dot(h);
    let denom2 = refraction_denominator(eta, cos_ih, cos_oh);
    let (cos_h, sin2_h) = normal_angle(n, h);
    let d = ggx_d(cos_h, sin2_h, m.alpha());
    let transmitted = dielectric_transmittance(cos_oh, eta, cos_t);
    let pdf =
        transmitted * ggx_g1(cos_o, m.alpha()) * cos_oh * d / cos_o * (eta2 * (-cos_ih) / denom2);
    let w = ggx_g1(cos_i, m.alpha()) / eta2;
    BsdfSampleV3 {
        wi,
        weight: V3::new(w, w, w),
        pdf: pdf.min(R::splat(f32::MAX)),
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
fn refraction_denominator<R: Real>(eta: R, cos_ih: R, cos_oh: R) -> R {
    let d = eta * cos_ih + cos_oh;
    (d * d).max(R::splat(f32::MIN_POSITIVE))
}
