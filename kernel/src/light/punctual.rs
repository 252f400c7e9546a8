//! A point or spot light (`light_kind::PUNCTUAL`, glTF's `KHR_lights_punctual`): a delta light
//! at `position` of radiant intensity `radiance` (per steradian) along its axis `edge1`,
//! attenuated off the axis by glTF's spot falloff (a point light's is 1). Next-event estimation
//! alone finds it: no ray can hit it, so its samples have MIS weight 1.

use super::LightSample;
use crate::real::{Real, V3};
use crate::sampling::SurfacePoint;
use crate::scene::Light;
use spirv_std::glam::Vec3;

/// glTF's spot falloff of `l` toward unit direction `out` (from the light):
/// clamp(cos * scale + offset, 0, 1)^2 with cos the cosine to the axis, scale
/// 1 / (cos inner - cos outer) and offset -cos outer * scale (`KHR_lights_punctual`, "Spot");
/// 1 everywhere for a point light (scale 0, offset 1).
#[inline]
pub fn spot_attenuation(l: &Light, out: Vec3) -> f32 {
    spot_attenuation_v3(
        V3::from(Vec3::from(l.edge1)),
        l.edge2[0],
        l.edge2[1],
        V3::from(out),
    )
}

/// [`spot_attenuation`] of the spot of axis `axis`, `scale` and `offset`, over any scalar
/// [`Real`] in the same operations (so that a device's arithmetic can be bounded by running it
/// on one: `tests/src/device_class.rs`, `punctual_apart`).
#[inline]
pub fn spot_attenuation_v3<R: Real>(axis: V3<R>, scale: R, offset: R, out: V3<R>) -> R {
    let a = (axis.dot(out) * scale + offset).clamp(R::splat(0.0), R::splat(1.0));
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
    let (normal, pdf) = direction_and_density(V3::from(p), l.select_pmf, V3::from(x));
    LightSample {
        point: SurfacePoint {
            position: p,
            normal: normal.into(),
        },
        light,
        pdf_solid_angle: pdf,
    }
}

/// [`sample`]'s normal and density for a light at `p` chosen with probability `select_pmf`,
/// over any scalar [`Real`] in the same operations: ((x - p) / |x - p|, select_pmf |x - p|^2),
/// or (+z, 0) where |x - p|^2 is 0 or not finite.
#[inline]
pub fn direction_and_density<R: Real<Bits = u32>>(p: V3<R>, select_pmf: R, x: V3<R>) -> (V3<R>, R) {
    let d = x - p;
    let d2 = d.dot(d);
    if d2.greater_than(R::splat(0.0)) == 0 || d2.finite() == 0 {
        return (V3::splat(Vec3::Z), R::splat(0.0));
    }
    (d / d2.sqrt(), select_pmf * d2)
}

/// The radiance light sample `ls` of `l` sends toward its receiver: the intensity times the
/// spot falloff toward the receiver (the sample's "normal").
#[inline]
pub fn radiance(l: &Light, ls: &LightSample) -> Vec3 {
    Vec3::from(l.radiance) * spot_attenuation(l, ls.point.normal)
}
