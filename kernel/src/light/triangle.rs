//! An emissive triangle (`light_kind::TRIANGLE`, of a quad or a mesh): emits from its front
//! face, or from both when two-sided. Sampled uniformly in the solid angle it subtends where
//! that pays (`spherical_triangle`), else uniformly in area; an emission texture scales its
//! radiance at the sampled point.

use super::LightSample;
use crate::features::FeatureSet;
use crate::geometry::{
    area_to_solid_angle_pdf, blend2, triangle_barycentrics, triangle_normal, triangle_point,
};
use crate::opacity::coverage;
use crate::sampling::{sample_triangle_barycentrics, SurfacePoint};
use crate::scene::{light_sampling, Light, Material, NONE};
use crate::spherical_triangle::{barycentrics_along, SphericalTriangle};
use crate::texture;
use spirv_std::glam::{Vec2, Vec3};

/// Triangle light `l` as seen from `x`, if `mode` samples it as a spherical triangle there;
/// else it is sampled by area. Two tests decide, both functions of `x` and the light alone (so
/// the sampler and the density MIS uses decide alike): the small-triangle estimate of its solid
/// angle, area |cos theta| / d^2 from the centroid, must reach
/// [`SPHERICAL_SAMPLING_MIN_ESTIMATE`] (below it the spherical sampler's cost buys less than
/// it costs, and this estimate is cheap where the exact solid angle is not), then the exact
/// solid angle must satisfy `spherical_triangle::SphericalTriangle::sampled` (pbrt-v4's
/// numerical limits and the edge-on guard).
#[inline]
pub fn spherical_triangle_used(l: &Light, mode: u32, x: Vec3) -> Option<SphericalTriangle> {
    if mode != light_sampling::SOLID_ANGLE {
        return None;
    }
    let (p0, e1, e2) = (
        Vec3::from(l.position),
        Vec3::from(l.edge1),
        Vec3::from(l.edge2),
    );
    let to_x = x - (p0 + (e1 + e2) * (1.0 / 3.0));
    let d = to_x.length();
    let twice_area_cos = e1.cross(e2).dot(to_x).abs() / d;
    if !(0.5 * twice_area_cos >= SPHERICAL_SAMPLING_MIN_ESTIMATE * (d * d)) {
        return None;
    }
    let t = SphericalTriangle::of(x, p0, e1, e2);
    if t.sampled() {
        Some(t)
    } else {
        None
    }
}

/// The smallest estimated solid angle (sr; area |cos| / d^2) at which a triangle light is
/// sampled as a spherical triangle: measured (docs/performance.md, "Triangle lights"), the
/// spherical sampler costs about twice the area sampler and pays for it only where the light
/// is large in the receiver's view.
pub const SPHERICAL_SAMPLING_MIN_ESTIMATE: f32 = 0.1;

/// Whether receiver `x` lies within rounding of the plane of triangle light `l` (unit normal
/// `n`) at its point `y`: its height |n . (x - y)| below 4 (the point's error bound plus eps of
/// the magnitudes of `x` and of `x - y`), where the sign of cos theta_light, and whether the
/// shadow segment starts in front of the light, are rounding noise (found by the re-intersection
/// test: 77 of 750,000 such segments hit their own light). Light sampling leaves such receivers
/// to BSDF sampling: its density there is 0 for the sampler and for MIS alike, which the power
/// heuristic then gives weight 1; what it loses is at most cos theta_light ~ that height over the
/// distance.
#[inline]
fn within_plane_rounding(l: &Light, n: Vec3, x: Vec3, y: Vec3) -> bool {
    let d = x - y;
    let bound =
        4.0 * (l.point_error + f32::EPSILON * (x.abs().max_element() + d.abs().max_element()));
    n.dot(d).abs() <= bound
}

/// The normal a triangle light's point shows receiver `x`: the geometric one
/// (`geometry::triangle_normal`, as a hit's), turned toward `x` if the light is two-sided.
#[inline]
fn triangle_light_normal(l: &Light, point: Vec3, x: Vec3) -> Vec3 {
    let n = triangle_normal(Vec3::from(l.edge1), Vec3::from(l.edge2));
    if l.two_sided != 0 && n.dot(x - point) < 0.0 {
        -n
    } else {
        n
    }
}

/// A point on triangle light `l` (index `light`) for receiver `x`: uniform in the solid angle
/// it subtends (`spherical_triangle::sample`, then the point that direction meets) where `mode`
/// is [`light_sampling::SOLID_ANGLE`] and `spherical_triangle::SphericalTriangle::sampled` allows,
/// else uniform in area (density 1 / area,
/// converted to solid angle). Either way the point is placed by barycentrics on the triangle
/// (`geometry::triangle_point`, as hits are), so its error bound is `Light::point_error`.
/// A one-sided light seen from behind gets a point whose normal faces away, which the caller
/// skips as it skips a sphere's far side.
#[inline]
pub fn sample(l: &Light, light: u32, mode: u32, x: Vec3, u1: f32, u2: f32) -> LightSample {
    let p0 = Vec3::from(l.position);
    let (e1, e2) = (Vec3::from(l.edge1), Vec3::from(l.edge2));
    let spherical = spherical_triangle_used(l, mode, x);
    let (u, v) = match spherical {
        Some(t) => barycentrics_along(x, t.sample(u1, u2), p0, e1, e2),
        None => sample_triangle_barycentrics(u1, u2),
    };
    let position = triangle_point(p0, e1, e2, u, v);
    let normal = triangle_light_normal(l, position, x);
    LightSample {
        point: SurfacePoint { position, normal },
        light,
        pdf_solid_angle: pdf_given(l, spherical, x, position, normal),
    }
}

/// Solid-angle density with which [`sample`] produces point `y` (normal `n_y`)
/// of triangle light `l` for receiver `x`.
#[inline]
pub fn pdf(l: &Light, mode: u32, x: Vec3, y: Vec3, n_y: Vec3) -> f32 {
    pdf_given(l, spherical_triangle_used(l, mode, x), x, y, n_y)
}

/// The density of [`pdf`] once the sampler is known (`spherical`, from
/// [`spherical_triangle_used`]): 0 for a receiver within rounding of the light's plane
/// ([`within_plane_rounding`]).
#[inline]
fn pdf_given(l: &Light, spherical: Option<SphericalTriangle>, x: Vec3, y: Vec3, n_y: Vec3) -> f32 {
    if within_plane_rounding(l, n_y, x, y) {
        0.0
    } else if let Some(t) = spherical {
        l.select_pmf / t.solid_angle()
    } else {
        area_to_solid_angle_pdf(l.select_pmf / l.area, x, y, n_y)
    }
}

/// What multiplies triangle light `l`'s radiance at the point of light sample `ls`: its
/// emission texture's value there (1 without one) times its material's coverage there
/// (`opacity::coverage`: 1 without holes), both at the texture coordinates the light's `uv`
/// gives the point's barycentrics on the triangle.
#[inline]
pub fn radiance_factor<F: FeatureSet>(
    features: F,
    materials: &[Material],
    textures: &[u32],
    l: &Light,
    ls: &LightSample,
) -> Vec3 {
    let textured = features.textures() && l.emission_texture != NONE;
    let holed =
        features.opacity() && l.material != NONE && materials[l.material as usize].has_holes();
    if !(textured || holed) {
        return Vec3::ONE;
    }
    let bary = triangle_barycentrics(
        Vec3::from(l.position),
        Vec3::from(l.edge1),
        Vec3::from(l.edge2),
        ls.point.position,
    );
    let uv = blend2(
        Vec2::new(l.uv[0], l.uv[1]),
        Vec2::new(l.uv[2], l.uv[3]),
        Vec2::new(l.uv[4], l.uv[5]),
        bary,
    );
    let mut factor = Vec3::ONE;
    if textured {
        factor = texture::lookup_in(features, textures, l.emission_texture, uv);
    }
    if holed {
        factor *= coverage(features, materials, textures, l.material, uv);
    }
    factor
}

/// Rounding-error bound of a point sampled on `l` (barycentrics on the triangle): what lifts
/// the end of its shadow ray off the surface.
#[inline]
pub fn point_error(l: &Light) -> f32 {
    l.point_error
}
