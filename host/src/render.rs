//! The render driver: a scene, a backend, a sample count in, a film out, with progress and
//! Ctrl-C (the samples finished so far are kept and written).

pub use crate::backend::Backend;

use crate::backend::{open, RayCounts};
use crate::film::Film;
use crate::sample_range::SampleRange;
use crate::scene::Scene;
use crate::settings::{RenderSettings, Split};
use crate::split_pilot::{pilot_spp, split_table};
use anyhow::{bail, Result};
use indicatif::{ProgressBar, ProgressStyle};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Options of a render besides the scene.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    pub backend: Backend,
    /// Vulkan device index (`twinpath info` lists them).
    pub device: Option<usize>,
    pub validation: bool,
    pub progress: bool,
    /// The sample indices to render (`None`: all of `0..settings.spp`); a part of a
    /// render split across processes (docs/parts.md).
    pub samples: Option<SampleRange>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            backend: Backend::Auto,
            device: None,
            validation: false,
            progress: false,
            samples: None,
        }
    }
}

impl RenderOptions {
    /// The sample indices to render with `settings`: `samples`, or all of `0..settings.spp`.
    pub fn sample_range(&self, settings: &RenderSettings) -> SampleRange {
        self.samples.unwrap_or(SampleRange::all(settings.spp))
    }
}

/// What a render produced and what it cost.
pub struct RenderOutput {
    pub film: Film,
    /// The backend that actually rendered (never `Auto`).
    pub backend: Backend,
    /// Set-up before the first sample: on the CPU the BVH, and with `--backend auto` the look
    /// for a Vulkan device before it; on the GPU instance, device, acceleration structures and
    /// pipeline.
    pub setup: Duration,
    /// Of `setup`: the BVH build (CPU), or the acceleration-structure build (GPU).
    pub accel_build: Duration,
    pub pipeline: Duration,
    /// Bytes of the acceleration structure (`SampleBackend::accel_bytes`).
    pub accel_bytes: u64,
    /// Time spent rendering samples.
    pub render: Duration,
    /// The rays traced, where the backend counts them (`SampleBackend::rays_traced`).
    pub rays: Option<RayCounts>,
    /// Samples per pixel actually rendered (fewer than asked after Ctrl-C).
    pub spp_done: u32,
    /// The sample indices actually rendered: the range asked for, or its beginning after
    /// Ctrl-C.
    pub samples: SampleRange,
    pub interrupted: bool,
}

/// Set by Ctrl-C (after `install_interrupt_handler`); renders stop between passes.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Makes Ctrl-C stop the render after the current pass instead of killing the process.
pub fn install_interrupt_handler() {
    let _ = ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130); // second Ctrl-C: give up at once
        }
    });
}

/// Renders `scene` with `settings`: `settings.spp` samples per pixel, or the range
/// `opts.samples` of them, with a progress bar on stderr where `opts.progress`.
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    opts: &RenderOptions,
) -> Result<RenderOutput> {
    let progress = opts
        .progress
        .then(|| progress_bar(samples_to_count(scene, settings, opts)));
    let out = render_counting(scene, settings, opts, progress.as_ref());
    if let Some(p) = progress {
        p.finish_and_clear();
    }
    out
}

/// The samples a render counts on its progress bar: the pixels times the samples per pixel
/// asked for, and the split table's pilot samples where `split = auto`
/// (`split_pilot::pilot_spp`), which the render renders first.
pub fn samples_to_count(scene: &Scene, settings: &RenderSettings, opts: &RenderOptions) -> u64 {
    let spp = opts.sample_range(settings).len();
    let pilot = match settings.split {
        Split::Auto => pilot_spp(settings.spp),
        Split::Off | Split::Fixed(_) => 0,
    };
    scene.pixel_count() as u64 * (spp + pilot) as u64
}

/// [`render`], counting each sample on `progress` as it finishes, the pilot's included (the bar
/// ends at [`samples_to_count`] unless Ctrl-C stops the render).
pub fn render_counting(
    scene: &Scene,
    settings: &RenderSettings,
    opts: &RenderOptions,
    progress: Option<&ProgressBar>,
) -> Result<RenderOutput> {
    if let (Some(range), true) = (opts.samples, settings.adaptive()) {
        bail!(
            "adaptive sampling (--target-error) cannot be split into parts (samples {range}): \
             which samples a pixel takes depends on all its earlier ones (docs/parts.md)"
        );
    }
    let range = opts.sample_range(settings);
    let t0 = Instant::now();
    let (mut backend, kind) = open(opts.backend, scene, settings, opts.device, opts.validation)?;
    let setup = t0.elapsed();
    let spp = range.len();
    let t1 = Instant::now();
    // The split table's pilot, if any, is part of the render's time.
    if let Some(table) = split_table(backend.as_mut(), scene, settings, progress)? {
        backend.set_splits(&table)?;
    }
    let mut spp_done = 0;
    while spp_done < spp && !INTERRUPTED.load(Ordering::SeqCst) {
        let count = backend.next_pass(spp_done, spp);
        let first = range.start + spp_done;
        let params = scene.params(settings, first, count);
        backend.add_samples(&params, first, count, progress)?;
        spp_done += count;
    }
    let film = backend.read_film()?;
    let render = t1.elapsed();
    let (accel_build, pipeline) = backend.setup_times();
    Ok(RenderOutput {
        film,
        backend: kind,
        setup,
        accel_build,
        pipeline,
        accel_bytes: backend.accel_bytes(),
        render,
        rays: backend.rays_traced(),
        spp_done,
        samples: SampleRange {
            start: range.start,
            end: range.start + spp_done,
        },
        interrupted: spp_done < spp,
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
