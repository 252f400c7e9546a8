//! A directional light (`light_kind::DIRECTIONAL`, glTF's "directional"; pbrt-v4's
//! `DistantLight`): irradiance `radiance` (per unit area perpendicular to the light) arriving
//! along `edge1`, the direction the light travels, from beyond the sphere (`position`,
//! `radius`) that bounds the scene. A delta light: next-event estimation alone finds it.

use super::LightSample;
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
    let far = 2.0 * (l.radius + (x - Vec3::from(l.position)).length());
    LightSample {
        point: SurfacePoint {
            position: x - travel * far,
            normal: travel,
        },
        light,
        pdf_solid_angle: l.select_pmf,
    }
}

/// The irradiance the light sends toward every receiver.
#[inline]
pub fn radiance(l: &Light) -> Vec3 {
    Vec3::from(l.radiance)
}
