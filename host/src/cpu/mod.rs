//! The CPU backend: the kernel's `render_sample` over a BVH, image tiles in parallel (rayon).
//! Deterministic for a given seed whatever the thread count: each sample is a pure function of
//! (seed, pixel, sample index) and each pixel sums its samples in index order.

pub mod bvh;

use crate::film::Film;
use crate::scene::Scene;
use bvh::Bvh;
use glam::Vec3;
use indicatif::ProgressBar;
use kernel::path::render_sample;
use kernel::scene::{Material, RenderParams, SphereLight};
use kernel::{SurfaceHit, Tracer};
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
}

impl CpuRenderer {
    /// Builds the BVH over the scene's spheres and triangles.
    pub fn new(scene: &Scene) -> Self {
        Self {
            bvh: Bvh::build(scene.spheres.clone(), scene.triangles.clone()),
            materials: scene.materials.clone(),
            lights: scene.lights.clone(),
        }
    }

    /// One sample of one pixel, exactly as the GPU's ray-generation shader computes it.
    pub fn sample(&self, params: &RenderParams, px: u32, py: u32, sample: u32) -> Vec3 {
        let mut tracer = BvhTracer { bvh: &self.bvh };
        render_sample(
            &mut tracer,
            params,
            &self.materials,
            &self.lights,
            px,
            py,
            sample,
        )
    }

    /// Adds samples `first..first + count` of every pixel to `film`, tiles in parallel.
    /// Non-finite samples are not added; they are counted in `film.discarded`.
    pub fn render_into(
        &self,
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
        let results: Vec<((u32, u32), Vec<PixelSums>)> = tiles
            .par_iter()
            .map(|&(tx, ty)| {
                let mut out = Vec::with_capacity((TILE * TILE) as usize);
                for py in ty * TILE..((ty + 1) * TILE).min(h) {
                    for px in tx * TILE..((tx + 1) * TILE).min(w) {
                        let mut acc = PixelSums::default();
                        for s in first..first + count {
                            acc.add(self.sample(params, px, py, s));
                        }
                        out.push(acc);
                    }
                }
                if let Some(p) = progress {
                    p.inc(out.len() as u64 * count as u64);
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

/// Per-pixel running sums of samples, their squares, and the counts.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelSums {
    pub sum: [f64; 3],
    pub sum_sq: [f64; 3],
    pub count: u32,
    pub discarded: u32,
}

impl PixelSums {
    #[inline]
    pub fn add(&mut self, v: Vec3) {
        if !v.is_finite() {
            self.discarded += 1;
            return;
        }
        for c in 0..3 {
            let x = v[c] as f64;
            self.sum[c] += x;
            self.sum_sq[c] += x * x;
        }
        self.count += 1;
    }
}
