//! Which samples a film sums: each channel finite and smaller in magnitude than
//! [`MAX_SAMPLE`]. Both backends ask this one predicate, so they drop the same samples. The
//! bound exists because the CPU film sums fixed-point integers of bounded width
//! (`host/src/fixed_sum.rs`, docs/parts.md); a radiance sample of 2^40 (about 1.1e12) or
//! more is a numerical failure, not light, in any scene twinpath renders.

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
