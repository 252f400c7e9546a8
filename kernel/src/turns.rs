//! Cosine and sine of an angle given in turns (1 turn = 2 pi), the form every azimuth the
//! kernel samples takes (phi = 2 pi u). Written as polynomials so that the accuracy of a sampled
//! direction, which the pdf it is divided by assumes, does not rest on the driver: the Vulkan
//! environment for SPIR-V (1.0, appendix A.4) leaves the precision of GLSL.std.450's
//! trigonometric functions undefined. Both backends run the same arithmetic (on lavapipe
//! `sample_sphere` and `sample_brdf` are now bit-exact against the CPU; with libm and the
//! driver's sin/cos they differed by up to 1.2e-7). Speed on the CPU is unchanged: the
//! polynomials cost what libm's `sincosf` did (4.4% of a Cornell render).

use crate::real::Real;
use crate::word::Word;
use core::f32::consts::FRAC_PI_2;

/// (cos(2 pi u), sin(2 pi u)) for finite `u` (one number, or one per lane: [`Real`]).
///
/// Range reduction is exact: q = the nearest integer to 4u (quarter turns) and r = 4u - q,
/// |r| <= 1/2, are computed without rounding (4u is exact, and r by Sterbenz's lemma or q = 0),
/// so only theta = (pi/2) r in [-pi/4, pi/4] is rounded. There the Taylor series of sin to the
/// theta^9 term and of cos to the theta^10 term leave truncation errors below theta^11 / 11!
/// = 1.7e-9 and theta^12 / 12! = 1.2e-10 (Abramowitz and Stegun 4.3.65-66 with the remainder
/// bound of an alternating series), below half an ulp of the results; the quadrant q mod 4 then
/// swaps and negates them exactly. Error within 2^-23 absolute (tested against f64 on every
/// sampler value in `tests/tests/sampling.rs`); |u| must stay below 2^22 for the reduction to
/// see its fraction.
#[inline]
pub fn cos_sin_turns<R: Real>(u: R) -> (R, R) {
    let c = R::splat;
    let quarters = c(4.0) * u;
    // floor(quarters + 1/2) by conversions (truncation, less one below zero: the mask is -1
    // there): `floor` is a libm call on baseline x86-64.
    let half_up = quarters + c(0.5);
    let truncated = half_up.to_i32_bits();
    let nearest = truncated.wrapping_add(R::from_i32_bits(truncated).greater_than(half_up));
    let q = R::from_i32_bits(nearest);
    let theta = (quarters - q) * c(FRAC_PI_2);
    let z = theta * theta;
    let sin = theta
        + theta
            * z
            * (c(-1.0 / 6.0)
                + z * (c(1.0 / 120.0) + z * (c(-1.0 / 5040.0) + z * c(1.0 / 362_880.0))));
    let cos = c(1.0)
        + z * (c(-0.5)
            + z * (c(1.0 / 24.0)
                + z * (c(-1.0 / 720.0) + z * (c(1.0 / 40_320.0) + z * c(-1.0 / 3_628_800.0)))));
    // Rotate by q quarter turns, (c, s) -> (-s, c) per quarter: odd quadrants swap the two,
    // quadrants 1 and 2 negate the cosine, 2 and 3 the sine. Done on the bits, without a branch,
    // because the quadrant of a random azimuth is unpredictable.
    let bits = R::Bits::splat;
    let quadrant = nearest & bits(3);
    let swap = bits(0).wrapping_sub(quadrant & bits(1));
    let (cos_bits, sin_bits) = (cos.to_bits(), sin.to_bits());
    // Where `swap` is all ones the two exchange: x ^ ((x ^ y) & swap).
    let exchanged = (cos_bits ^ sin_bits) & swap;
    let cos_sign = (quadrant.wrapping_add(bits(1)) & bits(2)) << 30;
    let sin_sign = (quadrant & bits(2)) << 30;
    (
        R::from_bits(cos_bits ^ exchanged ^ cos_sign),
        R::from_bits(sin_bits ^ exchanged ^ sin_sign),
    )
}
