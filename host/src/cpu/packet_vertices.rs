//! The light samples and BRDF directions of sixteen paths' next vertices at once. After a
//! round's rays, the kernel's samplers in their [`kernel::real::Real`] form
//! (`sample_sphere_cone_v3`, `brdf::sample_brdf_v3`) run on SIMD lanes, one path per
//! lane, from the numbers `packet_numbers` computed; each path's vertex then takes its samples
//! through [`VertexSampler`] instead of computing them one at a time (a chain of divisions and
//! square roots: `sample_light_from` alone was 20% of a Cornell render). A lane computes exactly
//! what the scalar sampler computes, and a path takes a sample only if the arguments it asks
//! with are, bit for bit, the ones the sample was computed for, so images do not change.

use super::packet::LANES;
use super::packet_numbers::{
    PrefetchedStream, BRDF_PAIR, EMPTY, LIGHT_CHOICE_SINGLE, LIGHT_POINT_PAIR,
};
use super::simd::widest_simd;
use glam::Vec3;
use kernel::brdf::sample_brdf_v3;
use kernel::light::{choose_light, cone_light_sample, uses_cone, DirectionalLightSample};
use kernel::path::{
    PathState, BRDF_DIMENSION, CAMERA_DIMENSIONS, DIMENSIONS_PER_VERTEX, LIGHT_CHOICE_DIMENSION,
    LIGHT_POINT_DIMENSION,
};
use kernel::real::V3;
use kernel::sampling::{sample_sphere_cone_v3, ConeSample, SurfacePoint};
use kernel::scene::{light_sampling, SphereLight, NONE};
use kernel::vertex_sampler::VertexSampler;
use kernel::SurfaceHit;
use std::simd::Simd;

type Lanes = Simd<f32, LANES>;
/// Sixteen values of one argument, by lane.
type Column = [f32; LANES];

/// A light sample computed ahead, with the arguments it was computed for: the stream position
/// of its pair of numbers ([`EMPTY`]: no sample) and the arguments of
/// `VertexSampler::sample_light_from`.
#[derive(Clone, Copy, Debug)]
pub struct PresampledLight {
    dimension: u32,
    x: Vec3,
    u_select: f32,
    light_count: u32,
    mode: u32,
    sample: DirectionalLightSample,
}

impl PresampledLight {
    pub const NONE: Self = Self {
        dimension: EMPTY,
        x: Vec3::ZERO,
        u_select: 0.0,
        light_count: 0,
        mode: 0,
        sample: DirectionalLightSample {
            point: SurfacePoint {
                position: Vec3::ZERO,
                normal: Vec3::ZERO,
            },
            light: NONE,
            pdf_solid_angle: 0.0,
        },
    };
}

/// A BRDF direction computed ahead, with the stream position of its pair ([`EMPTY`]: none)
/// and the facing normal.
#[derive(Clone, Copy, Debug)]
pub struct PresampledBrdf {
    dimension: u32,
    n: Vec3,
    wi: Vec3,
}

impl PresampledBrdf {
    pub const NONE: Self = Self {
        dimension: EMPTY,
        n: Vec3::ZERO,
        wi: Vec3::ZERO,
    };
}

/// Whether `a` and `b` have the same bits (so any function gives both the same result).
#[inline(always)]
fn same_bits(a: Vec3, b: Vec3) -> bool {
    let same = |p: f32, q: f32| p.to_bits() == q.to_bits();
    same(a.x, b.x) & same(a.y, b.y) & same(a.z, b.z)
}

impl PrefetchedStream {
    /// Whether a light sample whose pair starts at `dimension` is computed ahead.
    pub fn holds_light_sample(&self, dimension: u32) -> bool {
        self.light.dimension == dimension
    }

    /// Whether a BRDF direction whose pair starts at `dimension` is computed ahead.
    pub fn holds_brdf_direction(&self, dimension: u32) -> bool {
        self.brdf.dimension == dimension
    }
}

// Inlined into the kernel's vertex: a few comparisons, then the sample computed ahead or, for
// anything else, `SampleRng`'s own (which computes the pair's numbers again: rare, and the same
// numbers).
impl VertexSampler for PrefetchedStream {
    #[inline(always)]
    fn sample_light_from(
        &mut self,
        lights: &[SphereLight],
        light_count: u32,
        mode: u32,
        x: Vec3,
        u_select: f32,
    ) -> DirectionalLightSample {
        let p = &self.light;
        // (A dimension the stream is at is never EMPTY.)
        if p.dimension == self.rng.dimension
            && same_bits(p.x, x)
            && p.u_select.to_bits() == u_select.to_bits()
            && p.light_count == light_count
            && p.mode == mode
        {
            self.rng.dimension += 2;
            return p.sample;
        }
        // Computed now, as the one-path loop does.
        self.rng
            .sample_light_from(lights, light_count, mode, x, u_select)
    }

    #[inline(always)]
    fn sample_brdf(&mut self, n: Vec3) -> Vec3 {
        let p = &self.brdf;
        if p.dimension == self.rng.dimension && same_bits(p.n, n) {
            self.rng.dimension += 2;
            return p.wi;
        }
        self.rng.sample_brdf(n)
    }
}

/// The samplers' arguments by lane (zero in empty lanes; lanes that want nothing compute too,
/// and their results, NaN or not, are not read).
#[derive(Default)]
struct Arguments {
    center: [Column; 3],
    radius: Column,
    receiver: [Column; 3],
    u_light: [Column; 2],
    normal: [Column; 3],
    u_brdf: [Column; 2],
}

/// The samplers' results by lane: the light point, its normal, its density, and the BRDF
/// direction.
struct Results {
    position: [Column; 3],
    light_normal: [Column; 3],
    pdf: Column,
    wi: [Column; 3],
}

/// Lanes `v` as a [`V3`] of SIMD vectors.
fn lanes3(v: &[Column; 3]) -> V3<Lanes> {
    V3::new(
        Lanes::from_array(v[0]),
        Lanes::from_array(v[1]),
        Lanes::from_array(v[2]),
    )
}

fn columns3(v: V3<Lanes>) -> [Column; 3] {
    [v.x.to_array(), v.y.to_array(), v.z.to_array()]
}

/// Lane `lane` of `v` as a vector.
fn lane3(v: &[Column; 3], lane: usize) -> Vec3 {
    Vec3::new(v[0][lane], v[1][lane], v[2][lane])
}

fn set_lane3(v: &mut [Column; 3], lane: usize, x: Vec3) {
    for (column, value) in v.iter_mut().zip(x.to_array()) {
        column[lane] = value;
    }
}

impl Arguments {
    widest_simd! {
        /// Both samplers on every lane.
        fn compute(&self) -> Results = compute_any_cpu, compute_avx512, compute_avx2
    }

    #[inline(always)]
    fn compute_any_cpu(&self) -> Results {
        let lanes = Lanes::from_array;
        let cone = sample_sphere_cone_v3(
            lanes3(&self.center),
            lanes(self.radius),
            lanes3(&self.receiver),
            lanes(self.u_light[0]),
            lanes(self.u_light[1]),
        );
        let wi = sample_brdf_v3(
            lanes3(&self.normal),
            lanes(self.u_brdf[0]),
            lanes(self.u_brdf[1]),
        );
        Results {
            position: columns3(cone.position),
            light_normal: columns3(cone.normal),
            pdf: cone.pdf_solid_angle.to_array(),
            wi: columns3(wi),
        }
    }
}

/// For each path of `slots` whose extension ray found a surface that is not a light
/// (`hits`, by lane), computes the light sample and BRDF direction of the vertex there from its
/// computed numbers (`packet_numbers::prefetch_vertices`, called before): the light sample if
/// `mode` is cone sampling and the receiver is outside the chosen light (what the kernel's
/// `sample_light_from` then samples by the cone), with `light_count` lights.
pub fn presample_vertices<T>(
    slots: &mut [Option<(T, PathState<PrefetchedStream>)>; LANES],
    hits: &[SurfaceHit; LANES],
    lights: &[SphereLight],
    light_count: u32,
    mode: u32,
) {
    // Written without branches on the lanes' data (hit or miss, which light), which a CPU
    // cannot predict: every lane computes, and the ones that want nothing get EMPTY dimensions.
    let mut args = Arguments::default();
    // By lane: the dimensions of the light sample's and the BRDF's pairs (EMPTY: none), the
    // light whose cone is sampled and the light choice's number.
    let mut light_dimension = [EMPTY; LANES];
    let mut brdf_dimension = [EMPTY; LANES];
    let mut chosen = [0u32; LANES];
    let mut u_selects = [0f32; LANES];
    let cones = light_count > 0 && mode == light_sampling::CONE;
    for (lane, slot) in slots.iter().enumerate() {
        let Some((_, path)) = slot else { continue };
        let hit = &hits[lane];
        let at_surface = path.extend & hit.is_hit() & (hit.light == NONE);
        // The block of the vertex the hit becomes (its depth is one more than the path's).
        let block = CAMERA_DIMENSIONS + path.depth * DIMENSIONS_PER_VERTEX;
        let x = hit.position;
        if cones {
            let (choice_dimension, u_select) = if light_count > 1 {
                path.rng.single(LIGHT_CHOICE_SINGLE)
            } else {
                (block + LIGHT_CHOICE_DIMENSION, 0.0)
            };
            let (dimension, (u1, u2)) = path.rng.pair(LIGHT_POINT_PAIR);
            let light = choose_light(lights, light_count, u_select);
            let l = &lights[light as usize];
            let wanted = at_surface
                & (choice_dimension == block + LIGHT_CHOICE_DIMENSION)
                & (dimension == block + LIGHT_POINT_DIMENSION)
                & uses_cone(mode, l, x);
            set_lane3(&mut args.center, lane, Vec3::from(l.center));
            args.radius[lane] = l.radius;
            set_lane3(&mut args.receiver, lane, x);
            (args.u_light[0][lane], args.u_light[1][lane]) = (u1, u2);
            light_dimension[lane] = if wanted { dimension } else { EMPTY };
            chosen[lane] = light;
            u_selects[lane] = u_select;
        }
        let (dimension, (u1, u2)) = path.rng.pair(BRDF_PAIR);
        let wanted = at_surface & (dimension == block + BRDF_DIMENSION);
        set_lane3(&mut args.normal, lane, hit.facing_normal());
        (args.u_brdf[0][lane], args.u_brdf[1][lane]) = (u1, u2);
        brdf_dimension[lane] = if wanted { dimension } else { EMPTY };
    }
    let wanted = |dimensions: &[u32; LANES]| dimensions.iter().any(|&d| d != EMPTY);
    if !wanted(&light_dimension) && !wanted(&brdf_dimension) {
        for (_, path) in slots.iter_mut().flatten() {
            path.rng.light = PresampledLight::NONE;
            path.rng.brdf = PresampledBrdf::NONE;
        }
        return;
    }
    let results = args.compute();
    for (lane, slot) in slots.iter_mut().enumerate() {
        let Some((_, path)) = slot else { continue };
        path.rng.light = if cones {
            let light = chosen[lane];
            let cone = ConeSample {
                point: SurfacePoint {
                    position: lane3(&results.position, lane),
                    normal: lane3(&results.light_normal, lane),
                },
                pdf_solid_angle: results.pdf[lane],
            };
            PresampledLight {
                dimension: light_dimension[lane],
                x: lane3(&args.receiver, lane),
                u_select: u_selects[lane],
                light_count,
                mode,
                sample: cone_light_sample(&lights[light as usize], light, cone),
            }
        } else {
            PresampledLight::NONE
        };
        path.rng.brdf = PresampledBrdf {
            dimension: brdf_dimension[lane],
            n: lane3(&args.normal, lane),
            wi: lane3(&results.wi, lane),
        };
    }
}
