//! Spherical area lights: choosing one, a point on it, and the densities of those choices.

use crate::geometry::area_to_solid_angle_pdf;
use crate::sampling::{
    pdf_sphere_area, pdf_sphere_cone, sample_sphere, sample_sphere_cone, SurfacePoint,
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

/// Picks a light index from a uniform number by the lights' cumulative selection probabilities
/// (`select_cdf`, nondecreasing, last = 1). A linear scan: light tables are small.
#[inline]
pub fn choose_light(lights: &[SphereLight], light_count: u32, u: f32) -> u32 {
    let mut i = 0;
    while i + 1 < light_count {
        if u < lights[i as usize].select_cdf {
            return i;
        }
        i += 1;
    }
    i
}

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

/// Seed: `EvalRadiance(L)`. Radiance leaving the light's outer surface toward `w_out` (unit,
/// pointing away from the surface): the constant emission on the outside, zero on the inside.
#[inline]
pub fn eval_radiance(emission: Vec3, normal: Vec3, w_out: Vec3) -> Vec3 {
    if normal.dot(w_out) > 0.0 {
        emission
    } else {
        Vec3::ZERO
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
fn uses_cone(mode: u32, l: &SphereLight, x: Vec3) -> bool {
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
        let s = sample_sphere_cone(center, l.radius, x, u1, u2);
        DirectionalLightSample {
            point: s.point,
            light,
            pdf_solid_angle: l.select_pmf * s.pdf_solid_angle,
        }
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
