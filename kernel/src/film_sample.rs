//! Which samples a film sums, and where: each channel finite and smaller in magnitude than
//! [`MAX_SAMPLE`], to the pilot sums if adaptive sampling makes it a pilot, else to the image.
//! Both films (the CPU's `host/src/film.rs`, the GPU's ray-generation shader) ask [`classify`],
//! so they drop and split the same samples. The
//! bound exists because the CPU film sums fixed-point integers of bounded width
//! (`host/src/fixed_sum.rs`, docs/parts.md); a radiance sample of 2^40 (about 1.1e12) or
//! more is a numerical failure, not light, in any scene twinpath renders.

use crate::adaptive::is_pilot_sample;
use crate::scene::RenderParams;
use spirv_std::glam::Vec3;

/// Samples must be smaller than this in every channel's magnitude: 2^40.
pub const MAX_SAMPLE: f32 = 1_099_511_627_776.0;

/// Whether the film sums sample `v` (false for NaN, infinities and values at or beyond
/// [`MAX_SAMPLE`]); the rest are counted as discarded.
#[inline]
pub fn summable(v: Vec3) -> bool {
    // `<` is false for NaN, so a NaN channel fails.
    let a = v.abs();
    a.x < MAX_SAMPLE && a.y < MAX_SAMPLE && a.z < MAX_SAMPLE
}

/// What a film does with a sample (the values [`classify`] returns).
pub mod sample_use {
    /// Not summable ([`super::summable`]): counted as discarded.
    pub const DISCARDED: u32 = 0;
    /// A pilot of adaptive sampling (`crate::adaptive`): summed apart, for the stopping rule.
    pub const PILOT: u32 = 1;
    /// An image sample.
    pub const IMAGE: u32 = 2;
}

/// What a film does with sample index `sample` of value `v` (one of [`sample_use`]).
#[inline]
pub fn classify(params: &RenderParams, sample: u32, v: Vec3) -> u32 {
    if !summable(v) {
        sample_use::DISCARDED
    } else if is_pilot_sample(params, sample) {
        sample_use::PILOT
    } else {
        sample_use::IMAGE
    }
}
