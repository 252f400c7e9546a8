//! Shadow segments through the 8-wide BVH as packets of sixteen (`bvh_packet.rs`, whose
//! descent this is, for any-hit): a lane leaves the traversal once something blocks it, a leaf's
//! triangles and spheres are tested on the lanes still open, subtrees wanted by at most
//! [`ONE_AT_A_TIME_SHADOW_LANES`] lanes go one ray at a time, and each lane's answer is the one-ray
//! [`Bvh::any_hit`]'s (or [`Bvh::any_hit_through`]'s, where materials have holes).

use super::bvh::{Bvh, HoleTables, Solid, LEAF, STACK};
use super::bvh_packet::{column, rays_to_object, SlabRays};
use super::packet::{RayPacket, LANES};
use super::packet_presence::{LaneHoles, LanePresence};
use super::simd::{sphere_lanes, triangle_lanes, widest_simd};
use kernel::scene::NONE;
use std::mem::MaybeUninit;
use std::simd::cmp::SimdPartialOrd;
use std::simd::{Mask, Simd};

type Lanes = Simd<f32, LANES>;
type LaneMask = Mask<i32, LANES>;

/// Subtrees wanted by at most this many lanes are traced one ray at a time (closest hits use
/// `bvh_packet.rs`' own threshold; both measured in docs/performance.md).
const ONE_AT_A_TIME_SHADOW_LANES: u32 = 5;

impl Bvh {
    /// Whether each lane's ray meets anything within (0, t_max) (lanes with t_max 0 have no
    /// ray): lane by lane what [`Bvh::any_hit`] says.
    #[inline]
    pub fn occluded_packet(&self, rays: &RayPacket, t_max: Lanes) -> LaneMask {
        if self.instances.is_empty() {
            self.occluded_packet_one_level(rays, t_max)
        } else {
            self.occluded_packet_two_level(rays, t_max)
        }
    }

    widest_simd! {
        /// [`Bvh::occluded_packet`] of a tree without instances.
        fn occluded_packet_one_level(&self, rays: &RayPacket, t_max: Lanes) -> LaneMask
            = occluded_one_level_any_cpu, occluded_one_level_avx512, occluded_one_level_avx2
    }

    #[inline(always)]
    fn occluded_one_level_any_cpu(&self, rays: &RayPacket, t_max: Lanes) -> LaneMask {
        let occluded = match self.packet_start(t_max) {
            Some((root, active)) => {
                self.occluded_packet_in::<false, _>(root, rays, active, t_max, Solid)
            }
            None => 0,
        };
        LaneMask::from_bitmask(occluded as u64)
    }

    widest_simd! {
        /// [`Bvh::occluded_packet`] of a tree with instances.
        fn occluded_packet_two_level(&self, rays: &RayPacket, t_max: Lanes) -> LaneMask
            = occluded_two_level_any_cpu, occluded_two_level_avx512, occluded_two_level_avx2
    }

    #[inline(always)]
    fn occluded_two_level_any_cpu(&self, rays: &RayPacket, t_max: Lanes) -> LaneMask {
        let occluded = match self.packet_start(t_max) {
            Some((root, active)) => {
                self.occluded_packet_in::<true, _>(root, rays, active, t_max, Solid)
            }
            None => 0,
        };
        LaneMask::from_bitmask(occluded as u64)
    }

    widest_simd! {
        /// [`Bvh::occluded_packet`] where materials may have holes: candidates that `tables`
        /// say are not there are passed through (`packet_presence.rs`), lane by lane what
        /// [`Bvh::any_hit_through`] says.
        pub fn occluded_packet_through(
            &self,
            rays: &RayPacket,
            t_max: Lanes,
            tables: &HoleTables<'_>
        ) -> LaneMask = occluded_through_any_cpu, occluded_through_avx512, occluded_through_avx2
    }

    #[inline(always)]
    fn occluded_through_any_cpu(
        &self,
        rays: &RayPacket,
        t_max: Lanes,
        tables: &HoleTables<'_>,
    ) -> LaneMask {
        let Some((root, active)) = self.packet_start(t_max) else {
            return LaneMask::splat(false);
        };
        let holes = LaneHoles::of_packet(*tables, rays);
        let occluded = if self.instances.is_empty() {
            self.occluded_packet_in::<false, _>(root, rays, active, t_max, holes)
        } else {
            self.occluded_packet_in::<true, _>(root, rays, active, t_max, holes)
        };
        LaneMask::from_bitmask(occluded as u64)
    }

    /// The lanes of `active` whose rays meet anything within (0, t_max) in subtree `start`
    /// that `presence` counts, as a bit mask, with the instance step where `INSTANCES`.
    #[inline(always)]
    fn occluded_packet_in<const INSTANCES: bool, P: LanePresence>(
        &self,
        start: u32,
        rays: &RayPacket,
        active: u32,
        t_max: Lanes,
        presence: P,
    ) -> u32 {
        let zero = Lanes::splat(0.0);
        let slab_rays = SlabRays::new(rays, active);
        let mut stack = [const { MaybeUninit::<(u32, u32)>::uninit() }; STACK];
        let mut sp = 0;
        let mut occluded = 0u32;
        let (mut current, mut lanes) = (start, active);
        loop {
            if lanes.count_ones() <= ONE_AT_A_TIME_SHADOW_LANES {
                let mut rest = lanes;
                while rest != 0 {
                    let lane = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    let (origin, dir) = rays.lane(lane);
                    let one = presence.lane(lane);
                    if self.any_in::<INSTANCES, P::Lane>(current, origin, dir, t_max[lane], one) {
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
                        let t = if P::SOLID {
                            t
                        } else {
                            self.present_lanes(presence, id, rays, lanes & !occluded, t)
                        };
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
                if INSTANCES {
                    for &i in &self.leaf_instances[self.instances_of_leaf(current)] {
                        let left = lanes & !occluded;
                        if left == 0 {
                            break;
                        }
                        let mesh = &self.meshes[self.instance_meshes[i as usize] as usize];
                        let Some(mesh_root) = mesh.root else { continue };
                        let object = rays_to_object(&self.instances[i as usize], rays, left);
                        let in_mesh = presence.in_instance(i);
                        occluded |= mesh.occluded_packet_in::<false, P>(
                            mesh_root, &object, left, t_max, in_mesh,
                        );
                    }
                }
            }
            if occluded & active == active {
                return occluded;
            }
            loop {
                if sp == 0 {
                    return occluded;
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
