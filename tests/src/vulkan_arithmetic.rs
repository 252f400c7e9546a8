//! [`Vk32`]: an `f32` that computes as a Vulkan device may, for running the kernel's generic
//! numerics (everything written over `kernel::real::Real`) on the CPU under the arithmetic the
//! Vulkan specification allows instead of IEEE-754's ("Precision and Operation of SPIR-V
//! Instructions", Vulkan 1.3, section 47.5 (appendix "Precision")):
//!
//! - `OpFAdd`, `OpFSub`, `OpFMul`: correctly rounded, in a rounding mode the device chooses
//!   (round to nearest even, or toward zero) unless the module sets one (float controls);
//! - a multiply followed by an add may be fused into one operation rounded once, unless the
//!   result is decorated `NoContraction`;
//! - `OpFDiv`: within 2.5 ULP of the exact quotient;
//! - `sqrt`: inherited from `1.0 / inversesqrt(x)`, `inversesqrt` within 2 ULP;
//! - `exp`: within 3 + 2 |x| ULP; `log`: within 3 ULP, or within 2^-21 absolutely for x in
//!   [0.5, 2];
//! - any denormal input or result may be flushed to zero, and the sign of a zero is
//!   unspecified unless the module preserves them (float controls);
//! - comparisons, `min`, `max`, negation and bit casts: exact.
//!
//! Each operation draws its choice (rounding mode, fused or not, how many ULP off, flushed or
//! not) from a per-thread stream ([`seed`], [`set_model`]), independently per operation, which
//! is more hostile than any one device (a device keeps one rounding mode) and so covers them all.
//! Every result is one a conformant device may return: [`Vk32`]'s own test checks each against
//! the exact value computed in `f64`.

use kernel::real::{Exponential, Real};
use std::cell::Cell;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// Which of Vulkan's liberties [`Vk32`] takes (all of them by default).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Model {
    /// Round toward zero on a coin flip (else to nearest even).
    pub round_toward_zero: bool,
    /// Fuse a multiply into the add or subtract that consumes it on a coin flip.
    pub contract: bool,
    /// Divisions off by up to 2 ULP of the correctly rounded quotient (2.5 ULP of the exact
    /// one), square roots as 1 / inversesqrt with each step off by what the table allows,
    /// exponentials and logarithms off by what `exp` and `log` may be.
    pub loose_division_and_sqrt: bool,
    /// Flush denormal inputs and results to a zero of either sign on a coin flip.
    pub flush_denormals: bool,
    /// Every inexact result as far off as allowed, all one way: rounding always toward zero,
    /// quotients off by their whole allowance in the direction of [`lean`]'s sign and square
    /// roots in the other (so a normalisation x / sqrt(x . x) errs by both).
    /// The errors of a computation then add up instead of averaging out, as on a device whose
    /// every rounding happened to fall the same way.
    pub worst: bool,
}

impl Model {
    /// Every liberty Vulkan allows without float controls.
    pub const VULKAN: Model = Model {
        round_toward_zero: true,
        contract: true,
        loose_division_and_sqrt: true,
        flush_denormals: true,
        worst: false,
    };
    /// [`Model::VULKAN`] with every error at its largest, one way ([`Model::worst`]).
    pub const VULKAN_WORST: Model = Model {
        round_toward_zero: true,
        contract: true,
        loose_division_and_sqrt: true,
        flush_denormals: true,
        worst: true,
    };
    /// None: [`Vk32`] computes exactly as `f32` does (IEEE-754, round to nearest even).
    pub const IEEE: Model = Model {
        round_toward_zero: false,
        contract: false,
        loose_division_and_sqrt: false,
        flush_denormals: false,
        worst: false,
    };
}

thread_local! {
    static STATE: Cell<u64> = const { Cell::new(0x9e37_79b9_7f4a_7c15) };
    static MODEL: Cell<Model> = const { Cell::new(Model::VULKAN) };
    static LEAN: Cell<i32> = const { Cell::new(1) };
}

/// Which way [`Model::worst`] pushes quotients and roots: up (+1) or down (-1).
pub fn lean(direction: i32) {
    LEAN.with(|l| l.set(direction.signum()));
}

/// Restarts this thread's stream of choices from `seed`.
pub fn seed(seed: u64) {
    STATE.with(|s| s.set(seed ^ 0x9e37_79b9_7f4a_7c15));
}

/// Sets which liberties this thread's [`Vk32`] operations take.
pub fn set_model(model: Model) {
    MODEL.with(|m| m.set(model));
}

fn model() -> Model {
    MODEL.with(|m| m.get())
}

/// `f`'s result computed under `model`, leaning `direction` ([`lean`]), this thread's model and
/// lean restored afterwards (its stream of choices goes on).
pub fn with_model<T>(model: Model, direction: i32, f: impl FnOnce() -> T) -> T {
    let (before, lean_before) = (MODEL.with(|m| m.get()), LEAN.with(|l| l.get()));
    set_model(model);
    lean(direction);
    let result = f();
    set_model(before);
    lean(lean_before);
    result
}

/// The next 64 random bits of this thread's stream (splitmix64).
fn bits() -> u64 {
    STATE.with(|s| {
        let z = s.get().wrapping_add(0x9e37_79b9_7f4a_7c15);
        s.set(z);
        let z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        let z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    })
}

fn coin() -> bool {
    bits() & 1 == 1
}

/// The spacing of `f32`s at `x` (the unit in the last place of the binade holding |x|; the
/// smallest denormal spacing below 2^-126).
pub fn ulp(x: f64) -> f64 {
    let a = x.abs();
    if a < f32::MIN_POSITIVE as f64 {
        return 2f64.powi(-149);
    }
    2f64.powi(a.log2().floor() as i32 - 23)
}

/// `x` moved `k` representable `f32`s up (k > 0) or down.
fn step(mut x: f32, k: i32) -> f32 {
    for _ in 0..k.abs() {
        x = if k > 0 { x.next_up() } else { x.next_down() };
    }
    x
}

/// `exact` rounded to an `f32` in the mode this operation draws: to nearest even, or (if the
/// model allows) toward zero on a coin flip.
fn round(exact: f64) -> f32 {
    let nearest = exact as f32;
    let m = model();
    if !m.round_toward_zero || !(m.worst || coin()) || !nearest.is_finite() {
        return nearest;
    }
    if (nearest as f64).abs() > exact.abs() {
        step(nearest, if nearest > 0.0 { -1 } else { 1 })
    } else {
        nearest
    }
}

/// An `f32` within `ulps` ULP of `exact` (0 gives the correctly rounded one): the correctly
/// rounded value moved by a random whole number of steps, kept only where it stays in bounds.
fn within(exact: f64, ulps: f64) -> f32 {
    within_leaning(exact, ulps, 1)
}

/// [`within`], where [`Model::worst`] pushes by the whole allowance in the direction of
/// `sign` times [`lean`]'s.
fn within_leaning(exact: f64, ulps: f64, sign: i32) -> f32 {
    let nearest = exact as f32;
    if ulps == 0.0 || !nearest.is_finite() || exact == 0.0 {
        return nearest;
    }
    let reach = ulps.ceil() as i32;
    let k = if model().worst {
        reach * sign * LEAN.with(|l| l.get())
    } else {
        (bits() % (2 * reach as u64 + 1)) as i32 - reach
    };
    // The farthest step toward k that stays within the allowance.
    let mut k = k;
    loop {
        let candidate = step(nearest, k);
        if candidate.is_finite() && (candidate as f64 - exact).abs() <= ulps * ulp(exact) {
            return candidate;
        }
        k -= k.signum();
        if k == 0 {
            return nearest;
        }
    }
}

/// An `f32` less than `abs` from `exact` (an absolute allowance): the nearest `f32` to a random
/// point of (exact - abs, exact + abs), or under [`Model::worst`] to the end [`lean`] points at,
/// stepped toward `exact` until it is inside.
fn within_absolute(exact: f64, abs: f64) -> f32 {
    let offset = if model().worst {
        abs * LEAN.with(|l| l.get()) as f64
    } else {
        abs * ((bits() >> 11) as f64 * 2f64.powi(-52) - 1.0)
    };
    let mut candidate = (exact + offset) as f32;
    while (candidate as f64 - exact).abs() >= abs {
        candidate = if (candidate as f64) > exact {
            candidate.next_down()
        } else {
            candidate.next_up()
        };
    }
    candidate
}

/// `x`, or on a coin flip a zero of random sign if `x` is denormal (the model allowing).
fn flush(x: f32) -> f32 {
    if model().flush_denormals && x != 0.0 && x.is_subnormal() && coin() {
        if coin() {
            0.0
        } else {
            -0.0
        }
    } else {
        x
    }
}

/// An `f32` computed under Vulkan's rules. `product` holds the factors of a multiply whose
/// consumer may still fuse it (an unrounded product, as a contracted `OpFMul` feeding `OpFAdd`).
#[derive(Clone, Copy, Debug)]
pub struct Vk32 {
    pub value: f32,
    product: Option<(f32, f32)>,
}

impl Vk32 {
    pub fn new(value: f32) -> Self {
        Self {
            value,
            product: None,
        }
    }

    /// The rounded value (what every consumer but a fusing add sees).
    fn get(self) -> f32 {
        flush(self.value)
    }

    fn exact(value: f32) -> Self {
        Self::new(flush(value))
    }
}

/// The value a device would hold (a pending product rounded as the last operation left it).
impl From<Vk32> for f32 {
    fn from(x: Vk32) -> f32 {
        x.value
    }
}

impl From<f32> for Vk32 {
    fn from(x: f32) -> Self {
        Self::new(x)
    }
}

/// a + b, fusing a pending product of either operand on a coin flip (the model allowing).
fn sum(a: Vk32, b: Vk32) -> Vk32 {
    if model().contract {
        for (p, other) in [(a, b), (b, a)] {
            if let Some((x, y)) = p.product {
                if coin() {
                    // Both factors are f32: their product is exact in f64, and the sum with one
                    // more f32 is rounded once more in f64, then to f32 (the f64 step is exact
                    // unless the exponents differ by more than 29, where it changes nothing the
                    // f32 rounding keeps).
                    let exact = x as f64 * y as f64 + other.get() as f64;
                    return Vk32::exact(round(exact));
                }
            }
        }
    }
    Vk32::exact(round(a.get() as f64 + b.get() as f64))
}

impl Add for Vk32 {
    type Output = Self;
    fn add(self, rhs: Self) -> Self {
        sum(self, rhs)
    }
}

impl Sub for Vk32 {
    type Output = Self;
    fn sub(self, rhs: Self) -> Self {
        sum(self, -rhs)
    }
}

impl Neg for Vk32 {
    type Output = Self;
    fn neg(self) -> Self {
        Self {
            value: -self.value,
            product: self.product.map(|(x, y)| (-x, y)),
        }
    }
}

impl Mul for Vk32 {
    type Output = Self;
    fn mul(self, rhs: Self) -> Self {
        let (x, y) = (self.get(), rhs.get());
        Self {
            value: flush(round(x as f64 * y as f64)),
            product: Some((x, y)),
        }
    }
}

impl Div for Vk32 {
    type Output = Self;
    fn div(self, rhs: Self) -> Self {
        let exact = self.get() as f64 / rhs.get() as f64;
        let ulps = if model().loose_division_and_sqrt {
            2.5
        } else {
            0.0
        };
        Vk32::exact(within(exact, ulps))
    }
}

impl Exponential for Vk32 {
    fn exp(self) -> Self {
        let x = self.get();
        let exact = (x as f64).exp();
        if !model().loose_division_and_sqrt {
            return Vk32::exact(x.exp());
        }
        Vk32::exact(within(exact, 3.0 + 2.0 * (x as f64).abs()))
    }

    fn ln(self) -> Self {
        let x = self.get();
        let exact = (x as f64).ln();
        if !model().loose_division_and_sqrt || !exact.is_finite() {
            return Vk32::exact(x.ln());
        }
        if (0.5..=2.0).contains(&x) {
            Vk32::exact(within_absolute(exact, 2f64.powi(-21)))
        } else {
            Vk32::exact(within(exact, 3.0))
        }
    }
}

impl Real for Vk32 {
    type Bits = u32;

    fn splat(x: f32) -> Self {
        Self::new(x)
    }

    fn sqrt(self) -> Self {
        let x = self.get();
        if !model().loose_division_and_sqrt {
            return Vk32::exact(x.sqrt());
        }
        // 1 / inversesqrt(x): each step within its allowance of its own exact result. The
        // worst model pushes both steps toward a root that errs against the lean (a length too
        // small where quotients are too large), so that x / sqrt(y) is off by the sum.
        let inverse_root = within_leaning(1.0 / (x as f64).sqrt(), 2.0, 1);
        Vk32::exact(within_leaning(1.0 / inverse_root as f64, 2.5, -1))
    }

    fn min(self, other: Self) -> Self {
        Self::exact(self.get().min(other.get()))
    }

    fn max(self, other: Self) -> Self {
        Self::exact(self.get().max(other.get()))
    }

    fn clamp(self, lo: Self, hi: Self) -> Self {
        Self::exact(self.get().clamp(lo.get(), hi.get()))
    }

    fn to_bits(self) -> u32 {
        self.value.to_bits()
    }

    fn from_bits(bits: u32) -> Self {
        Self::new(f32::from_bits(bits))
    }

    fn greater_than(self, other: Self) -> u32 {
        mask(self.get() > other.get())
    }

    fn at_least(self, other: Self) -> u32 {
        mask(self.get() >= other.get())
    }

    fn less_than(self, other: Self) -> u32 {
        mask(self.get() < other.get())
    }

    fn at_most(self, other: Self) -> u32 {
        mask(self.get() <= other.get())
    }

    fn not_equal(self, other: Self) -> u32 {
        mask(self.get() != other.get())
    }

    fn finite(self) -> u32 {
        mask(self.value.is_finite())
    }

    fn to_i32_bits(self) -> u32 {
        self.get() as i32 as u32
    }

    fn from_i32_bits(bits: u32) -> Self {
        Vk32::exact(round(bits as i32 as f64))
    }
}

fn mask(b: bool) -> u32 {
    if b {
        u32::MAX
    } else {
        0
    }
}
