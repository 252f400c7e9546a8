//! The film: per-pixel sums of samples and of their squares (so every pixel knows its own
//! variance), and image files: EXR (linear float32 RGB) and PNG (sRGB, clamped).
//!
//! Sample sums are fixed-point integers (`fixed_sum`): a pixel's sum does not depend on how its
//! samples were grouped into passes, tiles or parts, so a render split into parts and merged
//! is the single render bit for bit (docs/parts.md). Sums of squares, which only estimate
//! variance and never enter the image, stay f64.

use crate::fixed_sum::FixedSum;
use anyhow::{bail, Context, Result};
use glam::Vec3;
use kernel::adaptive::luminance;
use kernel::film_sample::{classify, sample_use};
use kernel::scene::RenderParams;
use std::path::Path;

/// Accumulated samples of an image.
#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub sum: Vec<[FixedSum; 3]>,
    pub sum_sq: Vec<[f64; 3]>,
    /// Samples added per pixel.
    pub count: Vec<u32>,
    /// Samples dropped: non-finite, or too large to sum (`kernel::film_sample`); expected 0.
    pub discarded: u64,
    /// Adaptive sampling's pilot samples (`kernel::adaptive`): luminance sum and sum of
    /// squares per pixel, and their number. Not part of the image (and never split into
    /// parts, so plain f64 sums).
    pub pilot: Vec<[f64; 2]>,
    pub pilot_count: Vec<u32>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            sum: vec![[FixedSum::default(); 3]; n],
            sum_sq: vec![[0.0; 3]; n],
            count: vec![0; n],
            discarded: 0,
            pilot: vec![[0.0; 2]; n],
            pilot_count: vec![0; n],
        }
    }

    /// Whether adaptive sampling stops pixel (px, py): `kernel::adaptive::pixel_converged` on
    /// the pilots' mean and sum of squared deviations.
    pub fn converged(&self, params: &RenderParams, px: u32, py: u32) -> bool {
        let i = (py * self.width + px) as usize;
        let n = self.pilot_count[i] as f64;
        if n < 1.0 {
            return false;
        }
        let mean = self.pilot[i][0] / n;
        let m2 = (self.pilot[i][1] - n * mean * mean).max(0.0);
        kernel::adaptive::pixel_converged(
            params,
            mean as f32,
            m2 as f32,
            n as f32,
            self.count[i] as f32,
        )
    }

    /// Samples each pixel received (image and pilot samples), row by row.
    pub fn samples_per_pixel(&self) -> Vec<u32> {
        self.count
            .iter()
            .zip(&self.pilot_count)
            .map(|(c, p)| c + p)
            .collect()
    }

    pub fn add_sums(&mut self, px: u32, py: u32, s: &PixelSums) {
        let i = (py * self.width + px) as usize;
        for c in 0..3 {
            self.sum[i][c].add(s.sum[c]);
            self.sum_sq[i][c] += s.sum_sq[c];
        }
        self.count[i] += s.count;
        self.discarded += s.discarded as u64;
        self.pilot[i][0] += s.pilot[0];
        self.pilot[i][1] += s.pilot[1];
        self.pilot_count[i] += s.pilot_count;
    }

    /// Adds every pixel's image sums of `other` (a film of the same size): the sample sums
    /// exactly, so the image does not depend on the order films are added. Pilot sums are not
    /// added.
    pub fn add_film(&mut self, other: &Film) {
        debug_assert_eq!((self.width, self.height), (other.width, other.height));
        for i in 0..self.sum.len() {
            for c in 0..3 {
                self.sum[i][c].add(other.sum[i][c]);
                self.sum_sq[i][c] += other.sum_sq[i][c];
            }
            self.count[i] += other.count[i];
        }
        self.discarded += other.discarded;
    }

    /// The pixel values: the plain mean of each pixel's samples (box filter).
    pub fn mean(&self) -> Vec<[f32; 3]> {
        self.sum
            .iter()
            .zip(&self.count)
            .map(|(s, &n)| {
                let n = n.max(1) as f64;
                [
                    (s[0].to_f64() / n) as f32,
                    (s[1].to_f64() / n) as f32,
                    (s[2].to_f64() / n) as f32,
                ]
            })
            .collect()
    }

    /// Estimated variance of each pixel's mean: the unbiased sample variance over n.
    pub fn variance_of_mean(&self) -> Vec<[f32; 3]> {
        (0..self.sum.len())
            .map(|i| {
                let n = self.count[i] as f64;
                let mut v = [0.0f32; 3];
                if n >= 2.0 {
                    for (c, vc) in v.iter_mut().enumerate() {
                        let m = self.sum[i][c].to_f64() / n;
                        let var = ((self.sum_sq[i][c] - n * m * m) / (n - 1.0)).max(0.0);
                        *vc = (var / n) as f32;
                    }
                }
                v
            })
            .collect()
    }

    /// Total samples over all pixels (image and pilot samples).
    pub fn total_samples(&self) -> u64 {
        self.samples_per_pixel().iter().map(|&c| c as u64).sum()
    }
}

/// Per-pixel running sums of samples, their squares, and the counts; and of the adaptive
/// sampler's pilot samples (luminance only).
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelSums {
    pub sum: [FixedSum; 3],
    pub sum_sq: [f64; 3],
    pub count: u32,
    pub discarded: u32,
    /// Sum and sum of squares of the pilot samples' luminance, and their number.
    pub pilot: [f64; 2],
    pub pilot_count: u32,
}

impl PixelSums {
    /// Adds sample number `sample` of the pixel, of value `v`: to the pilot sums if adaptive
    /// sampling (`kernel::adaptive::is_adaptive`) makes it a pilot sample, else to the image sums.
    /// A value that cannot be summed (non-finite, or beyond `kernel::film_sample::MAX_SAMPLE`) is
    /// counted as discarded instead.
    #[inline]
    pub fn add_sample(&mut self, params: &RenderParams, sample: u32, v: Vec3) {
        match classify(params, sample, v) {
            sample_use::DISCARDED => self.discarded += 1,
            sample_use::PILOT => self.add_pilot(v),
            _ => self.add(v),
        }
    }

    /// Adds an image sample (in range).
    #[inline]
    fn add(&mut self, v: Vec3) {
        for (c, x) in v.to_array().into_iter().enumerate() {
            self.sum[c].add_sample(x);
            self.sum_sq[c] += x as f64 * x as f64;
        }
        self.count += 1;
    }

    /// Adds a pilot sample (`kernel::adaptive`; finite).
    #[inline]
    fn add_pilot(&mut self, v: Vec3) {
        let y = luminance(v) as f64;
        self.pilot[0] += y;
        self.pilot[1] += y * y;
        self.pilot_count += 1;
    }
}

/// An RGB float image in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

impl RgbImage {
    pub fn from_film(film: &Film) -> Self {
        Self {
            width: film.width,
            height: film.height,
            pixels: film.mean(),
        }
    }

    /// Reads an EXR (or any format the `image` crate reads) as linear float RGB.
    pub fn read(path: &Path) -> Result<Self> {
        let img = image::open(path)
            .with_context(|| format!("{}: cannot read image", path.display()))?
            .to_rgb32f();
        let (width, height) = img.dimensions();
        let pixels = img.pixels().map(|p| p.0).collect();
        Ok(Self {
            width,
            height,
            pixels,
        })
    }

    /// Writes by extension: `.exr` linear float32 RGB, `.png` 8-bit sRGB (clamped to [0, 1]).
    pub fn write(&self, path: &Path) -> Result<()> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("exr") => {
                // The exr crate with scan lines in increasing order: the same pixels make the
                // same bytes (the image crate's writer orders tiles as threads finish them).
                use exr::prelude::*;
                let width = self.width as usize;
                let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
                    let [r, g, b] = self.pixels[p.y() * width + p.x()];
                    (r, g, b)
                });
                let layer = Layer::new(
                    (width, self.height as usize),
                    LayerAttributes::default(),
                    Encoding::SMALL_LOSSLESS,
                    channels,
                );
                Image::from_layer(layer)
                    .write()
                    .to_file(path)
                    .with_context(|| format!("{}: cannot write EXR", path.display()))
            }
            Some("png") => {
                let bytes: Vec<u8> = self
                    .pixels
                    .iter()
                    .flatten()
                    .map(|&v| (linear_to_srgb(v) * 255.0 + 0.5) as u8)
                    .collect();
                let img = image::RgbImage::from_raw(self.width, self.height, bytes)
                    .context("image size mismatch")?;
                img.save_with_format(path, image::ImageFormat::Png)
                    .with_context(|| format!("{}: cannot write PNG", path.display()))
            }
            _ => bail!(
                "{}: unknown output format (use .exr or .png)",
                path.display()
            ),
        }
    }
}

/// The sRGB transfer function (IEC 61966-2-1), input clamped to [0, 1]; NaN maps to 0.
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Differences between two images of the same size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageDiff {
    pub rmse: f64,
    /// Mean over pixels and channels of (a - b)^2 / (b^2 + 0.01).
    pub relmse: f64,
    /// Mean over pixels and channels of a - b.
    pub mean_signed: f64,
    /// `mean_signed` over its standard error, the pixels taken as independent samples of the
    /// difference (each pixel's channels averaged first, since a path's channels are
    /// correlated): whether two renders of one image differ by more than their noise, e.g. a
    /// peer's image against a converged reference (|z| of a few at most). 0 where every pixel
    /// differs alike (no spread), as for identical images.
    pub mean_z: f64,
    pub max_abs: f64,
}

/// Compares `a` against reference `b`.
pub fn diff_images(a: &RgbImage, b: &RgbImage) -> Result<ImageDiff> {
    if (a.width, a.height) != (b.width, b.height) {
        bail!(
            "image sizes differ: {}x{} vs {}x{}",
            a.width,
            a.height,
            b.width,
            b.height
        );
    }
    let (mut se, mut rel, mut signed, mut max_abs) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut pixel_squares = 0.0f64;
    for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
        let mut pixel = 0.0f64;
        for c in 0..3 {
            let (x, y) = (pa[c] as f64, pb[c] as f64);
            let d = x - y;
            se += d * d;
            rel += d * d / (y * y + 0.01);
            signed += d;
            pixel += d;
            max_abs = max_abs.max(d.abs());
        }
        pixel /= 3.0;
        pixel_squares += pixel * pixel;
    }
    let n = (a.pixels.len() * 3).max(1) as f64;
    let pixels = a.pixels.len().max(1) as f64;
    // The mean of the pixels' means is `signed / n`; their sample variance over `pixels`.
    let mean = signed / n;
    let variance =
        (pixel_squares / pixels - mean * mean).max(0.0) * pixels / (pixels - 1.0).max(1.0);
    let standard_error = (variance / pixels).sqrt();
    Ok(ImageDiff {
        rmse: (se / n).sqrt(),
        relmse: rel / n,
        mean_signed: mean,
        mean_z: if standard_error > 0.0 {
            mean / standard_error
        } else {
            0.0
        },
        max_abs,
    })
}
