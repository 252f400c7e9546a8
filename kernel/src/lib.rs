//! twinpath's rendering kernel: everything that decides a pixel's value.
//!
//! Written once in `no_std` Rust and compiled twice: to SPIR-V by rust-gpu (the `shaders` module
//! holds the entry points) and to native code for the CPU backend and the tests. The kernel
//! reaches the scene only through [`path::Tracer`], so it knows neither backend.
#![cfg_attr(target_arch = "spirv", no_std)]
// Natively, the sampler's hashes and the sampling of points and directions also run on SIMD
// lanes (`word`, `real`: the CPU's packets of paths).
#![cfg_attr(not(target_arch = "spirv"), feature(portable_simd))]

pub mod adaptive;
pub mod bsdf;
pub mod camera;
pub mod delta_tracking;
pub mod density_grid;
pub mod environment;
pub mod features;
pub mod film_sample;
pub mod frame;
pub mod free_flight;
pub mod geometry;
pub mod hash;
pub mod hit;
pub mod instance;
pub mod intersect;
pub mod light;
pub mod medium;
pub mod opacity;
pub mod path;
pub mod path_media;
pub mod phase;
pub mod plane_side;
#[cfg(feature = "probe")]
pub mod probe;
pub mod real;
pub mod rng;
pub mod sampling;
pub mod scene;
pub mod scene_view;
#[cfg(target_arch = "spirv")]
pub mod shaders;
pub mod sobol;
pub mod spherical_triangle;
pub mod split;
pub mod surface;
pub mod texture;
pub mod turns;
pub mod vertex_samples;
pub mod word;

pub use hit::SurfaceHit;
pub use path::{trace_path, Tracer};
pub use scene_view::SceneView;
pub use spirv_std::glam;

/// `f32` methods (sqrt, sin, ...) on the GPU come from this trait; natively they are inherent.
#[cfg(target_arch = "spirv")]
#[allow(unused_imports)]
pub(crate) use spirv_std::num_traits::Float;
