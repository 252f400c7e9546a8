//! A path vertex's random samples as a value (pbrt-v4's wavefront `RaySamples`,
//! `src/pbrt/gpu/workitems.h`, filled by `src/pbrt/gpu/samples.cpp`): the vertex first states
//! what it will draw ([`VertexQuery`]: its block of dimensions, its receiver and normal, its
//! light choice, whether roulette draws), then consumes a [`VertexSamples`]: the uniform
//! numbers it reads, and any sample a filler computed from them ahead. One path fills it with
//! [`VertexSamples::draw`] (the GPU, the one-path loop: numbers only); the CPU's packets fill
//! sixteen at once from sixteen queries with the samplers' `Real`/`Word` forms on SIMD lanes. A
//! filler must give, for every number the query asks for, exactly what `draw` gives, and for a
//! sample it gives, exactly what the vertex would compute. This module alone owns the layout of
//! a vertex's dimensions.

use crate::bsdf::lambert::sample_brdf;
use crate::light::{self, LightKinds, LightSample};
use crate::rng::SampleRng;
use crate::scene_view::SceneView;
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
// Split paths' continuations read their own sequence index from the first vertex's roulette
// number on (`crate::split`).
const _: () = assert!(crate::rng::CONTINUED_FROM == CAMERA_DIMENSIONS + ROULETTE_DIMENSION);
/// The lobe choice of the vertex at depth d (a BSDF that mixes lobes,
/// `bsdf::BsdfFlags::chooses_lobe`) is dimension `LOBE_DIMENSION + d`: outside every vertex's
/// block, so scenes without such a material draw exactly the numbers they drew before it
/// existed. (Both samplers hash the dimension into an independent stream: any dimension is as
/// good as the next.)
pub const LOBE_DIMENSION: u32 = 1 << 31;
/// The thin lens's pair (the point on the lens), drawn only by cameras with a lens: outside every
/// vertex's block and below the lobe choices, so pinhole renders draw exactly what they drew
/// before lenses existed.
pub const LENS_DIMENSION: u32 = LOBE_DIMENSION - 2;
/// A path's hero channel in media (`crate::free_flight`) is dimension `FLIGHT_DIMENSION`, the
/// distance of its k-th free flight in a homogeneous medium that scatters `FLIGHT_DIMENSION +
/// 1 + k`: outside every vertex's block and above the lobe choices, so scenes without such a
/// medium draw exactly the numbers they drew before media existed.
pub const FLIGHT_DIMENSION: u32 = LOBE_DIMENSION + (1 << 30);
/// The seed of the k-th flight's tracking stream in a grid medium (`crate::delta_tracking`)
/// is dimension `GRID_DIMENSION + k` (between the lobe choices and the flights).
pub const GRID_DIMENSION: u32 = LOBE_DIMENSION + (1 << 29);
/// In [`VertexQuery::dimensions`]: a number the vertex does not read.
pub const NO_DIMENSION: u32 = u32::MAX;

/// What a vertex will draw, decided before any number is drawn.
#[derive(Clone, Copy, Debug)]
pub struct VertexQuery {
    /// The vertex's depth (1 for the camera ray's hit): its block of dimensions.
    pub depth: u32,
    /// The receiver point and the normal on the side the ray arrived from: the shading
    /// normal, or the geometric one (`ng`) on surfaces without vertex normals.
    pub x: Vec3,
    pub n: Vec3,
    /// The geometric normal on the side the ray arrived from (rays leave offset along it).
    pub ng: Vec3,
    /// Whether `n` is an interpolated shading normal (`crate::surface`).
    pub smooth: bool,
    /// Lights next-event estimation chooses among; 0: no light sample (no lights, or a black
    /// surface).
    pub light_count: u32,
    /// How a point on the chosen light is sampled (`scene::light_sampling`).
    pub mode: u32,
    /// The light kinds the table may hold besides spheres.
    pub light_kinds: LightKinds,
    /// Whether the vertex may extend the path (its depth is below `max_depth`).
    pub extend: bool,
    /// The roulette's survival probability: a number is drawn only where `roulette` and not
    /// `survival >= 1` (survival at 1 is certain).
    pub roulette: bool,
    pub survival: f32,
    /// Whether the surface is Lambertian (the diffuse renderer's vertex; a filler may give
    /// its direction, `VertexSamples::brdf_dir`).
    pub lambertian: bool,
    /// Whether the BSDF reads a lobe-choice number (`VertexSamples::u_lobe`) when it extends.
    pub chooses_lobe: bool,
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

    /// The dimensions of the numbers the vertex may read ([`NO_DIMENSION`] where it reads
    /// none): the single numbers `[light choice, roulette]` and the first dimensions of the
    /// pairs `[light point, BRDF]`, the order of [`VertexSamples::from_numbers`].
    #[inline]
    pub fn dimensions(&self) -> ([u32; 2], [u32; 2]) {
        let block = self.block();
        let at = |read: bool, offset: u32| if read { block + offset } else { NO_DIMENSION };
        (
            [
                at(self.chooses_light(), LIGHT_CHOICE_DIMENSION),
                at(self.draws_roulette(), ROULETTE_DIMENSION),
            ],
            [
                at(self.samples_light(), LIGHT_POINT_DIMENSION),
                at(self.extend, BRDF_DIMENSION),
            ],
        )
    }

    /// The dimension of the lobe-choice number, or [`NO_DIMENSION`] where none is read.
    #[inline]
    pub fn lobe_dimension(&self) -> u32 {
        if self.extend && self.chooses_lobe {
            LOBE_DIMENSION + self.depth
        } else {
            NO_DIMENSION
        }
    }

    /// Whether the path survives roulette number `u` (always, where no number is drawn).
    #[inline]
    pub fn survives(&self, u: f32) -> bool {
        !self.draws_roulette() || u < self.survival
    }
}

/// A vertex's samples: the uniform numbers it reads (the light choice's where
/// [`VertexQuery::chooses_light`], the light point's pair where [`VertexQuery::samples_light`],
/// the roulette's where [`VertexQuery::draws_roulette`], the BRDF's pair where the vertex
/// extends and survives roulette), and optionally the light sample and the BRDF direction a
/// filler computed from them ahead (`has_light`, `has_brdf_dir`; the CPU's packets, on SIMD
/// lanes). The vertex computes any sample not given with the kernel's scalar sampler, so a
/// filler that knows nothing of a new lobe or light stays correct. Fields the query does not
/// ask for are not read.
#[derive(Clone, Copy, Debug)]
pub struct VertexSamples {
    pub u_select: f32,
    pub u_light: (f32, f32),
    pub u_roulette: f32,
    pub u_brdf: (f32, f32),
    /// The lobe choice, where [`VertexQuery::lobe_dimension`] names one and the path survives
    /// roulette.
    pub u_lobe: f32,
    /// `light::sample(scene, light_kinds, light_count, mode, x, u_select, u_light)`, if
    /// `has_light`.
    pub light: LightSample,
    pub has_light: bool,
    /// `sample_brdf(n, u_brdf)`, if `has_brdf_dir`.
    pub brdf_dir: Vec3,
    pub has_brdf_dir: bool,
}

impl VertexSamples {
    /// No numbers, no samples (the fields a filler has not set).
    pub const NONE: Self = Self {
        u_select: 0.0,
        u_light: (0.0, 0.0),
        u_roulette: 0.0,
        u_brdf: (0.0, 0.0),
        u_lobe: 0.0,
        light: LightSample::NONE,
        has_light: false,
        brdf_dir: Vec3::ZERO,
        has_brdf_dir: false,
    };

    /// The samples holding the numbers read at `dimensions` (a [`VertexQuery::dimensions`]):
    /// `singles` = [light choice, roulette], `pairs` = [light point, BRDF], each kept where its
    /// dimension is read and 0 elsewhere, as [`VertexSamples::draw`] leaves it (a filler that
    /// computes numbers for many vertices at once gives them here; no sample is given; the
    /// lobe choice, where drawn, is set apart: [`VertexQuery::lobe_dimension`]).
    #[inline]
    pub fn from_numbers(
        ([choice, roulette], [point, brdf]): ([u32; 2], [u32; 2]),
        singles: [f32; 2],
        pairs: [(f32, f32); 2],
    ) -> Self {
        let single = |d: u32, u: f32| if d != NO_DIMENSION { u } else { 0.0 };
        let pair = |d: u32, u: (f32, f32)| if d != NO_DIMENSION { u } else { (0.0, 0.0) };
        Self {
            u_select: single(choice, singles[0]),
            u_roulette: single(roulette, singles[1]),
            u_light: pair(point, pairs[0]),
            u_brdf: pair(brdf, pairs[1]),
            ..Self::NONE
        }
    }

    /// One vertex's numbers from its stream, at [`VertexQuery::dimensions`], drawing only
    /// those it will read: no BRDF pair after roulette ends the path (the stream is
    /// counter-based: the others keep their values either way).
    #[inline]
    pub fn draw(query: &VertexQuery, rng: &mut SampleRng) -> Self {
        let mut s = Self::NONE;
        let ([choice, roulette], [point, brdf]) = query.dimensions();
        if choice != NO_DIMENSION {
            rng.seek(choice);
            s.u_select = rng.next_f32();
        }
        if point != NO_DIMENSION {
            rng.seek(point);
            s.u_light = rng.next_2d();
        }
        if roulette != NO_DIMENSION {
            rng.seek(roulette);
            s.u_roulette = rng.next_f32();
            if !query.survives(s.u_roulette) {
                return s;
            }
        }
        if brdf != NO_DIMENSION {
            rng.seek(brdf);
            s.u_brdf = rng.next_2d();
        }
        let lobe = query.lobe_dimension();
        if lobe != NO_DIMENSION {
            rng.seek(lobe);
            s.u_lobe = rng.next_f32();
        }
        s
    }

    /// The light sample for `query`: the one given, or computed now.
    #[inline]
    pub fn light_sample(&self, query: &VertexQuery, scene: &SceneView) -> LightSample {
        if self.has_light {
            return self.light;
        }
        light::sample(
            scene,
            query.light_kinds,
            query.light_count,
            query.mode,
            query.x,
            self.u_select,
            self.u_light,
        )
    }

    /// The BRDF direction for `query`: the one given, or computed now.
    #[inline]
    pub fn brdf_direction(&self, query: &VertexQuery) -> Vec3 {
        if self.has_brdf_dir {
            return self.brdf_dir;
        }
        let (u1, u2) = self.u_brdf;
        sample_brdf(query.n, u1, u2)
    }
}
