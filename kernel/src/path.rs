//! TracePath: the path-tracing estimator with next-event estimation and Russian roulette,
//! generic over how rays meet the scene ([`Tracer`]).

use crate::adaptive::sample_stream;
use crate::bsdf::lambert::{eval_scattering, pdf_brdf, sampled_brdf_weight};
use crate::bsdf::{self, DELTA_PDF};
use crate::camera::{camera_origin, camera_ray_direction, lens_radius, thin_lens_ray};
use crate::environment;
use crate::features::FeatureSet;
use crate::geometry::{
    continuation_origin, lift_ray_origin, origin_by_angle, shadow_ray_end, shadow_segment,
};
use crate::hit::SurfaceHit;
use crate::light::{self, eval_radiance, LightKinds, LightSample};
use crate::medium;
use crate::rng::SampleRng;
use crate::sampling::power_heuristic;
use crate::scene::{light_sampling, mis, Light, Material, RenderParams, NONE};
use crate::scene_view::SceneView;
use crate::surface::{self, emission_at, shade};
use crate::vertex_samples::{VertexQuery, VertexSamples, CAMERA_DIMENSION, LENS_DIMENSION};
use spirv_std::glam::Vec3;

/// How the kernel meets the scene: the GPU implements it with `trace_ray` on an acceleration
/// structure, the CPU with a BVH. Both must return the same surfaces for the same rays.
pub trait Tracer {
    /// The closest surface along `origin + t * dir` for t in (0, inf).
    fn closest_hit(&mut self, origin: Vec3, dir: Vec3) -> SurfaceHit;
    /// Whether any surface lies on the open segment from `from` to `to`.
    fn occluded(&mut self, from: Vec3, to: Vec3) -> bool;
    /// The closest surface on the open segment from `from` to `to`: the ray
    /// `from + t (to - from)`, t in (0, 1), as [`Tracer::occluded`] tests it. A scene with media
    /// traces its shadow segments so, to pass through interfaces (`crate::medium`).
    fn first_hit_on(&mut self, from: Vec3, to: Vec3) -> SurfaceHit;
}

/// Seed: `TracePath(ray)`. One unbiased estimate of the radiance arriving at `origin` from
/// direction `-dir` (`dir` unit length).
///
/// # Derivation
/// The rendering equation at a surface point x with outgoing direction w_o is
/// `L(x, w_o) = Le(x, w_o) + \int_{H^2} f(x, w_i, w_o) L(y(x, w_i), -w_i) cos(theta_i) dw_i`,
/// with f = Kd/pi here. Split the incoming radiance into emitted light from the lights, light
/// from the background, and light reflected by other surfaces; this estimator treats them so:
///
/// 1. **Camera ray.** If it misses, the estimate is the background radiance; if it hits a light,
///    the light's emitted radiance toward the camera (a light reflects nothing, so this is
///    exact and the path ends).
/// 2. **Emitted light at vertex x, two strategies combined by multiple importance sampling.**
///    (a) *Light sampling* (next-event estimation): choose a point y on a light. The seed's way
///    picks it with area density p_A(y) = pmf(light) / (4 pi r^2); the integral over directions
///    becomes one over the light's area with dw_i = |cos theta_y| / |x - y|^2 dA(y), so in solid
///    angle the density is `p_w = p_A |x - y|^2 / |cos theta_y|`. The default instead draws the
///    direction uniformly in the cone the sphere subtends, p_w = pmf / (2 pi (1 - cos theta_max))
///    (no samples wasted on the far side, no 1/d^2 spikes close to the light). The contribution is
///    `w_L * f cos(theta_x) * Le * V(x, y) / p_w`. The seed's `PdfLight / GeometryFactor` also
///    divides by cos(theta_x); since `EvalScattering` already carries cos(theta_x), that would
///    count it twice, so only the light's cosine converts the measure here. Points on the far
///    side of the light (cos theta_y <= 0) and below the surface (cos theta_x <= 0) contribute
///    nothing and are skipped.
///    (b) *BRDF sampling*: the extension direction (below) that hits a light y adds
///    `w_B * f cos(theta_x) * Le / p_brdf`.
///    Any weights with w_L + w_B = 1 wherever both densities are positive keep the sum
///    unbiased (Veach's thesis, ch. 9): the seed's constant 1/2 each, or the power heuristic.
///    *The background is not light-sampled*, so a path that escapes gets weight 1.
/// 3. **Reflected light: extension.** Choose w_i with the cosine-weighted density
///    p_brdf = cos(theta_x)/pi and multiply the path throughput by `f cos(theta_x) / p_brdf`,
///    which is exactly Kd. No direction ends the path. (The seed ends it where p_brdf < 1e-6,
///    which looks harmless in the continuum, 1e-11 of the cosine-weighted measure; but the
///    uniform numbers are discrete, u1 = 0 had probability 2^-24 and gave the tangent direction,
///    pdf 0, so the cut-off lost 2^-24 of the paths at every bounce. The uniform numbers are now
///    in the open interval (0, 1), `rng::u32_to_unit_f32`, so cos(theta) >= 2^-12, p_brdf >=
///    7.8e-5 and no extension is tangent; a tangent ray could graze into a sphere and be trapped
///    inside.)
/// 4. **Russian roulette** decides whether the extension of step 3 happens: with probability q
///    it does and the throughput is divided by q, else the path ends. Everything found after the
///    decision (the BRDF-sampled light hit, later vertices' light samples) is therefore divided
///    by the probability of having got there, so the expectation is unchanged. The seed tests
///    roulette *before* the light sample of each vertex but divides only the extension by q,
///    which makes the light sample at vertex k reachable with probability q^k but weighted by
///    1/q^(k-1): direct light would come out 20% too dark at q = 0.8. Here the light sample of
///    a vertex always happens, and the roulette decision follows it.
/// 5. A path also ends where its throughput is exactly zero (nothing after can add light) and,
///    as a guard only, after `max_depth` vertices (`u32::MAX` by default: no bias). Every place
///    a path ends without escaping is listed in `docs/correctness.md` ("Where a path ends").
///    No shadow ray is traced from a black surface (its light sample would add exactly zero).
///
/// `features` answers which of these steps the scene needs (`crate::features`): a
/// [`crate::features::Static`] set compiles the others away, a dynamic one asks `params`.
///
/// The loop is written as a state machine ([`PathState`]) that stops at each ray cast, so a
/// backend can trace many paths' rays together (the CPU's packets); this function runs one
/// path to its end ([`PathState::run`], the GPU's way).
#[inline]
pub fn trace_path<T: Tracer, F: FeatureSet>(
    tracer: &mut T,
    features: F,
    scene: &SceneView,
    origin: Vec3,
    dir: Vec3,
    rng: &mut SampleRng,
) -> Vec3 {
    let path = PathState::new(origin, dir, *rng).run(tracer, features, scene);
    *rng = path.rng;
    path.radiance
}

/// A path of [`trace_path`] between two rounds of ray casts: what it has gathered, and the rays
/// it waits for. Each round traces up to two rays, both known before either is cast: the
/// extension (or camera) ray `ray_origin + t ray_dir` when `extend`, and the shadow segment
/// `shadow_from -> shadow_to` of the last vertex's light sample when `shadow`;
/// [`PathState::advance`] takes their answers. The light sample's contribution is computed
/// with the vertex and added once the segment is known to be clear, before the extension's
/// hit is looked at, so the radiance sums its terms in the same order as a loop that casts the
/// shadow ray first.
#[derive(Clone, Copy, Debug)]
pub struct PathState {
    /// The estimate so far; the result once [`PathState::finished`].
    pub radiance: Vec3,
    /// The product of the BRDF weights (and roulette divisions) up to the current vertex.
    pub throughput: Vec3,
    pub ray_origin: Vec3,
    /// The direction of the ray to trace (unit length); `-ray_dir` leaves the next vertex.
    pub ray_dir: Vec3,
    /// Whether `ray_origin + t ray_dir` waits to be traced (closest hit).
    pub extend: bool,
    pub shadow_from: Vec3,
    pub shadow_to: Vec3,
    /// Whether the segment `shadow_from -> shadow_to` waits to be tested (any hit).
    pub shadow: bool,
    /// What the light sample adds if the segment is clear (in a scene with media, before the
    /// transmittance of the part of the segment from `shadow_from` on).
    pub shadow_radiance: Vec3,
    /// The medium the shadow segment starts in, at `shadow_from` (scenes with media: the
    /// segment passes interfaces, `crate::medium`).
    pub shadow_medium: u32,
    /// The vertex the extension ray left and the BSDF density it was sampled with (for the MIS
    /// weight of a light it finds; `bsdf::DELTA_PDF` after a delta lobe).
    pub previous_vertex: Vec3,
    pub previous_pdf: f32,
    /// The product of the eta^2 of the refractions so far (pbrt-v4's `etaScale`): the
    /// throughput times it is what roulette reads, so radiance scaling at refractions alone
    /// does not end paths inside glass nor keep them after they leave it.
    pub eta_scale: f32,
    /// The medium the current ray travels through (an index into the media table,
    /// `crate::medium`; the scene's medium where a path starts, vacuum by default).
    pub medium: u32,
    /// The path's free flights in media that scatter (`crate::free_flight`), one word (a
    /// path's state is copied every round; scenes without media carry it unread): bits 2..30
    /// count the flights sampled so far (their numbers' dimensions, `FLIGHT_DIMENSION`), bits
    /// 0..2 are the hero channel that draws them (drawn at the first flight), and bit 31 says
    /// the last extension ray scattered at `ray_origin`, the vertex [`PathState::advance`]
    /// reached: a medium vertex ([`PathState::scattered`]).
    pub flights: u32,
    /// The ratios of the three channels' densities of the path's flights to their mean
    /// (`crate::free_flight`; the throughput is already divided by that mean).
    pub ratios: Vec3,
    /// Vertices so far: 0 while the camera ray is out.
    pub depth: u32,
    /// The sample's random numbers (the one-path loop draws a vertex's samples from them; the
    /// CPU's packets compute them for sixteen paths at once).
    pub rng: SampleRng,
}

/// A vertex a path reached ([`PathState::arrival`]): its surface there (textures applied,
/// resolved for its BSDF: `surface::shade`) and what it will draw.
#[derive(Clone, Copy, Debug)]
pub struct Arrival {
    pub material: Material,
    pub query: VertexQuery,
}

impl PathState {
    /// A path whose camera ray `origin + t dir` is to be traced; `rng` is past the camera's
    /// dimensions.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3, rng: SampleRng) -> Self {
        Self {
            radiance: Vec3::ZERO,
            throughput: Vec3::ONE,
            ray_origin: origin,
            ray_dir: dir,
            extend: true,
            shadow_from: Vec3::ZERO,
            shadow_to: Vec3::ZERO,
            shadow: false,
            shadow_radiance: Vec3::ZERO,
            shadow_medium: medium::VACUUM,
            previous_vertex: origin,
            previous_pdf: 0.0,
            eta_scale: 1.0,
            medium: medium::VACUUM,
            flights: 0,
            ratios: Vec3::ONE,
            depth: 0,
            rng,
        }
    }

    /// Whether the path is complete: no ray waits.
    #[inline]
    pub fn finished(&self) -> bool {
        !self.extend && !self.shadow
    }

    /// Runs the path to its end, one ray cast at a time through `tracer`; the result is in
    /// `radiance` of the returned (finished) state. Each round is one step of the protocol the
    /// CPU's packets also follow: trace the waiting rays, [`PathState::advance`] with their
    /// answers, and if that reached a vertex, its [`PathState::arrival`], the vertex's
    /// samples (here drawn from the path's own stream), and [`PathState::vertex`].
    #[inline]
    pub fn run<T: Tracer, F: FeatureSet>(
        mut self,
        tracer: &mut T,
        features: F,
        scene: &SceneView,
    ) -> Self {
        let mut hit = SurfaceHit::miss();
        loop {
            if self.round(tracer, features, scene, &mut hit) {
                let arrival = self.arrival(features, scene, &hit);
                let samples = VertexSamples::draw(&arrival.query, &mut self.rng);
                self.vertex(
                    features,
                    scene,
                    &hit,
                    &arrival.material,
                    &arrival.query,
                    &samples,
                );
            }
            if self.finished() {
                return self;
            }
        }
    }

    /// The first half of a round of [`PathState::run`]: traces the waiting rays through
    /// `tracer` and [`PathState::advance`]s with their answers, the extension's hit left in
    /// `hit`. Returns whether that reached a vertex (at `hit`), whose arrival, samples and
    /// [`PathState::vertex`] are the caller's.
    #[inline]
    pub fn round<T: Tracer, F: FeatureSet>(
        &mut self,
        tracer: &mut T,
        features: F,
        scene: &SceneView,
        hit: &mut SurfaceHit,
    ) -> bool {
        // A scene with media asks for the surface that blocks the segment (it may be an
        // interface, which the segment passes); any other only whether one does.
        if self.shadow {
            if features.media() {
                let blocker = tracer.first_hit_on(self.shadow_from, self.shadow_to);
                if self.shadow_passes(scene, &blocker) {
                    return false;
                }
            } else {
                let occluded = tracer.occluded(self.shadow_from, self.shadow_to);
                self.settle_shadow(occluded);
            }
        }
        *hit = if self.extend {
            tracer.closest_hit(self.ray_origin, self.ray_dir)
        } else {
            SurfaceHit::miss()
        };
        self.advance(features, scene, hit, false)
    }

    /// The vertex [`PathState::advance`] reached at `hit`: its surface (`surface::shade`) and
    /// what it will draw ([`PathState::vertex_query`]). The caller fills that query's samples
    /// and hands them with both to [`PathState::vertex`].
    #[inline]
    pub fn arrival<F: FeatureSet>(
        &self,
        features: F,
        scene: &SceneView,
        hit: &SurfaceHit,
    ) -> Arrival {
        if features.media() && self.scattered() {
            return Arrival {
                material: Material::diffuse([0.0; 3]),
                query: self.medium_query(features, scene.params),
            };
        }
        let (material, shading_normal) = shade(features, scene, hit);
        let query = self.vertex_query(features, scene.params, hit, &material, shading_normal);
        Arrival { material, query }
    }

    /// Takes the answers to this round's rays: `hit`, the closest hit of the extension ray
    /// (ignored unless `extend`), and whether the shadow segment is `occluded` (ignored unless
    /// `shadow`; in a scene with media, [`PathState::shadow_passes`] has settled the segment
    /// first); then runs the estimator up to its next ray casts (steps 1-5 above) or up to the
    /// vertex at `hit`. Returns whether the path reached that vertex: then the caller states
    /// its query ([`PathState::vertex_query`]), fills its samples and hands them to
    /// [`PathState::vertex`], which prepares the next rays. An interface (`crate::medium`) is
    /// no vertex: an extension ray that meets one goes on from its far side.
    #[inline(always)]
    pub fn advance<F: FeatureSet>(
        &mut self,
        features: F,
        scene: &SceneView,
        hit: &SurfaceHit,
        occluded: bool,
    ) -> bool {
        let (params, lights, environment) = (scene.params, scene.lights, scene.environment);
        if self.shadow {
            self.settle_shadow(occluded);
        }
        if !self.extend {
            return false;
        }
        self.extend = false;
        if features.media() {
            if self.fly(scene, hit) {
                self.depth += 1;
                return true;
            }
            if hit.is_hit() && medium::is_interface(&scene.materials[hit.material as usize]) {
                self.pass_interface(scene, hit);
                return false;
            }
        }
        if !hit.is_hit() {
            if features.environment(params) && environment::has_map(params) {
                // 1: the camera ray sees the environment map; 2(b): an extension found it,
                // weighted against light sampling's choice of the same direction as any light.
                let emitted = environment::eval(params, environment, self.ray_dir);
                if self.depth == 0 {
                    // (The throughput: 1, or what media before the first vertex leave.)
                    self.radiance = self.throughput * emitted;
                } else {
                    let pdf_l = light::environment::pdf(
                        &lights[params.environment.light as usize],
                        light_sampling_of(features, params),
                        scene,
                        self.ray_dir,
                    );
                    let weight = self.found_light_weight(features, params, pdf_l);
                    self.radiance += self.throughput * emitted * weight;
                }
                return false;
            }
            // 1: the camera ray sees the background; an extension adds it with weight 1.
            if self.depth == 0 {
                self.radiance = self.throughput * background(params);
            } else if features.background() {
                self.radiance += self.throughput * background(params);
            }
            return false;
        }
        if hit.light != NONE {
            let material = &scene.materials[hit.material as usize];
            let two_sided = features.triangle_lights() && lights[hit.light as usize].two_sided != 0;
            let emission = emission_at(features, scene, material, hit);
            let emitted = eval_radiance(emission, hit.arrived_behind, two_sided);
            if self.depth == 0 {
                // 1: a light seen directly.
                self.radiance = self.throughput * emitted;
            } else {
                // 2(b): the extension found a light.
                let pdf_l = light::pdf(
                    lights,
                    LightKinds::of(features, params),
                    light_sampling_of(features, params),
                    hit.light,
                    self.previous_vertex,
                    hit.position,
                    hit.normal,
                );
                let weight = self.found_light_weight(features, params, pdf_l);
                self.radiance += self.throughput * emitted * weight;
            }
            // A light that reflects nothing ends the path; one that also reflects (glTF's
            // emissive materials, TOML's emission + kd) goes on as any surface: its emission
            // is counted here, once, and its reflection by the vertex like any other.
            if !(features.reflecting_lights() && material.reflects()) {
                return false;
            }
        }
        self.depth += 1;
        true
    }

    /// What the vertex at `hit` (just reached, at `self.depth`) will draw: its receiver and
    /// facing normal, its light choice (none on a black or delta surface, or without light
    /// sampling), whether it may extend, roulette's survival probability and whether it
    /// chooses a lobe.
    #[inline]
    pub fn vertex_query<F: FeatureSet>(
        &self,
        features: F,
        params: &RenderParams,
        hit: &SurfaceHit,
        material: &Material,
        shading_normal: Vec3,
    ) -> VertexQuery {
        let lambertian = !features.materials() || bsdf::is_lambertian(material);
        // A Lambertian vertex reads its albedo and never chooses a lobe: only other kinds are
        // asked for their flags.
        let flags = if lambertian {
            bsdf::lambert::FLAGS
        } else {
            bsdf::flags(material)
        };
        let reflects = if lambertian {
            Vec3::from(material.albedo).max_element() > 0.0
        } else {
            !flags.delta
        };
        let light_count = self.light_count(features, params, reflects);
        let survival = self.survival(features, params);
        let ng = hit.facing_normal();
        let smooth = features.shading_normals() && shading_normal != Vec3::ZERO;
        let n = if smooth {
            // The shading normal on wo's side (pbrt-v4's two-sided BxDFs mirror wo's
            // hemisphere of the shading frame; `crate::surface`).
            side(shading_normal, shading_normal.dot(self.ray_dir) < 0.0)
        } else {
            ng
        };
        VertexQuery {
            depth: self.depth,
            x: hit.position,
            n,
            ng,
            smooth,
            light_count,
            mode: light_sampling_of(features, params),
            light_kinds: LightKinds::of(features, params),
            extend: self.depth < params.integrator.max_depth,
            roulette: self.depth >= params.integrator.rr_start_depth,
            survival,
            lambertian,
            chooses_lobe: !lambertian && flags.chooses_lobe,
        }
    }

    /// The lights next-event estimation chooses among at a vertex that `reflects` (0: none,
    /// for a black or delta surface, without lights, or with BSDF sampling alone).
    #[inline]
    pub(crate) fn light_count<F: FeatureSet>(
        &self,
        features: F,
        params: &RenderParams,
        reflects: bool,
    ) -> u32 {
        if !(features.lights(params) && reflects) || features.mis_mode(params) == mis::BSDF_ONLY {
            0
        } else if features.single_light(params) {
            1
        } else {
            params.integrator.light_count
        }
    }

    /// Roulette's survival probability at the current vertex: the throughput's largest
    /// channel (times the refractions' eta^2) up to 1, or the constant.
    #[inline]
    pub(crate) fn survival<F: FeatureSet>(&self, features: F, params: &RenderParams) -> f32 {
        let mut throughput = self.throughput;
        if features.dielectric() {
            throughput *= self.eta_scale;
        }
        if features.rr_throughput(params) {
            throughput.max_element().min(1.0)
        } else {
            params.integrator.rr_probability
        }
    }

    /// Steps 2(a), 4 and 3 at vertex `hit` (reached at `self.depth`), left toward the ray's
    /// origin, with the samples `samples` filled for `query` (this vertex's
    /// [`PathState::vertex_query`]): prepares the light sample's shadow segment and, unless the
    /// path ends here, the extension. A Lambertian vertex runs the diffuse renderer's exact
    /// arithmetic; any other material, its BSDF (`crate::bsdf`).
    #[inline]
    pub fn vertex<F: FeatureSet>(
        &mut self,
        features: F,
        scene: &SceneView,
        hit: &SurfaceHit,
        material: &Material,
        query: &VertexQuery,
        samples: &VertexSamples,
    ) {
        if features.media() && self.scattered() {
            self.medium_vertex(features, scene, query, samples);
        } else if query.lambertian {
            self.lambertian_vertex(features, scene, hit, material, query, samples);
        } else {
            self.bsdf_vertex(features, scene, hit, material, query, samples);
        }
    }

    /// [`PathState::vertex`] on a Lambertian surface.
    #[inline]
    fn lambertian_vertex<F: FeatureSet>(
        &mut self,
        features: F,
        scene: &SceneView,
        hit: &SurfaceHit,
        material: &Material,
        query: &VertexQuery,
        samples: &VertexSamples,
    ) {
        let (params, lights) = (scene.params, scene.lights);
        let (x, n, ng) = (query.x, query.n, query.ng);
        let albedo = Vec3::from(material.albedo);
        // Rays that leave at an angle start here; grazing ones higher (`geometry::GRAZING_COS`).
        let leaving = lift_ray_origin(x, ng, hit.offset);
        // With a shading normal, a direction below the geometric surface carries nothing
        // (`crate::surface`): it would leave through the surface.
        let smooth = features.shading_normals() && query.smooth;

        // 2(a): next-event estimation.
        if query.samples_light() {
            let ls = samples.light_sample(query, scene);
            let y = ls.point.position;
            let wi = (y - x).normalize();
            let cos_x = n.dot(wi);
            let cos_y = -ls.point.normal.dot(wi);
            let pdf_w = ls.pdf_solid_angle;
            let above = !smooth || ng.dot(wi) > 0.0;
            if cos_x > 0.0 && cos_y > 0.0 && pdf_w > 0.0 && above {
                let emitted = light::radiance(features, scene, query.light_kinds, &ls);
                let weight = light_sample_weight(
                    features,
                    params,
                    query.light_kinds,
                    &lights[ls.light as usize],
                    pdf_w,
                    pdf_brdf(n, wi),
                );
                let radiance =
                    self.throughput * eval_scattering(n, wi, albedo) * emitted * (weight / pdf_w);
                self.await_shadow_leaving(query.light_kinds, lights, (x, ng, leaving), hit, &ls);
                self.shadow_radiance = radiance;
                if features.media() {
                    // A Lambertian surface leaves the path in its medium.
                    self.shadow_medium = self.medium;
                }
            }
        }

        if !query.extend {
            return;
        }
        // 4: Russian roulette on the extension.
        if !self.survives_roulette(query, samples) {
            return;
        }

        // 3: extension by BRDF sampling. Every direction the sampler returns continues the
        // path (none is tangent; step 3 of `trace_path`).
        let wi = samples.brdf_direction(query);
        if smooth && ng.dot(wi) <= 0.0 {
            return;
        }
        let pdf_b = pdf_brdf(n, wi);
        // = eval_scattering(n, wi, albedo) / pdf_b, exactly (see `sampled_brdf_weight`).
        self.throughput *= sampled_brdf_weight(albedo);
        if self.throughput.max_element() <= 0.0 {
            return;
        }
        let grazing_height = hit.offset + hit.grazing_offset;
        let origin = origin_by_angle(x, ng, leaving, (wi.dot(ng), 1.0), grazing_height);
        self.await_extension(origin, wi, x, pdf_b);
    }

    /// [`PathState::vertex`] on any other material: the light sample weighed by the BSDF's
    /// value and density (skipped on delta surfaces, which `query` gives no light), the
    /// extension drawn from the BSDF. Rays leave from the side of the direction they take
    /// (through the surface after a refraction).
    #[inline]
    fn bsdf_vertex<F: FeatureSet>(
        &mut self,
        features: F,
        scene: &SceneView,
        hit: &SurfaceHit,
        material: &Material,
        query: &VertexQuery,
        samples: &VertexSamples,
    ) {
        let (params, lights) = (scene.params, scene.lights);
        let (x, n, ng) = (query.x, query.n, query.ng);
        let smooth = features.shading_normals() && query.smooth;
        let wo = -self.ray_dir;
        // The index beyond the surface over the index on wo's side (dielectrics only): the
        // outside is the side the normal points to (`SurfaceHit::normal`).
        let eta = if hit.arrived_behind {
            1.0 / material.ior
        } else {
            material.ior
        };
        // What the glossy lobe loses to multiple scattering seen from wo (glTF's material).
        let albedo = surface::glossy_albedo(features, material, scene.textures, n, wo);

        // 2(a): next-event estimation.
        if query.samples_light() {
            let ls = samples.light_sample(query, scene);
            let y = ls.point.position;
            let wi = (y - x).normalize();
            let cos_y = -ls.point.normal.dot(wi);
            let pdf_w = ls.pdf_solid_angle;
            let (f_cos, pdf_b) = bsdf::eval(features, material, n, wo, wi, eta, albedo);
            // With a shading normal, the BSDF's reflection must be one geometrically too, and
            // its transmission cross the surface (`crate::surface`).
            let consistent = !smooth || (n.dot(wi) > 0.0) == (ng.dot(wi) > 0.0);
            if cos_y > 0.0 && pdf_w > 0.0 && f_cos.max_element() > 0.0 && consistent {
                let emitted = light::radiance(features, scene, query.light_kinds, &ls);
                let weight = light_sample_weight(
                    features,
                    params,
                    query.light_kinds,
                    &lights[ls.light as usize],
                    pdf_w,
                    pdf_b,
                );
                let n_side = side(ng, ng.dot(wi) > 0.0);
                let leaving = lift_ray_origin(x, n_side, hit.offset);
                let radiance = self.throughput * f_cos * emitted * (weight / pdf_w);
                self.await_shadow_leaving(
                    query.light_kinds,
                    lights,
                    (x, n_side, leaving),
                    hit,
                    &ls,
                );
                self.shadow_radiance = radiance;
                if features.media() {
                    self.shadow_medium = self.medium_beyond(scene, material, hit, wi);
                }
            }
        }

        if !query.extend {
            return;
        }
        // 4: Russian roulette on the extension.
        if !self.survives_roulette(query, samples) {
            return;
        }

        // 3: extension by BSDF sampling.
        let (u1, u2) = samples.u_brdf;
        let s = bsdf::sample(
            features,
            material,
            n,
            wo,
            eta,
            albedo,
            samples.u_lobe,
            u1,
            u2,
        );
        if smooth && (ng.dot(s.wi) > 0.0) == s.transmitted {
            return;
        }
        self.throughput *= s.weight;
        if features.dielectric() {
            self.eta_scale *= s.eta2;
            // Only a dielectric bounds a medium (`features::MEDIA` implies `DIELECTRIC`).
            if features.media() {
                self.medium = self.medium_beyond(scene, material, hit, s.wi);
            }
        }
        if !(self.throughput.max_element() > 0.0) {
            return;
        }
        let n_side = side(ng, !s.transmitted);
        let origin =
            crate::geometry::continuation_origin(x, n_side, s.wi, hit.offset, hit.grazing_offset);
        self.await_extension(origin, s.wi, x, s.pdf);
    }

    /// The shadow segment's answer: the light sample's radiance is added if the segment is
    /// not `occluded`, and no segment waits any more. [`PathState::run`] settles it before it
    /// traces the extension ray, so that `shadow_radiance` is not live across that trace (on a
    /// GPU, what is live across a trace call is saved and restored around it); the sum is the
    /// same, since [`PathState::advance`] adds nothing before it.
    #[inline]
    fn settle_shadow(&mut self, occluded: bool) {
        if !occluded {
            self.radiance += self.shadow_radiance;
        }
        self.shadow = false;
    }

    /// Step 4 at the vertex of `query`: whether the path survives Russian roulette, dividing
    /// its throughput by the survival probability if so (no number is drawn, and the path
    /// always survives, where survival is certain).
    #[inline]
    pub(crate) fn survives_roulette(
        &mut self,
        query: &VertexQuery,
        samples: &VertexSamples,
    ) -> bool {
        if query.draws_roulette() {
            if !query.survives(samples.u_roulette) {
                return false;
            }
            self.throughput /= query.survival;
        }
        true
    }

    /// The light sample `ls` waits for its shadow segment from `from` (offset off the surface)
    /// to the light point; `radiance` is what it adds if the segment is clear (in a scene with
    /// media, times the segment's transmittance: the caller sets `shadow_medium`, the medium
    /// the segment leaves into, and [`PathState::shadow_passes`] applies it).
    #[inline]
    pub(crate) fn await_shadow(
        &mut self,
        kinds: LightKinds,
        lights: &[Light],
        from: Vec3,
        ls: &LightSample,
        radiance: Vec3,
    ) {
        self.shadow = true;
        self.shadow_from = from;
        self.shadow_to = shadow_ray_end(
            from,
            ls.point.position,
            ls.point.normal,
            light::point_error(kinds, &lights[ls.light as usize]),
        );
        self.shadow_radiance = radiance;
    }

    /// [`PathState::await_shadow`] for a segment leaving surface point `x` (its hit `hit`) on
    /// the side of unit normal `n_side`, `leaving` being `x` lifted by the hit's offset: the
    /// segment of `geometry::shadow_segment` (lifted higher where it grazes the surface). The
    /// caller sets `shadow_radiance`.
    #[inline]
    pub(crate) fn await_shadow_leaving(
        &mut self,
        kinds: LightKinds,
        lights: &[Light],
        (x, n_side, leaving): (Vec3, Vec3, Vec3),
        hit: &SurfaceHit,
        ls: &LightSample,
    ) {
        let target_error = light::point_error(kinds, &lights[ls.light as usize]);
        let (from, to) = shadow_segment(
            x,
            n_side,
            leaving,
            (hit.offset, hit.offset + hit.grazing_offset),
            (ls.point.position, ls.point.normal, target_error),
        );
        self.shadow = true;
        self.shadow_from = from;
        self.shadow_to = to;
    }

    /// The extension ray `origin + t dir` waits to be traced, leaving vertex `x`, drawn with
    /// density `pdf` (`bsdf::DELTA_PDF` for a delta lobe).
    #[inline]
    pub(crate) fn await_extension(&mut self, origin: Vec3, dir: Vec3, x: Vec3, pdf: f32) {
        self.extend = true;
        self.ray_origin = origin;
        self.ray_dir = dir;
        self.previous_vertex = x;
        self.previous_pdf = pdf;
    }
}

impl PathState {
    /// The MIS weight of a light (area light or environment map) that the extension from
    /// `previous_vertex` found, where light sampling has density `pdf_light` (read only under
    /// the power heuristic; the other modes' unused density is pure code, which inlining
    /// drops). After a delta lobe (pdf `DELTA_PDF`) light sampling
    /// could not have found it: the power heuristic's ratio pdf_l / inf is 0, weight 1; the
    /// other modes test for it.
    #[inline]
    fn found_light_weight<F: FeatureSet>(
        &self,
        features: F,
        params: &RenderParams,
        pdf_light: f32,
    ) -> f32 {
        let mode = features.mis_mode(params);
        if mode == mis::POWER {
            power_heuristic(self.previous_pdf, pdf_light)
        } else if features.materials() && self.previous_pdf == DELTA_PDF {
            1.0
        } else {
            bsdf_strategy_weight(mode)
        }
    }
}

/// The origin of a ray along unit `dir` that goes on through the surface at `hit`: its point,
/// lifted to the side `dir` points to (`geometry::continuation_origin`).
#[inline]
pub(crate) fn beyond_surface(hit: &SurfaceHit, dir: Vec3) -> Vec3 {
    continuation_origin(
        hit.position,
        side(hit.normal, hit.normal.dot(dir) > 0.0),
        dir,
        hit.offset,
        hit.grazing_offset,
    )
}

/// The origin of the rest of a shadow segment along `dir` toward `to` that goes on through the
/// surface at `hit`: its point lifted by the hit's offset to the side `dir` points to, or by
/// both heights where the segment from there to `to` grazes the surface
/// (`geometry::origin_by_angle_v3`, decided on the segment as traced: its end does not move).
#[inline]
pub(crate) fn beyond_surface_toward(hit: &SurfaceHit, dir: Vec3, to: Vec3) -> Vec3 {
    let n_side = side(hit.normal, hit.normal.dot(dir) > 0.0);
    let leaving = lift_ray_origin(hit.position, n_side, hit.offset);
    let d = to - leaving;
    let grazing_height = hit.offset + hit.grazing_offset;
    origin_by_angle(
        hit.position,
        n_side,
        leaving,
        (d.dot(n_side), d.length()),
        grazing_height,
    )
}

/// `n` where `toward_n`, else `-n`: the normal of the side a ray leaves from.
#[inline]
fn side(n: Vec3, toward_n: bool) -> Vec3 {
    if toward_n {
        n
    } else {
        -n
    }
}

/// The MIS weight of a sample of light `light` (density `pdf_light`, the BSDF's `pdf_bsdf`):
/// 1 for a delta light (`light::is_delta`), which no BSDF sample can meet, else
/// [`light_strategy_weight`]'s.
#[inline]
pub(crate) fn light_sample_weight<F: FeatureSet>(
    features: F,
    params: &RenderParams,
    kinds: LightKinds,
    light: &Light,
    pdf_light: f32,
    pdf_bsdf: f32,
) -> f32 {
    if light::is_delta(kinds, light) {
        1.0
    } else {
        light_strategy_weight(features, params, pdf_light, pdf_bsdf)
    }
}

/// The MIS weight of a light sample of density `pdf_light` whose direction the BSDF samples
/// with density `pdf_bsdf`.
#[inline]
fn light_strategy_weight<F: FeatureSet>(
    features: F,
    params: &RenderParams,
    pdf_light: f32,
    pdf_bsdf: f32,
) -> f32 {
    let mode = features.mis_mode(params);
    if mode == mis::POWER {
        power_heuristic(pdf_light, pdf_bsdf)
    } else if mode == mis::LIGHT_ONLY {
        1.0
    } else {
        // HALF (BSDF_ONLY takes no light sample).
        0.5
    }
}

/// The MIS weight of a light found by BSDF sampling under a constant-weight `mode` (not the
/// power heuristic, not after a delta lobe).
#[inline]
fn bsdf_strategy_weight(mode: u32) -> f32 {
    if mode == mis::LIGHT_ONLY {
        0.0
    } else if mode == mis::BSDF_ONLY {
        1.0
    } else {
        0.5
    }
}

/// The background radiance (seen by rays that leave the scene).
#[inline]
fn background(params: &RenderParams) -> Vec3 {
    Vec3::new(
        params.environment.background[0],
        params.environment.background[1],
        params.environment.background[2],
    )
}

/// How this render samples points on lights (`scene::light_sampling`).
#[inline]
pub fn light_sampling_of<F: FeatureSet>(features: F, params: &RenderParams) -> u32 {
    if features.light_solid_angle(params) {
        light_sampling::SOLID_ANGLE
    } else {
        light_sampling::AREA
    }
}

/// One sample of pixel (px, py) (column from the left, row from the top): a uniformly random
/// position inside the pixel (box filter), the camera ray through it (and through a point of
/// the lens, with a thin lens), and [`trace_path`]. Both backends compute exactly this, so a
/// sample is the same function of (seed, pixel, sample): the GPU by this function, the CPU's
/// packets by [`start_sample`] and [`PathState::advance`].
#[inline]
pub fn render_sample<T: Tracer, F: FeatureSet>(
    tracer: &mut T,
    features: F,
    scene: &SceneView,
    px: u32,
    py: u32,
    sample: u32,
) -> Vec3 {
    start_sample(features, scene.params, px, py, sample)
        .run(tracer, features, scene)
        .radiance
}

/// The path of sample `sample` of pixel (px, py) with its camera ray waiting (see
/// [`render_sample`]).
#[inline]
pub fn start_sample<F: FeatureSet>(
    features: F,
    params: &RenderParams,
    px: u32,
    py: u32,
    sample: u32,
) -> PathState {
    start_path(features, params, px, py, sample_rng(params, px, py, sample))
}

/// The random numbers of sample `sample` of pixel (px, py) (its sampler and sequence index
/// from [`sample_stream`]).
#[inline]
pub fn sample_rng(params: &RenderParams, px: u32, py: u32, sample: u32) -> SampleRng {
    let (sampler, index) = sample_stream(params, sample);
    SampleRng::with_sampler(
        params.samples.seed,
        py * params.samples.width + px,
        index,
        sampler,
    )
}

/// The path of pixel (px, py) that draws its numbers from `rng`, with its camera ray waiting:
/// through a uniformly random position inside the pixel, the camera's pair of numbers.
#[inline]
pub fn start_path<F: FeatureSet>(
    features: F,
    params: &RenderParams,
    px: u32,
    py: u32,
    mut rng: SampleRng,
) -> PathState {
    rng.seek(CAMERA_DIMENSION);
    let (u, v) = rng.next_2d();
    start_path_at(features, params, px, py, rng, (u, v))
}

/// [`start_path`] with the camera's pair `(u, v)` already drawn (the CPU's packets draw
/// sixteen at once). With a thin lens, the lens point's pair is drawn here, from its own
/// dimensions (`vertex_samples::LENS_DIMENSION`).
#[inline]
pub fn start_path_at<F: FeatureSet>(
    features: F,
    params: &RenderParams,
    px: u32,
    py: u32,
    mut rng: SampleRng,
    (u, v): (f32, f32),
) -> PathState {
    let camera = &params.camera;
    let dir = camera_ray_direction(
        camera,
        params.samples.width,
        params.samples.height,
        px,
        py,
        u,
        v,
    );
    let mut path = if features.thin_lens() && lens_radius(camera) > 0.0 {
        rng.seek(LENS_DIMENSION);
        let (u1, u2) = rng.next_2d();
        let (origin, dir) = thin_lens_ray(camera, dir, u1, u2);
        PathState::new(origin, dir, rng)
    } else {
        PathState::new(camera_origin(camera), dir, rng)
    };
    if features.media() {
        // The camera is outside every closed shape, in the scene's medium.
        path.medium = params.environment.medium;
    }
    path
}
