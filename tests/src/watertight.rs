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
    let a = dir_f32.abs();
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
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    // Keep the winding: a negative dominant component mirrors the frame.
    if dir_f32[kz] < 0.0 {
        core::mem::swap(&mut kx, &mut ky);
    }
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
