//! Cosine and sine of an angle given in turns (1 turn = 2 pi), the form every azimuth the
//! kernel samples takes (phi = 2 pi u). Written as polynomials so that the accuracy of a sampled
//! direction, which the pdf it is divided by assumes, does not rest on the driver: the Vulkan
//! environment for SPIR-V (1.0, appendix A.4) leaves the precision of GLSL.std.450's
//! trigonometric functions undefined. Both backends run the same arithmetic (on lavapipe
//! `sample_sphere` and `sample_brdf` are now bit-exact against the CPU; with libm and the
//! driver's sin/cos they differed by up to 1.2e-7). Their cost on the CPU is libm's `sincosf`'s
//! (docs/gpu.md).

use crate::real::{abs, select, Real};

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
/// see its fraction. The polynomials are [`Real::cos_sin_turns`]'s default (in `real`, since
/// they choose the quadrant on the bits, which a test's interval type has not).
#[inline]
pub fn cos_sin_turns<R: Real>(u: R) -> (R, R) {
    u.cos_sin_turns()
}

/// The angle, in turns, of the vector (x, y) with y >= 0: atan2(y, x) / (2 pi), in [0, 1/2]
/// (0 for x = y = 0); one number, or one per lane ([`Real`]). A polynomial for the same reason
/// as [`cos_sin_turns`]: solid angles and the spherical-triangle sampler's angles feed a pdf,
/// and the driver's `atan2` has no stated precision.
///
/// The octant is reduced without rounding: with m = min(|x|, y) and M = max(|x|, y), the angle
/// of (M, m) is in [0, pi/4]; above pi/8 (m > tan(pi/8) M) it is pi/4 + atan(w) with
/// w = (m - M) / (m + M) in [-tan(pi/8), 0], below it atan(w) with w = m / M in
/// [0, tan(pi/8)]. There the Taylor series of atan to the w^17 term leaves a truncation error
/// below |w|^19 / 19 = 2.9e-9 rad (alternating series, Abramowitz and Stegun 4.4.42); w itself
/// is within an ulp or two. The octant's symmetries (pi/2 - a where y > |x|, pi - a where
/// x < 0) are then subtractions from 1/8, 1/4 and 1/2 turn. Error within 2^-24 turn plus
/// 2 ulp of the result (tested against f64 in `tests/tests/sampling.rs`); small angles keep
/// their relative precision.
#[inline]
pub fn atan2_turns<R: Real>(y: R, x: R) -> R {
    let c = R::splat;
    let ax = abs(x);
    // Without branches, so that it runs on lanes: each choice below is a mask.
    let steep = y.greater_than(ax);
    let m = select(steep, ax, y);
    let big = select(steep, y, ax);
    // tan(pi/8) = sqrt(2) - 1.
    let above_eighth = m.greater_than(c(0.414_213_57) * big);
    let w = select(above_eighth, m - big, m) / select(above_eighth, m + big, big);
    let z = w * w;
    let atan_w = w + w
        * z
        * (c(-1.0 / 3.0)
            + z * (c(1.0 / 5.0)
                + z * (c(-1.0 / 7.0)
                    + z * (c(1.0 / 9.0)
                        + z * (c(-1.0 / 11.0)
                            + z * (c(1.0 / 13.0) + z * (c(-1.0 / 15.0) + z * c(1.0 / 17.0))))))));
    let turns = atan_w * c(0.5 * core::f32::consts::FRAC_1_PI);
    let octant = select(above_eighth, c(0.125) + turns, turns);
    let quadrant = select(steep, c(0.25) - octant, octant);
    let angle = select(x.less_than(c(0.0)), c(0.5) - quadrant, quadrant);
    // (0, 0) and NaN give 0 (their quotient, NaN, is not chosen).
    select(big.greater_than(c(0.0)), angle, c(0.0))
}
