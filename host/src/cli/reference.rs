//! `twinpath reference`: a converged image as the mean of two independent halves, with its own
//! noise estimate.

use super::{load_scene, show_notes};
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;
use twinpath::film::{diff_images, RgbImage};
use twinpath::render::{install_interrupt_handler, render, Backend, RenderOptions};
use twinpath::scene::SceneFile;

/// Render a converged reference as the mean of two independent halves, and estimate its noise.
#[derive(Args)]
pub struct ReferenceArgs {
    scene: Option<PathBuf>,
    /// Total samples per pixel (each half renders half of them).
    #[arg(long)]
    spp: u32,
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    backend: Backend,
    /// Output EXR; the halves go beside it as <stem>_half_a.exr and <stem>_half_b.exr.
    #[arg(long, short = 'o', default_value = "reference.exr")]
    out: PathBuf,
}

pub fn run(a: ReferenceArgs) -> Result<()> {
    install_interrupt_handler();
    if a.spp < 2 {
        bail!("--spp must be at least 2 (two halves)");
    }
    let SceneFile {
        scene,
        mut settings,
    } = load_scene(a.scene.as_deref())?;
    show_notes(&scene);
    settings.spp = a.spp / 2;
    let opts = RenderOptions {
        backend: a.backend,
        device: None,
        validation: false,
        progress: true,
        samples: None,
    };
    let first = render(&scene, &settings, &opts)?;
    settings.seed = settings.seed.wrapping_add(0x9e37_79b9);
    let second = render(&scene, &settings, &opts)?;
    if first.interrupted || second.interrupted {
        bail!("interrupted: no reference written");
    }
    let (ia, ib) = (
        RgbImage::from_film(&first.film),
        RgbImage::from_film(&second.film),
    );
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
    let out = &a.out;
    let stem = out
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("reference");
    let half = |tag: &str| out.with_file_name(format!("{stem}_half_{tag}.exr"));
    mean.write(out)?;
    ia.write(&half("a"))?;
    ib.write(&half("b"))?;
    // The mean of two halves has a quarter of their squared difference as its error.
    let d = diff_images(&ia, &ib)?;
    eprintln!(
        "reference: wrote {} ({} spp) and its halves; estimated noise: RMSE {:.3e}, relMSE {:.3e}",
        out.display(),
        a.spp,
        d.rmse / 2.0,
        d.relmse / 4.0
    );
    Ok(())
}
