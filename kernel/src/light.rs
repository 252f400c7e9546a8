//! Spherical area lights: choosing one, a point on it, and the densities of those choices.

use crate::geometry::area_to_solid_angle_pdf;
use crate::sampling::{
    pdf_sphere_area, pdf_sphere_cone, sample_sphere, sample_sphere_cone, ConeSample, SurfacePoint,
};
use crate::scene::{light_sampling, SphereLight};
use spirv_std::glam::Vec3;

/// A point chosen on a light, and the density of having chosen it.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub point: SurfacePoint,
    /// Index of the chosen light in the light table.
    pub light: u32,
    /// Density per unit area of the light's surface, selection probability included.
    pub pdf_area: f32,
}

/// Picks a light index from one uniform number in O(1) with the light table's alias table
/// (Walker 1977; Vose 1991; pbrt-v4 `AliasTable::Sample`): slot i = floor(u n) is chosen
/// uniformly, and the rest of u, rescaled to [0, 1), keeps light i with probability
/// `alias_threshold[i]`, else gives `alias[i]`. Light i is then chosen with probability
/// (threshold_i + sum over slots j aliasing to i of (1 - threshold_j)) / n, which the host's
/// construction makes equal to `select_pmf[i]`.
#[inline]
pub fn choose_light(lights: &[SphereLight], light_count: u32, u: f32) -> u32 {
    if light_count == 1 {
        return 0;
    }
    let scaled = u * light_count as f32;
    let slot = (scaled as u32).min(light_count - 1);
    // The fractional part, clamped below 1 (u close to 1 rounds scaled up to n).
    let rest = (scaled - slot as f32).min(ONE_MINUS_EPSILON);
    let l = &lights[slot as usize];
    if rest < l.alias_threshold {
        slot
    } else {
        l.alias
    }
}

/// The largest f32 below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Seed: `SampleLight()`. Chooses a light by its selection probability (the host sets it
/// uniform, 1 / number of lights, as the seed does) and a uniformly distributed point on its
/// sphere (seed `SampleSphere`).
#[inline]
pub fn sample_light(
    lights: &[SphereLight],
    light_count: u32,
    u_select: f32,
    u1: f32,
    u2: f32,
) -> LightSample {
    let light = choose_light(lights, light_count, u_select);
    let l = lights[light as usize];
    let point = sample_sphere(Vec3::from(l.center), l.radius, u1, u2);
    LightSample {
        point,
        light,
        pdf_area: l.select_pmf * pdf_sphere_area(l.radius),
    }
}

/// Seed: `PdfLight(L)`. Area density with which [`sample_light`] produces a given point of light
/// `light`: select_pmf / (4 pi r^2), i.e. 1 / (number of lights * area) for uniform selection.
#[inline]
pub fn pdf_light(lights: &[SphereLight], light: u32) -> f32 {
    let l = lights[light as usize];
    l.select_pmf * pdf_sphere_area(l.radius)
}

/// Seed: `EvalRadiance(L)`. Radiance a light sends back along a ray that met it: the constant
/// emission on its outer surface, zero on the inside. `arrived_behind` is the hit record's
/// side (`path::SurfaceHit::arrived_behind`), decided robustly where the record is made rather
/// than from the sign of `normal . w_out`, which rounding flips at grazing hits.
#[inline]
pub fn eval_radiance(emission: Vec3, arrived_behind: bool) -> Vec3 {
    if arrived_behind {
        Vec3::ZERO
    } else {
        emission
    }
}

/// A light point chosen for a receiver, with its density per unit solid angle at the receiver.
#[derive(Clone, Copy, Debug)]
pub struct DirectionalLightSample {
    pub point: SurfacePoint,
    pub light: u32,
    /// Solid-angle density at the receiver, selection probability included; 0 if unusable.
    pub pdf_solid_angle: f32,
}

/// Whether `mode` samples light `l` by its cone from receiver `x` (x strictly outside).
#[inline]
pub fn uses_cone(mode: u32, l: &SphereLight, x: Vec3) -> bool {
    let d = Vec3::from(l.center) - x;
    mode == light_sampling::CONE && d.dot(d) > l.radius * l.radius
}

/// Chooses a light and a point on it for receiver `x`: by the seed's uniform area sampling
/// ([`sample_light`], density converted to solid angle), or by the cone the sphere subtends
/// ([`sample_sphere_cone`]) when `mode` is [`light_sampling::CONE`] and `x` is outside it.
#[inline]
pub fn sample_light_from(
    lights: &[SphereLight],
    light_count: u32,
    mode: u32,
    x: Vec3,
    u_select: f32,
    u1: f32,
    u2: f32,
) -> DirectionalLightSample {
    let light = choose_light(lights, light_count, u_select);
    let l = lights[light as usize];
    let center = Vec3::from(l.center);
    if uses_cone(mode, &l, x) {
        cone_light_sample(&l, light, sample_sphere_cone(center, l.radius, x, u1, u2))
    } else {
        let point = sample_sphere(center, l.radius, u1, u2);
        DirectionalLightSample {
            point,
            light,
            pdf_solid_angle: area_to_solid_angle_pdf(
                l.select_pmf * pdf_sphere_area(l.radius),
                x,
                point.position,
                point.normal,
            ),
        }
    }
}

/// The light sample of [`sample_light_from`] that samples light `l` (index `light`) by its cone:
/// the cone's sample `s`, its density times the light's selection probability.
#[inline]
pub fn cone_light_sample(l: &SphereLight, light: u32, s: ConeSample) -> DirectionalLightSample {
    DirectionalLightSample {
        point: s.point,
        light,
        pdf_solid_angle: l.select_pmf * s.pdf_solid_angle,
    }
}

/// Solid-angle density with which [`sample_light_from`] produces light point `y` (unit normal
/// `n_y`) of light `light` for receiver `x`: what MIS needs when BRDF sampling finds the light.
#[inline]
pub fn pdf_light_from(
    lights: &[SphereLight],
    mode: u32,
    light: u32,
    x: Vec3,
    y: Vec3,
    n_y: Vec3,
) -> f32 {
    let l = lights[light as usize];
    if uses_cone(mode, &l, x) {
        l.select_pmf * pdf_sphere_cone(Vec3::from(l.center), l.radius, x)
    } else {
        area_to_solid_angle_pdf(pdf_light(lights, light), x, y, n_y)
    }
}
