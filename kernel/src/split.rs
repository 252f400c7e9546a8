//! Splitting at the first vertex: a sample's path, once it reaches its first vertex, continues
//! from there `n` times, and the sample's value is the first vertex's part plus the mean of the
//! continuations'. Where the variance of a pixel lies mostly after the first vertex, this buys
//! its variance for less than `n` whole samples would cost (the camera ray, the first vertex's
//! shading and its light sample are paid once).
//!
//! # Derivation
//! Write a sample's estimate as L = P + C: P what the path gathers up to and including the
//! first vertex's light sample (the emission the camera ray sees, the light sample's
//! contribution), C what the path gathers from the first vertex's roulette and BRDF sample
//! on. Given the prefix X (the camera sample, the first vertex, its light sample), n
//! continuations C_1..C_n drawn independently from the same conditional law give
//! `P + (1/n) sum C_j` with expectation E[P + E[C | X]] = E[L]: unbiased for any n >= 1 that
//! depends on nothing the sample draws. Its variance is Var(E[L | X]) + E[Var(C | X)] / n (the
//! law of total variance), at cost c_P + n c_C. This is splitting as in Arvo and Kirk 1990
//! ("Particle transport and image synthesis", section 5) and, with n chosen per region from
//! what each part costs and contributes, the splitting half of Vorba and Křivánek 2016
//! ("Adjoint-driven Russian roulette and splitting", section 4) and Rath et al. 2022
//! ("EARS", section 4.1), whose n minimises variance times cost.
//!
//! Here n comes from the split table, one entry per tile of the image, which the host learns
//! from a pilot render with its own seed (`host::split_pilot`), so n is a function of the
//! pixel alone and a render stays a pure function of (scene, settings, seed, pixel, sample
//! index): parts merge exactly.
//!
//! # Numbers
//! The prefix draws the sample's numbers (`crate::vertex_samples`): the camera's, and the first
//! vertex's light choice and point. Continuation j of sample s draws every number it reads,
//! from the first vertex's roulette, BRDF pair and lobe choice on, from sample index `s n + j`
//! of the same stream: no dimension is read twice, and the n N continuations of N samples take
//! the first n N points of every later pair's Sobol sequence (independent numbers with the
//! independent sampler). With n = 1 the sample is exactly the unsplit path, numbers and
//! arithmetic alike.
//!
//! # Pilot
//! Under `split_mode::PILOT` every sample splits in two and its value is
//! [`pilot_value`]: the two unsplit estimates' luminances y1 = Y(P + C_1), y2 = Y(P + C_2)
//! and the first continuation's rounds of ray casts, from which the film's sums give, per pixel,
//! Var(L) = Var(y1), Var(E[L | X]) = Cov(y1, y2) = (Var(y1 + y2) - 2 Var(y1)) / 2 and the
//! continuation's cost.

use crate::adaptive::luminance;
use crate::features::FeatureSet;
use crate::hit::SurfaceHit;
use crate::path::{start_sample, PathState, Tracer};
use crate::rng::SampleRng;
use crate::scene::{split_mode, Material, RenderParams};
use crate::scene_view::SceneView;
use crate::vertex_samples::{VertexQuery, VertexSamples};
use spirv_std::glam::Vec3;

/// The most continuations a split table may give (the CPU's packets keep this many radiances
/// per sample).
pub const MAX_CONTINUATIONS: u32 = 4;
/// The continuations of every sample of the pilot.
pub const PILOT_CONTINUATIONS: u32 = 2;

/// How many times the paths of pixel (px, py) continue from their first vertex: the split
/// table's entry for the pixel's tile (clamped to 1..=[`MAX_CONTINUATIONS`]), two for the
/// pilot, one where nothing splits.
#[inline]
pub fn continuations_at(scene: &SceneView, px: u32, py: u32) -> u32 {
    let split = &scene.params.split;
    if split.mode == split_mode::PILOT {
        return PILOT_CONTINUATIONS;
    }
    if split.mode != split_mode::TABLE || split.tile_size == 0 {
        return 1;
    }
    let tile = (py / split.tile_size) * split.tile_columns + px / split.tile_size;
    if (tile as usize) < scene.splits.len() {
        scene.splits[tile as usize].clamp(1, MAX_CONTINUATIONS)
    } else {
        1
    }
}

/// The stream of continuation `j` of `n` of the sample drawn by `rng`: the same stream at
/// sample index `s n + j`.
#[inline]
pub fn continuation_rng(rng: SampleRng, n: u32, j: u32) -> SampleRng {
    SampleRng {
        continuation: rng.sample.wrapping_mul(n).wrapping_add(j),
        ..rng
    }
}

/// Makes `path` at its first vertex, and the `query` it reached there with, continuation `j`
/// of `n`: its stream ([`continuation_rng`]: the vertex's roulette, lobe and BRDF numbers are
/// its own, the light choice and point the sample's), and the light sample in continuation 0
/// only (in all of them under the pilot); the others start with no radiance.
#[inline]
pub fn continue_at_vertex(
    scene: &SceneView,
    n: u32,
    j: u32,
    path: &mut PathState,
    query: &mut VertexQuery,
) {
    path.rng = continuation_rng(path.rng, n, j);
    if j != 0 && scene.params.split.mode != split_mode::PILOT {
        path.radiance = Vec3::ZERO;
        query.light_count = 0;
    }
}

/// A path at its first vertex, before the vertex's light sample and extension: what every
/// continuation starts from.
#[derive(Clone, Copy, Debug)]
pub struct FirstVertex {
    /// The path as [`PathState::round`] left it at the vertex.
    pub path: PathState,
    pub hit: SurfaceHit,
    pub material: Material,
    pub query: VertexQuery,
}

impl FirstVertex {
    /// The first vertex `path` reached at `hit` (its round returned true at depth 1).
    #[inline]
    pub fn reached<F: FeatureSet>(
        path: PathState,
        features: F,
        scene: &SceneView,
        hit: &SurfaceHit,
    ) -> Self {
        let arrival = path.arrival(features, scene, hit);
        Self {
            path,
            hit: *hit,
            material: arrival.material,
            query: arrival.query,
        }
    }

    /// Continuation `j` of `n` at the vertex, and the query it draws its samples for
    /// ([`continue_at_vertex`]). The caller draws the samples, runs `PathState::vertex`, then
    /// [`FirstVertex::left`].
    #[inline]
    pub fn at_vertex(&self, scene: &SceneView, n: u32, j: u32) -> (PathState, VertexQuery) {
        let (mut path, mut query) = (self.path, self.query);
        continue_at_vertex(scene, n, j, &mut path, &mut query);
        (path, query)
    }

    /// Continuation `j` of `n` once `PathState::vertex` has run: continuation 0 carries the
    /// emission found so far and the light sample's contribution (P) times n, so the sample's
    /// value is the continuations' sum over n (not under the pilot, whose continuations are
    /// each P + C_j). Run to its end, its radiance is then n P + C_0, or C_j.
    #[inline]
    pub fn left(scene: &SceneView, n: u32, j: u32, path: &mut PathState) {
        if j == 0 && scene.params.split.mode != split_mode::PILOT {
            let scale = n as f32;
            path.radiance *= scale;
            path.shadow_radiance *= scale;
        }
    }
}

/// The rounds of ray casts a continuation that ended at depth `depth` took, as the pilot counts
/// its cost: one per vertex it reached after the first, and the round of its last extension
/// (a round casts a path's extension and its last vertex's shadow ray together, and the
/// backends' time goes by rounds: the CPU's packets trace sixteen paths' rounds at once).
#[inline]
pub fn continuation_rounds(depth: u32) -> f32 {
    depth.max(1) as f32
}

/// The pilot's value of a sample (`split_mode::PILOT`): the luminances of the two unsplit
/// estimates `l1` and `l2` and the first continuation's rounds, as (y1, rounds, y1 + y2).
#[inline]
pub fn pilot_value(l1: Vec3, l2: Vec3, rounds: f32) -> Vec3 {
    let (y1, y2) = (luminance(l1), luminance(l2));
    Vec3::new(y1, rounds, y1 + y2)
}

/// The value of a sample from the sum of its `n` continuations' radiances (added in the
/// order j = 0, 1, ..., from zero; continuation 0 carries n P): P + sum_j C_j / n.
#[inline]
pub fn split_value(continued: Vec3, n: u32) -> Vec3 {
    continued * (1.0 / n as f32)
}

/// The value of sample `sample` of pixel (px, py) with its path split at its first vertex as
/// [`continuations_at`] says; with one continuation exactly `path::render_sample`. A path that
/// ends before any vertex is its own value (the pilot's, as if both its continuations were
/// empty). One loop runs the prefix and every continuation, with one call of each step
/// (`round`, `arrival`, `vertex`): a continuation restarts from the path as it reached the
/// vertex and arrives there again (the arrival is a function of that state and the hit), so
/// that the ray generation shader, which runs it for every render, holds one copy of the
/// path's code. `may_split` false: one continuation, whatever the table says (the shader
/// passes `features::SPLIT`'s answer, a constant in a specialized kernel, which then keeps
/// nothing of the fork and is `render_sample`).
#[inline]
pub fn render_split_sample<T: Tracer, F: FeatureSet>(
    tracer: &mut T,
    features: F,
    scene: &SceneView,
    px: u32,
    py: u32,
    sample: u32,
    may_split: bool,
) -> Vec3 {
    let params = scene.params;
    let n = if may_split {
        continuations_at(scene, px, py)
    } else {
        1
    };
    let mut path = start_sample(features, params, px, py, sample);
    let mut hit = SurfaceHit::miss();
    // The path as it reached its first vertex, once it has (where it splits), and where.
    let (mut at_first, mut first_hit, mut forked) = (path, hit, false);
    let (mut j, mut restart) = (0, false);
    let mut continued = Vec3::ZERO;
    let (mut first, mut second, mut rounds) = (Vec3::ZERO, Vec3::ZERO, 0.0);
    loop {
        let again = restart;
        let reached = if restart {
            (path, hit, restart) = (at_first, first_hit, false);
            true
        } else {
            path.round(tracer, features, scene, &mut hit)
        };
        if reached {
            let arrival = path.arrival(features, scene, &hit);
            let mut query = arrival.query;
            // The first vertex: reached for the first time, or again by a continuation.
            let leaving = n > 1 && (again || !forked);
            if leaving {
                if !forked {
                    (at_first, first_hit, forked) = (path, hit, true);
                }
                continue_at_vertex(scene, n, j, &mut path, &mut query);
            }
            let samples = VertexSamples::draw(&query, &mut path.rng);
            path.vertex(features, scene, &hit, &arrival.material, &query, &samples);
            if leaving {
                FirstVertex::left(scene, n, j, &mut path);
            }
        }
        if path.finished() {
            if !forked {
                return unsplit_value(params, path.radiance);
            }
            continued += path.radiance;
            if j == 0 {
                first = path.radiance;
                rounds = continuation_rounds(path.depth);
            } else if j == 1 {
                second = path.radiance;
            }
            j += 1;
            if j == n {
                break;
            }
            restart = true;
        }
    }
    if params.split.mode == split_mode::PILOT {
        pilot_value(first, second, rounds)
    } else {
        split_value(continued, n)
    }
}

/// The value of a sample split in `continued.len()` continuations (a backend that runs them
/// apart, the CPU's packets): from the continuations' radiances in order and the first
/// continuation's rounds, exactly what [`render_split_sample`] computes.
#[inline]
pub fn combine(params: &RenderParams, continued: &[Vec3], first_rounds: f32) -> Vec3 {
    if params.split.mode == split_mode::PILOT {
        return pilot_value(continued[0], continued[1], first_rounds);
    }
    let mut sum = Vec3::ZERO;
    let mut j = 0;
    while j < continued.len() {
        sum += continued[j];
        j += 1;
    }
    split_value(sum, continued.len() as u32)
}

/// The value of a sample whose path ended before any vertex: its radiance, or under the pilot
/// the pilot's value of two equal estimates and no continuation.
#[inline]
pub fn unsplit_value(params: &RenderParams, radiance: Vec3) -> Vec3 {
    if params.split.mode == split_mode::PILOT {
        pilot_value(radiance, radiance, 0.0)
    } else {
        radiance
    }
}
