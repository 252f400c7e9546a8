//! The scattering of every [`Material`] kind (`scene::material_kind`) at a path vertex:
//! its value times the cosine, its density, and its importance sampling. The Lambertian
//! surface keeps its own exact form in `brdf`; this module adds the seed's Kd + Ks BRDF, the
//! conductor and the dielectric, rough (GGX, `microfacet`) or smooth (delta). Derivations and
//! sources: `docs/materials.md`.
//!
//! Conventions: `wo` is the unit direction toward the previous vertex (the camera side), `wi`
//! the unit direction toward the next one (the light side); `n` is the unit normal on `wo`'s
//! side (`SurfaceHit::facing_normal`); `eta` is the index of refraction beyond the surface over
//! the index on `wo`'s side (only a dielectric reads it). Values are for radiance transport
//! (pbrt-v4's `TransportMode::Radiance`): refraction into a denser medium scales radiance by
//! 1 / eta^2.

use crate::brdf::{eval_scattering, pdf_brdf, sample_brdf, sampled_brdf_weight};
use crate::features::FeatureSet;
use crate::fresnel::{conductor_rgb, dielectric, dielectric_transmittance, refract, schlick};
use crate::microfacet::{
    ggx_d, ggx_g1, normal_angle, pdf_reflected, reflection, sample_visible_normal,
};
use crate::scene::{material_kind, Material};
use core::f32::consts::PI;
use spirv_std::glam::Vec3;

/// Roughness below which a lobe is a perfect mirror or refraction (a delta distribution),
/// pbrt-v4's `EffectivelySmooth` threshold: GGX with alpha < 1e-3 has D up to 1/(pi 1e-6),
/// beyond which f32 sampling and evaluation lose the lobe's shape.
pub const DELTA_ALPHA: f32 = 1e-3;

/// The density [`BsdfSample::pdf`] gives a delta lobe's direction: infinite relative to any
/// solid-angle density, so the power heuristic gives a light found along it weight 1.
pub const DELTA_PDF: f32 = f32::INFINITY;

/// A direction drawn by [`sample`], with what the path multiplies its throughput by.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    /// f |n . wi| / pdf: what the throughput is multiplied by (zero: the path ends).
    pub weight: Vec3,
    /// The density of `wi` per unit solid angle (the whole mixture's), or [`DELTA_PDF`].
    pub pdf: f32,
    /// eta^2 of a refraction (index on `wi`'s side over `wo`'s, squared), 1 for a reflection:
    /// the factor by which `weight` holds 1 / eta^2, which Russian roulette leaves out.
    pub eta2: f32,
    /// Whether `wi` crossed the surface (leaves on the side opposite `n`).
    pub transmitted: bool,
}

impl BsdfSample {
    /// The sample that ends the path.
    const NONE: Self = Self {
        wi: Vec3::Z,
        weight: Vec3::ZERO,
        pdf: 0.0,
        eta2: 1.0,
        transmitted: false,
    };
}

/// Whether the material's scattering is a delta distribution only (a perfect mirror or
/// refraction): no light sample can meet it, so its vertex takes none.
#[inline]
pub fn is_delta(m: &Material) -> bool {
    !has_diffuse_lobe(m) && m.alpha < DELTA_ALPHA
}

/// Whether the material has a Lambertian lobe (the Lambertian surface, the Kd + Ks mixture and
/// glTF's metallic-roughness material), which no roughness makes a delta distribution.
#[inline]
fn has_diffuse_lobe(m: &Material) -> bool {
    m.kind == material_kind::DIFFUSE
        || m.kind == material_kind::GLOSSY
        || m.kind == material_kind::METALLIC_ROUGHNESS
}

/// Whether the Kd + Ks code evaluates and samples `m`: the seed's mixture, and glTF's
/// metallic-roughness material once resolved ([`resolve_metallic_roughness`]).
#[inline]
fn is_glossy<F: FeatureSet>(features: F, m: &Material) -> bool {
    features.glossy()
        && (m.kind == material_kind::GLOSSY
            || (features.metallic_roughness() && m.kind == material_kind::METALLIC_ROUGHNESS))
}

/// glTF's dielectric reflectance at normal incidence, ((1 - 1.5) / (1 + 1.5))^2 (glTF 2.0,
/// Appendix B, "dielectric_brdf", index 1.5).
pub const GLTF_DIELECTRIC_F0: f32 = 0.04;

/// glTF 2.0's metallic-roughness material (Appendix B) in the Kd + Ks form [`eval`] reads,
/// from its base colour (`albedo`), `metallic` and `roughness` as textures left them:
///
/// `mix(dielectric_brdf, metal_brdf, metallic)` with
/// `dielectric_brdf = fresnel_mix(0.04; diffuse(base), specular)` and
/// `metal_brdf = specular * F_Schlick(F0 = base)`. The specular lobes share D and G, and
/// Schlick's F is affine in F0, so their sum is one GGX lobe with
/// F_Schlick(F0 = lerp(0.04, base, metallic)) (`specular`), and the diffuse part is
/// `(1 - metallic) base / pi` (`albedo`) weighed by 1 - F_Schlick(0.04, |wo . h|)
/// ([`diffuse_share`]); alpha = roughness^2. The kind stays METALLIC_ROUGHNESS, which is what
/// selects that weight.
#[inline]
pub fn resolve_metallic_roughness(m: &Material) -> Material {
    let mut r = *m;
    let base = Vec3::from(m.albedo);
    let metallic = m.metallic;
    r.albedo = (base * (1.0 - metallic)).to_array();
    r.specular = (Vec3::splat(GLTF_DIELECTRIC_F0) * (1.0 - metallic) + base * metallic).to_array();
    r.alpha = m.roughness * m.roughness;
    r
}

/// The factor on the Kd lobe for light from `wi` toward `wo`: 1 for the seed's mixture, and
/// for glTF's material the share its dielectric layer lets through, 1 - F_Schlick(0.04,
/// |wo . h|) at the half vector h of `wo` and `wi` (Appendix B's `fresnel_mix`).
#[inline]
fn diffuse_share<F: FeatureSet>(features: F, m: &Material, wo: Vec3, wi: Vec3) -> f32 {
    if features.metallic_roughness() && m.kind == material_kind::METALLIC_ROUGHNESS {
        let h = (wo + wi).normalize();
        1.0 - schlick(Vec3::splat(GLTF_DIELECTRIC_F0), wo.dot(h).abs()).x
    } else {
        1.0
    }
}

/// Whether [`sample`] reads the lobe-choice number `u_lobe`: the Kd + Ks mixture chooses its
/// lobe, the dielectric reflection or refraction.
#[inline]
pub fn chooses_lobe(m: &Material) -> bool {
    m.kind == material_kind::GLOSSY
        || m.kind == material_kind::DIELECTRIC
        || m.kind == material_kind::METALLIC_ROUGHNESS
}

/// The probability that the Kd + Ks mixture samples its glossy lobe from `wo` at cosine
/// `cos_o`: each lobe in proportion to an estimate of its albedo, mean(Kd) for the diffuse
/// and mean(F_Schlick(cos_o)) for the glossy (the masking left out); 0 when both are 0.
#[inline]
pub fn glossy_lobe_probability(m: &Material, cos_o: f32) -> f32 {
    let fd = Vec3::from(m.albedo).dot(Vec3::ONE);
    let fs = schlick(Vec3::from(m.specular), cos_o).dot(Vec3::ONE);
    if fd + fs > 0.0 {
        fs / (fd + fs)
    } else {
        0.0
    }
}

/// A conductor's Fresnel reflectance at cosine `cos`: exact for its complex index, or its
/// constant reflectance.
#[inline]
fn conductor_fresnel(m: &Material, cos: f32) -> Vec3 {
    if m.complex != 0 {
        conductor_rgb(cos, Vec3::from(m.eta), Vec3::from(m.k))
    } else {
        Vec3::from(m.specular)
    }
}

/// The mirror direction of `wo` about unit `h`.
#[inline]
fn reflect(wo: Vec3, h: Vec3) -> Vec3 {
    2.0 * wo.dot(h) * h - wo
}

/// The non-delta part of the scattering from `wi` toward `wo`: (f |n . wi|, the density with
/// which [`sample`] draws `wi`, per unit solid angle). Delta lobes contribute to neither (no
/// direction given in advance meets them). Zero where `wo` is not above `n` (rounding at
/// grazing hits) for the microfacet lobes. `features` keeps only the kinds the scene may have.
#[inline]
pub fn eval<F: FeatureSet>(
    features: F,
    m: &Material,
    n: Vec3,
    wo: Vec3,
    wi: Vec3,
    eta: f32,
) -> (Vec3, f32) {
    let cos_o = n.dot(wo);
    let cos_i = n.dot(wi);
    if m.kind == material_kind::DIFFUSE {
        return (
            eval_scattering(n, wi, Vec3::from(m.albedo)),
            pdf_brdf(n, wi),
        );
    }
    if !(cos_o > 0.0) {
        return (Vec3::ZERO, 0.0);
    }
    if is_glossy(features, m) {
        eval_glossy(features, m, n, wo, wi, cos_o, cos_i)
    } else if m.alpha < DELTA_ALPHA {
        (Vec3::ZERO, 0.0)
    } else if features.conductor() && m.kind == material_kind::CONDUCTOR {
        eval_conductor(m, n, wo, wi, cos_o, cos_i)
    } else if features.dielectric() && m.kind == material_kind::DIELECTRIC {
        eval_dielectric(m, n, wo, wi, cos_o, cos_i, eta)
    } else {
        (Vec3::ZERO, 0.0)
    }
}

/// [`eval`] of the Kd + Ks mixture: Kd/pi cos (times [`diffuse_share`]) + D G F_Schlick(wi . h)
/// / (4 cos_o), density the mixture of the cosine lobe and the visible-normal reflection.
#[inline]
fn eval_glossy<F: FeatureSet>(
    features: F,
    m: &Material,
    n: Vec3,
    wo: Vec3,
    wi: Vec3,
    cos_o: f32,
    cos_i: f32,
) -> (Vec3, f32) {
    if !(cos_i > 0.0) {
        return (Vec3::ZERO, 0.0);
    }
    let p_glossy = glossy_lobe_probability(m, cos_o);
    let c = cos_i * (1.0 / PI);
    let mut f = Vec3::from(m.albedo) * (c * diffuse_share(features, m, wo, wi));
    let mut pdf = (1.0 - p_glossy) * c;
    if !(m.alpha < DELTA_ALPHA) {
        let r = reflection(n, wo, wi, cos_o, cos_i, m.alpha);
        f += schlick(Vec3::from(m.specular), wi.dot(r.h)) * r.value;
        pdf += p_glossy * r.pdf;
    }
    (f, pdf)
}

/// [`eval`] of a rough conductor: F(wo . h) D G / (4 cos_o).
#[inline]
fn eval_conductor(
    m: &Material,
    n: Vec3,
    wo: Vec3,
    wi: Vec3,
    cos_o: f32,
    cos_i: f32,
) -> (Vec3, f32) {
    if !(cos_i > 0.0) {
        return (Vec3::ZERO, 0.0);
    }
    let r = reflection(n, wo, wi, cos_o, cos_i, m.alpha);
    (conductor_fresnel(m, wo.dot(r.h)) * r.value, r.pdf)
}

/// [`eval`] of a rough dielectric: Walter et al. 2007, eqs. 20-21 (radiance transport).
#[inline]
fn eval_dielectric(
    m: &Material,
    n: Vec3,
    wo: Vec3,
    wi: Vec3,
    cos_o: f32,
    cos_i: f32,
    eta: f32,
) -> (Vec3, f32) {
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

/// Draws `wi` for `wo` from the material's lobes: `u_lobe` chooses a lobe (where
/// [`chooses_lobe`]), `(u1, u2)` the direction within it. The weight is f |n . wi| / pdf in the
/// forms that cancel analytically (a conductor's F G1(wi); a dielectric's G1(wi), over eta^2
/// after a refraction; exactly 1 for smooth reflection), and computed for the Kd + Ks mixture.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn sample<F: FeatureSet>(
    features: F,
    m: &Material,
    n: Vec3,
    wo: Vec3,
    eta: f32,
    u_lobe: f32,
    u1: f32,
    u2: f32,
) -> BsdfSample {
    let cos_o = n.dot(wo);
    if m.kind == material_kind::DIFFUSE {
        let wi = sample_brdf(n, u1, u2);
        return reflected(
            wi,
            sampled_brdf_weight(Vec3::from(m.albedo)),
            pdf_brdf(n, wi),
        );
    }
    if !(cos_o > 0.0) {
        return BsdfSample::NONE;
    }
    if is_glossy(features, m) {
        sample_glossy(features, m, n, wo, cos_o, u_lobe, u1, u2)
    } else if features.conductor() && m.kind == material_kind::CONDUCTOR {
        sample_conductor(m, n, wo, cos_o, u1, u2)
    } else if features.dielectric() && m.kind == material_kind::DIELECTRIC {
        sample_dielectric(m, n, wo, cos_o, eta, u_lobe, u1, u2)
    } else {
        BsdfSample::NONE
    }
}

/// [`sample`] of the Kd + Ks mixture.
#[inline]
#[allow(clippy::too_many_arguments)]
fn sample_glossy<F: FeatureSet>(
    features: F,
    m: &Material,
    n: Vec3,
    wo: Vec3,
    cos_o: f32,
    u_lobe: f32,
    u1: f32,
    u2: f32,
) -> BsdfSample {
    let smooth = m.alpha < DELTA_ALPHA;
    let p_glossy = glossy_lobe_probability(m, cos_o);
    let glossy = u_lobe < p_glossy;
    if smooth && glossy {
        return mirror(
            n,
            reflect(wo, n),
            schlick(Vec3::from(m.specular), cos_o) / p_glossy,
        );
    }
    let wi = if glossy {
        reflect(wo, sample_visible_normal(n, wo, m.alpha, u1, u2))
    } else {
        sample_brdf(n, u1, u2)
    };
    if smooth {
        // The diffuse lobe beside a delta one: (Kd/pi cos) / ((1 - p) cos/pi), exactly.
        let weight = Vec3::from(m.albedo) * (diffuse_share(features, m, wo, wi) / (1.0 - p_glossy));
        return reflected(wi, weight, (1.0 - p_glossy) * n.dot(wi) * (1.0 / PI));
    }
    let (f, pdf) = eval(features, m, n, wo, wi, 1.0);
    if !(pdf > 0.0) {
        return BsdfSample::NONE;
    }
    reflected(wi, f / pdf, pdf)
}

/// [`sample`] of a conductor.
#[inline]
fn sample_conductor(m: &Material, n: Vec3, wo: Vec3, cos_o: f32, u1: f32, u2: f32) -> BsdfSample {
    if m.alpha < DELTA_ALPHA {
        return mirror(n, reflect(wo, n), conductor_fresnel(m, cos_o));
    }
    let h = sample_visible_normal(n, wo, m.alpha, u1, u2);
    let wi = reflect(wo, h);
    let cos_i = n.dot(wi);
    if !(cos_i > 0.0) {
        return BsdfSample::NONE;
    }
    let weight = conductor_fresnel(m, wo.dot(h)) * ggx_g1(cos_i, m.alpha);
    reflected(
        wi,
        weight,
        pdf_reflected(cos_o, normal_angle(n, h), m.alpha),
    )
}

/// [`sample`] of a dielectric: a microfacet normal (n itself when smooth), then reflection
/// with the probability F of its Fresnel reflectance, else refraction.
#[inline]
#[allow(clippy::too_many_arguments)]
fn sample_dielectric(
    m: &Material,
    n: Vec3,
    wo: Vec3,
    cos_o: f32,
    eta: f32,
    u_lobe: f32,
    u1: f32,
    u2: f32,
) -> BsdfSample {
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
            return mirror(n, wi, Vec3::ONE);
        }
        let cos_i = n.dot(wi);
        if !(cos_i > 0.0) {
            return BsdfSample::NONE;
        }
        let pdf = fresnel * pdf_reflected(cos_o, normal_angle(n, h), m.alpha);
        return reflected(wi, Vec3::splat(ggx_g1(cos_i, m.alpha)), pdf);
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

/// A delta lobe's reflection `wi` (about `n` or a microfacet), unless rounding put it below
/// the surface (a grazing `wo` has a grazing mirror image): then the path ends, as for the
/// rough lobes' directions below the surface.
#[inline]
fn mirror(n: Vec3, wi: Vec3, weight: Vec3) -> BsdfSample {
    if !(n.dot(wi) > 0.0) {
        return BsdfSample::NONE;
    }
    reflected(wi, weight, DELTA_PDF)
}

/// A reflected sample.
#[inline]
fn reflected(wi: Vec3, weight: Vec3, pdf: f32) -> BsdfSample {
    BsdfSample {
        wi,
        weight,
        pdf,
        eta2: 1.0,
        transmitted: false,
    }
}
