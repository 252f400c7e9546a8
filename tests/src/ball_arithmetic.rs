//! [`Ball`]: a number known only to lie within `radius` of `mid`, for bounding how far one
//! computation of a kernel function (everything written over `kernel::real::Real`) may be from
//! the exact value, in an arithmetic described by its [`Roundoff`]: IEEE-754 single precision
//! (the CPU, lavapipe) or what the Vulkan specification allows any device (quotients within
//! 2.5 ULP, square roots as 1 / inversesqrt, rounding toward zero, denormals flushed, multiplies
//! fused into adds).
//!
//! It is running error analysis (Wilkinson; Higham, "Accuracy and Stability of Numerical
//! Algorithms", 2nd ed., 3.3) done as midpoint-radius interval arithmetic (Rump, "Fast and
//! parallel interval arithmetic", BIT 39, 1999): each operation's ball holds every result of
//! that operation applied to any numbers of its operands' balls and rounded as the arithmetic
//! allows, so the ball of a function's output holds what any computation in that arithmetic
//! returns. The bounds are not first-order: a product carries the product of the radii, a
//! quotient spans the quotients of its operands' ends (a ball holding 0 divides to an
//! unbounded one), a square root of a ball reaching 0 is bounded by the root of
//! the radius. Midpoints are computed in `f64` from the `f32` inputs (exact there: the balls
//! start with radius 0) and carry their own `f64` rounding in the radius.
//!
//! A comparison whose operands' balls overlap may come out either way in a computation, and a
//! conversion to an integer of a ball that spans integers may give any of them, so a function
//! with a branch or a conversion is bounded along each way it may go ([`computations`]
//! explores them);
//! a fused multiply-add rounds once where the ball rounds twice, which the ball holds.

use kernel::real::{Real, V3};
use std::cell::{Cell, RefCell};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The relative errors of one arithmetic's operations and whether it may flush denormals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roundoff {
    /// Sums, differences and products (and the rounding of a fused multiply-add).
    pub unit: f64,
    /// Quotients.
    pub quotient: f64,
    /// Square roots.
    pub root: f64,
    /// Whether a denormal operand or result may read as 0.
    pub flush: bool,
}

impl Roundoff {
    /// IEEE-754 single precision, round to nearest even: eps / 2 each, denormals kept.
    pub const IEEE: Roundoff = Roundoff {
        unit: 0.5 * EPS,
        quotient: 0.5 * EPS,
        root: 0.5 * EPS,
        flush: false,
    };
    /// Vulkan's precision rules without float controls: rounding toward zero (eps), quotients
    /// within 2.5 ULP (2.5 eps), square roots as 1 / inversesqrt (2 ULP, then a quotient's
    /// 2.5 ULP: 4.5 eps), denormals flushed.
    pub const VULKAN: Roundoff = Roundoff {
        unit: EPS,
        quotient: 2.5 * EPS,
        root: 4.5 * EPS,
        flush: true,
    };
}

const EPS: f64 = f32::EPSILON as f64;

thread_local! {
    static ROUNDOFF: Cell<Roundoff> = const { Cell::new(Roundoff::IEEE) };
    /// The ways the uncertain comparisons so far are forced to go (in order of occurrence);
    /// those beyond the list go the exact way.
    static FORCED: RefCell<Vec<bool>> = const { RefCell::new(Vec::new()) };
    /// How many uncertain comparisons this computation has met.
    static UNCERTAIN: Cell<usize> = const { Cell::new(0) };
}

/// A number within `radius` of `mid`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    pub mid: f64,
    pub radius: f64,
}

impl Ball {
    /// An input: an `f32` known exactly (but a denormal one may read as 0 in an arithmetic
    /// that flushes them).
    pub fn exact(x: f32) -> Self {
        let flushed = x.is_subnormal() && ROUNDOFF.with(|r| r.get().flush);
        Self {
            mid: x as f64,
            radius: if flushed { x.abs() as f64 } else { 0.0 },
        }
    }

    /// The ball of an operation's result: `mid` the exact operation on the midpoints (rounded
    /// in `f64`), `spread` how far the exact operation on any operands of the balls may be from
    /// it, `relative` the operation's rounding.
    fn rounded(mid: f64, spread: f64, relative: f64) -> Self {
        if mid == 0.0 && spread == 0.0 {
            // Exactly 0 (a product by an exact 0, a difference of equal exact numbers): every
            // arithmetic returns 0 itself, so a test of it is certain.
            return Self { mid, radius: 0.0 };
        }
        let roundoff = ROUNDOFF.with(|r| r.get());
        // A denormal result is rounded to the denormal spacing (absolute, not relative) and
        // may be flushed to 0 where the arithmetic allows.
        let absolute = 2f64.powi(-149)
            + if roundoff.flush {
                f32::MIN_POSITIVE as f64
            } else {
                0.0
            };
        let radius = spread + relative * (mid.abs() + spread) + f64::EPSILON * mid.abs() + absolute;
        Self {
            mid,
            radius: if mid.is_nan() { f64::INFINITY } else { radius },
        }
    }

    /// A ball that holds every number (the computation may return anything, NaN included).
    fn unbounded(mid: f64) -> Self {
        Self {
            mid,
            radius: f64::INFINITY,
        }
    }

    /// An input vector: three `f32`s known exactly (each [`Ball::exact`]).
    pub fn exact_v3(x: [f32; 3]) -> V3<Ball> {
        V3::new(Ball::exact(x[0]), Ball::exact(x[1]), Ball::exact(x[2]))
    }

    /// The ball of the numbers from `lo` to `hi` (None unless both are finite: an unbounded
    /// ball or a NaN has no ends).
    fn between(lo: f64, hi: f64) -> Option<Self> {
        (lo.is_finite() && hi.is_finite()).then_some(Self {
            mid: 0.5 * (lo + hi),
            radius: 0.5 * (hi - lo),
        })
    }

    /// Whether `x` is in the ball.
    pub fn holds(self, x: f64) -> bool {
        self.radius == f64::INFINITY || (x - self.mid).abs() <= self.radius
    }
}

fn unit() -> f64 {
    ROUNDOFF.with(|r| r.get().unit)
}

impl Add for Ball {
    type Output = Self;
    fn add(self, rhs: Self) -> Self {
        Ball::rounded(self.mid + rhs.mid, self.radius + rhs.radius, unit())
    }
}

impl Sub for Ball {
    type Output = Self;
    fn sub(self, rhs: Self) -> Self {
        self + -rhs
    }
}

impl Neg for Ball {
    type Output = Self;
    fn neg(self) -> Self {
        Self {
            mid: -self.mid,
            radius: self.radius,
        }
    }
}

/// Whether `b` is exactly a power of two (a scale that multiplies without rounding): a single
/// finite, nonzero number whose mantissa bits are all zero.
fn is_power_of_two(b: Ball) -> bool {
    const MANTISSA: u64 = (1 << 52) - 1;
    b.radius == 0.0 && b.mid.is_normal() && b.mid.to_bits() & MANTISSA == 0
}

impl Mul for Ball {
    type Output = Self;
    fn mul(self, rhs: Self) -> Self {
        // A product by an exact power of two is exact in every arithmetic while it stays
        // among the normal floats (4 x, x / 2: a sampler's scales).
        for (scale, x) in [(self, rhs), (rhs, self)] {
            if is_power_of_two(scale) {
                let (mid, radius) = (x.mid * scale.mid, x.radius * scale.mid.abs());
                let least = mid.abs() - radius;
                if least >= f32::MIN_POSITIVE as f64 && mid.abs() + radius <= f32::MAX as f64 {
                    return Ball { mid, radius };
                }
            }
        }
        let spread =
            self.mid.abs() * rhs.radius + rhs.mid.abs() * self.radius + self.radius * rhs.radius;
        Ball::rounded(self.mid * rhs.mid, spread, unit())
    }
}

impl Div for Ball {
    type Output = Self;
    fn div(self, rhs: Self) -> Self {
        let (b, rb) = (rhs.mid.abs(), rhs.radius);
        if !(b > rb) {
            return Ball::unbounded(self.mid / rhs.mid);
        }
        // The denominator's ball holds no 0, so the quotient is monotone in each operand over
        // the two balls: its range is spanned by the quotients of their ends (a ball centred
        // on a / b would reach as far below it as above, though 1 / y grows faster toward 0).
        let q = ROUNDOFF.with(|r| r.get().quotient);
        let ends = |b: Ball| [b.mid - b.radius, b.mid + b.radius];
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for x in ends(self) {
            for y in ends(rhs) {
                lo = lo.min(x / y);
                hi = hi.max(x / y);
            }
        }
        if self.radius == 0.0 && rhs.radius == 0.0 {
            return Ball::rounded(self.mid / rhs.mid, 0.0, q);
        }
        // An unbounded operand (or a quotient beyond f64) has no finite range.
        match Ball::between(lo, hi) {
            Some(range) => Ball::rounded(range.mid, range.radius, q),
            None => Ball::unbounded(self.mid / rhs.mid),
        }
    }
}

/// Whether a comparison of `a` and `b` may come out either way: their balls overlap and are
/// not both single numbers.
fn uncertain(a: Ball, b: Ball) -> bool {
    let reach = a.radius + b.radius;
    a.mid.is_nan() || b.mid.is_nan() || (reach > 0.0 && (a.mid - b.mid).abs() <= reach)
}

/// The way a comparison of `a` and `b` goes: `exact` (on the midpoints) where the balls are
/// apart, else as [`decide_if`] an uncertain one.
fn decide(a: Ball, b: Ball, exact: bool) -> u32 {
    decide_if(uncertain(a, b), exact)
}

/// The way a test goes: `exact` where it is certain, else the way this computation is forced
/// to take its next uncertain test (exact by default).
fn decide_if(uncertain: bool, exact: bool) -> u32 {
    let way = if uncertain {
        let k = UNCERTAIN.with(|n| {
            let k = n.get();
            n.set(k + 1);
            k
        });
        FORCED.with(|f| f.borrow().get(k).copied().unwrap_or(exact))
    } else {
        exact
    };
    if way {
        u32::MAX
    } else {
        0
    }
}

impl Real for Ball {
    type Bits = u32;

    fn splat(x: f32) -> Self {
        Ball::exact(x)
    }

    fn sqrt(self) -> Self {
        let hi = self.mid + self.radius;
        if !(hi >= 0.0) {
            return Ball::unbounded(f64::NAN);
        }
        let lo = (self.mid - self.radius).max(0.0);
        // The root is monotone: every root of the ball lies between those of its ends, and the
        // ball of them is centred between the two (not at the root of the midpoint, whose ball
        // would reach below 0 where the operand's ball straddles it: a root is never negative,
        // and a difference with it, as the sphere test's q = -(b - sqrt(disc)), must not
        // seem able to vanish where it cannot).
        let (root_lo, root_hi) = (lo.sqrt(), hi.sqrt());
        let w = ROUNDOFF.with(|r| r.get().root);
        Ball::rounded(0.5 * (root_lo + root_hi), 0.5 * (root_hi - root_lo), w)
    }

    // min, max and clamp are exact: the min of numbers of two balls lies between the min of
    // their lower ends and the min of their upper ends (so a ball clamped below a bound stays
    // below it), and likewise the max.
    fn min(self, other: Self) -> Self {
        Ball::between(
            (self.mid - self.radius).min(other.mid - other.radius),
            (self.mid + self.radius).min(other.mid + other.radius),
        )
        .unwrap_or(Self {
            mid: self.mid.min(other.mid),
            radius: self.radius.max(other.radius),
        })
    }

    fn max(self, other: Self) -> Self {
        Ball::between(
            (self.mid - self.radius).max(other.mid - other.radius),
            (self.mid + self.radius).max(other.mid + other.radius),
        )
        .unwrap_or(Self {
            mid: self.mid.max(other.mid),
            radius: self.radius.max(other.radius),
        })
    }

    fn clamp(self, lo: Self, hi: Self) -> Self {
        self.max(lo).min(hi)
    }

    fn to_bits(self) -> u32 {
        unimplemented!("a Ball has no bits: functions that work on them cannot be bounded so")
    }

    fn from_bits(_: u32) -> Self {
        unimplemented!("a Ball has no bits: functions that work on them cannot be bounded so")
    }

    fn greater_than(self, other: Self) -> u32 {
        decide(self, other, self.mid > other.mid)
    }

    fn at_least(self, other: Self) -> u32 {
        decide(self, other, self.mid >= other.mid)
    }

    fn less_than(self, other: Self) -> u32 {
        decide(self, other, self.mid < other.mid)
    }

    fn at_most(self, other: Self) -> u32 {
        decide(self, other, self.mid <= other.mid)
    }

    fn not_equal(self, other: Self) -> u32 {
        decide(self, other, self.mid != other.mid)
    }

    // An unbounded ball may hold finite numbers and others.
    fn finite(self) -> u32 {
        decide_if(
            self.mid.is_finite() && !self.radius.is_finite(),
            self.mid.is_finite(),
        )
    }

    /// The conversion truncates toward zero (saturating): every number of the ball truncates
    /// to an integer between those of its ends, so where they differ each of them is a way the
    /// computation may go (the first uncertain test asks "the lowest?", the next "the next?",
    /// and so on). More than [`MOST_WAYS`] of them exhaust [`computations`], which then
    /// returns unbounded balls.
    fn to_i32_bits(self) -> u32 {
        let truncate = |x: f64| x as i32;
        let (lo, hi) = if self.radius.is_finite() {
            (
                truncate(self.mid - self.radius),
                truncate(self.mid + self.radius),
            )
        } else {
            (i32::MIN, i32::MAX)
        };
        let exact = truncate(self.mid);
        let mut k = lo;
        while k < hi && k.abs_diff(lo) as usize <= MOST_WAYS {
            if decide_if(true, exact == k) != 0 {
                return k as u32;
            }
            k += 1;
        }
        k as u32
    }

    /// The integer as a float: exact where it fits in 24 bits, else rounded.
    fn from_i32_bits(bits: u32) -> Self {
        let i = bits as i32;
        if (i as f32) as i32 == i {
            Ball {
                mid: i as f64,
                radius: 0.0,
            }
        } else {
            Ball::rounded(i as f64, 0.0, unit())
        }
    }

    // The operations the kernel writes on the bits, on the numbers instead.

    fn abs(self) -> Self {
        Self {
            mid: self.mid.abs(),
            radius: self.radius,
        }
    }

    fn select(mask: u32, yes: Self, no: Self) -> Self {
        if mask != 0 {
            yes
        } else {
            no
        }
    }

    /// The exact cosine and sine of 2 pi `self`'s midpoint, within 2 pi times the argument's
    /// radius (both have slope at most 2 pi per turn) and what `kernel::turns::cos_sin_turns`'
    /// polynomials keep to under IEEE and every Vulkan model
    /// (`cos_sin_turns_is_within_four_roundings_under_every_arithmetic`): 4 units of roundoff,
    /// or 4 of them relative to the value (the smaller, so a sine near its zero stays as
    /// accurate as its argument) plus the smallest normal float.
    fn cos_sin_turns(self) -> (Self, Self) {
        let roundoff = ROUNDOFF.with(|r| r.get());
        let angle = std::f64::consts::TAU * self.mid;
        let moved = std::f64::consts::TAU * self.radius;
        let u = roundoff.unit;
        let ball = |mid: f64| {
            let absolute = 4.0 * u
                + if roundoff.flush {
                    f32::MIN_POSITIVE as f64
                } else {
                    0.0
                };
            let relative = 4.0 * u * (mid.abs() + moved) + f32::MIN_POSITIVE as f64;
            Self {
                mid,
                radius: moved + absolute.min(relative),
            }
        };
        (ball(angle.cos()), ball(angle.sin()))
    }
}

/// The most ways [`computations`] follows before it gives up (and returns unbounded balls).
const MOST_WAYS: usize = 64;

/// The balls of `f`'s outputs along every way a computation in arithmetic `roundoff` may take
/// through its uncertain comparisons (depth first: each uncertain comparison forced each way in
/// turn, the later ones found along the forced way). More than [`MOST_WAYS`] ways give one way
/// of unbounded balls.
pub fn computations<const N: usize>(
    roundoff: Roundoff,
    f: &dyn Fn() -> [Ball; N],
) -> Vec<[Ball; N]> {
    ROUNDOFF.with(|r| r.set(roundoff));
    let mut ways = Vec::new();
    let mut pending = vec![Vec::new()];
    while let Some(forced) = pending.pop() {
        if ways.len() >= MOST_WAYS {
            let any = [Ball::unbounded(f64::NAN); N];
            return vec![any];
        }
        FORCED.with(|x| *x.borrow_mut() = forced.clone());
        UNCERTAIN.with(|n| n.set(0));
        let out = f();
        let met = UNCERTAIN.with(|n| n.get());
        if met > forced.len() {
            for way in [false, true] {
                let mut next = forced.clone();
                next.push(way);
                pending.push(next);
            }
        } else {
            ways.push(out);
        }
    }
    FORCED.with(|x| x.borrow_mut().clear());
    ways
}

/// How far apart one IEEE computation of `f` (the CPU's) and one under Vulkan's rules (a
/// conformant device's) may be, per output: the largest distance between a ball of one and a
/// ball of the other, over every way each may take.
pub fn ieee_and_vulkan_apart<const N: usize>(f: &dyn Fn() -> [Ball; N]) -> [f64; N] {
    let ieee = computations(Roundoff::IEEE, f);
    let vulkan = computations(Roundoff::VULKAN, f);
    std::array::from_fn(|i| {
        let mut apart = 0f64;
        for a in &ieee {
            for b in &vulkan {
                // The same infinity in both (a delta lobe's density) is not apart.
                let same_infinity = a[i].mid.is_infinite()
                    && a[i].mid == b[i].mid
                    && a[i].radius == 0.0
                    && b[i].radius == 0.0;
                let d = if same_infinity {
                    0.0
                } else {
                    (a[i].mid - b[i].mid).abs() + a[i].radius + b[i].radius
                };
                apart = if d.is_nan() {
                    f64::INFINITY
                } else {
                    apart.max(d)
                };
            }
        }
        apart
    })
}
