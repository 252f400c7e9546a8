//! The SPIR-V entry points (compiled only for `target_arch = "spirv"`; ray-tracing intrinsics
//! are GPU-only). The ray-generation shader runs [`crate::split::render_split_sample`] (which
//! is [`crate::path::render_sample`] where paths do not split) with a [`Tracer`] built on
//! `trace_ray`; the other shaders answer its rays.
//!
//! Bindings (descriptor set 0): 0 TLAS, 1 running mean (rgba32f: rgb mean, a sample count),
//! 2 params ([`RenderParams`]), 3 materials, 4 lights, 5 triangles, 6 spheres,
//! 7 running M2 (rgba32f: rgb sum of squared deviations from the mean, a discarded samples),
//! 8 adaptive-sampling pilots (rgba32f: luminance mean, luminance M2, count, unused),
//! 9 the environment table (`crate::environment`; one number when there is no map),
//! 10 the shading table (`ShadingTriangle`s; one zero record when there is none),
//! 11 the texture table (`crate::texture`), 12 the instance table (`Instance`s; one zero record
//! when there is none), 13 the media table (`crate::medium`; record 0, vacuum, always there),
//! 14 the grid table (`crate::density_grid`; one word when no medium has a grid),
//! 15 the split table (`crate::split`; one word when paths do not split).
//! Specialization constant 0: the feature bits of `crate::features` (0: generic path).
//! Hit groups: 0 triangles (closest hit + any hit), then 1 spheres (intersection + closest
//! hit), then instanced triangles (closest hit + any hit), each present only where the scene
//! has that geometry. Triangle BLASes are built without the OPAQUE flag and rays traced without
//! `RayFlags::OPAQUE`, so the any-hit shaders see every candidate and drop those the ray cannot
//! make (`crate::plane_side`) or that fall in a hole (`crate::opacity`). Miss shader 0 serves
//! both kinds of ray.

use crate::adaptive::{luminance, pixel_converged};
use crate::features::{Dynamic, FeatureSet};
use crate::film_sample::{classify, sample_use};
use crate::geometry::{intersect_sphere, TriangleShape};
use crate::hit::SurfaceHit;
use crate::instance::ray_to_object;
use crate::medium::Medium;
use crate::opacity::{covers, CandidateRay, HoleTables};
use crate::path::Tracer;
use crate::plane_side::ray_leaves_triangle_plane;
use crate::scene::{
    Instance, Light, Material, RenderParams, ShadingTriangle, Sphere, Triangle, NONE,
};
use crate::scene_view::SceneView;
use crate::split::render_split_sample;
#[cfg(feature = "probe")]
use spirv_std::glam::UVec4;
use spirv_std::glam::{UVec2, UVec3, Vec2, Vec3, Vec4};
use spirv_std::image::Image;
use spirv_std::ray_tracing::{AccelerationStructure, RayFlags};
use spirv_std::spirv;

/// What a closest-hit or miss shader hands back to the ray-generation shader.
#[derive(Clone, Copy)]
#[repr(C)]
pub struct HitPayload {
    /// xyz: hit position, w: ray parameter t (negative: miss).
    pub position_t: Vec4,
    /// xyz: unit geometric normal, w: the height rays leave at (`SurfaceHit::offset`).
    pub normal: Vec4,
    pub material: u32,
    pub light: u32,
    /// 0 if the ray hit nothing (the miss shader clears it); else 1, plus 2 if it arrived from
    /// behind the normal (`SurfaceHit::arrived_behind`).
    pub hit: u32,
    /// `SurfaceHit::grazing_offset`.
    pub grazing_offset: f32,
    /// A triangle's barycentrics and shading-table index (`SurfaceHit::shading`).
    pub barycentrics: Vec2,
    pub shading: u32,
    /// The hit's instance (`SurfaceHit::instance`).
    pub instance: u32,
}

impl HitPayload {
    /// Stores a closest-hit shader's record (and marks the ray as having hit).
    fn store(&mut self, h: &SurfaceHit) {
        self.position_t = h.position.extend(h.t);
        self.normal = h.normal.extend(h.offset);
        self.material = h.material;
        self.light = h.light;
        self.hit = 1 | (h.arrived_behind as u32) << 1;
        self.grazing_offset = h.grazing_offset;
        self.barycentrics = h.barycentrics;
        self.shading = h.shading;
        self.instance = h.instance;
    }

    /// The record a closest-hit shader stored, or a miss.
    fn surface(&self) -> SurfaceHit {
        if self.hit == 0 {
            return SurfaceHit::miss();
        }
        SurfaceHit {
            position: self.position_t.truncate(),
            t: self.position_t.w,
            normal: self.normal.truncate(),
            material: self.material,
            light: self.light,
            offset: self.normal.w,
            grazing_offset: self.grazing_offset,
            arrived_behind: self.hit & 2 != 0,
            shading: self.shading,
            barycentrics: self.barycentrics,
            instance: self.instance,
        }
    }
}

/// [`Tracer`] over the top-level acceleration structure. Rays carry no opacity flag: the
/// geometry's decides (triangles without OPAQUE, so their any-hit shaders see every candidate;
/// spheres OPAQUE).
struct RayTracer<'a> {
    tlas: &'a AccelerationStructure,
    payload: &'a mut HitPayload,
}

impl RayTracer<'_> {
    /// The closest hit along `origin + t dir`, t in (0, t_max), through the closest-hit and
    /// miss shaders.
    fn trace_closest(&mut self, origin: Vec3, dir: Vec3, t_max: f32) -> SurfaceHit {
        self.payload.hit = 0;
        unsafe {
            self.tlas.trace_ray(
                RayFlags::NONE,
                0xff,
                0,
                1,
                0,
                origin,
                0.0,
                dir,
                t_max,
                self.payload,
            );
        }
        self.payload.surface()
    }
}

impl Tracer for RayTracer<'_> {
    fn closest_hit(&mut self, origin: Vec3, dir: Vec3) -> SurfaceHit {
        self.trace_closest(origin, dir, f32::MAX)
    }

    fn occluded(&mut self, from: Vec3, to: Vec3) -> bool {
        // Any hit ends the ray at once and no closest-hit shader runs; only a miss clears `hit`.
        self.payload.hit = 1;
        unsafe {
            self.tlas.trace_ray(
                RayFlags::TERMINATE_ON_FIRST_HIT | RayFlags::SKIP_CLOSEST_HIT_SHADER,
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

    fn first_hit_on(&mut self, from: Vec3, to: Vec3) -> SurfaceHit {
        self.trace_closest(from, to - from, 1.0)
    }
}

/// Ray generation: `samples_per_launch` samples of this pixel, merged into the running mean and
/// M2 (sum of squared deviations) of the accumulation images: Welford's update within the
/// launch, Chan, Golub and LeVeque's pairwise combination with the earlier launches. Both stay
/// accurate in f32 where a sum of squares minus n mean^2 would cancel. Samples the film does not
/// sum (`film_sample::classify`: non-finite or huge) are not merged; they are counted in
/// `accum_m2.a`. With adaptive sampling, a converged pixel takes no samples, and pilot samples
/// go to the pilot image instead (`crate::adaptive`).
/// The earlier launches' mean and M2 are read after the sample loop, where they are merged: a
/// value read before it would be live across every trace call, which GPUs that traverse in
/// hardware save and restore around each ray (`docs/gpu.md`).
#[spirv(ray_generation)]
pub fn raygen(
    #[spirv(launch_id)] launch_id: UVec3,
    #[spirv(spec_constant(id = 0, default = 0))] features: u32,
    #[spirv(descriptor_set = 0, binding = 0)] tlas: &AccelerationStructure,
    #[spirv(descriptor_set = 0, binding = 1)] accum_mean: &Image!(
        2D,
        format = rgba32f,
        sampled = false
    ),
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] params: &RenderParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] materials: &[Material],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] lights: &[Light],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 9)] environment: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 10)] shading: &[ShadingTriangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 11)] textures: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 12)] instances: &[Instance],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 13)] media: &[Medium],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 14)] grids: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 15)] splits: &[u32],
    #[spirv(descriptor_set = 0, binding = 7)] accum_m2: &Image!(
        2D,
        format = rgba32f,
        sampled = false
    ),
    #[spirv(descriptor_set = 0, binding = 8)] pilots: &Image!(
        2D,
        format = rgba32f,
        sampled = false
    ),
    #[spirv(ray_payload)] payload: &mut HitPayload,
) {
    let px = launch_id.x;
    let py = launch_id.y;
    let coord = UVec2::new(px, py);
    let adaptive = Dynamic(features).adaptive(params);
    let mut pilot = Vec4::ZERO;
    if adaptive {
        pilot = pilots.read(coord);
        let merged: Vec4 = accum_mean.read(coord);
        if pixel_converged(params, pilot.x, pilot.y, pilot.z, merged.w) {
            return;
        }
    }
    let mut tracer = RayTracer { tlas, payload };
    let mut n_b = 0.0;
    let mut mean_b = Vec3::ZERO;
    let mut m2_b = Vec3::ZERO;
    let mut discarded = 0.0;
    let scene = SceneView {
        params,
        materials,
        lights,
        environment,
        shading,
        textures,
        instances,
        media,
        grids,
        splits,
    };
    let split = Dynamic(features).split(params);
    let mut s = 0;
    while s < params.samples.count {
        let index = params.samples.first + s;
        // One loop for split and unsplit paths: one copy of the path's code in the module.
        let f = Dynamic(features);
        let l = render_split_sample(&mut tracer, f, &scene, px, py, index, split);
        let class = classify(params, index, l);
        if class == sample_use::DISCARDED {
            discarded += 1.0;
        } else if class == sample_use::PILOT {
            // Welford on the pilots' luminance, straight into the pilot record.
            let y = luminance(l);
            pilot.z += 1.0;
            let d = y - pilot.x;
            pilot.x += d / pilot.z;
            pilot.y += d * (y - pilot.x);
        } else {
            n_b += 1.0;
            let d = l - mean_b;
            mean_b += d / n_b;
            m2_b += d * (l - mean_b);
        }
        s += 1;
    }
    if adaptive {
        unsafe {
            pilots.write(coord, pilot);
        }
    }
    let a: Vec4 = accum_mean.read(coord);
    let a_m2: Vec4 = accum_m2.read(coord);
    let n_a = a.w;
    let n = n_a + n_b;
    // Share of this launch in the merged mean (0 when nothing at all has been merged yet).
    let w = if n > 0.0 { n_b / n } else { 0.0 };
    let delta = mean_b - a.truncate();
    let mean = a.truncate() + delta * w;
    let m2 = a_m2.truncate() + m2_b + delta * delta * (n_a * w);
    unsafe {
        accum_mean.write(coord, mean.extend(n));
        accum_m2.write(coord, m2.extend(a_m2.w + discarded));
    }
}

/// Miss: the ray left the scene.
#[spirv(miss)]
pub fn miss(#[spirv(incoming_ray_payload)] payload: &mut HitPayload) {
    payload.hit = 0;
}

/// Closest hit on a triangle: the record of `SurfaceHit::triangle`, as on the CPU, from the
/// triangle table (`instance_custom_index` is the instance's first triangle).
#[spirv(closest_hit)]
pub fn closest_hit_triangle(
    #[spirv(incoming_ray_payload)] payload: &mut HitPayload,
    #[spirv(hit_attribute)] barycentrics: &Vec2,
    #[spirv(primitive_id)] primitive: u32,
    #[spirv(instance_custom_index)] first: u32,
    #[spirv(world_ray_direction)] dir: Vec3,
    #[spirv(ray_tmax)] t: f32,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] triangles: &[Triangle],
) {
    let tri = &triangles[(first + primitive) as usize];
    let shape = TriangleShape::of(Vec3::from(tri.edge1), Vec3::from(tri.edge2));
    payload.store(&SurfaceHit::triangle(
        tri,
        shape,
        dir,
        t,
        barycentrics.x,
        barycentrics.y,
    ));
}

/// Closest hit on an instanced triangle: the record of `SurfaceHit::instanced_triangle`, as on
/// the CPU, from the instance table (`instance_custom_index` is the instance's record) and the
/// triangle table (the instance's mesh from `Instance::first_triangle`). The hardware's `t` and
/// barycentrics are the object-space ray's, which an affine map keeps.
#[spirv(closest_hit)]
pub fn closest_hit_instance(
    #[spirv(incoming_ray_payload)] payload: &mut HitPayload,
    #[spirv(hit_attribute)] barycentrics: &Vec2,
    #[spirv(primitive_id)] primitive: u32,
    #[spirv(instance_custom_index)] index: u32,
    #[spirv(world_ray_direction)] dir: Vec3,
    #[spirv(ray_tmax)] t: f32,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] triangles: &[Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 12)] instances: &[Instance],
) {
    let instance = &instances[index as usize];
    let tri = &triangles[(instance.first_triangle + primitive) as usize];
    let shape = TriangleShape::of(Vec3::from(tri.edge1), Vec3::from(tri.edge2));
    payload.store(&SurfaceHit::instanced_triangle(
        tri,
        shape,
        instance,
        index,
        dir,
        t,
        barycentrics.x,
        barycentrics.y,
    ));
}

/// Any hit on a triangle: the candidate is ignored where the ray certainly leaves the
/// triangle's plane ([`plane_side`](crate::plane_side): a hit the device's triangle test made by
/// its rounding) or where `opacity::covers` says the surface is not there, as the CPU's leaf
/// test ignores it (`instance_custom_index` is the instance's first triangle; the instance's
/// transform is the identity, so the world-space ray is the one the device met it with). Of
/// the specialization constant it reads only whether a material may have holes.
#[spirv(any_hit)]
pub fn any_hit_triangle(
    #[spirv(spec_constant(id = 0, default = 0))] features: u32,
    #[spirv(hit_attribute)] barycentrics: &Vec2,
    #[spirv(primitive_id)] primitive: u32,
    #[spirv(instance_custom_index)] first: u32,
    #[spirv(world_ray_origin)] origin: Vec3,
    #[spirv(world_ray_direction)] dir: Vec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] materials: &[Material],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] triangles: &[Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 10)] shading: &[ShadingTriangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 11)] textures: &[u32],
) {
    let index = first + primitive;
    let ray = CandidateRay {
        origin,
        dir,
        triangle: index,
        instance: NONE,
    };
    let tri = &triangles[index as usize];
    let tables = HoleTables {
        materials,
        shading,
        textures,
    };
    ignore_unless_met(features, &tables, tri, *barycentrics, &ray, origin, dir);
}

/// Any hit on an instanced triangle: as [`any_hit_triangle`], the triangle from the instance's
/// mesh (`instance_custom_index` is the instance's record) and its plane tested against the
/// world ray mapped into object space by the stored inverse (`instance::ray_to_object`), as the
/// CPU maps it: not the device's object ray, whose inverse Vulkan does not specify, so that the
/// plane height (`instance::instanced_plane_height_v3`) needs only that map's rounding.
#[spirv(any_hit)]
pub fn any_hit_instance(
    #[spirv(spec_constant(id = 0, default = 0))] features: u32,
    #[spirv(hit_attribute)] barycentrics: &Vec2,
    #[spirv(primitive_id)] primitive: u32,
    #[spirv(instance_custom_index)] index: u32,
    #[spirv(world_ray_origin)] origin: Vec3,
    #[spirv(world_ray_direction)] dir: Vec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] materials: &[Material],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] triangles: &[Triangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 10)] shading: &[ShadingTriangle],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 11)] textures: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 12)] instances: &[Instance],
) {
    let ray = CandidateRay {
        origin,
        dir,
        triangle: primitive,
        instance: index,
    };
    let instance = &instances[index as usize];
    let tri = &triangles[(instance.first_triangle + primitive) as usize];
    let (object_origin, object_dir) = ray_to_object(instance, origin, dir);
    let tables = HoleTables {
        materials,
        shading,
        textures,
    };
    ignore_unless_met(
        features,
        &tables,
        tri,
        *barycentrics,
        &ray,
        object_origin,
        object_dir,
    );
}

/// Ignores the candidate hit of `ray` on `tri` at barycentrics `bary` where the ray in the
/// triangle's space (`origin`, `dir`: the world ray, or for an instance the world ray mapped by
/// the stored inverse) certainly leaves its plane,
/// or, where `features` says a material may have holes, where `opacity::covers` says the
/// surface is not there (asked the generic path's questions, `Dynamic(0)`: the same answers as
/// specialized); what both any-hit shaders do.
#[inline]
fn ignore_unless_met(
    features: u32,
    tables: &HoleTables,
    tri: &Triangle,
    bary: Vec2,
    ray: &CandidateRay,
    origin: Vec3,
    dir: Vec3,
) {
    let (p0, edge1, edge2) = (
        Vec3::from(tri.p0),
        Vec3::from(tri.edge1),
        Vec3::from(tri.edge2),
    );
    if ray_leaves_triangle_plane(origin, dir, p0, edge1, edge2)
        || (Dynamic(features).opacity() && !covers(Dynamic(0), tables, tri, bary, ray))
    {
        unsafe { spirv_std::arch::ignore_intersection() };
    }
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
    payload.store(&SurfaceHit::sphere(
        origin,
        dir,
        t,
        &spheres[(first + primitive) as usize],
    ));
}

/// Push constants of [`probe`] (feature `probe`: tests only).
#[cfg(feature = "probe")]
#[derive(Clone, Copy)]
#[repr(C)]
pub struct ProbeArgs {
    /// One of `crate::probe::function`.
    pub function: u32,
    /// Number of records.
    pub count: u32,
}

/// Compute entry point for the equivalence tests: record i of `input` (four `UVec4`) through
/// [`crate::probe::evaluate`] into record i of `output` (two `UVec4`). Only in the tests'
/// module (feature `probe`).
#[cfg(feature = "probe")]
#[spirv(compute(threads(64)))]
pub fn probe(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(push_constant)] args: &ProbeArgs,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] input: &[UVec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] output: &mut [UVec4],
) {
    let i = id.x;
    if i < args.count {
        let b = (4 * i) as usize;
        let out = crate::probe::evaluate(
            args.function,
            [input[b], input[b + 1], input[b + 2], input[b + 3]],
        );
        output[(2 * i) as usize] = out[0];
        output[(2 * i + 1) as usize] = out[1];
    }
}
