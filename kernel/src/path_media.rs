//! A path in participating media (`crate::medium`): the [`PathState`] steps that only scenes
//! with the `MEDIA` feature bit take. A ray crossing a medium that only absorbs takes its
//! transmittance; one crossing a medium that scatters draws a free flight
//! (`crate::free_flight`; in a density grid `crate::delta_tracking`), and a collision is a
//! medium vertex, where next-event estimation and the extension use the phase function
//! (`crate::phase`); an interface is no vertex (extension rays and shadow segments pass it); a
//! shadow segment takes the transmittance of each medium it crosses. Out of line on the CPU:
//! scenes without media never call these.

use crate::delta_tracking::{self, TrackingStream};
use crate::density_grid::{self, DensityGrid};
use crate::features::FeatureSet;
use crate::free_flight;
use crate::hit::SurfaceHit;
use crate::light::{self, LightKinds};
use crate::medium::{self, Medium};
use crate::path::{
    beyond_surface, beyond_surface_toward, light_sample_weight, light_sampling_of, PathState,
};
use crate::phase;
use crate::scene::{Material, RenderParams};
use crate::scene_view::SceneView;
use crate::vertex_samples::{VertexQuery, VertexSamples, FLIGHT_DIMENSION, GRID_DIMENSION};
use spirv_std::glam::Vec3;

/// [`PathState::flights`]: the mask of the flight count (bits 2..30, shifted down) and the
/// medium vertex's bit.
const FLIGHT_COUNT: u32 = (1 << 29) - 1;
const SCATTERED: u32 = 1 << 31;

/// The largest probability with which roulette keeps a path at a medium vertex. A medium that
/// does not absorb (albedo 1 in some channel) keeps a path's throughput, and throughput
/// roulette (survival min(throughput, 1)) would then never end it; in a medium without bound
/// (a fog filling the scene, around an open room) a path that wanders off is a random walk in
/// three dimensions, which does not come back, so it never ended (a render hung). Ending at
/// least 1% of paths at each medium vertex bounds every walk (about 100 vertices more at
/// most, on average) and stays unbiased: the survivors' throughput is divided by the same
/// probability (Mitsuba 3 caps every vertex at 0.95).
pub const MAX_MEDIUM_SURVIVAL: f32 = 0.99;

impl PathState {
    /// Whether the vertex [`PathState::advance`] reached is a medium vertex, at `ray_origin`
    /// (see [`PathState::flights`]).
    #[inline]
    pub fn scattered(&self) -> bool {
        self.flights & SCATTERED != 0
    }

    /// The ray just traced crosses the medium it travels in up to `hit` (or out of the scene).
    /// In a medium that only absorbs, the throughput takes the segment's transmittance
    /// (`medium`; in a grid from its exact optical depth, `density_grid::optical_depth`); in
    /// one that scatters, a free flight is sampled (the path's hero channel from the number at
    /// `FLIGHT_DIMENSION`, drawn at its first flight; the k-th flight's distance from the
    /// number at `FLIGHT_DIMENSION + 1 + k`, `crate::free_flight`, or in a grid by delta
    /// tracking from the stream seeded at `GRID_DIMENSION + k`, `crate::delta_tracking`) and
    /// its weight taken. Returns whether the ray scattered before `hit`: then `ray_origin` is
    /// the collision, a medium vertex (`scattered`). Out of line on the CPU: only scenes with
    /// media call it.
    #[cfg_attr(not(target_arch = "spirv"), inline(never))]
    pub(crate) fn fly(&mut self, scene: &SceneView, hit: &SurfaceHit) -> bool {
        let m = &scene.media[self.medium as usize];
        let sigma_t = m.extinction();
        if !(sigma_t.max_element() > 0.0) {
            return false;
        }
        let distance = self.distance_to(hit);
        if m.has_grid() {
            return self.fly_grid(scene, m, distance);
        }
        if !m.scatters() {
            self.throughput *= medium::transmittance(sigma_t, distance);
            return false;
        }
        let (count, hero) = self.hero_channel();
        self.rng.seek(FLIGHT_DIMENSION + 1 + count);
        let u = self.rng.next_f32();
        let sigma_s = Vec3::from(m.sigma_s);
        let flight = free_flight::sample(sigma_t, sigma_s, distance, hero, u, self.ratios);
        self.take_flight(&flight, count, hero)
    }

    /// [`PathState::fly`] in grid medium `m` whose surface lies at `distance`: the
    /// transmittance from the exact optical depth
    /// (`density_grid::optical_depth`) where it only absorbs, else delta tracking
    /// (`crate::delta_tracking`) from the stream seeded by the number at `GRID_DIMENSION + k`
    /// for the path's k-th flight. Out of line on the CPU: a homogeneous medium's flight does
    /// not carry its code.
    #[cfg_attr(not(target_arch = "spirv"), inline(never))]
    fn fly_grid(&mut self, scene: &SceneView, m: &Medium, distance: f32) -> bool {
        let sigma_t = m.extinction();
        if !m.scatters() {
            let (origin, dir) = (self.ray_origin, self.ray_dir);
            self.throughput *= grid_transmittance(scene, m, origin, dir, distance);
            return false;
        }
        let (count, hero) = self.hero_channel();
        self.rng.seek(GRID_DIMENSION + count);
        let mut stream = TrackingStream::new(self.rng.next_u32(), count);
        let grid = DensityGrid::at(scene.grids, m.grid);
        let ray = (self.ray_origin, self.ray_dir, distance);
        let sigmas = (sigma_t, Vec3::from(m.sigma_s));
        let flight = delta_tracking::flight(sigmas, &grid, ray, hero, &mut stream, self.ratios);
        self.take_flight(&flight, count, hero)
    }

    /// The distance along the ray to `hit`, `f32::MAX` where it left the scene.
    #[inline]
    fn distance_to(&self, hit: &SurfaceHit) -> f32 {
        if hit.is_hit() {
            (hit.position - self.ray_origin).length()
        } else {
            f32::MAX
        }
    }

    /// The number of flights the path has sampled and its hero channel, drawn from the number
    /// at `FLIGHT_DIMENSION` at its first flight.
    #[inline]
    fn hero_channel(&mut self) -> (u32, u32) {
        let count = (self.flights >> 2) & FLIGHT_COUNT;
        if count == 0 {
            self.rng.seek(FLIGHT_DIMENSION);
            self.flights = free_flight::hero_channel(self.rng.next_f32());
        }
        (count, self.flights & 3)
    }

    /// Takes the path's `count`-th flight, drawn by channel `hero`: its weight and ratios, and
    /// its collision as the next vertex where it scattered (returned).
    #[inline]
    fn take_flight(&mut self, flight: &free_flight::Flight, count: u32, hero: u32) -> bool {
        self.throughput *= flight.weight;
        self.ratios = flight.ratios;
        self.flights = (((count + 1) & FLIGHT_COUNT) << 2) | hero;
        if flight.scattered {
            self.ray_origin += self.ray_dir * flight.t;
            self.flights |= SCATTERED;
        }
        flight.scattered
    }

    /// The medium a ray leaving the surface of `material` at `hit` along `dir` travels in
    /// (`medium::beyond`; outside every shape, the scene's).
    #[inline]
    pub(crate) fn medium_beyond(
        &self,
        scene: &SceneView,
        material: &Material,
        hit: &SurfaceHit,
        dir: Vec3,
    ) -> u32 {
        let outside = scene.params.environment.medium;
        medium::beyond(material, hit.normal, dir, self.medium, outside)
    }

    /// What a medium vertex (`scattered`) will draw: a light sample unless BSDF sampling
    /// alone is asked for (the phase function is never a delta), the extension and roulette
    /// as at a surface; no lobe choice. Its normals are the direction of travel (unread: the
    /// phase function has no hemisphere).
    #[inline]
    pub(crate) fn medium_query<F: FeatureSet>(
        &self,
        features: F,
        params: &RenderParams,
    ) -> VertexQuery {
        let light_count = self.light_count(features, params, true);
        let survival = self.survival(features, params).min(MAX_MEDIUM_SURVIVAL);
        VertexQuery {
            depth: self.depth,
            x: self.ray_origin,
            n: self.ray_dir,
            ng: self.ray_dir,
            smooth: false,
            light_count,
            mode: light_sampling_of(features, params),
            light_kinds: LightKinds::of(features, params),
            extend: self.depth < params.integrator.max_depth,
            roulette: self.depth >= params.integrator.rr_start_depth,
            survival,
            lambertian: false,
            chooses_lobe: false,
        }
    }

    /// [`PathState::vertex`] at a medium vertex (the path scattered at `query.x` in its medium,
    /// its throughput already weighed by sigma_s over the collision's density,
    /// `crate::free_flight`): next-event estimation with the phase function in the place of
    /// f cos (a medium point has no surface, no cosine), its shadow segment starting in the
    /// medium, weighed by MIS against phase sampling; then roulette, and the extension drawn
    /// from the phase function (weight exactly 1, its density the MIS density of a light it
    /// finds). Rays leave from the point itself: there is no surface to offset from.
    #[cfg_attr(not(target_arch = "spirv"), inline(never))]
    pub(crate) fn medium_vertex<F: FeatureSet>(
        &mut self,
        features: F,
        scene: &SceneView,
        query: &VertexQuery,
        samples: &VertexSamples,
    ) {
        self.flights &= !SCATTERED;
        let (params, lights) = (scene.params, scene.lights);
        let x = query.x;
        let wo = -self.ray_dir;
        let g = scene.media[self.medium as usize].g;
        if query.samples_light() {
            let ls = samples.light_sample(query, scene);
            let wi = (ls.point.position - x).normalize();
            let cos_y = -ls.point.normal.dot(wi);
            let pdf_w = ls.pdf_solid_angle;
            let p = phase::eval(g, wo, wi);
            if cos_y > 0.0 && pdf_w > 0.0 && p > 0.0 {
                let emitted = light::radiance(features, scene, query.light_kinds, &ls);
                let weight = light_sample_weight(
                    features,
                    params,
                    query.light_kinds,
                    &lights[ls.light as usize],
                    pdf_w,
                    p,
                );
                let radiance = self.throughput * emitted * (p * weight / pdf_w);
                self.await_shadow(query.light_kinds, lights, x, &ls, radiance);
                self.shadow_medium = self.medium;
            }
        }
        if !query.extend || !self.survives_roulette(query, samples) {
            return;
        }
        let (u1, u2) = samples.u_brdf;
        let wi = phase::sample(g, wo, u1, u2);
        let pdf = phase::eval(g, wo, wi);
        if !(self.throughput.max_element() > 0.0) {
            return;
        }
        self.await_extension(x, wi, x, pdf);
    }

    /// In a scene with media, the shadow segment's answer, taken before
    /// [`PathState::advance`]: `blocker`, the closest surface on the segment from
    /// `shadow_from` ([`Tracer::first_hit_on`]). Clear (a miss): the light sample adds its
    /// radiance times the transmittance of the segment. An interface: the segment keeps the
    /// transmittance of the part up to it and goes on from the interface's far side, in the
    /// medium beyond, to the same end; returns true: the segment waits, and the caller leaves
    /// this round's extension answer untaken (the same ray is traced again with the segment,
    /// so the radiance sums its terms in the one order). Any other surface: the sample adds
    /// nothing. Returns false once the segment is settled (`shadow` is then false). Out of line
    /// on the CPU: only scenes with media call it.
    #[cfg_attr(not(target_arch = "spirv"), inline(never))]
    pub fn shadow_passes(&mut self, scene: &SceneView, blocker: &SurfaceHit) -> bool {
        if !blocker.is_hit() {
            let t = self.shadow_transmittance(scene, self.shadow_to);
            self.radiance += self.shadow_radiance * t;
            self.shadow = false;
            return false;
        }
        let material = &scene.materials[blocker.material as usize];
        if !medium::is_interface(material) {
            self.shadow = false;
            return false;
        }
        let dir = self.shadow_to - self.shadow_from;
        let t = self.shadow_transmittance(scene, blocker.position);
        self.shadow_radiance *= t;
        let outside = scene.params.environment.medium;
        self.shadow_medium =
            medium::beyond(material, blocker.normal, dir, self.shadow_medium, outside);
        self.shadow_from = beyond_surface_toward(blocker, dir, self.shadow_to);
        true
    }

    /// The transmittance of the shadow segment's piece from `shadow_from` to `to` in
    /// `shadow_medium`: exact in a homogeneous medium (`medium::along`) and in a grid
    /// (exp(-sigma_t tau), `density_grid::optical_depth`).
    #[inline]
    fn shadow_transmittance(&self, scene: &SceneView, to: Vec3) -> Vec3 {
        let (from, medium) = (self.shadow_from, self.shadow_medium);
        let m = &scene.media[medium as usize];
        if !m.has_grid() {
            return medium::along(scene.media, medium, from, to);
        }
        let d = to - from;
        let length = d.length();
        if !(length > 0.0) {
            return Vec3::ONE;
        }
        grid_transmittance(scene, m, from, d / length, length)
    }

    /// The extension ray met an interface at `hit` (its transmittance up to there already
    /// applied): it goes on from the far side in the medium beyond, as the same ray (the
    /// vertex it left, its density and the depth unchanged). Out of line on the CPU, as
    /// [`PathState::shadow_passes`].
    #[cfg_attr(not(target_arch = "spirv"), inline(never))]
    pub(crate) fn pass_interface(&mut self, scene: &SceneView, hit: &SurfaceHit) {
        let material = &scene.materials[hit.material as usize];
        self.medium = self.medium_beyond(scene, material, hit, self.ray_dir);
        self.ray_origin = beyond_surface(hit, self.ray_dir);
        self.extend = true;
    }
}

/// The transmittance of ray `origin + t dir` (`dir` of unit length) for t in [0, `length`]
/// through grid medium `m`: exp(-sigma_t tau), tau its exact optical depth
/// (`density_grid::optical_depth`). Out of line on the CPU, as [`PathState::fly_grid`].
#[cfg_attr(not(target_arch = "spirv"), inline(never))]
fn grid_transmittance(scene: &SceneView, m: &Medium, origin: Vec3, dir: Vec3, length: f32) -> Vec3 {
    let grid = DensityGrid::at(scene.grids, m.grid);
    let tau = density_grid::optical_depth(&grid, origin, dir, length);
    medium::transmittance(m.extinction(), tau)
}
