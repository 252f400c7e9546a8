//! The lights of the light table (`scene::Light`, one of `scene::light_kind`): choosing one
//! ([`choice`]: the alias table), a point on it for a receiver and the density of that choice,
//! the radiance it sends, and what a ray that finds it needs. One file per kind: `sphere`,
//! `triangle`, `environment`, `punctual` (point and spot), `directional`; this module holds the
//! one dispatch over kinds ([`sample`], [`pdf`], [`radiance`], [`point_error`], [`is_delta`],
//! [`light_features`]). Derivations and sources: `docs/lights.md`.
//!
//! A kind's arm is compiled only where the scene's features allow it ([`LightKinds`]); a light
//! whose kind no arm takes is never sampled (density 0).

pub mod choice;
pub mod directional;
pub mod environment;
pub mod punctual;
pub mod sphere;
pub mod triangle;

pub use choice::choose_light;

use crate::features::{self, FeatureSet};
use crate::sampling::SurfacePoint;
use crate::scene::{light_kind, Light, RenderParams, NONE};
use crate::scene_view::SceneView;
use spirv_std::glam::Vec3;

/// A light point chosen for a receiver, with its density per unit solid angle at the receiver.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub point: SurfacePoint,
    pub light: u32,
    /// Solid-angle density at the receiver, selection probability included; 0 if unusable.
    pub pdf_solid_angle: f32,
}

impl LightSample {
    /// No sample: density 0, which the vertex skips.
    pub const NONE: Self = Self {
        point: SurfacePoint {
            position: Vec3::ZERO,
            normal: Vec3::ZERO,
        },
        light: NONE,
        pdf_solid_angle: 0.0,
    };
}

/// Which light kinds besides spheres the light table may hold (`crate::features`: the scene's
/// bits, or every kind on the generic path).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightKinds {
    /// Triangles (`features::TRIANGLE_LIGHTS`).
    pub triangles: bool,
    /// The environment map (`features::ENVIRONMENT`).
    pub environment: bool,
    /// Point, spot and directional lights, the delta lights (`features::PUNCTUAL_LIGHTS`).
    pub delta: bool,
}

impl LightKinds {
    /// The kinds `features` allows, for a render of `params`.
    #[inline]
    pub fn of<F: FeatureSet>(features: F, params: &RenderParams) -> Self {
        Self {
            triangles: features.triangle_lights(),
            environment: features.environment(params),
            delta: features.punctual_lights(),
        }
    }
}

/// The feature bits (`crate::features`) a scene with these lights needs.
#[inline]
pub fn light_features(lights: &[Light]) -> u32 {
    let mut f = 0;
    for l in lights {
        f |= match l.kind {
            light_kind::TRIANGLE => features::TRIANGLE_LIGHTS,
            light_kind::PUNCTUAL | light_kind::DIRECTIONAL => features::PUNCTUAL_LIGHTS,
            _ => 0,
        };
    }
    f
}

/// Chooses a light of the first `light_count` (by its selection probability, `u_select`) and a
/// point on it for receiver `x` (`u1`, `u2`), sampled as `mode` (`scene::light_sampling`) asks
/// of its kind.
#[inline]
pub fn sample(
    scene: &SceneView,
    kinds: LightKinds,
    light_count: u32,
    mode: u32,
    x: Vec3,
    u_select: f32,
    (u1, u2): (f32, f32),
) -> LightSample {
    let light = choose_light(scene.lights, light_count, u_select);
    let l = &scene.lights[light as usize];
    match l.kind {
        light_kind::SPHERE => sphere::sample(l, light, mode, x, u1, u2),
        light_kind::TRIANGLE if kinds.triangles => triangle::sample(l, light, mode, x, u1, u2),
        light_kind::ENVIRONMENT if kinds.environment => {
            environment::sample(l, light, mode, scene, x, u1, u2)
        }
        light_kind::PUNCTUAL if kinds.delta => punctual::sample(l, light, x),
        light_kind::DIRECTIONAL if kinds.delta => directional::sample(l, light, x),
        _ => LightSample::NONE,
    }
}

/// Solid-angle density with which [`sample`] produces point `y` (unit normal `n_y`) of light
/// `light` for receiver `x`: what MIS needs when BSDF sampling hits the light. Only spheres and
/// triangles can be hit.
#[inline]
pub fn pdf(
    lights: &[Light],
    kinds: LightKinds,
    mode: u32,
    light: u32,
    x: Vec3,
    y: Vec3,
    n_y: Vec3,
) -> f32 {
    let l = &lights[light as usize];
    match l.kind {
        light_kind::SPHERE => sphere::pdf(l, mode, x, y, n_y),
        light_kind::TRIANGLE if kinds.triangles => triangle::pdf(l, mode, x, y, n_y),
        _ => 0.0,
    }
}

/// The radiance light sample `ls` sends toward its receiver: the light's constant radiance (a
/// triangle's times its emission texture and its coverage at the point, where the scene has
/// textures or holes: `triangle::radiance_factor`), the
/// environment map's along the sample, a punctual light's intensity times its spot falloff, a
/// directional light's irradiance. Always inlined: it sits in the Lambertian vertex's hot path.
#[inline(always)]
pub fn radiance<F: FeatureSet>(
    features: F,
    scene: &SceneView,
    kinds: LightKinds,
    ls: &LightSample,
) -> Vec3 {
    let l = &scene.lights[ls.light as usize];
    match l.kind {
        light_kind::TRIANGLE if kinds.triangles && (features.textures() || features.opacity()) => {
            Vec3::from(l.radiance)
                * triangle::radiance_factor(features, scene.materials, scene.textures, l, ls)
        }
        light_kind::ENVIRONMENT if kinds.environment => environment::radiance(scene, ls),
        light_kind::PUNCTUAL if kinds.delta => punctual::radiance(l, ls),
        light_kind::DIRECTIONAL if kinds.delta => directional::radiance(l),
        _ => Vec3::from(l.radiance),
    }
}

/// Whether `l` is a delta light (point, spot, directional), which no BSDF sample can meet:
/// its light samples get MIS weight 1 (as pbrt-v4's `LightSampleContext` treats them).
#[inline]
pub fn is_delta(kinds: LightKinds, l: &Light) -> bool {
    kinds.delta && (l.kind == light_kind::PUNCTUAL || l.kind == light_kind::DIRECTIONAL)
}

/// Rounding-error bound of a point sampled on `l`: what lifts the end of its shadow ray off
/// the light's surface. A triangle's is its own; every other kind's point is bounded as a point
/// c + r n of its sphere (a sphere light's own; the bounding sphere the environment map and a
/// directional light send their light from; a point light's position, radius 0).
#[inline]
pub fn point_error(kinds: LightKinds, l: &Light) -> f32 {
    match l.kind {
        light_kind::TRIANGLE if kinds.triangles => triangle::point_error(l),
        _ => sphere::point_error(l),
    }
}

/// Seed: `EvalRadiance(L)`. Radiance a light sends back along a ray that met it: the constant
/// emission on its emitting side (a sphere's outside, a triangle's front), zero on the other,
/// unless `two_sided`. `arrived_behind` is the hit record's side
/// (`hit::SurfaceHit::arrived_behind`), decided robustly where the record is made rather than
/// from the sign of `normal . w_out`, which rounding flips at grazing hits.
#[inline]
pub fn eval_radiance(emission: Vec3, arrived_behind: bool, two_sided: bool) -> Vec3 {
    if arrived_behind && !two_sided {
        Vec3::ZERO
    } else {
        emission
    }
}
