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
//! - any denormal input or result may be flushed to zero, and the sign of a zero is
//!   unspecified unless the module preserves them (float controls);
//! - comparisons, `min`, `max`, negation and bit casts: exact.
//!
//! Each operation draws its choice (rounding mode, fused or not, how many ULP off, flushed or
//! not) from a per-thread stream ([`seed`], [`set_model`]), independently per operation, which
//! is more hostile than any one device (a device keeps one rounding mode) and so covers them all.
//! Every result is one a conformant device may return: [`Vk32`]'s own test checks each against
//! the exact value computed in `f64`.

use kernel::real::Real;
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
    /// one), square roots as 1 / inversesqrt with each step off by what the table allows.
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

/// How far apart the CPU's and a conformant Vulkan device's `orthonormal_basis` may be, per
/// component, in eps (derived in `tests/tests/vulkan_precision.rs`; used by `gpu_functions.rs`
/// for devices that are not IEEE).
pub const BASIS_APART_EPS: f32 = 9.0;

/// How far apart the CPU's and a conformant device's cone-sampled points (and normals) may be,
/// relative to the size of the geometry: twice the square root of the 25 eps the cancelling
/// ratio carries (derived in `tests/tests/vulkan_precision.rs`).
pub fn cone_points_apart() -> f32 {
    2.0 * (25.0 * f32::EPSILON).sqrt()
}

/// How far apart the CPU's and a conformant device's `geometry_factor` G = |(n_a . d)(n_b . d)|
/// / (d . d)^2 may be, for points |d|^2 = `d2` apart (derived in
/// `tests/tests/vulkan_precision.rs`): 12 eps / |d|^2 + 21 eps G.
pub fn geometry_factor_apart(d2: f64, g: f64) -> f64 {
    f32::EPSILON as f64 * (12.0 / d2 + 21.0 * g)
}

/// The roundoff of one IEEE and one Vulkan computation added: u (eps / 2 and eps) and a
/// quotient's relative error (eps / 2 and 2.5 eps). A quantity computed by both is apart by at
/// most its error bound with these.
const APART_U: f64 = 1.5 * f32::EPSILON as f64;
const APART_Q: f64 = 3.0 * f32::EPSILON as f64;

fn d3(v: [f32; 3]) -> glam::DVec3 {
    glam::Vec3::from_array(v).as_dvec3()
}

/// Whether `kernel::intersect::triangle` (Moller-Trumbore) of this ray may say hit on one device
/// and miss on another: a barycentric, their sum, or t within rounding of its limit, or the
/// determinant within rounding of 0. Exact values in `f64` from the `f32` inputs; error bounds
/// of each computation (u its unit roundoff, q its quotient's error): the cross products within
/// 3 u |a||b| (and tvec's own rounding u), so U = tvec . pvec within 7 u |tvec||d||e2|, V = d .
/// qvec within 7 u |d||tvec||e1|, T = e2 . qvec within 7 u |e2||tvec||e1|, det within 6 u
/// |e1||d||e2|; a barycentric X / det within (dX + |X / det| d(det)) / |det| + (q + u) |X / det|.
pub fn triangle_hit_may_flip(
    origin: [f32; 3],
    dir: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    t_min: f32,
    t_max: f32,
) -> bool {
    let (o, d, p0, e1, e2) = (d3(origin), d3(dir), d3(p0), d3(e1), d3(e2));
    let (u, q) = (APART_U, APART_Q);
    let pvec = d.cross(e2);
    let det = e1.dot(pvec);
    let tvec = o - p0;
    let qvec = tvec.cross(e1);
    let (nd, ne1, ne2, nt) = (d.length(), e1.length(), e2.length(), tvec.length());
    let d_det = 6.0 * u * ne1 * nd * ne2;
    if det.abs() <= d_det {
        return true;
    }
    let quotient = |x: f64, dx: f64| {
        let value = x / det;
        (
            value,
            (dx + value.abs() * d_det) / det.abs() + (q + u) * value.abs(),
        )
    };
    let (bu, du) = quotient(tvec.dot(pvec), 7.0 * u * nt * nd * ne2);
    let (bv, dv) = quotient(d.dot(qvec), 7.0 * u * nd * nt * ne1);
    let (t, dt) = quotient(e2.dot(qvec), 7.0 * u * ne2 * nt * ne1);
    let dsum = du + dv + u * (bu + bv).abs();
    bu.abs() <= du
        || (1.0 - bu).abs() <= du
        || bv.abs() <= dv
        || (1.0 - bu - bv).abs() <= dsum
        || (t - t_min as f64).abs() <= dt
        || (t_max as f64 - t).abs() <= dt
}

/// Whether `kernel::intersect::sphere` of this ray may say hit on one device and miss on
/// another: the ray within rounding of tangent, or a root within rounding of t_min or t_max.
/// Exact values in `f64`; error bounds of each computation: f = o - c within u |f|, the
/// perpendicular f - d (f . d) / (d . d) within 6 u |f| (a dot product, a quotient, a product
/// and a difference), so the margin r^2 - |perp|^2 within 2 r 6 u |f| + 4 u r^2 near tangency;
/// a root, at half = sqrt(margin / a) from the closest point, within 16 (u + q) (|f| + r) / |d|
/// (the stable quadratic: a square root and two quotients) plus the margin's error times
/// d(half)/d(margin) = 1 / (2 a half), which grows without bound toward tangency.
pub fn sphere_hit_may_flip(
    origin: [f32; 3],
    dir: [f32; 3],
    center: [f32; 3],
    radius: f32,
    t_min: f32,
    t_max: f32,
) -> bool {
    let (o, d, c, r) = (d3(origin), d3(dir), d3(center), radius as f64);
    let (u, q) = (APART_U, APART_Q);
    let f = o - c;
    let a = d.dot(d);
    let perp = f - d * (f.dot(d) / a);
    let margin = r * r - perp.length_squared();
    let d_margin = 12.0 * u * r * f.length() + 4.0 * u * r * r;
    if margin.abs() <= d_margin {
        return true;
    }
    if margin < 0.0 {
        return false;
    }
    // The roots along -/+ half, half = sqrt(margin / a): the margin's error moves half by
    // d_margin / (2 a half) (near tangency this dominates), the rest by 16 (u + q) of the sizes.
    let along = -f.dot(d) / a;
    let half = (margin / a).sqrt();
    let dt = 16.0 * (u + q) * (f.length() + r) / a.sqrt() + d_margin / (2.0 * a * half);
    [along - half, along + half]
        .iter()
        .any(|&t| (t - t_min as f64).abs() <= dt || (t_max as f64 - t).abs() <= dt)
}

/// How far apart the CPU's and a conformant device's `camera_ray_direction` may be, per
/// component, for camera axes `forward`, `right`, `up` and image-plane position (x, y) in
/// [-1, 1] (derived in `tests/tests/vulkan_precision.rs`): eps ([10.5 (|right| + |up|) +
/// 4.5 S] / |v| + 11.85), S = |forward| + |x||right| + |y||up|, v the unnormalised direction.
pub fn camera_direction_apart(
    forward: [f32; 3],
    right: [f32; 3],
    up: [f32; 3],
    x: f64,
    y: f64,
) -> f64 {
    let (f, r, u) = (d3(forward), d3(right), d3(up));
    let v = f + r * x + u * y;
    let s = f.length() + x.abs() * r.length() + y.abs() * u.length();
    f32::EPSILON as f64 * ((10.5 * (r.length() + u.length()) + 4.5 * s) / v.length() + 11.85)
}

/// How far apart the CPU's and a conformant device's cosine-sampled direction (per component)
/// and its density may be, for uniform number `u1` (c = sqrt(u1), s = sqrt(1 - u1); derived in
/// `tests/tests/vulkan_precision.rs`): eps (33 s + 11.1 c) and 21 eps.
pub fn cosine_sample_apart(u1: f32) -> (f64, f64) {
    let u1 = u1 as f64;
    let eps = f32::EPSILON as f64;
    (
        eps * (33.0 * (1.0 - u1).sqrt() + 11.1 * u1.sqrt()),
        21.0 * eps,
    )
}
