//! The CPU backend: the kernel's `render_sample` over a BVH, image tiles in parallel (rayon).
//! Deterministic for a given seed whatever the thread count: each sample is a pure function of
//! (seed, pixel, sample index) and each pixel sums its samples in index order.

pub mod bvh;
pub mod bvh_build;
pub mod packet;
pub mod packet_numbers;
pub mod packet_paths;
pub mod packet_vertices;
pub mod simd;

use crate::film::{Film, PixelSums};
use crate::scene::Scene;
use bvh::Bvh;
use glam::Vec3;
use indicatif::ProgressBar;
use kernel::adaptive::is_pilot_sample;
use kernel::features::{self, Dynamic, FeatureSet, Static};
use kernel::path::render_sample;
use kernel::scene::{Material, RenderParams, SphereLight};
use kernel::{SurfaceHit, Tracer};
use packet::SmallScene;
use rayon::prelude::*;

/// Side of the square image tiles that threads take one at a time.
pub const TILE: u32 = 16;

/// [`Tracer`] over the BVH; the same answers as the GPU's acceleration structure.
pub struct BvhTracer<'a> {
    pub bvh: &'a Bvh,
}

impl Tracer for BvhTracer<'_> {
    #[inline]
    fn closest_hit(&mut self, origin: Vec3, dir: Vec3) -> SurfaceHit {
        self.bvh.closest_hit(origin, dir, f32::INFINITY)
    }
    #[inline]
    fn occluded(&mut self, from: Vec3, to: Vec3) -> bool {
        self.bvh.any_hit(from, to - from, 1.0)
    }
}

/// A scene prepared for CPU rendering.
pub struct CpuRenderer {
    pub bvh: Bvh,
    pub materials: Vec<Material>,
    pub lights: Vec<SphereLight>,
    /// The kernel's feature bits (`kernel::features`; 0: generic path).
    pub features: u32,
    /// For scenes of at most `packet::MAX_PRIMITIVES` primitives (unless the scene's
    /// `packets` setting is off): all of them, for tracing sixteen paths' rays at once.
    pub small: Option<SmallScene>,
}

/// `match bits { combo => body with f = Static::<combo>, ..., other => body with Dynamic(other) }`.
macro_rules! monomorphised {
    ($bits:expr, $f:ident => $body:expr; $($combo:expr),+) => {
        match $bits {
            $(x if x == $combo => {
                let $f = Static::<{ $combo }>;
                $body
            })+
            other => {
                let $f = Dynamic(other);
                $body
            }
        }
    };
}

/// The feature combinations with their own monomorphised `trace_path`: every combination of
/// the scene features (lights: none, one, several; background; constant or throughput
/// roulette) under the default MIS (power) and light sampling (cone). Others run the
/// [`Dynamic`] path with the same bits.
macro_rules! with_features {
    ($bits:expr, $f:ident => $body:expr) => {{
        const BASE: u32 = features::SPECIALIZED | features::MIS_POWER | features::LIGHT_CONE;
        const L: u32 = features::LIGHTS;
        const L1: u32 = features::LIGHTS | features::SINGLE_LIGHT;
        const B: u32 = features::BACKGROUND;
        const R: u32 = features::RR_THROUGHPUT;
        monomorphised!($bits, $f => $body;
            BASE, BASE | B, BASE | R, BASE | B | R,
            BASE | L, BASE | L | B, BASE | L | R, BASE | L | B | R,
            BASE | L1, BASE | L1 | B, BASE | L1 | R, BASE | L1 | B | R)
    }};
}

impl CpuRenderer {
    /// Builds the BVH over the scene's spheres and triangles (and, for a small scene, the
    /// packets' copy of them).
    pub fn new(scene: &Scene) -> Self {
        let bvh = Bvh::build(scene.spheres.clone(), scene.triangles.clone());
        // Primitive ids as the BVH numbers them (`Bvh::surface` reads them).
        let small = scene
            .render
            .packets
            .then(|| SmallScene::if_small(&bvh.spheres, &bvh.triangles))
            .flatten();
        Self {
            bvh,
            materials: scene.materials.clone(),
            lights: scene.light_table(),
            features: scene.features(),
            small,
        }
    }

    /// One sample of one pixel, exactly as the GPU's ray-generation shader computes it.
    pub fn sample(&self, params: &RenderParams, px: u32, py: u32, sample: u32) -> Vec3 {
        with_features!(self.features, f => self.sample_with(f, params, px, py, sample))
    }

    #[inline]
    fn sample_with<F: FeatureSet>(
        &self,
        features: F,
        params: &RenderParams,
        px: u32,
        py: u32,
        sample: u32,
    ) -> Vec3 {
        let mut tracer = BvhTracer { bvh: &self.bvh };
        render_sample(
            &mut tracer,
            features,
            params,
            &self.materials,
            &self.lights,
            px,
            py,
            sample,
        )
    }

    /// Adds samples `first..first + count` of every pixel to `film`, tiles in parallel.
    /// Non-finite samples are not added; they are counted in `film.discarded`. With adaptive
    /// sampling (`params.pilot_period > 0`), pixels the film says have converged are skipped
    /// and pilot samples go to the film's pilot sums (`kernel::adaptive`).
    pub fn render_into(
        &self,
        params: &RenderParams,
        first: u32,
        count: u32,
        film: &mut Film,
        progress: Option<&ProgressBar>,
    ) {
        with_features!(self.features, f => self.render_tiles(f, params, first, count, film, progress))
    }

    fn render_tiles<F: FeatureSet + Sync>(
        &self,
        features: F,
        params: &RenderParams,
        first: u32,
        count: u32,
        film: &mut Film,
        progress: Option<&ProgressBar>,
    ) {
        let (w, h) = (params.width, params.height);
        let tiles_x = w.div_ceil(TILE);
        let tiles_y = h.div_ceil(TILE);
        let tiles: Vec<(u32, u32)> = (0..tiles_y)
            .flat_map(|ty| (0..tiles_x).map(move |tx| (tx, ty)))
            .collect();
        let adaptive = params.pilot_period > 0;
        let film_ref = &*film;
        let results: Vec<((u32, u32), Vec<PixelSums>)> = tiles
            .par_iter()
            .map(|&(tx, ty)| {
                if let Some(small) = &self.small {
                    let pixels = (ty * TILE..((ty + 1) * TILE).min(h)).flat_map(|py| {
                        (tx * TILE..((tx + 1) * TILE).min(w)).map(move |px| (px, py))
                    });
                    let sums = self
                        .tile_by_packets(features, small, params, pixels, first, count, film_ref);
                    if let Some(p) = progress {
                        p.inc(
                            sums.iter()
                                .map(|s| (s.count + s.pilot_count + s.discarded) as u64)
                                .sum(),
                        );
                    }
                    return ((tx, ty), sums);
                }
                let mut out = Vec::with_capacity((TILE * TILE) as usize);
                let mut done = 0u64;
                for py in ty * TILE..((ty + 1) * TILE).min(h) {
                    for px in tx * TILE..((tx + 1) * TILE).min(w) {
                        let mut acc = PixelSums::default();
                        if !(adaptive && film_ref.converged(params, px, py)) {
                            for s in first..first + count {
                                let l = self.sample_with(features, params, px, py, s);
                                if adaptive && is_pilot_sample(params, s) {
                                    acc.add_pilot(l);
                                } else {
                                    acc.add(l);
                                }
                            }
                            done += count as u64;
                        }
                        out.push(acc);
                    }
                }
                if let Some(p) = progress {
                    p.inc(done);
                }
                ((tx, ty), out)
            })
            .collect();
        for ((tx, ty), sums) in results {
            let mut k = 0;
            for py in ty * TILE..((ty + 1) * TILE).min(h) {
                for px in tx * TILE..((tx + 1) * TILE).min(w) {
                    film.add_sums(px, py, &sums[k]);
                    k += 1;
                }
            }
        }
    }
}
