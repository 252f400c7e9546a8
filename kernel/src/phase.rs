//! The Henyey-Greenstein phase function (Henyey and Greenstein, "Diffuse radiation in the
//! galaxy", Astrophysical Journal 93, 1941), the angular distribution of light a medium
//! scatters: with theta the angle between the light's direction of travel before and after
//! the scattering,
//!
//! p(cos theta) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^(3/2)),
//!
//! normalised over the sphere, g in (-1, 1) its mean cosine (0 isotropic, positive forward).
//! In a path's terms (both directions leaving the scattering point x): `wo` toward where the
//! light goes (the previous vertex), `wi` toward where it comes from; the light travels along
//! -wi, then along wo, so cos theta = -wi . wo. A path tracer's phase "sample" is therefore a
//! `wi` near the path's own direction of travel -wo for g > 0.
//!
//! Sampling inverts the distribution of mu = cos theta, whose density over [-1, 1] (the
//! azimuth uniform) is (1 - g^2) / (2 (1 + g^2 - 2 g mu)^(3/2)). Its CDF is
//! F(mu) = (1 - g^2) / (2 g) [(1 + g^2 - 2 g mu)^(-1/2) - 1 / (1 + g)], and F(mu) = xi gives
//! mu = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g xi))^2) / (2 g) (the form in pbrt-v4, 4th ed.,
//! section 11.3.1, derived here from the CDF). Below |g| = 1e-3 the formula cancels badly and
//! the distribution is isotropic to within 0.3% (its ratio to the isotropic density lies between
//! (1 - g) / (1 + g)^2 and (1 + g) / (1 - g)^2);
//! there [`eval`] and [`sample`] both take g as 0 (mu = 2 xi - 1), so the sampler stays exact
//! for the density it reports.

use crate::frame::orthonormal_basis_v3;
use crate::real::{self, abs, V3};
use crate::turns::cos_sin_turns;
use core::f32::consts::PI;
use spirv_std::glam::Vec3;

/// Below this |g| the phase function is taken as isotropic (see the module's documentation).
pub const ISOTROPIC_G: f32 = 1e-3;

/// g as the sampler and the density use it: 0 below [`ISOTROPIC_G`].
#[inline]
fn effective<R: real::Real>(g: R) -> R {
    real::select(abs(g).less_than(R::splat(ISOTROPIC_G)), R::splat(0.0), g)
}

/// The phase function of asymmetry `g` at `cos_theta` (the cosine of the scattering angle),
/// per steradian. Over any [`real::Real`] (the tests bound its error under a Vulkan device's
/// arithmetic by running it on intervals).
#[inline]
pub fn of_angle<R: real::Real>(g: R, cos_theta: R) -> R {
    let one = R::splat(1.0);
    let g = effective(g);
    let denom = one + g * g - R::splat(2.0) * g * cos_theta;
    (one - g * g) / (R::splat(4.0 * PI) * denom * denom.max(R::splat(0.0)).sqrt())
}

/// The phase function for light arriving from `wi` and leaving toward `wo` (unit, both
/// pointing away from the scattering point); also the density of [`sample`]'s direction.
#[inline]
pub fn eval(g: f32, wo: Vec3, wi: Vec3) -> f32 {
    eval_v3(g, V3::from(wo), V3::from(wi))
}

/// [`eval`] over any [`real::Real`].
#[inline]
pub fn eval_v3<R: real::Real>(g: R, wo: V3<R>, wi: V3<R>) -> R {
    of_angle(g, -wi.dot(wo))
}

/// A direction `wi` drawn with density [`eval`]`(g, wo, wi)` from uniform numbers `u1` (the
/// angle) and `u2` (the azimuth) in (0, 1).
///
/// The sine of the scattering angle is sqrt((1 - mu)(1 + mu)) with both factors written without
/// a difference of nearly equal numbers: with d = 1 - g + 2 g u1 = (1 - g)(1 - u1) + (1 + g) u1
/// and s = (1 - g)(1 + g) / d, the module's mu gives 1 - mu = (1 - g)(1 - u1)(s + 1 - g) / d and
/// 1 + mu = (1 + g) u1 (1 + g + s) / d, so the angle keeps its precision where the direction
/// nears the axis of travel (sqrt(1 - mu^2) took the square root of a rounding there) and for
/// strong asymmetry (1 - g^2 and d cancelled for |g| near 1); mu is taken from the smaller
/// factor. These hold at g = 0 too (1 - mu = 2 (1 - u1), 1 + mu = 2 u1: mu = 2 u1 - 1, the
/// isotropic sampler), so no branch is needed where [`eval`] takes g as 0. The azimuth is
/// [`cos_sin_turns`] of u2: sums and products only, so a Vulkan device, whose `sin` and `cos`
/// may be off by 2^-11 (absolute), turns it as the CPU does.
#[inline(always)]
pub fn sample(g: f32, wo: Vec3, u1: f32, u2: f32) -> Vec3 {
    sample_v3(g, V3::from(wo), u1, u2).into()
}

/// [`sample`] over any [`real::Real`] (the tests run it under a model of Vulkan's arithmetic).
#[inline(always)]
pub fn sample_v3<R: real::Real>(g: R, wo: V3<R>, u1: R, u2: R) -> V3<R> {
    let one = R::splat(1.0);
    let g = effective(g);
    let (minus, plus, rest) = (one - g, one + g, one - u1);
    let d = minus * rest + plus * u1;
    let s = minus * plus / d;
    let one_minus_mu = minus * rest * (s + minus) / d;
    let one_plus_mu = plus * u1 * (plus + s) / d;
    let mu = real::select(
        one_minus_mu.less_than(one_plus_mu),
        one - one_minus_mu,
        one_plus_mu - one,
    );
    let sin = (one_minus_mu * one_plus_mu).sqrt();
    let (cos_phi, sin_phi) = cos_sin_turns(u2);
    // About the direction of travel -wo: mu = cos theta = -wi . wo.
    let travel = -wo;
    let (t, b) = orthonormal_basis_v3(travel);
    let v = travel * mu + (t * cos_phi + b * sin_phi) * sin;
    v.normalize()
}
