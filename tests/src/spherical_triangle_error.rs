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
    (u, q, w): (f64, f64, f64),
) -> f64 {
    let v = view(x, p0, e1, e2, u, q, w);
    let (y, d) = (v.volume.abs(), v.denominator);
    let half = y.atan2(d);
    let moved = (d.abs() * v.volume_error + y * v.denominator_error) / (y * y + d * d);
    let half_turns = half / std::f64::consts::TAU;
    let turns_error = moved / std::f64::consts::TAU + atan2_turns_error(y, d, u, q);
    turns_error / half_turns + u + 0.5 * f32::EPSILON as f64
}
