//! The scattering of every [`Material`] kind (`scene::material_kind`) at a path vertex: its
//! value times the cosine, its density, its importance sampling and its flags. One file per
//! kind: `lambert` (DIFFUSE), `mixture` (GLOSSY, the seed's Kd + Ks), `metallic_roughness`
//! (glTF's), `conductor`, `dielectric`; `fresnel` and `microfacet` are what they share. This
//! module holds the one dispatch over kinds ([`flags`], [`eval`], [`sample`], [`at_point`],
//! [`apply_ks_texture`], [`material_features`]), pbrt-v4's tagged `BxDF`
//! dispatch in one `match`. The scattering is written once over any scalar [`Real`]
//! ([`eval_v3`], [`sample_v3`], reading the material through `inputs::BsdfNumbers`): [`eval`]
//! and [`sample`] are its `f32` instances, and a test's interval type bounds what a Vulkan
//! device's arithmetic may make of it (`docs/robustness.md`). `multiple_scattering` gives back
//! what a GGX lobe loses between its microfacets (glTF's material), `coat` its clear coat
//! (`KHR_materials_clearcoat`), `sheen` its sheen (`KHR_materials_sheen`).
//! Derivations and sources: `docs/materials.md`.
//!
//! Conventions: `wo` is the unit direction toward the previous vertex (the camera side), `wi`
//! the unit direction toward the next one (the light side); `n` is the unit normal on `wo`'s
//! side (`SurfaceHit::facing_normal`); `eta` is the index of refraction beyond the surface over
//! the index on `wo`'s side (only a dielectric reads it). Values are for radiance transport
//! (pbrt-v4's `TransportMode::Radiance`): refraction into a denser medium scales radiance by
//! 1 / eta^2.
//!
//! A kind's arm is compiled only where the scene's features allow it (`features`: its
//! `FEATURES` bits); a material whose kind no arm takes scatters nothing.

pub mod coat;
pub mod conductor;
pub mod dielectric;
pub mod fresnel;
pub mod inputs;
pub mod lambert;
pub mod metallic_roughness;
pub mod microfacet;
pub mod mixture;
pub mod multiple_scattering;
pub mod sheen;

use crate::features::FeatureSet;
use crate::real::{Real, V3};
use crate::scene::{material_kind, Material};
use inputs::BsdfNumbers;
use multiple_scattering::GlossyAlbedo;
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

/// [`BsdfSample`] over any scalar [`Real`]: what [`sample_v3`] returns.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSampleV3<R> {
    pub wi: V3<R>,
    pub weight: V3<R>,
    pub pdf: R,
    pub eta2: R,
    pub transmitted: bool,
}

impl<R: Real> BsdfSampleV3<R> {
    /// The sample that ends the path: no weight, density 0, `wi` +z.
    #[inline]
    pub fn none() -> Self {
        Self {
            wi: V3::splat(Vec3::Z),
            weight: V3::splat(Vec3::ZERO),
            pdf: R::splat(0.0),
            eta2: R::splat(1.0),
            transmitted: false,
        }
    }

    /// A reflected sample.
    #[inline]
    pub fn reflected(wi: V3<R>, weight: V3<R>, pdf: R) -> Self {
        Self {
            wi,
            weight,
            pdf,
            eta2: R::splat(1.0),
            transmitted: false,
        }
    }
}

impl<R: Real<Bits = u32>> BsdfSampleV3<R> {
    /// A delta lobe's reflection `wi` (about `n` or a microfacet), unless rounding put it
    /// below the surface (a grazing `wo` has a grazing mirror image): then the path ends, as
    /// for the rough lobes' directions below the surface.
    #[inline]
    pub fn mirror(n: V3<R>, wi: V3<R>, weight: V3<R>) -> Self {
        if n.dot(wi).greater_than(R::splat(0.0)) == 0 {
            return Self::none();
        }
        Self::reflected(wi, weight, R::splat(DELTA_PDF))
    }
}

impl From<BsdfSampleV3<f32>> for BsdfSample {
    #[inline]
    fn from(s: BsdfSampleV3<f32>) -> Self {
        Self {
            wi: s.wi.into(),
            weight: s.weight.into(),
            pdf: s.pdf,
            eta2: s.eta2,
            transmitted: s.transmitted,
        }
    }
}

/// The mirror direction of `wo` about unit `h`: 2 (wo . h) h - wo.
#[inline]
pub fn reflect<R: Real>(wo: V3<R>, h: V3<R>) -> V3<R> {
    h * (R::splat(2.0) * wo.dot(h)) - wo
}

/// What a path vertex asks of a material before it draws its numbers (pbrt-v4's
/// `BxDFFlags`): each kind's file states its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BsdfFlags {
    /// The scattering is a delta distribution only (a perfect mirror or refraction): no light
    /// sample can meet it, so its vertex takes none.
    pub delta: bool,
    /// [`sample`] reads the lobe-choice number `u_lobe` (the vertex draws it).
    pub chooses_lobe: bool,
}

/// The flags of material `m` (as `crate::surface::shade` left it at the point).
#[inline]
pub fn flags(m: &Material) -> BsdfFlags {
    match m.kind {
        material_kind::DIFFUSE => lambert::FLAGS,
        material_kind::GLOSSY => mixture::FLAGS,
        material_kind::METALLIC_ROUGHNESS => metallic_roughness::FLAGS,
        material_kind::CONDUCTOR => conductor::flags(m),
        material_kind::DIELECTRIC => dielectric::flags(m),
        // No arm scatters: nothing to sample, no lobe.
        _ => BsdfFlags {
            delta: true,
            chooses_lobe: false,
        },
    }
}

/// Whether `m` is the Lambertian surface, whose vertex the path computes with the diffuse
/// renderer's exact arithmetic (`path::PathState`).
#[inline]
pub fn is_lambertian(m: &Material) -> bool {
    m.kind == material_kind::DIFFUSE
}

/// The feature bits (`crate::features`) a scene with these materials needs: each kind's
/// `FEATURES`.
#[inline]
pub fn material_features(materials: &[Material]) -> u32 {
    let mut f = 0;
    for m in materials {
        f |= match m.kind {
            material_kind::GLOSSY => mixture::FEATURES,
            material_kind::CONDUCTOR => conductor::FEATURES,
            material_kind::DIELECTRIC => dielectric::FEATURES,
            material_kind::METALLIC_ROUGHNESS => metallic_roughness::FEATURES,
            _ => 0,
        };
    }
    f
}

/// Material `m` (textures applied) as [`eval`] and [`sample`] read it at the point: glTF's
/// metallic-roughness material resolved into the mixture's form
/// (`metallic_roughness::resolve`), every other kind as it is.
#[inline]
pub fn at_point<F: FeatureSet>(features: F, m: &Material) -> Material {
    match m.kind {
        material_kind::METALLIC_ROUGHNESS if features.metallic_roughness() => {
            metallic_roughness::resolve(m)
        }
        _ => *m,
    }
}

/// The `KS` texture's value `value` at a point applied to `m` (`crate::texture`): it
/// multiplies Ks, except for glTF's metallic-roughness material, whose map holds metalness and
/// roughness (`metallic_roughness::apply_ks_texture`).
#[inline]
pub fn apply_ks_texture(m: &mut Material, value: Vec3) {
    match m.kind {
        material_kind::METALLIC_ROUGHNESS => metallic_roughness::apply_ks_texture(m, value),
        _ => m.specular = (Vec3::from(m.specular) * value).to_array(),
    }
}

/// The non-delta part of the scattering from `wi` toward `wo`: (f |n . wi|, the density with
/// which [`sample`] draws `wi`, per unit solid angle). Delta lobes contribute to neither (no
/// direction given in advance meets them). `features` keeps only the kinds the scene may have;
/// `albedo` is `surface::glossy_albedo` at the point for `wo` (what the glossy lobe of glTF's
/// material loses to multiple scattering; `GlossyAlbedo::NONE` for every other kind).
#[inline]
pub fn eval<F: FeatureSet>(
    features: F,
    m: &Material,
    n: Vec3,
    wo: Vec3,
    wi: Vec3,
    eta: f32,
    albedo: GlossyAlbedo,
) -> (Vec3, f32) {
    let (f, pdf) = eval_v3(
        features,
        m,
        V3::from(n),
        V3::from(wo),
        V3::from(wi),
        eta,
        albedo,
    );
    (f.into(), pdf)
}

/// [`eval`] over any scalar [`Real`], in the same operations: the `f32` instance is [`eval`]'s
/// arithmetic, another type bounds it (`tests/src/device_class.rs`).
#[inline]
pub fn eval_v3<F: FeatureSet, R: Real<Bits = u32>>(
    features: F,
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    wi: V3<R>,
    eta: R,
    albedo: GlossyAlbedo<R>,
) -> (V3<R>, R) {
    match m.kind() {
        material_kind::DIFFUSE => lambert::eval(m, n, wi),
        material_kind::GLOSSY if features.has_all(mixture::FEATURES) => {
            mixture::eval::<false, R>(m, n, wo, wi, GlossyAlbedo::none())
        }
        material_kind::METALLIC_ROUGHNESS if features.has_all(metallic_roughness::FEATURES) => {
            metallic_roughness::eval(m, n, wo, wi, albedo)
        }
        material_kind::CONDUCTOR if features.has_all(conductor::FEATURES) => {
            conductor::eval(m, n, wo, wi)
        }
        material_kind::DIELECTRIC if features.has_all(dielectric::FEATURES) => {
            dielectric::eval(m, n, wo, wi, eta)
        }
        _ => (V3::splat(Vec3::ZERO), R::splat(0.0)),
    }
}

/// Draws `wi` for `wo` from the material's lobes: `u_lobe` chooses a lobe (where
/// [`BsdfFlags::chooses_lobe`]), `(u1, u2)` the direction within it. The weight is
/// f |n . wi| / pdf in the forms that cancel analytically (a conductor's F G1(wi); a
/// dielectric's G1(wi), over eta^2 after a refraction; exactly 1 for smooth reflection), and
/// computed for the Kd + Ks mixture. `albedo` as for [`eval`].
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn sample<F: FeatureSet>(
    features: F,
    m: &Material,
    n: Vec3,
    wo: Vec3,
    eta: f32,
    albedo: GlossyAlbedo,
    u_lobe: f32,
    u1: f32,
    u2: f32,
) -> BsdfSample {
    sample_v3(
        features,
        m,
        V3::from(n),
        V3::from(wo),
        eta,
        albedo,
        (u_lobe, u1, u2),
    )
    .into()
}

/// [`sample`] over any scalar [`Real`], in the same operations, with `u` = (u_lobe, u1, u2).
#[inline]
pub fn sample_v3<F: FeatureSet, R: Real<Bits = u32>>(
    features: F,
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    wo: V3<R>,
    eta: R,
    albedo: GlossyAlbedo<R>,
    (u_lobe, u1, u2): (R, R, R),
) -> BsdfSampleV3<R> {
    match m.kind() {
        material_kind::DIFFUSE => lambert::sample(m, n, u1, u2),
        material_kind::GLOSSY if features.has_all(mixture::FEATURES) => {
            mixture::sample::<false, R>(m, n, wo, GlossyAlbedo::none(), (u_lobe, u1, u2))
        }
        material_kind::METALLIC_ROUGHNESS if features.has_all(metallic_roughness::FEATURES) => {
            metallic_roughness::sample(m, n, wo, albedo, (u_lobe, u1, u2))
        }
        material_kind::CONDUCTOR if features.has_all(conductor::FEATURES) => {
            conductor::sample(m, n, wo, u1, u2)
        }
        material_kind::DIELECTRIC if features.has_all(dielectric::FEATURES) => {
            dielectric::sample(m, n, wo, eta, u_lobe, u1, u2)
        }
        _ => BsdfSampleV3::none(),
    }
}
