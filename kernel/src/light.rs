//! Area lights (spheres and triangles): choosing one, a point on it, and the densities of
//! those choices.

use crate::environment;
use crate::geometry::{
    area_to_solid_angle_pdf, blend2, sphere_point_error, triangle_barycentrics, triangle_normal,
    triangle_point,
};
use crate::sampling::{
    pdf_sphere_area, pdf_sphere_cone, sample_sphere, sample_sphere_cone,
    sample_triangle_barycentrics, ConeSample, SurfacePoint,
};
use crate::scene::{light_kind, light_sampling, Light, RenderParams, NONE};
use crate::spherical_triangle::{barycentrics_along, SphericalTriangle};
use crate::texture;
#[cfg(target_arch = "spirv")]
use crate::Float;
use spirv_std::glam::{Vec2, Vec3};

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
pub fn choose_light(lights: &[Light], light_count: u32, u: f32) -> u32 {
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
/// sphere (seed `SampleSphere`). Sphere lights only (the seed's; the renderer samples with
/// [`sample_light_from`]).
#[inline]
pub fn sample_light(
    lights: &[Light],
    light_count: u32,
    u_select: f32,
    u1: f32,
    u2: f32,
) -> LightSample {
    let light = choose_light(lights, light_count, u_select);
    let l = lights[light as usize];
    let point = sample_sphere(Vec3::from(l.position), l.radius, u1, u2);
    LightSample {
        point,
        light,
        pdf_area: l.select_pmf * pdf_sphere_area(l.radius),
    }
}

/// Seed: `PdfLight(L)`. Area density with which [`sample_light`] produces a given point of light
/// `light`: select_pmf / (4 pi r^2), i.e. 1 / (number of lights * area) for uniform selection.
#[inline]
pub fn pdf_light(lights: &[Light], light: u32) -> f32 {
    let l = lights[light as usize];
    l.select_pmf * pdf_sphere_area(l.radius)
}

/// Seed: `EvalRadiance(L)`. Radiance a light sends back along a ray that met it: the constant
/// emission on its emitting side (a sphere's outside, a triangle's front), zero on the other,
/// unless `two_sided`. `arrived_behind` is the hit record's side
/// (`path::SurfaceHit::arrived_behind`), decided robustly where the record is made rather than
/// from the sign of `normal . w_out`, which rounding flips at grazing hits.
#[inline]
pub fn eval_radiance(emission: Vec3, arrived_behind: bool, two_sided: bool) -> Vec3 {
    if arrived_behind && !two_sided {
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

/// Whether light `l` is a triangle, where the light table may hold triangles (`triangles`:
/// `features::TRIANGLE_LIGHTS`; without it every light is a sphere and this is false).
#[inline]
pub fn is_triangle(triangles: bool, l: &Light) -> bool {
    triangles && l.kind == light_kind::TRIANGLE
}

/// Whether light `l` is a point or spot light, where the light table may hold one
/// (`punctual`: `features::PUNCTUAL_LIGHTS`).
#[inline]
pub fn is_punctual(punctual: bool, l: &Light) -> bool {
    punctual && l.kind == light_kind::PUNCTUAL
}

/// glTF's spot falloff of punctual light `l` toward unit direction `out` (from the light):
/// clamp(cos * scale + offset, 0, 1)^2 with cos the cosine to the axis, scale
/// 1 / (cos inner - cos outer) and offset -cos outer * scale (`KHR_lights_punctual`, "Spot");
/// 1 everywhere for a point light (scale 0, offset 1).
#[inline]
pub fn spot_attenuation(l: &Light, out: Vec3) -> f32 {
    let a = (Vec3::from(l.edge1).dot(out) * l.edge2[0] + l.edge2[1]).clamp(0.0, 1.0);
    a * a
}

/// The light sample of punctual light `l` (index `light`) for receiver `x`: its position,
/// "facing" `x` (normal the unit direction from the light to `x`, so the receiver sees it head
/// on), with `pdf_solid_angle` = selection probability x d^2. A delta light has no density per
/// solid angle; this one makes the estimator's f cos x radiance / pdf equal f cos x I / d^2 /
/// p_select, the point light's irradiance (pbrt-v4 `PointLight::SampleLi`), and the vertex
/// gives it MIS weight 1 (no BSDF sample can meet it). Receiver at the light: density 0.
///
/// A directional light (`radius` > 0): the point beyond the scene's bounding sphere against the
/// light's direction of travel, 2 (radius + |x - centre|) away, so the shadow ray crosses the
/// whole scene, facing `x` along that direction; `pdf_solid_angle` = the selection
/// probability, so the estimator is f cos x E / p_select with E the irradiance (pbrt-v4
/// `DistantLight::SampleLi`).
#[inline]
pub fn sample_punctual_light(l: &Light, light: u32, x: Vec3) -> DirectionalLightSample {
    let p = Vec3::from(l.position);
    if l.radius > 0.0 {
        let travel = Vec3::from(l.edge1);
        let far = 2.0 * (l.radius + (x - p).length());
        return DirectionalLightSample {
            point: SurfacePoint {
                position: x - travel * far,
                normal: travel,
            },
            light,
            pdf_solid_angle: l.select_pmf,
        };
    }
    let d = x - p;
    let d2 = d.dot(d);
    let ok = d2 > 0.0 && d2.is_finite();
    DirectionalLightSample {
        point: SurfacePoint {
            position: p,
            normal: if ok { d / d2.sqrt() } else { Vec3::Z },
        },
        light,
        pdf_solid_angle: if ok { l.select_pmf * d2 } else { 0.0 },
    }
}

/// Whether light `l` is the environment map, where the light table may hold one
/// (`environment`: `features::ENVIRONMENT`).
#[inline]
pub fn is_environment(environment: bool, l: &Light) -> bool {
    environment && l.kind == light_kind::ENVIRONMENT
}

/// A direction toward the environment map (light `l`, index `light`) for receiver `x`, by
/// `environment::sample` under `mode`, as a light point: beyond the sphere bounding the scene
/// (`l.position`, `l.radius`) along the direction, facing back along it, so the shadow ray to
/// it crosses the whole scene. Density: the map's, times the selection probability.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn sample_environment_light(
    l: &Light,
    light: u32,
    mode: u32,
    params: &RenderParams,
    table: &[f32],
    x: Vec3,
    u1: f32,
    u2: f32,
) -> DirectionalLightSample {
    let dir = environment::sample(params, table, mode, u1, u2);
    let far = 2.0 * (l.radius + (x - Vec3::from(l.position)).length());
    DirectionalLightSample {
        point: SurfacePoint {
            position: x + dir * far,
            normal: -dir,
        },
        light,
        pdf_solid_angle: l.select_pmf * environment::pdf(params, table, mode, dir),
    }
}

/// The solid-angle density with which [`sample_light_from`] chooses the environment map (light
/// `l`) and direction `dir`: what MIS needs when a path escapes along `dir`.
#[inline]
pub fn pdf_environment_light(
    l: &Light,
    mode: u32,
    params: &RenderParams,
    table: &[f32],
    dir: Vec3,
) -> f32 {
    l.select_pmf * environment::pdf(params, table, mode, dir)
}

/// The radiance light sample `ls` of light `l` sends toward its receiver: the light's constant
/// radiance, or the environment map's along the sample's direction (-normal). (A punctual
/// light's is [`punctual_radiance`].) (A triangle with
/// an emission texture scales it by [`emission_texture_at`].)
#[inline]
pub fn sample_radiance(
    environment: bool,
    params: &RenderParams,
    table: &[f32],
    l: &Light,
    ls: &DirectionalLightSample,
) -> Vec3 {
    if is_environment(environment, l) {
        environment::eval(params, table, -ls.point.normal)
    } else {
        Vec3::from(l.radiance)
    }
}

/// The radiance light sample `ls` of punctual light `l` sends toward its receiver: its
/// intensity times its spot falloff toward the receiver (the sample's "normal"); a directional
/// light's irradiance (its falloff is 1: edge2 = [0, 1]).
#[inline]
pub fn punctual_radiance(l: &Light, ls: &DirectionalLightSample) -> Vec3 {
    Vec3::from(l.radiance) * spot_attenuation(l, ls.point.normal)
}

/// The emission texture's value at the point of light sample `ls` on triangle light `l`
/// (1 where the light has no texture): the point's barycentrics on the triangle, its texture
/// coordinates from the light's `uv`, the texture there.
#[inline]
pub fn emission_texture_at(textures: &[u32], l: &Light, ls: &DirectionalLightSample) -> Vec3 {
    if l.emission_texture == NONE {
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
    texture::lookup(textures, l.emission_texture, uv)
}

/// Whether `mode` samples light `l` by its cone from receiver `x`: a sphere (the caller knows it
/// is one) with `x` strictly outside.
#[inline]
pub fn uses_cone(mode: u32, l: &Light, x: Vec3) -> bool {
    let d = Vec3::from(l.position) - x;
    mode == light_sampling::SOLID_ANGLE && d.dot(d) > l.radius * l.radius
}

/// Chooses a light and a point on it for receiver `x`. A sphere: by the seed's uniform area
/// sampling ([`sample_light`], density converted to solid angle), or by the cone the sphere
/// subtends ([`sample_sphere_cone`]) when `mode` is [`light_sampling::SOLID_ANGLE`] and `x` is
/// outside it. A triangle (only where `triangles`, see [`is_triangle`]): by
/// [`sample_triangle_light`]. The environment map (only where `environment`, see
/// [`is_environment`]; `params` and `table` describe it): by [`sample_environment_light`]. A
/// point or spot light (only where `punctual`, see [`is_punctual`]): [`sample_punctual_light`].
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn sample_light_from(
    lights: &[Light],
    light_count: u32,
    mode: u32,
    triangles: bool,
    environment: bool,
    punctual: bool,
    params: &RenderParams,
    table: &[f32],
    x: Vec3,
    u_select: f32,
    u1: f32,
    u2: f32,
) -> DirectionalLightSample {
    let light = choose_light(lights, light_count, u_select);
    let l = lights[light as usize];
    if is_triangle(triangles, &l) {
        return sample_triangle_light(&l, light, mode, x, u1, u2);
    }
    if is_environment(environment, &l) {
        return sample_environment_light(&l, light, mode, params, table, x, u1, u2);
    }
    if is_punctual(punctual, &l) {
        return sample_punctual_light(&l, light, x);
    }
    let center = Vec3::from(l.position);
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
pub fn cone_light_sample(l: &Light, light: u32, s: ConeSample) -> DirectionalLightSample {
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
    lights: &[Light],
    mode: u32,
    triangles: bool,
    light: u32,
    x: Vec3,
    y: Vec3,
    n_y: Vec3,
) -> f32 {
    let l = lights[light as usize];
    if is_triangle(triangles, &l) {
        pdf_triangle_light(&l, mode, x, y, n_y)
    } else if uses_cone(mode, &l, x) {
        l.select_pmf * pdf_sphere_cone(Vec3::from(l.position), l.radius, x)
    } else {
        area_to_solid_angle_pdf(pdf_light(lights, light), x, y, n_y)
    }
}

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
pub fn sample_triangle_light(
    l: &Light,
    light: u32,
    mode: u32,
    x: Vec3,
    u1: f32,
    u2: f32,
) -> DirectionalLightSample {
    let p0 = Vec3::from(l.position);
    let (e1, e2) = (Vec3::from(l.edge1), Vec3::from(l.edge2));
    let spherical = spherical_triangle_used(l, mode, x);
    let (u, v) = match spherical {
        Some(t) => barycentrics_along(x, t.sample(u1, u2), p0, e1, e2),
        None => sample_triangle_barycentrics(u1, u2),
    };
    let position = triangle_point(p0, e1, e2, u, v);
    let normal = triangle_light_normal(l, position, x);
    DirectionalLightSample {
        point: SurfacePoint { position, normal },
        light,
        pdf_solid_angle: triangle_light_pdf(l, spherical, x, position, normal),
    }
}

/// Solid-angle density with which [`sample_triangle_light`] produces point `y` (normal `n_y`)
/// of triangle light `l` for receiver `x`.
#[inline]
pub fn pdf_triangle_light(l: &Light, mode: u32, x: Vec3, y: Vec3, n_y: Vec3) -> f32 {
    triangle_light_pdf(l, spherical_triangle_used(l, mode, x), x, y, n_y)
}

/// The density of [`pdf_triangle_light`] once the sampler is known (`spherical`, from
/// [`spherical_triangle_used`]): 0 for a receiver within rounding of the light's plane
/// ([`within_plane_rounding`]).
#[inline]
fn triangle_light_pdf(
    l: &Light,
    spherical: Option<SphericalTriangle>,
    x: Vec3,
    y: Vec3,
    n_y: Vec3,
) -> f32 {
    if within_plane_rounding(l, n_y, x, y) {
        0.0
    } else if let Some(t) = spherical {
        l.select_pmf / t.solid_angle()
    } else {
        area_to_solid_angle_pdf(l.select_pmf / l.area, x, y, n_y)
    }
}

/// Rounding-error bound of a point sampled on light `l` (c + r n on a sphere, barycentrics on a
/// triangle): what lifts the end of its shadow ray off the surface.
#[inline]
pub fn light_point_error(triangles: bool, l: &Light) -> f32 {
    if is_triangle(triangles, l) {
        l.point_error
    } else {
        sphere_point_error(Vec3::from(l.position), l.radius)
    }
}
