//! twinpath's host: scenes, the CPU backend, the film and image files, and the render driver.
//! Everything here is "not a pixel's value"; the kernel crate decides those.

// std::simd: the CPU traversal's four-lane box and triangle tests (cpu/simd.rs).
#![feature(portable_simd)]

pub mod backend;
pub mod bench;
pub mod cpu;
pub mod film;
pub mod fixed_sum;
pub mod merge;
pub mod part_file;
pub mod render;
pub mod sample_range;
pub mod scene;
pub mod settings;
pub mod split_pilot;
#[cfg(feature = "gpu")]
pub mod vulkan;

/// The kernel's SPIR-V module: the shipped `kernel/shipped/kernel.spv`, whose manifest the build
/// checked against the kernel's sources, or with the feature `kernel-from-source` the module
/// rust-gpu compiled at build time (host/build.rs).
#[cfg(feature = "gpu")]
pub const KERNEL_SPV: &[u8] = include_bytes!(env!("kernel.spv"));

/// The tests' module: the kernel compiled with its feature `probe` (the compute entry point
/// `shaders::probe`, which `vulkan::compute` runs for the CPU-vs-GPU equivalence tests). Not
/// part of the renderer: only with the feature `test-support`.
#[cfg(all(feature = "gpu", feature = "test-support"))]
pub const PROBE_SPV: &[u8] = include_bytes!(env!("probe.spv"));

/// Where [`KERNEL_SPV`] came from, in words (shipped, or compiled from source).
#[cfg(feature = "gpu")]
pub const KERNEL_ORIGIN: &str = env!("TWINPATH_KERNEL_ORIGIN");
