//! Exact (`f64`) references of the kernel's samplers, computed from the same `f32` inputs, for
//! the tests that measure how far the kernel's `f32` results are from them (`media_sampling.rs`,
//! `vulkan_precision.rs`).

/// (1 - mu, 1 + mu) of the Henyey-Greenstein sample of asymmetry `g` (already taken as 0 where
/// the kernel does) for the uniform number `u1`: the factored forms `kernel::phase` derives
/// from the inverse CDF, with d = (1 - g)(1 - u1) + (1 + g) u1 and s = (1 - g)(1 + g) / d,
/// 1 - mu = (1 - g)(1 - u1)(s + 1 - g) / d and 1 + mu = (1 + g) u1 (1 + g + s) / d (at g = 0,
/// mu = 2 u1 - 1).
pub fn henyey_greenstein_factors(g: f64, u1: f64) -> (f64, f64) {
    let d = (1.0 - g) * (1.0 - u1) + (1.0 + g) * u1;
    let s = (1.0 - g) * (1.0 + g) / d;
    (
        (1.0 - g) * (1.0 - u1) * (s + 1.0 - g) / d,
        (1.0 + g) * u1 * (1.0 + g + s) / d,
    )
}
