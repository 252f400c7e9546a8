//! The CPU backend's bounding volume hierarchy over spheres and triangles: the binary SAH tree
//! of [`super::bvh_build`] collapsed into an 8-wide tree (each node holds its children's boxes
//! side by side, as Embree's BVH8 does), so one SIMD slab test visits eight children; leaves
//! hold their triangles four to a block for the SIMD triangle test of [`super::simd`].
//! Traversal is iterative, nearest child first, and culls on pop by the entry distance stored
//! with each pushed node (`traverse`). 8 wide rather than 4: incoherent rays on large meshes are
//! bound by memory latency, and a shallower tree waits less (docs/performance.md, "CPU
//! traversal"). `hits` makes the kernel's hit records from the primitives found.
//!
//! Primitive ids below `spheres.len()` are spheres, then triangles, then instances. An instance
//! (`kernel::scene::Instance`) places a mesh that has its own hierarchy in object space: a ray
//! reaching it in a leaf is mapped into object space (`kernel::instance::ray_to_object`; its
//! direction not normalised, so t means the same in both) and traced through the mesh's tree
//! (a two-level BVH, as Embree and the GPU's TLAS over BLASes do). Traversal is compiled twice,
//! with and without the instance step, so a scene without instances runs the one-level loop.
//! The closest hit is the kernel's own intersection functions' answer (bit-identical t), the
//! least (t, instance, id), whatever the traversal order.

mod hits;
mod holes;
mod traverse;

pub use holes::HoleTables;
pub(super) use holes::{Holes, Presence, Solid};

use super::bvh_build::{Aabb, BinaryBvh, SAH_MAX_DEPTH};
use super::huge_pages;
use super::simd::{widest_simd, Boxes, Ray4, Spheres4, Triangles4, SLAB_PAD};
use crate::scene::instancing::instance_box;
use crate::scene::Scene;
use glam::Vec3;
use kernel::geometry::{intersect_sphere, intersect_triangle, triangle_record_uv, TriangleShape};
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

/// A "best so far" for a search that must also report hits at exactly its t: a tree's own
/// primitive beats it at that t whatever its id, and `tie_limit` admits that t. An instance's
/// mesh is searched from it where the ray has a hit already, so that a tie with that hit is
/// decided by the instance order (`own_tie_won`'s counterpart in `closest_in`).
pub(super) const TIE: u32 = NONE - 1;

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
    pub(super) instances: Vec<Instance>,
    pub(super) instance_meshes: Vec<u32>,
    pub(super) meshes: Vec<Bvh>,
    /// The instances of the listed leaves, leaf by leaf, and each listed leaf's range of them
    /// (by the leaf's index in `leaves`).
    pub(super) leaf_instances: Vec<u32>,
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
        let binary = BinaryBvh::build(&bounds, spheres.len() + triangles.len());
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
