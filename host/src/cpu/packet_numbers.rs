//! The random numbers of sixteen paths at once: the kernel's sampler (`kernel::rng`,
//! `kernel::sobol`, written over `kernel::word::Word`) run on SIMD lanes, one path per lane,
//! for the dimensions each path reads next. A path then takes them from its
//! [`PrefetchedStream`] instead of computing them one at a time (which cost 18% of a Cornell
//! render). Each lane computes exactly what `SampleRng` computes, so images do not change.

use super::packet::LANES;
use super::packet_vertices::{PresampledBrdf, PresampledLight};
use super::simd::widest_simd;
use kernel::path::{
    PathState, BRDF_DIMENSION, CAMERA_DIMENSIONS, DIMENSIONS_PER_VERTEX, LIGHT_CHOICE_DIMENSION,
    LIGHT_POINT_DIMENSION, ROULETTE_DIMENSION,
};
use kernel::rng::{independent_bits, u32_to_unit_f32, SampleRng, SampleStream};
use kernel::scene::sampler;
use kernel::sobol::{sobol_pair, sobol_single};
use std::simd::{Mask, Select, Simd};

type Words = Simd<u32, LANES>;
/// Computed numbers by lane: two pairs (x, y) and two single numbers.
type Numbers = ([[[u32; LANES]; 2]; 2], [[u32; LANES]; 2]);

/// No dimension: an empty entry.
pub const EMPTY: u32 = u32::MAX;

/// Numbers computed ahead for one dimension (`bits[1]` unused for a single number).
#[derive(Clone, Copy, Debug)]
struct Entry {
    dimension: u32,
    bits: [u32; 2],
}

impl Entry {
    const NONE: Entry = Entry {
        dimension: EMPTY,
        bits: [0; 2],
    };
}

/// A sample's [`SampleRng`] with the numbers of its next dimensions computed ahead: two pairs
/// and two single numbers (a vertex's light point, BRDF direction, light choice and roulette
/// number, or the camera's pair). A read of any other dimension computes it as [`SampleRng`]
/// does.
#[derive(Clone, Copy, Debug)]
pub struct PrefetchedStream {
    pub rng: SampleRng,
    pairs: [Entry; 2],
    singles: [Entry; 2],
    /// The next vertex's light sample and BRDF direction computed ahead
    /// (`super::packet_vertices`), or none (their dimension [`EMPTY`]).
    pub(super) light: PresampledLight,
    pub(super) brdf: PresampledBrdf,
}

impl PrefetchedStream {
    /// `rng` with nothing computed ahead.
    pub fn new(rng: SampleRng) -> Self {
        Self {
            rng,
            pairs: [Entry::NONE; 2],
            singles: [Entry::NONE; 2],
            light: PresampledLight::NONE,
            brdf: PresampledBrdf::NONE,
        }
    }

    /// Whether the pair (`pair`) or single number starting at `dimension` is computed ahead.
    pub fn holds(&self, dimension: u32, pair: bool) -> bool {
        let entries = if pair { &self.pairs } else { &self.singles };
        entries.iter().any(|e| e.dimension == dimension)
    }

    /// Pair `p` computed ahead: its first dimension ([`EMPTY`] for none) and the numbers
    /// `next_2d` returns there.
    pub fn pair(&self, p: usize) -> (u32, (f32, f32)) {
        let e = &self.pairs[p];
        let numbers = (u32_to_unit_f32(e.bits[0]), u32_to_unit_f32(e.bits[1]));
        (e.dimension, numbers)
    }

    /// Single number `p` computed ahead: its dimension ([`EMPTY`] for none) and the number
    /// `next_f32` returns there.
    pub fn single(&self, p: usize) -> (u32, f32) {
        let e = &self.singles[p];
        (e.dimension, u32_to_unit_f32(e.bits[0]))
    }
}

impl SampleStream for PrefetchedStream {
    #[inline]
    fn seek(&mut self, dimension: u32) {
        self.rng.seek(dimension);
    }

    #[inline]
    fn next_f32(&mut self) -> f32 {
        for entry in &self.singles {
            if entry.dimension == self.rng.dimension {
                self.rng.dimension += 1;
                return u32_to_unit_f32(entry.bits[0]);
            }
        }
        self.rng.next_f32()
    }

    #[inline]
    fn next_2d(&mut self) -> (f32, f32) {
        for entry in &self.pairs {
            if entry.dimension == self.rng.dimension {
                self.rng.dimension += 2;
                return (
                    u32_to_unit_f32(entry.bits[0]),
                    u32_to_unit_f32(entry.bits[1]),
                );
            }
        }
        self.rng.next_2d()
    }
}

/// What the lanes compute ahead: each lane's stream (seed, pixel, sequence index, whether it is
/// Sobol's), the first dimensions of two pairs and the dimensions of two single numbers
/// ([`EMPTY`] where a lane wants none).
struct Requests {
    seed: [u32; LANES],
    pixel: [u32; LANES],
    sample: [u32; LANES],
    sobol: [bool; LANES],
    pairs: [[u32; LANES]; 2],
    singles: [[u32; LANES]; 2],
}

impl Requests {
    fn new() -> Self {
        Self {
            seed: [0; LANES],
            pixel: [0; LANES],
            sample: [0; LANES],
            sobol: [false; LANES],
            pairs: [[EMPTY; LANES]; 2],
            singles: [[EMPTY; LANES]; 2],
        }
    }

    fn set(&mut self, lane: usize, rng: &SampleRng, pairs: [u32; 2], singles: [u32; 2]) {
        self.seed[lane] = rng.seed;
        self.pixel[lane] = rng.pixel;
        self.sample[lane] = rng.sample;
        self.sobol[lane] = rng.sampler == sampler::SOBOL;
        for p in 0..2 {
            self.pairs[p][lane] = pairs[p];
            self.singles[p][lane] = singles[p];
        }
    }

    widest_simd! {
        /// The requested numbers of every lane, computed together: pairs[p] = (x, y), singles[p].
        /// (Baseline x86-64 has no lane-wise 32-bit multiply; AVX2 and AVX-512F do.)
        fn compute(&self) -> Numbers = compute_any_cpu, compute_avx512, compute_avx2
    }

    #[inline(always)]
    fn compute_any_cpu(&self) -> Numbers {
        let (seed, pixel, sample) = (
            Words::from_array(self.seed),
            Words::from_array(self.pixel),
            Words::from_array(self.sample),
        );
        let sobol = Mask::<i32, LANES>::from_array(self.sobol);
        let (any_sobol, any_independent) = (sobol.any(), !sobol.all());
        let wanted = |d: &[u32; LANES]| d.iter().any(|&d| d != EMPTY);
        let mut pairs = [[[0; LANES]; 2]; 2];
        for (out, dims) in pairs.iter_mut().zip(&self.pairs) {
            if !wanted(dims) {
                continue;
            }
            let d = Words::from_array(*dims);
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

/// Lane `lane`'s entries of computed numbers.
fn entries(
    requests: &Requests,
    (pairs, singles): &Numbers,
    lane: usize,
) -> ([Entry; 2], [Entry; 2]) {
    let pair = |p: usize| Entry {
        dimension: requests.pairs[p][lane],
        bits: [pairs[p][0][lane], pairs[p][1][lane]],
    };
    let single = |p: usize| Entry {
        dimension: requests.singles[p][lane],
        bits: [singles[p][lane], 0],
    };
    ([pair(0), pair(1)], [single(0), single(1)])
}

/// New samples' streams (`rngs`, by lane) with their camera pair (dimension 0) computed
/// together.
pub fn camera_streams(rngs: &[Option<SampleRng>; LANES]) -> [Option<PrefetchedStream>; LANES] {
    let mut requests = Requests::new();
    for (lane, rng) in rngs.iter().enumerate() {
        if let Some(rng) = rng {
            requests.set(lane, rng, [0, EMPTY], [EMPTY; 2]);
        }
    }
    let numbers = requests.compute();
    std::array::from_fn(|lane| {
        rngs[lane].map(|rng| {
            let (pairs, singles) = entries(&requests, &numbers, lane);
            PrefetchedStream {
                pairs,
                singles,
                ..PrefetchedStream::new(rng)
            }
        })
    })
}

/// Where [`prefetch_vertices`] puts a vertex's numbers: the pairs of the light point and of the
/// BRDF direction, the roulette number and the light choice.
pub const LIGHT_POINT_PAIR: usize = 0;
pub const BRDF_PAIR: usize = 1;
pub const ROULETTE_SINGLE: usize = 0;
pub const LIGHT_CHOICE_SINGLE: usize = 1;

/// For each path of `slots` whose extension ray has been traced (it may reach its next vertex),
/// computes that vertex's numbers: pairs [`LIGHT_POINT_PAIR`] and [`BRDF_PAIR`], single numbers
/// [`ROULETTE_SINGLE`] and, if `choose_light` (several lights), [`LIGHT_CHOICE_SINGLE`].
pub fn prefetch_vertices<T>(
    slots: &mut [Option<(T, PathState<PrefetchedStream>)>; LANES],
    choose_light: bool,
) {
    let mut requests = Requests::new();
    for (lane, slot) in slots.iter().enumerate() {
        let Some((_, path)) = slot else { continue };
        if !path.extend {
            continue;
        }
        let block = CAMERA_DIMENSIONS + path.depth * DIMENSIONS_PER_VERTEX;
        let choice = if choose_light {
            block + LIGHT_CHOICE_DIMENSION
        } else {
            EMPTY
        };
        requests.set(
            lane,
            &path.rng.rng,
            // In the order of LIGHT_POINT_PAIR, BRDF_PAIR; ROULETTE_SINGLE, LIGHT_CHOICE_SINGLE.
            [block + LIGHT_POINT_DIMENSION, block + BRDF_DIMENSION],
            [block + ROULETTE_DIMENSION, choice],
        );
    }
    let numbers = requests.compute();
    for (lane, slot) in slots.iter_mut().enumerate() {
        let Some((_, path)) = slot else { continue };
        if path.extend {
            (path.rng.pairs, path.rng.singles) = entries(&requests, &numbers, lane);
        }
    }
}
