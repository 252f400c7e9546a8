//! 32-bit floats one at a time or many at once: the float arithmetic of the samplers that turn
//! random numbers into points and directions (`sampling`, `frame`, `turns`), so they are written
//! once and run on an `f32` (the GPU and the one-path loop) or on a SIMD vector of `f32` (the
//! CPU's packets, one lane per path). Every operation is IEEE-754 arithmetic on each lane alone
//! (no fused multiply-add, no approximate reciprocal), so a lane's result is exactly the `f32`
//! one, bit for bit. The operations the kernel writes on the bits (`abs`, `select`, and the
//! quadrant of `turns::cos_sin_turns`' polynomials, which live here for that reason) are `Real`
//! methods with those bit operations as defaults, so that a test's interval type, which has no
//! bits, can provide them otherwise.

use crate::word::Word;
use core::f32::consts::FRAC_PI_2;
use core::ops::{Add, Div, Mul, Neg, Sub};
use spirv_std::glam::Vec3;

/// An `f32`, or several side by side, with its bits as a [`Word`] of the same width.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The bits of each lane (comparison masks, sign flips, integer conversions).
    type Bits: Word;
    /// `x` in every lane.
    fn splat(x: f32) -> Self;
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    /// `f32::min` of each lane.
    fn min(self, other: Self) -> Self;
    /// `f32::max` of each lane.
    fn max(self, other: Self) -> Self;
    /// `f32::clamp` of each lane to [`lo`, `hi`] (lo <= hi; NaN stays NaN).
    fn clamp(self, lo: Self, hi: Self) -> Self;
    fn to_bits(self) -> Self::Bits;
    fn from_bits(bits: Self::Bits) -> Self;
    /// All ones where `self > other`, zero elsewhere.
    fn greater_than(self, other: Self) -> Self::Bits;
    /// All ones where `self >= other`, zero elsewhere.
    fn at_least(self, other: Self) -> Self::Bits;
    /// All ones where `self < other`, zero elsewhere.
    fn less_than(self, other: Self) -> Self::Bits;
    /// All ones where `self <= other`, zero elsewhere.
    fn at_most(self, other: Self) -> Self::Bits;
    /// All ones where `self != other` (so also where either is NaN), zero elsewhere.
    fn not_equal(self, other: Self) -> Self::Bits;
    /// All ones where the lane is neither infinite nor NaN, zero elsewhere.
    fn finite(self) -> Self::Bits;
    /// `self as i32` (toward zero, saturating), as the bits of the `i32`.
    fn to_i32_bits(self) -> Self::Bits;
    /// The `i32` whose bits are `bits`, `as f32` (rounded to nearest).
    fn from_i32_bits(bits: Self::Bits) -> Self;

    /// The largest integer not above each lane, for |x| < 2^31: written on the conversions to
    /// and from `i32` (toward zero, then one less where that rounded up), which are exact under
    /// any arithmetic for such values, as Vulkan's `floor` is. `f32` uses its own `floor`.
    #[inline]
    fn floor(self) -> Self {
        let t = Self::from_i32_bits(self.to_i32_bits());
        Self::select(t.greater_than(self), t - Self::splat(1.0), t)
    }

    // Operations written on the bits, which a type that has none (a test's interval type)
    // provides otherwise.

    /// |x| of each lane: the sign bit cleared (exact under any arithmetic).
    #[inline]
    fn abs(self) -> Self {
        Self::from_bits(self.to_bits() & Self::Bits::splat(0x7fff_ffff))
    }

    /// `self` where `self > other`, else `other` (so `other` where either is NaN): glam's
    /// `max_element` comparison, which x86's `maxss` computes in one instruction.
    #[inline]
    fn greater_of(self, other: Self) -> Self {
        Self::select(self.greater_than(other), self, other)
    }

    /// `yes` in the lanes where `mask` is all ones, `no` where it is zero.
    #[inline]
    fn select(mask: Self::Bits, yes: Self, no: Self) -> Self {
        let (yes, no) = (yes.to_bits(), no.to_bits());
        Self::from_bits(no ^ ((yes ^ no) & mask))
    }

    /// (cos, sin) of `self` turns: `crate::turns::cos_sin_turns`' polynomials, whose quadrant
    /// is chosen on the bits.
    #[inline]
    fn cos_sin_turns(self) -> (Self, Self) {
        polynomial_cos_sin_turns(self)
    }
}

/// `crate::turns::cos_sin_turns`' polynomials and quadrant rotation on the bits (its doc
/// comment derives them): [`Real::cos_sin_turns`] of every type with bits.
#[inline]
fn polynomial_cos_sin_turns<R: Real>(u: R) -> (R, R) {
    let c = R::splat;
    let quarters = c(4.0) * u;
    // floor(quarters + 1/2) by conversions (truncation, less one below zero: the mask is -1
    // there): `floor` is a libm call on baseline x86-64.
    let half_up = quarters + c(0.5);
    let truncated = half_up.to_i32_bits();
    let nearest = truncated.wrapping_add(R::from_i32_bits(truncated).greater_than(half_up));
    let q = R::from_i32_bits(nearest);
    let theta = (quarters - q) * c(FRAC_PI_2);
    let z = theta * theta;
    let sin = theta
        + theta
            * z
            * (c(-1.0 / 6.0)
                + z * (c(1.0 / 120.0) + z * (c(-1.0 / 5040.0) + z * c(1.0 / 362_880.0))));
    let cos = c(1.0)
        + z * (c(-0.5)
            + z * (c(1.0 / 24.0)
                + z * (c(-1.0 / 720.0) + z * (c(1.0 / 40_320.0) + z * c(-1.0 / 3_628_800.0)))));
    // Rotate by q quarter turns, (c, s) -> (-s, c) per quarter: odd quadrants swap the two,
    // quadrants 1 and 2 negate the cosine, 2 and 3 the sine. Done on the bits, without a branch,
    // because the quadrant of a random azimuth is unpredictable.
    let bits = R::Bits::splat;
    let quadrant = nearest & bits(3);
    let swap = bits(0).wrapping_sub(quadrant & bits(1));
    let (cos_bits, sin_bits) = (cos.to_bits(), sin.to_bits());
    // Where `swap` is all ones the two exchange: x ^ ((x ^ y) & swap).
    let exchanged = (cos_bits ^ sin_bits) & swap;
    let cos_sign = (quadrant.wrapping_add(bits(1)) & bits(2)) << 30;
    let sin_sign = (quadrant & bits(2)) << 30;
    (
        R::from_bits(cos_bits ^ exchanged ^ cos_sign),
        R::from_bits(sin_bits ^ exchanged ^ sin_sign),
    )
}

/// The exponential function and the natural logarithm, for the media's flights (the unit
/// exponential numbers of `free_flight::unit_exponential`, the transmittances of
/// `medium::transmittance_v3`); apart from [`Real`] because neither the packets nor the tests'
/// interval type need them. On a Vulkan device `exp(x)` errs by up to 3 + 2 |x| ULP and `log`
/// by up to 3 ULP, or by 2^-21 absolutely on [0.5, 2] ("Precision and Operation of SPIR-V
/// Instructions"), which a test's type implements to check the flights against their bounds.
pub trait Exponential: Real {
    fn exp(self) -> Self;
    fn ln(self) -> Self;
}

impl Exponential for f32 {
    #[inline]
    fn exp(self) -> Self {
        #[cfg(target_arch = "spirv")]
        {
            <f32 as crate::Float>::exp(self)
        }
        #[cfg(not(target_arch = "spirv"))]
        {
            f32::exp(self)
        }
    }

    #[inline]
    fn ln(self) -> Self {
        #[cfg(target_arch = "spirv")]
        {
            <f32 as crate::Float>::ln(self)
        }
        #[cfg(not(target_arch = "spirv"))]
        {
            f32::ln(self)
        }
    }
}

/// |x| of each lane ([`Real::abs`]).
#[inline]
pub fn abs<R: Real>(x: R) -> R {
    Real::abs(x)
}

/// `yes` in the lanes where `mask` is all ones, `no` where it is zero ([`Real::select`]).
#[inline]
pub fn select<R: Real>(mask: R::Bits, yes: R, no: R) -> R {
    R::select(mask, yes, no)
}

impl Real for f32 {
    type Bits = u32;

    #[inline]
    fn splat(x: f32) -> Self {
        x
    }

    #[inline]
    fn sqrt(self) -> Self {
        #[cfg(target_arch = "spirv")]
        {
            <f32 as crate::Float>::sqrt(self)
        }
        #[cfg(not(target_arch = "spirv"))]
        {
            f32::sqrt(self)
        }
    }

    #[inline]
    fn floor(self) -> Self {
        #[cfg(target_arch = "spirv")]
        {
            <f32 as crate::Float>::floor(self)
        }
        #[cfg(not(target_arch = "spirv"))]
        {
            f32::floor(self)
        }
    }

    #[inline]
    fn min(self, other: Self) -> Self {
        f32::min(self, other)
    }

    #[inline]
    fn max(self, other: Self) -> Self {
        f32::max(self, other)
    }

    #[inline]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        f32::clamp(self, lo, hi)
    }

    #[inline]
    fn greater_of(self, other: Self) -> Self {
        if self > other {
            self
        } else {
            other
        }
    }

    #[inline]
    fn to_bits(self) -> u32 {
        f32::to_bits(self)
    }

    #[inline]
    fn from_bits(bits: u32) -> Self {
        f32::from_bits(bits)
    }

    #[inline]
    fn greater_than(self, other: Self) -> u32 {
        if self > other {
            u32::MAX
        } else {
            0
        }
    }

    #[inline]
    fn at_least(self, other: Self) -> u32 {
        if self >= other {
            u32::MAX
        } else {
            0
        }
    }

    #[inline]
    fn less_than(self, other: Self) -> u32 {
        if self < other {
            u32::MAX
        } else {
            0
        }
    }

    #[inline]
    fn at_most(self, other: Self) -> u32 {
        if self <= other {
            u32::MAX
        } else {
            0
        }
    }

    #[inline]
    fn not_equal(self, other: Self) -> u32 {
        if self != other {
            u32::MAX
        } else {
            0
        }
    }

    #[inline]
    fn finite(self) -> u32 {
        if self.is_finite() {
            u32::MAX
        } else {
            0
        }
    }

    #[inline]
    fn to_i32_bits(self) -> u32 {
        self as i32 as u32
    }

    #[inline]
    fn from_i32_bits(bits: u32) -> Self {
        bits as i32 as f32
    }
}

/// SIMD lanes (native code only).
#[cfg(not(target_arch = "spirv"))]
impl<const N: usize> Real for core::simd::Simd<f32, N> {
    type Bits = core::simd::Simd<u32, N>;

    #[inline]
    fn splat(x: f32) -> Self {
        Self::splat(x)
    }

    #[inline]
    fn sqrt(self) -> Self {
        std::simd::StdFloat::sqrt(self)
    }

    #[inline]
    fn min(self, other: Self) -> Self {
        core::simd::num::SimdFloat::simd_min(self, other)
    }

    #[inline]
    fn max(self, other: Self) -> Self {
        core::simd::num::SimdFloat::simd_max(self, other)
    }

    #[inline]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        core::simd::num::SimdFloat::simd_clamp(self, lo, hi)
    }

    #[inline]
    fn to_bits(self) -> Self::Bits {
        core::simd::num::SimdFloat::to_bits(self)
    }

    #[inline]
    fn from_bits(bits: Self::Bits) -> Self {
        core::simd::num::SimdFloat::from_bits(bits)
    }

    #[inline]
    fn greater_than(self, other: Self) -> Self::Bits {
        use core::simd::{cmp::SimdPartialOrd, Select};
        self.simd_gt(other)
            .select(Self::Bits::splat(u32::MAX), Self::Bits::splat(0))
    }

    #[inline]
    fn at_least(self, other: Self) -> Self::Bits {
        use core::simd::{cmp::SimdPartialOrd, Select};
        self.simd_ge(other)
            .select(Self::Bits::splat(u32::MAX), Self::Bits::splat(0))
    }

    #[inline]
    fn less_than(self, other: Self) -> Self::Bits {
        use core::simd::{cmp::SimdPartialOrd, Select};
        self.simd_lt(other)
            .select(Self::Bits::splat(u32::MAX), Self::Bits::splat(0))
    }

    #[inline]
    fn at_most(self, other: Self) -> Self::Bits {
        use core::simd::{cmp::SimdPartialOrd, Select};
        self.simd_le(other)
            .select(Self::Bits::splat(u32::MAX), Self::Bits::splat(0))
    }

    #[inline]
    fn not_equal(self, other: Self) -> Self::Bits {
        use core::simd::{cmp::SimdPartialEq, Select};
        self.simd_ne(other)
            .select(Self::Bits::splat(u32::MAX), Self::Bits::splat(0))
    }

    #[inline]
    fn finite(self) -> Self::Bits {
        use core::simd::{num::SimdFloat, Select};
        self.is_finite()
            .select(Self::Bits::splat(u32::MAX), Self::Bits::splat(0))
    }

    #[inline]
    fn to_i32_bits(self) -> Self::Bits {
        use core::simd::num::{SimdFloat, SimdInt};
        self.cast::<i32>().cast()
    }

    #[inline]
    fn from_i32_bits(bits: Self::Bits) -> Self {
        use core::simd::num::{SimdInt, SimdUint};
        bits.cast::<i32>().cast()
    }
}

/// A 3-vector of [`Real`]s: one vector, or one per lane. Its operations are glam's `Vec3` ones,
/// component by component in the same order (`dot` = (x x' + y y') + z z'), so a `V3<f32>`
/// gives exactly the `Vec3` result.
#[derive(Clone, Copy, Debug)]
pub struct V3<R> {
    pub x: R,
    pub y: R,
    pub z: R,
}

impl<R: Real> V3<R> {
    #[inline]
    pub fn new(x: R, y: R, z: R) -> Self {
        Self { x, y, z }
    }

    #[inline]
    pub fn dot(self, rhs: Self) -> R {
        (self.x * rhs.x) + (self.y * rhs.y) + (self.z * rhs.z)
    }

    /// The cross product in glam's order of operations.
    #[inline]
    pub fn cross(self, rhs: Self) -> Self {
        Self::new(
            self.y * rhs.z - rhs.y * self.z,
            self.z * rhs.x - rhs.z * self.x,
            self.x * rhs.y - rhs.x * self.y,
        )
    }

    /// `x` in every lane of every component.
    #[inline]
    pub fn splat(v: Vec3) -> Self {
        Self::new(R::splat(v.x), R::splat(v.y), R::splat(v.z))
    }

    /// |v|, as glam's `Vec3::length` computes it: the root of [`Self::dot`] with itself.
    #[inline]
    pub fn length(self) -> R {
        self.dot(self).sqrt()
    }

    /// v / |v|, as glam's `Vec3::normalize` computes it: times the reciprocal of
    /// [`Self::length`], so that a `V3<f32>` gives glam's result bit for bit.
    #[inline]
    pub fn normalize(self) -> Self {
        self * (R::splat(1.0) / self.length())
    }

    /// v . v, as glam's `Vec3::length_squared`.
    #[inline]
    pub fn length_squared(self) -> R {
        self.dot(self)
    }

    /// The largest component, as glam's `Vec3::max_element` takes it: max(x, max(y, z)) with
    /// max(a, b) = a where a > b, else b ([`Real::greater_of`]).
    #[inline]
    pub fn max_element(self) -> R {
        self.x.greater_of(self.y.greater_of(self.z))
    }

    /// (x + y) + z: the dot product with (1, 1, 1) bit for bit (a product by 1 is exact in
    /// any arithmetic), without its three products.
    #[inline]
    pub fn element_sum(self) -> R {
        (self.x + self.y) + self.z
    }

    /// `yes` in the lanes where `mask` is all ones, `no` where it is zero, component by
    /// component ([`select`]).
    #[inline]
    pub fn select(mask: R::Bits, yes: Self, no: Self) -> Self {
        Self::new(
            select(mask, yes.x, no.x),
            select(mask, yes.y, no.y),
            select(mask, yes.z, no.z),
        )
    }
}

impl<R: Real> Add for V3<R> {
    type Output = Self;
    #[inline]
    fn add(self, rhs: Self) -> Self {
        Self::new(self.x + rhs.x, self.y + rhs.y, self.z + rhs.z)
    }
}

impl<R: Real> Sub for V3<R> {
    type Output = Self;
    #[inline]
    fn sub(self, rhs: Self) -> Self {
        Self::new(self.x - rhs.x, self.y - rhs.y, self.z - rhs.z)
    }
}

impl<R: Real> Neg for V3<R> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}

/// Each component times `rhs`.
impl<R: Real> Mul<R> for V3<R> {
    type Output = Self;
    #[inline]
    fn mul(self, rhs: R) -> Self {
        Self::new(self.x * rhs, self.y * rhs, self.z * rhs)
    }
}

/// Component by component, as glam's `Vec3 * Vec3`.
impl<R: Real> Mul for V3<R> {
    type Output = Self;
    #[inline]
    fn mul(self, rhs: Self) -> Self {
        Self::new(self.x * rhs.x, self.y * rhs.y, self.z * rhs.z)
    }
}

/// Each component divided by `rhs`.
impl<R: Real> Div<R> for V3<R> {
    type Output = Self;
    #[inline]
    fn div(self, rhs: R) -> Self {
        Self::new(self.x / rhs, self.y / rhs, self.z / rhs)
    }
}

impl From<Vec3> for V3<f32> {
    #[inline]
    fn from(v: Vec3) -> Self {
        Self::new(v.x, v.y, v.z)
    }
}

impl From<V3<f32>> for Vec3 {
    #[inline]
    fn from(v: V3<f32>) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}
