//! How a path vertex turns random numbers into its light sample and its BRDF direction. By
//! default it draws the numbers from its [`SampleStream`] and calls the samplers, one path at a
//! time (the GPU, the one-path loop); the CPU's packets hand over the same samples computed for
//! sixteen paths at once by the samplers' [`crate::real::Real`] forms.

use crate::brdf::sample_brdf;
use crate::light::{sample_light_from, DirectionalLightSample};
use crate::rng::{SampleRng, SampleStream};
use crate::scene::SphereLight;
use spirv_std::glam::Vec3;

/// A [`SampleStream`] that also gives a vertex's samples. An implementation may return samples
/// it computed earlier, but only ones equal to what the provided methods compute for the same
/// arguments and stream position.
pub trait VertexSampler: SampleStream {
    /// [`sample_light_from`] for receiver `x` with light choice `u_select` and the pair of numbers
    /// at the current dimension (the stream advances two).
    #[inline]
    fn sample_light_from(
        &mut self,
        lights: &[SphereLight],
        light_count: u32,
        mode: u32,
        x: Vec3,
        u_select: f32,
    ) -> DirectionalLightSample {
        let (u1, u2) = self.next_2d();
        sample_light_from(lights, light_count, mode, x, u_select, u1, u2)
    }

    /// [`sample_brdf`] around the facing normal `n` with the pair of numbers at the current
    /// dimension (the stream advances two).
    #[inline]
    fn sample_brdf(&mut self, n: Vec3) -> Vec3 {
        let (u1, u2) = self.next_2d();
        sample_brdf(n, u1, u2)
    }
}

impl VertexSampler for SampleRng {}
