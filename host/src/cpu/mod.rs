//! The CPU backend: the kernel's `render_sample` over a BVH, image tiles in parallel (rayon).
//! Deterministic for a given seed whatever the thread count: each sample is a pure function of
//! (seed, pixel, sample index) and each pixel sums its samples in index order.

mod backend;
mod bvh;
mod bvh_build;
mod bvh_packet;
mod huge_pages;
mod packet;
mod packet_numbers;
mod packet_paths;
mod packet_vertices;
mod renderer;
mod simd;
mod tile;

pub use backend::CpuBackend;
pub use bvh::{Bvh, PrimHit};
pub use packet::{PacketTracer, RayPacket, SmallScene, LANES, MAX_PRIMITIVES};
pub use renderer::{CpuRenderer, TileStrategy};
pub use tile::TILE;

/// The backend's internals, for the tests of their pieces (`tests/tests/bvh.rs`, `packets.rs`,
/// `properties.rs`): the binary SAH build, the SIMD ray types, the packets' numbers and vertex
/// samples. Not part of the product (feature `test-support`).
#[cfg(feature = "test-support")]
pub mod internals {
    pub use super::bvh_build::{Aabb, BinaryBvh};
    pub use super::packet_numbers::{camera_numbers, NumberRequests, EMPTY};
    pub use super::packet_vertices::fill_vertex_samples;
    pub use super::simd::{Ray4, Spheres4, Triangles4};
}

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
