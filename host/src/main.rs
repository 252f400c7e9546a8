//! The `twinpath` command line: render, diff, info.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use twinpath::film::{diff_images, RgbImage};
use twinpath::render::{install_interrupt_handler, render, Backend, RenderOptions};
use twinpath::scene::{Scene, DEFAULT_SCENE_NAME};

#[derive(Parser)]
#[command(
    name = "twinpath",
    version,
    about = "A path tracer whose kernel runs on the CPU and, through Vulkan ray tracing, on the GPU"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Roulette {
    /// The seed's constant survival probability (--rr).
    Constant,
    /// Survival probability min(1, max throughput component), from --rr-start-depth on.
    Throughput,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Mis {
    /// Veach's power heuristic (beta = 2).
    Power,
    /// The seed's fixed 1/2 weights.
    Half,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum LightSampling {
    /// A direction uniform in the cone each sphere light subtends.
    Cone,
    /// The seed's uniform point on the light's whole surface.
    Area,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene (default: the built-in Cornell scene) to EXR and/or PNG.
    Render {
        /// Scene file (TOML). Without it, the built-in Cornell scene.
        scene: Option<PathBuf>,
        #[arg(long, value_enum, default_value_t = Backend::Auto)]
        backend: Backend,
        /// Vulkan device index for the GPU backend (see `twinpath info`).
        #[arg(long)]
        device: Option<usize>,
        /// Enable the Vulkan validation layers (Debian package vulkan-validationlayers).
        #[arg(long)]
        validation: bool,
        /// Samples per pixel (overrides the scene's [render] spp).
        #[arg(long)]
        spp: Option<u32>,
        /// Random seed (overrides the scene's [render] seed).
        #[arg(long)]
        seed: Option<u32>,
        /// Output file(s): .exr (linear float32) or .png (sRGB). Default: <scene stem>.exr and .png.
        #[arg(long = "out", short = 'o')]
        out: Vec<PathBuf>,
        /// Constant Russian-roulette survival probability in (0, 1] (the seed's 0.8).
        #[arg(long)]
        rr: Option<f32>,
        /// Russian-roulette strategy.
        #[arg(long, value_enum)]
        roulette: Option<Roulette>,
        /// First path vertex whose extension roulette decides (1 = the camera ray's hit).
        #[arg(long)]
        rr_start_depth: Option<u32>,
        /// How light sampling and BRDF sampling are weighted.
        #[arg(long, value_enum)]
        mis: Option<Mis>,
        /// How next-event estimation picks a point on a sphere light.
        #[arg(long, value_enum)]
        light_sampling: Option<LightSampling>,
        /// Worker threads for the CPU backend (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Compare two images: RMSE, relMSE, mean signed difference, max abs difference.
    Diff {
        /// The image to judge.
        a: PathBuf,
        /// The reference.
        b: PathBuf,
    },
    /// What this build contains: the SPIR-V module and the backends.
    Info,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("twinpath: error: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> Result<()> {
    match Cli::parse().command {
        Command::Render {
            scene,
            backend,
            device,
            validation,
            spp,
            seed,
            out,
            rr,
            roulette,
            rr_start_depth,
            mis,
            light_sampling,
            threads,
            quiet,
        } => {
            if let Some(t) = threads {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(t)
                    .build_global()
                    .context("cannot set the thread count")?;
            }
            let mut scene = match &scene {
                Some(path) => Scene::load(path)?,
                None => Scene::builtin_default(),
            };
            let r = &mut scene.render;
            if let Some(s) = spp {
                if s == 0 {
                    bail!("--spp must be at least 1");
                }
                r.spp = s;
            }
            if let Some(s) = seed {
                r.seed = s;
            }
            if let Some(m) = roulette {
                r.rr_mode = match m {
                    Roulette::Constant => kernel::scene::roulette::CONSTANT,
                    Roulette::Throughput => {
                        r.rr_start_depth = 5;
                        kernel::scene::roulette::THROUGHPUT
                    }
                };
            }
            if let Some(q) = rr {
                if !(q > 0.0 && q <= 1.0) {
                    bail!("--rr {q}: must be a probability in (0, 1]");
                }
                r.rr_probability = q;
            }
            if let Some(d) = rr_start_depth {
                r.rr_start_depth = d;
            }
            if let Some(m) = mis {
                r.mis_mode = match m {
                    Mis::Power => kernel::scene::mis::POWER,
                    Mis::Half => kernel::scene::mis::HALF,
                };
            }
            if let Some(l) = light_sampling {
                r.light_sampling = match l {
                    LightSampling::Cone => kernel::scene::light_sampling::CONE,
                    LightSampling::Area => kernel::scene::light_sampling::AREA,
                };
            }
            let outputs = if out.is_empty() {
                let stem = scene_stem(scene.name.as_str());
                vec![
                    PathBuf::from(format!("{stem}.exr")),
                    PathBuf::from(format!("{stem}.png")),
                ]
            } else {
                out
            };
            for o in &outputs {
                match o
                    .extension()
                    .and_then(|e| e.to_str())
                    .map(|e| e.to_ascii_lowercase())
                    .as_deref()
                {
                    Some("exr") | Some("png") => {}
                    _ => bail!("--out {}: unknown format (use .exr or .png)", o.display()),
                }
            }
            eprintln!(
                "twinpath: {} ({}x{}, {} spheres, {} triangles, {} lights), {} spp, seed {}",
                scene.name,
                scene.camera.width,
                scene.camera.height,
                scene.spheres.len(),
                scene.triangles.len(),
                scene.lights.len(),
                scene.render.spp,
                scene.render.seed
            );
            install_interrupt_handler();
            let opts = RenderOptions {
                backend,
                device,
                validation,
                progress: !quiet,
            };
            let result = render(&scene, &opts)?;
            let samples = result.film.total_samples();
            let secs = result.render.as_secs_f64();
            let setup = match result.backend {
                Backend::Gpu => format!(
                    "setup {:.3} s (acceleration structures {:.3} s, pipeline {:.3} s)",
                    result.setup.as_secs_f64(),
                    result.accel_build.as_secs_f64(),
                    result.pipeline.as_secs_f64()
                ),
                _ => format!("setup {:.3} s (BVH)", result.setup.as_secs_f64()),
            };
            eprintln!(
                "twinpath: {:?} backend: {setup}, render {:.3} s, {:.3} M samples/s, {} non-finite samples discarded",
                result.backend,
                secs,
                samples as f64 / secs.max(1e-9) / 1e6,
                result.film.discarded
            );
            if result.interrupted {
                eprintln!(
                    "twinpath: interrupted: writing the image so far, {} of {} samples per pixel",
                    result.spp_done, scene.render.spp
                );
            }
            let image = RgbImage::from_film(&result.film);
            for o in &outputs {
                image.write(o)?;
                eprintln!("twinpath: wrote {}", o.display());
            }
            Ok(())
        }
        Command::Diff { a, b } => {
            let ia = RgbImage::read(&a)?;
            let ib = RgbImage::read(&b)?;
            let d = diff_images(&ia, &ib)?;
            println!("rmse {:.6e}", d.rmse);
            println!("relmse {:.6e}", d.relmse);
            println!("mean_signed_diff {:+.6e}", d.mean_signed);
            println!("max_abs_diff {:.6e}", d.max_abs);
            Ok(())
        }
        Command::Info => {
            println!("twinpath {}", env!("CARGO_PKG_VERSION"));
            println!(
                "kernel SPIR-V module: {} bytes (compiled by rust-gpu at build time)",
                twinpath::KERNEL_SPV.len()
            );
            println!("cpu backend: {} threads", rayon::current_num_threads());
            match twinpath::vulkan::device::list_devices() {
                Ok(devices) if devices.is_empty() => println!("gpu backend: no Vulkan devices"),
                Ok(devices) => {
                    println!("gpu backend: Vulkan devices (use --device N):");
                    for d in devices {
                        let (ma, mi, pa) = d.api_version;
                        let status = if d.usable() {
                            "usable".to_string()
                        } else {
                            format!("lacks {}", d.missing.join(", "))
                        };
                        println!(
                            "  [{}] {} ({:?}, Vulkan {ma}.{mi}.{pa}): {status}",
                            d.index, d.name, d.device_type
                        );
                    }
                }
                Err(e) => println!("gpu backend: unavailable: {e:#}"),
            }
            Ok(())
        }
    }
}

/// `scenes/cornell.toml` -> `cornell`; the built-in scene -> `cornell`.
fn scene_stem(name: &str) -> String {
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
