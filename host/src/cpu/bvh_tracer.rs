//! The kernel's [`Tracer`] over the CPU's BVH, as the one-path loop traces its rays.

use super::bvh::{Bvh, HoleTables};
use crate::backend::RayCounts;
use glam::Vec3;
use kernel::{SurfaceHit, Tracer};

/// [`Tracer`] over the BVH; the same answers as the GPU's acceleration structure. Counts the
/// rays it traces. With `holes` (a scene whose materials have holes, `kernel::opacity`) its
/// traversals pass through the candidates those tables say are not there, as the GPU's
/// any-hit shaders do.
pub struct BvhTracer<'a> {
    pub bvh: &'a Bvh,
    pub rays: RayCounts,
    pub holes: Option<HoleTables<'a>>,
}

impl<'a> BvhTracer<'a> {
    /// The tracer of a scene without holes.
    pub fn new(bvh: &'a Bvh) -> Self {
        Self {
            bvh,
            rays: RayCounts::default(),
            holes: None,
        }
    }
}

impl Tracer for BvhTracer<'_> {
    #[inline]
    fn closest_hit(&mut self, origin: Vec3, dir: Vec3) -> SurfaceHit {
        self.rays.closest += 1;
        match &self.holes {
            None => self.bvh.closest_hit(origin, dir, f32::INFINITY),
            Some(tables) => self
                .bvh
                .closest_hit_through(origin, dir, f32::INFINITY, tables),
        }
    }
    #[inline]
    fn occluded(&mut self, from: Vec3, to: Vec3) -> bool {
        self.rays.shadow += 1;
        match &self.holes {
            None => self.bvh.any_hit(from, to - from, 1.0),
            Some(tables) => self.bvh.any_hit_through(from, to - from, 1.0, tables),
        }
    }
    #[inline]
    fn first_hit_on(&mut self, from: Vec3, to: Vec3) -> SurfaceHit {
        self.rays.shadow += 1;
        match &self.holes {
            None => self.bvh.closest_hit(from, to - from, 1.0),
            Some(tables) => self.bvh.closest_hit_through(from, to - from, 1.0, tables),
        }
    }
}
