//! Statistics the tests use: z-tests of estimates against expectations.

use twinpath::film::RgbImage;

/// Per-pixel z-test of an image (with its per-pixel variance of the mean) against a reference
/// (optionally with its own variance). A channel passes when |z| <= `z_max`; a pixel passes
/// when all three channels do. Where both variances are zero the values must be equal to within
/// float rounding (relative 1e-5), since neither estimate has noise there.
#[derive(Clone, Copy, Debug)]
pub struct PixelZTest {
    pub pixels: usize,
    pub passed: usize,
    pub max_abs_z: f64,
    /// Mean over pixels and channels of (image - reference).
    pub mean_signed_diff: f64,
}

impl PixelZTest {
    pub fn pass_fraction(&self) -> f64 {
        self.passed as f64 / self.pixels.max(1) as f64
    }
}

pub fn pixel_z_test(
    image: &RgbImage,
    image_var: &[[f32; 3]],
    reference: &RgbImage,
    reference_var: Option<&[[f32; 3]]>,
    z_max: f64,
) -> PixelZTest {
    let mut passed = 0;
    let mut max_abs_z: f64 = 0.0;
    let mut signed = 0.0;
    for i in 0..image.pixels.len() {
        let mut ok = true;
        for c in 0..3 {
            let a = image.pixels[i][c] as f64;
            let b = reference.pixels[i][c] as f64;
            signed += a - b;
            let var = image_var[i][c] as f64 + reference_var.map_or(0.0, |v| v[i][c] as f64);
            if var > 0.0 {
                let z = (a - b) / var.sqrt();
                max_abs_z = max_abs_z.max(z.abs());
                ok &= z.abs() <= z_max;
            } else {
                ok &= (a - b).abs() <= 1e-5 * a.abs().max(b.abs());
            }
        }
        if ok {
            passed += 1;
        }
    }
    PixelZTest {
        pixels: image.pixels.len(),
        passed,
        max_abs_z,
        mean_signed_diff: signed / (3 * image.pixels.len()).max(1) as f64,
    }
}

/// Mean and variance of the mean of a set of independent samples.
pub fn mean_and_variance_of_mean(samples: &[f64]) -> (f64, f64) {
    let n = samples.len() as f64;
    let mean = samples.iter().sum::<f64>() / n;
    let var = samples.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, var / n)
}

/// The variance of an image's mean over its pixels and channels, from each pixel's per-channel
/// variances of the mean, for pixels whose estimates are independent. A pixel's three channels
/// come from the same paths and may be fully correlated (a grey scene's are equal), so the
/// variance of a pixel's channel mean is bounded by the square of the mean of the channels'
/// standard errors (Cauchy-Schwarz); the pixels add. Summing the channels' variances as if
/// independent understates it up to threefold.
pub fn variance_of_channel_mean(var: &[[f32; 3]]) -> f64 {
    let pixels = var.len().max(1) as f64;
    var.iter()
        .map(|v| {
            let se = v.iter().map(|&c| (c as f64).sqrt()).sum::<f64>() / 3.0;
            se * se
        })
        .sum::<f64>()
        / (pixels * pixels)
}
