//! The record of where a ray meets the scene ([`SurfaceHit`]) and its one constructor per shape
//! (`sphere`, `triangle`, `instanced_triangle`), which both backends call: the GPU's hit
//! shaders and the CPU's traversal make the same record from the same ray.

use crate::geometry::{
    reproject_to_sphere, sphere_point_error, triangle_offsets_conditioned, triangle_point,
    TriangleShape,
};
use crate::instance::{instanced_offsets_v3, normal_to_world, point_to_world, ObjectLeaving};
use crate::real::V3;
use crate::scene::{Instance, Sphere, Triangle, NONE};
use spirv_std::glam::{Vec2, Vec3};

/// Where a ray meets the scene first. `t < 0` means it met nothing.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    pub position: Vec3,
    /// Ray parameter of the hit (in units of the ray's direction), negative for a miss.
    pub t: f32,
    /// Unit geometric normal: outward for spheres, edge1 x edge2 for triangles.
    pub normal: Vec3,
    /// Index into the material table.
    pub material: u32,
    /// Index into the light table if the surface is a light, else [`NONE`].
    pub light: u32,
    /// How far along the normal rays leaving `position` start (`geometry::lift_ray_origin`):
    /// the position's rounding along the normal and what the tests that could meet the surface
    /// again need to decide the ray's side (`geometry::triangle_offsets_v3`; for a sphere, a
    /// per-component error bound times |normal|_1; for an instance,
    /// `instance::instanced_offsets_v3`).
    pub offset: f32,
    /// What a ray within `geometry::GRAZING_COS` of the surface adds to `offset`
    /// (`geometry::continuation_origin`, `geometry::shadow_segment`): a GPU's triangle test's
    /// rounding anywhere on the triangle (`geometry::triangle_grazing_offset_v3`; for an
    /// instance, what lifts such a ray to `instance::instanced_offset_v3`'s height, or 0 where
    /// `offset` is that height); 0 for spheres.
    pub grazing_offset: f32,
    /// Whether the ray arrived from the side `normal` points away from (a sphere's inside, a
    /// triangle's back). Decided where the record is made, and robustly for spheres: by which
    /// side of the sphere the ray's origin lies on, not by the sign of `normal . dir`, which
    /// rounding flips at grazing hits (a grazing ray would otherwise leave inward and be
    /// trapped inside the sphere).
    pub arrived_behind: bool,
    /// A triangle's index into the shading table (`Triangle::shading`), else [`NONE`].
    pub shading: u32,
    /// A triangle's barycentrics (u, v) of p1 and p2 at the hit.
    pub barycentrics: Vec2,
    /// The instance (`scene::Instance`) whose mesh the triangle belongs to, else [`NONE`]
    /// (the triangle is in world space): its shading record is then in object space.
    pub instance: u32,
}

impl SurfaceHit {
    /// The record of a ray that left the scene.
    #[inline]
    pub fn miss() -> Self {
        Self {
            position: Vec3::ZERO,
            t: -1.0,
            normal: Vec3::ZERO,
            material: NONE,
            light: NONE,
            offset: 0.0,
            grazing_offset: 0.0,
            arrived_behind: false,
            shading: NONE,
            barycentrics: Vec2::ZERO,
            instance: NONE,
        }
    }

    /// The record of ray `origin + t dir` meeting `sphere` at `t`: the
    /// point re-projected onto the surface, the outward normal, the point's error bound, and
    /// the side the ray came from (the side its origin is on: exact geometry for a convex
    /// surface, and a sign that holds at grazing hits). Both backends build sphere hits here.
    #[inline]
    pub fn sphere(origin: Vec3, dir: Vec3, t: f32, sphere: &Sphere) -> Self {
        let (center, radius) = (Vec3::from(sphere.center), sphere.radius);
        let position = reproject_to_sphere(origin + t * dir, center, radius);
        let from_center = origin - center;
        let normal = (position - center) / radius;
        Self {
            position,
            t,
            normal,
            material: sphere.material,
            light: sphere.light,
            offset: sphere_point_error(center, radius) * normal.abs().element_sum(),
            grazing_offset: 0.0,
            arrived_behind: from_center.dot(from_center) < radius * radius,
            shading: NONE,
            barycentrics: Vec2::ZERO,
            instance: NONE,
        }
    }

    /// The record of a ray along `dir` meeting triangle `tri` (of shape `shape`) at `t`, at
    /// barycentric (u, v): the point from the barycentrics (`triangle_point`: on the plane up to
    /// a few roundings, whatever t's error), the geometric normal edge1 x edge2, the heights
    /// rays leave at (`geometry::triangle_offsets_v3`), and the side by the sign of
    /// `normal . dir`. Both backends build triangle
    /// hits here.
    #[inline]
    pub fn triangle(
        tri: &Triangle,
        shape: TriangleShape,
        dir: Vec3,
        t: f32,
        u: f32,
        v: f32,
    ) -> Self {
        let (p0, e1, e2) = (
            Vec3::from(tri.p0),
            Vec3::from(tri.edge1),
            Vec3::from(tri.edge2),
        );
        let (offset, grazing_offset) = triangle_offsets_conditioned(p0, e1, e2, u, v, &shape);
        Self {
            position: triangle_point(p0, e1, e2, u, v),
            t,
            normal: shape.normal,
            material: tri.material,
            light: tri.light,
            offset,
            grazing_offset,
            arrived_behind: Self::behind_plane(shape.normal, dir),
            shading: tri.shading,
            barycentrics: Vec2::new(u, v),
            instance: NONE,
        }
    }

    /// The record of a ray along world direction `dir` meeting triangle `tri` (object space, of
    /// shape `shape`) of instance `instance` (number `index`) at `t`, barycentric (u, v): the
    /// object point (`triangle_point`) mapped to world space, the geometric normal
    /// M^-T (edge1 x edge2) normalised (along the edge cross product of the same triangle
    /// flattened into world space, whose winding a mirroring transform reverses), the heights
    /// of `instance::instanced_offsets_v3` (the object triangle's own offset carried to world
    /// space where the map turns directions little, else the object point's bound and its
    /// grazing offset for every ray), and the side by the sign of `normal . dir`. Barycentrics
    /// and the shading record stay the object-space triangle's (an affine map keeps
    /// barycentrics). Both backends build instanced hits here.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn instanced_triangle(
        tri: &Triangle,
        shape: TriangleShape,
        instance: &Instance,
        index: u32,
        dir: Vec3,
        t: f32,
        u: f32,
        v: f32,
    ) -> Self {
        let (p0, e1, e2) = (
            Vec3::from(tri.p0),
            Vec3::from(tri.edge1),
            Vec3::from(tri.edge2),
        );
        let object = ObjectLeaving::of_triangle((p0, e1, e2), (u, v), &shape);
        let position = point_to_world(instance, object.point.into());
        let world_normal = normal_to_world(instance, shape.normal);
        let normal = world_normal.normalize();
        let (offset, grazing_offset) = instanced_offsets_v3(
            instance,
            &object,
            (V3::from(position), V3::from(normal), world_normal.length()),
        );
        Self {
            position,
            t,
            normal,
            material: tri.material,
            light: tri.light,
            offset,
            grazing_offset,
            arrived_behind: Self::behind_plane(normal, dir),
            shading: tri.shading,
            barycentrics: Vec2::new(u, v),
            instance: index,
        }
    }

    /// Whether a ray along `dir` meets a flat surface of unit normal `normal` from behind.
    #[inline]
    pub fn behind_plane(normal: Vec3, dir: Vec3) -> bool {
        normal.dot(-dir) < 0.0
    }

    /// The normal on the side the ray arrived from, which light leaving toward the ray's
    /// origin leaves from (surfaces are two-sided): the `n` of a vertex's BRDF.
    #[inline]
    pub fn facing_normal(&self) -> Vec3 {
        if self.arrived_behind {
            -self.normal
        } else {
            self.normal
        }
    }

    #[inline]
    pub fn is_hit(&self) -> bool {
        self.t >= 0.0
    }
}
