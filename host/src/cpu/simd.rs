//! One ray against N boxes or four triangles at once (`std::simd`; the BVH uses 8 box lanes,
//! one AVX2 instruction per step where the CPU has it, two SSE ones elsewhere). The triangle
//! and sphere tests are the kernel's (`kernel::intersect`) instantiated on SIMD lanes, so each
//! lane's result is bit-identical to the scalar one (Rust never contracts a * b + c into a
//! fused multiply-add); `tests/tests/properties.rs` checks this on random and degenerate
//! triangles.

use glam::Vec3;
use kernel::intersect;
use kernel::real::V3;
use std::simd::cmp::SimdPartialOrd;
use std::simd::num::SimdFloat;
use std::simd::{f32x4, Mask, Select, Simd};

/// 1 + 2 gamma(3): widening of a slab test's far distance so rounding never culls a box the
/// ray touches (pbrt-v4 6.8.2; gamma(n) = n u / (1 - n u), u = 2^-24).
pub const SLAB_PAD: f32 = 1.0 + 2.0 * (3.0 * 5.960_464_5e-8) / (1.0 - 3.0 * 5.960_464_5e-8);

/// N boxes, one per lane, as per-axis lower and upper bounds.
#[derive(Clone, Copy, Debug)]
pub struct Boxes<const N: usize> {
    pub min: [Simd<f32, N>; 3],
    pub max: [Simd<f32, N>; 3],
}

/// Four triangles, one per lane, as the kernel stores them: p0 and the two edges.
#[derive(Clone, Copy, Debug)]
pub struct Triangles4 {
    pub p0: [f32x4; 3],
    pub edge1: [f32x4; 3],
    pub edge2: [f32x4; 3],
}

/// Four spheres, one per lane.
#[derive(Clone, Copy, Debug)]
pub struct Spheres4 {
    pub center: [f32x4; 3],
    pub radius: f32x4,
}

/// A ray with its components broadcast to every lane.
#[derive(Clone, Copy, Debug)]
pub struct Ray4 {
    pub origin: [f32x4; 3],
    pub dir: [f32x4; 3],
    /// Component-wise 1 / dir (infinite for zero components).
    pub inv_dir: [f32; 3],
    pub origin_xyz: [f32; 3],
    /// Whether some 1 / dir component is infinite, so that the slab test can meet 0 x inf.
    pub parallel: bool,
}

impl Ray4 {
    pub fn new(origin: Vec3, dir: Vec3) -> Ray4 {
        let inv = dir.recip();
        let s = |v: Vec3| [f32x4::splat(v.x), f32x4::splat(v.y), f32x4::splat(v.z)];
        Ray4 {
            origin: s(origin),
            dir: s(dir),
            inv_dir: inv.to_array(),
            origin_xyz: origin.to_array(),
            parallel: !inv.is_finite(),
        }
    }

    /// The slab test against four boxes: each lane's entry distance (clamped at 0) and whether
    /// the ray enters that box within (0, t_max]; boxes are closed, and the far distance is
    /// widened by [`SLAB_PAD`].
    ///
    /// A ray parallel to an axis (1/d infinite) meets 0 x inf = NaN when its origin lies on a
    /// face's plane: it then runs inside that closed slab for every t, so that axis must not
    /// narrow the interval. Such rays take a branch that says so (`tests/tests/bvh.rs` has
    /// rays along triangle edges lying in box faces); for the others no NaN can arise, and
    /// min/max are single instructions (minps/maxps).
    #[inline(always)]
    pub fn slab<const N: usize>(&self, b: &Boxes<N>, t_max: f32) -> (Simd<f32, N>, Mask<i32, N>) {
        let [ox, oy, oz] = self.origin_xyz;
        let [ix, iy, iz] = self.inv_dir;
        slab_lanes(
            &[Simd::splat(ox), Simd::splat(oy), Simd::splat(oz)],
            &[Simd::splat(ix), Simd::splat(iy), Simd::splat(iz)],
            b,
            Simd::splat(t_max),
            [self.parallel; 3],
        )
    }

    /// Moller-Trumbore against four triangles (the kernel's `intersect_triangle_uv`, lane by
    /// lane): each lane's t where it hits within (t_min, t_max), else -1.
    #[inline(always)]
    pub fn triangles(&self, tri: &Triangles4, t_min: f32, t_max: f32) -> f32x4 {
        triangle_lanes(
            &self.origin,
            &self.dir,
            &tri.p0,
            &tri.edge1,
            &tri.edge2,
            f32x4::splat(t_min),
            f32x4::splat(t_max),
        )
    }

    /// The kernel's `intersect_sphere` against four spheres, lane by lane: each lane's nearest
    /// root in (t_min, t_max), else -1. A lane with a NaN centre never hits (a block's padding).
    #[inline(always)]
    pub fn spheres(&self, s: &Spheres4, t_min: f32, t_max: f32) -> f32x4 {
        sphere_lanes(
            &self.origin,
            &self.dir,
            &s.center,
            s.radius,
            f32x4::splat(t_min),
            f32x4::splat(t_max),
        )
    }
}

/// The slab test on N lanes, each lane a ray (origin, 1 / dir) against a box (`b`'s lane):
/// the entry distance (clamped at 0) and whether the ray enters the box within (0, t_max];
/// boxes are closed, and the far distance is widened by [`SLAB_PAD`]. Either side may be
/// broadcast: one ray against N boxes ([`Ray4::slab`]) or N rays against one box
/// (`cpu::bvh_packet`), so both make the same verdict for the same ray and box. Where
/// `parallel[axis]` (some lane's 1 / dir is infinite on that axis), a NaN from 0 x inf (an
/// origin on a face's plane) leaves that axis's interval open, as [`Ray4::slab`] explains.
#[inline(always)]
pub fn slab_lanes<const N: usize>(
    origin: &[Simd<f32, N>; 3],
    inv_dir: &[Simd<f32, N>; 3],
    b: &Boxes<N>,
    t_max: Simd<f32, N>,
    parallel: [bool; 3],
) -> (Simd<f32, N>, Mask<i32, N>) {
    let mut near = Simd::splat(0.0);
    let mut far = t_max;
    for axis in 0..3 {
        let t0 = (b.min[axis] - origin[axis]) * inv_dir[axis];
        let t1 = (b.max[axis] - origin[axis]) * inv_dir[axis];
        let mut axis_near = min_or_second(t0, t1);
        let mut axis_far = max_or_second(t0, t1);
        if parallel[axis] {
            let on_plane = t0.is_nan() | t1.is_nan();
            axis_near = on_plane.select(Simd::splat(f32::NEG_INFINITY), axis_near);
            axis_far = on_plane.select(Simd::splat(f32::INFINITY), axis_far);
        }
        near = max_or_second(axis_near, near);
        far = min_or_second(axis_far, far);
    }
    let far = far * Simd::splat(SLAB_PAD);
    (near, near.simd_le(far))
}

/// [`triangle_lanes_uv`]'s t only.
#[inline(always)]
pub fn triangle_lanes<const N: usize>(
    origin: &[Simd<f32, N>; 3],
    dir: &[Simd<f32, N>; 3],
    p0: &[Simd<f32, N>; 3],
    edge1: &[Simd<f32, N>; 3],
    edge2: &[Simd<f32, N>; 3],
    t_min: Simd<f32, N>,
    t_max: Simd<f32, N>,
) -> Simd<f32, N> {
    triangle_lanes_uv(origin, dir, p0, edge1, edge2, t_min, t_max).0
}

/// The kernel's [`kernel::intersect::triangle`] on N lanes: each lane's t where its ray hits
/// its triangle within (t_min, t_max), else -1, and the barycentrics u, v (meaningful where
/// t >= 0). Either side may be broadcast: one ray against N triangles ([`Ray4::triangles`]) or
/// N rays against one triangle (`cpu::packet`).
#[inline(always)]
pub fn triangle_lanes_uv<const N: usize>(
    origin: &[Simd<f32, N>; 3],
    dir: &[Simd<f32, N>; 3],
    p0: &[Simd<f32, N>; 3],
    edge1: &[Simd<f32, N>; 3],
    edge2: &[Simd<f32, N>; 3],
    t_min: Simd<f32, N>,
    t_max: Simd<f32, N>,
) -> (Simd<f32, N>, Simd<f32, N>, Simd<f32, N>) {
    intersect::triangle(
        v3(origin),
        v3(dir),
        v3(p0),
        v3(edge1),
        v3(edge2),
        t_min,
        t_max,
    )
}

/// The kernel's [`kernel::intersect::sphere`] on N lanes: each lane's nearest root in
/// (t_min, t_max), else -1.
#[inline(always)]
pub fn sphere_lanes<const N: usize>(
    origin: &[Simd<f32, N>; 3],
    dir: &[Simd<f32, N>; 3],
    center: &[Simd<f32, N>; 3],
    radius: Simd<f32, N>,
    t_min: Simd<f32, N>,
    t_max: Simd<f32, N>,
) -> Simd<f32, N> {
    intersect::sphere(v3(origin), v3(dir), v3(center), radius, t_min, t_max)
}

/// Three lane vectors as the kernel's [`V3`].
#[inline(always)]
fn v3<const N: usize>(c: &[Simd<f32, N>; 3]) -> V3<Simd<f32, N>> {
    V3::new(c[0], c[1], c[2])
}

/// Lane-wise a < b ? a : b: the second operand wherever either is NaN (x86 minps).
#[inline(always)]
pub fn min_or_second<const N: usize>(a: Simd<f32, N>, b: Simd<f32, N>) -> Simd<f32, N> {
    a.simd_lt(b).select(a, b)
}

/// Lane-wise a > b ? a : b: the second operand wherever either is NaN (x86 maxps).
#[inline(always)]
pub fn max_or_second<const N: usize>(a: Simd<f32, N>, b: Simd<f32, N>) -> Simd<f32, N> {
    a.simd_gt(b).select(a, b)
}

/// Defines method `$name` that runs `$any_cpu` (an `#[inline(always)]` method taking the same
/// arguments, written with `std::simd`) compiled for the widest SIMD this CPU has, detected at
/// run time: AVX-512F (method `$avx512`: sixteen `f32` lanes in one register), AVX2 (`$avx2`:
/// two 8-lane registers), or the baseline. Every variant performs the same lane-wise IEEE
/// operations (no FMA), so all give the same results.
macro_rules! widest_simd {
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident(&self $(, $arg:ident: $ty:ty)*) -> $out:ty
        = $any_cpu:ident, $avx512:ident, $avx2:ident
    ) => {
        $(#[$attr])*
        $vis fn $name(&self $(, $arg: $ty)*) -> $out {
            #[cfg(target_arch = "x86_64")]
            if std::is_x86_feature_detected!("avx512f") {
                // SAFETY: the CPU has AVX-512F (checked just above).
                return unsafe { self.$avx512($($arg),*) };
            }
            #[cfg(target_arch = "x86_64")]
            if std::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has AVX2 (checked just above).
                return unsafe { self.$avx2($($arg),*) };
            }
            self.$any_cpu($($arg),*)
        }

        #[doc = concat!("`", stringify!($name), "` for CPUs with AVX-512F.")]
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx512f")]
        unsafe fn $avx512(&self $(, $arg: $ty)*) -> $out {
            self.$any_cpu($($arg),*)
        }

        #[doc = concat!("`", stringify!($name), "` for CPUs with AVX2.")]
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        unsafe fn $avx2(&self $(, $arg: $ty)*) -> $out {
            self.$any_cpu($($arg),*)
        }
    };
}
pub(crate) use widest_simd;
