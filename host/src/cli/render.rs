//! `twinpath render`: a scene to EXR and/or PNG, with progress, Ctrl-C and an honest log.

use super::{check_writable, extension, load_scene, mib, scene_stem, show_notes, SettingFlags};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;
use twinpath::film::RgbImage;
use twinpath::part_file::{write_part, PartHeader};
use twinpath::render::{install_interrupt_handler, render, Backend, RenderOptions, RenderOutput};
use twinpath::sample_range::{Part, SampleRange};
use twinpath::scene::SceneFile;
use twinpath::settings::RenderSettings;

/// Render a scene (default: the built-in Cornell scene) to EXR and/or PNG.
#[derive(Args)]
pub struct RenderArgs {
    /// Scene file: TOML, or glTF 2.0 (.gltf, .glb). Without it, the built-in Cornell scene.
    scene: Option<PathBuf>,
    /// A perspective camera to render through, by name: of the glTF file (default: its first),
    /// or of a TOML scene's [[gltf]] files (instead of its [camera] table).
    #[arg(long)]
    camera: Option<String>,
    /// Image width in pixels, instead of the scene's (alone: the height follows the scene's
    /// aspect ratio). The vertical field of view is kept.
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels, instead of the scene's (alone: the width follows the scene's
    /// aspect ratio).
    #[arg(long)]
    height: Option<u32>,
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    backend: Backend,
    /// Vulkan device index for the GPU backend (see `twinpath info`).
    #[arg(long)]
    device: Option<usize>,
    /// Enable the Vulkan validation layers (Debian package vulkan-validationlayers).
    #[arg(long)]
    validation: bool,
    /// Output file(s): .exr (linear float32) or .png (sRGB). Default: <scene stem>.exr and .png
    /// (with --part or --samples: one part file, <scene stem>.part-I-of-N.exr or
    /// <scene stem>.samples-A-B.exr).
    #[arg(long = "out", short = 'o')]
    out: Vec<PathBuf>,
    /// Render only part I of N of the samples (I counts from 0: a job array's index) and write
    /// a part file for `twinpath merge`.
    #[arg(long, value_name = "I/N", conflicts_with = "samples")]
    part: Option<String>,
    /// Render only sample indices A..B of every pixel and write a part file for `twinpath
    /// merge`.
    #[arg(long, value_name = "A..B")]
    samples: Option<String>,
    #[command(flatten)]
    settings: SettingFlags,
    /// Write the samples each pixel received as an image (EXR: the count in every channel).
    #[arg(long)]
    spp_map: Option<PathBuf>,
    /// Worker threads for the CPU backend (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

pub fn run(a: RenderArgs) -> Result<()> {
    if let Some(t) = a.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build_global()
            .context("cannot set the thread count")?;
    }
    let SceneFile {
        mut scene,
        mut settings,
    } = match (&a.scene, &a.camera) {
        (Some(path), Some(name)) => SceneFile::load_with_camera(path, Some(name))?,
        (None, Some(_)) => bail!("--camera selects a glTF file's camera: give the file"),
        (path, None) => load_scene(path.as_deref())?,
    };
    a.settings.apply(&mut settings)?;
    scene.camera = scene
        .camera
        .resized(a.width, a.height)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    if let Some(m) = &a.spp_map {
        if extension(m).as_deref() != Some("exr") {
            bail!("--spp-map {}: must be an .exr file", m.display());
        }
        check_writable(m).with_context(|| format!("--spp-map {}", m.display()))?;
    }
    let share = PartShare::of(&a, &settings)?;
    let outputs = if let Some(share) = &share {
        let out = match a.out.as_slice() {
            [] => PathBuf::from(share.file_name(&scene_stem(scene.name.as_str()))),
            [o] if extension(o).as_deref() == Some("exr") => o.clone(),
            _ => bail!(
                "--out: a part renders one part file, an .exr (twinpath merge makes the image)"
            ),
        };
        vec![out]
    } else if a.out.is_empty() {
        let stem = scene_stem(scene.name.as_str());
        vec![
            PathBuf::from(format!("{stem}.exr")),
            PathBuf::from(format!("{stem}.png")),
        ]
    } else {
        a.out
    };
    for o in &outputs {
        match extension(o).as_deref() {
            Some("exr") | Some("png") => {}
            _ => bail!("--out {}: unknown format (use .exr or .png)", o.display()),
        }
        // Before the render, not after an hour of it.
        check_writable(o).with_context(|| format!("--out {}", o.display()))?;
    }
    // From here on Ctrl-C stops the render and keeps the image (the line below says so).
    install_interrupt_handler();
    let instances = if scene.instances.is_empty() {
        String::new()
    } else {
        let meshes = scene.meshes.len();
        format!(
            " ({} of them stored once in {meshes} {} placed by {} instances)",
            scene.triangles.len() - scene.world_triangle_count(),
            if meshes == 1 { "mesh" } else { "meshes" },
            scene.instances.len()
        )
    };
    // The media table's record 0 is vacuum, always there.
    let media = match (scene.media.len().saturating_sub(1), scene.medium) {
        (0, _) => String::new(),
        (n, 0) => format!(", {n} {}", if n == 1 { "medium" } else { "media" }),
        (n, _) => format!(
            ", {n} {}, the scene in one",
            if n == 1 { "medium" } else { "media" }
        ),
    };
    let samples = match &share {
        Some(s) => s.describe(),
        None => format!("{} spp", settings.spp),
    };
    eprintln!(
        "twinpath: {} ({}x{}, {} spheres, {} triangles{instances}, {} lights{media}), {samples}, seed {}",
        scene.name,
        scene.camera.width,
        scene.camera.height,
        scene.spheres.len(),
        scene.triangles.len(),
        scene.lights.len(),
        settings.seed
    );
    eprintln!("twinpath: scene memory: {}", scene.memory_report());
    show_notes(&scene);
    let opts = RenderOptions {
        backend: a.backend,
        device: a.device,
        validation: a.validation,
        progress: !a.quiet,
        samples: share.as_ref().map(|s| s.samples),
    };
    let result = render(&scene, &settings, &opts)?;
    log_costs(&result, a.backend);
    if result.interrupted {
        eprintln!(
            "twinpath: interrupted: writing the image so far, {} of {} samples per pixel",
            result.spp_done,
            opts.samples.map_or(settings.spp, |s| s.len())
        );
    }
    if let Some(share) = &share {
        let backend = match result.backend {
            Backend::Gpu => "gpu",
            _ => "cpu",
        };
        let mut header = PartHeader::new(&scene, &settings, backend, result.samples);
        header.part = share.part.map(|p| (p, SampleRange::all(settings.spp)));
        write_part(&outputs[0], &header, &result.film)?;
        eprintln!(
            "twinpath: wrote part file {} (samples {})",
            outputs[0].display(),
            result.samples
        );
        return Ok(());
    }
    let image = RgbImage::from_film(&result.film);
    for o in &outputs {
        image.write(o)?;
        eprintln!("twinpath: wrote {}", o.display());
    }
    write_sample_counts(&settings, &result, a.spp_map.as_ref())
}

/// The samples of a render split into parts: `--part I/N` or `--samples A..B`.
struct PartShare {
    part: Option<Part>,
    samples: SampleRange,
}

impl PartShare {
    /// The share the flags ask for (`None`: the whole render).
    fn of(a: &RenderArgs, settings: &RenderSettings) -> Result<Option<Self>> {
        Ok(Some(match (&a.part, &a.samples) {
            (Some(text), _) => {
                let part = Part::parse(text).with_context(|| format!("--part {text}"))?;
                let spp = settings.spp;
                if part.count > spp {
                    bail!(
                        "--part {text}: {} parts of {spp} samples per pixel would leave parts empty",
                        part.count
                    );
                }
                Self {
                    part: Some(part),
                    samples: part.samples(SampleRange::all(spp)),
                }
            }
            (None, Some(text)) => Self {
                part: None,
                samples: SampleRange::parse(text).with_context(|| format!("--samples {text}"))?,
            },
            (None, None) => return Ok(None),
        }))
    }

    /// The part file's default name.
    fn file_name(&self, stem: &str) -> String {
        match self.part {
            Some(p) => format!("{stem}.part-{}-of-{}.exr", p.index, p.count),
            None => format!(
                "{stem}.samples-{}-{}.exr",
                self.samples.start, self.samples.end
            ),
        }
    }

    /// For the log: which samples.
    fn describe(&self) -> String {
        match self.part {
            Some(p) => format!("part {p}: samples {} of each pixel", self.samples),
            None => format!("samples {} of each pixel", self.samples),
        }
    }
}

/// The log lines of set-up and render time, throughput and discarded samples, and the rays
/// traced per sample where the backend counts them.
fn log_costs(result: &RenderOutput, asked: Backend) {
    let samples = result.film.total_samples();
    let secs = result.render.as_secs_f64();
    let setup = match result.backend {
        Backend::Gpu => format!(
            "setup {:.3} s (acceleration structures {:.3} s, {:.1} MiB; pipeline {:.3} s)",
            result.setup.as_secs_f64(),
            result.accel_build.as_secs_f64(),
            mib(result.accel_bytes),
            result.pipeline.as_secs_f64()
        ),
        _ => {
            // With --backend auto, set-up also holds the look for a Vulkan device
            // (loading the driver: up to two seconds on a cold file cache).
            let probe = result.setup.saturating_sub(result.accel_build);
            let probe = if asked == Backend::Auto {
                format!("looking for a Vulkan device {:.3} s, ", probe.as_secs_f64())
            } else {
                String::new()
            };
            format!(
                "setup {:.3} s ({probe}BVH {:.3} s, {:.1} MiB)",
                result.setup.as_secs_f64(),
                result.accel_build.as_secs_f64(),
                mib(result.accel_bytes)
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
    if let Some(rays) = result.rays {
        let per_sample = |n: u64| n as f64 / samples.max(1) as f64;
        eprintln!(
            "twinpath: rays: {:.3} per sample ({:.3} closest-hit, {:.3} shadow), {:.3} M rays/s",
            per_sample(rays.total()),
            per_sample(rays.closest),
            per_sample(rays.shadow),
            rays.total() as f64 / secs.max(1e-9) / 1e6
        );
    }
}

/// Adaptive sampling's summary, and the sample-count image if asked for.
fn write_sample_counts(
    settings: &RenderSettings,
    result: &RenderOutput,
    spp_map: Option<&PathBuf>,
) -> Result<()> {
    let spp = result.film.samples_per_pixel();
    if settings.adaptive() {
        let mean = spp.iter().map(|&c| c as f64).sum::<f64>() / spp.len().max(1) as f64;
        eprintln!(
            "twinpath: adaptive sampling (target {}): {mean:.1} samples per pixel on average, {} of {} pixels stopped early",
            settings.adaptive_target,
            spp.iter().filter(|&&c| c < result.spp_done).count(),
            spp.len()
        );
    }
    if let Some(m) = spp_map {
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
