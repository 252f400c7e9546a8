//! The kernel's [`Tracer`] over the CPU's BVH, as the one-path loop traces its rays.

use super::bvh::Bvh;
use crate::backend::RayCounts;
use glam::Vec3;
use kernel::{SurfaceHit, Tracer};

/// [`Tracer`] over the BVH; the same answers as the GPU's acceleration structure. Counts the
/// rays it traces.
pub struct BvhTracer<'a> {
    pub bvh: &'a Bvh,
    pub rays: RayCounts,
}

impl<'a> BvhTracer<'a> {
    pub fn new(bvh: &'a Bvh) -> Self {
        Self {
            bvh,
            rays: RayCounts::default(),
        }
    }
}

impl Tracer for BvhTracer<'_> {
    #[inline]
    fn closest_hit(&mut self, origin: Vec3, dir: Vec3) -> SurfaceHit {
        self.rays.closest += 1;
        self.bvh.closest_hit(origin, dir, f32::INFINITY)
    }
    #[inline]
    fn occluded(&mut self, from: Vec3, to: Vec3) -> bool {
        self.rays.shadow += 1;
        self.bvh.any_hit(from, to - from, 1.0)
    }
}
