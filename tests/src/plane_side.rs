//! The exact answer to the plane-side test (`kernel::plane_side`), for the tests that hold the
//! kernel's `f32` answer to it (`vulkan_precision.rs` under every arithmetic, `gpu_functions.rs`
//! on the device).

use glam::{DVec3, Vec3};

/// The exact side and direction of a ray against a triangle's plane, with the first-order error
/// counts of their `f32` computation.
pub struct Exact {
    /// (o - p0) . N, N the cross product of the device's triangle's edges (p1 - p0, p2 - p0 with
    /// p1 = fl(p0 + edge1), p2 = fl(p0 + edge2), as the host uploads them).
    pub side: f64,
    /// d . N.
    pub toward: f64,
    /// How far the kernel's `f32` side may be from `side` to first order under Vulkan's
    /// arithmetic, without the spare its constants carry: 6 eps of the permanent of o - p0
    /// and the record's edges, plus twice the vertices' rounding.
    pub side_count: f64,
    /// The same for `toward`: 5 eps of d's permanent, plus twice the vertices' rounding.
    pub toward_count: f64,
}

/// [`Exact`] for the ray `o + t d` and the triangle record (`p0`, `e1`, `e2`), from `f64`
/// arithmetic; `None` where `f64`'s own rounding (8 of its eps of the permanents) could flip
/// the sign of either.
pub fn exact(o: Vec3, d: Vec3, p0: Vec3, e1: Vec3, e2: Vec3) -> Option<Exact> {
    let p1 = (p0 + e1).as_dvec3() - p0.as_dvec3();
    let p2 = (p0 + e2).as_dvec3() - p0.as_dvec3();
    let a = o.as_dvec3() - p0.as_dvec3();
    let n = p1.cross(p2);
    let perm = |x: DVec3, y: DVec3| {
        DVec3::new(
            (x.y * y.z).abs() + (x.z * y.y).abs(),
            (x.z * y.x).abs() + (x.x * y.z).abs(),
            (x.x * y.y).abs() + (x.y * y.x).abs(),
        )
    };
    let exact_perm = perm(p1, p2);
    let (side, toward) = (a.dot(n), d.as_dvec3().dot(n));
    let f64_error = |f: DVec3| 8.0 * f64::EPSILON * f.abs().dot(exact_perm);
    if side.abs() <= f64_error(a) || toward.abs() <= f64_error(d.as_dvec3()) {
        return None;
    }
    // The counts the constants carry a spare over: 6 and 5 roundings of the permanent of the
    // record's edges, and twice the vertices' rounding.
    let eps = f32::EPSILON as f64;
    let (e1d, e2d) = (e1.as_dvec3(), e2.as_dvec3());
    let vertex = |p: f64, e: f64| {
        if e.abs() <= 0.49 * p.abs() {
            0.0
        } else {
            (0.5 * eps * (p.abs() + e.abs())).min(e.abs())
        }
    };
    let rounding = |e: DVec3| {
        let p = p0.as_dvec3();
        DVec3::new(vertex(p.x, e.x), vertex(p.y, e.y), vertex(p.z, e.z))
    };
    let (r1, r2) = (rounding(e1d), rounding(e2d));
    let vertices = perm(r1, e2d.abs()) + perm(e1d.abs(), r2);
    let edges = perm(e1d, e2d);
    let count = |f: DVec3, k: f64| k * eps * f.abs().dot(edges) + 2.0 * f.abs().dot(vertices);
    Some(Exact {
        side,
        toward,
        side_count: count(a, 6.0),
        toward_count: count(d.as_dvec3(), 5.0),
    })
}

impl Exact {
    /// Whether the exact ray leaves the plane: off it, and not toward it.
    pub fn leaves(&self) -> bool {
        self.side * self.toward > 0.0
    }
}
