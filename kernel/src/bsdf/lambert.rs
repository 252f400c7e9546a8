//! The two-sided Lambertian BRDF, f = Kd / pi (`material_kind::DIFFUSE`). `n` is always the
//! normal flipped to the side the light leaves toward (the side of the outgoing direction), so
//! both sides reflect alike. The path's Lambertian vertex (`path::PathState`) and the CPU's
//! packets call these functions directly; [`eval`] and [`sample`] are the kind's entries in
//! `bsdf`'s dispatch.

use super::inputs::BsdfNumbers;
use super::{BsdfFlags, BsdfSampleV3};
use crate::real::{self, V3};
use crate::sampling::{
    pdf_cosine_hemisphere, pdf_cosine_hemisphere_v3, sample_cosine_hemisphere_v3,
};
use spirv_std::glam::Vec3;

/// Seed: `EvalScattering(N, w_i)`. The BRDF times the cosine at the receiver,
/// f(w_i) max(0, n . w_i) = Kd / pi * max(0, n . w_i): the factor the rendering equation
/// integrates against incoming radiance per unit solid angle. The seed's |n . w_i| would let
/// light arrive through the back of the surface; with `n` on the outgoing side it must be zero.
#[inline]
pub fn eval_scattering(n: Vec3, wi: Vec3, albedo: Vec3) -> Vec3 {
    albedo * pdf_cosine_hemisphere(n, wi)
}

/// Seed: `SampleBrdf(N)`. Direction w_i = SampleLobe(n, sqrt(u1), 2 pi u2): cosine-weighted, the
/// importance sampling of the Lambertian `eval_scattering`.
#[inline]
pub fn sample_brdf(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    sample_brdf_v3(V3::from(n), u1, u2).into()
}

/// [`sample_brdf`] for one normal, or one per lane ([`real::Real`]: the CPU's packets).
#[inline]
pub fn sample_brdf_v3<R: real::Real>(n: V3<R>, u1: R, u2: R) -> V3<R> {
    sample_cosine_hemisphere_v3(n, u1, u2)
}

/// Seed: `PdfBrdf(N, w_i)`. Solid-angle density of [`sample_brdf`]: max(0, n . w_i) / pi.
#[inline]
pub fn pdf_brdf(n: Vec3, wi: Vec3) -> f32 {
    pdf_cosine_hemisphere(n, wi)
}

/// The throughput factor f cos(theta) / p for a direction drawn by [`sample_brdf`], simplified
/// analytically: (Kd/pi cos) / (cos/pi) = Kd. Computing the ratio numerically would leave
/// rounding of the cancelling cosines in it (a white furnace would drift from exactly 1).
#[inline]
pub fn sampled_brdf_weight(albedo: Vec3) -> Vec3 {
    albedo
}

/// The kind's flags: a Lambertian lobe, never a delta distribution, one lobe.
pub const FLAGS: BsdfFlags = BsdfFlags {
    delta: false,
    chooses_lobe: false,
};

/// The kind's entry in `bsdf::eval`: (f |n . wi|, the density of [`sample`]), over any
/// scalar [`real::Real`] in [`eval_scattering`]'s and [`pdf_brdf`]'s operations.
#[inline]
pub fn eval<R: real::Real<Bits = u32>>(m: &impl BsdfNumbers<R>, n: V3<R>, wi: V3<R>) -> (V3<R>, R) {
    let c = pdf_cosine_hemisphere_v3(n, wi);
    (m.albedo() * c, c)
}

/// The kind's entry in `bsdf::sample`: a cosine-weighted direction, weight exactly Kd.
#[inline]
pub fn sample<R: real::Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    n: V3<R>,
    u1: R,
    u2: R,
) -> BsdfSampleV3<R> {
    let wi = sample_brdf_v3(n, u1, u2);
    BsdfSampleV3::reflected(wi, m.albedo(), pdf_cosine_hemisphere_v3(n, wi))
}
