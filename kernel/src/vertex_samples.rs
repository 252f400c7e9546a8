//! A path vertex's random samples as a value (pbrt-v4's wavefront `RaySamples`,
//! `src/pbrt/gpu/workitems.h`, filled by `src/pbrt/gpu/samples.cpp`): the vertex first states
//! what it will draw ([`VertexQuery`]: its block of dimensions, its receiver and normal, its
//! light choice, whether roulette draws), then consumes a [`VertexSamples`]. One path fills it
//! with [`VertexSamples::draw`] (the GPU, the one-path loop); the CPU's packets fill sixteen at
//! once from sixteen queries with the samplers' `Real`/`Word` forms on SIMD lanes. A filler
//! must give, for every sample the query asks for, exactly what `draw` gives. This module alone
//! owns the layout of a vertex's dimensions.

use crate::brdf::sample_brdf;
use crate::light::{sample_light_from, DirectionalLightSample};
use crate::rng::SampleRng;
use crate::sampling::SurfacePoint;
use crate::scene::{SphereLight, NONE};
use spirv_std::glam::Vec3;

/// Random dimensions per path vertex: light choice (1) and point (2), roulette (1), BRDF (2).
/// (Pairs start at offsets 1 and 4 of the block; the Sobol sampler scrambles each from its own
/// starting dimension, so pairs need no alignment.)
pub const DIMENSIONS_PER_VERTEX: u32 = 6;
/// Offsets in a vertex's block of dimensions: the light choice (one number), the point on the
/// light (a pair), the roulette decision (one), the BRDF direction (a pair).
pub const LIGHT_CHOICE_DIMENSION: u32 = 0;
pub const LIGHT_POINT_DIMENSION: u32 = 1;
pub const ROULETTE_DIMENSION: u32 = 3;
pub const BRDF_DIMENSION: u32 = 4;
/// The camera's pair (the position inside the pixel), before the first vertex's block.
pub const CAMERA_DIMENSION: u32 = 0;
pub const CAMERA_DIMENSIONS: u32 = 2;

/// What a vertex will draw, decided before any number is drawn.
#[derive(Clone, Copy, Debug)]
pub struct VertexQuery {
    /// The vertex's depth (1 for the camera ray's hit): its block of dimensions.
    pub depth: u32,
    /// The receiver point and the normal on the side the ray arrived from.
    pub x: Vec3,
    pub n: Vec3,
    /// Lights next-event estimation chooses among; 0: no light sample (no lights, or a black
    /// surface).
    pub light_count: u32,
    /// How a point on the chosen light is sampled (`scene::light_sampling`).
    pub mode: u32,
    /// Whether the vertex may extend the path (its depth is below `max_depth`).
    pub extend: bool,
    /// The roulette's survival probability: a number is drawn only where `roulette` and not
    /// `survival >= 1` (survival at 1 is certain).
    pub roulette: bool,
    pub survival: f32,
}

impl VertexQuery {
    /// First dimension of the vertex's block.
    #[inline]
    pub fn block(&self) -> u32 {
        CAMERA_DIMENSIONS + (self.depth - 1) * DIMENSIONS_PER_VERTEX
    }

    /// Whether a light sample is drawn.
    #[inline]
    pub fn samples_light(&self) -> bool {
        self.light_count > 0
    }

    /// Whether the light choice's number is drawn (several lights to choose among).
    #[inline]
    pub fn chooses_light(&self) -> bool {
        self.light_count > 1
    }

    /// Whether the roulette's number is drawn.
    #[inline]
    pub fn draws_roulette(&self) -> bool {
        self.extend && self.roulette && !(self.survival >= 1.0)
    }

    /// Whether the path survives roulette number `u` (always, where no number is drawn).
    #[inline]
    pub fn survives(&self, u: f32) -> bool {
        !self.draws_roulette() || u < self.survival
    }
}

/// A vertex's samples: its light sample (where [`VertexQuery::samples_light`]), its roulette
/// number (where [`VertexQuery::draws_roulette`]) and its BRDF direction (where the vertex
/// extends and survives roulette). Fields the query does not ask for are not read.
#[derive(Clone, Copy, Debug)]
pub struct VertexSamples {
    pub light: DirectionalLightSample,
    pub u_roulette: f32,
    pub brdf_dir: Vec3,
}

impl VertexSamples {
    /// No samples (the fields a filler has not set).
    pub const NONE: Self = Self {
        light: DirectionalLightSample {
            point: SurfacePoint {
                position: Vec3::ZERO,
                normal: Vec3::ZERO,
            },
            light: NONE,
            pdf_solid_angle: 0.0,
        },
        u_roulette: 0.0,
        brdf_dir: Vec3::ZERO,
    };

    /// One vertex's samples from its stream, drawing only the numbers it will read (the stream
    /// is counter-based: the others keep their values either way).
    #[inline]
    pub fn draw(query: &VertexQuery, rng: &mut SampleRng, lights: &[SphereLight]) -> Self {
        let mut s = Self::NONE;
        let block = query.block();
        if query.samples_light() {
            let u_select = if query.chooses_light() {
                rng.seek(block + LIGHT_CHOICE_DIMENSION);
                rng.next_f32()
            } else {
                0.0
            };
            rng.seek(block + LIGHT_POINT_DIMENSION);
            let (u1, u2) = rng.next_2d();
            s.light = sample_light_from(
                lights,
                query.light_count,
                query.mode,
                query.x,
                u_select,
                u1,
                u2,
            );
        }
        if !query.extend {
            return s;
        }
        if query.draws_roulette() {
            rng.seek(block + ROULETTE_DIMENSION);
            s.u_roulette = rng.next_f32();
            if !query.survives(s.u_roulette) {
                return s;
            }
        }
        rng.seek(block + BRDF_DIMENSION);
        let (u1, u2) = rng.next_2d();
        s.brdf_dir = sample_brdf(query.n, u1, u2);
        s
    }
}
