//! A point or spot light (`light_kind::PUNCTUAL`, glTF's `KHR_lights_punctual`): a delta light
//! at `position` of radiant intensity `radiance` (per steradian) along its axis `edge1`,
//! attenuated off the axis by glTF's spot falloff (a point light's is 1). Next-event estimation
//! alone finds it: no ray can hit it, so its samples have MIS weight 1.

use super::LightSample;
use crate::sampling::SurfacePoint;
use crate::scene::Light;
#[cfg(target_arch = "spirv")]
use crate::Float;
use spirv_std::glam::Vec3;

/// glTF's spot falloff of `l` toward unit direction `out` (from the light):
/// clamp(cos * scale + offset, 0, 1)^2 with cos the cosine to the axis, scale
/// 1 / (cos inner - cos outer) and offset -cos outer * scale (`KHR_lights_punctual`, "Spot");
/// 1 everywhere for a point light (scale 0, offset 1).
#[inline]
pub fn spot_attenuation(l: &Light, out: Vec3) -> f32 {
    let a = (Vec3::from(l.edge1).dot(out) * l.edge2[0] + l.edge2[1]).clamp(0.0, 1.0);
    a * a
}

/// The light sample of `l` (index `light`) for receiver `x`: its position, "facing" `x`
/// (normal the unit direction from the light to `x`, so the receiver sees it head on), with
/// `pdf_solid_angle` = selection probability x d^2. A delta light has no density per solid
/// angle; this one makes the estimator's f cos x radiance / pdf equal f cos x I / d^2 /
/// p_select, the point light's irradiance (pbrt-v4 `PointLight::SampleLi`). Receiver at the
/// light: density 0.
#[inline]
pub fn sample(l: &Light, light: u32, x: Vec3) -> LightSample {
    let p = Vec3::from(l.position);
    let d = x - p;
    let d2 = d.dot(d);
    let ok = d2 > 0.0 && d2.is_finite();
    LightSample {
        point: SurfacePoint {
            position: p,
            normal: if ok { d / d2.sqrt() } else { Vec3::Z },
        },
        light,
        pdf_solid_angle: if ok { l.select_pmf * d2 } else { 0.0 },
    }
}

/// The radiance light sample `ls` of `l` sends toward its receiver: the intensity times the
/// spot falloff toward the receiver (the sample's "normal").
#[inline]
pub fn radiance(l: &Light, ls: &LightSample) -> Vec3 {
    Vec3::from(l.radiance) * spot_attenuation(l, ls.point.normal)
}
