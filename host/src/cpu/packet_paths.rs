//! Sixteen paths at a time: the kernel's path state machine (`kernel::path::PathState`) with
//! each round's rays traced as packets by a [`PacketTracer`] (SIMD over rays: against every
//! primitive of a small scene, `packet.rs`, or through the BVH, `bvh_packet.rs`). Every path
//! runs the same kernel code as `render_sample`, and the packet tracers return the one-ray
//! traversal's primitive, instance, t and barycentrics bit for bit (ties at equal t go to the
//! least (instance, id) in both), so a pixel's samples are the ones the one-path loop computes.
//! Each round is the kernel's step protocol, as `PathState::run` follows it: `advance` with
//! the round's answers, the `arrival` at each vertex reached, the vertices' samples (here filled
//! for sixteen at once), `vertex`.

use super::bvh::{Bvh, PrimHit};
use super::packet::{PacketHits, PacketTracer, RayPacket, LANES};
use super::packet_forks::{Forks, Job, Part};
use super::packet_numbers::camera_numbers;
use super::packet_vertices::fill_vertex_samples;
use super::tile::TileSums;
use crate::backend::RayCounts;
use crate::film::Film;
use crate::film::PixelSums;
use glam::Vec3;
use kernel::features::FeatureSet;
use kernel::path::{sample_rng, start_path_at};
use kernel::scene::{split_mode, Material, RenderParams, NONE};
use kernel::split::{
    combine, continuation_rounds, continuations_at, unsplit_value, FirstVertex, MAX_CONTINUATIONS,
};
use kernel::{SceneView, SurfaceHit};
use std::ops::Range;
use std::simd::Simd;

/// The rays the paths in `slots` wait for, as two packets with their t_max: the extension rays
/// (t_max infinite) and the shadow segments (from + t (to - from), t_max 1, as the BVH tracer
/// tests them). Lanes without such a ray get t_max 0, which nothing is hit within.
fn gather(slots: &[Option<Job>; LANES]) -> [(RayPacket, [f32; LANES]); 2] {
    let [mut extension, mut shadow] = [RayPacket::zero(); 2];
    let mut t_max = [[0f32; LANES]; 2];
    for (lane, slot) in slots.iter().enumerate() {
        let Some(Job { path, .. }) = slot else {
            continue;
        };
        if path.extend {
            extension.set(lane, path.ray_origin, path.ray_dir);
            t_max[0][lane] = f32::INFINITY;
        }
        if path.shadow {
            let from = path.shadow_from;
            shadow.set(lane, from, path.shadow_to - from);
            t_max[1][lane] = 1.0;
        }
    }
    [(extension, t_max[0]), (shadow, t_max[1])]
}

/// In a scene with media: each shadow segment of `shadow` (t_max `t_max`) traced to its
/// closest surface and settled by its path (`PathState::shadow_passes`); returns the lanes
/// whose segment passed an interface and waits again.
#[inline(never)]
fn settle_shadows<T: PacketTracer>(
    tracer: &T,
    scene: &SceneView,
    bvh: &Bvh,
    slots: &mut [Option<Job>; LANES],
    shadow: &RayPacket,
    t_max: [f32; LANES],
) -> [bool; LANES] {
    let h = LaneHits::of(&tracer.closest_hits(shadow, Simd::from_array(t_max)));
    let mut waiting = [false; LANES];
    for (lane, slot) in slots.iter_mut().enumerate() {
        let Some(Job { path, .. }) = slot else {
            continue;
        };
        if !path.shadow {
            continue;
        }
        let mut blocker = SurfaceHit::miss();
        if h.prim[lane] != NONE {
            let (o, d) = (path.shadow_from, path.shadow_to - path.shadow_from);
            blocker = h.surface(bvh, lane, o, d);
        }
        waiting[lane] = path.shadow_passes(scene, &blocker);
    }
    waiting
}

/// A packet tracer's hits as arrays, lane by lane.
struct LaneHits {
    prim: [u32; LANES],
    t: [f32; LANES],
    u: [f32; LANES],
    v: [f32; LANES],
    instance: [u32; LANES],
}

impl LaneHits {
    fn of(h: &PacketHits) -> Self {
        LaneHits {
            prim: h.prim.to_array(),
            t: h.t.to_array(),
            u: h.u.to_array(),
            v: h.v.to_array(),
            instance: h.instance.to_array(),
        }
    }

    /// Sixteen misses.
    fn miss() -> Self {
        LaneHits {
            prim: [NONE; LANES],
            t: [0.0; LANES],
            u: [0.0; LANES],
            v: [0.0; LANES],
            instance: [NONE; LANES],
        }
    }

    /// The hit record of lane `lane`, which hit something, for its ray `origin + t dir`, made
    /// by `bvh` as the one-path tracer makes it: from the known barycentrics on the scene's own
    /// primitives, by [`Bvh::surface`] on an instance's triangle.
    #[inline(always)]
    fn surface(&self, bvh: &Bvh, lane: usize, origin: Vec3, dir: Vec3) -> SurfaceHit {
        let (prim, t) = (self.prim[lane], self.t[lane]);
        debug_assert!(prim != NONE);
        if self.instance[lane] == NONE {
            bvh.surface_with_uv(prim, origin, dir, t, (self.u[lane], self.v[lane]))
        } else {
            let instance = self.instance[lane];
            bvh.surface(PrimHit { prim, instance, t }, origin, dir)
        }
    }
}

/// The radiances of a tile's sample slots as their jobs finish them: a whole path's, the
/// continuations' of the samples that split, and the first continuation's rounds (the pilot's,
/// `kernel::split::pilot_value`).
struct SlotValues {
    radiance: Vec<Vec3>,
    forked: Vec<bool>,
    continued: Vec<[Vec3; MAX_CONTINUATIONS as usize]>,
    first_rounds: Vec<f32>,
}

impl SlotValues {
    /// For `n` sample slots; room for continuations only where a render splits.
    fn new(n: usize, splits: bool) -> Self {
        let m = if splits { n } else { 0 };
        Self {
            radiance: vec![Vec3::ZERO; n],
            forked: vec![false; m],
            continued: vec![[Vec3::ZERO; MAX_CONTINUATIONS as usize]; m],
            first_rounds: vec![0.0; m],
        }
    }

    /// Keeps what the finished `job` found.
    fn finish(&mut self, job: &Job) {
        match job.part {
            Part::Whole => self.radiance[job.k] = job.path.radiance,
            Part::Continuation(j) => {
                self.continued[job.k][j as usize] = job.path.radiance;
                if j == 0 {
                    self.first_rounds[job.k] = continuation_rounds(job.path.depth);
                }
            }
        }
    }

    /// Sample slot `k`'s value, split in `n` continuations where it forked.
    fn value(&self, params: &RenderParams, k: usize, n: u32) -> Vec3 {
        if self.forked.get(k).copied().unwrap_or(false) {
            let continued = &self.continued[k][..n as usize];
            combine(params, continued, self.first_rounds[k])
        } else {
            unsplit_value(params, self.radiance[k])
        }
    }
}

/// Samples `samples` of each of `pixels` (skipping those `film` says have converged, under
/// adaptive sampling), sixteen paths at a time, their rays traced by `tracer` and their hits
/// made by `bvh` (which holds the scene's primitives); returns each pixel's sums, added in
/// sample order as the one-path loop adds them, and the rays traced.
pub(super) fn tile_by_packets<F: FeatureSet, T: PacketTracer>(
    features: F,
    tracer: &T,
    scene: &SceneView,
    bvh: &Bvh,
    pixels: &mut dyn Iterator<Item = (u32, u32)>,
    samples: Range<u32>,
    film: &Film,
) -> TileSums {
    if scene.params.split.mode == split_mode::OFF {
        packets::<false, F, T>(features, tracer, scene, bvh, pixels, samples, film)
    } else {
        packets::<true, F, T>(features, tracer, scene, bvh, pixels, samples, film)
    }
}

/// [`tile_by_packets`], compiled apart for renders whose paths split (`SPLITS`) and those
/// whose paths do not, which so carry none of the forks' work.
fn packets<const SPLITS: bool, F: FeatureSet, T: PacketTracer>(
    features: F,
    tracer: &T,
    scene: &SceneView,
    bvh: &Bvh,
    pixels: &mut dyn Iterator<Item = (u32, u32)>,
    samples: Range<u32>,
    film: &Film,
) -> TileSums {
    let (params, first) = (scene.params, samples.start);
    let count = samples.end - samples.start;
    let adaptive = kernel::adaptive::is_adaptive(params);
    let pixels: Vec<(u32, u32, bool)> = pixels
        .map(|(px, py)| (px, py, !(adaptive && film.converged(params, px, py))))
        .collect();
    let work: Vec<(u32, u32)> = pixels
        .iter()
        .filter(|p| p.2)
        .map(|&(px, py, _)| (px, py))
        .collect();
    let n = work.len() * count as usize;
    let pixel_of = |k: usize| work[k / count as usize];
    // Continuations at each pixel's first vertices (1 where nothing splits).
    let continuations: Vec<u32> = work
        .iter()
        .map(|&(px, py)| {
            if SPLITS {
                continuations_at(scene, px, py)
            } else {
                1
            }
        })
        .collect();
    let continuations_of = |k: usize| continuations[k / count as usize];
    let mut values = SlotValues::new(n, SPLITS);
    let mut slots: [Option<Job>; LANES] = [None; LANES];
    // Continuations waiting to leave their first vertex, and those waiting for a lane.
    let mut forks = Forks::default();
    let mut pending: Vec<Job> = Vec::new();
    let mut leaving = Vec::with_capacity(LANES);
    let mut next = 0;
    // The streams of samples next..next + 16, and their camera numbers computed together.
    let mut batch = [None; LANES];
    let mut batch_camera = [(0.0, 0.0); LANES];
    let mut hits = [SurfaceHit::miss(); LANES];
    // The materials of this round's vertices as `PathState::arrival` gives them.
    let mut materials = [Material::diffuse([0.0; 3]); LANES];
    let mut rays = RayCounts::default();
    loop {
        // Continuations leave in fills of their own when they pile up, or when nothing else is
        // left to do.
        while SPLITS && forks.queued() >= LANES
            || (forks.queued() > 0
                && pending.is_empty()
                && next == n
                && slots.iter().all(Option::is_none))
        {
            forks.leave_sixteen(features, scene, &mut pending);
        }
        for slot in slots.iter_mut().filter(|s| s.is_none()) {
            if SPLITS {
                if let Some(job) = pending.pop() {
                    *slot = Some(job);
                    continue;
                }
            }
            if next == n {
                break;
            }
            if next % LANES == 0 {
                batch = std::array::from_fn(|i| {
                    let k = next + i;
                    (k < n).then(|| {
                        let (px, py) = pixel_of(k);
                        sample_rng(params, px, py, first + (k % count as usize) as u32)
                    })
                });
                batch_camera = camera_numbers(&batch);
            }
            let rng = batch[next % LANES]
                .take()
                .expect("the batch holds sample next");
            let (px, py) = pixel_of(next);
            let uv = batch_camera[next % LANES];
            *slot = Some(Job {
                k: next,
                part: Part::Whole,
                path: start_path_at(features, params, px, py, rng, uv),
            });
            next += 1;
        }
        if slots.iter().all(Option::is_none) {
            break;
        }
        let [(extension, ext_t_max), (shadow, shadow_t_max)] = gather(&slots);
        let lanes = |t_max: &[f32; LANES]| t_max.iter().filter(|&&t| t > 0.0).count() as u64;
        let (extensions, shadows) = (lanes(&ext_t_max), lanes(&shadow_t_max));
        rays.closest += extensions;
        rays.shadow += shadows;
        let found = if extensions > 0 {
            LaneHits::of(&tracer.closest_hits(&extension, Simd::from_array(ext_t_max)))
        } else {
            LaneHits::miss()
        };
        // A scene with media asks for the surface blocking each shadow segment (an interface
        // lets it pass, `kernel::medium`); any other only whether one does.
        let mut occluded = [false; LANES];
        if shadows > 0 && !features.media() {
            occluded = tracer
                .occluded_lanes(&shadow, Simd::from_array(shadow_t_max))
                .to_array();
        }
        // Filled in place (an array built by `from_fn` was copied each round).
        hits.fill(SurfaceHit::miss());
        for (lane, slot) in slots.iter().enumerate() {
            let Some(Job { path, .. }) = slot else {
                continue;
            };
            if path.extend && found.prim[lane] != NONE {
                hits[lane] = found.surface(bvh, lane, path.ray_origin, path.ray_dir);
            }
        }
        // (Shadow segments that pass an interface wait again, with their extension untaken.)
        let mut waiting = [false; LANES];
        if shadows > 0 && features.media() {
            waiting = settle_shadows(tracer, scene, bvh, &mut slots, &shadow, shadow_t_max);
        }
        // Each path takes its round's answers; those that reach a vertex state what it will
        // draw, and the sixteen vertices' samples are filled together. A whole path that
        // splits forks at its first vertex: the lane goes on with continuation 0 (its vertex
        // among the sixteen), and the others queue to leave the vertex (`packet_forks`).
        let mut queries = [None; LANES];
        let mut reached = [false; LANES];
        let mut forked_here = [0; LANES];
        for (lane, slot) in slots.iter_mut().enumerate() {
            let Some(job) = slot else { continue };
            let hit = &hits[lane];
            if waiting[lane] {
                continue;
            }
            if job.path.advance(features, scene, hit, occluded[lane]) {
                reached[lane] = true;
                let n = if SPLITS { continuations_of(job.k) } else { 1 };
                if n > 1 && job.part == Part::Whole {
                    let vertex = FirstVertex::reached(job.path, features, scene, hit);
                    forks.fork(job.k, n, vertex);
                    let (path, query) = vertex.at_vertex(scene, n, 0);
                    (job.path, job.part) = (path, Part::Continuation(0));
                    materials[lane] = vertex.material;
                    queries[lane] = Some((path.rng, query));
                    forked_here[lane] = n;
                    values.forked[job.k] = true;
                    continue;
                }
                let arrival = job.path.arrival(features, scene, hit);
                materials[lane] = arrival.material;
                queries[lane] = Some((job.path.rng, arrival.query));
            }
        }
        // Queued continuations take the query slots no lane uses.
        if SPLITS && forks.queued() > 0 {
            forks.take_slots(scene, &mut queries, &mut leaving);
        }
        let vertex_samples = fill_vertex_samples(&queries, scene.lights);
        if SPLITS && !leaving.is_empty() {
            forks.leave(features, scene, &leaving, &vertex_samples, &mut pending);
            leaving.clear();
        }
        for (lane, slot) in slots.iter_mut().enumerate() {
            let Some(job) = slot else { continue };
            if let (true, Some((_, query))) = (!SPLITS || reached[lane], &queries[lane]) {
                let hit = &hits[lane];
                job.path.vertex(
                    features,
                    scene,
                    hit,
                    &materials[lane],
                    query,
                    &vertex_samples[lane],
                );
                if SPLITS && forked_here[lane] > 1 {
                    FirstVertex::left(scene, forked_here[lane], 0, &mut job.path);
                }
            }
            if job.path.finished() {
                values.finish(job);
                *slot = None;
            }
        }
    }
    let mut k = 0;
    let sums = pixels
        .iter()
        .map(|&(_, _, sampled)| {
            let mut acc = PixelSums::default();
            if sampled && count > 0 {
                let n_k = if SPLITS { continuations_of(k) } else { 1 };
                for s in first..first + count {
                    let value = if SPLITS {
                        values.value(params, k, n_k)
                    } else {
                        values.radiance[k]
                    };
                    acc.add_sample(params, s, value);
                    k += 1;
                }
            }
            acc
        })
        .collect();
    (sums, rays)
}
