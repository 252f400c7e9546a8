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
use super::packet_numbers::camera_numbers;
use super::packet_vertices::fill_vertex_samples;
use super::tile::TileSums;
use crate::backend::RayCounts;
use crate::film::Film;
use crate::film::PixelSums;
use glam::Vec3;
use kernel::features::FeatureSet;
use kernel::path::{sample_rng, start_path_at, PathState};
use kernel::scene::{Material, NONE};
use kernel::{SceneView, SurfaceHit};
use std::ops::Range;
use std::simd::Simd;

/// The rays the paths in `slots` wait for, as two packets with their t_max: the extension rays
/// (t_max infinite) and the shadow segments (from + t (to - from), t_max 1, as the BVH tracer
/// tests them). Lanes without such a ray get t_max 0, which nothing is hit within.
fn gather(slots: &[Option<(usize, Path)>; LANES]) -> [(RayPacket, [f32; LANES]); 2] {
    let [mut extension, mut shadow] = [RayPacket::zero(); 2];
    let mut t_max = [[0f32; LANES]; 2];
    for (lane, slot) in slots.iter().enumerate() {
        let Some((_, path)) = slot else { continue };
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
    slots: &mut [Option<(usize, Path)>; LANES],
    shadow: &RayPacket,
    t_max: [f32; LANES],
) -> [bool; LANES] {
    let h = LaneHits::of(&tracer.closest_hits(shadow, Simd::from_array(t_max)));
    let mut waiting = [false; LANES];
    for (lane, slot) in slots.iter_mut().enumerate() {
        let Some((_, path)) = slot else { continue };
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

/// A path of the packets.
type Path = PathState;

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
    let mut radiance = vec![Vec3::ZERO; n];
    let mut slots: [Option<(usize, Path)>; LANES] = [None; LANES];
    let mut next = 0;
    // The streams of samples next..next + 16, and their camera numbers computed together.
    let mut batch = [None; LANES];
    let mut batch_camera = [(0.0, 0.0); LANES];
    let mut hits = [SurfaceHit::miss(); LANES];
    // The materials of this round's vertices as `PathState::arrival` gives them.
    let mut materials = [Material::diffuse([0.0; 3]); LANES];
    let mut rays = RayCounts::default();
    loop {
        for slot in slots.iter_mut().filter(|s| s.is_none()) {
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
            *slot = Some((next, start_path_at(features, params, px, py, rng, uv)));
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
            let Some((_, path)) = slot else { continue };
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
        // draw, and the sixteen vertices' samples are filled together.
        let mut queries = [None; LANES];
        for (lane, slot) in slots.iter_mut().enumerate() {
            let Some((_, path)) = slot else { continue };
            let hit = &hits[lane];
            if waiting[lane] {
                continue;
            }
            if path.advance(features, scene, hit, occluded[lane]) {
                let arrival = path.arrival(features, scene, hit);
                materials[lane] = arrival.material;
                queries[lane] = Some((path.rng, arrival.query));
            }
        }
        let vertex_samples = fill_vertex_samples(&queries, scene.lights);
        for (lane, slot) in slots.iter_mut().enumerate() {
            let Some((k, path)) = slot else { continue };
            if let Some((_, query)) = &queries[lane] {
                let hit = &hits[lane];
                path.vertex(
                    features,
                    scene,
                    hit,
                    &materials[lane],
                    query,
                    &vertex_samples[lane],
                );
            }
            if path.finished() {
                radiance[*k] = path.radiance;
                *slot = None;
            }
        }
    }
    let mut samples = radiance.chunks(count.max(1) as usize);
    let sums = pixels
        .iter()
        .map(|&(_, _, sampled)| {
            let mut acc = PixelSums::default();
            if sampled {
                let values = samples.next().unwrap_or(&[]);
                for (s, &l) in (first..).zip(values) {
                    acc.add_sample(params, s, l);
                }
            }
            acc
        })
        .collect();
    (sums, rays)
}
