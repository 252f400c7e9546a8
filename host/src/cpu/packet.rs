//! Sixteen rays at once against every primitive of a small scene: SIMD over rays instead of
//! over boxes. Each primitive is broadcast to the sixteen lanes and tested with the same
//! lane-wise functions as the BVH's leaves (`simd::triangle_lanes`, `simd::sphere_lanes`), so
//! each lane's t is bit-identical to the kernel's scalar intersection of that ray.

use super::simd::{sphere_lanes, triangle_lanes_uv, widest_simd};
use glam::Vec3;
use kernel::scene::{Sphere, Triangle, NONE};
use std::simd::cmp::SimdPartialOrd;
use std::simd::{Mask, Select, Simd};

/// Rays per packet: one AVX-512 register of f32 (two AVX2 ones, four SSE ones).
pub const LANES: usize = 16;

type Lanes = Simd<f32, LANES>;
type Ids = Simd<u32, LANES>;

/// Sixteen rays, component by component.
#[derive(Clone, Copy, Debug)]
pub struct RayPacket {
    pub origin: [Lanes; 3],
    pub dir: [Lanes; 3],
}

impl RayPacket {
    /// Sixteen zero rays (direction 0: nothing is hit), to be filled with [`RayPacket::set`].
    pub fn zero() -> Self {
        Self {
            origin: [Lanes::splat(0.0); 3],
            dir: [Lanes::splat(0.0); 3],
        }
    }

    /// Makes lane `lane` the ray `origin + t dir`.
    #[inline(always)]
    pub fn set(&mut self, lane: usize, origin: Vec3, dir: Vec3) {
        for a in 0..3 {
            self.origin[a][lane] = origin[a];
            self.dir[a][lane] = dir[a];
        }
    }

    /// Lane `lane`'s ray: (origin, direction).
    #[inline(always)]
    pub fn lane(&self, lane: usize) -> (Vec3, Vec3) {
        let v = |c: &[Lanes; 3]| Vec3::new(c[0][lane], c[1][lane], c[2][lane]);
        (v(&self.origin), v(&self.dir))
    }

    /// Each lane's nearest root on the sphere (centre, radius) `s` in (0, t_max), else -1.
    #[inline(always)]
    fn sphere(&self, s: &[f32; 4], t_max: Lanes) -> Lanes {
        let center = splat3([s[0], s[1], s[2]]);
        let radius = Lanes::splat(s[3]);
        sphere_lanes(
            &self.origin,
            &self.dir,
            &center,
            radius,
            Lanes::splat(0.0),
            t_max,
        )
    }

    /// Each lane's t on the triangle (p0, edge1, edge2) `tri` in (0, t_max), else -1, and the
    /// barycentrics u, v.
    #[inline(always)]
    fn triangle(&self, tri: &[[f32; 3]; 3], t_max: Lanes) -> (Lanes, Lanes, Lanes) {
        let [p0, e1, e2] = tri.map(splat3);
        triangle_lanes_uv(
            &self.origin,
            &self.dir,
            &p0,
            &e1,
            &e2,
            Lanes::splat(0.0),
            t_max,
        )
    }
}

/// What a packet tracer found, lane by lane: the primitive (`NONE` for a miss; numbered as
/// its instance's mesh numbers it where `instance` is not `NONE`), its t, for a triangle of the
/// scene's own the barycentrics u, v of the hit (as the kernel's `intersect_triangle_uv`
/// computes them; 0 for spheres, misses and instances' triangles), and the instance hit
/// (`NONE` but in a scene with instances, `bvh_packet.rs`).
#[derive(Clone, Copy, Debug)]
pub struct PacketHits {
    pub prim: Ids,
    pub t: Lanes,
    pub u: Lanes,
    pub v: Lanes,
    pub instance: Ids,
}

/// What the packets of paths (`packet_paths.rs`) need of a scene: sixteen rays' closest hits
/// and their occlusion, lane by lane the one-ray answers. Lanes with t_max 0 have no ray.
pub trait PacketTracer: Sync {
    fn closest_hits(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits;
    fn occluded_lanes(&self, rays: &RayPacket, t_max: Lanes) -> Mask<i32, LANES>;
}

impl PacketTracer for SmallScene {
    fn closest_hits(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits {
        self.closest(rays, t_max)
    }
    fn occluded_lanes(&self, rays: &RayPacket, t_max: Lanes) -> Mask<i32, LANES> {
        self.occluded(rays, t_max)
    }
}

impl PacketHits {
    /// Sixteen misses: no primitive, t = t_max, barycentrics 0, no instance.
    #[inline(always)]
    pub fn miss(t_max: Lanes) -> Self {
        let zero = Lanes::splat(0.0);
        PacketHits {
            prim: Ids::splat(NONE),
            t: t_max,
            u: zero,
            v: zero,
            instance: Ids::splat(NONE),
        }
    }
}

/// Scenes with at most this many primitives are traced by packets without a hierarchy.
pub const MAX_PRIMITIVES: usize = 32;

/// Every primitive of a small scene, stored as the packet tests read them. Primitive ids are
/// the BVH's: spheres first, then triangles.
#[derive(Clone, Debug)]
pub struct SmallScene {
    spheres: Vec<[f32; 4]>,
    triangles: Vec<[[f32; 3]; 3]>,
}

fn splat3(v: [f32; 3]) -> [Lanes; 3] {
    [Lanes::splat(v[0]), Lanes::splat(v[1]), Lanes::splat(v[2])]
}

impl SmallScene {
    /// The packets' copy of a scene of at most [`MAX_PRIMITIVES`] primitives; `None` for a
    /// larger one (which keeps the BVH).
    pub fn if_small(spheres: &[Sphere], triangles: &[Triangle]) -> Option<SmallScene> {
        (spheres.len() + triangles.len() <= MAX_PRIMITIVES)
            .then(|| SmallScene::new(spheres, triangles))
    }

    pub fn new(spheres: &[Sphere], triangles: &[Triangle]) -> SmallScene {
        SmallScene {
            spheres: spheres
                .iter()
                .map(|s| [s.center[0], s.center[1], s.center[2], s.radius])
                .collect(),
            triangles: triangles.iter().map(|t| [t.p0, t.edge1, t.edge2]).collect(),
        }
    }

    widest_simd! {
        /// Each lane's closest hit in (0, t_max) (`NONE` and t_max for a miss). Of primitives at
        /// exactly the same t the first in id order wins.
        pub fn closest(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits
            = closest_any_cpu, closest_avx512, closest_avx2
    }

    #[inline(always)]
    fn closest_any_cpu(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits {
        let zero = Lanes::splat(0.0);
        let mut hits = PacketHits::miss(t_max);
        for (i, s) in self.spheres.iter().enumerate() {
            let t = rays.sphere(s, hits.t);
            let closer = t.simd_ge(zero) & t.simd_lt(hits.t);
            hits.t = closer.select(t, hits.t);
            hits.prim = closer.select(Ids::splat(i as u32), hits.prim);
        }
        let first = self.spheres.len() as u32;
        for (i, tri) in self.triangles.iter().enumerate() {
            let (t, u, v) = rays.triangle(tri, hits.t);
            let closer = t.simd_ge(zero) & t.simd_lt(hits.t);
            hits.t = closer.select(t, hits.t);
            hits.u = closer.select(u, hits.u);
            hits.v = closer.select(v, hits.v);
            hits.prim = closer.select(Ids::splat(first + i as u32), hits.prim);
        }
        hits
    }

    widest_simd! {
        /// Whether each lane's ray meets anything within (0, t_max).
        pub fn occluded(&self, rays: &RayPacket, t_max: Lanes) -> Mask<i32, LANES>
            = occluded_any_cpu, occluded_avx512, occluded_avx2
    }

    #[inline(always)]
    fn occluded_any_cpu(&self, rays: &RayPacket, t_max: Lanes) -> Mask<i32, LANES> {
        let zero = Lanes::splat(0.0);
        let mut hit = Mask::splat(false);
        for s in &self.spheres {
            hit |= rays.sphere(s, t_max).simd_ge(zero);
        }
        for tri in &self.triangles {
            if hit.all() {
                return hit;
            }
            let (t, _, _) = rays.triangle(tri, t_max);
            hit |= t.simd_ge(zero);
        }
        hit
    }
}
