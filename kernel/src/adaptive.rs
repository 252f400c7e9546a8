//! Adaptive sampling that stays unbiased: the decision to stop a pixel never looks at the
//! samples that make up its image.
//!
//! With `RenderParams::adaptive_target > 0`, every `pilot_period`-th sample index of a pixel is
//! a *pilot*: its value only feeds an estimate of the pixel's variance (of luminance), and the
//! image is the mean of the other samples. Sampling proceeds in passes; before each pass a pixel
//! whose estimated relative error is below the target gets no more samples. The number of image
//! samples N is then a function of the pilot samples alone, which are independent of the image
//! samples (pilots always draw independent numbers, see [`sample_stream`]), so
//! E[mean | N = n] = mu for every n >= 1 and the image stays unbiased. Stopping on the image
//! samples themselves would not be: a pixel whose first samples happen to agree (say, all miss
//! a small bright light) would stop early with a low estimate, which is the bias of most
//! adaptive samplers. The price is the
//! pilot share (1 / pilot_period) of the samples, which the bench reports.

use crate::scene::{sampler, RenderParams};
use spirv_std::glam::Vec3;

/// Whether the render samples adaptively: the one test both backends and the film ask (the
/// host sets `pilot_period` from its settings, `RenderSettings::adaptive`).
#[inline]
pub fn is_adaptive(params: &RenderParams) -> bool {
    params.adaptive.pilot_period > 0
}

/// Whether sample index `sample` of a pixel is a pilot sample (see the module comment).
#[inline]
pub fn is_pilot_sample(params: &RenderParams, sample: u32) -> bool {
    is_adaptive(params) && sample.is_multiple_of(params.adaptive.pilot_period)
}

/// The sampler (`scene::sampler`) and sequence index with which sample `sample` of a pixel
/// draws its numbers. Pilots draw independent numbers: Sobol points of one pixel are stratified
/// jointly, so pilots taken from the image's own sequence would depend on the image samples,
/// and so would a decision to stop. With Sobol points the image samples take consecutive
/// indices of the sequence (the pilots' slots left out), so its power-of-two prefixes stay nets.
#[inline]
pub fn sample_stream(params: &RenderParams, sample: u32) -> (u32, u32) {
    if params.samples.sampler != sampler::SOBOL || params.adaptive.pilot_period == 0 {
        (params.samples.sampler, sample)
    } else if is_pilot_sample(params, sample) {
        (sampler::INDEPENDENT, sample)
    } else {
        (
            sampler::SOBOL,
            sample - sample / params.adaptive.pilot_period - 1,
        )
    }
}

/// Rec. 709 luminance of linear RGB.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Whether a pixel needs no more samples: the relative error its image mean would have with
/// `image_samples` samples, estimated from the pilots' luminance mean and sum of squared
/// deviations `pilot_m2` (`pilot_samples` of them), is below the target:
/// `(s^2 / N) / (m^2 + 0.01) < target^2`, with s^2 = M2 / (n - 1) the pilots' unbiased
/// variance, and the floor 0.01 of `twinpath diff`'s relMSE so black pixels can converge.
#[inline]
pub fn pixel_converged(
    params: &RenderParams,
    pilot_mean: f32,
    pilot_m2: f32,
    pilot_samples: f32,
    image_samples: f32,
) -> bool {
    let target = params.adaptive.target;
    if !(target > 0.0)
        || pilot_samples < params.adaptive.min_pilot_samples as f32
        || pilot_samples < 2.0
        || image_samples < 1.0
    {
        return false;
    }
    let variance = pilot_m2 / (pilot_samples - 1.0);
    let relative_variance = variance / image_samples / (pilot_mean * pilot_mean + 0.01);
    relative_variance < target * target
}
