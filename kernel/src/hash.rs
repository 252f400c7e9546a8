//! The integer hash both samplers build on (`rng`'s independent numbers, `sobol`'s shuffles
//! and scrambles): `pcg4d` from Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT
//! 9(3), 2020, a 4D-to-4D permutation with good avalanche that costs a few integer
//! multiply-adds. Its own module so that `rng` and `sobol` both import it and not each other.

use crate::word::Word;

/// Jarzynski and Olano's pcg4d: bijective mixing of four 32-bit words (each [`Word`] lane
/// alone).
#[inline]
pub fn pcg4d<W: Word>(mut v: [W; 4]) -> [W; 4] {
    let (a, c) = (W::splat(1664525), W::splat(1013904223));
    v[0] = v[0].wrapping_mul(a).wrapping_add(c);
    v[1] = v[1].wrapping_mul(a).wrapping_add(c);
    v[2] = v[2].wrapping_mul(a).wrapping_add(c);
    v[3] = v[3].wrapping_mul(a).wrapping_add(c);
    v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[3]));
    v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
    v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
    v[3] = v[3].wrapping_add(v[1].wrapping_mul(v[2]));
    v[0] = v[0] ^ (v[0] >> 16);
    v[1] = v[1] ^ (v[1] >> 16);
    v[2] = v[2] ^ (v[2] >> 16);
    v[3] = v[3] ^ (v[3] >> 16);
    v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[3]));
    v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
    v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
    v[3] = v[3].wrapping_add(v[1].wrapping_mul(v[2]));
    v
}
