//! The seed's Kd + Ks BRDF (`material_kind::GLOSSY`): a Lambertian lobe Kd / pi plus a GGX
//! microfacet lobe with Schlick's Fresnel (F0 = Ks, F90 [`glossy_f90`]), each sampled in
//! proportion to an estimate of its albedo. With `LAYERED`, the Lambertian lobe lies under a
//! dielectric layer of reflectance `layer_f0` at normal incidence and `layer_f90` at grazing
//! (`crate::scene::LAYER_F0` and 1 by default) and is weighed by the share it lets through (glTF's
//! `fresnel_mix` with `KHR_materials_specular`'s weight and colour, which `metallic_roughness`
//! resolves into this form). With the layer (glTF's material) the glossy lobe's masking is
//! the height-correlated Smith G2 (glTF's Appendix B, as Cycles), and the lobe is multiplied by
//! its multiple-scattering factor (`multiple_scattering::factor`); GLOSSY keeps the separable
//! G1 G1 (as Mitsuba's models, its peer) and single scattering.

use super::coat::{self, Coat};
use super::fresnel::schlick_f90;
use super::inputs::BsdfNumbers;
use super::lambert::sample_brdf_v3;
use super::microfacet::{reflection, reflection_height_correlated, sample_visible_normal_v3};
use super::multiple_scattering::{factor, GlossyAlbedo};
use super::sheen::{self, Sheen};
use super::{reflect, BsdfFlags, BsdfSampleV3, DELTA_ALPHA};
use crate::features;
use crate::real::{Real, V3};
use core::f32::consts::PI;
use spirv_std::glam::Vec3;

/// The feature bits of a scene with this kind.
pub const FEATURES: u32 = features::GLOSSY;

/// A Lambertian lobe (never a delta distribution) beside the glossy one: the vertex chooses.
pub const FLAGS: BsdfFlags = BsdfFlags {
    delta: false,
    chooses_lobe: true,
};

/// The probability that the mixture samples its glossy lobe from `wo` at cosine `cos_o`: each
/// lobe in proportion to an estimate of its albedo, mean(Kd) for the diffuse and
/// mean(F_Schlick(cos_o)) for the glossy (the masking left out); 0 when both are 0.
#[inline]
pub fn glossy_lobe_probability<R: Real<Bits = u32>>(m: &impl BsdfNumbers<R>, cos_o: R) -> R {
    let fd = m.albedo().element_sum();
    let fs = schlick_f90(m.specular(), glossy_f90(m), cos_o).element_sum();
    let sum = fd + fs;
    if sum.greater_than(R::splat(0.0)) != 0 {
        fs / sum
    } else {
        R::splat(0.0)
    }
}

/// The glossy lobe's reflectance at grazing incidence: the layer's `layer_f90` blended toward a
/// metal's 1 by `metallic` (Schlick's F is affine in F0 and F90, so the dielectric's and the
/// metal's specular terms sum to one Schlick curve); 1 for GLOSSY (`layer_f90` 1, `metallic`
/// 0), exactly.
#[inline]
pub fn glossy_f90<R: Real<Bits = u32>>(m: &impl BsdfNumbers<R>) -> R {
    m.layer_f90() + (R::splat(1.0) - m.layer_f90()) * m.metallic()
}

/// The factor on the Kd lobe for light from `wi` toward `wo`: 1 without the layer, and with it
/// the share the layer lets through, 1 - max over channels of F_Schlick(`layer_f0`,
/// `layer_f90`, |wo . h|) at the half vector h of `wo` and `wi` (Appendix B's `fresnel_mix`
/// as `KHR_materials_specular` extends it: `1 - weight * max_value(fr)`).
#[inline(always)]
fn diffuse_share<const LAYERED: bool, R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    wo: V3<R>,
    wi: V3<R>,
) -> R {
    if LAYERED {
        let h = (wo + wi).normalize();
        R::splat(1.0) - schlick_f90(m.layer_f0(), m.layer_f90(), wo.dot(h).abs()).max_element()
    } else {
        R::splat(1.0)
    }
}

/// `bsdf::eval` of the mixture: Kd/pi cos (times the layer's share) + D G F_Schlick(wi . h) /
/// (4 cos_o) (times the multiple-scattering factor of `albedo`, E at `wo`), density the
/// mixture of the cosine lobe and the visible-normal reflection; with the layer, under the
/// clear coat and the sheen where the material has them. Zero where `wo` is not above `n`
/// (rounding at grazing hits).
#[inline]
pub fn eval<const LAYERED: bool, R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    wi: V3<R>,
    albedo: GlossyAlbedo<R>,
) -> (V3<R>, R) {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let cos_o = n.dot(wo);
    let cos_i = n.dot(wi);
    if cos_o.greater_than(zero) == 0 || cos_i.greater_than(zero) == 0 {
        return (V3::splat(Vec3::ZERO), zero);
    }
    let p_glossy = glossy_lobe_probability(m, cos_o);
    let c = cos_i * R::splat(1.0 / PI);
    let mut f = m.albedo() * (c * diffuse_share::<LAYERED, R>(m, wo, wi));
    let mut pdf = (one - p_glossy) * c;
    if m.alpha().less_than(R::splat(DELTA_ALPHA)) == 0 {
        let r = if LAYERED {
            reflection_height_correlated(n, wo, wi, cos_o, cos_i, m.alpha())
        } else {
            reflection(n, wo, wi, cos_o, cos_i, m.alpha())
        };
        let (f0, f90) = (m.specular(), glossy_f90(m));
        let glossy = schlick_f90(f0, f90, wi.dot(r.h)) * r.value;
        f = f + if LAYERED {
            glossy * factor(albedo, f0, f90)
        } else {
            glossy
        };
        pdf = pdf + p_glossy * r.pdf;
    }
    if LAYERED && m.coat() != 0 {
        let coat = coat::at(m, cos_o, albedo);
        if coat.weight.greater_than(zero) != 0 {
            // Under glTF's clear coat (`coat`): the material's 1 - c, and the coat's rough
            // lobe (a smooth one is a delta lobe: in neither).
            f = f * (one - coat.weight);
            pdf = pdf * (one - coat.weight);
            if coat.alpha.less_than(R::splat(DELTA_ALPHA)) == 0 {
                let r = coat::reflection(&coat, n, wo, wi, cos_o, cos_i);
                let value = coat::lobe_weight(m, wo, r.h, albedo) * r.value;
                f = f + V3::new(value, value, value);
                pdf = pdf + coat.weight * r.pdf;
            }
        }
    }
    if LAYERED && albedo.sheen.z.greater_than(zero) != 0 {
        // Over everything, glTF's sheen (`sheen`): the rest's 1 - s, and the sheen's lobe.
        // Its R is 0 where the material has none (`surface::glossy_albedo` looks it up only
        // for a sheen): one test of a number already at hand.
        let sheen = sheen::at(m.sheen_colour(), albedo.sheen);
        if sheen.weight.greater_than(zero) != 0 {
            let (value, density) = sheen::eval(&sheen, n, wo, wi);
            f = f * (one - sheen.weight) + value;
            pdf = pdf * (one - sheen.weight) + sheen.weight * density;
        }
    }
    (f, pdf)
}

/// `bsdf::sample` of the mixture with numbers `u` = (u_lobe, u1, u2): with the layer, `u_lobe`
/// below the sheen's weight s chooses the sheen (`sheen`), and is else mapped onto [0, 1) again
/// by (u_lobe - s) / (1 - s); then below the clear coat's weight c it chooses the coat
/// (`coat`), and is else mapped again by (u_lobe - c) / (1 - c); then below the glossy lobe's
/// probability it chooses that lobe; (u1, u2) draw the direction in the chosen lobe.
#[inline]
pub fn sample<const LAYERED: bool, R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    albedo: GlossyAlbedo<R>,
    (u_lobe, u1, u2): (R, R, R),
) -> BsdfSampleV3<R> {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let mut u_lobe = u_lobe;
    let cos_o = n.dot(wo);
    if cos_o.greater_than(zero) == 0 {
        return BsdfSampleV3::none();
    }
    let mut sheen_weight = zero;
    if LAYERED && albedo.sheen.z.greater_than(zero) != 0 {
        let sheen = sheen::at(m.sheen_colour(), albedo.sheen);
        if u_lobe.less_than(sheen.weight) != 0 {
            return sampled_sheen::<LAYERED, R>(&sheen, m, n, wo, albedo, (u1, u2));
        }
        // s < 1 here (u_lobe < 1).
        sheen_weight = sheen.weight;
        u_lobe = (u_lobe - sheen.weight) / (one - sheen.weight);
    }
    let coat = if LAYERED && m.coat() != 0 {
        coat::at(m, cos_o, albedo)
    } else {
        Coat::none()
    };
    let coated = coat.weight.greater_than(zero) != 0;
    if coated {
        if u_lobe.less_than(coat.weight) != 0 {
            // The coat, chosen with probability c: a smooth one's mirror weighs c / c.
            if coat.alpha.less_than(R::splat(DELTA_ALPHA)) != 0 {
                return BsdfSampleV3::mirror(n, reflect(wo, n), V3::new(one, one, one));
            }
            let wi = reflect(wo, sample_visible_normal_v3(n, wo, coat.alpha, u1, u2));
            return weighed::<LAYERED, R>(m, n, wo, wi, albedo);
        }
        // c < 1 here (u_lobe < 1).
        u_lobe = (u_lobe - coat.weight) / (one - coat.weight);
    }
    let smooth = m.alpha().less_than(R::splat(DELTA_ALPHA)) != 0;
    let p_glossy = glossy_lobe_probability(m, cos_o);
    let glossy = u_lobe.less_than(p_glossy) != 0;
    if smooth && glossy {
        return BsdfSampleV3::mirror(
            n,
            reflect(wo, n),
            schlick_f90(m.specular(), glossy_f90(m), cos_o) / p_glossy,
        );
    }
    let wi = if glossy {
        reflect(wo, sample_visible_normal_v3(n, wo, m.alpha(), u1, u2))
    } else {
        sample_brdf_v3(n, u1, u2)
    };
    if smooth && coat.weight.not_equal(zero) == 0 && sheen_weight.not_equal(zero) == 0 {
        // The diffuse lobe beside a delta one: (Kd/pi cos) / ((1 - p) cos/pi), exactly.
        let weight = m.albedo() * (diffuse_share::<LAYERED, R>(m, wo, wi) / (one - p_glossy));
        return BsdfSampleV3::reflected(
            wi,
            weight,
            (one - p_glossy) * n.dot(wi) * R::splat(1.0 / PI),
        );
    }
    weighed::<LAYERED, R>(m, n, wo, wi, albedo)
}

/// The sheen's sample (chosen with probability s) from numbers `u`, weighed by the whole
/// mixture. Kept out of line on the CPU: materials without a sheen never run it.
#[cfg_attr(not(target_arch = "spirv"), inline(never))]
fn sampled_sheen<const LAYERED: bool, R: Real<Bits = u32>>(
    sheen: &Sheen<R>,
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    albedo: GlossyAlbedo<R>,
    u: (R, R),
) -> BsdfSampleV3<R> {
    let wi = sheen::sample(sheen, n, wo, u.0, u.1);
    weighed::<LAYERED, R>(m, n, wo, wi, albedo)
}

/// The sample of direction `wi` weighed f cos / pdf by [`eval`] (the whole mixture's value and
/// density, the delta lobes in neither), or none where the density is 0.
#[inline]
fn weighed<const LAYERED: bool, R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    wi: V3<R>,
    albedo: GlossyAlbedo<R>,
) -> BsdfSampleV3<R> {
    let (f, pdf) = eval::<LAYERED, R>(m, n, wo, wi, albedo);
    if pdf.greater_than(R::splat(0.0)) == 0 {
        return BsdfSampleV3::none();
    }
    BsdfSampleV3::reflected(wi, f / pdf, pdf)
}
