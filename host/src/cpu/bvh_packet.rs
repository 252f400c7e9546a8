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
//! With instances the packet is two-level: at a leaf's instance its rays are mapped into the
//! mesh's object space lane by lane and descend the mesh's own tree as a packet. Where
//! materials have holes each lane's candidates are asked of its own ray
//! (`packet_presence.rs`). The any-hit descent for shadow segments is `bvh_packet_shadows.rs`.
//!
//! Every lane's answer is the one-ray traversal's, bit for bit: each box verdict and each t is
//! computed by the same IEEE operations on that lane's ray, a lane leaves a subtree only where
//! its own slab test (or the pop test, which is looser) rejects it, and the closest hit is the
//! least (t, instance, id) over the primitives reached (`bvh/traverse.rs`, `closest_in`),
//! whatever the order.

use super::bvh::{Bvh, HoleTables, Presence, Solid, LEAF, STACK, TIE, WIDTH};
use super::packet::{PacketHits, PacketTracer, RayPacket, LANES};
use super::packet_presence::{LaneHoles, LanePresence};
use super::simd::{slab_lanes, sphere_lanes, triangle_lanes_uv, widest_simd, Boxes, SLAB_PAD};
use kernel::instance::ray_to_object;
use kernel::scene::{Instance, NONE};
use std::mem::MaybeUninit;
use std::simd::cmp::{SimdPartialEq, SimdPartialOrd};
use std::simd::num::SimdFloat;
use std::simd::{Mask, Select, Simd};

type Lanes = Simd<f32, LANES>;
type Ids = Simd<u32, LANES>;
type LaneMask = Mask<i32, LANES>;

/// Subtrees wanted by at most this many lanes are traced one ray at a time (closest hits;
/// `bvh_packet_shadows.rs` has its own threshold for shadow segments).
const ONE_AT_A_TIME_LANES: u32 = 4;

/// The packet's rays as the slab test reads them: 1 / dir by lane, and per axis whether some
/// active lane's ray is parallel to it (1 / dir infinite, where 0 x inf can arise).
pub(super) struct SlabRays<'a> {
    rays: &'a RayPacket,
    inv_dir: [Lanes; 3],
    parallel: [bool; 3],
}

impl<'a> SlabRays<'a> {
    #[inline(always)]
    pub(super) fn new(rays: &'a RayPacket, active: u32) -> Self {
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
    pub(super) fn slab(&self, b: &Boxes<WIDTH>, c: usize, t_max: Lanes) -> (Lanes, LaneMask) {
        let b = Boxes {
            min: column(&b.min, c),
            max: column(&b.max, c),
        };
        slab_lanes(&self.rays.origin, &self.inv_dir, &b, t_max, self.parallel)
    }
}

/// Lane `j` of a vector of any width (a node's child box, a block's triangle), in every lane of
/// a packet.
#[inline(always)]
pub(super) fn column<const N: usize>(v: &[Simd<f32, N>; 3], j: usize) -> [Lanes; 3] {
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
/// lanes' hits so far where nearer, or at the same t where (instance, id) is less, this tree's
/// own primitives counting as instance `NONE` (`bvh.rs`, `closest_in`: the least (t, instance,
/// id) wins; a tree traversed without `INSTANCES` has only its own).
#[inline(always)]
fn keep_nearer<const INSTANCES: bool>(
    hits: &mut PacketHits,
    inside: LaneMask,
    id: u32,
    t: Lanes,
    u: Lanes,
    v: Lanes,
) {
    let ids = Ids::splat(id);
    let mut tie_won = t.simd_eq(hits.t) & ids.simd_lt(hits.prim);
    if INSTANCES {
        tie_won &= hits.instance.simd_eq(Ids::splat(NONE));
    }
    let nearer = t.simd_lt(hits.t) | tie_won;
    let take = inside & t.simd_ge(Lanes::splat(0.0)) & nearer;
    hits.t = take.select(t, hits.t);
    hits.u = take.select(u, hits.u);
    hits.v = take.select(v, hits.v);
    hits.prim = take.select(ids, hits.prim);
    if INSTANCES {
        hits.instance = take.select(Ids::splat(NONE), hits.instance);
    }
}

/// The rays of `lanes` mapped into the object space of `instance`
/// (`kernel::instance::ray_to_object`, lane by lane as the one-ray traversal maps them); the
/// other lanes zero rays.
#[inline(always)]
pub(super) fn rays_to_object(instance: &Instance, rays: &RayPacket, lanes: u32) -> RayPacket {
    let mut object = RayPacket::zero();
    let mut rest = lanes;
    while rest != 0 {
        let lane = rest.trailing_zeros() as usize;
        rest &= rest - 1;
        let (origin, dir) = rays.lane(lane);
        let (o, d) = ray_to_object(instance, origin, dir);
        object.set(lane, o, d);
    }
    object
}

impl Bvh {
    /// The root and the lanes with a ray (t_max > 0) as a bit mask; `None` when there is no
    /// tree or no ray.
    #[inline(always)]
    pub(super) fn packet_start(&self, t_max: Lanes) -> Option<(u32, u32)> {
        let active = t_max.simd_gt(Lanes::splat(0.0)).to_bitmask() as u32;
        match self.root {
            Some(root) if active != 0 => Some((root, active)),
            _ => None,
        }
    }

    /// Each lane's closest hit in (0, t_max) (`NONE` and t_max for a miss; lanes with t_max 0
    /// have no ray), with a triangle's barycentrics and the instance hit (`NONE` for the
    /// tree's own primitives; the barycentrics of an instance's triangle are left 0, for
    /// [`Bvh::surface`] to find): lane by lane what [`Bvh::closest_prim`] and the kernel's
    /// `intersect_triangle_uv` give.
    #[inline]
    pub fn closest_packet(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits {
        if self.instances.is_empty() {
            self.closest_packet_one_level(rays, t_max)
        } else {
            self.closest_packet_two_level(rays, t_max)
        }
    }

    widest_simd! {
        /// [`Bvh::closest_packet`] of a tree without instances.
        fn closest_packet_one_level(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits
            = packet_one_level_any_cpu, packet_one_level_avx512, packet_one_level_avx2
    }

    #[inline(always)]
    fn packet_one_level_any_cpu(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits {
        let mut hits = PacketHits::miss(t_max);
        if let Some((root, active)) = self.packet_start(t_max) {
            self.closest_packet_in::<false, _>(root, rays, active, &mut hits, Solid);
        }
        hits
    }

    widest_simd! {
        /// [`Bvh::closest_packet`] of a tree with instances.
        fn closest_packet_two_level(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits
            = packet_two_level_any_cpu, packet_two_level_avx512, packet_two_level_avx2
    }

    #[inline(always)]
    fn packet_two_level_any_cpu(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits {
        let mut hits = PacketHits::miss(t_max);
        if let Some((root, active)) = self.packet_start(t_max) {
            self.closest_packet_in::<true, _>(root, rays, active, &mut hits, Solid);
        }
        hits
    }

    widest_simd! {
        /// [`Bvh::closest_packet`] where materials may have holes: candidates that `tables` say
        /// are not there are passed through (`packet_presence.rs`), lane by lane what
        /// [`Bvh::closest_hit_through`] finds.
        pub fn closest_packet_through(
            &self,
            rays: &RayPacket,
            t_max: Lanes,
            tables: &HoleTables<'_>
        ) -> PacketHits = packet_through_any_cpu, packet_through_avx512, packet_through_avx2
    }

    #[inline(always)]
    fn packet_through_any_cpu(
        &self,
        rays: &RayPacket,
        t_max: Lanes,
        tables: &HoleTables<'_>,
    ) -> PacketHits {
        let mut hits = PacketHits::miss(t_max);
        if let Some((root, active)) = self.packet_start(t_max) {
            let holes = LaneHoles::of_packet(*tables, rays);
            if self.instances.is_empty() {
                self.closest_packet_in::<false, _>(root, rays, active, &mut hits, holes);
            } else {
                self.closest_packet_in::<true, _>(root, rays, active, &mut hits, holes);
            }
        }
        hits
    }

    /// `t` with the lanes of `lanes` whose candidate triangle `id` (hit at t >= 0) `presence`
    /// says is not there set to -1 (missed): the one-ray traversal's question, asked of each
    /// such lane's ray.
    #[inline(always)]
    pub(super) fn present_lanes<P: LanePresence>(
        &self,
        presence: P,
        id: u32,
        rays: &RayPacket,
        lanes: u32,
        mut t: Lanes,
    ) -> Lanes {
        let mut candidates = t.simd_ge(Lanes::splat(0.0)).to_bitmask() as u32 & lanes;
        while candidates != 0 {
            let lane = candidates.trailing_zeros() as usize;
            candidates &= candidates - 1;
            let (origin, dir) = rays.lane(lane);
            if !self.triangle_present(presence.lane(lane), id, origin, dir) {
                t[lane] = -1.0;
            }
        }
        t
    }

    /// The closest hits in subtree `start` of the rays of lanes `active` among the candidates
    /// `presence` counts, from their hits so far `hits` (which may hold [`TIE`] where an
    /// instance's mesh is searched for hits at exactly a t already found), with the instance
    /// step where `INSTANCES`.
    #[inline(always)]
    fn closest_packet_in<const INSTANCES: bool, P: LanePresence>(
        &self,
        start: u32,
        rays: &RayPacket,
        active: u32,
        hits: &mut PacketHits,
        presence: P,
    ) {
        let zero = Lanes::splat(0.0);
        let slab_rays = SlabRays::new(rays, active);
        // Entries: a subtree, the lanes that entered its box, and the least entry distance
        // among them. Not zero-filled: entries below `sp` are always written first.
        let mut stack = [const { MaybeUninit::<(u32, u32, f32)>::uninit() }; STACK];
        let mut sp = 0;
        let (mut current, mut lanes) = (start, active);
        loop {
            if lanes.count_ones() <= ONE_AT_A_TIME_LANES {
                let mut rest = lanes;
                while rest != 0 {
                    let lane = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    self.closest_of_lane::<INSTANCES, _>(
                        current,
                        rays,
                        lane,
                        hits,
                        presence.lane(lane),
                    );
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
                            tie_limits(hits),
                        );
                        let t = if P::SOLID {
                            t
                        } else {
                            self.present_lanes(presence, id, rays, lanes, t)
                        };
                        keep_nearer::<INSTANCES>(hits, inside, id, t, u, v);
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
                            tie_limits(hits),
                        );
                        keep_nearer::<INSTANCES>(hits, inside, id, t, zero, zero);
                    }
                }
                if INSTANCES {
                    self.closest_in_leaf_instances(current, rays, lanes, hits, presence);
                }
            }
            // Pop the next subtree some of whose lanes may still find a nearer hit in it: a
            // lane whose closest hit is nearer than every lane's entry distance would fail its
            // own slab test there too.
            loop {
                if sp == 0 {
                    return;
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

    /// The instance step of [`Bvh::closest_packet_in`] at leaf `leaf` for the rays of `lanes`:
    /// each instance's mesh searched as a packet in object space, from the lanes' hits so far
    /// (a lane with a hit seeks ties at its t too, [`TIE`]); a hit is taken where nearer, or at
    /// the same t where the instance is less (as `closest_in` decides it one ray at a time).
    #[inline(always)]
    fn closest_in_leaf_instances<P: LanePresence>(
        &self,
        leaf: u32,
        rays: &RayPacket,
        lanes: u32,
        hits: &mut PacketHits,
        presence: P,
    ) {
        let inside = LaneMask::from_bitmask(lanes as u64);
        for &i in &self.leaf_instances[self.instances_of_leaf(leaf)] {
            let mesh = &self.meshes[self.instance_meshes[i as usize] as usize];
            let Some(mesh_root) = mesh.root else { continue };
            let object = rays_to_object(&self.instances[i as usize], rays, lanes);
            let none = Ids::splat(NONE);
            let mut found = PacketHits::miss(hits.t);
            found.prim = hits.prim.simd_eq(none).select(none, Ids::splat(TIE));
            let in_mesh = presence.in_instance(i);
            mesh.closest_packet_in::<false, P>(mesh_root, &object, lanes, &mut found, in_mesh);
            let ids = Ids::splat(i);
            let wins =
                found.t.simd_lt(hits.t) | (found.t.simd_eq(hits.t) & ids.simd_lt(hits.instance));
            let take = inside & found.prim.simd_lt(Ids::splat(TIE)) & wins;
            hits.t = take.select(found.t, hits.t);
            hits.prim = take.select(found.prim, hits.prim);
            hits.u = take.select(Lanes::splat(0.0), hits.u);
            hits.v = take.select(Lanes::splat(0.0), hits.v);
            hits.instance = take.select(ids, hits.instance);
        }
    }

    /// Lane `lane`'s closest hit in subtree `start` by the one-ray traversal among the
    /// candidates `presence` counts (with the instance step where `INSTANCES`), from its hit so
    /// far, with a new hit's barycentrics
    /// ([`Bvh::barycentrics`]; 0 for an instance's triangle).
    #[inline(always)]
    fn closest_of_lane<const INSTANCES: bool, P: Presence>(
        &self,
        start: u32,
        rays: &RayPacket,
        lane: usize,
        hits: &mut PacketHits,
        presence: P,
    ) {
        let (origin, dir) = rays.lane(lane);
        let best = (hits.prim[lane], hits.t[lane]);
        let mut instance = hits.instance[lane];
        let (prim, t) =
            self.closest_in::<INSTANCES, P>(start, origin, dir, best, &mut instance, presence);
        if (prim, t) == best && instance == hits.instance[lane] {
            return;
        }
        let (u, v) = if instance == NONE {
            self.barycentrics(prim, origin, dir)
        } else {
            (0.0, 0.0)
        };
        hits.prim[lane] = prim;
        hits.t[lane] = t;
        hits.u[lane] = u;
        hits.v[lane] = v;
        hits.instance[lane] = instance;
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

/// Packets through the BVH of a scene whose materials have holes (`tables`): its rays pass
/// through the candidates that are not there, lane by lane as one ray alone does.
pub struct PacketsThroughHoles<'a> {
    pub bvh: &'a Bvh,
    pub tables: HoleTables<'a>,
}

impl PacketTracer for PacketsThroughHoles<'_> {
    fn closest_hits(&self, rays: &RayPacket, t_max: Lanes) -> PacketHits {
        self.bvh.closest_packet_through(rays, t_max, &self.tables)
    }
    fn occluded_lanes(&self, rays: &RayPacket, t_max: Lanes) -> LaneMask {
        self.bvh.occluded_packet_through(rays, t_max, &self.tables)
    }
}
