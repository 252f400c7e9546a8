//! Ray throughput of the CPU traversal, on two ray sets with opposite coherence: the camera's
//! rays (one per pixel centre, neighbours nearly parallel) and diffuse bounce rays (one
//! cosine-distributed direction from each camera ray's hit, as a path tracer's second
//! vertex shoots them); and on the rays a render itself traces (one path per pixel: its
//! extension rays and its shadow segments). Every set can be written to a file so another ray
//! tracer (Embree, in `scripts/embree_rays.c`) traces exactly the same rays.

use crate::cpu::Bvh;
use crate::cpu::{BvhTracer, CpuRenderer};
use crate::cpu::{PacketTracer, RayPacket, SmallScene, LANES};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use glam::Vec3;
use kernel::camera::{camera_origin, camera_ray_direction};
use kernel::features::Dynamic;
use kernel::geometry::lift_ray_origin;
use kernel::rng::SampleRng;
use kernel::sampling::sample_cosine_hemisphere;
use kernel::scene::NONE;
use kernel::{SurfaceHit, Tracer};
use std::io::Write;
use std::simd::Simd;
use std::time::Instant;

/// Rays to trace, each from `origins[i]` along `dirs[i]` for t in (0, t_max[i]).
#[derive(Clone, Debug, Default)]
pub struct RaySet {
    pub name: &'static str,
    pub origins: Vec<Vec3>,
    pub dirs: Vec<Vec3>,
    pub t_max: Vec<f32>,
}

impl RaySet {
    pub fn len(&self) -> usize {
        self.origins.len()
    }
    pub fn is_empty(&self) -> bool {
        self.origins.is_empty()
    }
}

/// The primary rays through the pixel centres of a `width` x `height` image of the scene.
pub fn camera_rays(scene: &Scene, width: u32, height: u32) -> RaySet {
    let mut desc = scene.camera;
    desc.width = width;
    desc.height = height;
    let camera = desc.to_kernel();
    let eye = camera_origin(&camera);
    let mut rays = RaySet {
        name: "camera (coherent)",
        ..RaySet::default()
    };
    for py in 0..height {
        for px in 0..width {
            rays.origins.push(eye);
            rays.dirs.push(camera_ray_direction(
                &camera, width, height, px, py, 0.5, 0.5,
            ));
            rays.t_max.push(f32::INFINITY);
        }
    }
    rays
}

/// One diffuse bounce from each hit of `primary`: cosine-distributed about the normal on the
/// side the ray came from, starting at the kernel's offset origin (as `trace_path` spawns it).
pub fn bounce_rays(bvh: &Bvh, primary: &RaySet, seed: u32) -> RaySet {
    let mut rays = RaySet {
        name: "diffuse bounce (incoherent)",
        ..RaySet::default()
    };
    for i in 0..primary.len() {
        let hit = bvh.closest_hit(primary.origins[i], primary.dirs[i], primary.t_max[i]);
        if !hit.is_hit() {
            continue;
        }
        let n = hit.facing_normal();
        let mut rng = SampleRng::new(seed, i as u32, 0);
        let (u1, u2) = (rng.next_f32(), rng.next_f32());
        rays.origins
            .push(lift_ray_origin(hit.position, n, hit.offset));
        rays.dirs.push(sample_cosine_hemisphere(n, u1, u2));
        rays.t_max.push(f32::INFINITY);
    }
    rays
}

/// What one pass over a ray set found: per ray the primitive hit (`NONE` for a miss) and t.
#[derive(Clone, Debug, PartialEq)]
pub struct RayResults {
    pub prim: Vec<u32>,
    pub t: Vec<f32>,
}

/// Traces every ray of `rays` (closest hit) on this thread.
pub fn trace_all(bvh: &Bvh, rays: &RaySet) -> RayResults {
    let mut out = RayResults {
        prim: Vec::with_capacity(rays.len()),
        t: Vec::with_capacity(rays.len()),
    };
    for i in 0..rays.len() {
        let hit = bvh.closest_prim(rays.origins[i], rays.dirs[i], rays.t_max[i]);
        out.prim.push(hit.prim);
        out.t.push(hit.t);
    }
    out
}

/// Whether each ray of `rays` is occluded (any hit), on this thread.
pub fn occluded_all(bvh: &Bvh, rays: &RaySet) -> Vec<bool> {
    (0..rays.len())
        .map(|i| bvh.any_hit(rays.origins[i], rays.dirs[i], rays.t_max[i]))
        .collect()
}

/// The rays `first..first + 16` of `rays` as a packet with their t_max (the tail repeats the
/// last ray).
fn packet_of(rays: &RaySet, first: usize) -> (RayPacket, [f32; LANES]) {
    let mut packet = RayPacket::zero();
    let mut t = [0f32; LANES];
    for (lane, t_max) in t.iter_mut().enumerate() {
        let i = (first + lane).min(rays.len() - 1);
        packet.set(lane, rays.origins[i], rays.dirs[i]);
        *t_max = rays.t_max[i];
    }
    (packet, t)
}

/// Closest hits of every ray of `rays` by packets of 16 (against every primitive of a
/// [`SmallScene`], or through a [`Bvh`]), on this thread.
pub fn trace_all_packets(scene: &impl PacketTracer, rays: &RaySet) -> RayResults {
    let mut out = RayResults {
        prim: Vec::with_capacity(rays.len()),
        t: Vec::with_capacity(rays.len()),
    };
    for first in (0..rays.len()).step_by(LANES) {
        let (packet, t_max) = packet_of(rays, first);
        let hits = scene.closest_hits(&packet, Simd::from_array(t_max));
        let n = LANES.min(rays.len() - first);
        out.prim.extend_from_slice(&hits.prim.to_array()[..n]);
        out.t.extend_from_slice(&hits.t.to_array()[..n]);
    }
    out
}

/// Whether each ray of `rays` is occluded, by packets of 16, on this thread.
pub fn occluded_all_packets(scene: &impl PacketTracer, rays: &RaySet) -> Vec<bool> {
    let mut out = Vec::with_capacity(rays.len());
    for first in (0..rays.len()).step_by(LANES) {
        let (packet, t_max) = packet_of(rays, first);
        let hit = scene
            .occluded_lanes(&packet, Simd::from_array(t_max))
            .to_array();
        out.extend_from_slice(&hit[..LANES.min(rays.len() - first)]);
    }
    out
}

/// Closest-hit and any-hit rays per second of `tracer`'s packets over `rays`.
fn packet_rates(tracer: &impl PacketTracer, rays: &RaySet, repeats: u32) -> (f64, f64) {
    let closest = rays_per_second(rays, repeats, || {
        std::hint::black_box(trace_all_packets(tracer, rays));
    });
    let occluded = rays_per_second(rays, repeats, || {
        std::hint::black_box(occluded_all_packets(tracer, rays));
    });
    (closest, occluded)
}

/// Rays per second of `pass` over `rays`: the best of `repeats` timed passes (the least
/// disturbed by other work on the machine), each of which traces every ray once.
pub fn rays_per_second(rays: &RaySet, repeats: u32, mut pass: impl FnMut()) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        pass();
        best = best.min(start.elapsed().as_secs_f64());
    }
    rays.len() as f64 / best
}

/// A closed tube around a (2, 3) torus knot with a rippled radius: `about` triangles (to within
/// a few percent), centred at `center`, about `size` across. A stand-in for a dense scanned
/// mesh: long thin triangles at every orientation, many of them close to each other.
pub fn knot_mesh(about: usize, center: Vec3, size: f32) -> Vec<[Vec3; 3]> {
    // rings x sides quads, two triangles each; sides ~ sqrt(rings / 8) keeps the cells square-ish.
    let quads = (about / 2).max(32);
    let sides = ((quads as f64 / 16.0).sqrt().round() as usize).max(4);
    let rings = (quads / sides).max(8);
    let scale = size / 6.0;
    let curve = |a: f32| -> Vec3 {
        let r = 2.0 + (3.0 * a).cos();
        Vec3::new(r * (2.0 * a).cos(), r * (2.0 * a).sin(), -(3.0 * a).sin())
    };
    let tau = std::f32::consts::TAU;
    let mut vertices = Vec::with_capacity(rings * sides);
    for i in 0..rings {
        let a = tau * i as f32 / rings as f32;
        let p = curve(a);
        let tangent = (curve(a + 1e-3) - curve(a - 1e-3)).normalize();
        let side = tangent.cross(Vec3::Z).normalize();
        let normal = side.cross(tangent);
        for j in 0..sides {
            let b = tau * j as f32 / sides as f32;
            let radius = 0.45 * (1.0 + 0.2 * (17.0 * a).sin() * (5.0 * b).sin());
            let offset = radius * (b.cos() * side + b.sin() * normal);
            vertices.push(center + scale * (p + offset));
        }
    }
    let at = |i: usize, j: usize| vertices[(i % rings) * sides + j % sides];
    let mut triangles = Vec::with_capacity(2 * rings * sides);
    for i in 0..rings {
        for j in 0..sides {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    triangles
}

/// Writes the scene's primitives, the ray sets and our closest hits as little-endian binary
/// for `scripts/embree_rays.c` (its header documents the layout).
pub fn write_ray_file(
    path: &std::path::Path,
    bvh: &Bvh,
    sets: &[(&RaySet, &RayResults)],
) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    let f32s = |out: &mut std::io::BufWriter<std::fs::File>, v: &[f32]| -> std::io::Result<()> {
        for x in v {
            out.write_all(&x.to_le_bytes())?;
        }
        Ok(())
    };
    out.write_all(b"TPRAYS1\0")?;
    for n in [bvh.triangles.len(), bvh.spheres.len(), sets.len()] {
        out.write_all(&(n as u32).to_le_bytes())?;
    }
    for t in &bvh.triangles {
        let p0 = Vec3::from(t.p0);
        let p1 = p0 + Vec3::from(t.edge1);
        let p2 = p0 + Vec3::from(t.edge2);
        f32s(
            &mut out,
            &[p0.x, p0.y, p0.z, p1.x, p1.y, p1.z, p2.x, p2.y, p2.z],
        )?;
    }
    for s in &bvh.spheres {
        f32s(&mut out, &[s.center[0], s.center[1], s.center[2], s.radius])?;
    }
    for (rays, results) in sets {
        let mut name = [0u8; 32];
        let n = rays.name.len().min(31);
        name[..n].copy_from_slice(&rays.name.as_bytes()[..n]);
        out.write_all(&name)?;
        out.write_all(&(rays.len() as u32).to_le_bytes())?;
        for i in 0..rays.len() {
            let (o, d) = (rays.origins[i], rays.dirs[i]);
            f32s(&mut out, &[o.x, o.y, o.z, d.x, d.y, d.z, rays.t_max[i]])?;
        }
        for i in 0..rays.len() {
            out.write_all(&results.prim[i].to_le_bytes())?;
            f32s(&mut out, &[results.t[i]])?;
        }
    }
    out.flush()
}

/// Fraction of rays on which two passes found the same primitive (both missing counts).
pub fn agreement(a: &RayResults, b: &RayResults) -> f64 {
    let same = a.prim.iter().zip(&b.prim).filter(|(x, y)| x == y).count();
    same as f64 / a.prim.len().max(1) as f64
}

/// Number of rays that hit something.
pub fn hits(r: &RayResults) -> usize {
    r.prim.iter().filter(|&&p| p != NONE).count()
}

/// Vertex triples as the kernel's triangles, all of material `material`.
pub fn to_triangles(vertices: &[[Vec3; 3]], material: u32) -> Vec<kernel::scene::Triangle> {
    vertices
        .iter()
        .map(|&p| crate::scene::triangle(p, material))
        .collect()
}

/// What `twinpath rays` measured on one scene.
#[derive(Clone, Debug)]
pub struct RayReport {
    pub triangles: usize,
    pub spheres: usize,
    pub build_seconds: f64,
    pub nodes: usize,
    pub hierarchy_bytes: usize,
    pub primitive_bytes: usize,
    pub sets: Vec<RaySetReport>,
}

/// Throughput on one ray set.
#[derive(Clone, Debug)]
pub struct RaySetReport {
    pub name: &'static str,
    pub rays: usize,
    pub hits: usize,
    pub closest_per_second: f64,
    pub occluded_per_second: f64,
    /// Closest-hit and any-hit rays per second by packets of 16 as the renderer traces them
    /// (`cpu::packet` for scenes of at most `MAX_PRIMITIVES`, else `cpu::bvh_packet`); `None`
    /// for scenes with instances.
    pub packets: Option<(f64, f64)>,
}

/// Builds the BVH over `scene` (timed), makes the camera rays of a `width` x `height` image,
/// their diffuse bounces (seeded by `settings.seed`) and the rays of one path per pixel
/// rendered with `settings` ([`path_rays`]), and times
/// closest-hit and any-hit traversal of each set on one thread. With `ray_file`, also writes the rays and our hits for `scripts/embree_rays.c`.
pub fn measure(
    scene: &Scene,
    settings: &RenderSettings,
    width: u32,
    height: u32,
    repeats: u32,
    ray_file: Option<&std::path::Path>,
) -> std::io::Result<RayReport> {
    let start = Instant::now();
    let bvh = Bvh::build_scene(scene);
    let build_seconds = start.elapsed().as_secs_f64();
    let renderer = CpuRenderer::with_bvh(scene, settings, bvh);
    let bvh = &renderer.bvh;
    let camera = camera_rays(scene, width, height);
    let bounce = bounce_rays(bvh, &camera, settings.seed);
    let (path_ext, path_shadow) = path_rays(&renderer, scene, settings, width, height);
    let mut sets = Vec::new();
    let mut results = Vec::new();
    for rays in [&camera, &bounce, &path_ext, &path_shadow] {
        let found = trace_all(bvh, rays);
        let closest = rays_per_second(rays, repeats, || {
            std::hint::black_box(trace_all(bvh, rays));
        });
        let occluded = rays_per_second(rays, repeats, || {
            std::hint::black_box(occluded_all(bvh, rays));
        });
        // The same rays sixteen at a time, as the renderer's packets trace them.
        let packets = if let Some(small) = SmallScene::if_small(&bvh.spheres, &bvh.triangles) {
            Some(packet_rates(&small, rays, repeats))
        } else if bvh.instances().is_empty() {
            Some(packet_rates(bvh, rays, repeats))
        } else {
            None
        };
        sets.push(RaySetReport {
            name: rays.name,
            rays: rays.len(),
            hits: hits(&found),
            closest_per_second: closest,
            occluded_per_second: occluded,
            packets,
        });
        results.push(found);
    }
    if let Some(path) = ray_file {
        write_ray_file(
            path,
            bvh,
            &[
                (&camera, &results[0]),
                (&bounce, &results[1]),
                (&path_ext, &results[2]),
                (&path_shadow, &results[3]),
            ],
        )?;
    }
    Ok(RayReport {
        triangles: bvh.triangles.len(),
        spheres: bvh.spheres.len(),
        build_seconds,
        nodes: bvh.node_count(),
        hierarchy_bytes: bvh.hierarchy_bytes(),
        primitive_bytes: bvh.primitive_bytes(),
        sets,
    })
}

/// Adds [`knot_mesh`] with about `n` triangles to `scene`, white (kd 0.73), centred on the
/// camera's look-at point and a third of the camera's distance across; renames the scene
/// `<stem>+knot<n/1000>k`.
pub fn add_knot_mesh(scene: &mut Scene, n: usize) {
    let size = 0.35 * (scene.camera.look_at - scene.camera.eye).length();
    let vertices = knot_mesh(n, scene.camera.look_at, size);
    let material = scene.materials.len() as u32;
    scene
        .materials
        .push(kernel::scene::Material::diffuse([0.73; 3]));
    scene.material_names.push("knot".into());
    let start = scene.triangles.len();
    scene.triangles.extend(to_triangles(&vertices, material));
    scene.triangle_groups.push(crate::scene::TriangleGroup {
        name: "knot".into(),
        range: start..scene.triangles.len(),
    });
    let stem = std::path::Path::new(&scene.name)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| scene.name.clone());
    scene.name = format!("{stem}+knot{}k", n / 1000);
}

/// The rays a render traces: one path per pixel of a `width` x `height` image of `scene`
/// (sample 0, `settings`, the one-path loop of `cpu`, built over `scene` with them), its
/// extension rays (the camera ray
/// first) and its shadow segments (from + t (to - from), t_max 1), each set ordered by depth,
/// then pixel, so that sixteen consecutive rays are those of neighbouring pixels' paths at the
/// same depth. Deeper bounces start anywhere in the scene, unlike [`bounce_rays`]'s from the
/// camera's hits; this is the distribution the renderer's traversal meets.
pub fn path_rays(
    cpu: &CpuRenderer,
    scene: &Scene,
    settings: &RenderSettings,
    width: u32,
    height: u32,
) -> (RaySet, RaySet) {
    /// A tracer that records each ray with its path's depth and pixel, then traces it.
    struct Recorder<'a> {
        inner: BvhTracer<'a>,
        key: (u32, u32),
        extensions: Vec<((u32, u32), Vec3, Vec3)>,
        shadows: Vec<((u32, u32), Vec3, Vec3)>,
    }
    impl Tracer for Recorder<'_> {
        fn closest_hit(&mut self, origin: Vec3, dir: Vec3) -> SurfaceHit {
            self.extensions.push((self.key, origin, dir));
            self.key.0 += 1;
            self.inner.closest_hit(origin, dir)
        }
        fn occluded(&mut self, from: Vec3, to: Vec3) -> bool {
            self.shadows.push((self.key, from, to));
            self.inner.occluded(from, to)
        }
        fn first_hit_on(&mut self, from: Vec3, to: Vec3) -> SurfaceHit {
            self.shadows.push((self.key, from, to));
            self.inner.first_hit_on(from, to)
        }
    }
    // The image size only changes the camera, i.e. the parameters, not the renderer's tables.
    let mut sized = scene.clone();
    sized.camera.width = width;
    sized.camera.height = height;
    let params = sized.params(settings, 0, 1);
    let mut recorder = Recorder {
        inner: cpu.tracer(),
        key: (0, 0),
        extensions: Vec::new(),
        shadows: Vec::new(),
    };
    for py in 0..height {
        for px in 0..width {
            recorder.key = (0, py * width + px);
            cpu.sample_with(Dynamic(cpu.features), &mut recorder, &params, px, py, 0);
        }
    }
    let set = |name, mut rays: Vec<((u32, u32), Vec3, Vec3)>, segments: bool| {
        rays.sort_by_key(|r| r.0);
        RaySet {
            name,
            origins: rays.iter().map(|r| r.1).collect(),
            dirs: rays
                .iter()
                .map(|r| if segments { r.2 - r.1 } else { r.2 })
                .collect(),
            t_max: vec![if segments { 1.0 } else { f32::INFINITY }; rays.len()],
        }
    };
    (
        set("path extensions (render)", recorder.extensions, false),
        set("path shadows (render)", recorder.shadows, true),
    )
}
