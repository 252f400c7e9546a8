//! The environment map as a light (`light_kind::ENVIRONMENT`): radiance arriving from
//! infinitely far in every direction, sampled by `crate::environment` (by luminance or
//! uniformly). Its light-table entry holds a sphere bounding the scene, which shadow rays toward
//! it leave, and the map's mean radiance (for the selection by power).

use super::LightSample;
use crate::environment as map;
use crate::sampling::SurfacePoint;
use crate::scene::Light;
use crate::scene_view::SceneView;
use spirv_std::glam::Vec3;

/// A direction toward the map (light `l`, index `light`) for receiver `x`, by
/// `environment::sample` under `mode`, as a light point: beyond the sphere bounding the scene
/// (`l.position`, `l.radius`) along the direction, facing back along it, so the shadow ray to
/// it crosses the whole scene. Density: that of the map's texel drawn (`environment::sample`),
/// times the selection probability.
#[inline]
pub fn sample(
    l: &Light,
    light: u32,
    mode: u32,
    scene: &SceneView,
    x: Vec3,
    u1: f32,
    u2: f32,
) -> LightSample {
    let s = map::sample(scene.params, scene.environment, mode, u1, u2);
    let far = 2.0 * (l.radius + (x - Vec3::from(l.position)).length());
    LightSample {
        point: SurfacePoint {
            position: x + s.direction * far,
            normal: -s.direction,
        },
        light,
        pdf_solid_angle: l.select_pmf * s.pdf,
    }
}

/// The solid-angle density with which light sampling chooses the map (light `l`) and direction
/// `dir`: what MIS needs when a path escapes along `dir`.
#[inline]
pub fn pdf(l: &Light, mode: u32, scene: &SceneView, dir: Vec3) -> f32 {
    l.select_pmf * map::pdf(scene.params, scene.environment, mode, dir)
}

/// The radiance the map sends toward the receiver of light sample `ls`: the map's value in
/// the direction the receiver looks, -normal (the sample faces back along it).
#[inline]
pub fn radiance(scene: &SceneView, ls: &LightSample) -> Vec3 {
    map::eval(scene.params, scene.environment, -ls.point.normal)
}
