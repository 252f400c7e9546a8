//! Sixteen rays through the 8-wide BVH together (a ray packet: Wald, Slusallek, Benthin and
//! Wagner 2001; Wald, Boulos and Shirley 2007), for the packets of paths of `packet_paths.rs`.
//!
//! The packet descends as one: at an interior node each child's box is slab-tested against the
//! sixteen rays at once (SIMD over rays, one box broadcast), and the child is visited by the
//! lanes whose rays enter it, nearest first by the least entry distance among them; a leaf's
//! triangles and spheres are broadcast to the lanes and tested with the same lane-wise kernel
//! functions as the one-ray traversal. Where the lanes still wanting a subtree are few, they
//! finish it one ray at a time ([`ONE_AT_A_TIME_LANES`]; the hybrid of Benthin, Wald, Woop, Ernst
//! and Mark 2012), since a packet's tests cost the same for one lane as for sixteen.
//!
//! Every lane's answer is the one-ray traversal's, bit for bit: each box verdict and each t is
//! computed by the same IEEE operations on that lane's ray, a lane leaves a subtree only where
//! its own slab test (or the pop test, which is looser) rejects it, and the closest hit is the
//! least (t, id) over the primitives reached (`bvh.rs`, `closest_in`), whatever the order.

use super::bvh::{Bvh, Solid, LEAF, STACK, WIDTH};
use super::packet::{PacketHits, PacketTracer, RayPacket, LANES};
use super::simd::{
    slab_lanes, sphere_lanes, triangle_lanes, triangle_lanes_uv, widest_simd, Boxes, SLAB_PAD,
};
use glam::Vec3;
use kernel::scene::NONE;
use std::mem::MaybeUninit;
use std::simd::cmp::{SimdPartialEq, SimdPartialOrd};
use std::simd::num::SimdFloat;
use std::simd::{Mask, Select, Simd};

type Lanes = Simd<f32, LANES>;
type Ids = Simd<u32, LANES>;
type LaneMask = Mask<i32, LANES>;

/// Subtrees wanted by at most this many lanes are traced one ray at a time.
pub const ONE_AT_A_TIME_LANES: u32 = 2;

/// The packet's rays as the slab test reads them: 1 / dir by lane, and per axis whether some
/// active lane's ray is parallel to it (1 / dir infinite, where 0 x inf can arise).
struct SlabRays<'a> {
    rays: &'a RayPacket,
    inv_dir: [Lanes; 3],
    parallel: [bool; 3],
}

impl<'a> SlabRays<'a> {
    #[inline(always)]
    fn new(rays: &'a RayPacket, active: u32) -> Self {
        let one = Lanes::splat(1.0);
        let inv_dir = [one / rays.dir[0], one / rays.dir[1], one / rays.dir[2]];
        let active = LaneMask::from_bitmask(active as u64);
        let parallel = [0, 1, 2].map(|a| (inv_dir[a].is_infinite() & active).any());
        SlabRays {
            rays,
            inv_dir,
            parallel,
        }
    }

    /// The slab test of child `c` of a node against every lane (`simd::slab_lanes`, as
    /// `simd::Ray4::slab` runs it for one ray): each lane's entry distance and whether its ray
    /// enters the box within (0, t_max].
    #[inline(always)]
    fn slab(&self, b: &Boxes<WIDTH>, c: usize, t_max: Lanes) -> (Lanes, LaneMask) {
        let b = Boxes {
            min: column(&b.min, c),
            max: column(&b.max, c),
        };
        slab_lanes(&self.rays.origin, &self.inv_dir, &b, t_max, self.parallel)
    }
}

/// Lane `lane`'s ray.
#[inline(always)]
fn lane_ray(rays: &RayPacket, lane: usize) -> (Vec3, Vec3) {
    let v = |c: &[Lanes; 3]| Vec3::new(c[0][lane], c[1][lane], c[2][lane]);
    (v(&rays.origin), v(&rays.dir))
}

/// Lane `j` of a vector of any width (a node's child box, a block's triangle), in every lane of
/// a packet.
#[inline(always)]
fn column<const N: usize>(v: &[Simd<f32, N>; 3], j: usize) -> [Lanes; 3] {
    [
        Lanes::splat(v[0][j]),
        Lanes::splat(v[1][j]),
        Lanes::splat(v[2][j]),
    ]
}

/// Lane by lane, `bvh::traverse::tie_limit`: t while nothing is hit, else the next float above it.
#[inline(always)]
fn tie_limits(hits: &PacketHits) -> Lanes {
    let next_up = Lanes::from_bits(hits.t.to_bits() + Ids::splat(1));
    hits.prim.simd_eq(Ids::splat(NONE)).select(hits.t, next_up)
}

/// Primitive `id`'s hits t (negative: missed) with barycentrics u, v replace the `inside`
/// lanes' hits so far where nearer, or at the same t where `id` is smaller (`bvh.rs`,
/// `closest_in`: the least (t, id) wins).
#[inline(always)]
fn keep_nearer(hits: &mut PacketHits, inside: LaneMask, id: u32, t: Lanes, u: Lanes, v: Lanes) {
    let ids = Ids::splat(id);
    let nearer = t.simd_lt(hits.t) | (t.simd_eq(hits.t) & ids.simd_lt(hits.prim));
    let take = inside & t.simd_ge(Lanes::splat(0.0)) & nearer;
    hits.t = take.select(t, hits.t);
    hits.u = take.select(u, hits.u);
    hits.v = take.select(v, hits.v);
    hits.prim = take.select(ids, hits.prim);
}

impl Bvh {
    /// The root and the lanes with a ray (t_max > 0) as a bit mask; `None` when there is no
    /// tree or no ray.
    #[inline(always)]
    fn packet_start(&self, t_max: Lanes) -> Option<(u32, u32)> {
        let active = t_max.simd_gt(Lanes::splat(0.0)).to_bitmask() as u32;
        match self.root {
            Some(root) if active != 0 => Some((root, active)),
            _ => None,
        }
    }

    widest_simd! {
        /// Each lane's closest hit in (0, t_max) of a tree without instances (`NONE` and t_max
        /// for a miss; lanes with t_max 0 have no ray), with a triangle's barycentrics: lane by
        /// lane what [`Bvh::closest_prim`] and the kernel's `intersect_triangle_uv` give.
        pub fn closest_packet(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits
            = closest_packet_any_cpu, closest_packet_avx512, closest_packet_avx2
    }

    #[inline(always)]
    fn closest_packet_any_cpu(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits {
        debug_assert!(self.instances().is_empty());
        let zero = Lanes::splat(0.0);
        let mut hits = PacketHits::miss(t_max);
        let Some((root, active)) = self.packet_start(t_max) else {
            return hits;
        };
        let slab_rays = SlabRays::new(rays, active);
        // Entries: a subtree, the lanes that entered its box, and the least entry distance
        // among them. Not zero-filled: entries below `sp` are always written first.
        let mut stack = [const { MaybeUninit::<(u32, u32, f32)>::uninit() }; STACK];
        let mut sp = 0;
        let (mut current, mut lanes) = (root, active);
        loop {
            if lanes.count_ones() <= ONE_AT_A_TIME_LANES {
                let mut rest = lanes;
                while rest != 0 {
                    let lane = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    self.closest_of_lane(current, rays, lane, &mut hits);
                }
            } else if current & LEAF == 0 {
                let node = &self.nodes[current as usize];
                let mut order = [(0u32, 0u32, 0.0f32); WIDTH];
                let mut k = 0;
                let mut used = node.used;
                while used != 0 {
                    let c = used.trailing_zeros() as usize;
                    used &= used - 1;
                    let (near, hit) = slab_rays.slab(&node.boxes, c, hits.t);
                    let entered = hit.to_bitmask() as u32 & lanes;
                    if entered == 0 {
                        continue;
                    }
                    let inside = LaneMask::from_bitmask(entered as u64);
                    let nearest = inside
                        .select(near, Lanes::splat(f32::INFINITY))
                        .reduce_min();
                    let mut j = k;
                    while j > 0 && order[j - 1].2 > nearest {
                        order[j] = order[j - 1];
                        j -= 1;
                    }
                    order[j] = (node.child[c], entered, nearest);
                    k += 1;
                }
                if k > 0 {
                    for &entry in order[1..k].iter().rev() {
                        stack[sp].write(entry);
                        sp += 1;
                        self.prefetch(entry.0);
                    }
                    (current, lanes) = (order[0].0, order[0].1);
                    continue;
                }
            } else {
                let inside = LaneMask::from_bitmask(lanes as u64);
                let (blocks, spheres) = self.leaf_contents(current);
                for block in &self.blocks[blocks] {
                    for (j, &id) in block.id.iter().enumerate() {
                        if id == NONE {
                            break;
                        }
                        let tri = &block.triangles;
                        let (t, u, v) = triangle_lanes_uv(
                            &rays.origin,
                            &rays.dir,
                            &column(&tri.p0, j),
                            &column(&tri.edge1, j),
                            &column(&tri.edge2, j),
                            zero,
                            tie_limits(&hits),
                        );
                        keep_nearer(&mut hits, inside, id, t, u, v);
                    }
                }
                for block in &self.sphere_blocks[spheres] {
                    for (j, &id) in block.id.iter().enumerate() {
                        if id == NONE {
                            break;
                        }
                        let s = &block.spheres;
                        let center = column(&s.center, j);
                        let radius = Lanes::splat(s.radius[j]);
                        let t = sphere_lanes(
                            &rays.origin,
                            &rays.dir,
                            &center,
                            radius,
                            zero,
                            tie_limits(&hits),
                        );
                        keep_nearer(&mut hits, inside, id, t, zero, zero);
                    }
                }
            }
            // Pop the next subtree some of whose lanes may still find a nearer hit in it: a
            // lane whose closest hit is nearer than every lane's entry distance would fail its
            // own slab test there too.
            loop {
                if sp == 0 {
                    return hits;
                }
                sp -= 1;
                // SAFETY: entry `sp` was written by a push (sp only grows by writing).
                let (r, entered, nearest) = unsafe { stack[sp].assume_init() };
                let reach = hits.t * Lanes::splat(SLAB_PAD);
                let still = Lanes::splat(nearest).simd_le(reach).to_bitmask() as u32 & entered;
                if still != 0 {
                    (current, lanes) = (r, still);
                    break;
                }
            }
        }
    }

    /// Lane `lane`'s closest hit in subtree `start` by the one-ray traversal, from its hit so
    /// far, with a new hit's barycentrics ([`Bvh::barycentrics`]).
    #[inline(always)]
    fn closest_of_lane(&self, start: u32, rays: &RayPacket, lane: usize, hits: &mut PacketHits) {
        let (origin, dir) = lane_ray(rays, lane);
        let best = (hits.prim[lane], hits.t[lane]);
        let mut no_instance = NONE;
        let (prim, t) =
            self.closest_in::<false, Solid>(start, origin, dir, best, &mut no_instance, Solid);
        if (prim, t) == best {
            return;
        }
        let (u, v) = self.barycentrics(prim, origin, dir);
        hits.prim[lane] = prim;
        hits.t[lane] = t;
        hits.u[lane] = u;
        hits.v[lane] = v;
    }

    widest_simd! {
        /// Whether each lane's ray meets anything within (0, t_max) in a tree without instances
        /// (lanes with t_max 0 have no ray): lane by lane what [`Bvh::any_hit`] says.
        pub fn occluded_packet(&self, rays: &RayPacket, t_max: Lanes) -> LaneMask
            = occluded_packet_any_cpu, occluded_packet_avx512, occluded_packet_avx2
    }

    #[inline(always)]
    fn occluded_packet_any_cpu(&self, rays: &RayPacket, t_max: Lanes) -> LaneMask {
        debug_assert!(self.instances().is_empty());
        let zero = Lanes::splat(0.0);
        let Some((root, active)) = self.packet_start(t_max) else {
            return LaneMask::splat(false);
        };
        let slab_rays = SlabRays::new(rays, active);
        let mut stack = [const { MaybeUninit::<(u32, u32)>::uninit() }; STACK];
        let mut sp = 0;
        let mut occluded = 0u32;
        let (mut current, mut lanes) = (root, active);
        loop {
            if lanes.count_ones() <= ONE_AT_A_TIME_LANES {
                let mut rest = lanes;
                while rest != 0 {
                    let lane = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    let (origin, dir) = lane_ray(rays, lane);
                    if self.any_in::<false, Solid>(current, origin, dir, t_max[lane], Solid) {
                        occluded |= 1 << lane;
                    }
                }
            } else if current & LEAF == 0 {
                let node = &self.nodes[current as usize];
                let mut used = node.used;
                while used != 0 {
                    let c = used.trailing_zeros() as usize;
                    used &= used - 1;
                    let (_, hit) = slab_rays.slab(&node.boxes, c, t_max);
                    let entered = hit.to_bitmask() as u32 & lanes;
                    if entered != 0 {
                        stack[sp].write((node.child[c], entered));
                        sp += 1;
                    }
                }
            } else {
                let (blocks, spheres) = self.leaf_contents(current);
                'leaf: for block in &self.blocks[blocks] {
                    for (j, &id) in block.id.iter().enumerate() {
                        if id == NONE {
                            break;
                        }
                        let tri = &block.triangles;
                        let t = triangle_lanes(
                            &rays.origin,
                            &rays.dir,
                            &column(&tri.p0, j),
                            &column(&tri.edge1, j),
                            &column(&tri.edge2, j),
                            zero,
                            t_max,
                        );
                        occluded |= t.simd_ge(zero).to_bitmask() as u32 & lanes;
                        if lanes & !occluded == 0 {
                            break 'leaf;
                        }
                    }
                }
                for block in &self.sphere_blocks[spheres] {
                    for (j, &id) in block.id.iter().enumerate() {
                        if id == NONE || lanes & !occluded == 0 {
                            break;
                        }
                        let s = &block.spheres;
                        let center = column(&s.center, j);
                        let radius = Lanes::splat(s.radius[j]);
                        let t = sphere_lanes(&rays.origin, &rays.dir, &center, radius, zero, t_max);
                        occluded |= t.simd_ge(zero).to_bitmask() as u32 & lanes;
                    }
                }
            }
            if occluded == active {
                return LaneMask::from_bitmask(occluded as u64);
            }
            loop {
                if sp == 0 {
                    return LaneMask::from_bitmask(occluded as u64);
                }
                sp -= 1;
                // SAFETY: entry `sp` was written by a push (sp only grows by writing).
                let (r, entered) = unsafe { stack[sp].assume_init() };
                let still = entered & !occluded;
                if still != 0 {
                    (current, lanes) = (r, still);
                    break;
                }
            }
        }
    }
}

impl PacketTracer for Bvh {
    fn closest_hits(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits {
        self.closest_packet(rays, t_max)
    }
    fn occluded_lanes(&self, rays: &RayPacket, t_max: Lanes) -> LaneMask {
        self.occluded_packet(rays, t_max)
    }
}
