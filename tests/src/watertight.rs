//! A model of the triangle test a GPU runs in `traceRay`: the watertight test of Woop, Benthin
//! and Wald ("Watertight Ray/Triangle Intersection", JCGT 2(1), 2013), written here from the
//! paper over [`Real`], so that the re-intersection tests can run it in IEEE single precision
//! (`f32`) and under the model of Vulkan's arithmetic (`vulkan_arithmetic::Vk32`).
//!
//! Why a model: on the GPU the device's own test decides whether a ray leaving a triangle meets
//! it again, not the kernel's Moller-Trumbore, and Vulkan specifies no precision for it.
//! lavapipe's follows this paper but forms the edge functions and t in double precision (Mesa,
//! `lvp_build_intersect_ray_tri`), radv's software path in single precision as here; an RTX
//! GPU's is not published. A watertight test decides inside/outside by the signs of three 2-D
//! edge functions in the plane normal to the ray, which is what makes it watertight, and the
//! distance by interpolating the vertices' depths with them, which is what makes its distance
//! error grow with the triangle's elongation (`docs/robustness.md`, "Needles under a watertight
//! test", where the kernel's offset is derived to clear it).
//!
//! Invariant: the operations are the paper's, in its order; a zero edge function is not
//! recomputed in double precision (the paper's optional fallback), so an edge is decided in
//! single precision as a device without doubles would.

use glam::Vec3;
use kernel::real::{Real, V3};

/// Component `k` (0, 1, 2 for x, y, z) of `v`.
fn axis<R: Real>(v: V3<R>, k: usize) -> R {
    match k {
        0 => v.x,
        1 => v.y,
        _ => v.z,
    }
}

/// The watertight test's frame for a ray along `dir`: (kx, ky, kz), kz the axis of `dir`'s
/// largest component and kx, ky the next two in cyclic order, swapped where that component is
/// negative so that the frame keeps the triangle's winding.
fn ray_axes(dir: Vec3) -> (usize, usize, usize) {
    let a = dir.abs();
    let kz = if a.x > a.y {
        if a.x > a.z {
            0
        } else {
            2
        }
    } else if a.y > a.z {
        1
    } else {
        2
    };
    let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if dir[kz] < 0.0 {
        (ky, kx, kz)
    } else {
        (kx, ky, kz)
    }
}

/// The ray `origin + t dir` against the triangle with vertices `p`: its t where t is in
/// (`t_min`, `t_max`) and the ray meets the triangle (either face), else `None`. `dir_f32` is
/// `dir` as data, which picks the ray's dominant axis (a comparison of magnitudes, exact in any
/// arithmetic).
pub fn watertight_triangle<R: Real + Into<f32>>(
    origin: V3<R>,
    dir: V3<R>,
    dir_f32: Vec3,
    p: [V3<R>; 3],
    t_min: f32,
    t_max: f32,
) -> Option<f32> {
    let (kx, ky, kz) = ray_axes(dir_f32);
    let dz = axis(dir, kz);
    let sx = axis(dir, kx) / dz;
    let sy = axis(dir, ky) / dz;
    let sz = R::splat(1.0) / dz;
    let rel = p.map(|q| q - origin);
    let sheared = rel.map(|q| {
        (
            axis(q, kx) - sx * axis(q, kz),
            axis(q, ky) - sy * axis(q, kz),
        )
    });
    let [(ax, ay), (bx, by), (cx, cy)] = sheared;
    let u: f32 = (cx * by - cy * bx).into();
    let v: f32 = (ax * cy - ay * cx).into();
    let w: f32 = (bx * ay - by * ax).into();
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let (ur, vr, wr) = (R::splat(u), R::splat(v), R::splat(w));
    let det = ur + vr + wr;
    let det_f: f32 = det.into();
    if det_f == 0.0 || !det_f.is_finite() {
        return None;
    }
    let [az, bz, cz] = rel.map(|q| sz * axis(q, kz));
    let t: f32 = ((ur * az + vr * bz + wr * cz) / det).into();
    (t > t_min && t < t_max && t.is_finite()).then_some(t)
}

/// Whether the watertight test could meet the triangle with vertices `p` on the ray
/// `origin + t dir` at some t in (0, `t_max`) if every rounding it makes were as large as
/// Vulkan's rules allow (unit roundoff eps, quotients within 2.5 ULP) and all fell the way that
/// brings the triangle toward the ray's origin: the derivation of the kernel's offset
/// (`docs/robustness.md`, "Needles under a watertight test") played out by an adversary, in
/// `f64`. `toward_origin` is the triangle's unit normal on the origin's side.
///
/// The adversary moves each vertex as the test's roundings may (its difference from the
/// origin, the shear and the depths: 2 eps |A_kx| + 4.5 eps |S_x| |A_k| along the axis kx, the
/// same along ky, eps |A_k| along k, 4 eps |A_k| / |d_k| along the ray, each toward
/// `toward_origin`'s side), then errs each edge function by 2 eps |P_j| |P_k| in the direction
/// that raises t, and reports a hit where the three keep one sign and t > 0.
pub fn worst_case_watertight_hit(
    origin: Vec3,
    dir: Vec3,
    p: [Vec3; 3],
    toward_origin: Vec3,
    t_max: f32,
) -> bool {
    let eps = f32::EPSILON as f64;
    let (o, d, n) = (origin.as_dvec3(), dir.as_dvec3(), toward_origin.as_dvec3());
    let (kx, ky, kz) = ray_axes(dir);
    let (sx, sy) = (d[kx] / d[kz], d[ky] / d[kz]);
    let unit = |k: usize| glam::DVec3::AXES[k];
    let toward = |axis: glam::DVec3| if axis.dot(n) >= 0.0 { axis } else { -axis };
    let moved = p.map(|q| {
        let rel = q.as_dvec3() - o;
        let (ax, ay, ak) = (rel[kx].abs(), rel[ky].abs(), rel[kz].abs());
        let m = toward(unit(kx)) * eps * (2.0 * ax + 4.5 * sx.abs() * ak)
            + toward(unit(ky)) * eps * (2.0 * ay + 4.5 * sy.abs() * ak)
            + toward(unit(kz)) * eps * ak
            + toward(d) * eps * 4.0 * ak / d[kz].abs();
        rel + m
    });
    let sheared = moved.map(|r| (r[kx] - sx * r[kz], r[ky] - sy * r[kz], r[kz] / d[kz]));
    let [(ax, ay, az), (bx, by, bz), (cx, cy, cz)] = sheared;
    let exact = [cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax];
    let norm = [ax.hypot(ay), bx.hypot(by), cx.hypot(cy)];
    let size: [f64; 3] = core::array::from_fn(|i| norm[(i + 1) % 3] * norm[(i + 2) % 3]);
    let depth = [az, bz, cz];
    let det: f64 = exact.iter().sum();
    if det == 0.0 {
        return false;
    }
    let t = exact.iter().zip(depth).map(|(e, z)| e * z).sum::<f64>() / det;
    // dt / dU_i = (Z_i - t) / det: each error pushed the way that raises t.
    let edges: [f64; 3] =
        core::array::from_fn(|i| exact[i] + 2.0 * eps * size[i] * ((depth[i] - t) / det).signum());
    let inside = edges.iter().all(|&e| e >= 0.0) || edges.iter().all(|&e| e <= 0.0);
    let det: f64 = edges.iter().sum();
    if !inside || det == 0.0 {
        return false;
    }
    let t = edges.iter().zip(depth).map(|(e, z)| e * z).sum::<f64>() / det;
    t > 0.0 && t < t_max as f64
}
