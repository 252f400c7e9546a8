//! Sub-triangle bins of a triangle for chi-square tests of light samplers in solid angle: the
//! regular subdivision of its barycentric (u, v) domain into N^2 sub-triangles, the bin of a
//! point, where a ray meets the triangle's plane, and a triangle's solid angle, all in `f64`
//! (`tests/tests/triangle_lights.rs`, `tests/tests/vulkan_precision.rs`).

use glam::DVec3;

/// The solid angle of the triangle `p` seen from `x`, in f64: Van Oosterom and Strackee (1983),
/// tan(omega / 2) = |a . (b x c)| / (|a||b||c| + (a . b)|c| + (a . c)|b| + (b . c)|a|) with
/// a, b, c the vectors from x to the vertices.
pub fn solid_angle_f64(x: DVec3, p: [DVec3; 3]) -> f64 {
    let [a, b, c] = p.map(|v| v - x);
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c)).abs();
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}

/// Sub-triangles along each edge: N^2 bins.
pub const N: usize = 8;

/// The bin of a point of the triangle at barycentric (u, v): one of the N^2 sub-triangles of
/// the regular subdivision (cell (i, j) of the (u, v) grid holds an upright sub-triangle and,
/// unless on the diagonal, an inverted one).
pub fn bin_of(u: f64, v: f64) -> usize {
    let (su, sv) = (u.clamp(0.0, 1.0) * N as f64, v.clamp(0.0, 1.0) * N as f64);
    let (mut i, mut j) = ((su as usize).min(N - 1), (sv as usize).min(N - 1));
    if i + j > N - 1 {
        // Rounding past the hypotenuse: the nearest upright cell on it.
        let excess = i + j - (N - 1);
        if i >= excess {
            i -= excess;
        } else {
            j -= excess;
        }
    }
    let inverted = (su - i as f64) + (sv - j as f64) > 1.0 && i + j < N - 1;
    2 * (i * N + j) + inverted as usize
}

/// The vertices, in barycentric (u, v), of every bin (index as [`bin_of`]; unused indices empty).
pub fn bins() -> Vec<Option<[(f64, f64); 3]>> {
    let mut out = vec![None; 2 * N * N];
    let s = 1.0 / N as f64;
    for i in 0..N {
        for j in 0..N - i {
            let (u, v) = (i as f64 * s, j as f64 * s);
            out[2 * (i * N + j)] = Some([(u, v), (u + s, v), (u, v + s)]);
            if i + j < N - 1 {
                out[2 * (i * N + j) + 1] = Some([(u + s, v), (u + s, v + s), (u, v + s)]);
            }
        }
    }
    out
}

/// Barycentric (u, v) of the point where the ray x + t d meets the triangle's plane, in f64.
pub fn barycentrics(x: DVec3, d: DVec3, p: [DVec3; 3]) -> (f64, f64) {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let q = d.cross(e2);
    let det = e1.dot(q);
    let s = x - p[0];
    let u = s.dot(q) / det;
    let v = d.dot(s.cross(e1)) / det;
    (u, v)
}
