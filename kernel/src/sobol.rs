//! Owen-scrambled Sobol points, "padded" two dimensions at a time: Burley, "Practical Hash-based
//! Owen Scrambling", JCGT 9(4), 2020, with the Laine-Karras style hash improved by Vegdahl
//! ("Building a Better LK Hash", psychopath.io, 2021).
//!
//! Each pair of dimensions of a pixel gets the first two dimensions of the Sobol sequence (a
//! (0,2)-sequence in base 2), with its own random shuffle of the sample index and its own
//! nested uniform (Owen) scramble of each coordinate, both derived from (seed, pixel,
//! dimension) by a hash. So within a pixel the first 2^k samples of every pair form a
//! (0,k,2)-net (one point in each elementary box of area 2^-k), which is what lowers the
//! variance; across pixels and pairs the scrambles are independent, and each point on its own
//! is uniform in [0,1)^2, so every estimator stays unbiased.

use crate::hash::pcg4d;
use crate::word::Word;

/// Reverses the bit order of `x` (written out, so both backends and every lane run the same
/// integer steps; LLVM turns the first two into a byte swap).
#[inline]
pub fn reverse_bits<W: Word>(x: W) -> W {
    let m = W::splat;
    let x = ((x & m(0x0000_ffff)) << 16) | (x >> 16);
    let x = ((x & m(0x00ff_00ff)) << 8) | ((x >> 8) & m(0x00ff_00ff));
    let x = ((x & m(0x0f0f_0f0f)) << 4) | ((x >> 4) & m(0x0f0f_0f0f));
    let x = ((x & m(0x3333_3333)) << 2) | ((x >> 2) & m(0x3333_3333));
    ((x & m(0x5555_5555)) << 1) | ((x >> 1) & m(0x5555_5555))
}

/// A seeded bijection of u32 in which each output bit depends only on the same and lower input
/// bits (xor with an even multiple, addition and odd multiplication only carry upward): Vegdahl's
/// improved Laine-Karras hash.
#[inline]
pub fn laine_karras<W: Word>(x: W, seed: W) -> W {
    let x = x ^ x.wrapping_mul(W::splat(0x3d20_adea));
    let x = x.wrapping_add(seed);
    let x = x.wrapping_mul((seed >> 16) | W::splat(1));
    let x = x ^ x.wrapping_mul(W::splat(0x0552_6c56));
    x ^ x.wrapping_mul(W::splat(0x53a2_2864))
}

/// Nested uniform (Owen) scramble of the binary fraction `x`: each digit is flipped by a random
/// function of the digits before it (more significant), i.e. [`laine_karras`] on reversed bits.
/// Maps every aligned interval of length 2^-k onto an aligned interval of the same length.
#[inline]
pub fn owen_scramble<W: Word>(x: W, seed: W) -> W {
    reverse_bits(laine_karras(reverse_bits(x), seed))
}

/// Sobol's second dimension with its digits reversed (bit i = the fraction's digit 2^-(i+1)).
/// Its generator matrix is Pascal's triangle mod 2: digit i is the xor of the index bits j with
/// C(j, i) odd, i.e. (Lucas) with i a bit-subset of j. That matrix is the Kronecker product of
/// [[1, 1], [0, 1]] over the five bits of i and j, so five butterfly steps apply it.
#[inline]
pub fn sobol_second_dimension_reversed<W: Word>(index: W) -> W {
    let m = W::splat;
    let index = index ^ ((index >> 1) & m(0x5555_5555));
    let index = index ^ ((index >> 2) & m(0x3333_3333));
    let index = index ^ ((index >> 4) & m(0x0f0f_0f0f));
    let index = index ^ ((index >> 8) & m(0x00ff_00ff));
    index ^ ((index >> 16) & m(0x0000_ffff))
}

/// Tag mixed into the hash so the scrambles are independent of the independent sampler's numbers.
const SOBOL_STREAM: u32 = 0x50b0_1d1e;

/// The scramble seeds of a pair of dimensions, and its shuffled sample index: an Owen scramble
/// of the index's reversed digits maps each aligned block of 2^k indices (in particular the
/// first one) onto an aligned block, so every power-of-two prefix stays a net.
#[inline]
fn shuffled<W: Word>(seed: W, pixel: W, sample: W, dimension: W) -> ([W; 4], W) {
    let h = pcg4d([pixel, dimension, seed, W::splat(SOBOL_STREAM)]);
    (h, owen_scramble(sample, h[0]))
}

/// The `sample`-th point of the scrambled pair of dimensions (`dimension`, `dimension` + 1) of
/// `pixel` under `seed`, as two 32-bit binary fractions. Sobol's first dimension is the van der
/// Corput sequence reverse_bits(index); Owen-scrambling a reversed sequence,
/// reverse_bits(laine_karras(reverse_bits(reverse_bits(.)))), needs one reversal only.
#[inline]
pub fn sobol_pair<W: Word>(seed: W, pixel: W, sample: W, dimension: W) -> (W, W) {
    let (h, index) = shuffled(seed, pixel, sample, dimension);
    let x = reverse_bits(laine_karras(index, h[1]));
    let y = reverse_bits(laine_karras(sobol_second_dimension_reversed(index), h[2]));
    (x, y)
}

/// The first coordinate of [`sobol_pair`] alone (a scrambled 1D (0,1)-sequence).
#[inline]
pub fn sobol_single<W: Word>(seed: W, pixel: W, sample: W, dimension: W) -> W {
    let (h, index) = shuffled(seed, pixel, sample, dimension);
    reverse_bits(laine_karras(index, h[1]))
}
