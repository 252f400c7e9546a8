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

use crate::real::{Real, V3};
use crate::sampling::sample_sphere;
use crate::scene::{light_sampling, RenderParams};
use crate::turns::{atan2_turns, cos_sin_turns};
use core::f32::consts::PI;
use spirv_std::glam::Vec3;

/// Whether the render has an environment map.
#[inline]
pub fn has_map(params: &RenderParams) -> bool {
    params.environment.width > 0
}

/// The environment table's layout for a `width` x `height` map: where its parts start (module
/// doc: texels, the marginal CDF, each row's conditional CDF) and its length. The one statement
/// of the layout: the kernel reads by it, the host builds and sizes the table by it, and tests
/// read the stored CDFs by it.
#[derive(Clone, Copy)]
pub struct TableLayout {
    pub width: u32,
    pub height: u32,
}

impl TableLayout {
    /// The layout of the render's map.
    #[inline]
    pub fn of(params: &RenderParams) -> Self {
        Self {
            width: params.environment.width,
            height: params.environment.height,
        }
    }

    /// Where the marginal CDF over rows (height + 1 numbers) starts: after the texels' RGB.
    #[inline]
    pub fn marginal(self) -> u32 {
        3 * self.width * self.height
    }

    /// Where row `row`'s conditional CDF over its columns (width + 1 numbers) starts.
    #[inline]
    pub fn conditional(self, row: u32) -> u32 {
        self.marginal() + self.height + 1 + row * (self.width + 1)
    }

    /// The number of entries: where a conditional CDF after the last row would start.
    #[inline]
    pub fn entries(self) -> u32 {
        self.conditional(self.height)
    }
}

/// World direction `d` in the map's frame: the map's rotation (cos, sin) about +y undone.
#[inline]
fn to_map<R: Real>(rotation: [R; 2], d: V3<R>) -> V3<R> {
    let [c, s] = rotation;
    V3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z)
}

/// Direction `m` of the map's frame in the world: the map's rotation (cos, sin) about +y
/// applied.
#[inline]
fn to_world<R: Real>(rotation: [R; 2], m: V3<R>) -> V3<R> {
    let [c, s] = rotation;
    V3::new(c * m.x + s * m.z, m.y, c * m.z - s * m.x)
}

/// The map coordinates (u, v) in [0, 1]^2 of unit world direction `d` under the map's rotation
/// (cos, sin) about +y, and sin theta; over any scalar [`Real`] (so that a device's arithmetic
/// can be bounded by running it on one: `tests/src/device_class.rs`, `environment_apart`).
#[inline]
pub fn map_coordinates<R: Real<Bits = u32>>(rotation: [R; 2], d: V3<R>) -> (R, R, R) {
    let m = to_map(rotation, d);
    let sin_theta = (m.x * m.x + m.z * m.z).sqrt();
    let t = atan2_turns(m.z.abs(), m.x);
    let u = if m.z.less_than(R::splat(0.0)) != 0 {
        R::splat(1.0) - t
    } else {
        t
    };
    let v = R::splat(2.0) * atan2_turns(sin_theta, m.y);
    (u, v, sin_theta)
}

/// The texel (column, row) of map coordinates (u, v) in [0, 1]^2 on a `width` x `height` map:
/// (floor(u W), floor(v H)), the last column and row also holding u = 1 and v = 1. The
/// conversions truncate, so coordinates within rounding of a texel's edge may read either
/// texel on another arithmetic (a test's ball arithmetic follows both).
#[inline]
pub fn texel_of<R: Real<Bits = u32>>(width: u32, height: u32, u: R, v: R) -> (u32, u32) {
    (
        (u * R::splat(width as f32)).to_i32_bits().min(width - 1),
        (v * R::splat(height as f32)).to_i32_bits().min(height - 1),
    )
}

/// The solid-angle density of a direction at sin theta `sin_theta` in a texel of row
/// probability `p_row` and column probability `p_column` (given its row), on a map of `texels`
/// texels: the texel's probability spread over its 1 / (W H) share of the (u, v) square,
/// divided by the map's Jacobian 2 pi^2 sin theta (dw = 2 pi^2 sin theta du dv).
#[inline]
pub fn texel_density<R: Real>(p_row: R, p_column: R, texels: R, sin_theta: R) -> R {
    p_row * p_column * texels / (R::splat(2.0 * PI * PI) * sin_theta)
}

/// A map's shape as its sampler's numbers see it: `width` x `height` texels, rotated by
/// `rotation` = (cos, sin) about +y.
#[derive(Clone, Copy, Debug)]
pub struct MapShape<R> {
    pub rotation: [R; 2],
    pub width: u32,
    pub height: u32,
}

/// A texel the sampler chose and the numbers that chose it: its `row`, where the marginal CDF
/// runs from `row_cdf[0]` to `row_cdf[1]` around `u2`, and its `column`, where the row's
/// conditional CDF `column_cdf` runs around `u1` (as [`sample`]'s search finds them:
/// cdf[k] <= u < cdf[k + 1]).
#[derive(Clone, Copy, Debug)]
pub struct DrawnTexel<R> {
    pub row: u32,
    pub row_cdf: [R; 2],
    pub u2: R,
    pub column: u32,
    pub column_cdf: [R; 2],
    pub u1: R,
}

/// The direction drawn within texel `drawn` of map `map`, and its solid-angle density: v
/// continuous within the row by u2, u within the column by u1; the density is the texel's
/// ([`texel_density`] at the drawn direction's own sin theta), which is positive wherever the
/// sampler can land: it never chooses a bin of probability 0, and the drawn v is positive (the
/// first row's CDF starts at 0, the uniform numbers above it) and clamped below 1, so sin theta
/// > 0. Over any scalar [`Real`] (`environment_apart`).
#[inline]
pub fn direction_in_texel<R: Real<Bits = u32>>(
    map: MapShape<R>,
    drawn: DrawnTexel<R>,
) -> (V3<R>, R) {
    let c = R::splat;
    let ([r0, r1], [c0, c1]) = (drawn.row_cdf, drawn.column_cdf);
    let v = (c(drawn.row as f32) + (drawn.u2 - r0) / (r1 - r0)) / c(map.height as f32);
    let u = (c(drawn.column as f32) + (drawn.u1 - c0) / (c1 - c0)) / c(map.width as f32);
    let (cos_phi, sin_phi) = cos_sin_turns(u.min(c(ONE_MINUS_EPSILON)));
    let (cos_theta, sin_theta) = cos_sin_turns(c(0.5) * v.min(c(ONE_MINUS_EPSILON)));
    let direction = to_world(
        map.rotation,
        V3::new(sin_theta * cos_phi, cos_theta, sin_theta * sin_phi),
    );
    let texels = c((map.width * map.height) as f32);
    (
        direction,
        texel_density(r1 - r0, c1 - c0, texels, sin_theta),
    )
}

/// The radiance the map sends along -`d` (arriving from direction `d`): its texel's RGB times
/// the map's scale. `d` unit length; the map must exist ([`has_map`]).
#[inline]
pub fn eval(params: &RenderParams, table: &[f32], d: Vec3) -> Vec3 {
    let (w, h) = (params.environment.width, params.environment.height);
    let (u, v, _) = map_coordinates(params.environment.rotation, V3::from(d));
    let (i, j) = texel_of(w, h, u, v);
    let k = (3 * (j * w + i)) as usize;
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

/// A direction toward the map and the solid-angle density with which [`sample`] drew it.
#[derive(Clone, Copy, Debug)]
pub struct MapSample {
    pub direction: Vec3,
    pub pdf: f32,
}

/// A direction toward the environment from two uniform numbers in (0, 1), and its density:
/// by `mode` ([`light_sampling::SOLID_ANGLE`]: proportional to the map's luminance, the row
/// from u2 by the marginal CDF and the column from u1 by the row's conditional CDF, each
/// continuous within its bin ([`direction_in_texel`]); [`light_sampling::AREA`]: uniform over
/// the sphere of directions). The density is that of the texel drawn, as pbrt-v4's and
/// Mitsuba 3's map samplers return it: [`pdf`] of the drawn direction reads the same texel
/// except within rounding of a texel's edge, where it may read a neighbour (of another
/// probability, possibly 0), so it is not asked again.
#[inline]
pub fn sample(params: &RenderParams, table: &[f32], mode: u32, u1: f32, u2: f32) -> MapSample {
    if mode != light_sampling::SOLID_ANGLE {
        return MapSample {
            direction: sample_sphere(Vec3::ZERO, 1.0, u1, u2).normal,
            pdf: 1.0 / (4.0 * PI),
        };
    }
    let (w, h) = (params.environment.width, params.environment.height);
    let layout = TableLayout::of(params);
    let m = layout.marginal();
    let row = find_interval(table, m, h, u2);
    let row_cdf = [table[(m + row) as usize], table[(m + row + 1) as usize]];
    let c = layout.conditional(row);
    let column = find_interval(table, c, w, u1);
    let column_cdf = [
        table[(c + column) as usize],
        table[(c + column + 1) as usize],
    ];
    let map = MapShape {
        rotation: params.environment.rotation,
        width: w,
        height: h,
    };
    let drawn = DrawnTexel {
        row,
        row_cdf,
        u2,
        column,
        column_cdf,
        u1,
    };
    let (direction, pdf) = direction_in_texel(map, drawn);
    MapSample {
        direction: direction.into(),
        pdf,
    }
}

/// The solid-angle density with which [`sample`] gives unit direction `d` (what MIS needs
/// where a path escapes along `d`). By luminance: the density of `d`'s texel
/// ([`texel_density`]: row pmf times column pmf, differences of the stored CDFs, exactly what
/// the sampler compares its numbers with); 0 straight up and down, where no direction is
/// sampled. Uniform: 1 / 4 pi.
#[inline]
pub fn pdf(params: &RenderParams, table: &[f32], mode: u32, d: Vec3) -> f32 {
    if mode != light_sampling::SOLID_ANGLE {
        return 1.0 / (4.0 * PI);
    }
    let (w, h) = (params.environment.width, params.environment.height);
    let (u, v, sin_theta) = map_coordinates(params.environment.rotation, V3::from(d));
    if !(sin_theta > 0.0) {
        return 0.0;
    }
    let (i, j) = texel_of(w, h, u, v);
    let layout = TableLayout::of(params);
    let m = layout.marginal();
    let c = layout.conditional(j);
    let p_row = table[(m + j + 1) as usize] - table[(m + j) as usize];
    let p_column = table[(c + i + 1) as usize] - table[(c + i) as usize];
    texel_density(p_row, p_column, (w * h) as f32, sin_theta)
}
