//! The CPU backend's bounding volume hierarchy over spheres and triangles: the binary SAH tree
//! of [`super::bvh_build`] collapsed into an 8-wide tree (each node holds its children's boxes
//! side by side, as Embree's BVH8 does), so one SIMD slab test visits eight children; leaves
//! hold their triangles four to a block for the SIMD triangle test of [`super::simd`].
//! Traversal is iterative, nearest child first, and culls on pop by the entry distance stored
//! with each pushed node. 8 wide rather than 4: on the 1M-triangle mesh of `twinpath rays`,
//! incoherent rays are bound by memory latency, and a shallower tree waits less (measured:
//! 0.6x Embree's throughput with 4 lanes, 0.8x with 8; README "CPU traversal").
//!
//! Primitive ids below `spheres.len()` are spheres, then triangles, then instances. An instance
//! (`kernel::scene::Instance`) places a mesh that has its own hierarchy in object space: a ray
//! reaching it in a leaf is mapped into object space (`kernel::instance::ray_to_object`; its
//! direction not normalised, so t means the same in both) and traced through the mesh's tree
//! (a two-level BVH, as Embree and the GPU's TLAS over BLASes do). Traversal is compiled twice,
//! with and without the instance step, so a scene without instances runs the one-level loop.
//! The closest hit is the kernel's own intersection functions' answer (bit-identical t),
//! whatever the traversal order.

use super::bvh_build::{Aabb, BinaryBvh, SAH_MAX_DEPTH};
use super::huge_pages;
use super::simd::{widest_simd, Boxes, Ray4, Spheres4, Triangles4, SLAB_PAD};
use crate::scene::instancing::instance_box;
use crate::scene::Scene;
use glam::Vec3;
use kernel::geometry::{
    intersect_sphere, intersect_triangle, intersect_triangle_uv, TriangleShape,
};
use kernel::instance::ray_to_object;
use kernel::scene::{Instance, Sphere, Triangle, NONE};
use kernel::SurfaceHit;
use rayon::prelude::*;
use std::mem::MaybeUninit;
use std::ops::Range;
use std::simd::{f32x4, Mask, Simd};

/// A child reference: a node index, or with this bit set a leaf. A leaf of triangles only is
/// encoded in the reference itself (blocks - 1 in the two bits below [`LISTED`], the first
/// block in the low [`BLOCK_BITS`]), saving a dependent memory load per leaf; a leaf with
/// spheres or instances (or past 2^28 blocks) has [`LISTED`] set and indexes [`Bvh::leaves`].
pub(super) const LEAF: u32 = 1 << 31;
const LISTED: u32 = 1 << 30;
const BLOCK_BITS: u32 = 28;
/// Traversal stack: each level pushes at most WIDTH - 1 entries, and the wide tree is no deeper
/// than the binary one (< SAH_MAX_DEPTH + 32 levels for up to 2^32 primitives).
pub(super) const STACK: usize = (WIDTH - 1) * (SAH_MAX_DEPTH + 32) + 1;

/// Children per node.
pub(super) const WIDTH: usize = 8;

/// An interior node: up to [`WIDTH`] children's boxes (lane i = child i) and references.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct WideNode {
    pub(super) boxes: Boxes<WIDTH>,
    pub(super) child: [u32; WIDTH],
    /// Used slots (the first lanes) as a bit mask.
    pub(super) used: u32,
}

/// A leaf: `triangle_blocks` blocks of four triangles from `first_block`, and `sphere_blocks`
/// blocks of four spheres from `first_sphere_block`; its instances are listed apart
/// ([`Bvh::leaf_instance_ranges`]), so the one-level loop reads what it always read.
#[derive(Clone, Copy, Debug)]
struct Leaf {
    first_block: u32,
    triangle_blocks: u32,
    first_sphere_block: u32,
    sphere_blocks: u32,
}

/// The closest hit a traversal found: the primitive (a sphere or triangle of this tree, or of
/// the mesh of `instance`, numbered as that mesh's tree numbers them), the instance or `NONE`,
/// and t; `prim` is `NONE` for a miss.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimHit {
    pub prim: u32,
    pub instance: u32,
    pub t: f32,
}

/// Four triangles of a leaf and their primitive ids (`NONE` in unused lanes, whose edges are
/// zero so that they never hit).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(super) struct TriangleBlock {
    pub(super) triangles: Triangles4,
    pub(super) id: [u32; 4],
}

/// Four spheres of a leaf and their primitive ids (`NONE` in unused lanes, whose centres are
/// NaN so that they never hit).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(super) struct SphereBlock {
    pub(super) spheres: Spheres4,
    pub(super) id: [u32; 4],
}

/// Geometry plus its hierarchy.
pub struct Bvh {
    pub(super) nodes: Vec<WideNode>,
    leaves: Vec<Leaf>,
    pub(super) blocks: Vec<TriangleBlock>,
    pub(super) sphere_blocks: Vec<SphereBlock>,
    /// The root's reference; `None` for an empty scene.
    pub(super) root: Option<u32>,
    pub spheres: Vec<Sphere>,
    pub triangles: Vec<Triangle>,
    /// By triangle, what its hit records need that depends on its shape alone (computed once).
    shapes: Vec<TriangleShape>,
    /// The instances, the mesh (an index into `meshes`) each places, and the meshes' own
    /// object-space trees (without instances of their own).
    instances: Vec<Instance>,
    instance_meshes: Vec<u32>,
    meshes: Vec<Bvh>,
    /// The instances of the listed leaves, leaf by leaf, and each listed leaf's range of them
    /// (by the leaf's index in `leaves`).
    leaf_instances: Vec<u32>,
    leaf_instance_ranges: Vec<(u32, u32)>,
}

fn prim_bounds(
    spheres: &[Sphere],
    triangles: &[Triangle],
    instance_boxes: &[Aabb],
    id: u32,
) -> Aabb {
    let id = id as usize;
    if id >= spheres.len() + triangles.len() {
        instance_boxes[id - spheres.len() - triangles.len()]
    } else if id < spheres.len() {
        let s = &spheres[id];
        let c = Vec3::from(s.center);
        Aabb {
            min: c - Vec3::splat(s.radius),
            max: c + Vec3::splat(s.radius),
        }
    } else {
        let t = &triangles[id - spheres.len()];
        let p0 = Vec3::from(t.p0);
        Aabb::EMPTY
            .grow(p0)
            .grow(p0 + Vec3::from(t.edge1))
            .grow(p0 + Vec3::from(t.edge2))
    }
}

impl Bvh {
    /// Builds the hierarchy: the binary SAH tree (O(n log n)), then its wide collapse (O(n)).
    pub fn build(spheres: Vec<Sphere>, triangles: Vec<Triangle>) -> Bvh {
        Self::build_with_instances(spheres, triangles, Vec::new(), Vec::new(), Vec::new())
    }

    /// The scene's hierarchy: its world-space spheres and triangles, and its instances over a
    /// tree per instanced mesh (built in parallel, each over that mesh's object-space
    /// triangles).
    pub fn build_scene(scene: &Scene) -> Bvh {
        let world = scene.world_triangle_count();
        let meshes: Vec<Bvh> = scene
            .meshes
            .par_iter()
            .map(|m| {
                Bvh::build(
                    Vec::new(),
                    huge_pages::copy_of(&scene.triangles[m.range.clone()]),
                )
            })
            .collect();
        Self::build_with_instances(
            scene.spheres.clone(),
            huge_pages::copy_of(&scene.triangles[..world]),
            meshes,
            scene.instances.clone(),
            scene.instance_meshes.clone(),
        )
    }

    /// The two-level hierarchy: `spheres`, `triangles` and `instances` (instance i places
    /// `meshes[instance_meshes[i]]`) under one tree.
    pub fn build_with_instances(
        spheres: Vec<Sphere>,
        triangles: Vec<Triangle>,
        meshes: Vec<Bvh>,
        instances: Vec<Instance>,
        instance_meshes: Vec<u32>,
    ) -> Bvh {
        let instance_boxes: Vec<Aabb> = instances
            .iter()
            .zip(&instance_meshes)
            .map(|(inst, &m)| meshes[m as usize].placed_box(inst))
            .collect();
        let n = spheres.len() + triangles.len() + instances.len();
        let bounds: Vec<Aabb> = (0..n as u32)
            .map(|i| prim_bounds(&spheres, &triangles, &instance_boxes, i))
            .collect();
        let binary = BinaryBvh::build(&bounds);
        let mut bvh = Bvh {
            nodes: huge_pages::vec_with_capacity(binary.nodes.len() / 2 + 1),
            leaves: Vec::new(),
            // Each leaf's last block may be partly empty: at most one block per binary leaf
            // beyond a quarter of the triangles (so the advised buffer never reallocates).
            blocks: huge_pages::vec_with_capacity(triangles.len() / 4 + binary.nodes.len() / 2 + 1),
            sphere_blocks: Vec::new(),
            root: None,
            shapes: {
                let mut shapes = huge_pages::vec_with_capacity(triangles.len());
                shapes.extend(
                    triangles
                        .iter()
                        .map(|t| TriangleShape::of(Vec3::from(t.edge1), Vec3::from(t.edge2))),
                );
                shapes
            },
            spheres,
            triangles,
            instances,
            instance_meshes,
            meshes,
            leaf_instances: Vec::new(),
            leaf_instance_ranges: Vec::new(),
        };
        if n > 0 {
            bvh.root = Some(if binary.nodes[0].count > 0 {
                // A single leaf: give it a node so that traversal always starts at one.
                bvh.nodes.push(WideNode {
                    boxes: lanes(&[binary.nodes[0].bounds]),
                    child: [0; WIDTH],
                    used: 1,
                });
                bvh.nodes[0].child[0] = bvh.collapse(&binary, 0);
                0
            } else {
                bvh.collapse(&binary, 0)
            });
        }
        bvh
    }

    /// The wide subtree for binary node `b`: its reference. An interior node takes the two
    /// children, then repeatedly replaces its largest interior child by that child's children
    /// until it has WIDTH (the surface-area greedy collapse).
    fn collapse(&mut self, binary: &BinaryBvh, b: usize) -> u32 {
        let node = binary.nodes[b];
        if node.count > 0 {
            return self.make_leaf(binary, b);
        }
        let mut kids = vec![node.first as usize, node.first as usize + 1];
        while kids.len() < WIDTH {
            let widest = (0..kids.len())
                .filter(|&i| binary.nodes[kids[i]].count == 0)
                .max_by(|&i, &j| {
                    let area = |k: usize| binary.nodes[kids[k]].bounds.half_area();
                    area(i).total_cmp(&area(j))
                });
            let Some(i) = widest else { break };
            let first = binary.nodes[kids[i]].first as usize;
            kids[i] = first;
            kids.push(first + 1);
        }
        let index = self.nodes.len();
        let child_bounds: Vec<Aabb> = kids.iter().map(|&k| binary.nodes[k].bounds).collect();
        self.nodes.push(WideNode {
            boxes: lanes(&child_bounds),
            child: [0; WIDTH],
            used: (1 << kids.len()) - 1,
        });
        for (lane, &k) in kids.iter().enumerate() {
            let r = self.collapse(binary, k);
            self.nodes[index].child[lane] = r;
        }
        index as u32
    }

    /// Packs binary leaf `b`'s primitives (triangles four to a block, spheres by id) and
    /// returns its reference.
    fn make_leaf(&mut self, binary: &BinaryBvh, b: usize) -> u32 {
        let node = binary.nodes[b];
        let prims = &binary.prims[node.first as usize..(node.first + node.count) as usize];
        let n_spheres = self.spheres.len() as u32;
        let n_geometry = n_spheres + self.triangles.len() as u32;
        let first_sphere_block = self.sphere_blocks.len() as u32;
        let first_block = self.blocks.len() as u32;
        let first_instance = self.leaf_instances.len() as u32;
        let (instances, prims): (Vec<u32>, Vec<u32>) =
            prims.iter().partition(|&&p| p >= n_geometry);
        self.leaf_instances
            .extend(instances.iter().map(|&p| p - n_geometry));
        let (spheres, tris): (Vec<u32>, Vec<u32>) = prims.iter().partition(|&&p| p < n_spheres);
        for chunk in spheres.chunks(4) {
            let mut block = SphereBlock {
                spheres: Spheres4 {
                    center: [f32x4::splat(f32::NAN); 3],
                    radius: f32x4::splat(0.0),
                },
                id: [NONE; 4],
            };
            for (lane, &p) in chunk.iter().enumerate() {
                let s = &self.spheres[p as usize];
                for axis in 0..3 {
                    block.spheres.center[axis][lane] = s.center[axis];
                }
                block.spheres.radius[lane] = s.radius;
                block.id[lane] = p;
            }
            self.sphere_blocks.push(block);
        }
        for chunk in tris.chunks(4) {
            let mut block = TriangleBlock {
                triangles: Triangles4 {
                    p0: [f32x4::splat(0.0); 3],
                    edge1: [f32x4::splat(0.0); 3],
                    edge2: [f32x4::splat(0.0); 3],
                },
                id: [NONE; 4],
            };
            for (lane, &p) in chunk.iter().enumerate() {
                let t = &self.triangles[(p - n_spheres) as usize];
                for axis in 0..3 {
                    block.triangles.p0[axis][lane] = t.p0[axis];
                    block.triangles.edge1[axis][lane] = t.edge1[axis];
                    block.triangles.edge2[axis][lane] = t.edge2[axis];
                }
                block.id[lane] = p;
            }
            self.blocks.push(block);
        }
        let triangle_blocks = self.blocks.len() as u32 - first_block;
        let sphere_blocks = self.sphere_blocks.len() as u32 - first_sphere_block;
        let instance_count = instances.len() as u32;
        if sphere_blocks == 0
            && instance_count == 0
            && (1..=4).contains(&triangle_blocks)
            && first_block < 1 << BLOCK_BITS
        {
            return LEAF | (triangle_blocks - 1) << BLOCK_BITS | first_block;
        }
        self.leaves.push(Leaf {
            first_block,
            triangle_blocks,
            first_sphere_block,
            sphere_blocks,
        });
        self.leaf_instance_ranges
            .push((first_instance, first_instance + instance_count));
        LEAF | LISTED | (self.leaves.len() as u32 - 1)
    }

    /// The instances (the kernel's instance table on the CPU: a hit's `instance` indexes it).
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }

    /// Number of interior nodes (for statistics).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Bytes the hierarchy takes beyond the primitives themselves: nodes, leaves, the
    /// leaves' packed copies of their triangles, and the triangles' precomputed shapes; with
    /// the instanced meshes' trees.
    pub fn hierarchy_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.shapes.as_slice())
            + std::mem::size_of_val(self.leaves.as_slice())
            + std::mem::size_of_val(self.blocks.as_slice())
            + std::mem::size_of_val(self.sphere_blocks.as_slice())
            + std::mem::size_of_val(self.leaf_instances.as_slice())
            + std::mem::size_of_val(self.leaf_instance_ranges.as_slice())
            + self.meshes.iter().map(Bvh::hierarchy_bytes).sum::<usize>()
    }

    /// Bytes of the primitives as the scene holds them (materials included): spheres,
    /// triangles, instances, and the instanced meshes' triangles (once each).
    pub fn primitive_bytes(&self) -> usize {
        std::mem::size_of_val(self.spheres.as_slice())
            + std::mem::size_of_val(self.triangles.as_slice())
            + std::mem::size_of_val(self.instances.as_slice())
            + std::mem::size_of_val(self.instance_meshes.as_slice())
            + self.meshes.iter().map(Bvh::primitive_bytes).sum::<usize>()
    }

    /// The world-space box of this tree's geometry placed by `instance`: the union of its root's
    /// child boxes, each mapped by its eight corners (`instancing::instance_box`), which under
    /// a rotation is tighter than the mapped box of the whole; empty for an empty tree.
    fn placed_box(&self, instance: &Instance) -> Aabb {
        let mut placed = Aabb::EMPTY;
        if let Some(root) = self.nodes.first() {
            for lane in (0..WIDTH).filter(|&lane| root.used & (1 << lane) != 0) {
                let corner =
                    |b: &[Simd<f32, WIDTH>; 3]| Vec3::new(b[0][lane], b[1][lane], b[2][lane]);
                let (lo, hi) =
                    instance_box(instance, (corner(&root.boxes.min), corner(&root.boxes.max)));
                placed = placed.union(Aabb { min: lo, max: hi });
            }
        }
        placed
    }

    /// Closest hit along `origin + t dir`, t in (0, t_max).
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> SurfaceHit {
        let hit = self.closest_prim(origin, dir, t_max);
        if hit.prim == NONE {
            return SurfaceHit::miss();
        }
        self.surface(hit, origin, dir)
    }

    /// The primitive hit first along `origin + t dir`, t in (0, t_max), and its t; `NONE`
    /// for a miss. Of a one-level tree's primitives hit at exactly the same t, the smallest id
    /// (with instances, see `closest_in`).
    #[inline]
    pub fn closest_prim(&self, origin: Vec3, dir: Vec3, t_max: f32) -> PrimHit {
        if self.instances.is_empty() {
            let (prim, t) = self.closest_one_level(origin, dir, t_max);
            PrimHit {
                prim,
                instance: NONE,
                t,
            }
        } else {
            self.closest_two_level(origin, dir, t_max)
        }
    }

    widest_simd! {
        /// [`Bvh::closest_prim`] of a tree without instances: the primitive and t.
        fn closest_one_level(&self, origin: Vec3, dir: Vec3, t_max: f32) -> (u32, f32)
            = closest_one_level_any_cpu, closest_one_level_avx512, closest_one_level_avx2
    }

    #[inline(always)]
    fn closest_one_level_any_cpu(&self, origin: Vec3, dir: Vec3, t_max: f32) -> (u32, f32) {
        let Some(root) = self.root else {
            return (NONE, t_max);
        };
        let mut no_instance = NONE;
        self.closest_in::<false>(root, origin, dir, (NONE, t_max), &mut no_instance)
    }

    widest_simd! {
        /// [`Bvh::closest_prim`] of a tree with instances.
        fn closest_two_level(&self, origin: Vec3, dir: Vec3, t_max: f32) -> PrimHit
            = closest_two_level_any_cpu, closest_two_level_avx512, closest_two_level_avx2
    }

    #[inline(always)]
    fn closest_two_level_any_cpu(&self, origin: Vec3, dir: Vec3, t_max: f32) -> PrimHit {
        let mut instance = NONE;
        let Some(root) = self.root else {
            return PrimHit {
                prim: NONE,
                instance,
                t: t_max,
            };
        };
        let (prim, t) = self.closest_in::<true>(root, origin, dir, (NONE, t_max), &mut instance);
        PrimHit { prim, instance, t }
    }

    /// The closest hit in the subtree `start` of a ray that has found `best` = (primitive, t)
    /// so far (`NONE` and t_max at first): the primitive and t, with the instance step compiled
    /// in where `INSTANCES` (the hit's instance is then written to `best_instance`, `NONE` for
    /// this tree's own primitives; the one-level loop never touches it).
    ///
    /// Of this tree's primitives hit at exactly the same t, the smallest id wins, so the answer
    /// is the least (t, id) whatever order the nodes are visited in: packet traversal
    /// (`bvh_packet.rs`) gives the same hits. (A tie between an instance's triangle and any
    /// other primitive still depends on the order; packets are not used with instances.)
    #[inline(always)]
    pub(super) fn closest_in<const INSTANCES: bool>(
        &self,
        start: u32,
        origin: Vec3,
        dir: Vec3,
        (mut best, mut best_t): (u32, f32),
        best_instance: &mut u32,
    ) -> (u32, f32) {
        let ray = Ray4::new(origin, dir);
        // Not zero-filled (3 KiB per ray): entries below `sp` are always written first.
        let mut stack = [const { MaybeUninit::<(u32, f32)>::uninit() }; STACK];
        let mut sp = 0;
        let mut current = start;
        loop {
            if current & LEAF == 0 {
                let node = &self.nodes[current as usize];
                let (near, hit) = ray.slab(&node.boxes, best_t);
                let mut bits = (hit & Mask::from_bitmask(node.used as u64)).to_bitmask() as u32;
                if bits != 0 {
                    let near = near.to_array();
                    if bits & (bits - 1) == 0 {
                        current = node.child[bits.trailing_zeros() as usize];
                        continue;
                    }
                    // Two or more children: sort by entry distance, go to the nearest and
                    // push the others farthest first. The build bounds the depth, so the
                    // stack never overflows.
                    let mut order = [(0u32, 0.0f32); WIDTH];
                    let mut k = 0;
                    while bits != 0 {
                        let lane = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        let mut j = k;
                        while j > 0 && order[j - 1].1 > near[lane] {
                            order[j] = order[j - 1];
                            j -= 1;
                        }
                        order[j] = (node.child[lane], near[lane]);
                        k += 1;
                    }
                    for &entry in order[1..k].iter().rev() {
                        stack[sp].write(entry);
                        sp += 1;
                        self.prefetch(entry.0);
                    }
                    current = order[0].0;
                    continue;
                }
            } else {
                let (blocks, spheres) = self.leaf_contents(current);
                for block in &self.blocks[blocks] {
                    let limit = tie_limit(best, best_t);
                    let t = ray.triangles(&block.triangles, 0.0, limit).to_array();
                    for (&t, &id) in t.iter().zip(&block.id) {
                        // Missed lanes are -1; hits are below `limit` as it was at the call.
                        if t >= 0.0 && (t < best_t || (t == best_t && id < best)) {
                            best_t = t;
                            best = id;
                            if INSTANCES {
                                *best_instance = NONE;
                            }
                        }
                    }
                }
                for block in &self.sphere_blocks[spheres] {
                    let limit = tie_limit(best, best_t);
                    let t = ray.spheres(&block.spheres, 0.0, limit).to_array();
                    for (&t, &id) in t.iter().zip(&block.id) {
                        if t >= 0.0 && (t < best_t || (t == best_t && id < best)) {
                            best_t = t;
                            best = id;
                            if INSTANCES {
                                *best_instance = NONE;
                            }
                        }
                    }
                }
                if INSTANCES {
                    for &i in &self.leaf_instances[self.instances_of_leaf(current)] {
                        let instance = &self.instances[i as usize];
                        let (o, d) = ray_to_object(instance, origin, dir);
                        let mesh = &self.meshes[self.instance_meshes[i as usize] as usize];
                        let Some(mesh_root) = mesh.root else { continue };
                        let mut no_instance = NONE;
                        let (prim, t) = mesh.closest_in::<false>(
                            mesh_root,
                            o,
                            d,
                            (NONE, best_t),
                            &mut no_instance,
                        );
                        if prim != NONE && t < best_t {
                            best_t = t;
                            best = prim;
                            *best_instance = i;
                        }
                    }
                }
            }
            // Pop the next node still in front of the closest hit: its stored entry distance
            // against the padded far bound, exactly the slab test's verdict with today's t_max.
            loop {
                if sp == 0 {
                    return (best, best_t);
                }
                sp -= 1;
                // SAFETY: entry `sp` was written by a push (sp only grows by writing).
                let (r, near) = unsafe { stack[sp].assume_init() };
                if near <= best_t * SLAB_PAD {
                    current = r;
                    break;
                }
            }
        }
    }

    /// Whether anything is hit along `origin + t dir`, t in (0, t_max).
    #[inline]
    pub fn any_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        if self.instances.is_empty() {
            self.any_one_level(origin, dir, t_max)
        } else {
            self.any_two_level(origin, dir, t_max)
        }
    }

    widest_simd! {
        /// [`Bvh::any_hit`] of a tree without instances.
        fn any_one_level(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool
            = any_one_level_any_cpu, any_one_level_avx512, any_one_level_avx2
    }

    #[inline(always)]
    fn any_one_level_any_cpu(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        // Not `is_some_and`: a closure is not compiled with the caller's target features.
        match self.root {
            Some(root) => self.any_in::<false>(root, origin, dir, t_max),
            None => false,
        }
    }

    widest_simd! {
        /// [`Bvh::any_hit`] of a tree with instances.
        fn any_two_level(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool
            = any_two_level_any_cpu, any_two_level_avx512, any_two_level_avx2
    }

    #[inline(always)]
    fn any_two_level_any_cpu(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        // Not `is_some_and`: a closure is not compiled with the caller's target features.
        match self.root {
            Some(root) => self.any_in::<true>(root, origin, dir, t_max),
            None => false,
        }
    }

    /// [`Bvh::any_hit`] in the subtree `start`, with the instance step compiled in where
    /// `INSTANCES`.
    #[inline(always)]
    pub(super) fn any_in<const INSTANCES: bool>(
        &self,
        start: u32,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
    ) -> bool {
        let ray = Ray4::new(origin, dir);
        let mut stack = [const { MaybeUninit::<u32>::uninit() }; STACK];
        let mut sp = 0;
        let mut current = start;
        loop {
            if current & LEAF == 0 {
                let node = &self.nodes[current as usize];
                let (_, hit) = ray.slab(&node.boxes, t_max);
                let mut bits = (hit & Mask::from_bitmask(node.used as u64)).to_bitmask() as u32;
                while bits != 0 {
                    let lane = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    stack[sp].write(node.child[lane]);
                    sp += 1;
                }
            } else {
                let (blocks, spheres) = self.leaf_contents(current);
                for block in &self.blocks[blocks] {
                    let t = ray.triangles(&block.triangles, 0.0, t_max);
                    if t.to_array().iter().any(|&t| t >= 0.0) {
                        return true;
                    }
                }
                for block in &self.sphere_blocks[spheres] {
                    let t = ray.spheres(&block.spheres, 0.0, t_max);
                    if t.to_array().iter().any(|&t| t >= 0.0) {
                        return true;
                    }
                }
                if INSTANCES {
                    for &i in &self.leaf_instances[self.instances_of_leaf(current)] {
                        let (o, d) = ray_to_object(&self.instances[i as usize], origin, dir);
                        let mesh = &self.meshes[self.instance_meshes[i as usize] as usize];
                        let Some(mesh_root) = mesh.root else { continue };
                        if mesh.any_in::<false>(mesh_root, o, d, t_max) {
                            return true;
                        }
                    }
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: entry `sp` was written by a push (sp only grows by writing).
            current = unsafe { stack[sp].assume_init() };
        }
    }

    /// Starts loading the node or first triangle block of reference `r` into the cache: a
    /// pushed child is usually popped soon, and incoherent rays on large meshes wait on memory
    /// (measured on the 1M-triangle mesh: 10-19% more closest-hit rays per second).
    #[inline(always)]
    pub(super) fn prefetch(&self, r: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let (start, bytes) = if r & LEAF == 0 {
                let node = self.nodes.as_ptr().wrapping_add(r as usize);
                (node as *const i8, std::mem::size_of::<WideNode>())
            } else if r & LISTED == 0 {
                let first = (r & ((1 << BLOCK_BITS) - 1)) as usize;
                let block = self.blocks.as_ptr().wrapping_add(first);
                (block as *const i8, std::mem::size_of::<TriangleBlock>())
            } else {
                return;
            };
            for line in (0..bytes).step_by(64) {
                // SAFETY: a prefetch is a hint; it never faults, whatever the address.
                unsafe { _mm_prefetch(start.wrapping_add(line), _MM_HINT_T0) };
            }
        }
    }

    /// The triangle blocks and the sphere blocks of leaf reference `r`.
    #[inline(always)]
    pub(super) fn leaf_contents(&self, r: u32) -> (Range<usize>, Range<usize>) {
        if r & LISTED == 0 {
            let first = (r & ((1 << BLOCK_BITS) - 1)) as usize;
            let count = ((r >> BLOCK_BITS) & 3) as usize + 1;
            (first..first + count, 0..0)
        } else {
            let leaf = &self.leaves[(r & !(LEAF | LISTED)) as usize];
            let first = leaf.first_block as usize;
            let sphere = leaf.first_sphere_block as usize;
            (
                first..first + leaf.triangle_blocks as usize,
                sphere..sphere + leaf.sphere_blocks as usize,
            )
        }
    }

    /// The range of [`Bvh::leaf_instances`] that leaf reference `r` holds.
    #[inline(always)]
    fn instances_of_leaf(&self, r: u32) -> Range<usize> {
        if r & LISTED == 0 {
            0..0
        } else {
            let (first, end) = self.leaf_instance_ranges[(r & !(LEAF | LISTED)) as usize];
            first as usize..end as usize
        }
    }

    /// The kernel's scalar intersection of primitive `id` (a sphere or a triangle of this
    /// tree): t in (0, t_max), or negative.
    pub fn intersect_prim(&self, id: u32, origin: Vec3, dir: Vec3, t_max: f32) -> f32 {
        let id = id as usize;
        if id < self.spheres.len() {
            let s = &self.spheres[id];
            intersect_sphere(origin, dir, Vec3::from(s.center), s.radius, 0.0, t_max)
        } else {
            let t = &self.triangles[id - self.spheres.len()];
            intersect_triangle(
                origin,
                dir,
                Vec3::from(t.p0),
                Vec3::from(t.edge1),
                Vec3::from(t.edge2),
                0.0,
                t_max,
            )
        }
    }

    /// The hit record of `hit` (from [`Bvh::closest_prim`] on this ray), computed as the GPU's
    /// closest-hit shaders do. An instance's triangle is intersected again with the ray mapped
    /// into its object space as the traversal mapped it (the same t and barycentrics).
    #[inline]
    pub fn surface(&self, hit: PrimHit, origin: Vec3, dir: Vec3) -> SurfaceHit {
        if hit.instance == NONE {
            self.surface_of_prim(hit.prim, origin, dir, hit.t)
        } else {
            self.surface_of_instance(hit, origin, dir)
        }
    }

    /// [`Bvh::surface`] of a hit on an instance's triangle.
    #[inline(never)]
    fn surface_of_instance(&self, hit: PrimHit, origin: Vec3, dir: Vec3) -> SurfaceHit {
        let instance = &self.instances[hit.instance as usize];
        let mesh = &self.meshes[self.instance_meshes[hit.instance as usize] as usize];
        let (o, d) = ray_to_object(instance, origin, dir);
        let index = hit.prim as usize;
        let tri = &mesh.triangles[index];
        let h = intersect_triangle_uv(
            o,
            d,
            Vec3::from(tri.p0),
            Vec3::from(tri.edge1),
            Vec3::from(tri.edge2),
            0.0,
            f32::INFINITY,
        );
        SurfaceHit::instanced_triangle(
            tri,
            mesh.shapes[index],
            instance,
            hit.instance,
            dir,
            hit.t,
            h.u,
            h.v,
        )
    }

    /// The hit record of sphere or triangle `id` of this tree at `t` along the ray.
    pub fn surface_of_prim(&self, id: u32, origin: Vec3, dir: Vec3, t: f32) -> SurfaceHit {
        // The winning triangle again, for its barycentrics (once per ray).
        let uv = self.barycentrics(id, origin, dir);
        self.surface_with_uv(id, origin, dir, t, uv)
    }

    /// The barycentrics u, v where the ray meets primitive `id` of this tree, as the kernel's
    /// `intersect_triangle_uv` computes them; (0, 0) for a sphere.
    #[inline(always)]
    pub fn barycentrics(&self, id: u32, origin: Vec3, dir: Vec3) -> (f32, f32) {
        if (id as usize) < self.spheres.len() {
            return (0.0, 0.0);
        }
        let tri = &self.triangles[id as usize - self.spheres.len()];
        let (p0, e1, e2) = (
            Vec3::from(tri.p0),
            Vec3::from(tri.edge1),
            Vec3::from(tri.edge2),
        );
        let h = intersect_triangle_uv(origin, dir, p0, e1, e2, 0.0, f32::INFINITY);
        (h.u, h.v)
    }

    /// [`Bvh::surface_of_prim`] with the barycentrics `uv` of a triangle's hit already known (as
    /// the kernel's `intersect_triangle_uv` computes them; ignored for spheres).
    pub fn surface_with_uv(
        &self,
        id: u32,
        origin: Vec3,
        dir: Vec3,
        t: f32,
        (u, v): (f32, f32),
    ) -> SurfaceHit {
        let id = id as usize;
        if id < self.spheres.len() {
            SurfaceHit::sphere(origin, dir, t, &self.spheres[id])
        } else {
            let index = id - self.spheres.len();
            SurfaceHit::triangle(&self.triangles[index], self.shapes[index], dir, t, u, v)
        }
    }
}

/// The bound below which a leaf's hits are accepted by a ray whose closest hit so far is
/// `best` at `best_t`: `best_t` itself while nothing is hit (t_max is excluded), else the next
/// float above it, so that a hit at exactly `best_t` is seen and the smaller id can win.
#[inline(always)]
pub(super) fn tie_limit(best: u32, best_t: f32) -> f32 {
    // Once something is hit, best_t is positive and finite: the next float is the next pattern.
    f32::from_bits(best_t.to_bits() + (best != NONE) as u32)
}

/// Up to [`WIDTH`] boxes in lanes (unused lanes empty; the node's `used` masks them).
fn lanes(bounds: &[Aabb]) -> Boxes<WIDTH> {
    let mut b = Boxes {
        min: [Simd::splat(f32::INFINITY); 3],
        max: [Simd::splat(f32::NEG_INFINITY); 3],
    };
    for (lane, a) in bounds.iter().enumerate() {
        for axis in 0..3 {
            b.min[axis][lane] = a.min[axis];
            b.max[axis][lane] = a.max[axis];
        }
    }
    b
}
