//! The render driver: a scene, a backend, a sample count in, a film out, with progress.

use crate::cpu::CpuRenderer;
use crate::film::Film;
use crate::scene::Scene;
use anyhow::{bail, Result};
use indicatif::{ProgressBar, ProgressStyle};
use std::time::{Duration, Instant};

/// Which backend renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    /// The GPU when a Vulkan ray-tracing device is present, else the CPU.
    Auto,
    Cpu,
    Gpu,
}

/// What a render produced and what it cost.
pub struct RenderOutput {
    pub film: Film,
    pub backend: Backend,
    /// Acceleration-structure build (and other set-up) time.
    pub setup: Duration,
    /// Time spent rendering samples.
    pub render: Duration,
}

/// Renders `scene.render.spp` samples per pixel on the chosen backend.
pub fn render(scene: &Scene, backend: Backend, show_progress: bool) -> Result<RenderOutput> {
    let backend = match backend {
        Backend::Auto => {
            eprintln!("twinpath: --backend auto: the GPU backend is not built yet, using the CPU");
            Backend::Cpu
        }
        Backend::Gpu => bail!("the GPU (Vulkan) backend is not implemented yet; use --backend cpu"),
        Backend::Cpu => Backend::Cpu,
    };
    let t0 = Instant::now();
    let renderer = CpuRenderer::new(scene);
    let setup = t0.elapsed();

    let spp = scene.render.spp;
    let mut film = Film::new(scene.camera.width, scene.camera.height);
    let progress = show_progress.then(|| progress_bar(scene.pixel_count() as u64 * spp as u64));
    let t1 = Instant::now();
    // Passes of a few samples per pixel, so the progress bar moves evenly.
    let pass = spp.clamp(1, 16);
    let mut first = 0;
    while first < spp {
        let count = pass.min(spp - first);
        let params = scene.params(first, count);
        renderer.render_into(&params, first, count, &mut film, progress.as_ref());
        first += count;
    }
    let render = t1.elapsed();
    if let Some(p) = progress {
        p.finish_and_clear();
    }
    Ok(RenderOutput {
        film,
        backend,
        setup,
        render,
    })
}

/// A progress bar on stderr counting samples (drawn only when stderr is a terminal).
pub fn progress_bar(total: u64) -> ProgressBar {
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% {per_sec} eta {eta}",
        )
        .expect("valid progress template"),
    );
    bar
}
