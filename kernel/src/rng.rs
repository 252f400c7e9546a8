//! Counter-based random numbers: a value is a pure function of (seed, pixel, sample, dimension),
//! so any backend, thread or dispatch order reproduces any sample exactly.
//!
//! The hash is [`crate::hash::pcg4d`].
//! `scene::sampler::SOBOL` draws the same dimensions from Owen-scrambled Sobol points instead
//! (`crate::sobol`).

pub use crate::hash::pcg4d;
use crate::scene::sampler;
use crate::sobol::{sobol_pair, sobol_single};
use crate::word::Word;

/// The independent sampler's 32 random bits of dimension `dimension` of sample `sample` of
/// `pixel` under `seed`: the first word of [`pcg4d`] of the four.
#[inline]
pub fn independent_bits<W: Word>(seed: W, pixel: W, sample: W, dimension: W) -> W {
    pcg4d([pixel, sample, dimension, seed])[0]
}

/// Maps 32 random bits to a float uniform in the open interval (0, 1): the top 23 bits k as
/// (k + 1/2) 2^-23, the midpoint of the k-th of 2^23 equal intervals. Every step is exact in f32
/// under any rounding mode (k + 1/2 needs 24 bits; the scale is a power of two), the values run
/// from 2^-24 to 1 - 2^-24 and are symmetric (1 - u is one of them), so no sampler ever sees 0
/// or 1 (a tangent direction, a zero-length flight, the log of 0) and none needs a guard of its
/// own. (24 bits cannot do this: 1 - 2^-25 is not an `f32`.)
#[inline]
pub fn u32_to_unit_f32(x: u32) -> f32 {
    ((x >> 9) as f32 + 0.5) * (1.0 / 8_388_608.0)
}

/// The random stream of one sample of one pixel; each call to [`SampleRng::next_f32`] consumes
/// the next dimension, [`SampleRng::next_2d`] the next two.
#[derive(Clone, Copy, Debug)]
pub struct SampleRng {
    pub seed: u32,
    pub pixel: u32,
    /// The sequence index of the dimensions below [`CONTINUED_FROM`].
    pub sample: u32,
    pub dimension: u32,
    /// One of `scene::sampler`.
    pub sampler: u32,
    /// The sequence index of the dimensions from [`CONTINUED_FROM`] on: `sample`, except in a
    /// continuation of a path split at its first vertex (`crate::split`).
    pub continuation: u32,
}

/// The first dimension a continuation of a split path reads from its own sequence index
/// (`SampleRng::continuation`): the first vertex's roulette number. The dimensions below it
/// (the camera's pair, the first vertex's light choice and point) are the sample's. The
/// layout is `crate::vertex_samples`', which asserts this is its first vertex's roulette
/// dimension (named here by value: `vertex_samples` draws through this module).
pub const CONTINUED_FROM: u32 = 5;

impl SampleRng {
    /// The independent stream of sample `sample` of pixel `pixel` (row-major index) under `seed`.
    #[inline]
    pub fn new(seed: u32, pixel: u32, sample: u32) -> Self {
        Self::with_sampler(seed, pixel, sample, sampler::INDEPENDENT)
    }

    /// The stream of sample `sample` of pixel `pixel` drawn by `sampler` (`scene::sampler`).
    #[inline]
    pub fn with_sampler(seed: u32, pixel: u32, sample: u32, sampler: u32) -> Self {
        Self {
            seed,
            pixel,
            sample,
            dimension: 0,
            sampler,
            continuation: sample,
        }
    }

    /// The sequence index the current dimension is drawn from: `sample` below
    /// [`CONTINUED_FROM`], `continuation` from it on.
    #[inline]
    fn index(&self) -> u32 {
        if self.dimension < CONTINUED_FROM {
            self.sample
        } else {
            self.continuation
        }
    }

    /// 32 random bits for (seed, pixel, sample, dimension) ([`independent_bits`]), then
    /// advances the dimension.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let x = independent_bits(self.seed, self.pixel, self.index(), self.dimension);
        self.dimension = self.dimension.wrapping_add(1);
        x
    }

    /// A float uniform in (0, 1) ([`u32_to_unit_f32`]), then advances the dimension. With the
    /// Sobol sampler it is the first coordinate of the dimension's pair (a stratified 1D
    /// sequence per pixel).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        if self.sampler == sampler::SOBOL {
            let x = sobol_single(self.seed, self.pixel, self.index(), self.dimension);
            self.dimension = self.dimension.wrapping_add(1);
            u32_to_unit_f32(x)
        } else {
            u32_to_unit_f32(self.next_u32())
        }
    }

    /// Two floats uniform in (0, 1) for one 2D decision (a point on a light, a direction),
    /// then advances two dimensions. Independent: two calls of [`SampleRng::next_f32`], the
    /// same numbers. Sobol: one point of the pair's scrambled (0,2)-sequence.
    #[inline]
    pub fn next_2d(&mut self) -> (f32, f32) {
        if self.sampler == sampler::SOBOL {
            let (x, y) = sobol_pair(self.seed, self.pixel, self.index(), self.dimension);
            self.dimension = self.dimension.wrapping_add(2);
            (u32_to_unit_f32(x), u32_to_unit_f32(y))
        } else {
            let u = self.next_f32();
            (u, self.next_f32())
        }
    }
}

impl SampleRng {
    /// Jumps to dimension `dimension`, so each path vertex reads a fixed block of dimensions
    /// whatever branches earlier vertices took.
    #[inline]
    pub fn seek(&mut self, dimension: u32) {
        self.dimension = dimension;
    }
}

/// Where a path reads its random numbers: a stream of dimensions with [`SampleRng`]'s
/// interface. [`SampleRng`] computes each number when asked; the CPU's packets of paths also
/// hand over numbers they computed for sixteen paths at once, which must be exactly the ones
/// [`SampleRng`] would compute.
pub trait SampleStream {
    /// Jumps to dimension `dimension`.
    fn seek(&mut self, dimension: u32);
    /// The number of the current dimension (see [`SampleRng::next_f32`]), then advances one.
    fn next_f32(&mut self) -> f32;
    /// The pair starting at the current dimension (see [`SampleRng::next_2d`]), then advances
    /// two.
    fn next_2d(&mut self) -> (f32, f32);
}

impl SampleStream for SampleRng {
    #[inline]
    fn seek(&mut self, dimension: u32) {
        SampleRng::seek(self, dimension)
    }

    #[inline]
    fn next_f32(&mut self) -> f32 {
        SampleRng::next_f32(self)
    }

    #[inline]
    fn next_2d(&mut self) -> (f32, f32) {
        SampleRng::next_2d(self)
    }
}
