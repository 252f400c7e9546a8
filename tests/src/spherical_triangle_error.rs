//! First-order error bounds of `kernel::spherical_triangle` for one computation in a given
//! arithmetic: unit roundoff `u` (sums, differences, products), quotient error `q` and root
//! error `w`, relative (`device_class::IEEE_ROUNDOFF`, `VULKAN_ROUNDOFF`), every rounding
//! aligned. The exact quantities a bound depends on (lengths, the triple product, the angles)
//! are computed in `f64` from the same `f32` inputs, so a bound is per record: it carries the
//! record's own conditioning (a receiver near the triangle's plane, a thin triangle), which no
//! arithmetic removes. Checked against the model of a Vulkan device in
//! `tests/tests/vulkan_precision.rs`; collected in `docs/robustness.md`.

use glam::DVec3;

/// The exact view of the triangle p0, p0 + e1, p0 + e2 from x, and how far
/// `SphericalTriangle::view`'s intermediate quantities may be off in one computation.
struct View {
    /// Exact triple product of the unit directions and its error bound.
    volume: f64,
    volume_error: f64,
    /// Exact 1 + A . B + B . C + C . A and its error bound.
    denominator: f64,
    denominator_error: f64,
}

fn d3(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

/// The view's errors, term by term (a, b, c the vectors to the vertices; n = e1 x e2). An
/// error that scales a vector as a whole moves a dot product by that fraction of the product;
/// an error in any other direction moves it by up to its length times the other vector's
/// length, which is where the receiver's elevation (the triple product is |n'| h) and the
/// triangle's shape enter:
///
/// - a = p0 - x is off by u |a| per component; b = a + e1 by u (|a| + |b|), c likewise:
///   relative r_v, in any direction;
/// - the computed v / |v| is v' / |v'| of the rounded v' (r_v, not along v: moving v along
///   itself does not move its direction) scaled by the length's roundings (three products and
///   two sums of non-negative terms 3 u, halved by the root, and the root's w: 1.5 u + w), and
///   each component's quotient (q, in any direction);
/// - |b| and |c| as computed are off by r_v + 1.5 u + w each, their product by u more: a scale
///   of n' = n / (|b| |c|); n's components are ab - cd of exact inputs, u (|ab| + |cd|) +
///   u |n_i|, and the vector of |ab| + |cd| is at most sqrt 2 |e1| |e2| long, so
///   u (sqrt 2 / sin theta + 1) of |n| (theta the triangle's angle at p0) in any direction;
///   the quotients q in any direction;
/// - the triple product A . n': the scales times |V|; the rest, A's and n''s, and the dot's
///   three roundings of terms whose magnitudes sum to at most |n'|, times |n'| = |V| / h, h the
///   sine of the receiver's elevation above the triangle's plane;
/// - D = 1 + A . B + B . C + C . A: each dot of unit directions off by the two scales times the
///   dot, the two other errors, and 3 u; the three sums by u of their partial sums.
fn view(x: [f32; 3], p0: [f32; 3], e1: [f32; 3], e2: [f32; 3], u: f64, q: f64, w: f64) -> View {
    let (e1, e2) = (d3(e1), d3(e2));
    let a = d3(p0) - d3(x);
    let v = [a, a + e1, a + e2];
    let len = v.map(|v| v.length());
    let rounded = [u, u * (1.0 + len[0] / len[1]), u * (1.0 + len[0] / len[2])];
    let dir_scale = [1.5 * u + w; 3];
    let dir_turn = rounded.map(|r| r + q);
    let n = e1.cross(e2);
    let normal_turn = u * (2f64.sqrt() * e1.length() * e2.length() / n.length() + 1.0);
    let lengths_scale = rounded[1] + rounded[2] + 2.0 * (1.5 * u + w) + u;
    let scaled_length = n.length() / (len[1] * len[2]);
    let d = v.map(|v| v.normalize());
    let volume = d[0].dot(n) / (len[1] * len[2]);
    let volume_error = volume.abs() * (dir_scale[0] + lengths_scale)
        + scaled_length * (dir_turn[0] + normal_turn + q + 3.0 * u);
    let dot_error = |i: usize, j: usize| {
        d[i].dot(d[j]).abs() * (dir_scale[i] + dir_scale[j]) + dir_turn[i] + dir_turn[j] + 3.0 * u
    };
    let s1 = 1.0 + d[0].dot(d[1]);
    let s2 = s1 + d[1].dot(d[2]);
    let denominator = s2 + d[2].dot(d[0]);
    let denominator_error = dot_error(0, 1)
        + dot_error(1, 2)
        + dot_error(2, 0)
        + u * (s1.abs() + s2.abs() + denominator.abs());
    View {
        volume,
        volume_error,
        denominator,
        denominator_error,
    }
}

/// First-order error, in turns, of `kernel::turns::atan2_turns(y, x)` computed on exact inputs
/// (y >= 0), following its branches: the reduced quotient w (its numerator's and denominator's
/// roundings and the quotient's, 2 u + q relative, moving atan w by at most as much), the
/// series' roundings (the last sum's u, and 10 u of a correction below 0.06 |w|), its
/// truncation (2.9e-9 rad), the product with 1 / (2 pi) (u, and the constant's own rounding,
/// eps / 2), then each octant or quadrant subtraction's u of its result.
pub fn atan2_turns_error(y: f64, x: f64, u: f64, q: f64) -> f64 {
    let ax = x.abs();
    let (m, big) = if y > ax { (ax, y) } else { (y, ax) };
    if !(big > 0.0) {
        return 0.0;
    }
    let above_eighth = m > 0.414_213_57 * big;
    let w_ = if above_eighth {
        (m - big) / (m + big)
    } else {
        m / big
    };
    let reduced = w_.atan() / std::f64::consts::TAU;
    let eps = f32::EPSILON as f64;
    let truncation = 2.9e-9 / std::f64::consts::TAU;
    // atan moves by at most dw (its derivative is at most 1).
    let w_turns = w_.abs() / std::f64::consts::TAU;
    let mut error =
        w_turns * (2.0 * u + q + 0.6 * u) + reduced.abs() * (2.0 * u + 0.5 * eps) + truncation;
    let octant = if above_eighth {
        0.125 + reduced
    } else {
        reduced
    };
    if above_eighth {
        error += u * octant.abs();
    }
    let quadrant = if y > ax { 0.25 - octant } else { octant };
    if y > ax {
        error += u * quadrant.abs();
    }
    if x < 0.0 {
        error += u * (0.5 - quadrant).abs();
    }
    error
}

/// The exact solid angle (steradians) of the triangle p0, p0 + e1, p0 + e2 seen from x, from
/// the `f32` inputs in `f64`, by Van Oosterom and Strackee's formula as the kernel writes it.
pub fn solid_angle_exact(x: [f32; 3], p0: [f32; 3], e1: [f32; 3], e2: [f32; 3]) -> f64 {
    let v = view(x, p0, e1, e2, 0.0, 0.0, 0.0);
    2.0 * v.volume.abs().atan2(v.denominator)
}

/// First-order relative error of one computation of `SphericalTriangle::solid_angle` in the
/// arithmetic (u, q, w): half the solid angle is atan2(|V|, D), which moves by
/// (|D| dV + |V| dD) / (V^2 + D^2) under its inputs' errors ([`view`]'s), plus
/// [`atan2_turns_error`]; doubling is exact, and the product with 2 pi adds u and the
/// constant's rounding (eps / 2, shared by every device). Infinite where the solid angle is 0.
pub fn solid_angle_error(
    x: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    roundoff: (f64, f64, f64),
) -> f64 {
    solid_angle_error_absolute(x, p0, e1, e2, roundoff) / solid_angle_exact(x, p0, e1, e2)
}

/// [`solid_angle_error`] in steradians instead of relative: 4 pi times the error of half the
/// solid angle in turns, plus u and eps / 2 of the solid angle. Finite where the solid angle is
/// 0 (a receiver in the triangle's plane, whose triple product is all rounding) unless D is too.
pub fn solid_angle_error_absolute(
    x: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    (u, q, w): (f64, f64, f64),
) -> f64 {
    let v = view(x, p0, e1, e2, u, q, w);
    let (y, d) = (v.volume.abs(), v.denominator);
    let moved = (d.abs() * v.volume_error + y * v.denominator_error) / (y * y + d * d);
    let turns_error = moved / std::f64::consts::TAU + atan2_turns_error(y, d, u, q);
    let omega = 2.0 * y.atan2(d);
    2.0 * std::f64::consts::TAU * turns_error + (u + 0.5 * f32::EPSILON as f64) * omega
}

/// The exact inputs of the sampler (`SphericalTriangle::sample_real`) for the triangle
/// p0, p0 + e1, p0 + e2 seen from x, and how far one computation of each may be off: the unit
/// directions per component (absolute), the triple product (absolute) and the solid angle in
/// turns (relative).
struct SamplerInputs {
    dir: [DVec3; 3],
    dir_error: [DVec3; 3],
    volume: f64,
    volume_error: f64,
    omega_turns: f64,
    omega_error: f64,
}

/// [`SamplerInputs`] in the arithmetic (u, q, w). A unit direction's component is the rounded
/// vector's (u |a_j| for a, u (|a_j| + |b_j|) for b and c) over the computed length, which is
/// off by the rounded vector's own relative error (r_v, [`view`]) and 1.5 u + w, then the
/// quotient's q.
fn sampler_inputs(
    x: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    roundoff: (f64, f64, f64),
) -> SamplerInputs {
    let (u, q, w) = roundoff;
    let a = d3(p0) - d3(x);
    let v = [a, a + d3(e1), a + d3(e2)];
    let rounded = [
        a.abs() * u,
        (a.abs() + v[1].abs()) * u,
        (a.abs() + v[2].abs()) * u,
    ];
    let dir = v.map(|v| v.normalize());
    let dir_error = [0, 1, 2].map(|i| {
        let length = v[i].length();
        let relative = rounded[i].length() / length + 1.5 * u + w + q;
        rounded[i] / length + dir[i].abs() * relative
    });
    let view = view(x, p0, e1, e2, u, q, w);
    let omega = solid_angle_exact(x, p0, e1, e2);
    SamplerInputs {
        dir,
        dir_error,
        volume: view.volume,
        volume_error: view.volume_error,
        omega_turns: omega / std::f64::consts::TAU,
        omega_error: solid_angle_error(x, p0, e1, e2, roundoff),
    }
}

/// The roundings of one computation of the sampler, one quantity (a slot) at a time: an exact
/// pass records each slot's allowance (how far that operation may move its result); a later
/// pass moves one slot by its whole allowance, up or down, and leaves the rest exact.
struct Roundings {
    roundoff: (f64, f64, f64),
    allowances: Vec<f64>,
    recording: bool,
    next: usize,
    moved: Option<(usize, f64)>,
}

impl Roundings {
    /// `x`, moved in this pass if its slot is the one moved; `allowance` is recorded on the
    /// exact pass.
    fn abs(&mut self, x: f64, allowance: f64) -> f64 {
        let k = self.next;
        self.next += 1;
        if self.recording {
            self.allowances.push(allowance);
        }
        match self.moved {
            Some((slot, sign)) if slot == k => x + sign * self.allowances[k],
            _ => x,
        }
    }

    fn rel(&mut self, x: f64, relative: f64) -> f64 {
        self.abs(x, relative * x.abs())
    }

    fn abs3(&mut self, v: DVec3, allowance: DVec3) -> DVec3 {
        DVec3::new(
            self.abs(v.x, allowance.x),
            self.abs(v.y, allowance.y),
            self.abs(v.z, allowance.z),
        )
    }

    /// A vector sum or difference: u of each component.
    fn sum3(&mut self, v: DVec3) -> DVec3 {
        let u = self.roundoff.0;
        self.abs3(v, v.abs() * u)
    }

    /// Componentwise products: u of each component.
    fn product3(&mut self, v: DVec3) -> DVec3 {
        self.sum3(v)
    }

    /// A dot product x . y: three products and two sums, 3 u of the sum of |x_j y_j|.
    fn dot(&mut self, x: DVec3, y: DVec3) -> f64 {
        let u = self.roundoff.0;
        self.abs(x.dot(y), 3.0 * u * (x.abs().dot(y.abs())))
    }

    /// `arc_toward(from, toward, x)`: the sine sqrt(x (2 - x)) (the difference u, the product
    /// u, the root w), the cosine 1 - x (u), the perpendicular toward - from (toward . from)
    /// (the dot, the products, the differences), its normalisation, and the two products and
    /// the sum.
    fn arc_toward(&mut self, from: DVec3, toward: DVec3, one_minus_cos: f64) -> DVec3 {
        let (u, _, w) = self.roundoff;
        let two_minus = self.abs(2.0 - one_minus_cos, u * (2.0 - one_minus_cos).abs());
        let product = self.rel(one_minus_cos * two_minus, u);
        let sin = self.rel(product.max(0.0).sqrt(), w);
        let cos = self.abs(1.0 - one_minus_cos, u * (1.0 - one_minus_cos).abs());
        let along = self.dot(toward, from);
        let along = self.product3(from * along);
        let perpendicular = self.sum3(toward - along);
        let unit = self.normalize(perpendicular);
        let first = self.product3(from * cos);
        let second = self.product3(unit * sin);
        self.sum3(first + second)
    }

    /// `v * (1 / |v|)`, as `normalize` computes it: the length (1.5 u + w), the reciprocal (q)
    /// and the products (u each).
    fn normalize(&mut self, v: DVec3) -> DVec3 {
        let (u, q, w) = self.roundoff;
        let length = self.rel(v.length(), 1.5 * u + w);
        let reciprocal = self.rel(1.0 / length, q);
        self.product3(v * reciprocal)
    }
}

/// `SphericalTriangle::sample_real`'s operations in `f64`, each result passed through
/// `r` (its slot), so that one rounding at a time can be put back.
fn sample_with(r: &mut Roundings, inputs: &SamplerInputs, u1: f64, u2: f64) -> DVec3 {
    use std::f64::consts::{PI, SQRT_2, TAU};
    let (u, q, w) = r.roundoff;
    let a = r.abs3(inputs.dir[0], inputs.dir_error[0]);
    let b = r.abs3(inputs.dir[1], inputs.dir_error[1]);
    let c = r.abs3(inputs.dir[2], inputs.dir_error[2]);
    let volume = r.abs(inputs.volume, inputs.volume_error);
    let omega_turns = r.rel(inputs.omega_turns, inputs.omega_error);
    // The angle at A: two cross products (each component u (|xy| + |zw|) + u |result|, a
    // vector at most u (sqrt 2 + |x cross y|) long) and their dot.
    let (ab, ac) = (a.cross(b), a.cross(c));
    let (sc, sb) = (ab.length(), ac.length());
    let cos_part = r.abs(
        ab.dot(ac),
        u * (sb * (SQRT_2 + sc) + sc * (SQRT_2 + sb) + 3.0 * sb * sc),
    );
    let sin_part = volume.abs();
    let alpha_turns = r.abs(
        sin_part.atan2(cos_part) / TAU,
        atan2_turns_error(sin_part, cos_part, u, q),
    );
    let sin_alpha = r.rel(
        sin_part / (cos_part * cos_part + sin_part * sin_part).sqrt(),
        u + w + q,
    );
    let sub_area_turns = r.rel(u1 * omega_turns, u);
    // `cos_sin_turns` is within 4 u of the exact sine (tested under every model).
    let s = r.abs((PI * sub_area_turns).sin(), 4.0 * u);
    let phi_turns = sub_area_turns - alpha_turns;
    let phi_turns = r.abs(phi_turns, u * phi_turns.abs());
    let sin_phi = r.abs((TAU * phi_turns).sin(), 4.0 * u);
    let chord_ab = r.sum3(a - b);
    let m = r.rel(0.5 * chord_ab.dot(chord_ab), 3.0 * u);
    let two_s2 = r.rel(2.0 * s * s, u);
    let two_minus_m = r.abs(2.0 - m, u * (2.0 - m).abs());
    let numerator = r.rel(two_s2 * two_minus_m, u);
    let p = r.rel(m * sin_alpha * sin_phi, 2.0 * u);
    let denominator = r.abs(two_s2 - p, u * (two_s2 - p).abs());
    let one_minus_q = r.rel(numerator / denominator, q);
    let one_minus_q = if one_minus_q > 0.0 {
        one_minus_q.min(2.0)
    } else {
        0.0
    };
    let c_prime = r.arc_toward(a, c, one_minus_q);
    let chord = r.sum3(b - c_prime);
    let half = r.rel(0.5 * chord.dot(chord), 3.0 * u);
    let one_minus_cos = r.rel(u2 * half, u);
    let direction = r.arc_toward(b, c_prime, one_minus_cos);
    r.normalize(direction)
}

/// The sampled direction for (u1, u2) computed exactly from the `f32` inputs with the vertex
/// `first` (0, 1 or 2 for p0, p1, p2) taken as A, the vertices after it in cyclic order.
pub fn sample_direction_exact(
    x: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    first: usize,
    (u1, u2): (f32, f32),
) -> DVec3 {
    let (inputs, mut r) = exact_pass(x, p0, e1, e2, first, crate::device_class::IEEE_ROUNDOFF);
    sample_with(&mut r, &inputs, u1 as f64, u2 as f64)
}

/// The sampler's inputs in the arithmetic `roundoff` with `first` taken as A, and the
/// [`Roundings`] of an exact pass that records the allowances.
fn exact_pass(
    x: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    first: usize,
    roundoff: (f64, f64, f64),
) -> (SamplerInputs, Roundings) {
    let mut inputs = sampler_inputs(x, p0, e1, e2, roundoff);
    inputs.dir.rotate_left(first);
    inputs.dir_error.rotate_left(first);
    let r = Roundings {
        roundoff,
        allowances: Vec::new(),
        recording: true,
        next: 0,
        moved: None,
    };
    (inputs, r)
}

/// The sampled direction for (u1, u2) computed exactly from the `f32` inputs, and its
/// first-order error per component for one computation in the arithmetic `roundoff`: the sum,
/// over every operation of the sampler and every input it takes from the view, of how far that
/// one rounding at its allowance moves the direction (evaluated in `f64`, each rounding put back
/// alone, up and down, the larger kept). The allowances are those of the operations: u for a
/// sum, a product or a component of either, 3 u of the terms' magnitudes for a dot product,
/// q for a quotient, w for a root, 4 u for `cos_sin_turns`, [`atan2_turns_error`] for the
/// angle at A, the view's own bounds for its directions, triple product and solid angle. Where
/// the sampler's map is steep (u1 near 0, a thin spherical triangle) one rounding's effect
/// is taken as it is, not its derivative. `first` is the vertex (0, 1 or 2 for p0, p1, p2) the
/// computation took as A (`SphericalTriangle::sampling_order`, whose comparisons a device's
/// roundings may decide otherwise than exact arithmetic would near a tie, so the caller says).
pub fn sample_direction_error(
    x: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    first: usize,
    (u1, u2): (f32, f32),
    roundoff: (f64, f64, f64),
) -> (DVec3, DVec3) {
    let (inputs, mut r) = exact_pass(x, p0, e1, e2, first, roundoff);
    let (u1, u2) = (u1 as f64, u2 as f64);
    let exact = sample_with(&mut r, &inputs, u1, u2);
    r.recording = false;
    let mut bound = DVec3::ZERO;
    for slot in 0..r.allowances.len() {
        let mut moved = DVec3::ZERO;
        for sign in [1.0, -1.0] {
            r.next = 0;
            r.moved = Some((slot, sign));
            moved = moved.max((sample_with(&mut r, &inputs, u1, u2) - exact).abs());
        }
        bound += moved;
    }
    (exact, bound)
}

/// How far apart one IEEE and one Vulkan computation of the solid angle may be, relative to
/// it: the two computations' [`solid_angle_error`]s (infinite where the solid angle is 0).
pub fn solid_angle_apart(x: [f32; 3], p0: [f32; 3], e1: [f32; 3], e2: [f32; 3]) -> f64 {
    use crate::device_class::{IEEE_ROUNDOFF, VULKAN_ROUNDOFF};
    [IEEE_ROUNDOFF, VULKAN_ROUNDOFF]
        .iter()
        .map(|&r| solid_angle_error(x, p0, e1, e2, r))
        .sum()
}

/// How far apart two computations of the solid angle may be, in steradians: the
/// [`solid_angle_error_absolute`]s of an IEEE one and of one in `other` (IEEE for lavapipe's
/// class, Vulkan for any device's).
pub fn solid_angle_apart_absolute(
    x: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    other: (f64, f64, f64),
) -> f64 {
    use crate::device_class::IEEE_ROUNDOFF;
    solid_angle_error_absolute(x, p0, e1, e2, IEEE_ROUNDOFF)
        + solid_angle_error_absolute(x, p0, e1, e2, other)
}

/// How far apart one IEEE and one Vulkan computation of a triangle light's spherical sample
/// (`light::triangle::sample` where `spherical_triangle_used` says so) may be, for the triangle
/// p0, p0 + e1, p0 + e2, the receiver x and (u1, u2).
#[derive(Clone, Copy, Debug)]
pub struct SphericalSampleApart {
    /// The point's distance, from the directions' bounds ([`sample_direction_error`] under
    /// both arithmetics) carried to where the direction meets the plane: a direction off by
    /// delta (radians) moves that point by t delta / |cos|, t the distance along the exact
    /// direction and cos its cosine with the plane's normal, and the clamp onto the triangle
    /// moves it by at most 2 / sin(theta_min) of that (barycentric coordinates clamped against
    /// world distances, theta_min the triangle's smallest angle). The plane step's own
    /// rounding is the caller's (the IEEE-class term).
    pub point: f64,
    /// The solid angle's (and so the density's, 1 / omega) relative distance
    /// ([`solid_angle_apart`]).
    pub solid_angle_relative: f64,
    /// Whether either computation may take another vertex as A (the two smallest of the dot
    /// products opposite the vertices within their roundings of each other): its sample is then
    /// another point of the same distribution, anywhere on the triangle.
    pub order_may_differ: bool,
}

/// [`SphericalSampleApart`] of the record: meaningful where the exact view samples the triangle
/// as a spherical triangle (the caller's decision).
pub fn spherical_sample_apart(
    x: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    (u1, u2): (f32, f32),
) -> SphericalSampleApart {
    use crate::device_class::{IEEE_ROUNDOFF, VULKAN_ROUNDOFF};
    let roundoffs = [IEEE_ROUNDOFF, VULKAN_ROUNDOFF];
    // The dot product opposite vertex i and how far each computation may put it: the two
    // directions' component errors and the dot's own 3 u.
    let inputs = roundoffs.map(|r| sampler_inputs(x, p0, e1, e2, r));
    let dir = inputs[0].dir;
    let opposite = |i: usize| dir[(i + 1) % 3].dot(dir[(i + 2) % 3]);
    let opposite_error = |i: usize| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        inputs
            .iter()
            .zip(roundoffs)
            .map(|(s, r)| {
                s.dir_error[j].dot(dir[k].abs()) + s.dir_error[k].dot(dir[j].abs()) + 3.0 * r.0
            })
            .sum::<f64>()
    };
    let mut by_dot = [0, 1, 2];
    by_dot.sort_by(|&i, &j| opposite(i).total_cmp(&opposite(j)));
    let first = by_dot[0];
    let order_may_differ = opposite(by_dot[1]) - opposite(by_dot[0])
        <= opposite_error(by_dot[0]) + opposite_error(by_dot[1]);
    // The exact direction (the same from either arithmetic's pass) and the two bounds.
    let [(exact, ieee_bound), (_, vulkan_bound)] =
        roundoffs.map(|r| sample_direction_error(x, p0, e1, e2, first, (u1, u2), r));
    let direction_apart = ieee_bound.length() + vulkan_bound.length();
    let solid_angle_relative = solid_angle_apart(x, p0, e1, e2);
    let (e1, e2) = (d3(e1), d3(e2));
    let n = e1.cross(e2).normalize();
    let to_plane = (d3(p0) - d3(x)).dot(n);
    let cos = exact.dot(n).abs();
    let t = to_plane.abs() / cos;
    let sin_angle = |a: DVec3, b: DVec3| a.cross(b).length() / (a.length() * b.length());
    let sin_min = sin_angle(e1, e2)
        .min(sin_angle(-e1, e2 - e1))
        .min(sin_angle(-e2, e1 - e2));
    SphericalSampleApart {
        point: t * direction_apart / cos * 2.0 / sin_min,
        solid_angle_relative,
        order_may_differ,
    }
}

/// Whether the triangle p0, p0 + e1, p0 + e2 seen from x is sampled as a spherical triangle
/// (`SphericalTriangle::sampled`) in one IEEE and one Vulkan computation alike: `Some` of that
/// decision, or `None` where they may decide otherwise. The decision is a conjunction (the
/// solid angle within [`MIN_SOLID_ANGLE`, `MAX_SOLID_ANGLE`], the triple product at least
/// `MIN_VOLUME_PER_SOLID_ANGLE` omega), so it is certainly false where one condition is false
/// beyond the two computations' bounds ([`solid_angle_error`], the view's triple-product
/// bound), certainly true where both hold beyond them, and open otherwise.
pub fn sampled_decision(x: [f32; 3], p0: [f32; 3], e1: [f32; 3], e2: [f32; 3]) -> Option<bool> {
    use crate::device_class::{IEEE_ROUNDOFF, VULKAN_ROUNDOFF};
    use kernel::spherical_triangle::{
        MAX_SOLID_ANGLE, MIN_SOLID_ANGLE, MIN_VOLUME_PER_SOLID_ANGLE,
    };
    let roundoffs = [IEEE_ROUNDOFF, VULKAN_ROUNDOFF];
    let omega = solid_angle_exact(x, p0, e1, e2);
    let omega_relative = solid_angle_apart(x, p0, e1, e2);
    // Whether `value >= threshold` in both computations (`Some`), or may differ (`None`).
    let at_least = |value: f64, threshold: f64, apart: f64| {
        if !((value - threshold).abs() <= apart) && value.is_finite() {
            Some(value >= threshold)
        } else if value.is_finite() && apart.is_finite() {
            None
        } else {
            // A 0 solid angle (its relative bound infinite) is 0 in both: below every threshold.
            Some(false)
        }
    };
    let views = roundoffs.map(|(u, q, w)| view(x, p0, e1, e2, u, q, w));
    let volume_apart: f64 = views.iter().map(|v| v.volume_error).sum();
    let min_volume = MIN_VOLUME_PER_SOLID_ANGLE as f64 * omega;
    let omega_apart = omega * omega_relative;
    let conditions = [
        at_least(omega, MIN_SOLID_ANGLE as f64, omega_apart),
        at_least(MAX_SOLID_ANGLE as f64, omega, omega_apart),
        at_least(
            views[0].volume.abs(),
            min_volume,
            volume_apart + min_volume * omega_relative,
        ),
    ];
    if conditions.contains(&Some(false)) {
        Some(false)
    } else if conditions.contains(&None) {
        None
    } else {
        Some(true)
    }
}
