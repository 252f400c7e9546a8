//! twinpath's host: scenes, the CPU backend, the film and image files, and the render driver.
//! Everything here is "not a pixel's value"; the kernel crate decides those.

// std::simd: the CPU traversal's four-lane box and triangle tests (cpu/simd.rs).
#![feature(portable_simd)]

pub mod backend;
#[cfg(feature = "gpu")]
pub mod bench;
pub mod cpu;
pub mod film;
pub mod fixed_sum;
pub mod merge;
pub mod part_file;
#[cfg(feature = "gpu")]
pub mod render;
pub mod sample_range;
pub mod scene;
pub mod settings;
#[cfg(feature = "gpu")]
pub mod vulkan;

/// The SPIR-V module rust-gpu compiled from `kernel/` at build time (host/build.rs).
#[cfg(feature = "gpu")]
pub const KERNEL_SPV: &[u8] = include_bytes!(env!("kernel.spv"));
