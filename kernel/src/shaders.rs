//! The SPIR-V entry points (compiled only for `target_arch = "spirv"`; ray-tracing intrinsics
//! are GPU-only). The ray-generation shader runs [`crate::path::render_sample`] with a
//! [`Tracer`] built on `trace_ray`; the other shaders answer its rays.
//!
//! Bindings (descriptor set 0): 0 TLAS, 1 accumulated sums (rgba32f: rgb sum, a count),
//! 2 params ([`RenderParams`]), 3 materials, 4 lights, 5 triangles, 6 spheres,
//! 7 accumulated squares (rgba32f: rgb sum of squared samples).
//! Hit groups: 0 triangles (closest hit), 1 spheres (intersection + closest hit).
//! Miss shader 0 serves both kinds of ray.

use crate::geometry::{intersect_sphere, reproject_to_sphere, triangle_normal};
use crate::path::{render_sample, SurfaceHit, Tracer};
use crate::scene::{Material, RenderParams, Sphere, SphereLight, Triangle, NONE};
use spirv_std::glam::{UVec2, UVec3, Vec3, Vec4};
use spirv_std::image::Image;
use spirv_std::ray_tracing::{AccelerationStructure, RayFlags};
use spirv_std::spirv;

/// What a closest-hit or miss shader hands back to the ray-generation shader.
#[derive(Clone, Copy)]
#[repr(C)]
pub struct HitPayload {
    /// xyz: hit position, w: ray parameter t (negative: miss).
    pub position_t: Vec4,
    /// xyz: unit geometric normal.
    pub normal: Vec4,
    pub material: u32,
    pub light: u32,
    /// 1 if the ray hit something; the miss shader clears it.
    pub hit: u32,
    pub _pad: u32,
}

/// [`Tracer`] over the top-level acceleration structure.
struct RayTracer<'a> {
    tlas: &'a AccelerationStructure,
    payload: &'a mut HitPayload,
}

impl Tracer for RayTracer<'_> {
    fn closest_hit(&mut self, origin: Vec3, dir: Vec3) -> SurfaceHit {
        self.payload.hit = 0;
        unsafe {
            self.tlas.trace_ray(
                RayFlags::OPAQUE,
                0xff,
                0,
                1,
                0,
                origin,
                0.0,
                dir,
                f32::MAX,
                self.payload,
            );
        }
        if self.payload.hit == 0 {
            return SurfaceHit::miss();
        }
        SurfaceHit {
            position: self.payload.position_t.truncate(),
            t: self.payload.position_t.w,
            normal: self.payload.normal.truncate(),
            material: self.payload.material,
            light: self.payload.light,
        }
    }

    fn occluded(&mut self, from: Vec3, to: Vec3) -> bool {
        // Any hit ends the ray at once and no closest-hit shader runs; only a miss clears `hit`.
        self.payload.hit = 1;
        unsafe {
            self.tlas.trace_ray(
                RayFlags::OPAQUE
                    | RayFlags::TERMINATE_ON_FIRST_HIT
                    | RayFlags::SKIP_CLOSEST_HIT_SHADER,
                0xff,
                0,
                1,
                0,
                from,
                0.0,
                to - from,
                1.0,
                self.payload,
            );
        }
        self.payload.hit != 0
    }
}

/// Ray generation: `samples_per_launch` samples of this pixel, added to the running sums in the
/// accumulation images (sums of radiance and sample count; sums of squared radiance, for each
/// pixel's variance). Non-finite samples are not added; they are counted in `accum_sq.a`.
#[spirv(ray_generation)]
pub fn raygen(
    #[spirv(launch_id)] launch_id: UVec3,
    #[spirv(descriptor_set = 0, binding = 0)] tlas: &AccelerationStructure,
    #[spirv(descriptor_set = 0, binding = 1)] accum: &Image!(2D, format = rgba32f, sampled = false),
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] params: &RenderParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] materials: &[Material],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] lights: &[SphereLight],
    #[spirv(descriptor_set = 0, binding = 7)] accum_sq: &Image!(
        2D,
        format = rgba32f,
        sampled = false
    ),
    #[spirv(ray_payload)] payload: &mut HitPayload,
) {
    let px = launch_id.x;
    let py = launch_id.y;
    let mut tracer = RayTracer { tlas, payload };
    let mut sum = Vec3::ZERO;
    let mut sum_sq = Vec3::ZERO;
    let mut count = 0.0;
    let mut discarded = 0.0;
    let mut s = 0;
    while s < params.samples_per_launch {
        let l = render_sample(
            &mut tracer,
            params,
            materials,
            lights,
            px,
            py,
            params.sample_offset + s,
        );
        if l.is_finite() {
            sum += l;
            sum_sq += l * l;
            count += 1.0;
        } else {
            discarded += 1.0;
        }
        s += 1;
    }
    let coord = UVec2::new(px, py);
    let previous: Vec4 = accum.read(coord);
    let previous_sq: Vec4 = accum_sq.read(coord);
    unsafe {
        accum.write(coord, previous + sum.extend(count));
        accum_sq.write(coord, previous_sq + sum_sq.extend(discarded));
    }
}

/// Miss: the ray left the scene.
#[spirv(miss)]
pub fn miss(#[spirv(incoming_ray_payload)] payload: &mut HitPayload) {
    payload.hit = 0;
}

/// Closest hit on a triangle: position from the ray, normal and material from the triangle
/// table (`instance_custom_index` is the instance's first triangle).
#[spirv(closest_hit)]
pub fn closest_hit_triangle(
    #[spirv(incoming_ray_payload)] payload: &mut HitPayload,
    #[spirv(primitive_id)] primitive: u32,
    #[spirv(instance_custom_index)] first: u32,
    #[spirv(world_ray_origin)] origin: Vec3,
    #[spirv(world_ray_direction)] dir: Vec3,
    #[spirv(ray_tmax)] t: f32,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] triangles: &[Triangle],
) {
    let tri = triangles[(first + primitive) as usize];
    let n = triangle_normal(Vec3::from(tri.edge1), Vec3::from(tri.edge2));
    payload.position_t = (origin + t * dir).extend(t);
    payload.normal = n.extend(0.0);
    payload.material = tri.material;
    payload.light = NONE;
    payload.hit = 1;
}

/// Intersection with a procedural sphere: the kernel's robust ray/sphere test, the same function
/// the CPU backend calls.
#[spirv(intersection)]
pub fn intersect_sphere_shader(
    #[spirv(primitive_id)] primitive: u32,
    #[spirv(instance_custom_index)] first: u32,
    #[spirv(object_ray_origin)] origin: Vec3,
    #[spirv(object_ray_direction)] dir: Vec3,
    #[spirv(ray_tmin)] t_min: f32,
    #[spirv(ray_tmax)] t_max: f32,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] spheres: &[Sphere],
) {
    let s = spheres[(first + primitive) as usize];
    let t = intersect_sphere(origin, dir, Vec3::from(s.center), s.radius, t_min, t_max);
    if t >= 0.0 {
        unsafe {
            spirv_std::arch::report_intersection(t, 0);
        }
    }
}

/// Closest hit on a sphere: the point re-projected onto the surface, the outward normal.
#[spirv(closest_hit)]
pub fn closest_hit_sphere(
    #[spirv(incoming_ray_payload)] payload: &mut HitPayload,
    #[spirv(primitive_id)] primitive: u32,
    #[spirv(instance_custom_index)] first: u32,
    #[spirv(world_ray_origin)] origin: Vec3,
    #[spirv(world_ray_direction)] dir: Vec3,
    #[spirv(ray_tmax)] t: f32,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] spheres: &[Sphere],
) {
    let s = spheres[(first + primitive) as usize];
    let center = Vec3::from(s.center);
    let p = reproject_to_sphere(origin + t * dir, center, s.radius);
    payload.position_t = p.extend(t);
    payload.normal = ((p - center) / s.radius).extend(0.0);
    payload.material = s.material;
    payload.light = s.light;
    payload.hit = 1;
}
