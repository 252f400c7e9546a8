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
use super::lambert::sample_brdf;
use super::microfacet::{reflection, reflection_height_correlated, sample_visible_normal};
use super::multiple_scattering::{factor, GlossyAlbedo};
use super::sheen::{self, Sheen};
use super::{reflect, BsdfFlags, BsdfSample, DELTA_ALPHA};
use crate::features;
use crate::scene::Material;
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
pub fn glossy_lobe_probability(m: &Material, cos_o: f32) -> f32 {
    let fd = Vec3::from(m.albedo).dot(Vec3::ONE);
    let fs = schlick_f90(Vec3::from(m.specular), glossy_f90(m), cos_o).dot(Vec3::ONE);
    if fd + fs > 0.0 {
        fs / (fd + fs)
    } else {
        0.0
    }
}

/// The glossy lobe's reflectance at grazing incidence: the layer's `layer_f90` blended toward a
/// metal's 1 by `metallic` (Schlick's F is affine in F0 and F90, so the dielectric's and the
/// metal's specular terms sum to one Schlick curve); 1 for GLOSSY (`layer_f90` 1, `metallic`
/// 0), exactly.
#[inline]
pub fn glossy_f90(m: &Material) -> f32 {
    m.layer_f90 + (1.0 - m.layer_f90) * m.metallic
}

/// The factor on the Kd lobe for light from `wi` toward `wo`: 1 without the layer, and with it
/// the share the layer lets through, 1 - max over channels of F_Schlick(`layer_f0`,
/// `layer_f90`, |wo . h|) at the half vector h of `wo` and `wi` (Appendix B's `fresnel_mix`
/// as `KHR_materials_specular` extends it: `1 - weight * max_value(fr)`).
#[inline]
fn diffuse_share<const LAYERED: bool>(m: &Material, wo: Vec3, wi: Vec3) -> f32 {
    if LAYERED {
        let h = (wo + wi).normalize();
        1.0 - schlick_f90(Vec3::from(m.layer_f0), m.layer_f90, wo.dot(h).abs()).max_element()
    } else {
        1.0
    }
}

/// `bsdf::eval` of the mixture: Kd/pi cos (times the layer's share) + D G F_Schlick(wi . h) /
/// (4 cos_o) (times the multiple-scattering factor of `albedo`, E at `wo`), density the
/// mixture of the cosine lobe and the visible-normal reflection; with the layer, under the
/// clear coat and the sheen where the material has them. Zero where `wo` is not above `n`
/// (rounding at grazing hits).
#[inline]
pub fn eval<const LAYERED: bool>(
    m: &Material,
    n: Vec3,
    wo: Vec3,
    wi: Vec3,
    albedo: GlossyAlbedo,
) -> (Vec3, f32) {
    let cos_o = n.dot(wo);
    let cos_i = n.dot(wi);
    if !(cos_o > 0.0) || !(cos_i > 0.0) {
        return (Vec3::ZERO, 0.0);
    }
    let p_glossy = glossy_lobe_probability(m, cos_o);
    let c = cos_i * (1.0 / PI);
    let mut f = Vec3::from(m.albedo) * (c * diffuse_share::<LAYERED>(m, wo, wi));
    let mut pdf = (1.0 - p_glossy) * c;
    if !(m.alpha < DELTA_ALPHA) {
        let r = if LAYERED {
            reflection_height_correlated(n, wo, wi, cos_o, cos_i, m.alpha)
        } else {
            reflection(n, wo, wi, cos_o, cos_i, m.alpha)
        };
        let (f0, f90) = (Vec3::from(m.specular), glossy_f90(m));
        let glossy = schlick_f90(f0, f90, wi.dot(r.h)) * r.value;
        f += if LAYERED {
            glossy * factor(albedo, f0, f90)
        } else {
            glossy
        };
        pdf += p_glossy * r.pdf;
    }
    if LAYERED && m.coat != 0 {
        let coat = coat::at(m, cos_o, albedo);
        if coat.weight > 0.0 {
            // Under glTF's clear coat (`coat`): the material's 1 - c, and the coat's rough
            // lobe (a smooth one is a delta lobe: in neither).
            f *= 1.0 - coat.weight;
            pdf *= 1.0 - coat.weight;
            if !(coat.alpha < DELTA_ALPHA) {
                let r = coat::reflection(&coat, n, wo, wi, cos_o, cos_i);
                f += Vec3::splat(coat::lobe_weight(m, wo, r.h, albedo) * r.value);
                pdf += coat.weight * r.pdf;
            }
        }
    }
    if LAYERED && albedo.sheen.z > 0.0 {
        // Over everything, glTF's sheen (`sheen`): the rest's 1 - s, and the sheen's lobe.
        // Its R is 0 where the material has none (`surface::glossy_albedo` looks it up only
        // for a sheen): one test of a number already at hand.
        let sheen = sheen::at(Vec3::from(m.sheen_colour()), albedo.sheen);
        if sheen.weight > 0.0 {
            let (value, density) = sheen::eval(&sheen, n, wo, wi);
            f = f * (1.0 - sheen.weight) + value;
            pdf = pdf * (1.0 - sheen.weight) + sheen.weight * density;
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
pub fn sample<const LAYERED: bool>(
    m: &Material,
    n: Vec3,
    wo: Vec3,
    albedo: GlossyAlbedo,
    u: Vec3,
) -> BsdfSample {
    let (mut u_lobe, u1, u2) = (u.x, u.y, u.z);
    let cos_o = n.dot(wo);
    if !(cos_o > 0.0) {
        return BsdfSample::NONE;
    }
    let mut sheen_weight = 0.0;
    if LAYERED && albedo.sheen.z > 0.0 {
        let sheen = sheen::at(Vec3::from(m.sheen_colour()), albedo.sheen);
        if u_lobe < sheen.weight {
            return sampled_sheen::<LAYERED>(&sheen, m, n, wo, albedo, (u1, u2));
        }
        // s < 1 here (u_lobe < 1).
        sheen_weight = sheen.weight;
        u_lobe = (u_lobe - sheen.weight) / (1.0 - sheen.weight);
    }
    let coat = if LAYERED && m.coat != 0 {
        coat::at(m, cos_o, albedo)
    } else {
        Coat::NONE
    };
    if coat.weight > 0.0 {
        if u_lobe < coat.weight {
            // The coat, chosen with probability c: a smooth one's mirror weighs c / c.
            if coat.alpha < DELTA_ALPHA {
                return BsdfSample::mirror(n, reflect(wo, n), Vec3::ONE);
            }
            let wi = reflect(wo, sample_visible_normal(n, wo, coat.alpha, u1, u2));
            return weighed::<LAYERED>(m, n, wo, wi, albedo);
        }
        // c < 1 here (u_lobe < 1).
        u_lobe = (u_lobe - coat.weight) / (1.0 - coat.weight);
    }
    let smooth = m.alpha < DELTA_ALPHA;
    let p_glossy = glossy_lobe_probability(m, cos_o);
    let glossy = u_lobe < p_glossy;
    if smooth && glossy {
        return BsdfSample::mirror(
            n,
            reflect(wo, n),
            schlick_f90(Vec3::from(m.specular), glossy_f90(m), cos_o) / p_glossy,
        );
    }
    let wi = if glossy {
        reflect(wo, sample_visible_normal(n, wo, m.alpha, u1, u2))
    } else {
        sample_brdf(n, u1, u2)
    };
    if smooth && coat.weight == 0.0 && sheen_weight == 0.0 {
        // The diffuse lobe beside a delta one: (Kd/pi cos) / ((1 - p) cos/pi), exactly.
        let weight =
            Vec3::from(m.albedo) * (diffuse_share::<LAYERED>(m, wo, wi) / (1.0 - p_glossy));
        return BsdfSample::reflected(wi, weight, (1.0 - p_glossy) * n.dot(wi) * (1.0 / PI));
    }
    weighed::<LAYERED>(m, n, wo, wi, albedo)
}

/// The sheen's sample (chosen with probability s) from numbers `u`, weighed by the whole
/// mixture. Kept out of line on the CPU: materials without a sheen never run it.
#[cfg_attr(not(target_arch = "spirv"), inline(never))]
fn sampled_sheen<const LAYERED: bool>(
    sheen: &Sheen,
    m: &Material,
    n: Vec3,
    wo: Vec3,
    albedo: GlossyAlbedo,
    u: (f32, f32),
) -> BsdfSample {
    let wi = sheen::sample(sheen, n, wo, u.0, u.1);
    weighed::<LAYERED>(m, n, wo, wi, albedo)
}

/// The sample of direction `wi` weighed f cos / pdf by [`eval`] (the whole mixture's value and
/// density, the delta lobes in neither), or none where the density is 0.
#[inline]
fn weighed<const LAYERED: bool>(
    m: &Material,
    n: Vec3,
    wo: Vec3,
    wi: Vec3,
    albedo: GlossyAlbedo,
) -> BsdfSample {
    let (f, pdf) = eval::<LAYERED>(m, n, wo, wi, albedo);
    if !(pdf > 0.0) {
        return BsdfSample::NONE;
    }
    BsdfSample::reflected(wi, f / pdf, pdf)
}
