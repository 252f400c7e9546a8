//! Heterogeneous media (a density grid, `crate::density_grid`): where along a ray the next
//! collision happens, by delta tracking against the grid's majorants, without bias and for
//! RGB coefficients.
//!
//! A grid medium's extinction at a point of density rho is rho sigma_t (per channel k:
//! rho sigma_t,k). In a majorant cell of majorant density M >= rho, add *null* particles of
//! density M - rho that scatter straight on with weight 1: the medium becomes homogeneous, of
//! extinction M sigma_t, in that cell, so free flights can be drawn in closed form, cell by
//! cell (memorylessness lets a flight stop at each cell's face and start again), and at each
//! tentative collision the particle hit is real with probability rho / M (Woodcock tracking;
//! the null-scattering path integral of Miller, Georgiev and Jarosz, SIGGRAPH 2019; pbrt-v4,
//! 4th ed., sections 11.4 and 14.1.2).
//!
//! Flights ([`flight`]): drawn by the path's hero channel h (`crate::free_flight`). Per
//! channel k, with T_k the majorant transmittance exp(-M sigma_t,k s) over the distance s since
//! the last event, the events' densities and contributions are
//! - a real collision: p_k = (rho / M) M sigma_t,k T_k = rho sigma_t,k T_k,
//!   f_k = rho sigma_s,k T_k;
//! - a null collision: p_k = f_k = (M - rho) sigma_t,k T_k (its contribution is its density);
//! - passing the surface: p_k = f_k = T_k.
//!
//! The path takes them as it takes a homogeneous medium's (the balance heuristic over the
//! three channels, `crate::free_flight`). The real/null choice (rho / M) is the same for every
//! channel, so it cancels in every ratio; a null collision changes the weight only through
//! the channels' different majorant transmittances, and in the one channel it is drawn by it
//! leaves the weight F_c / P_c unchanged: the bound 3 F_c / P_c holds with any number of them.
//! Where M equals the extinction everywhere (a constant grid) no null collision happens and
//! the estimator is the homogeneous one.
//!
//! Transmittance (shadow segments, media that only absorb) needs no estimate: the density is
//! trilinear, so the optical depth along a segment is exact (`density_grid::optical_depth`)
//! and exp(-sigma_t tau) is the transmittance itself. Ratio tracking (Novák, Selle and Jarosz,
//! SIGGRAPH Asia 2014) would estimate it with relative variance exp(sigma_t tau) - 1 where
//! the majorant is tight (docs/media.md).
//!
//! The numbers: a tracking loop draws as many as its tentative collisions need, so it reads
//! a [`TrackingStream`] (Jarzynski and Olano's pcg4d, `crate::hash`, of the 32 random bits the
//! sample's stream gives it and a counter), not the sample's dimensions one by one.

use crate::density_grid::{DensityGrid, MajorantWalk};
use crate::free_flight::{self, component, Flight};
use crate::hash::pcg4d;
use crate::medium::transmittance as majorant_transmittance;
use crate::rng::u32_to_unit_f32;
use spirv_std::glam::Vec3;

/// A stream of uniform numbers for one tracking loop: number n is the first word of
/// pcg4d(seed, key, n, constant), mapped to (0, 1).
#[derive(Clone, Copy, Debug)]
pub struct TrackingStream {
    seed: u32,
    key: u32,
    n: u32,
}

impl TrackingStream {
    /// The stream of 32 random bits `seed` (drawn from the sample's stream) and `key` (which
    /// tells apart loops that share a seed).
    #[inline]
    pub fn new(seed: u32, key: u32) -> Self {
        Self { seed, key, n: 0 }
    }

    /// The next number, uniform in (0, 1).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        let bits = pcg4d([self.seed, self.key, self.n, 0x2545_f491])[0];
        self.n = self.n.wrapping_add(1);
        u32_to_unit_f32(bits)
    }
}

/// The path's flight weight and ratios after an event of densities `p` and contribution `f`
/// (`free_flight::weigh`).
#[inline]
fn weigh(weight: Vec3, ratios: Vec3, p: Vec3, f: Vec3) -> (Vec3, Vec3) {
    let (w, r) = free_flight::weigh(ratios, p, f);
    (weight * w, r)
}

/// The free flight of ray `origin + t dir` (`dir` of unit length) through a grid medium of
/// extinction `sigma_t` and scattering `sigma_s` per unit density, whose surface (or the
/// scene's end, `f32::MAX`) lies at distance `end`, drawn by channel `hero` from `stream`
/// for a path whose ratios are `ratios`: delta tracking (see the module's documentation).
/// The weight is the product of the events' weights.
pub fn flight(
    (sigma_t, sigma_s): (Vec3, Vec3),
    grid: &DensityGrid,
    (origin, dir, end): (Vec3, Vec3, f32),
    hero: u32,
    stream: &mut TrackingStream,
    ratios: Vec3,
) -> Flight {
    let sigma_h = component(sigma_t, hero);
    let mut walk = MajorantWalk::new(grid, origin, dir, 0.0, end);
    let (mut weight, mut ratios) = (Vec3::ONE, ratios);
    // The majorant's optical depth per channel since the last event, and what is left of the
    // hero's exponential number.
    let mut depth = Vec3::ZERO;
    let mut left = free_flight::unit_exponential(stream.next_f32());
    while walk.more() {
        let segment = walk.next(grid);
        let majorant = segment.majorant;
        let rate = sigma_t * majorant;
        let rate_h = sigma_h * majorant;
        let mut t = segment.t0;
        loop {
            let span = segment.t1 - t;
            if !(rate_h * span > left) {
                depth += rate * span;
                left -= rate_h * span;
                break;
            }
            let dt = left / rate_h;
            t += dt;
            depth += rate * dt;
            let rho = grid.density_inside(origin + dir * t).min(majorant);
            let tr = majorant_transmittance(depth, 1.0);
            if stream.next_f32() * majorant < rho {
                let (w, r) = weigh(weight, ratios, sigma_t * (rho * tr), sigma_s * (rho * tr));
                return Flight {
                    scattered: true,
                    t,
                    weight: w,
                    ratios: r,
                };
            }
            let null = sigma_t * ((majorant - rho) * tr);
            (weight, ratios) = weigh(weight, ratios, null, null);
            depth = Vec3::ZERO;
            left = free_flight::unit_exponential(stream.next_f32());
        }
    }
    let tr = majorant_transmittance(depth, 1.0);
    (weight, ratios) = weigh(weight, ratios, tr, tr);
    Flight {
        scattered: false,
        t: end,
        weight,
        ratios,
    }
}
