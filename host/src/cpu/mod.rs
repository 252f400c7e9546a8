//! The CPU backend: the kernel's `render_sample` over a BVH, image tiles in parallel (rayon).
//! Deterministic for a given seed whatever the thread count: each sample is a pure function of
//! (seed, pixel, sample index) and each pixel sums its samples in index order.

mod backend;
mod bvh;
mod bvh_build;
mod bvh_packet;
mod bvh_packet_shadows;
mod bvh_tracer;
mod huge_pages;
mod packet;
mod packet_forks;
mod packet_numbers;
mod packet_paths;
mod packet_presence;
mod packet_vertices;
mod renderer;
mod simd;
mod tile;

pub use backend::CpuBackend;
pub use bvh::{Bvh, HoleTables, PrimHit};
pub use bvh_tracer::BvhTracer;
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
