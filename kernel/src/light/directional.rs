//! A directional light (`light_kind::DIRECTIONAL`, glTF's "directional"; pbrt-v4's
//! `DistantLight`): irradiance `radiance` (per unit area perpendicular to the light) arriving
//! along `edge1`, the direction the light travels, from beyond the sphere (`position`,
//! `radius`) that bounds the scene. A delta light: next-event estimation alone finds it.

use super::LightSample;
use crate::real::{Real, V3};
use crate::sampling::SurfacePoint;
use crate::scene::Light;
use spirv_std::glam::Vec3;

/// The light sample of `l` (index `light`) for receiver `x`: the point beyond the scene's
/// bounding sphere against the light's direction of travel, 2 (radius + |x - centre|) away, so
/// the shadow ray crosses the whole scene, facing `x` along that direction; `pdf_solid_angle`
/// = the selection probability, so the estimator is f cos x E / p_select with E the
/// irradiance (pbrt-v4 `DistantLight::SampleLi`).
#[inline]
pub fn sample(l: &Light, light: u32, x: Vec3) -> LightSample {
    let travel = Vec3::from(l.edge1);
    let position = far_point(
        V3::from(travel),
        V3::from(Vec3::from(l.position)),
        l.radius,
        V3::from(x),
    );
    LightSample {
        point: SurfacePoint {
            position: position.into(),
            normal: travel,
        },
        light,
        pdf_solid_angle: l.select_pmf,
    }
}

/// [`sample`]'s point for direction of travel `travel` and the scene's bounding sphere
/// (`centre`, `radius`), over any scalar [`Real`] in the same operations:
/// x - travel 2 (radius + |x - centre|).
#[inline]
pub fn far_point<R: Real>(travel: V3<R>, centre: V3<R>, radius: R, x: V3<R>) -> V3<R> {
    let far = R::splat(2.0) * (radius + (x - centre).length());
    x - travel * far
}

/// The irradiance the light sends toward every receiver.
#[inline]
pub fn radiance(l: &Light) -> Vec3 {
    Vec3::from(l.radiance)
}
