//! What the render loop asks of a backend: add a pass of samples to its film, say how many
//! samples per pixel the next pass holds, read the film back. `render::render` drives every
//! backend through this one trait, so progress, Ctrl-C and timing are written once.

use crate::film::Film;
use anyhow::Result;
use indicatif::ProgressBar;
use kernel::scene::RenderParams;
use std::time::Duration;

/// A scene prepared on one backend, accumulating samples into a film it owns.
///
/// Invariant: after `add_samples` for passes `0..n0`, `n0..n1`, ... in order, `read_film`
/// holds exactly those samples; the pass sizes come from `next_pass` alone (never from
/// timing), so a render is the same bit for bit every time.
pub trait SampleBackend {
    /// Samples per pixel of the next pass, `done` of `spp` having been added (1..=spp - done).
    fn next_pass(&self, done: u32, spp: u32) -> u32;
    /// Adds samples `first..first + count` of every pixel; `params` is
    /// `Scene::params(first, count)`. Counts the samples on `progress` as they finish.
    fn add_samples(
        &mut self,
        params: &RenderParams,
        first: u32,
        count: u32,
        progress: Option<&ProgressBar>,
    ) -> Result<()>;
    /// The film with every sample added so far.
    fn read_film(&self) -> Result<Film>;
    /// Forgets every sample added so far: the film as new (after the split pilot,
    /// `crate::split_pilot`). The rays counted stay counted.
    fn clear_film(&mut self) -> Result<()>;
    /// The split table the next passes read (`kernel::split`: continuations per tile, row
    /// by row, tiles of `SPLIT_TILE` pixels; one word `1` where nothing splits).
    fn set_splits(&mut self, splits: &[u32]) -> Result<()>;
    /// Of the set-up: building the acceleration structure (the CPU's BVH, the GPU's BLAS and
    /// TLAS) and creating the pipeline (zero on the CPU).
    fn setup_times(&self) -> (Duration, Duration);
    /// Bytes of the acceleration structure: the CPU's BVH beyond the primitives (with its
    /// instanced meshes' trees), the GPU's BLASes and TLAS as the driver sizes them.
    fn accel_bytes(&self) -> u64;
    /// The rays traced so far, where the backend counts them (the CPU; the GPU does not).
    fn rays_traced(&self) -> Option<RayCounts> {
        None
    }
}

/// Rays a render traced: closest-hit rays (camera rays and path extensions) and shadow rays
/// (next-event estimation's visibility tests). Counted where a ray is handed to the traversal,
/// so that a ray count per sample can be compared with another renderer's
/// (docs/performance.md, "Rays per sample").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    pub closest: u64,
    pub shadow: u64,
}

impl RayCounts {
    pub fn total(&self) -> u64 {
        self.closest + self.shadow
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, other: Self) {
        self.closest += other.closest;
        self.shadow += other.shadow;
    }
}
