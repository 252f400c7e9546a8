//! Which candidate hits a traversal counts: every one ([`Solid`], a scene whose surfaces have
//! no holes, the loop as it always was), or those `kernel::opacity::covers` says are there
//! ([`Holes`], glTF's MASK and BLEND materials), as the GPU's any-hit shaders decide them.

use glam::{Vec2, Vec3};
use kernel::features::Dynamic;
use kernel::geometry::triangle_record_uv;
pub use kernel::opacity::HoleTables;
use kernel::opacity::{covers, CandidateRay};
use kernel::scene::{Triangle, NONE};

/// The answer for a triangle candidate of a traversal.
pub trait Presence: Copy {
    /// Every candidate is there: the leaf tests skip the question (compiled out).
    const SOLID: bool;
    /// Whether triangle `tri`, number `index` of its tree (the scene's triangle table, or an
    /// instanced mesh's), met by the traversal's ray `origin + t dir` (in the tree's space), is
    /// there.
    fn present(&self, tri: &Triangle, index: u32, origin: Vec3, dir: Vec3) -> bool;
    /// The answer inside the mesh of instance `instance`.
    fn in_instance(&self, instance: u32) -> Self;
}

/// Every candidate is there.
#[derive(Clone, Copy, Debug)]
pub struct Solid;

impl Presence for Solid {
    const SOLID: bool = true;
    #[inline(always)]
    fn present(&self, _: &Triangle, _: u32, _: Vec3, _: Vec3) -> bool {
        true
    }
    #[inline(always)]
    fn in_instance(&self, _: u32) -> Self {
        Solid
    }
}

/// The candidates of one world-space ray `origin + t dir` that the materials say are there;
/// `instance` is the instance whose mesh the traversal is in (`NONE` at the top level).
#[derive(Clone, Copy)]
pub struct Holes<'a> {
    pub tables: HoleTables<'a>,
    pub origin: Vec3,
    pub dir: Vec3,
    pub instance: u32,
}

impl<'a> Holes<'a> {
    /// The candidates of the world-space ray `origin + t dir` at the top level of the tree.
    pub fn of_ray(tables: HoleTables<'a>, origin: Vec3, dir: Vec3) -> Self {
        Holes {
            tables,
            origin,
            dir,
            instance: NONE,
        }
    }
}

impl Presence for Holes<'_> {
    const SOLID: bool = false;
    #[inline]
    fn present(&self, tri: &Triangle, index: u32, origin: Vec3, dir: Vec3) -> bool {
        // Only a material with holes needs the point's barycentrics.
        if !self.tables.materials[tri.material as usize].has_holes() {
            return true;
        }
        // The barycentrics as the hit record computes them (`Bvh::barycentrics`).
        let h = triangle_record_uv(tri, origin, dir);
        let ray = CandidateRay {
            origin: self.origin,
            dir: self.dir,
            triangle: index,
            instance: self.instance,
        };
        covers(Dynamic(0), &self.tables, tri, Vec2::new(h.u, h.v), &ray)
    }
    #[inline(always)]
    fn in_instance(&self, instance: u32) -> Self {
        Holes { instance, ..*self }
    }
}
