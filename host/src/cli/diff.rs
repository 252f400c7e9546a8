//! `twinpath diff`: how far one image is from another.

use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use twinpath::film::{diff_images, RgbImage};

/// Compare two images: RMSE, relMSE, mean signed difference and its z (pixels as independent
/// samples), max abs difference.
#[derive(Args)]
pub struct DiffArgs {
    /// The image to judge.
    a: PathBuf,
    /// The reference.
    b: PathBuf,
}

pub fn run(a: DiffArgs) -> Result<()> {
    let ia = RgbImage::read(&a.a)?;
    let ib = RgbImage::read(&a.b)?;
    let d = diff_images(&ia, &ib)?;
    println!("rmse {:.6e}", d.rmse);
    println!("relmse {:.6e}", d.relmse);
    println!("mean_signed_diff {:+.6e}", d.mean_signed);
    println!("mean_diff_z {:+.2}", d.mean_z);
    println!("max_abs_diff {:.6e}", d.max_abs);
    Ok(())
}
