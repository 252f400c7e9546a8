//! The hit records of the [`Bvh`]'s primitives: the kernel's one constructor per shape
//! (`kernel::SurfaceHit`) for a sphere, a world-space triangle or an instanced one, from the
//! primitive a traversal found.

use super::*;

impl Bvh {
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
        let h = triangle_record_uv(tri, o, d);
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
        let h = triangle_record_uv(
            &self.triangles[id as usize - self.spheres.len()],
            origin,
            dir,
        );
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
