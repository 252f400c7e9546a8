//! Exact, order-free sums of samples: fixed-point integers.
//!
//! Floating-point addition is not associative, so a pixel's f64 sum depends on how its samples
//! were grouped (passes, tiles, machines). Integer addition is associative and commutative, so
//! a pixel whose samples are first rounded to a fixed-point grid has one sum whatever the
//! grouping: the render of samples 0..n in one process and the merge of any split of 0..n into
//! parts give the same sum, bit for bit (docs/parts.md).
//!
//! The grid: a sample `v` (an f32 radiance) becomes `round(v * 2^SUM_FRACTION_BITS)`, ties to
//! even, in an `i128`. Samples the kernel's `film_sample::summable` refuses (non-finite, or a
//! channel of magnitude `MAX_SAMPLE` = 2^40 or more) are counted, not summed, so 2^32 samples
//! can never overflow: `2^32 * 2^40 * 2^55 = 2^127`. One sample's rounding error is at most
//! 2^-56 (about 1.4e-17) absolute, below an f32's rounding of any pixel value above 2.3e-10.

/// Fraction bits of a sample sum.
pub const SUM_FRACTION_BITS: i32 = 55;

/// 2^SUM_FRACTION_BITS.
const SCALE: f64 = (1u64 << SUM_FRACTION_BITS) as f64;

/// A sum of samples in units of 2^-[`SUM_FRACTION_BITS`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FixedSum(pub i128);

impl FixedSum {
    /// Adds sample `v` (`|v| < MAX_SAMPLE`), rounded to the grid (ties to even).
    #[inline(always)]
    pub fn add_sample(&mut self, v: f32) {
        // `v * 2^55` is exact in f64. For 2^-32 <= |v| < 2^7 (and 0) it is an integer below
        // 2^62 and converts exactly with one instruction; the rest take the bitwise route.
        let x = v as f64 * SCALE;
        if x.abs() < (1u64 << 62) as f64 {
            // SAFETY: x is finite and |x| < 2^62, inside i64's range.
            let i = unsafe { x.to_int_unchecked::<i64>() };
            if i as f64 == x {
                self.0 += i as i128;
                return;
            }
        }
        self.0 += Self::rounded(v);
    }

    /// `v * 2^55` rounded to an integer, ties to even, by integer operations on the f32's
    /// bits: `v = m 2^e` with `m < 2^24` and `e <= 16`, so `m 2^(e + 55) < 2^95`.
    #[cold]
    fn rounded(v: f32) -> i128 {
        let bits = v.to_bits();
        let exponent = ((bits >> 23) & 0xff) as i32;
        let fraction = (bits & 0x7f_ffff) as u64;
        let (m, e) = if exponent == 0 {
            (fraction, -149)
        } else {
            (fraction | 0x80_0000, exponent - 150)
        };
        let shift = e + SUM_FRACTION_BITS;
        let magnitude = if shift >= 0 {
            (m as u128) << shift
        } else {
            let k = (-shift) as u32;
            if k > 25 {
                0 // m 2^-k < 2^24 2^-26: below 1/2
            } else {
                let q = m >> k;
                let r = m & ((1u64 << k) - 1);
                let half = 1u64 << (k - 1);
                (q + (r > half || (r == half && q & 1 == 1)) as u64) as u128
            }
        };
        if bits >> 31 != 0 {
            -(magnitude as i128)
        } else {
            magnitude as i128
        }
    }

    /// The sum `x` (finite, within the range of 2^32 samples) rounded to the grid: a sum
    /// from elsewhere, such as the GPU's running mean times its count.
    pub fn from_f64(x: f64) -> Self {
        Self((x * SCALE).round_ties_even() as i128)
    }

    #[inline]
    pub fn add(&mut self, other: FixedSum) {
        self.0 += other.0;
    }

    /// The sum as an f64 (correctly rounded).
    pub fn to_f64(self) -> f64 {
        self.0 as f64 / SCALE
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use kernel::film_sample::{summable, MAX_SAMPLE};

    /// Both routes of `add_sample` round exactly as `from_f64` does in f64, on random f32 bit
    /// patterns of every exponent (subnormals included), and ties go to even.
    #[test]
    fn samples_round_to_the_grid() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        };
        let mut tested = 0;
        while tested < 1_000_000 {
            let v = f32::from_bits(next() as u32);
            if !(v.abs() < MAX_SAMPLE) {
                continue;
            }
            tested += 1;
            let mut sum = FixedSum::default();
            sum.add_sample(v);
            assert_eq!(sum, FixedSum::from_f64(v as f64), "{v:e}");
            assert_eq!(FixedSum::rounded(v), sum.0, "{v:e}");
        }
        let half = (-(SUM_FRACTION_BITS + 1) as f32).exp2();
        for (v, want) in [
            (half, 0),
            (3.0 * half, 2),
            (5.0 * half, 2),
            (-3.0 * half, -2),
        ] {
            let mut sum = FixedSum::default();
            sum.add_sample(v);
            assert_eq!(sum.0, want, "{v:e}");
        }
    }

    #[test]
    fn the_largest_sums_do_not_overflow() {
        let v = f32::from_bits(MAX_SAMPLE.to_bits() - 1);
        assert!(summable(Vec3::splat(v)));
        assert!(!summable(Vec3::new(0.0, -MAX_SAMPLE, 0.0)));
        assert!(!summable(Vec3::new(f32::NAN, 0.0, 0.0)));
        let mut one = FixedSum::default();
        one.add_sample(-v);
        assert!(one.0.checked_mul(1 << 32).is_some());
        assert_eq!(one.to_f64(), -(v as f64));
    }
}
