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
//!     factor = 1 + F_ms (1 - E(mu_o)) / E(mu_o)     (per channel),
//!
//! which is 1 / E for F = 1 (Turquin's scale, the white furnace exact) and 1 where E = 1. This
//! is Cycles' `microfacet_ggx_preserve_energy`. The factor depends on `wo` alone: the
//! compensated lobe is not reciprocal (f(wo, wi) / factor(wo) is).
//!
//! E and E_avg come from a table (`GlossyAlbedo`), computed by quadrature on the host over
//! this kernel's own lobe (`microfacet`: GGX, separable Smith masking) at 32 roughnesses by 32
//! cosines (crowded toward grazing: node j at mu = (j / 31)^2) and stored as a float texture of the texture table (its record at word
//! `texture::GGX_ALBEDO`); `texture::ggx_albedo` interpolates it and `surface::glossy_albedo`
//! looks it up once per vertex. For Schlick's F with F0 and F90,
//! F_avg = F0 + (F90 - F0) / 21 (the integral of 2 mu (1 - mu)^5 over [0, 1] is 1/21).
//! Derivations and bounds: `docs/materials.md` ("Multiple scattering").

use spirv_std::glam::Vec3;

/// The directional albedo E(mu_o) of a GGX lobe (Fresnel factor 1) at a point's roughness and
/// view, and its hemispherical average E_avg: what the compensation divides by and weighs with.
/// [`GlossyAlbedo::NONE`] (both 1) is no compensation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlossyAlbedo {
    pub directional: f32,
    pub average: f32,
}

impl GlossyAlbedo {
    /// No energy lost, none given back: the factor is exactly 1.
    pub const NONE: Self = Self {
        directional: 1.0,
        average: 1.0,
    };
}

/// The factor on a Schlick lobe of reflectances `f0` (normal incidence) and `f90` (grazing):
/// 1 + F_ms (1 - E) / E, F_ms = F_avg E_avg / (1 - F_avg (1 - E_avg)), F_avg = F0 + (F90 -
/// F0) / 21. Exactly 1 for [`GlossyAlbedo::NONE`].
#[inline]
pub fn factor(albedo: GlossyAlbedo, f0: Vec3, f90: f32) -> Vec3 {
    let (e, e_avg) = (albedo.directional, albedo.average);
    let f_avg = f0 + (Vec3::splat(f90) - f0) * (1.0 / 21.0);
    let f_ms = f_avg * e_avg / (Vec3::ONE - f_avg * (1.0 - e_avg));
    Vec3::ONE + f_ms * ((1.0 - e) / e)
}
