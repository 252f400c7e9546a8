//! The environment map: radiance arriving from infinitely far away, stored as an
//! equirectangular image (latitude-longitude), looked up piecewise constant, and importance
//! sampled by a piecewise-constant 2D distribution (pbrt-v4 `PiecewiseConstant2D`, 13.6.7 of
//! the 3rd edition; Mitsuba 3 `envmap`).
//!
//! The map's frame: +y up; a direction at angle theta from +y and azimuth phi from +x toward +z
//! (after undoing the map's rotation about +y) reads texel column floor(u W), row floor(v H),
//! with u = phi / 2 pi and v = theta / pi (row 0 looks straight up).
//!
//! The environment table (one `f32` storage buffer) holds, for a W x H map: the texels' RGB,
//! row by row (3 W H numbers); the marginal CDF over rows (H + 1 numbers, 0 first and 1 last);
//! then each row's conditional CDF over its columns (H times W + 1 numbers). The host builds the
//! CDFs from texel luminance times sin theta at the row's centre (the equirectangular map's
//! area element), so a direction's density is proportional to its radiance.

use crate::sampling::sample_sphere;
use crate::scene::{light_sampling, RenderParams};
use crate::turns::{atan2_turns, cos_sin_turns};
#[cfg(target_arch = "spirv")]
use crate::Float;
use core::f32::consts::PI;
use spirv_std::glam::Vec3;

/// Whether the render has an environment map.
#[inline]
pub fn has_map(params: &RenderParams) -> bool {
    params.environment.width > 0
}

/// Where the marginal CDF starts in the environment table.
#[inline]
fn marginal_offset(params: &RenderParams) -> u32 {
    3 * params.environment.width * params.environment.height
}

/// Where row `row`'s conditional CDF starts in the environment table.
#[inline]
fn conditional_offset(params: &RenderParams, row: u32) -> u32 {
    marginal_offset(params) + params.environment.height + 1 + row * (params.environment.width + 1)
}

/// World direction `d` in the map's frame: the map's rotation about +y undone.
#[inline]
fn to_map(params: &RenderParams, d: Vec3) -> Vec3 {
    let [c, s] = params.environment.rotation;
    Vec3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z)
}

/// Direction `m` of the map's frame in the world: the map's rotation about +y applied.
#[inline]
fn to_world(params: &RenderParams, m: Vec3) -> Vec3 {
    let [c, s] = params.environment.rotation;
    Vec3::new(c * m.x + s * m.z, m.y, c * m.z - s * m.x)
}

/// The map coordinates (u, v) in [0, 1]^2 of unit world direction `d`, and sin theta.
#[inline]
fn map_coordinates(params: &RenderParams, d: Vec3) -> (f32, f32, f32) {
    let m = to_map(params, d);
    let sin_theta = (m.x * m.x + m.z * m.z).sqrt();
    let t = atan2_turns(m.z.abs(), m.x);
    let u = if m.z < 0.0 { 1.0 - t } else { t };
    let v = 2.0 * atan2_turns(sin_theta, m.y);
    (u, v, sin_theta)
}

/// The texel (column, row) of map coordinates (u, v).
#[inline]
fn texel(params: &RenderParams, u: f32, v: f32) -> (u32, u32) {
    let (w, h) = (params.environment.width, params.environment.height);
    (
        ((u * w as f32) as u32).min(w - 1),
        ((v * h as f32) as u32).min(h - 1),
    )
}

/// The radiance the map sends along -`d` (arriving from direction `d`): its texel's RGB times
/// the map's scale. `d` unit length; the map must exist ([`has_map`]).
#[inline]
pub fn eval(params: &RenderParams, table: &[f32], d: Vec3) -> Vec3 {
    let (u, v, _) = map_coordinates(params, d);
    let (i, j) = texel(params, u, v);
    let k = (3 * (j * params.environment.width + i)) as usize;
    Vec3::new(table[k], table[k + 1], table[k + 2]) * params.environment.scale
}

/// The largest k in [0, n) with cdf[base + k] <= x, for a CDF with cdf[base] = 0 <= x <
/// cdf[base + n] = 1: a binary search of ceil(log2 n) steps, without recursion. Bins of zero
/// probability are never returned (their upper end is <= x too).
#[inline]
fn find_interval(table: &[f32], base: u32, n: u32, x: f32) -> u32 {
    let (mut lo, mut hi) = (0u32, n);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if table[(base + mid) as usize] <= x {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The largest f32 below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// A direction toward the environment from two uniform numbers: by `mode`
/// ([`light_sampling::SOLID_ANGLE`]: proportional to the map's luminance, the row from u2 by the
/// marginal CDF and the column from u1 by the row's conditional CDF, each continuous within its
/// bin; [`light_sampling::AREA`]: uniform over the sphere of directions). Its density is
/// [`pdf`].
#[inline]
pub fn sample(params: &RenderParams, table: &[f32], mode: u32, u1: f32, u2: f32) -> Vec3 {
    if mode != light_sampling::SOLID_ANGLE {
        return sample_sphere(Vec3::ZERO, 1.0, u1, u2).normal;
    }
    let (w, h) = (params.environment.width, params.environment.height);
    let m = marginal_offset(params);
    let row = find_interval(table, m, h, u2);
    let (r0, r1) = (table[(m + row) as usize], table[(m + row + 1) as usize]);
    let v = (row as f32 + (u2 - r0) / (r1 - r0)) / h as f32;
    let c = conditional_offset(params, row);
    let column = find_interval(table, c, w, u1);
    let (c0, c1) = (
        table[(c + column) as usize],
        table[(c + column + 1) as usize],
    );
    let u = (column as f32 + (u1 - c0) / (c1 - c0)) / w as f32;
    let (cos_phi, sin_phi) = cos_sin_turns(u.min(ONE_MINUS_EPSILON));
    let (cos_theta, sin_theta) = cos_sin_turns(0.5 * v.min(ONE_MINUS_EPSILON));
    to_world(
        params,
        Vec3::new(sin_theta * cos_phi, cos_theta, sin_theta * sin_phi),
    )
}

/// The solid-angle density with which [`sample`] gives unit direction `d`. By luminance: the
/// texel's probability (row pmf times column pmf, differences of the stored CDFs, exactly what
/// the sampler compares its numbers with) spread over the texel's W H share of the (u, v)
/// square, divided by the Jacobian 2 pi^2 sin theta of the map (dw = 2 pi^2 sin theta du dv);
/// 0 straight up and down, where no direction is sampled. Uniform: 1 / 4 pi.
#[inline]
pub fn pdf(params: &RenderParams, table: &[f32], mode: u32, d: Vec3) -> f32 {
    if mode != light_sampling::SOLID_ANGLE {
        return 1.0 / (4.0 * PI);
    }
    let (u, v, sin_theta) = map_coordinates(params, d);
    if !(sin_theta > 0.0) {
        return 0.0;
    }
    let (i, j) = texel(params, u, v);
    let m = marginal_offset(params);
    let c = conditional_offset(params, j);
    let p_row = table[(m + j + 1) as usize] - table[(m + j) as usize];
    let p_column = table[(c + i + 1) as usize] - table[(c + i) as usize];
    let texels = (params.environment.width * params.environment.height) as f32;
    p_row * p_column * texels / (2.0 * PI * PI * sin_theta)
}
