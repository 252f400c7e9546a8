//! The energy a GGX lobe loses to multiple scattering between its microfacets, given back
//! (glTF's metallic-roughness material, as Cycles' multiscatter GGX gives it back).
//!
//! A single-scattering microfacet lobe with Fresnel factor 1 reflects E(mu_o) < 1 of the light
//! arriving from the direction at cosine mu_o, its *directional albedo*; the rest, 1 - E, leaves
//! after bouncing between microfacets, which the single-scattering model drops (a rough metal of
//! reflectance 1 is grey in a white furnace). Turquin ("Practical multiple scattering
//! compensation for microfacet models", 2019) scales the lobe by 1 / E(mu_o), so that its albedo
//! is 1 for every mu_o when F = 1, keeping its shape. With a Fresnel factor the light that
//! bounces k times more is weighed by F k times: Kulla and Conty ("Revisiting Physically Based
//! Shading at Imageworks", SIGGRAPH 2017 course, section on multiple scattering) sum that
//! geometric series with the hemispherical averages F_avg (the Fresnel factor's cosine-weighted
//! mean) and E_avg (the albedo's): the extra energy is (1 - E(mu_o)) F_ms with
//! F_ms = F_avg E_avg / (1 - F_avg (1 - E_avg)) (their F_ms with one F_avg less, since the
//! scaled lobe already carries one Fresnel factor). So the lobe is multiplied by
//!
//! ```text
//! factor = 1 + F_ms (1 - E(mu_o)) / E(mu_o)     (per channel),
//! ```
//!
//! which is 1 / E for F = 1 (Turquin's scale, the white furnace exact) and 1 where E = 1. This
//! is Cycles' `microfacet_ggx_preserve_energy`. The factor depends on `wo` alone: the
//! compensated lobe is not reciprocal (f(wo, wi) / factor(wo) is).
//!
//! E and E_avg come from a table (`GlossyAlbedo`), computed by quadrature on the host over
//! this kernel's own lobe (`microfacet::reflection_height_correlated`: GGX, height-correlated
//! Smith G2) at 32 roughnesses by 32 cosines (crowded toward grazing: node j at
//! mu = (j / 31)^2) and stored as a float texture of the texture table (its record at word
//! `texture::GGX_ALBEDO`); `texture::ggx_albedo` interpolates it and `surface::glossy_albedo`
//! looks it up once per vertex. For Schlick's F with F0 and F90, F_avg = F0 + (F90 - F0) / 21
//! (the integral of 2 mu (1 - mu)^5 over [0, 1] is 1/21).
//! Derivations and bounds: `docs/materials.md` ("Multiple scattering").

use crate::real::{Real, V3};
use spirv_std::glam::Vec3;

/// The directional albedo E(mu_o) of a point's GGX lobes (Fresnel factor 1) at their
/// roughness and its view, and their hemispherical averages E_avg: the material's glossy lobe's
/// (`directional`, `average`) and its clear coat's (`coat_directional`, `coat_average`; `coat`).
/// What the compensation divides by and weighs with; 1 (as in [`GlossyAlbedo::NONE`]) is no
/// compensation. Over any scalar [`Real`] (`f32` unless said), as `bsdf::eval_v3` reads it.
#[derive(Clone, Copy, Debug)]
pub struct GlossyAlbedo<R = f32> {
    pub directional: R,
    pub average: R,
    pub coat_directional: R,
    pub coat_average: R,
    /// The coat lobe's directional albedo with its Fresnel factor F(wo . h) (index 1.5), before
    /// its weight and its compensation: what the coat reflects of light from everywhere, and so
    /// what it takes from the material below (`coat`).
    pub coat_reflectance: R,
    /// The sheen's linearly transformed cosine (A, B, R) at its roughness and the view
    /// (`sheen`, `texture::sheen_ltc`); R = 0: no sheen.
    pub sheen: V3<R>,
}

impl GlossyAlbedo {
    /// No energy lost, none given back: every factor is exactly 1.
    /// (`coat_reflectance` 1: a rough coat needs the table's; `sheen` zero: no sheen lobe.)
    pub const NONE: Self = Self {
        directional: 1.0,
        average: 1.0,
        coat_directional: 1.0,
        coat_average: 1.0,
        coat_reflectance: 1.0,
        sheen: V3 {
            x: 0.0,
            y: 0.0,
            z: 0.0,
        },
    };
}

impl<R: Real> GlossyAlbedo<R> {
    /// [`GlossyAlbedo::NONE`] over `R`.
    #[inline]
    pub fn none() -> Self {
        let one = R::splat(1.0);
        Self {
            directional: one,
            average: one,
            coat_directional: one,
            coat_average: one,
            coat_reflectance: one,
            sheen: V3::splat(Vec3::ZERO),
        }
    }
}

/// The cosine-weighted hemispherical average of the exact Fresnel reflectance of a dielectric of
/// index 1.5 seen from outside, 2 \int_0^1 F(mu) mu dmu (`tests/multiple_scattering.rs`
/// integrates it): the clear coat's F_avg.
pub const COAT_FRESNEL_AVERAGE: f32 = 0.091_777_96;

/// The factor on the clear coat's lobe (`coat`): 1 + F_ms (1 - E) / E with the coat's albedos
/// and F_avg = [`COAT_FRESNEL_AVERAGE`], as Cycles gives its coat's energy back. Over any
/// scalar [`Real`].
#[inline]
pub fn coat_factor<R: Real>(albedo: GlossyAlbedo<R>) -> R {
    let (e, e_avg) = (albedo.coat_directional, albedo.coat_average);
    let (one, f_avg) = (R::splat(1.0), R::splat(COAT_FRESNEL_AVERAGE));
    let f_ms = f_avg * e_avg / (one - f_avg * (one - e_avg));
    one + f_ms * ((one - e) / e)
}

/// The factor on a Schlick lobe of reflectances `f0` (normal incidence) and `f90` (grazing):
/// 1 + F_ms (1 - E) / E, F_ms = F_avg E_avg / (1 - F_avg (1 - E_avg)), F_avg = F0 + (F90 -
/// F0) / 21, per channel. Exactly 1 for [`GlossyAlbedo::NONE`].
#[inline]
pub fn factor<R: Real>(albedo: GlossyAlbedo<R>, f0: V3<R>, f90: R) -> V3<R> {
    let (e, e_avg) = (albedo.directional, albedo.average);
    let one = R::splat(1.0);
    let (rest, scale) = (one - e_avg, (one - e) / e);
    let channel = |f0: R| {
        let f_avg = f0 + (f90 - f0) * R::splat(1.0 / 21.0);
        let f_ms = f_avg * e_avg / (one - f_avg * rest);
        one + f_ms * scale
    };
    V3::new(channel(f0.x), channel(f0.y), channel(f0.z))
}
