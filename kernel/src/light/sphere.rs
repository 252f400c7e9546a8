//! An emissive sphere (`light_kind::SPHERE`): emits from its outer surface. Sampled for a
//! receiver outside it by the cone it subtends (`light_sampling::SOLID_ANGLE`), else by the
//! seed's uniform area sampling converted to solid angle.

use super::LightSample;
use crate::geometry::{area_to_solid_angle_pdf, sphere_point_error};
use crate::sampling::{
    pdf_sphere_area, pdf_sphere_cone, sample_sphere, sample_sphere_cone, ConeSample, SurfacePoint,
};
use crate::scene::{light_sampling, Light};
use spirv_std::glam::Vec3;

/// A point chosen on a sphere light by area, and the density of having chosen it.
#[derive(Clone, Copy, Debug)]
pub struct AreaSample {
    pub point: SurfacePoint,
    /// Index of the chosen light in the light table.
    pub light: u32,
    /// Density per unit area of the light's surface, selection probability included.
    pub pdf_area: f32,
}

/// Seed: `SampleLight()`, for light `l` (index `light`): a uniformly distributed point on its
/// sphere (seed `SampleSphere`), density its selection probability over its area.
#[inline]
pub fn sample_area(l: &Light, light: u32, u1: f32, u2: f32) -> AreaSample {
    AreaSample {
        point: sample_sphere(Vec3::from(l.position), l.radius, u1, u2),
        light,
        pdf_area: pdf_area(l),
    }
}

/// Seed: `PdfLight(L)`. Area density with which [`sample_area`] produces a given point of `l`:
/// select_pmf / (4 pi r^2), i.e. 1 / (number of lights * area) for uniform selection.
#[inline]
pub fn pdf_area(l: &Light) -> f32 {
    l.select_pmf * pdf_sphere_area(l.radius)
}

/// Whether `mode` samples sphere light `l` by its cone from receiver `x`: `x` strictly outside.
#[inline]
pub fn uses_cone(mode: u32, l: &Light, x: Vec3) -> bool {
    let d = Vec3::from(l.position) - x;
    mode == light_sampling::SOLID_ANGLE && d.dot(d) > l.radius * l.radius
}

/// The light sample that samples light `l` (index `light`) by its cone: the cone's sample `s`,
/// its density times the light's selection probability.
#[inline]
pub fn cone_sample(l: &Light, light: u32, s: ConeSample) -> LightSample {
    LightSample {
        point: s.point,
        light,
        pdf_solid_angle: l.select_pmf * s.pdf_solid_angle,
    }
}

/// A point on sphere light `l` (index `light`) for receiver `x`: by its cone where
/// [`uses_cone`], else by area ([`sample_area`], density converted to solid angle).
#[inline]
pub fn sample(l: &Light, light: u32, mode: u32, x: Vec3, u1: f32, u2: f32) -> LightSample {
    let center = Vec3::from(l.position);
    if uses_cone(mode, l, x) {
        cone_sample(l, light, sample_sphere_cone(center, l.radius, x, u1, u2))
    } else {
        let point = sample_sphere(center, l.radius, u1, u2);
        LightSample {
            point,
            light,
            pdf_solid_angle: area_to_solid_angle_pdf(pdf_area(l), x, point.position, point.normal),
        }
    }
}

/// Solid-angle density with which [`sample`] produces point `y` (unit normal `n_y`) of `l` for
/// receiver `x`.
#[inline]
pub fn pdf(l: &Light, mode: u32, x: Vec3, y: Vec3, n_y: Vec3) -> f32 {
    if uses_cone(mode, l, x) {
        l.select_pmf * pdf_sphere_cone(Vec3::from(l.position), l.radius, x)
    } else {
        area_to_solid_angle_pdf(pdf_area(l), x, y, n_y)
    }
}

/// Rounding-error bound of a point sampled on `l` (c + r n): what lifts the end of its shadow
/// ray off the surface.
#[inline]
pub fn point_error(l: &Light) -> f32 {
    sphere_point_error(Vec3::from(l.position), l.radius)
}
