//! The samples of sixteen path vertices at once, filled from their sixteen
//! [`VertexQuery`]s: the numbers on SIMD lanes (`packet_numbers`), and from them the cone light
//! samples of sphere lights and the Lambertian BRDF directions (other materials' directions are the vertex's
//! own, from the numbers; the lobe choice is drawn one lane at a time) by the kernel's samplers in their
//! [`kernel::real::Real`] form (`sample_sphere_cone_v3`, `bsdf::lambert::sample_brdf_v3`) on lanes. Any
//! other sample (area sampling, a receiver inside its light) is left to the vertex, which
//! computes it from the numbers with the scalar sampler. Each lane's numbers are exactly what
//! `VertexSamples::draw` gives, and each sample given exactly what the vertex would compute
//! (one at a time, a chain of divisions and square roots, they were a large share of a render:
//! docs/performance.md).

use super::packet::LANES;
use super::packet_numbers::NumberRequests;
use super::simd::widest_simd;
use glam::Vec3;
use kernel::bsdf::lambert::sample_brdf_v3;
use kernel::light::choose_light;
use kernel::light::sphere::{cone_sample, uses_cone};
use kernel::real::V3;
use kernel::rng::SampleRng;
use kernel::sampling::{sample_sphere_cone_v3, ConeSample, SurfacePoint};
use kernel::scene::{light_kind, Light};
use kernel::vertex_samples::{VertexQuery, VertexSamples, NO_DIMENSION};
use std::simd::Simd;

type Lanes = Simd<f32, LANES>;
/// Sixteen values of one argument, by lane.
type Column = [f32; LANES];

/// The samplers' arguments by lane (zero in lanes that want nothing; those compute too, and
/// their results, NaN or not, are not read).
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

/// The samples of up to sixteen vertices, by lane: for each `(stream, query)`, the numbers
/// `VertexSamples::draw(query, stream)` gives and, where computed on lanes, the light sample
/// and BRDF direction the vertex would compute from them (`VertexSamples::NONE` in empty
/// lanes).
pub fn fill_vertex_samples(
    queries: &[Option<(SampleRng, VertexQuery)>; LANES],
    lights: &[Light],
) -> [VertexSamples; LANES] {
    let dimensions = queries.map(|entry| entry.map(|(_, q)| q.dimensions()));
    let mut requests = NumberRequests::default();
    for (lane, (entry, dims)) in queries.iter().zip(&dimensions).enumerate() {
        let (Some((rng, _)), Some((singles, pairs))) = (entry, dims) else {
            continue;
        };
        requests.set(lane, rng, *pairs, *singles);
    }
    let numbers = requests.compute();

    // Every lane's numbers and the samplers' arguments (written without branches on the lanes'
    // data where a CPU could not predict them).
    let mut samples = [VertexSamples::NONE; LANES];
    let mut args = Arguments::default();
    let mut cone_light = [None; LANES];
    let mut brdf_wanted = false;
    for (lane, (entry, dims)) in queries.iter().zip(&dimensions).enumerate() {
        let (Some((rng, q)), Some(dims)) = (entry, dims) else {
            continue;
        };
        let pair = |p: usize| (numbers.pairs[p][0][lane], numbers.pairs[p][1][lane]);
        let s = &mut samples[lane];
        *s = VertexSamples::from_numbers(
            *dims,
            [numbers.singles[0][lane], numbers.singles[1][lane]],
            [pair(0), pair(1)],
        );
        if q.samples_light() {
            let light = choose_light(lights, q.light_count, s.u_select);
            let l = &lights[light as usize];
            if l.kind == light_kind::SPHERE && uses_cone(q.mode, l, q.x) {
                set_lane3(&mut args.center, lane, Vec3::from(l.position));
                args.radius[lane] = l.radius;
                set_lane3(&mut args.receiver, lane, q.x);
                (args.u_light[0][lane], args.u_light[1][lane]) = s.u_light;
                cone_light[lane] = Some(light);
            }
        }
        set_lane3(&mut args.normal, lane, q.n);
        (args.u_brdf[0][lane], args.u_brdf[1][lane]) = s.u_brdf;
        brdf_wanted |= q.extend && q.lambertian;
        // The lobe choice, one number, drawn here for the few vertices that read it.
        let lobe = q.lobe_dimension();
        if lobe != NO_DIMENSION && q.survives(s.u_roulette) {
            let mut rng = *rng;
            rng.seek(lobe);
            s.u_lobe = rng.next_f32();
        }
    }
    if !brdf_wanted && cone_light.iter().all(Option::is_none) {
        return samples;
    }
    let results = args.compute();
    for (lane, s) in samples.iter_mut().enumerate() {
        let Some((_, q)) = &queries[lane] else {
            continue;
        };
        if let Some(light) = cone_light[lane] {
            let cone = ConeSample {
                point: SurfacePoint {
                    position: lane3(&results.position, lane),
                    normal: lane3(&results.light_normal, lane),
                },
                pdf_solid_angle: results.pdf[lane],
            };
            s.light = cone_sample(&lights[light as usize], light, cone);
            s.has_light = true;
        }
        // The Lambertian direction (`bsdf::lambert::sample_brdf`); other materials sample their own.
        s.brdf_dir = lane3(&results.wi, lane);
        s.has_brdf_dir = q.extend && q.lambertian;
    }
    samples
}
