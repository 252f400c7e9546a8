//! Function-level CPU-vs-GPU equivalence: every kernel function through `kernel::probe` on the
//! same 100,000 inputs natively and in the `shaders::probe` compute entry point (validation on).
//! Inputs favour the edges: normals on and near the axes (including exactly -Z), grazing
//! directions, points on the surface, magnitudes from 1e-6 to 1e6.

use glam::Vec3;
use kernel::probe::{evaluate, function};
use twinpath::vulkan::compute::ProbeRunner;
use twinpath_tests::device_class::{
    bsdf_apart, environment_apart, punctual_apart, EnvironmentRecord, PunctualRecord,
};
use twinpath_tests::gpu::{assert_validation_clean, context};

const N: usize = 100_000;

use twinpath_tests::probe_inputs::ProbeInputs as Gen;

fn rec(v: [[f32; 4]; 4]) -> [[u32; 4]; 4] {
    v.map(|r| r.map(f32::to_bits))
}
fn w(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

fn inputs(func: u32, g: &mut Gen) -> Vec<[[u32; 4]; 4]> {
    (0..N)
        .map(|_| match func {
            function::SAMPLE_LOBE => {
                let (a, b) = (g.range(-1.0, 1.0), g.unit().sqrt());
                let c = g.pick(&[0.0, 1.0, -1.0, a, b]);
                rec([
                    w(g.dir(), 0.0),
                    [c, g.range(0.0, 6.2831855), 0.0, 0.0],
                    [0.0; 4],
                    [0.0; 4],
                ])
            }
            function::ORTHONORMAL_BASIS => rec([w(g.dir(), 0.0), [0.0; 4], [0.0; 4], [0.0; 4]]),
            function::SAMPLE_SPHERE => {
                let s = g.scale();
                rec([
                    w(g.vec() * s, g.scale()),
                    [g.unit(), g.unit(), 0.0, 0.0],
                    [0.0; 4],
                    [0.0; 4],
                ])
            }
            function::SAMPLE_SPHERE_CONE => {
                let r = g.scale();
                let c = g.vec() * g.scale();
                // The receiver from just outside the surface to 1e6 radii away.
                let p = c + g.dir() * r * (1.0 + g.pick(&[1e-4, 1e-2, 1.0, 1e3, 1e6]));
                rec([w(c, r), w(p, 0.0), [g.unit(), g.unit(), 0.0, 0.0], [0.0; 4]])
            }
            function::GEOMETRY_FACTOR => {
                let s = g.scale();
                let pa = g.vec() * s;
                let pb = if g.u64().is_multiple_of(8) {
                    pa
                } else {
                    pa + g.dir() * g.scale()
                };
                rec([w(pa, 0.0), w(g.dir(), 0.0), w(pb, 0.0), w(g.dir(), 0.0)])
            }
            function::INTERSECT_SPHERE => {
                let r = g.scale();
                let c = g.vec() * g.scale();
                // Origins on the surface, inside, or far; directions toward, grazing or away.
                let n = g.dir();
                let o = match g.u64() % 3 {
                    0 => c + n * r,
                    1 => c + g.vec() * r * 0.5,
                    _ => c + n * r * g.range(1.5, 1e4),
                };
                let d = if g.u64().is_multiple_of(2) {
                    g.grazing(n)
                } else {
                    (c - o + g.vec() * r).normalize_or(n)
                };
                rec([
                    w(o, 0.0),
                    w(d, 0.0),
                    w(c, r),
                    [0.0, f32::INFINITY, 0.0, 0.0],
                ])
            }
            function::INTERSECT_TRIANGLE => {
                let s = g.scale();
                let p0 = g.vec() * s;
                let (e1, e2) = (g.vec() * s, g.vec() * s);
                let n = e1.cross(e2).normalize_or(Vec3::Z);
                let target = p0 + e1 * g.unit() + e2 * g.unit();
                let o = target + g.grazing(n) * s * g.range(0.0, 10.0);
                let d = (target - o).normalize_or(g.dir());
                rec([w(o, f32::INFINITY), w(d, e2.x), w(p0, e2.y), w(e1, e2.z)])
            }
            function::PLANE_SIDE => {
                // A triangle (a quarter in a plane normal to z, a third translated by 10^3 of
                // its size), an origin on it or 10^-7 to 1 of its size off its plane, either
                // side, and a random or grazing direction.
                let s = g.scale();
                let p0 = g.vec() * s * g.pick(&[1.0, 1.0, 1e3]);
                let (mut e1, mut e2) = (g.vec() * s, g.vec() * s);
                if g.u64().is_multiple_of(4) {
                    (e1.z, e2.z) = (0.0, 0.0);
                }
                // The edges as the host computes them, from f32 vertices.
                let (e1, e2) = ((p0 + e1) - p0, (p0 + e2) - p0);
                let n = e1.cross(e2).normalize_or(Vec3::Z);
                let p = p0 + e1 * (0.5 * g.unit()) + e2 * (0.5 * g.unit());
                let h = g.pick(&[0.0, 1e-7, 1e-5, 1e-3, 1.0]) * g.pick(&[1.0, -1.0]);
                let o = p + n * h * s;
                let d = if g.u64().is_multiple_of(3) {
                    g.grazing(n)
                } else {
                    g.dir()
                };
                rec([w(o, e2.x), w(d, e2.y), w(p0, e2.z), w(e1, 0.0)])
            }
            function::OFFSET_RAY_ORIGIN => {
                let s = g.scale();
                let m = g.pick(&[s, 1e-3, 0.03, 1.0, 1e4]);
                let p = g.vec() * m;
                rec([
                    w(p, 0.0),
                    w(g.dir(), 0.0),
                    w(p + g.dir() * g.scale(), 0.0),
                    [0.0; 4],
                ])
            }
            function::BRDF => {
                let n = g.dir();
                rec([
                    w(n, 0.0),
                    w(g.grazing(n), 0.0),
                    [g.unit(), g.unit(), g.unit(), 0.0],
                    [g.unit(), g.unit(), 0.0, 0.0],
                ])
            }
            function::RNG => {
                let words = [
                    g.u64() as u32,
                    g.u64() as u32 % 4096,
                    g.u64() as u32 % 64,
                    g.u64() as u32,
                ];
                [words, [0; 4], [0; 4], [0; 4]]
            }
            function::CAMERA_RAY => {
                let f = g.dir();
                let r = f.cross(g.dir()).normalize_or(Vec3::X);
                let u = r.cross(f);
                let h = g.range(0.01, 10.0);
                let (wd, ht) = (1 + g.u64() as u32 % 4096, 1 + g.u64() as u32 % 4096);
                let (px, py) = (g.u64() as u32 % wd, g.u64() as u32 % ht);
                let mut x = rec([
                    w(f, 0.0),
                    w(r * h, 0.0),
                    w(u * h, 0.0),
                    [g.unit(), g.unit(), 0.0, 0.0],
                ]);
                x[0][3] = wd;
                x[1][3] = ht;
                x[2][3] = px;
                x[3][2] = py;
                x
            }
            function::FRESNEL => {
                let (u, v) = (g.unit(), g.unit().sqrt());
                let c = g.pick(&[0.0, 1.0, 1e-4, u, v]);
                let e = g.range(0.1, 10.0);
                let eta = g.pick(&[1.5, 1.0 / 1.5, 1.0001, e]);
                let k = g.range(0.0, 10.0);
                let k = g.pick(&[0.0, k]);
                rec([
                    [c, eta, k, 0.0],
                    [g.unit(), g.unit(), g.unit(), 0.0],
                    [0.0; 4],
                    [0.0; 4],
                ])
            }
            function::MICROFACET => {
                let n = g.dir();
                let a = g.range(1e-3, 1.0);
                let alpha = g.pick(&[1e-3, 0.05, 0.3, 1.0, a]);
                let wo = g.grazing(n);
                let wo = if wo.dot(n) < 0.0 { -wo } else { wo };
                let (u, v) = (g.unit(), g.unit().sqrt());
                let c = g.pick(&[0.0, 1.0, 1e-4, u, v]);
                let s2 = (1.0 - c * c).max(0.0);
                rec([
                    w(n, alpha),
                    w(wo, c),
                    [g.unit(), g.unit(), s2, 0.0],
                    [0.0; 4],
                ])
            }
            function::BSDF_EVAL | function::BSDF_SAMPLE => {
                let n = g.dir();
                let a = g.range(1e-3, 1.0);
                let alpha = g.pick(&[0.0, 1e-3, 0.05, 0.3, 1.0, a]);
                let eta = g.pick(&[1.5, 1.0 / 1.5, 1.0001]);
                let wo = g.grazing(n);
                let wo = if wo.dot(n) < 0.0 { -wo } else { wo };
                let third = if func == function::BSDF_EVAL {
                    w(g.grazing(n), 0.0)
                } else {
                    [g.unit(), g.unit(), g.unit(), 0.0]
                };
                let mut x = rec([w(n, alpha), w(wo, eta), third, [0.0; 4]]);
                // The clear coat (where `complex` asks for one) has the material's roughness.
                x[2][3] = kernel::scene::Material::pack_coat(0.8, alpha.sqrt());
                x[3][0] = (g.u64() % 5) as u32;
                // Bits of `probe_material`'s `complex`: gold's index, a clear coat, a sheen.
                x[3][1] = (g.u64() % 8) as u32;
                // The GGX albedo (E, E_avg) the compensation reads: none, or a table's range.
                let drawn = (g.range(0.3, 1.0), g.range(0.37, 1.0));
                let (e, e_avg) = g.pick(&[(1.0, 1.0), (0.3, 0.37), drawn]);
                x[3][2] = e.to_bits();
                x[3][3] = e_avg.to_bits();
                x
            }
            function::TRIANGLE_LIGHT => {
                let size = g.scale();
                let p0 = size * g.vec();
                let (e1, e2) = (size * g.vec(), size * g.vec());
                // Receivers near (large solid angles, up to a hemisphere), at a few sizes and
                // far (area sampling's range), in the triangle's plane, and anywhere.
                let centroid = p0 + (e1 + e2) / 3.0;
                let x = match g.u64() % 4 {
                    0 => centroid + size * g.range(1e-3, 0.1) * g.dir(),
                    1 => centroid + size * g.range(0.5, 3.0) * g.dir(),
                    2 => centroid + size * g.range(10.0, 1e3) * g.dir(),
                    _ => p0 + g.range(-1.0, 2.0) * e1 + g.range(-1.0, 2.0) * e2,
                };
                let mode = g.pick(&[
                    kernel::scene::light_sampling::AREA,
                    kernel::scene::light_sampling::SOLID_ANGLE,
                    kernel::scene::light_sampling::SOLID_ANGLE,
                ]);
                let mut r = rec([w(x, 0.0), w(p0, g.unit()), w(e1, g.unit()), w(e2, 0.0)]);
                r[0][3] = mode;
                r[3][3] = (g.u64() % 2) as u32;
                r
            }
            function::TEXTURE => {
                // Coordinates inside, on the edges, far outside and between texel centres;
                // sizes from one texel to 4096.
                let size = |g: &mut Gen| g.pick(&[1.0, 2.0, 3.0, 7.0, 64.0, 1000.0, 4096.0]) as u32;
                let coordinate = |g: &mut Gen| {
                    let (x, u) = (g.range(-3.0, 4.0), g.unit());
                    g.pick(&[x, u, 0.0, 1.0, -1.0, 0.5, 1e-7, 1.0 - 1e-7, 1e6 * x])
                };
                let (width, height) = (size(g), size(g));
                let mut r = rec([
                    [coordinate(g), coordinate(g), 0.0, 0.0],
                    [0.0; 4],
                    [0.0; 4],
                    [0.0; 4],
                ]);
                r[0][2] = width;
                r[0][3] = height;
                r[1][0] = (g.u64() % 3) as u32;
                r[1][1] = (g.u64() % 3) as u32;
                r[2] = [0; 4].map(|_| g.u64() as u32);
                r
            }
            function::MAPPED_NORMAL => {
                // Unit base normals; tangents of any length and angle to it (near-parallel
                // ones included); texels over the byte range, scales from 0 to 4.
                let n = g.dir();
                let length = g.pick(&[1.0, 0.01, 100.0]);
                let t = (g.dir() + n * g.range(-2.0, 2.0)) * length;
                let texel = Vec3::new(g.unit(), g.unit(), g.unit());
                let any = g.range(0.0, 4.0);
                let scale = g.pick(&[1.0, 0.0, 0.5, 2.0, 4.0, any]);
                let sign = g.pick(&[1.0, -1.0]);
                let (u, v) = (g.unit(), g.unit());
                rec([
                    w(n, scale),
                    w(t, sign),
                    w(texel, u * 0.5),
                    [v * 0.5, 0.0, 0.0, 0.0],
                ])
            }
            function::PUNCTUAL_LIGHT => g.punctual_record().to_probe(),
            function::MEDIUM => {
                // Phase: any g in (-1, 1) (isotropic below 1e-3 included), unit directions.
                // Flights: coefficients over four decades, a channel of 0 at times, surfaces
                // near and far and none (f32::MAX).
                let g_any = g.range(-0.99, 0.99);
                let gg = g.pick(&[0.0, 5e-4, -0.9, 0.9, g_any]);
                let coefficient = |g: &mut Gen| {
                    let any = 10f32.powf(g.range(-2.0, 2.0));
                    g.pick(&[0.0, 1.0, any])
                };
                let sigma_s = Vec3::new(coefficient(g), coefficient(g), coefficient(g));
                let sigma_a = Vec3::new(g.unit(), g.unit(), g.unit()) * g.pick(&[0.0, 1.0]);
                let near = 10f32.powf(g.range(-2.0, 2.0));
                let d = g.pick(&[f32::MAX, near]);
                rec([
                    w(g.dir(), gg),
                    w(g.dir(), g.unit()),
                    w(sigma_s + sigma_a, g.unit()),
                    w(sigma_s, d),
                ])
            }
            function::ENVIRONMENT => g.environment_record().to_probe(),
            _ => unreachable!(),
        })
        .collect()
}

/// Distance in units in the last place between two floats (0 when the bits are equal or both
/// are NaN; u32::MAX when only one is NaN).
fn ulps(a: f32, b: f32) -> u32 {
    if a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()) {
        return 0;
    }
    if a.is_nan() || b.is_nan() {
        return u32::MAX;
    }
    let ord = |x: f32| {
        let i = x.to_bits() as i32;
        if i < 0 {
            i32::MIN.wrapping_sub(i) as i64
        } else {
            i as i64
        }
    };
    (ord(a) - ord(b)).unsigned_abs().min(u32::MAX as u64) as u32
}

/// Whether a probe record's outputs are ill-conditioned in its inputs.
type IsIllConditioned = fn(&[[u32; 4]; 4]) -> bool;

/// How closely a function's outputs must agree, and why.
struct Bound {
    name: &'static str,
    func: u32,
    /// A component passes if within `max_ulps` or within `abs` absolutely.
    max_ulps: u32,
    abs: f32,
    /// Output components that are hit distances: a hit on one side and a miss on the other
    /// (t < 0) is a "flip", allowed for at most this fraction of records.
    flip_fraction: f64,
    /// Records whose outputs are ill-conditioned in their inputs (a rounding difference in an
    /// intermediate moves them far), and the relative difference allowed there instead.
    ill_conditioned: Option<(IsIllConditioned, f32)>,
    /// Whether this is the bound of a device that is not IEEE (`vulkan_class`).
    vulkan: bool,
    why: &'static str,
}

/// The bound on the error of a medium probe record's drawn distance -ln(1 - u) / sigma_h under
/// Vulkan's `log` (see `allowed_abs`; 0 where the hero does not attenuate), and the largest
/// extinction coefficient. (A flight that reaches the surface has t = d on both sides.)
fn medium_flight_error(r: &[[u32; 4]; 4]) -> (f64, f64) {
    let f = |i: usize, j: usize| f32::from_bits(r[i][j]) as f64;
    let sigma = [f(2, 0), f(2, 1), f(2, 2)];
    let sigma_max = sigma.iter().copied().fold(0.0, f64::max);
    let hero = ((f(1, 3) * 3.0) as usize).min(2);
    if sigma[hero] <= 0.0 {
        return (0.0, sigma_max);
    }
    let ln = (1.0 - f(2, 3)).ln();
    let dt = (2f64.powi(-21) + 3.0 * f32::EPSILON as f64 * ln.abs()) / sigma[hero];
    (dt, sigma_max)
}

/// The largest exponent sigma_k t of a medium probe record's flight (t recomputed in f64).
fn medium_exponent(r: &[[u32; 4]; 4]) -> f64 {
    let f = |i: usize, j: usize| f32::from_bits(r[i][j]) as f64;
    let sigma = [f(2, 0), f(2, 1), f(2, 2)];
    let hero = ((f(1, 3) * 3.0) as usize).min(2);
    let d = f(3, 3);
    let t = if sigma[hero] > 0.0 {
        (-(1.0 - f(2, 3)).ln() / sigma[hero]).min(d)
    } else {
        d
    };
    sigma.iter().map(|s| s * t).fold(0.0, f64::max)
}

/// The microfacet and BSDF probes' ill-conditioned records: roughness below 0.01 (a lobe a
/// thousandth of a radian wide: its density moves with the last bits of the half vector), and
/// refraction with |eta - 1| < 1e-3 (the generalised half vector wo + eta wi nearly vanishes).
fn sharp_or_index_matched(r: &[[u32; 4]; 4]) -> bool {
    let alpha = f32::from_bits(r[0][3]);
    let eta = f32::from_bits(r[1][3]);
    alpha < 0.01
        || (r[3][0] == kernel::scene::material_kind::DIELECTRIC && (eta - 1.0).abs() < 1e-3)
}

/// A record of `bsdf::sample` whose drawn direction is ill-conditioned: the sampler's stretch by
/// alpha magnifies the rounding of `wo` by 1 / alpha, and the density, read on a lobe alpha
/// wide, moves by about 4 eps / alpha^2 relative: beyond 2048 ULP below alpha = sqrt(4 / 2048)
/// = 0.044 (a glTF material's clear coat, drawn with probability up to 0.8 in the probe, lies
/// there as often as its base); or an index-matched dielectric.
fn sharply_sampled_or_index_matched(r: &[[u32; 4]; 4]) -> bool {
    f32::from_bits(r[0][3]) < 0.045 || sharp_or_index_matched(r)
}

const BOUNDS: &[Bound] = &[
    Bound { name: "rng (pcg4d, u32 -> float, scrambled Sobol)", func: function::RNG, max_ulps: 0, abs: 0.0, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "integer arithmetic: bit-exact" },
    Bound { name: "offset_ray_origin / shadow_ray_end", func: function::OFFSET_RAY_ORIGIN, max_ulps: 1, abs: 0.0, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "integer ULP steps are exact; p + s n may be fused into one FMA on the GPU: 1 ULP" },
    Bound { name: "orthonormal_basis", func: function::ORTHONORMAL_BASIS, max_ulps: 4, abs: 4.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "a few multiply-adds (FMA contraction): 4 ULP, or 4 eps absolute near zero" },
    Bound { name: "sample_lobe", func: function::SAMPLE_LOBE, max_ulps: 8, abs: 8.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "cos_sin_turns of phi / (2 pi) on both sides, the sine and the frame (FMA contraction): 8 eps absolute on unit vectors" },
    Bound { name: "sample_sphere", func: function::SAMPLE_SPHERE, max_ulps: 4, abs: 4.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "cos_sin_turns' polynomials under FMA contraction: normals 4 eps, positions 4 eps x (|centre| + radius)" },
    Bound { name: "sample_sphere_cone", func: function::SAMPLE_SPHERE_CONE, max_ulps: 4, abs: 4.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "cos_sin_turns and dot products under FMA contraction: pdf 4 ULP, normals 4 eps, positions 4 eps x (|centre| + radius)" },
    Bound { name: "geometry_factor", func: function::GEOMETRY_FACTOR, max_ulps: 8, abs: 0.0, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "dot products (FMA contraction): 8 ULP" },
    Bound { name: "intersect_sphere (+ re-projection)", func: function::INTERSECT_SPHERE, max_ulps: 64, abs: 0.0, flip_fraction: 1e-3, ill_conditioned: None, vulkan: false, why: "sqrt and FMA contraction; hit/miss may flip for rays within rounding of tangent or of the origin's surface" },
    Bound { name: "intersect_triangle (t, u, v, point, error bound)", func: function::INTERSECT_TRIANGLE, max_ulps: 64, abs: 4.0 * f32::EPSILON, flip_fraction: 1e-3, ill_conditioned: None, vulkan: false, why: "cross/dot products under FMA contraction: 64 ULP, u and v 4 eps, points 4 eps x (|p0| + |e1| + |e2|); hit/miss may flip for rays within rounding of an edge" },
    Bound { name: "eval_scattering / pdf_brdf / sample_brdf", func: function::BRDF, max_ulps: 8, abs: 8.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "cos_sin_turns and sqrt in sampling (FMA contraction): 8 eps absolute on unit vectors and pdfs <= 1/pi" },
    Bound { name: "fresnel (conductor, dielectric, schlick)", func: function::FRESNEL, max_ulps: 8, abs: 8.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "reflectances <= 1 with cancelling terms (FMA contraction): 8 ULP, or 8 eps absolute" },
    Bound { name: "microfacet (visible normal, D, G1, pdf)", func: function::MICROFACET, max_ulps: 64, abs: 64.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: Some((sharp_or_index_matched, 1e-2)), vulkan: false, why: "square roots and normalisations (FMA contraction): 64 ULP or 64 eps; alpha < 0.01: 1% relative" },
    Bound { name: "bsdf::eval", func: function::BSDF_EVAL, max_ulps: 64, abs: 64.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: Some((sharp_or_index_matched, 1e-2)), vulkan: false, why: "D, G1, Fresnel and the refraction Jacobian (FMA contraction): 64 ULP or 64 eps; alpha < 0.01 or |eta - 1| < 1e-3: 1% relative" },
    Bound { name: "bsdf::sample", func: function::BSDF_SAMPLE, max_ulps: 2048, abs: 64.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: Some((sharply_sampled_or_index_matched, 5e-2)), vulkan: false, why: "the visible-normal sampler, Fresnel choice and pdf (FMA contraction); weights of grazing directions carry G1 ~ n . wi, whose rounding moves them relatively (measured 648 ULP): 2048 ULP or 64 eps; alpha < 0.045 or |eta - 1| < 1e-3: the sampler's stretch by alpha magnifies the rounding of wo by up to 1/alpha, and the density is read at the sampled wi on a lobe alpha wide (4 eps / alpha^2 relative, 3354 ULP measured at alpha 0.016 under a clear coat), down to a thousandth of a radian (measured 2.6% where a 0.9-metallic glTF material picks the sharp lobe 9 times in 10): 5% relative" },
    Bound { name: "sample_triangle_light / solid_angle", func: function::TRIANGLE_LIGHT, max_ulps: 64, abs: 64.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "atan2_turns, normalisations and the ray/plane step (FMA contraction): 64 eps relative to the solid angle, density and geometry size, divided by h, the receiver's elevation above the light's plane (all are 0 / 0 in it); normals 64 eps" },
    Bound { name: "texture footprint and bilerp", func: function::TEXTURE, max_ulps: 0, abs: 0.0, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "the same texels and weights bit for bit: wrapping, clamping and the blend" },
    Bound { name: "phase::sample / eval, free_flight::sample", func: function::MEDIUM, max_ulps: 8, abs: 8.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "the phase sampler's azimuth (cos_sin_turns' polynomials), its factored sine, sqrt and normalisation (FMA contraction): 8 eps on a unit vector; its density a rational function of one dot product, 8 ULP; a flight's t = -ln(1 - u) / sigma under Vulkan's log (2^-21 absolute on [0.5, 2]) and its weights, quotients of exponentials (3 + 2 |x| ULP) whose exponents carry t's error, denormals flushed: derived per record in `allowed_abs`" },
    Bound { name: "surface::mapped_normal", func: function::MAPPED_NORMAL, max_ulps: 8, abs: 16.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "a blend, one Gram-Schmidt step, a cross product and two normalisations of unit-scale vectors (FMA contraction, sqrt): 16 eps on a unit vector" },
    Bound { name: "punctual and directional light samples", func: function::PUNCTUAL_LIGHT, max_ulps: 8, abs: 8.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "a difference, a dot product, a root and a quotient (FMA contraction): 8 eps on the unit normal, 8 ULP on the density; the spot's falloff a multiply-add clamped and squared, 8 eps times (1 + |scale| + |offset|); the directional light's point 8 eps of |x| + 2 (radius + |x - centre|), per record (`allowed_abs`)" },
    Bound { name: "environment map sample and look-up", func: function::ENVIRONMENT, max_ulps: 8, abs: 8.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "the drawn direction: two quotients, cos_sin_turns' polynomials and the rotation (FMA contraction), 8 eps on a unit vector; the density (1 / sin theta, ill-conditioned at the bottom pole, where 1 - v is a few eps) and the look-up (u, v, sin theta and the texel: a direction within rounding of the seam or of a texel's edge may read either side), by balls per record (`environment_apart`, whose Vulkan model holds FMA contraction)" },
    Bound { name: "plane_side::ray_leaves_triangle_plane", func: function::PLANE_SIDE, max_ulps: 0, abs: 0.0, flip_fraction: 1e-3, ill_conditioned: None, vulkan: false, why: "a sure answer (1) from either side is held to the exact one (f64): never wrong on any device; the two may differ only where one is sure and the other within its bound (FMA contraction), counted as flips" },
    Bound { name: "camera_ray_direction", func: function::CAMERA_RAY, max_ulps: 8, abs: 8.0 * f32::EPSILON, flip_fraction: 0.0, ill_conditioned: None, vulkan: false, why: "multiply-adds and a normalisation (FMA contraction, sqrt): 8 eps on unit vectors" },
];

/// The BSDF probe's record `r` of function `func` (`kernel::probe`'s layout).
fn bsdf_record(func: u32, r: &[[u32; 4]; 4]) -> twinpath_tests::device_class::BsdfRecord {
    let f = |i: usize, j: usize| f32::from_bits(r[i][j]);
    let v = |i: usize| [f(i, 0), f(i, 1), f(i, 2)];
    twinpath_tests::device_class::BsdfRecord {
        sample: func == function::BSDF_SAMPLE,
        kind: r[3][0],
        complex: r[3][1],
        coat: r[2][3],
        n: v(0),
        alpha: f(0, 3),
        wo: v(1),
        eta: f(1, 3),
        third: v(2),
        albedo: (f(3, 2), f(3, 3)),
    }
}

/// Whether the exact ray of a `PLANE_SIDE` record leaves its triangle's plane (decided in
/// `f64`; `false` where `f64` cannot decide, far inside any bound an `f32` answer is sure
/// beyond).
fn plane_side_is_right(r: &[[u32; 4]; 4]) -> bool {
    let f = |i: usize, j: usize| f32::from_bits(r[i][j]);
    let v = |i: usize| Vec3::new(f(i, 0), f(i, 1), f(i, 2));
    let e2 = Vec3::new(f(0, 3), f(1, 3), f(2, 3));
    twinpath_tests::plane_side::exact(v(0), v(1), v(2), v(3), e2).is_some_and(|x| x.leaves())
}

/// The absolute error allowed for output component (k, j) of record `r` under bound `b`, whose
/// larger magnitude on the two sides is `value`: unit vectors and pdfs take `b.abs`; positions on a sphere take `b.abs`
/// times the size of the geometry (|centre| + radius), since a unit-vector error scales with it.
fn allowed_abs(b: &Bound, r: &[[u32; 4]; 4], k: usize, j: usize, value: f32) -> f32 {
    let f = |i: usize, j: usize| f32::from_bits(r[i][j]);
    match b.func {
        // Triangle lights: the solid angle (its triple product), the density (its cosine at
        // the light, or the solid angle) and the point (where a direction meets the plane) are
        // proportional to, or divided by, h, the sine of the receiver's elevation above the
        // triangle's plane, which the rounding of x - p0 moves by a few eps: relative error
        // b.abs / h (points relative to the size of the geometry, |x| + |p0| + |e1| + |e2|). In
        // the plane (h within rounding) they are 0 / 0, and a two-sided light's normal may face
        // either way.
        function::TRIANGLE_LIGHT if b.vulkan => triangle_light_apart(b, r, k, j, value),
        function::TRIANGLE_LIGHT => triangle_light_ieee_class(b, r, k, j, value),
        // Triangle points (out1.xyz): relative to |p0| + |e1| + |e2|.
        function::INTERSECT_TRIANGLE if k == 1 && j < 3 => {
            let p0 = glam::Vec3::new(f(2, 0), f(2, 1), f(2, 2));
            let e1 = glam::Vec3::new(f(3, 0), f(3, 1), f(3, 2));
            let e2 = glam::Vec3::new(f(1, 3), f(2, 3), f(3, 3));
            b.abs * (p0.length() + e1.length() + e2.length())
        }
        // The Vulkan class's microfacet functions, per record (`microfacet_apart`): out0 =
        // (visible normal, D), out1 = (G1, the reflected density, 0, 0).
        function::MICROFACET if b.vulkan => {
            let v = |i: usize| [f(i, 0), f(i, 1), f(i, 2)];
            let apart = twinpath_tests::device_class::microfacet_apart(
                v(0),
                f(0, 3),
                v(1),
                (f(1, 3), f(2, 2)),
                (f(2, 0), f(2, 1)),
            );
            output_allowance(&apart, k, j)
        }
        // The Vulkan class's environment map, per record (`environment_apart`); the IEEE
        // class's density and look-up (out0.w, out1) by the same balls, since a contracted
        // rotation may move a direction on the seam (u = 0 or 1) or a texel's edge across it.
        function::ENVIRONMENT if b.vulkan || k == 1 || j == 3 => {
            output_allowance(&environment_apart(&EnvironmentRecord::from_probe(r)), k, j)
        }
        // The Vulkan class's punctual and directional lights, per record (`punctual_apart`).
        function::PUNCTUAL_LIGHT if b.vulkan => {
            output_allowance(&punctual_apart(&PunctualRecord::from_probe(r)), k, j)
        }
        // The IEEE class's: the falloff's magnitudes (out1.x), the far point's (out1.yzw).
        function::PUNCTUAL_LIGHT if k == 1 => {
            let r = PunctualRecord::from_probe(r);
            let length = |v: [f32; 3]| Vec3::from_array(v).length();
            if j == 0 {
                b.abs * (1.0 + r.spot.0.abs() + r.spot.1.abs())
            } else {
                let centre = [r.bounds[0], r.bounds[1], r.bounds[2]];
                let to_centre = Vec3::from_array(r.x) - Vec3::from_array(centre);
                b.abs * (length(r.x) + 2.0 * (r.bounds[3] + to_centre.length()))
            }
        }
        // The Vulkan class's BSDFs, per record (`bsdf_apart`): out0 = (f cos, pdf) or (wi,
        // pdf), out1 = (weight, eta2).
        function::BSDF_EVAL | function::BSDF_SAMPLE if b.vulkan => {
            output_allowance(&bsdf_apart(&bsdf_record(b.func, r)), k, j)
        }
        // The Vulkan class's intersections, per record (`sphere_hit_apart`,
        // `triangle_hit_apart`; the probe's layout: `kernel::probe`).
        function::INTERSECT_SPHERE if b.vulkan => {
            let v = |i: usize| [f(i, 0), f(i, 1), f(i, 2)];
            let apart = twinpath_tests::device_class::sphere_hit_apart(
                v(0),
                v(1),
                v(2),
                f(2, 3),
                f(3, 0),
                f(3, 1),
            );
            output_allowance(&apart, k, j)
        }
        function::INTERSECT_TRIANGLE if b.vulkan => {
            let v = |i: usize| [f(i, 0), f(i, 1), f(i, 2)];
            let e2 = [f(1, 3), f(2, 3), f(3, 3)];
            let apart = twinpath_tests::device_class::triangle_hit_apart(
                v(0),
                v(1),
                v(2),
                v(3),
                e2,
                f(0, 3),
            );
            output_allowance(&apart, k, j)
        }
        // The Vulkan class's texture footprint and blend, per record (`texture_apart`).
        function::TEXTURE if b.vulkan => {
            let apart = twinpath_tests::device_class::texture_apart(
                [f(0, 0), f(0, 1)],
                r[0][2],
                r[0][3],
                r[1][0],
                r[1][1],
            );
            output_allowance(&apart, k, j)
        }
        // The Vulkan class's mapped normal, per record (`mapped_normal_apart`).
        function::MAPPED_NORMAL if b.vulkan => {
            let v = |i: usize| [f(i, 0), f(i, 1), f(i, 2)];
            let apart = twinpath_tests::device_class::mapped_normal_apart(
                v(0),
                v(1),
                f(1, 3),
                (f(2, 3), f(3, 0)),
                v(2),
                f(0, 3),
            );
            output_allowance(&apart, k, j)
        }
        // The mapped normal: Gram-Schmidt leaves t's component across n, whose rounding is
        // eps |t| absolute, so relative to it b.abs |t| / |t - n (n . t)|.
        function::MAPPED_NORMAL => {
            let n = glam::Vec3::new(f(0, 0), f(0, 1), f(0, 2)).as_dvec3();
            let t = glam::Vec3::new(f(1, 0), f(1, 1), f(1, 2)).as_dvec3();
            let across = (t - n * n.dot(t)).length();
            (b.abs as f64 * (t.length() / across).max(1.0)) as f32
        }
        // A flight's weights (out1.yzw): exp(-x) moves by the absolute error of x relative, and
        // x = sigma_k t carries t's relative error (a logarithm, a division, a product: 3
        // eps); a weight is a quotient of two such, so (8 + 6 x) eps relative, x the record's
        // largest exponent up to 88 (beyond it every exponential is 0 or denormal on both).
        // A flight (out1): under Vulkan's precision rules ("Precision and Operation of SPIR-V
        // Instructions") `log` has an absolute error up to 2^-21 on [0.5, 2] (1 - u lies
        // there for u < 0.5), so t = -ln(1 - u) / sigma_h is off by up to (2^-21 + 3 eps
        // |ln(1 - u)|) / sigma_h (with the division), and each exponent x_k = sigma_k t by
        // sigma_k times that; `exp` is within 3 + 2 |x| ULP. A weight, a quotient of such
        // exponentials, is off relatively by 2 (max_k sigma_k dt + (3 + 2 x) eps) + 8 eps (x
        // the record's largest exponent, up to 88). Vulkan may also flush denormals: a
        // transmittance below 2^-126 read as 0 moves a weight sigma_s,c T_c / m by at most
        // sigma_s,c 2^-126 / m, and m >= sigma_h T_h / 3 >= 0.01 x 6e-8 / 3 (the hero's own
        // exponent is at most 17), sigma_s <= 100 here: 3e-25 absolute.
        function::MEDIUM if k == 1 => {
            let (dt, sigma_max) = medium_flight_error(r);
            if j == 0 {
                (dt + 2.0 * f32::EPSILON as f64 * value as f64) as f32
            } else {
                let x = medium_exponent(r).min(88.0);
                let eps = f32::EPSILON as f64;
                let rel = 2.0 * (sigma_max * dt + (3.0 + 2.0 * x) * eps) + 8.0 * eps;
                ((value as f64 * rel) as f32).max(3e-25)
            }
        }
        // The Vulkan class's phase function (out0.w), per record (`phase_density_apart`).
        function::MEDIUM if b.vulkan && k == 0 && j == 3 => {
            let v = |i: usize| [f(i, 0), f(i, 1), f(i, 2)];
            let apart = twinpath_tests::device_class::phase_density_apart(f(0, 3), v(0), v(1));
            rounded_up(apart)
        }
        // The phase function's density near its peak: 1 + g^2 - 2 g cos cancels, and the cosine
        // (a dot product, 2 eps absolute) moves it by 4 g eps: relative error 1.5 x 4 g eps /
        // (1 + g^2 - 2 g cos), beside 8 eps of the rest.
        function::MEDIUM if k == 0 && j == 3 => {
            let v = |i: usize| glam::Vec3::new(f(i, 0), f(i, 1), f(i, 2)).as_dvec3();
            let g = f(0, 3) as f64;
            let denom = 1.0 + g * g - 2.0 * g * (-v(1).dot(v(0)));
            value * ((8.0 + 6.0 * g.abs() / denom) * f32::EPSILON as f64) as f32
        }
        // The Vulkan class's camera direction, per record (`camera_direction_apart`).
        function::CAMERA_RAY if b.vulkan => {
            let v = |i: usize| [f(i, 0), f(i, 1), f(i, 2)];
            let size = (r[0][3] as f32, r[1][3] as f32);
            let pixel = (r[2][3] as f32, r[3][2] as f32);
            let offset = (f(3, 0), f(3, 1));
            twinpath_tests::device_class::camera_direction_apart(
                v(0),
                v(1),
                v(2),
                size,
                pixel,
                offset,
            ) as f32
        }
        // The Vulkan class's Fresnel reflectances, per record: the balls of the kernel's own
        // functions in IEEE and Vulkan arithmetic (`fresnel_apart`), out0 = (conductor,
        // dielectric F, cos_t, Schlick r), out1 = (Schlick g, b, 0, 0).
        function::FRESNEL if b.vulkan => {
            let (input, f0) = ([f(0, 0), f(0, 1), f(0, 2)], [f(1, 0), f(1, 1), f(1, 2)]);
            let apart =
                twinpath_tests::device_class::fresnel_apart(input[0], input[1], input[2], f0);
            output_allowance(&apart, k, j)
        }
        // The Vulkan class's cosine sample (out1.xyz) and its density (out1.w), per record
        // (`cosine_sample_apart` of u1 = in3.x); eval_scattering and pdf_brdf keep 8 eps.
        function::BRDF if b.vulkan && k == 1 => {
            let (direction, density) = twinpath_tests::device_class::cosine_sample_apart(f(3, 0));
            (if j < 3 { direction } else { density }) as f32
        }
        // The Vulkan class's uniform sphere points (out0.xyz) and normals (out1.xyz), and the
        // seed lobe's direction (out0.xyz), per record.
        function::SAMPLE_SPHERE if b.vulkan && j < 3 => {
            let c = [f(0, 0), f(0, 1), f(0, 2)];
            let (normal, position) = twinpath_tests::device_class::sphere_points_apart(c, f(0, 3));
            (if k == 0 { position } else { normal }) as f32
        }
        function::SAMPLE_LOBE if b.vulkan && k == 0 && j < 3 => {
            twinpath_tests::device_class::lobe_directions_apart(f(1, 1)) as f32
        }
        // The Vulkan class's phase-sampled direction (out0.xyz of the medium's record).
        function::MEDIUM if b.vulkan && k == 0 && j < 3 => {
            twinpath_tests::device_class::phase_directions_apart() as f32
        }
        // The Vulkan class's geometry factor, per record: 12 eps / |d|^2 + 21 eps G.
        function::GEOMETRY_FACTOR if b.vulkan => {
            let d = glam::Vec3::new(f(0, 0), f(0, 1), f(0, 2)).as_dvec3()
                - glam::Vec3::new(f(2, 0), f(2, 1), f(2, 2)).as_dvec3();
            twinpath_tests::device_class::geometry_factor_apart(d.length_squared(), value as f64)
                as f32
        }
        // The Vulkan class's cone points (out0.xyz) and normals (out1.xyz), per record
        // (`cone_points_apart`), and its density (out0.w, `cone_density_apart`).
        function::SAMPLE_SPHERE_CONE if b.vulkan => {
            let v = |i: usize| [f(i, 0), f(i, 1), f(i, 2)];
            if k == 0 && j == 3 {
                let (u1, u2) = (f(2, 0), f(2, 1));
                return rounded_up(twinpath_tests::device_class::cone_density_apart(
                    v(0),
                    f(0, 3),
                    v(1),
                    u1,
                    u2,
                ));
            }
            let (normal, position) =
                twinpath_tests::device_class::cone_points_apart(v(0), f(0, 3), v(1));
            (if k == 0 { position } else { normal }) as f32
        }
        function::SAMPLE_SPHERE | function::SAMPLE_SPHERE_CONE if k == 0 && j < 3 => {
            let c = glam::Vec3::new(f(0, 0), f(0, 1), f(0, 2));
            b.abs * (c.length() + f(0, 3))
        }
        _ => b.abs,
    }
}

/// A per-output bound of `device_class` as the allowance of output component (k, j): the
/// outputs numbered through out0 then out1 (4 k + j), those beyond `apart` 0 (both sides write
/// 0 there).
fn output_allowance(apart: &[f64], k: usize, j: usize) -> f32 {
    apart.get(4 * k + j).map_or(0.0, |&a| rounded_up(a))
}

/// `x` rounded up to an `f32` (by a millionth: more than an `f32`'s rounding).
fn rounded_up(x: f64) -> f32 {
    (x * (1.0 + 1e-6)) as f32
}

/// A triangle light record's allowance on an IEEE device (`allowed_abs`'s comment): b.abs / h
/// relative for the solid angle and the density, of the geometry's size for points; normals
/// b.abs (either way in the plane).
fn triangle_light_ieee_class(b: &Bound, r: &[[u32; 4]; 4], k: usize, j: usize, value: f32) -> f32 {
    let f = |i: usize, j: usize| f32::from_bits(r[i][j]);
    let v = |i: usize| glam::Vec3::new(f(i, 0), f(i, 1), f(i, 2));
    let h = triangle_light_elevation(r);
    if h == 0.0 {
        return triangle_light_in_plane(b, r, k, j, twinpath_tests::device_class::IEEE_ROUNDOFF);
    }
    if j == 3 {
        b.abs * value / h
    } else if k == 0 {
        // Points, where the sampled direction meets the plane at the angle h.
        b.abs * (v(0).length() + v(1).length() + v(2).length() + v(3).length()) / h
    } else if h > b.abs {
        b.abs
    } else {
        2.0
    }
}

/// h, the sine of a triangle light record's receiver's elevation above the light's plane
/// (computed in `f32`: 0 where the receiver was placed in the plane).
fn triangle_light_elevation(r: &[[u32; 4]; 4]) -> f32 {
    let f = |i: usize, j: usize| f32::from_bits(r[i][j]);
    let v = |i: usize| glam::Vec3::new(f(i, 0), f(i, 1), f(i, 2));
    let to_x = v(0) - v(1);
    to_x.dot(v(2).cross(v(3)).normalize()).abs() / to_x.length()
}

/// A triangle light record's allowance where the receiver lies in the light's plane (h = 0),
/// for an IEEE computation and one in the arithmetic `other` (its (u, q, w)): there the
/// light's small-triangle estimate is 0 in exact arithmetic and certainly below its threshold
/// in both (`estimate_decision`, else any value), so both sample by area, whose points do not
/// depend on h (b.abs of the geometry's size, as `triangle_point`'s); the density is 0 on both,
/// the height above the plane at the point being rounding far inside `within_plane_rounding`'s
/// fourfold bound; the solid angle is all rounding of the triple product, apart by the two
/// computations' absolute errors (`solid_angle_apart_absolute`); a two-sided light's normal may
/// face either way.
fn triangle_light_in_plane(
    b: &Bound,
    r: &[[u32; 4]; 4],
    k: usize,
    j: usize,
    other: (f64, f64, f64),
) -> f32 {
    let f = |i: usize, j: usize| f32::from_bits(r[i][j]);
    let v = |i: usize| glam::Vec3::new(f(i, 0), f(i, 1), f(i, 2));
    let (x, p0, e1, e2) = (v(0), v(1), v(2), v(3));
    match (k, j) {
        (1, 3) => {
            let a = |v: glam::Vec3| v.to_array();
            twinpath_tests::spherical_triangle_error::solid_angle_apart_absolute(
                a(x),
                a(p0),
                a(e1),
                a(e2),
                other,
            ) as f32
        }
        (1, _) => 2.0,
        _ if estimate_decision(x, p0, e1, e2) != Some(false) => f32::INFINITY,
        (0, 3) => 0.0,
        _ => b.abs * (x.length() + p0.length() + e1.length() + e2.length()),
    }
}

/// A triangle light record's allowance on a device that is not IEEE: the IEEE-class terms
/// (the plane step, the normal) plus, per record, the spherical sampler's direction bounds
/// carried to the point and the solid angle's bounds under both arithmetics
/// (`spherical_sample_apart`, checked against the models in `vulkan_precision.rs`). Where the
/// two computations may take different vertices as A (a tie of two arcs within rounding) the
/// sample is another point of the same distribution: any point of the light is allowed.
fn triangle_light_apart(b: &Bound, r: &[[u32; 4]; 4], k: usize, j: usize, value: f32) -> f32 {
    use twinpath_tests::spherical_triangle_error::{
        sampled_decision, solid_angle_apart, spherical_sample_apart,
    };
    let ieee_class = triangle_light_ieee_class(b, r, k, j, value);
    let f = |i: usize, j: usize| f32::from_bits(r[i][j]);
    let v = |i: usize| glam::Vec3::new(f(i, 0), f(i, 1), f(i, 2));
    let (x, p0, e1, e2) = (v(0), v(1), v(2), v(3));
    let a = |v: glam::Vec3| v.to_array();
    if triangle_light_elevation(r) == 0.0 {
        return triangle_light_in_plane(b, r, k, j, twinpath_tests::device_class::VULKAN_ROUNDOFF);
    }
    if k == 1 && j == 3 {
        let relative = solid_angle_apart(a(x), a(p0), a(e1), a(e2));
        return ieee_class + (value as f64 * relative) as f32;
    }
    if k == 1 && j < 3 {
        return ieee_class;
    }
    let light = kernel::probe::probe_triangle_light(p0, e1, e2, r[3][3]);
    let mode = r[0][3];
    // The light's decision is the estimate's and the view's together (a conjunction).
    let decisions = [
        estimate_decision(x, p0, e1, e2),
        sampled_decision(a(x), a(p0), a(e1), a(e2)),
    ];
    if mode == kernel::scene::light_sampling::SOLID_ANGLE
        && !decisions.contains(&Some(false))
        && decisions.contains(&None)
    {
        // The device may sample by area where the CPU samples the spherical triangle, or the
        // other way: another point of the light, another density.
        return f32::INFINITY;
    }
    if kernel::light::triangle::spherical_triangle_used(&light, mode, x).is_none() {
        return ieee_class;
    }
    let apart = spherical_sample_apart(a(x), a(p0), a(e1), a(e2), (f(1, 3), f(2, 3)));
    if apart.order_may_differ {
        f32::INFINITY
    } else if j == 3 {
        ieee_class + (value as f64 * apart.solid_angle_relative) as f32
    } else {
        ieee_class + apart.point as f32
    }
}

/// Whether `light::triangle::spherical_triangle_used`'s cheap estimate of the solid angle,
/// |n . (x - c)| / (2 d^3) with c the centroid and d = |x - c|, reaches its threshold in two
/// computations alike (`Some`), or lies within their rounding of it (`None`): x - c is off by
/// about 2 eps (|x| + |c|) in any direction, which moves n . (x - c) by that over h (the sine
/// of x's elevation above the plane) relative to it; the cross product, the length, its cube
/// and the quotients add a few eps each. 16 eps (1 + (|x| + |c|) / d) / h per computation, two
/// computations.
fn estimate_decision(
    x: glam::Vec3,
    p0: glam::Vec3,
    e1: glam::Vec3,
    e2: glam::Vec3,
) -> Option<bool> {
    let (x, p0, e1, e2) = (x.as_dvec3(), p0.as_dvec3(), e1.as_dvec3(), e2.as_dvec3());
    let c = p0 + (e1 + e2) / 3.0;
    let to_x = x - c;
    let d = to_x.length();
    let n = e1.cross(e2);
    let estimate = 0.5 * n.dot(to_x).abs() / (d * d * d);
    let threshold = kernel::light::triangle::SPHERICAL_SAMPLING_MIN_ESTIMATE as f64;
    // The relative error over h times the estimate, 0.5 |n| h / d^2: finite in the plane.
    let relative_times_h = 2.0 * 16.0 * f32::EPSILON as f64 * (1.0 + (x.length() + c.length()) / d);
    if (estimate - threshold).abs() <= 0.5 * n.length() / (d * d) * relative_times_h {
        None
    } else {
        Some(estimate >= threshold)
    }
}

/// Whether probe record `r` of an intersection function is a ray within the rounding of both
/// computations of a triangle's edge or a sphere's tangent or a t limit (the probe's layout:
/// `kernel::probe`).
fn hit_may_flip(func: u32, r: &[[u32; 4]; 4]) -> bool {
    use twinpath_tests::device_class::{sphere_hit_may_flip, triangle_hit_may_flip};
    let f = |i: usize, j: usize| f32::from_bits(r[i][j]);
    let v = |i: usize| [f(i, 0), f(i, 1), f(i, 2)];
    if func == function::INTERSECT_SPHERE {
        sphere_hit_may_flip(v(0), v(1), v(2), f(2, 3), f(3, 0), f(3, 1))
    } else {
        let e2 = [f(1, 3), f(2, 3), f(3, 3)];
        triangle_hit_may_flip(v(0), v(1), v(2), v(3), e2, 0.0, f(0, 3))
    }
}

/// The bound of a function on a device whose arithmetic is not IEEE's, where one has been
/// derived for any conformant Vulkan device (`docs/robustness.md`, "Under Vulkan's
/// arithmetic"; checked against a model of such a device in `vulkan_precision.rs`, which gives
/// 2.25 eps for the basis where the NVIDIA H200 gave 0.75 eps, cone points within 0.62 of
/// their bound, and the geometry factor within a fifth of its bound where the H200 was 3711
/// ULP off). The other functions keep the IEEE-class bound on every device until theirs is
/// derived.
fn vulkan_class(b: &Bound) -> Option<Bound> {
    let eps = f32::EPSILON;
    match b.func {
        function::ORTHONORMAL_BASIS => Some(Bound {
            max_ulps: 0,
            abs: twinpath_tests::device_class::BASIS_APART_EPS * eps,
            vulkan: true,
            why: "Vulkan class: a sum, a quotient within 2.5 ULP and products, rounded either way: 6.5 eps per component on a device, 2.5 on the CPU: 9 eps absolute",
            ..*b
        }),
        function::INTERSECT_SPHERE => Some(Bound {
            max_ulps: 0,
            vulkan: true,
            why: "Vulkan class: the kernel's sphere test and re-projection run on balls in IEEE and in Vulkan arithmetic, every way their tests may go (near a tangent the discriminant's conditioning; a root within rounding of a limit, as from an origin on the sphere, may be taken or not: the other root is among the ways), per record (`sphere_hit_apart`); hit/miss may flip only within rounding of a tangent or a limit (`hit_may_flip`)",
            ..*b
        }),
        function::INTERSECT_TRIANGLE => Some(Bound {
            max_ulps: 0,
            vulkan: true,
            why: "Vulkan class: Moller-Trumbore, the hit point and its error bound run on balls in IEEE and in Vulkan arithmetic, every way their tests may go, per record (`triangle_hit_apart`); hit/miss may flip only within rounding of an edge or a limit (`hit_may_flip`)",
            ..*b
        }),
        function::TEXTURE => Some(Bound {
            vulkan: true,
            why: "Vulkan class: the wrapped coordinate (two roundings), x = u n - 1/2 and fx = x - floor(x): u (4 n + 1/2) per computation; the blend Lipschitz in x and y (2 max|c|) with 9 u max|c| of its own roundings; an axis's indices and fx unchecked where x is within that of a texel boundary (the same blend by the next pair: the probe's image has a value per texel), per record (`texture_apart`)",
            ..*b
        }),
        function::SAMPLE_SPHERE_CONE => Some(Bound {
            max_ulps: 0,
            abs: 4.0 * eps,
            vulkan: true,
            why: "Vulkan class: the axis, its frame, sin and cos of alpha (cancellation-free), the cone's extent and the azimuth, every rounding of one IEEE and one Vulkan computation: ~106 eps plus 6 eps of tan(theta_max) for normals, times the radius plus 1.5 eps (|c| + 2 r) for points, per record (`allowed_abs`); the density the kernel's sampler run on balls in IEEE and in Vulkan arithmetic, which carries the receiver's conditioning near the sphere (`cone_density_apart`)",
            ..*b
        }),
        function::SAMPLE_SPHERE => Some(Bound {
            max_ulps: 0,
            vulkan: true,
            why: "Vulkan class: the latitude's radius (a product and a root) and cos_sin_turns' polynomials, for one IEEE and one Vulkan computation: 13.25 eps for normals, times the radius plus 1.5 eps (|c| + 2 r) for points, per record (`allowed_abs`)",
            ..*b
        }),
        function::SAMPLE_LOBE => Some(Bound {
            max_ulps: 0,
            vulkan: true,
            why: "Vulkan class: the sine sqrt((1 - c)(1 + c)), phi / (2 pi) and cos_sin_turns, the frame, products and sums, for one IEEE and one Vulkan computation: 28.25 + 1.5 |phi| eps per component, per record (`allowed_abs`)",
            ..*b
        }),
        function::MEDIUM => Some(Bound {
            vulkan: true,
            why: "Vulkan class: the phase direction's factored sine and mu (quotients within 2.5 ULP, a root), the frame, the azimuth's polynomials and the normalisation, for one IEEE and one Vulkan computation: 92.5 eps per component (`phase_directions_apart`); its density by balls in both arithmetics (`phase_density_apart`) and the flights as derived per record for any device (`allowed_abs`)",
            ..*b
        }),
        function::GEOMETRY_FACTOR => Some(Bound {
            max_ulps: 0,
            abs: 0.0,
            vulkan: true,
            why: "Vulkan class: cosines off by 4 u |d|, (d . d)^2 by 11 u, a quotient within 2.5 ULP: 12 eps / |d|^2 + 21 eps G apart from the CPU, per record (`allowed_abs`)",
            ..*b
        }),
        function::MICROFACET => Some(Bound {
            max_ulps: 0,
            abs: 0.0,
            ill_conditioned: None,
            vulkan: true,
            why: "Vulkan class: the kernel's visible-normal sampler, D, G1 and reflected density run on balls in IEEE and in Vulkan arithmetic (the azimuth within cos_sin_turns' four roundings), every way their tests may go; the largest distance between the two, per record (`microfacet_apart`), which carries a smooth lobe's conditioning; a density over n . wo within rounding of 0 is unbounded",
            ..*b
        }),
        function::MAPPED_NORMAL => Some(Bound {
            max_ulps: 0,
            abs: 0.0,
            vulkan: true,
            why: "Vulkan class: the kernel's mapped normal (a blend, one Gram-Schmidt step, a cross product, two normalisations and their tests) run on balls in IEEE and in Vulkan arithmetic, every way its tests may go; the largest distance between the two, per record (`mapped_normal_apart`)",
            ..*b
        }),
        function::ENVIRONMENT => Some(Bound {
            max_ulps: 0,
            abs: 0.0,
            vulkan: true,
            why: "Vulkan class: the kernel's environment-map sampler within a texel (two quotients within 2.5 ULP, cos_sin_turns, the rotation) and its density, and the look-up (the rotation, a root, atan2_turns, the conversions to a texel), run on balls in IEEE and in Vulkan arithmetic, every way their tests and conversions may go, per record (`environment_apart`), which carries 1 / sin theta near the poles and the texel's either side of an edge",
            ..*b
        }),
        function::PUNCTUAL_LIGHT => Some(Bound {
            max_ulps: 0,
            abs: 0.0,
            vulkan: true,
            why: "Vulkan class: the kernel's point and spot light sample (a difference, a dot product, a root within 4.5 eps, a quotient within 2.5 ULP) and falloff, and the directional light's point, run on balls in IEEE and in Vulkan arithmetic, every way their tests may go, per record (`punctual_apart`), which carries the falloff's slope",
            ..*b
        }),
        function::BSDF_EVAL | function::BSDF_SAMPLE => Some(Bound {
            max_ulps: 0,
            abs: 0.0,
            ill_conditioned: None,
            vulkan: true,
            why: "Vulkan class: the kernel's bsdf::eval_v3 / sample_v3 (every kind and lobe, the glTF material's resolution and the probe's albedos) run on balls in IEEE and in Vulkan arithmetic, every way their tests may go (a lobe choice within rounding of its threshold takes either lobe); the largest distance between the two, per record (`bsdf_apart`), which carries each lobe's conditioning; unbounded (unchecked) where a ball is",
            ..*b
        }),
        function::FRESNEL => Some(Bound {
            max_ulps: 0,
            abs: 0.0,
            vulkan: true,
            why: "Vulkan class: the kernel's conductor, dielectric and Schlick functions run on balls (midpoint-radius intervals) in IEEE and in Vulkan arithmetic, every way their comparisons may go; the largest distance between the two, per record (`fresnel_apart`)",
            ..*b
        }),
        function::BRDF => Some(Bound {
            vulkan: true,
            why: "Vulkan class: eval_scattering and pdf_brdf a dot product, a product and the albedo: 8 eps; the cosine sample from the frame (9 eps), sqrt(u1), sqrt(1 - u1), the azimuth's polynomials and four roundings: eps (33 s + 11.1 c) per component, its density 21 eps (`allowed_abs`)",
            ..*b
        }),
        function::TRIANGLE_LIGHT => Some(Bound {
            vulkan: true,
            why: "Vulkan class: the IEEE-class terms (the plane step, 64 eps over h; normals 64 eps) plus, where the light is sampled as a spherical triangle, the sampled direction's bounds under both arithmetics carried to the point (t delta / |cos|, times 2 / sin(theta_min) for the clamp onto the triangle) and the solid angle's for the density and the solid angle, per record (`allowed_abs`); any point where the two may take another vertex as A, or decide otherwise between area and spherical sampling (a threshold within both computations' rounding)",
            ..*b
        }),
        function::CAMERA_RAY => Some(Bound {
            max_ulps: 0,
            abs: 0.0,
            vulkan: true,
            why: "Vulkan class: the image-plane position (a sum, a quotient within 2.5 ULP, a difference), the direction's multiply-adds and its normalisation (a root within 4.6 eps): per record, eps ([10.5 (|right| + |up|) + 4.5 S] / |v| + 11.85) (`allowed_abs`)",
            ..*b
        }),
        _ => None,
    }
}

#[test]
fn kernel_functions_agree_between_cpu_and_gpu() {
    let ctx = context().lock().unwrap();
    // Device classes: lavapipe computes with LLVM's IEEE arithmetic, as the CPU does; any other
    // device is held to the bounds derived for Vulkan's arithmetic where they exist.
    let ieee_device = twinpath_tests::gpu::is_ieee_device(&ctx);
    functions_agree(&ctx, ieee_device);
}

/// An IEEE device (lavapipe) is held to the Vulkan class's bounds too: they are wider, so it
/// must meet them, and so every CI run exercises what only a real GPU's run would otherwise
/// reach (the per-record bounds by balls, the rounding bands of hit/miss flips, the records
/// left unchecked). On a Vulkan-class device the first test already does this.
#[test]
fn an_ieee_device_meets_the_vulkan_class_bounds_too() {
    let ctx = context().lock().unwrap();
    if twinpath_tests::gpu::is_ieee_device(&ctx) {
        functions_agree(&ctx, false);
    }
}

/// Runs every probe function on the CPU and on `ctx`'s device and holds their differences to
/// the IEEE class's bounds (`ieee_device`) or to the Vulkan class's where one is derived.
fn functions_agree(ctx: &twinpath::vulkan::device::Context, ieee_device: bool) {
    let runner = ProbeRunner::new(ctx).unwrap();
    println!(
        "device {}: held to the {} class",
        ctx.device_name,
        if ieee_device { "IEEE" } else { "Vulkan" }
    );
    assert_eq!(
        BOUNDS.len() as u32,
        function::COUNT,
        "every probe function has a bound"
    );
    let mut failures = Vec::new();
    for b in BOUNDS {
        let vulkan_bound = vulkan_class(b).filter(|_| !ieee_device);
        let b = vulkan_bound.as_ref().unwrap_or(b);
        let mut g = Gen(twinpath_tests::SplitMix(0x5eed_0000 + b.func as u64));
        let input = inputs(b.func, &mut g);
        let gpu = runner.run(ctx, b.func, &input).unwrap();
        let (mut max_ulps, mut max_abs, mut max_rel_scale) = (0u32, 0f32, 0f32);
        let (mut flips, mut bad, mut unexplained_flips) = (0usize, 0usize, 0usize);
        let mut bad_records = std::collections::HashSet::new();
        let mut loose_records = std::collections::HashSet::new();
        // Records a bound leaves unchecked (any value allowed: another sample of the same
        // distribution), counted so that a run says how many.
        let mut unchecked_records = std::collections::HashSet::new();
        let mut max_loose = 0f32;
        // The largest difference as a fraction of the bound it is held to, so that a run on a
        // new device says how close it came.
        let (mut max_fraction, mut max_fraction_at) = (0f32, (0, 0));
        for (r, g_out) in input.iter().zip(&gpu) {
            let c_out = evaluate(b.func, r.map(glam::UVec4::from_array)).map(|v| v.to_array());
            let is_t = matches!(
                b.func,
                function::INTERSECT_SPHERE | function::INTERSECT_TRIANGLE
            );
            if b.func == function::PLANE_SIDE {
                let (sure_c, sure_g) =
                    (c_out[0][0] == 1f32.to_bits(), g_out[0][0] == 1f32.to_bits());
                if sure_c != sure_g {
                    flips += 1;
                }
                // Either side's sure answer must be the exact one (`kernel::plane_side`'s bounds
                // hold on any conformant device).
                if (sure_c || sure_g) && !plane_side_is_right(r) {
                    bad += 1;
                    unexplained_flips += 1;
                    bad_records.insert(*r);
                }
                continue;
            }
            if is_t {
                let (tc, tg) = (f32::from_bits(c_out[0][0]), f32::from_bits(g_out[0][0]));
                if (tc >= 0.0) != (tg >= 0.0) {
                    flips += 1;
                    // A device that is not IEEE may flip only rays within the rounding of an
                    // edge, a tangent or a limit (derived in `device_class`).
                    if !ieee_device && !hit_may_flip(b.func, r) {
                        bad += 1;
                        unexplained_flips += 1;
                        bad_records.insert(*r);
                    }
                    continue;
                }
            }
            for k in 0..2 {
                for j in 0..4 {
                    let (x, y) = (f32::from_bits(c_out[k][j]), f32::from_bits(g_out[k][j]));
                    let u = ulps(x, y);
                    let d = (x - y).abs();
                    max_ulps = max_ulps.max(u);
                    if d.is_finite() {
                        max_abs = max_abs.max(d);
                    }
                    let allowed = allowed_abs(b, r, k, j, x.abs().max(y.abs()));
                    if allowed == f32::INFINITY {
                        unchecked_records.insert(*r);
                    }
                    if allowed.is_finite()
                        && allowed > 0.0
                        && d.is_finite()
                        && u > b.max_ulps
                        && d / allowed > max_fraction
                    {
                        (max_fraction, max_fraction_at) = (d / allowed, (k, j));
                    }
                    if allowed > b.abs && d.is_finite() && j < 3 {
                        max_rel_scale = max_rel_scale.max(d / (allowed / b.abs));
                    }
                    let loose = b
                        .ill_conditioned
                        .filter(|(is, _)| is(r))
                        .map(|(_, rel)| rel);
                    let ok = allowed == f32::INFINITY
                        || u <= b.max_ulps
                        || d <= allowed
                        || loose.is_some_and(|rel| d <= rel * x.abs().max(y.abs()));
                    if loose.is_some() && !(u <= b.max_ulps || d <= allowed) {
                        max_loose = max_loose.max(d / x.abs().max(y.abs()));
                        loose_records.insert(*r);
                    }
                    if !ok {
                        bad += 1;
                        bad_records.insert(*r);
                        if bad <= 3 {
                            println!(
                                "  {}: record {:?}: cpu {x:e} gpu {y:e} ({u} ulp)",
                                b.name, r
                            );
                        }
                    }
                }
            }
        }
        let flip_frac = flips as f64 / N as f64;
        println!(
            "{:<42} max {:>10} ulp, max abs {:.3e}{}, {:.2} of the bound (out{}.{}), hit/miss flips {flips} / {N} ({unexplained_flips} outside the rounding bands), {} records out of bound, {} ill-conditioned beyond it (max relative difference {:.1e}){}; bound: {}",
            b.name,
            max_ulps,
            max_abs,
            if max_rel_scale > 0.0 {
                format!(" (positions: max {:.2e} x geometry size)", max_rel_scale)
            } else {
                String::new()
            },
            max_fraction,
            max_fraction_at.0,
            ["x", "y", "z", "w"][max_fraction_at.1],
            bad_records.len(),
            loose_records.len(),
            max_loose,
            if unchecked_records.is_empty() {
                String::new()
            } else {
                format!(", {} records unchecked", unchecked_records.len())
            },
            b.why
        );
        if bad > 0 || (ieee_device && flip_frac > b.flip_fraction) {
            failures.push(format!(
                "{}: {bad} components out of bound, {flips} flips",
                b.name
            ));
        }
    }
    runner.destroy(ctx);
    assert_validation_clean();
    assert!(failures.is_empty(), "{failures:#?}");
}
