//! The subcommands and what they share: loading a scene, the render-settings flags.

mod bench;
mod diff;
mod info;
mod merge;
mod rays;
mod reference;
mod render;

use anyhow::{anyhow, Result};
use clap::{Args, Parser, Subcommand};
use std::path::Path;
use twinpath::scene::{SceneFile, DEFAULT_SCENE_NAME};
use twinpath::settings::{LightSampling, LightSelection, Mis, RenderSettings, Roulette, Sampler};

#[derive(Parser)]
#[command(
    name = "twinpath",
    version,
    about = "A path tracer whose kernel runs on the CPU and, through Vulkan ray tracing, on the GPU"
)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene (default: the built-in Cornell scene) to EXR and/or PNG.
    Render(Box<render::RenderArgs>),
    /// Time against error: render at 1, 2, 4, ... spp per variant and backend; CSV and a plot.
    Bench(bench::BenchArgs),
    /// Render a converged reference as the mean of two independent halves, and estimate its noise.
    Reference(reference::ReferenceArgs),
    /// Combine the part files of a render split with `render --part` or `--samples` into its
    /// image (exactly the single render's for CPU parts).
    Merge(merge::MergeArgs),
    /// Compare two images: RMSE, relMSE, mean signed difference, max abs difference.
    Diff(diff::DiffArgs),
    /// What this build contains: the SPIR-V module and the backends.
    Info,
    /// Ray throughput of the CPU traversal on one thread (camera rays, diffuse bounce rays and the
    /// rays of one path per pixel), and the BVH's build time and memory.
    Rays(rays::RaysArgs),
}

impl Cli {
    pub fn run(self) -> Result<()> {
        match self.command {
            Command::Render(a) => render::run(*a),
            Command::Bench(a) => bench::run(a),
            Command::Reference(a) => reference::run(a),
            Command::Merge(a) => merge::run(a),
            Command::Diff(a) => diff::run(a),
            Command::Info => info::run(),
            Command::Rays(a) => rays::run(a),
        }
    }
}

/// The render-settings flags: each is a name of the settings vocabulary
/// (`twinpath::settings`), applied through `RenderSettings::set` after the scene's `[render]`
/// table, so a flag checks and means exactly what the scene file's key does.
#[derive(Args, Clone, Debug, Default)]
pub struct SettingFlags {
    /// Samples per pixel.
    #[arg(long)]
    spp: Option<String>,
    /// Random seed.
    #[arg(long)]
    seed: Option<String>,
    /// Russian-roulette strategy (default: throughput).
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(Roulette::NAMES))]
    roulette: Option<String>,
    /// Survival probability of the constant roulette, in (0, 1].
    #[arg(long)]
    rr: Option<String>,
    /// First path vertex whose extension roulette decides (1 = the camera ray's hit; default
    /// 1 for constant roulette, 5 for throughput roulette).
    #[arg(long)]
    rr_start_depth: Option<String>,
    /// How light sampling and BRDF sampling are weighted.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(Mis::NAMES))]
    mis: Option<String>,
    /// How next-event estimation picks a point on a light: by the solid angle it subtends (a
    /// sphere's cone, a triangle's spherical triangle) or uniformly on its surface.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(LightSampling::NAMES))]
    light_sampling: Option<String>,
    /// How next-event estimation picks one of several lights.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(LightSelection::NAMES))]
    light_selection: Option<String>,
    /// Where each sample's random numbers come from.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(Sampler::NAMES))]
    sampler: Option<String>,
    /// Run the generic kernel path instead of one specialized to the scene's features.
    #[arg(long)]
    no_specialize: bool,
    /// CPU: trace one path at a time instead of sixteen-path packets (the same image, bit for
    /// bit; slower).
    #[arg(long)]
    no_packets: bool,
    /// Adaptive sampling: stop each pixel once its estimated relative error is below this
    /// (--spp is then the most a pixel gets).
    #[arg(long)]
    target_error: Option<String>,
    /// Any setting by its scene-file name (KEY=VALUE, repeatable), e.g. --set max_depth=64.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
}

impl SettingFlags {
    /// Applies the flags given to `settings`; an error names the flag.
    pub fn apply(&self, settings: &mut RenderSettings) -> Result<()> {
        let on_off = |b: bool| (!b).then_some("off".to_string());
        let named = [
            ("spp", "spp", self.spp.clone()),
            ("seed", "seed", self.seed.clone()),
            ("roulette", "roulette", self.roulette.clone()),
            ("rr", "russian_roulette", self.rr.clone()),
            (
                "rr-start-depth",
                "rr_start_depth",
                self.rr_start_depth.clone(),
            ),
            ("mis", "mis", self.mis.clone()),
            (
                "light-sampling",
                "light_sampling",
                self.light_sampling.clone(),
            ),
            (
                "light-selection",
                "light_selection",
                self.light_selection.clone(),
            ),
            ("sampler", "sampler", self.sampler.clone()),
            ("no-specialize", "specialize", on_off(!self.no_specialize)),
            ("no-packets", "packets", on_off(!self.no_packets)),
            ("target-error", "adaptive_target", self.target_error.clone()),
        ];
        for (flag, key, value) in named {
            if let Some(v) = value {
                settings
                    .set(key, &v)
                    .map_err(|m| anyhow!("--{flag} {v}: {m}"))?;
            }
        }
        for kv in &self.set {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| anyhow!("--set {kv}: not KEY=VALUE"))?;
            settings.set(k, v).map_err(|m| anyhow!("--set {kv}: {m}"))?;
        }
        Ok(())
    }
}

/// The scene file, or the built-in Cornell scene.
pub fn load_scene(path: Option<&Path>) -> Result<SceneFile> {
    Ok(match path {
        Some(p) => SceneFile::load(p)?,
        None => SceneFile::builtin_default(),
    })
}

/// Shows what the loader approximated, ignored or cannot prove about the scene (its notes), as
/// `render` does before it renders.
pub fn show_notes(scene: &twinpath::scene::Scene) {
    for note in &scene.notes {
        eprintln!("twinpath: note: {note}");
    }
}

/// `scenes/cornell.toml` -> `cornell`; the built-in scene -> `cornell`.
pub fn scene_stem(name: &str) -> String {
    let name = if name.is_empty() {
        DEFAULT_SCENE_NAME
    } else {
        name
    };
    Path::new(name)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("render")
        .to_string()
}

/// `bytes` in MiB, for the log lines.
pub fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

/// Fails unless `path` can be written: the file is opened for appending (and removed again
/// if it did not exist), so a render never runs for an hour to find its output unwritable.
pub fn check_writable(path: &Path) -> Result<()> {
    let existed = path.exists();
    std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .map_err(|e| anyhow!("cannot write {}: {e}", path.display()))?;
    if !existed {
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}

/// The lower-case extension of `path`, if any.
pub fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
}
