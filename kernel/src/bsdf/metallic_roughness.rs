//! glTF 2.0's metallic-roughness material (`material_kind::METALLIC_ROUGHNESS`; the
//! specification's Appendix B), stored as base colour (`albedo`), `metallic` and `roughness`
//! and resolved at each point ([`resolve`], after its textures) into the `mixture`'s Kd + Ks
//! form with the dielectric layer, which evaluates and samples it.

use super::inputs::{BsdfInputs, BsdfNumbers};
use super::mixture;
use super::multiple_scattering::GlossyAlbedo;
use super::{BsdfFlags, BsdfSampleV3};
use crate::features;
use crate::real::{Real, V3};
use crate::scene::Material;
use spirv_std::glam::Vec3;

/// The feature bits of a scene with this kind: the mixture's code and the layer's weight.
pub const FEATURES: u32 = features::GLOSSY | features::METALLIC_ROUGHNESS;

/// The mixture's flags: a Lambertian lobe beside the glossy one.
pub const FLAGS: BsdfFlags = mixture::FLAGS;

/// The material in the Kd + Ks form the mixture reads, from its base colour (`albedo`),
/// `metallic` and `roughness` as textures left them:
///
/// `mix(dielectric_brdf, metal_brdf, metallic)` with
/// `dielectric_brdf = fresnel_mix(layer_f0, layer_f90; diffuse(base), specular)` (0.04 and 1
/// by default; `KHR_materials_specular` and `KHR_materials_ior` set them) and
/// `metal_brdf = specular * F_Schlick(F0 = base, F90 = 1)`. The specular lobes share D and G,
/// and Schlick's F is affine in F0 and F90, so their sum is one GGX lobe with
/// F0 = lerp(layer_f0, base, metallic) (`specular`) and F90 = lerp(layer_f90, 1, metallic)
/// (`mixture::glossy_f90`), and the diffuse part is `(1 - metallic) base / pi` (`albedo`)
/// weighed by 1 - max F_Schlick(layer_f0, layer_f90, |wo . h|) (the mixture's layer);
/// alpha = roughness^2. The kind stays METALLIC_ROUGHNESS, which is what selects that weight.
#[inline]
pub fn resolve(m: &Material) -> Material {
    let resolved = resolve_v3::<f32>(m, m.roughness);
    let mut r = *m;
    r.albedo = Vec3::from(resolved.albedo).to_array();
    r.specular = Vec3::from(resolved.specular).to_array();
    r.alpha = resolved.alpha;
    r
}

/// [`resolve`] over any scalar [`Real`], in the same operations: `m`'s scattering numbers with
/// Kd, Ks and alpha resolved from `roughness` (`m.roughness`, or what computed it over `R`),
/// the others as they are.
#[inline]
pub fn resolve_v3<R: Real>(m: &Material, roughness: R) -> BsdfInputs<R> {
    let mut r = BsdfInputs::of(m);
    let base = r.albedo;
    let one_less = R::splat(1.0) - r.metallic;
    r.albedo = base * one_less;
    r.specular = r.layer_f0 * one_less + base * r.metallic;
    r.alpha = roughness * roughness;
    r
}

/// glTF's metallic-roughness map's value `value` at a point applied to `m`: blue is metalness,
/// green roughness.
#[inline]
pub fn apply_ks_texture(m: &mut Material, value: Vec3) {
    m.metallic *= value.z;
    m.roughness *= value.y;
}

/// `bsdf::eval` of the resolved material: the mixture's, with the layer and the glossy lobe's
/// multiple scattering given back (`albedo`: the GGX albedo at the point's roughness and `wo`,
/// `surface::glossy_albedo`).
#[inline]
pub fn eval<R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    wi: V3<R>,
    albedo: GlossyAlbedo<R>,
) -> (V3<R>, R) {
    mixture::eval::<true, R>(m, n, wo, wi, albedo)
}

/// `bsdf::sample` of the resolved material: the mixture's, as [`eval`].
#[inline]
pub fn sample<R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    albedo: GlossyAlbedo<R>,
    u: (R, R, R),
) -> BsdfSampleV3<R> {
    mixture::sample::<true, R>(m, n, wo, albedo, u)
}
