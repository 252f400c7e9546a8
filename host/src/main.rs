//! The `twinpath` command line: render, diff, info.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use twinpath::bench::{run_bench, write_csv, write_plot, BenchConfig, Variant};
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

#[derive(Clone, Copy, Debug, ValueEnum)]
enum LightSelection {
    /// Proportional to each light's power (alias table).
    Power,
    /// The seed's uniform choice.
    Uniform,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Sampler {
    /// Independent uniform numbers per dimension.
    Independent,
    /// Owen-scrambled Sobol points, stratified within each pixel.
    Sobol,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum BenchBackends {
    Cpu,
    Gpu,
    Both,
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
        /// How next-event estimation picks one of several lights.
        #[arg(long, value_enum)]
        light_selection: Option<LightSelection>,
        /// Where each sample's random numbers come from.
        #[arg(long, value_enum)]
        sampler: Option<Sampler>,
        /// Run the generic kernel path instead of one specialized to the scene's features.
        #[arg(long)]
        no_specialize: bool,
        /// CPU: trace one path at a time over the BVH even in scenes small enough for
        /// sixteen-path packets (README "Packets of paths").
        #[arg(long)]
        no_packets: bool,
        /// Adaptive sampling: stop each pixel once its estimated relative error is below this
        /// (--spp is then the most a pixel gets). Unbiased: see README "Adaptive sampling".
        #[arg(long)]
        target_error: Option<f32>,
        /// Write the samples each pixel received as an image (EXR: the count in every channel).
        #[arg(long)]
        spp_map: Option<PathBuf>,
        /// Worker threads for the CPU backend (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Time against error: render at 1, 2, 4, ... spp per variant and backend; CSV and a plot.
    Bench {
        /// Scene file (TOML). Without it, the built-in Cornell scene.
        scene: Option<PathBuf>,
        /// Converged reference image (EXR) of the same scene, e.g. from `twinpath reference`.
        #[arg(long)]
        reference: PathBuf,
        #[arg(long, value_enum, default_value_t = BenchBackends::Cpu)]
        backend: BenchBackends,
        /// NAME or NAME:key=value,... (mis=power|half, light_sampling=cone|area,
        /// light_selection=power|uniform, sampler=independent|sobol, roulette=constant|throughput, rr=P,
        /// rr_start_depth=D, specialize=on|off, packets=on|off, adaptive=TARGET), on top of the scene's
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
    },
    /// Render a converged reference as the mean of two independent halves, and estimate its noise.
    Reference {
        scene: Option<PathBuf>,
        /// Total samples per pixel (each half renders half of them).
        #[arg(long)]
        spp: u32,
        #[arg(long, value_enum, default_value_t = Backend::Auto)]
        backend: Backend,
        /// Output EXR; the halves go beside it as <stem>_half_a.exr and <stem>_half_b.exr.
        #[arg(long, short = 'o', default_value = "reference.exr")]
        out: PathBuf,
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
    /// Ray throughput of the CPU traversal on one thread (camera rays and diffuse bounce rays),
    /// and the BVH's build time and memory.
    Rays {
        /// Scene file (TOML). Without it, the built-in Cornell scene.
        scene: Option<PathBuf>,
        /// Add a generated mesh of about N triangles (a rippled torus-knot tube) at the point
        /// the camera looks at.
        #[arg(long)]
        mesh_triangles: Option<usize>,
        /// Width of the camera-ray image (its height follows the scene's aspect ratio).
        #[arg(long, default_value_t = 1024)]
        width: u32,
        /// Timed passes per measurement; the fastest is reported.
        #[arg(long, default_value_t = 3)]
        repeats: u32,
        /// Write the rays and our hits here, for scripts/embree_rays.c.
        #[arg(long)]
        ray_file: Option<PathBuf>,
        /// Append the results to this CSV file (header written when it is new).
        #[arg(long)]
        csv: Option<PathBuf>,
    },
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
            light_selection,
            sampler,
            no_specialize,
            no_packets,
            target_error,
            spp_map,
            threads,
            quiet,
        } => {
            if let Some(t) = threads {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(t)
                    .build_global()
                    .context("cannot set the thread count")?;
            }
            let mut scene = load_scene(scene.as_deref())?;
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
            if let Some(l) = light_selection {
                r.light_selection = match l {
                    LightSelection::Power => kernel::scene::light_selection::POWER,
                    LightSelection::Uniform => kernel::scene::light_selection::UNIFORM,
                };
            }
            if let Some(s) = sampler {
                r.sampler = match s {
                    Sampler::Independent => kernel::scene::sampler::INDEPENDENT,
                    Sampler::Sobol => kernel::scene::sampler::SOBOL,
                };
            }
            if no_specialize {
                r.specialize = false;
            }
            if no_packets {
                r.packets = false;
            }
            if let Some(t) = target_error {
                if !(t >= 0.0 && t.is_finite()) {
                    bail!("--target-error {t}: must be a finite relative error >= 0");
                }
                r.adaptive_target = t;
            }
            if let Some(m) = &spp_map {
                if m.extension()
                    .and_then(|e| e.to_str())
                    .map(|e| e.to_ascii_lowercase())
                    != Some("exr".into())
                {
                    bail!("--spp-map {}: must be an .exr file", m.display());
                }
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
            // From here on Ctrl-C stops the render and keeps the image (the line below says so).
            install_interrupt_handler();
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
                _ => {
                    // With --backend auto, set-up also holds the look for a Vulkan device
                    // (loading the driver: up to two seconds on a cold file cache).
                    let probe = result.setup.saturating_sub(result.accel_build);
                    let probe = if backend == Backend::Auto {
                        format!("looking for a Vulkan device {:.3} s, ", probe.as_secs_f64())
                    } else {
                        String::new()
                    };
                    format!(
                        "setup {:.3} s ({probe}BVH {:.3} s)",
                        result.setup.as_secs_f64(),
                        result.accel_build.as_secs_f64()
                    )
                }
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
            let spp = result.film.samples_per_pixel();
            if scene.render.adaptive_target > 0.0 {
                let mean = spp.iter().map(|&c| c as f64).sum::<f64>() / spp.len().max(1) as f64;
                eprintln!(
                    "twinpath: adaptive sampling (target {}): {mean:.1} samples per pixel on average, {} of {} pixels stopped early",
                    scene.render.adaptive_target,
                    spp.iter().filter(|&&c| c < result.spp_done).count(),
                    spp.len()
                );
            }
            if let Some(m) = &spp_map {
                RgbImage {
                    width: result.film.width,
                    height: result.film.height,
                    pixels: spp.iter().map(|&c| [c as f32; 3]).collect(),
                }
                .write(m)?;
                eprintln!("twinpath: wrote {} (samples per pixel)", m.display());
            }
            Ok(())
        }
        Command::Bench {
            scene,
            reference,
            backend,
            variants,
            max_spp,
            max_seconds,
            seeds,
            out_dir,
        } => {
            install_interrupt_handler();
            let scene = load_scene(scene.as_deref())?;
            let reference_image = RgbImage::read(&reference)?;
            let variants = if variants.is_empty() {
                vec![Variant {
                    name: "scene".into(),
                    settings: scene.render,
                }]
            } else {
                variants
                    .iter()
                    .map(|v| Variant::parse(v, &scene.render))
                    .collect::<Result<_>>()?
            };
            let backends = match backend {
                BenchBackends::Cpu => vec![Backend::Cpu],
                BenchBackends::Gpu => vec![Backend::Gpu],
                BenchBackends::Both => vec![Backend::Cpu, Backend::Gpu],
            };
            let cfg = BenchConfig {
                variants,
                backends,
                max_spp,
                max_seconds,
                seeds,
            };
            std::fs::create_dir_all(&out_dir)
                .with_context(|| format!("{}: cannot create", out_dir.display()))?;
            let rows = run_bench(&scene, &reference_image, &cfg, |r| {
                eprintln!(
                    "bench: {} {:?} {:>5} spp seed {:>3}: render {:>8.3} s, relMSE {:.4e}, efficiency {:.4e}",
                    r.variant, r.backend, r.spp, r.seed, r.render_s, r.relmse, r.efficiency
                )
            })?;
            let csv = out_dir.join("bench.csv");
            write_csv(&rows, &csv)?;
            eprintln!("bench: wrote {}", csv.display());
            let png = out_dir.join("bench.png");
            write_plot(
                &rows,
                &format!("{}: relMSE against render time", scene.name),
                &png,
            )?;
            eprintln!("bench: wrote {}", png.display());
            Ok(())
        }
        Command::Reference {
            scene,
            spp,
            backend,
            out,
        } => {
            install_interrupt_handler();
            if spp < 2 {
                bail!("--spp must be at least 2 (two halves)");
            }
            let mut scene = load_scene(scene.as_deref())?;
            scene.render.spp = spp / 2;
            let opts = RenderOptions {
                backend,
                device: None,
                validation: false,
                progress: true,
            };
            let a = render(&scene, &opts)?;
            scene.render.seed = scene.render.seed.wrapping_add(0x9e37_79b9);
            let b = render(&scene, &opts)?;
            if a.interrupted || b.interrupted {
                bail!("interrupted: no reference written");
            }
            let (ia, ib) = (RgbImage::from_film(&a.film), RgbImage::from_film(&b.film));
            let mean = RgbImage {
                width: ia.width,
                height: ia.height,
                pixels: ia
                    .pixels
                    .iter()
                    .zip(&ib.pixels)
                    .map(|(p, q)| std::array::from_fn(|c| 0.5 * (p[c] + q[c])))
                    .collect(),
            };
            let stem = out
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("reference");
            let half = |tag: &str| out.with_file_name(format!("{stem}_half_{tag}.exr"));
            mean.write(&out)?;
            ia.write(&half("a"))?;
            ib.write(&half("b"))?;
            // The mean of two halves has a quarter of their squared difference as its error.
            let d = diff_images(&ia, &ib)?;
            eprintln!(
                "reference: wrote {} ({spp} spp) and its halves; estimated noise: RMSE {:.3e}, relMSE {:.3e}",
                out.display(),
                d.rmse / 2.0,
                d.relmse / 4.0
            );
            Ok(())
        }
        Command::Rays {
            scene,
            mesh_triangles,
            width,
            repeats,
            ray_file,
            csv,
        } => {
            let mut scene = load_scene(scene.as_deref())?;
            if let Some(n) = mesh_triangles {
                twinpath::cpu::rays::add_knot_mesh(&mut scene, n);
            }
            if width == 0 {
                bail!("--width must be at least 1");
            }
            let height = ((width as u64 * scene.camera.height as u64) / scene.camera.width as u64)
                .max(1) as u32;
            let r =
                twinpath::cpu::rays::measure(&scene, width, height, repeats, ray_file.as_deref())
                    .context("writing the ray file")?;
            let mib = |b: usize| b as f64 / (1024.0 * 1024.0);
            println!(
                "{}: {} triangles, {} spheres; BVH build {:.3} s ({} threads), {} nodes, {:.1} MiB hierarchy + {:.1} MiB primitives",
                scene.name, r.triangles, r.spheres, r.build_seconds, rayon::current_num_threads(), r.nodes,
                mib(r.hierarchy_bytes), mib(r.primitive_bytes)
            );
            for s in &r.sets {
                println!(
                    "  {:<28} {:>9} rays ({:>9} hit): closest {:>7.3} Mrays/s, occluded {:>7.3} Mrays/s (one thread)",
                    s.name, s.rays, s.hits, s.closest_per_second * 1e-6, s.occluded_per_second * 1e-6
                );
                if let Some((closest, occluded)) = s.packets {
                    println!(
                        "  {:<28} {:>9} rays in packets of 16:  closest {:>7.3} Mrays/s, occluded {:>7.3} Mrays/s (one thread)",
                        "", s.rays, closest * 1e-6, occluded * 1e-6
                    );
                }
            }
            if let Some(path) = csv {
                use std::io::Write;
                let new = !path.exists();
                let mut f = std::fs::OpenOptions::new()
                    .create(true)
                    .append(true)
                    .open(&path)
                    .with_context(|| format!("opening {}", path.display()))?;
                if new {
                    writeln!(f, "tracer,scene,triangles,spheres,build_seconds,hierarchy_bytes,primitive_bytes,rays_name,rays,hits,closest_mrays_per_s,occluded_mrays_per_s")?;
                }
                for s in &r.sets {
                    writeln!(
                        f,
                        "twinpath,{},{},{},{:.6},{},{},{},{},{},{:.4},{:.4}",
                        scene_stem(&scene.name),
                        r.triangles,
                        r.spheres,
                        r.build_seconds,
                        r.hierarchy_bytes,
                        r.primitive_bytes,
                        s.name,
                        s.rays,
                        s.hits,
                        s.closest_per_second * 1e-6,
                        s.occluded_per_second * 1e-6
                    )?;
                    if let Some((closest, occluded)) = s.packets {
                        writeln!(
                            f,
                            "twinpath_packets,{},{},{},0,0,{},{},{},{},{:.4},{:.4}",
                            scene_stem(&scene.name),
                            r.triangles,
                            r.spheres,
                            r.primitive_bytes,
                            s.name,
                            s.rays,
                            s.hits,
                            closest * 1e-6,
                            occluded * 1e-6
                        )?;
                    }
                }
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

/// The scene file, or the built-in Cornell scene.
fn load_scene(path: Option<&Path>) -> Result<Scene> {
    Ok(match path {
        Some(p) => Scene::load(p)?,
        None => Scene::builtin_default(),
    })
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
