//! Free-flight sampling in a homogeneous medium that scatters: where along a ray the next
//! collision happens, for RGB coefficients, without bias.
//!
//! In one channel of extinction sigma_t, the distance to the first collision has density
//! sigma_t exp(-sigma_t t), and the ray passes a surface at distance d with probability
//! exp(-sigma_t d); drawing t = -ln(1 - u) / sigma_t and scattering where t < d, with weight
//! T(t) sigma_s / pdf(t) = sigma_s / sigma_t at a collision and T(d) / P(pass) = 1 at the
//! surface, estimates the volume rendering equation with the surface term (pbrt-v4, 4th ed.,
//! section 14.1; Woodcock's delta tracking with the majorant equal to sigma_t, where no null
//! collisions occur).
//!
//! With three channels, one channel's distances serve all three. A path chooses its *hero*
//! channel h uniformly once and draws every free flight with sigma_t,h; technique k ("draw with
//! channel k") gives the path's distances a density P_k, the product of its events' densities
//! p_k (sigma_t,k T_k(t) at a collision, T_k(d) at a pass). Weighing the path's contribution
//! F_c by 1 / ((1/3) sum_k P_k) is Veach's one-sample model of multiple importance sampling
//! with the balance heuristic over the three techniques (Veach's thesis, section 9.2.4; the
//! hero-wavelength spectral MIS of Wilkie, Nawaz, Droske, Weidlich and Hanika, EGSR 2014, which
//! pbrt-v4's volumetric path tracer applies per path with its rescaled probabilities r_u,
//! section 14.2.2): unbiased in every channel, and bounded by 3 F_c / P_c whatever the number of
//! collisions (a weight per collision would multiply up to 3 per collision). Directions,
//! roulette and the surfaces' lobes are drawn alike by every technique and cancel.
//!
//! The path carries the ratios r_k = P_k / mean(P) ([`Flight::ratios`], (1, 1, 1) where the
//! path starts) and its throughput as F / mean(P); an event of densities p and contribution f
//! (sigma_s T at a collision, T at a pass) updates them to
//! throughput f / mean(r p) and r p / mean(r p), which keeps mean(r) = 1 and every number
//! bounded.

use crate::medium::transmittance_v3;
use crate::real::{Exponential, Real, V3};
use spirv_std::glam::Vec3;

/// A sampled free flight along a ray: a collision at `t` (`scattered`) or none before the
/// surface at the ray's end, the weight that multiplies the path's throughput, and the path's
/// new ratios of technique densities.
#[derive(Clone, Copy, Debug)]
pub struct Flight {
    pub scattered: bool,
    pub t: f32,
    pub weight: Vec3,
    pub ratios: Vec3,
}

/// The component `channel` (0, 1 or 2) of `v`.
#[inline]
pub fn component(v: Vec3, channel: u32) -> f32 {
    component_v3(v.into(), channel)
}

/// [`component`] of a [`V3`].
#[inline]
pub fn component_v3<R: Real>(v: V3<R>, channel: u32) -> R {
    if channel == 0 {
        v.x
    } else if channel == 1 {
        v.y
    } else {
        v.z
    }
}

/// The hero channel (0, 1 or 2) of uniform number `u` in [0, 1).
#[inline]
pub fn hero_channel(u: f32) -> u32 {
    ((u * 3.0) as u32).min(2)
}

/// A unit exponential number, -ln(1 - u), from uniform `u` in (0, 1), never negative.
/// Under IEEE arithmetic ln(1 - u) <= 0 for every such u, but a Vulkan device's `log` may err
/// by 2^-21 absolutely on [0.5, 2], so for 1 - u within 2^-21 of 1 it may return a positive
/// number: the flight would run backwards, its collision behind the ray's origin and perhaps
/// across the surface the ray left (`docs/robustness.md`, "Under Vulkan's arithmetic"). The
/// clamp to 0 changes no number IEEE arithmetic gives but the sign of a zero.
#[inline]
pub fn unit_exponential<R: Exponential>(u: R) -> R {
    (-(R::splat(1.0) - u).ln()).max(R::splat(0.0))
}

/// The distance a hero channel of extinction `sigma` draws from uniform `u` in (0, 1)
/// (`f32::MAX` where it does not attenuate: it never collides).
#[inline]
pub fn distance<R: Exponential>(sigma: R, u: R) -> R {
    let attenuates = sigma.greater_than(R::splat(0.0));
    R::select(attenuates, unit_exponential(u) / sigma, R::splat(f32::MAX))
}

/// The free flight of a ray in a medium of extinction `sigma_t` and scattering `sigma_s`
/// whose surface (or the scene's end: `f32::MAX`) lies at distance `d`, drawn by channel
/// `hero` from uniform `u` in (0, 1), for a path whose ratios are `ratios` (see the module's
/// documentation).
#[inline]
pub fn sample(sigma_t: Vec3, sigma_s: Vec3, d: f32, hero: u32, u: f32, ratios: Vec3) -> Flight {
    let f = sample_v3(sigma_t.into(), sigma_s.into(), d, hero, u, ratios.into());
    Flight {
        scattered: f.scattered != 0,
        t: f.t,
        weight: f.weight.into(),
        ratios: f.ratios.into(),
    }
}

/// A [`Flight`] over any [`Exponential`] number: `scattered` is all ones where the ray collides.
#[derive(Clone, Copy, Debug)]
pub struct FlightV3<R: Real> {
    pub scattered: R::Bits,
    pub t: R,
    pub weight: V3<R>,
    pub ratios: V3<R>,
}

/// [`sample`] over any [`Exponential`] number.
#[inline]
pub fn sample_v3<R: Exponential>(
    sigma_t: V3<R>,
    sigma_s: V3<R>,
    d: R,
    hero: u32,
    u: R,
    ratios: V3<R>,
) -> FlightV3<R> {
    let t = distance(component_v3(sigma_t, hero), u);
    let scattered = t.less_than(d);
    let at = R::select(scattered, t, d);
    let tr = transmittance_v3(sigma_t, at);
    // Each technique's density of this event, and the path's contribution.
    let p = V3::select(scattered, sigma_t * tr, tr);
    let f = V3::select(scattered, sigma_s * tr, tr);
    let (weight, ratios) = weigh_v3(ratios, p, f);
    FlightV3 {
        scattered,
        t: at,
        weight,
        ratios,
    }
}

/// The weight of an event of technique densities `p` and contribution `f` for a path whose
/// ratios are `ratios`, and the path's new ratios: f / mean(r p) and r p / mean(r p) (see the
/// module's documentation). Delta tracking's events take the same update
/// (`crate::delta_tracking`).
#[inline]
pub fn weigh(ratios: Vec3, p: Vec3, f: Vec3) -> (Vec3, Vec3) {
    let (weight, ratios) = weigh_v3(ratios.into(), p.into(), f.into());
    (weight.into(), ratios.into())
}

/// [`weigh`] over any [`Real`] number.
#[inline]
pub fn weigh_v3<R: Real>(ratios: V3<R>, p: V3<R>, f: V3<R>) -> (V3<R>, V3<R>) {
    let q = ratios * p;
    let m = q.element_sum() * R::splat(1.0 / 3.0);
    (f / m, q / m)
}
