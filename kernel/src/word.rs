//! 32-bit words one at a time or many at once: the integer operations of the sampler's hashes
//! (`hash::pcg4d`, `sobol`) and of [`crate::real`]'s bit tricks, so they are written once and run
//! on a `u32` (the GPU, one path at a time) or on a SIMD vector of `u32` (the CPU's packets of
//! paths, one lane per path). Every operation acts on each lane alone, so a lane's result is
//! exactly the `u32` one.

use core::ops::{BitAnd, BitOr, BitXor, Shl, Shr};

/// A `u32`, or several side by side: bitwise operations, shifts by a constant, and addition
/// and multiplication modulo 2^32.
pub trait Word:
    Copy
    + BitXor<Output = Self>
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + Shl<u32, Output = Self>
    + Shr<u32, Output = Self>
{
    /// `x` in every lane.
    fn splat(x: u32) -> Self;
    /// Addition modulo 2^32.
    fn wrapping_add(self, rhs: Self) -> Self;
    /// Subtraction modulo 2^32.
    fn wrapping_sub(self, rhs: Self) -> Self;
    /// Multiplication modulo 2^32.
    fn wrapping_mul(self, rhs: Self) -> Self;
}

impl Word for u32 {
    #[inline]
    fn splat(x: u32) -> Self {
        x
    }

    #[inline]
    fn wrapping_add(self, rhs: Self) -> Self {
        u32::wrapping_add(self, rhs)
    }

    #[inline]
    fn wrapping_sub(self, rhs: Self) -> Self {
        u32::wrapping_sub(self, rhs)
    }

    #[inline]
    fn wrapping_mul(self, rhs: Self) -> Self {
        u32::wrapping_mul(self, rhs)
    }
}

/// SIMD lanes (native code only): `core::simd`'s integer arithmetic wraps, and its shifts by a
/// scalar shift every lane.
#[cfg(not(target_arch = "spirv"))]
impl<const N: usize> Word for core::simd::Simd<u32, N> {
    #[inline]
    fn splat(x: u32) -> Self {
        Self::splat(x)
    }

    #[inline]
    fn wrapping_add(self, rhs: Self) -> Self {
        self + rhs
    }

    #[inline]
    fn wrapping_sub(self, rhs: Self) -> Self {
        self - rhs
    }

    #[inline]
    fn wrapping_mul(self, rhs: Self) -> Self {
        self * rhs
    }
}
