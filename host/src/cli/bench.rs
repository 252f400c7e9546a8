//! `twinpath bench`: time against error for variants of the settings, as CSV and a plot.

use super::{load_scene, show_notes};
use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use twinpath::bench::{run_bench, write_csv, write_plot, BenchConfig, Variant};
use twinpath::film::RgbImage;
use twinpath::render::{install_interrupt_handler, Backend};
use twinpath::scene::SceneFile;

#[derive(Clone, Copy, Debug, ValueEnum)]
enum BenchBackends {
    Cpu,
    Gpu,
    Both,
}

/// Time against error: render at 1, 2, 4, ... spp per variant and backend; CSV and a plot.
#[derive(Args)]
pub struct BenchArgs {
    /// Scene file (TOML). Without it, the built-in Cornell scene.
    scene: Option<PathBuf>,
    /// Converged reference image (EXR) of the same scene, e.g. from `twinpath reference`.
    #[arg(long)]
    reference: PathBuf,
    #[arg(long, value_enum, default_value_t = BenchBackends::Cpu)]
    backend: BenchBackends,
    /// NAME or NAME:key=value,... with the scene file's [render] keys (e.g. roulette=constant,
    /// sampler=independent, packets=off, rr=0.8, adaptive=0.05), on top of the scene's
    /// settings; repeat to compare. Default: one variant, the scene's settings.
    #[arg(long = "variant")]
    variants: Vec<String>,
    /// Largest spp of the sweep.
    #[arg(long, default_value_t = 256)]
    max_spp: u32,
    /// Stop a curve after a render slower than this (seconds).
    #[arg(long, default_value_t = 60.0)]
    max_seconds: f64,
    /// Independent seeds per point at spp <= 8.
    #[arg(long, default_value_t = 4)]
    seeds: u32,
    /// Output folder for bench.csv and bench.png.
    #[arg(long, default_value = "bench")]
    out_dir: PathBuf,
}

pub fn run(a: BenchArgs) -> Result<()> {
    install_interrupt_handler();
    let SceneFile { scene, settings } = load_scene(a.scene.as_deref())?;
    show_notes(&scene);
    let reference_image = RgbImage::read(&a.reference)?;
    let variants = if a.variants.is_empty() {
        vec![Variant {
            name: "scene".into(),
            settings,
        }]
    } else {
        a.variants
            .iter()
            .map(|v| Variant::parse(v, &settings))
            .collect::<Result<_>>()?
    };
    let backends = match a.backend {
        BenchBackends::Cpu => vec![Backend::Cpu],
        BenchBackends::Gpu => vec![Backend::Gpu],
        BenchBackends::Both => vec![Backend::Cpu, Backend::Gpu],
    };
    let cfg = BenchConfig {
        variants,
        backends,
        max_spp: a.max_spp,
        max_seconds: a.max_seconds,
        seeds: a.seeds,
    };
    std::fs::create_dir_all(&a.out_dir)
        .with_context(|| format!("{}: cannot create", a.out_dir.display()))?;
    let rows = run_bench(&scene, &reference_image, &cfg, |r| {
        eprintln!(
            "bench: {} {:?} {:>5} spp seed {:>3}: render {:>8.3} s, relMSE {:.4e}, efficiency {:.4e}",
            r.variant, r.backend, r.spp, r.seed, r.render_s, r.relmse, r.efficiency
        )
    })?;
    let csv = a.out_dir.join("bench.csv");
    write_csv(&rows, &csv)?;
    eprintln!("bench: wrote {}", csv.display());
    let png = a.out_dir.join("bench.png");
    let title = format!("{}: relMSE against render time", scene.name);
    if write_plot(&rows, &title, &png)? {
        eprintln!("bench: wrote {}", png.display());
    } else {
        eprintln!(
            "bench: no plot: no render has both a positive time and a positive relMSE (every one \
             equals the reference, which a log-log plot has no place for); the CSV holds them"
        );
    }
    Ok(())
}
