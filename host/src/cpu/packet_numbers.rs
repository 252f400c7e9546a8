//! The random numbers of sixteen sample streams at once: the kernel's samplers (`kernel::rng`,
//! `kernel::sobol`, written over `kernel::word::Word`) run on SIMD lanes, one stream per lane,
//! at the dimensions each lane asks for. Each lane computes exactly what `SampleRng` gives at
//! that dimension (one at a time they were a large share of a render: docs/performance.md).

use super::packet::LANES;
use super::simd::widest_simd;
use kernel::rng::{independent_bits, u32_to_unit_f32, SampleRng, CONTINUED_FROM};
use kernel::scene::sampler;
use kernel::sobol::{sobol_pair, sobol_single};
use kernel::vertex_samples::CAMERA_DIMENSION;
use std::simd::cmp::{SimdPartialEq, SimdPartialOrd};
use std::simd::{Mask, Select, Simd};

type Words = Simd<u32, LANES>;

/// No dimension: a lane that asks for nothing there.
pub const EMPTY: u32 = kernel::vertex_samples::NO_DIMENSION;

/// The numbers by lane: two pairs (`pairs[p]` = the columns of x and y) and two single
/// numbers, as `SampleRng::next_2d` and `next_f32` return them. Lanes that asked for nothing
/// hold numbers nobody reads.
pub struct Numbers {
    pub pairs: [[[f32; LANES]; 2]; 2],
    pub singles: [[f32; LANES]; 2],
}

/// What the lanes ask for: each lane's stream (seed, pixel, sequence index, whether it is
/// Sobol's), the first dimensions of two pairs and the dimensions of two single numbers
/// ([`EMPTY`] where a lane wants none).
pub struct NumberRequests {
    seed: [u32; LANES],
    pixel: [u32; LANES],
    sample: [u32; LANES],
    continuation: [u32; LANES],
    sobol: [bool; LANES],
    pairs: [[u32; LANES]; 2],
    singles: [[u32; LANES]; 2],
}

impl Default for NumberRequests {
    fn default() -> Self {
        Self {
            seed: [0; LANES],
            pixel: [0; LANES],
            sample: [0; LANES],
            continuation: [0; LANES],
            sobol: [false; LANES],
            pairs: [[EMPTY; LANES]; 2],
            singles: [[EMPTY; LANES]; 2],
        }
    }
}

impl NumberRequests {
    /// Lane `lane` asks stream `rng` for the pairs starting at `pairs` and the numbers at
    /// `singles` (each [`EMPTY`] or a dimension).
    pub fn set(&mut self, lane: usize, rng: &SampleRng, pairs: [u32; 2], singles: [u32; 2]) {
        self.seed[lane] = rng.seed;
        self.pixel[lane] = rng.pixel;
        self.sample[lane] = rng.sample;
        self.continuation[lane] = rng.continuation;
        self.sobol[lane] = rng.sampler == sampler::SOBOL;
        for p in 0..2 {
            self.pairs[p][lane] = pairs[p];
            self.singles[p][lane] = singles[p];
        }
    }

    /// The numbers every lane asked for, computed together.
    pub fn compute(&self) -> Numbers {
        let (pairs, singles) = self.compute_bits();
        let unit = |column: &[u32; LANES]| column.map(u32_to_unit_f32);
        Numbers {
            pairs: pairs.map(|[x, y]| [unit(&x), unit(&y)]),
            singles: singles.map(|s| unit(&s)),
        }
    }

    widest_simd! {
        /// The requested numbers' bits: pairs[p] = (x, y), singles[p]. (Baseline x86-64 has no
        /// lane-wise 32-bit multiply; AVX2 and AVX-512F do.)
        fn compute_bits(&self) -> ([[[u32; LANES]; 2]; 2], [[u32; LANES]; 2])
            = compute_any_cpu, compute_avx512, compute_avx2
    }

    #[inline(always)]
    fn compute_any_cpu(&self) -> ([[[u32; LANES]; 2]; 2], [[u32; LANES]; 2]) {
        let (seed, pixel) = (Words::from_array(self.seed), Words::from_array(self.pixel));
        let (sample, continuation) = (
            Words::from_array(self.sample),
            Words::from_array(self.continuation),
        );
        // Each lane's sequence index for dimension d (`SampleRng::index`); the sample's
        // where no lane is a continuation of a split path.
        let continued = sample.simd_ne(continuation).any();
        let index = |d: Words| {
            if continued {
                d.simd_lt(Words::splat(CONTINUED_FROM))
                    .select(sample, continuation)
            } else {
                sample
            }
        };
        let sobol = Mask::<i32, LANES>::from_array(self.sobol);
        let (any_sobol, any_independent) = (sobol.any(), !sobol.all());
        let wanted = |d: &[u32; LANES]| d.iter().any(|&d| d != EMPTY);
        let mut pairs = [[[0; LANES]; 2]; 2];
        for (out, dims) in pairs.iter_mut().zip(&self.pairs) {
            if !wanted(dims) {
                continue;
            }
            let d = Words::from_array(*dims);
            let sample = index(d);
            let (mut x, mut y) = (Words::splat(0), Words::splat(0));
            if any_sobol {
                (x, y) = sobol_pair(seed, pixel, sample, d);
            }
            if any_independent {
                // SampleRng::next_2d: two independent numbers, dimensions d and d + 1.
                let ix = independent_bits(seed, pixel, sample, d);
                let iy = independent_bits(seed, pixel, sample, d + Words::splat(1));
                (x, y) = (sobol.select(x, ix), sobol.select(y, iy));
            }
            *out = [x.to_array(), y.to_array()];
        }
        let mut singles = [[0; LANES]; 2];
        for (out, dims) in singles.iter_mut().zip(&self.singles) {
            if !wanted(dims) {
                continue;
            }
            let d = Words::from_array(*dims);
            let sample = index(d);
            let mut x = Words::splat(0);
            if any_sobol {
                x = sobol_single(seed, pixel, sample, d);
            }
            if any_independent {
                x = sobol.select(x, independent_bits(seed, pixel, sample, d));
            }
            *out = x.to_array();
        }
        (pairs, singles)
    }
}

/// The camera's pair of numbers (the position inside the pixel) of up to sixteen new samples'
/// streams, by lane, computed together.
pub fn camera_numbers(rngs: &[Option<SampleRng>; LANES]) -> [(f32, f32); LANES] {
    let mut requests = NumberRequests::default();
    for (lane, rng) in rngs.iter().enumerate() {
        if let Some(rng) = rng {
            requests.set(lane, rng, [CAMERA_DIMENSION, EMPTY], [EMPTY; 2]);
        }
    }
    let numbers = requests.compute();
    std::array::from_fn(|lane| (numbers.pairs[0][0][lane], numbers.pairs[0][1][lane]))
}
