//! The CPU backend of the render loop (`crate::backend::SampleBackend`): a [`CpuRenderer`] and
//! the film it adds to.

use super::CpuRenderer;
use crate::backend::{RayCounts, SampleBackend};
use crate::film::Film;
use crate::scene::{Scene, ADAPTIVE_PASS};
use crate::settings::RenderSettings;
use anyhow::Result;
use indicatif::ProgressBar;
use kernel::scene::RenderParams;
use std::time::{Duration, Instant};

/// The CPU backend of the render loop: a [`CpuRenderer`] and the film it adds to.
pub struct CpuBackend {
    pub renderer: CpuRenderer,
    pub film: Film,
    /// Time [`CpuRenderer::new`] took (the BVH).
    pub build_time: Duration,
    adaptive: bool,
    /// The rays traced by the passes so far.
    rays: RayCounts,
}

impl CpuBackend {
    /// The CPU backend for `scene` rendered with `settings`.
    pub fn new(scene: &Scene, settings: &RenderSettings) -> Self {
        let t = Instant::now();
        let renderer = CpuRenderer::new(scene, settings);
        Self {
            renderer,
            film: Film::new(scene.camera.width, scene.camera.height),
            build_time: t.elapsed(),
            adaptive: settings.adaptive(),
            rays: RayCounts::default(),
        }
    }
}

impl SampleBackend for CpuBackend {
    /// Passes of a few samples per pixel, so progress moves and Ctrl-C is prompt; with
    /// adaptive sampling, the passes at whose ends pixels may stop.
    fn next_pass(&self, done: u32, spp: u32) -> u32 {
        let pass = if self.adaptive {
            ADAPTIVE_PASS
        } else {
            spp.clamp(1, 8)
        };
        pass.min(spp - done)
    }

    fn add_samples(
        &mut self,
        params: &RenderParams,
        first: u32,
        count: u32,
        progress: Option<&ProgressBar>,
    ) -> Result<()> {
        self.rays += self
            .renderer
            .render_into(params, first, count, &mut self.film, progress);
        Ok(())
    }

    fn read_film(&self) -> Result<Film> {
        Ok(self.film.clone())
    }

    fn clear_film(&mut self) -> Result<()> {
        self.film = Film::new(self.film.width, self.film.height);
        Ok(())
    }

    fn set_splits(&mut self, splits: &[u32]) -> Result<()> {
        self.renderer.splits = splits.to_vec();
        Ok(())
    }

    fn setup_times(&self) -> (Duration, Duration) {
        (self.build_time, Duration::ZERO)
    }

    fn accel_bytes(&self) -> u64 {
        self.renderer.bvh.hierarchy_bytes() as u64
    }

    fn rays_traced(&self) -> Option<RayCounts> {
        Some(self.rays)
    }
}
