//! `twinpath merge`: part files to the image of the whole render.

use super::{check_writable, extension};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;
use twinpath::film::RgbImage;
use twinpath::merge::merge_parts;

/// Combine part files (`twinpath render --part I/N` or `--samples A..B`) into one image.
#[derive(Args)]
pub struct MergeArgs {
    /// The part files, in any order.
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// Output file(s): .exr (linear float32) or .png (sRGB).
    #[arg(long = "out", short = 'o', required = true)]
    out: Vec<PathBuf>,
}

pub fn run(a: MergeArgs) -> Result<()> {
    for o in &a.out {
        match extension(o).as_deref() {
            Some("exr") | Some("png") => {}
            _ => bail!("--out {}: unknown format (use .exr or .png)", o.display()),
        }
        check_writable(o).with_context(|| format!("--out {}", o.display()))?;
    }
    let t = Instant::now();
    let merged = merge_parts(&a.parts)?;
    for note in &merged.notes {
        eprintln!("twinpath: note: {note}");
    }
    eprintln!(
        "twinpath: merged {} parts of {} ({}x{}): samples {} of each pixel, seed {}, {} samples discarded as not finite or too large, {:.3} s",
        a.parts.len(),
        merged.header.scene,
        merged.film.width,
        merged.film.height,
        merged.samples,
        merged.header.seed,
        merged.film.discarded,
        t.elapsed().as_secs_f64()
    );
    let image = RgbImage::from_film(&merged.film);
    for o in &a.out {
        image.write(o)?;
        eprintln!("twinpath: wrote {}", o.display());
    }
    Ok(())
}
