//! What the render loop asks of a backend (`sample_backend`: the trait, and the rays a
//! render traced) and which backend renders (`open`: the kind, and opening it for a scene).
//! The backends (`crate::cpu`, `crate::vulkan`) implement the trait; only `open` names them.

mod open;
mod sample_backend;

pub use open::{open, Backend};
pub use sample_backend::{RayCounts, SampleBackend};
