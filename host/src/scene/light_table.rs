//! The light table: its entries for emissive spheres and triangles, and their selection
//! probabilities and alias table (what `kernel::light::choose_light` reads), for uniform or
//! power-proportional light selection.

use glam::Vec3;
use kernel::geometry::triangle_light_point_error;
use kernel::scene::{light_kind, light_selection, Light, Sphere, Triangle, NONE};

/// The light of an emissive sphere (selection filled later by [`assign_light_selection`]).
pub fn sphere_light(center: Vec3, radius: f32, radiance: [f32; 3]) -> Light {
    Light {
        position: center.to_array(),
        radius,
        edge1: [0.0; 3],
        kind: light_kind::SPHERE,
        edge2: [0.0; 3],
        two_sided: 0,
        radiance,
        select_pmf: 0.0,
        alias_threshold: 0.0,
        alias: 0,
        area: 0.0,
        point_error: 0.0,
        uv: [0.0; 6],
        emission_texture: NONE,
        material: NONE,
    }
}

/// A point light (`cone` None) or a spot light (`cone` = (axis, inner and outer cone
/// half-angles in radians, inner < outer)) at `position` of radiant intensity `intensity`
/// along its axis, with glTF's `KHR_lights_punctual` falloff, scale
/// 1 / max(1e-3, cos inner - cos outer) and offset -cos outer x scale (the extension's
/// reference code).
pub fn punctual_light(
    position: Vec3,
    intensity: [f32; 3],
    cone: Option<(Vec3, f32, f32)>,
) -> Light {
    let mut l = sphere_light(position, 0.0, intensity);
    l.kind = light_kind::PUNCTUAL;
    match cone {
        None => {
            l.edge1 = [0.0, 0.0, -1.0];
            l.edge2 = [0.0, 1.0, 0.0];
        }
        Some((axis, inner, outer)) => {
            let (ci, co) = (inner.cos(), outer.cos());
            let scale = 1.0 / (ci - co).max(1e-3);
            l.edge1 = axis.normalize().to_array();
            l.edge2 = [scale, -co * scale, 0.0];
        }
    }
    l
}

/// A directional light (`light_kind::DIRECTIONAL`): irradiance `irradiance`
/// (per unit area perpendicular to the light) arriving along `travel`, the direction the light
/// travels. Its bounding sphere is a placeholder (unit, at the origin) until
/// [`place_directional_lights`] sets the scene's.
pub fn directional_light(travel: Vec3, irradiance: [f32; 3]) -> Light {
    let mut l = punctual_light(Vec3::ZERO, irradiance, None);
    l.kind = light_kind::DIRECTIONAL;
    l.radius = 1.0;
    l.edge1 = travel.normalize().to_array();
    l
}

/// Whether `l` is a directional light.
pub fn is_directional(l: &Light) -> bool {
    l.kind == light_kind::DIRECTIONAL
}

/// The sphere bounding `spheres`, the world-space `triangles` and the box `instanced` of the
/// instances (`instancing::instances_box`; empty without them) (centre, radius; at least
/// 1e-3), or the unit sphere at the origin for an empty scene: where the environment map and
/// directional lights send their light from.
pub fn scene_bounds(
    spheres: &[Sphere],
    triangles: &[Triangle],
    instanced: (Vec3, Vec3),
) -> (Vec3, f32) {
    let (mut lo, mut hi) = instanced;
    for s in spheres {
        let c = Vec3::from(s.center);
        lo = lo.min(c - s.radius);
        hi = hi.max(c + s.radius);
    }
    for t in triangles {
        let p0 = Vec3::from(t.p0);
        for p in [p0, p0 + Vec3::from(t.edge1), p0 + Vec3::from(t.edge2)] {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    if lo.x <= hi.x {
        ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-3))
    } else {
        (Vec3::ZERO, 1.0)
    }
}

/// Gives every directional light of `lights` the scene's bounding sphere (`scene_bounds`).
pub fn place_directional_lights(
    lights: &mut [Light],
    spheres: &[Sphere],
    triangles: &[Triangle],
    instanced: (Vec3, Vec3),
) {
    if !lights.iter().any(is_directional) {
        return;
    }
    let (center, radius) = scene_bounds(spheres, triangles, instanced);
    for l in lights.iter_mut().filter(|l| is_directional(l)) {
        l.position = center.to_array();
        l.radius = radius;
    }
}

/// The light of an emissive triangle `tri` (its own p0 and edges, so a sample and a hit see
/// the same triangle): its area (in f64, then rounded) and the error bound of its points.
pub fn triangle_light(tri: &Triangle, radiance: [f32; 3], two_sided: bool) -> Light {
    let (p0, e1, e2) = (
        Vec3::from(tri.p0),
        Vec3::from(tri.edge1),
        Vec3::from(tri.edge2),
    );
    let area = 0.5 * e1.as_dvec3().cross(e2.as_dvec3()).length();
    Light {
        position: tri.p0,
        radius: 0.0,
        edge1: tri.edge1,
        kind: light_kind::TRIANGLE,
        edge2: tri.edge2,
        two_sided: two_sided as u32,
        radiance,
        select_pmf: 0.0,
        alias_threshold: 0.0,
        alias: 0,
        area: area as f32,
        point_error: triangle_light_point_error(p0, e1, e2),
        uv: [0.0; 6],
        emission_texture: NONE,
        material: NONE,
    }
}

/// Emitted power of a light (luminance-weighted watts), one scale for every kind, since power
/// selection compares them: pi x area x radiance for a uniform Lambertian emitter (a sphere, a
/// triangle; a two-sided triangle emits from twice its area), intensity x the solid angle its
/// falloff lets through for a point or spot light, irradiance x the disc the scene presents for
/// a directional one.
pub fn light_power(l: &Light) -> f64 {
    let [r, g, b] = l.radiance.map(f64::from);
    let luminance = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    if is_directional(l) {
        // Irradiance over the disc the scene presents to it (pbrt-v4 `DistantLight::Phi`).
        return luminance.max(0.0) * std::f64::consts::PI * (l.radius as f64).powi(2);
    }
    if l.kind == light_kind::PUNCTUAL {
        // Intensity over the directions the falloff lets through: 4 pi for a point light, the
        // cap out to the outer cone (where the falloff reaches 0) for a spot.
        let (scale, offset) = (l.edge2[0] as f64, l.edge2[1] as f64);
        let cos_outer = if scale > 0.0 { -offset / scale } else { -1.0 };
        return luminance.max(0.0)
            * 2.0
            * std::f64::consts::PI
            * (1.0 - cos_outer.clamp(-1.0, 1.0));
    }
    let area = if l.kind == light_kind::TRIANGLE {
        l.area as f64 * if l.two_sided != 0 { 2.0 } else { 1.0 }
    } else {
        4.0 * std::f64::consts::PI * (l.radius as f64).powi(2)
    };
    luminance.max(0.0) * std::f64::consts::PI * area
}

/// Fills `select_pmf`, `alias_threshold` and `alias` of every light for `mode` (one of
/// `kernel::scene::light_selection`). Power selection falls back to uniform when every light
/// has zero power.
pub fn assign_light_selection(lights: &mut [Light], mode: u32) {
    let weights: Vec<f64> = match mode {
        light_selection::POWER => lights.iter().map(light_power).collect(),
        _ => vec![1.0; lights.len()],
    };
    let weights = if weights.iter().sum::<f64>() > 0.0 {
        weights
    } else {
        vec![1.0; lights.len()]
    };
    let table = alias_table(&weights);
    let total: f64 = weights.iter().sum();
    for (l, (w, (threshold, alias))) in lights.iter_mut().zip(weights.iter().zip(table)) {
        l.select_pmf = (w / total) as f32;
        l.alias_threshold = threshold;
        l.alias = alias;
    }
}

/// Walker's alias table by Vose's construction (Vose 1991, "A linear algorithm for generating
/// random numbers with a given distribution"; pbrt-v4 `AliasTable`): for n weights, slot i keeps
/// item i with probability `threshold[i]`, else gives `alias[i]`, so that item i's total
/// probability is w_i / sum(w). Computed in f64; every slot with no alias has threshold 1.
pub fn alias_table(weights: &[f64]) -> Vec<(f32, u32)> {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    // Each slot holds 1/n of the probability; scaled so a slot's capacity is 1.
    let mut scaled: Vec<f64> = weights.iter().map(|w| w * n as f64 / total).collect();
    let mut table: Vec<(f32, u32)> = (0..n as u32).map(|i| (1.0, i)).collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        // Slot s keeps item s with probability scaled[s] and gives item l the rest.
        table[s] = (scaled[s] as f32, l as u32);
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // Whatever is left is full up to rounding: threshold 1 (already set).
    table
}
