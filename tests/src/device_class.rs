//! How far a conformant Vulkan device's results may be from the CPU's, function by function:
//! the bounds of the device classes of `gpu_functions.rs` (lavapipe, IEEE like the CPU, is held
//! to tighter ones there). Each is derived for a pair of computations, one IEEE (unit roundoff
//! eps / 2, quotients and roots correctly rounded) and one under Vulkan's precision rules
//! (eps, quotients within 2.5 ULP, roots as 1 / inversesqrt), in the comment of the test that
//! checks it against the model of such a device (`tests/tests/vulkan_precision.rs`, on
//! [`crate::vulkan_arithmetic::Vk32`]), and collected in `docs/robustness.md`; or, for the
//! Fresnel, microfacet, phase and mapped-normal functions, the BSDFs, the punctual lights, the
//! environment map, the cone's density and the intersection probes, by running the kernel's own code on [`crate::ball_arithmetic::Ball`]s
//! in both arithmetics.

use crate::ball_arithmetic::{ieee_and_vulkan_apart, Ball};
use kernel::real::{Real, V3};

/// How far apart the CPU's and a conformant Vulkan device's `orthonormal_basis` may be, per
/// component, in eps (derived in `tests/tests/vulkan_precision.rs`; used by `gpu_functions.rs`
/// for devices that are not IEEE).
pub const BASIS_APART_EPS: f32 = 9.0;

/// (unit roundoff u, quotient error q, root error w) of a computation in IEEE-754 single
/// precision, relative: eps / 2 each (correctly rounded).
pub const IEEE_ROUNDOFF: (f64, f64, f64) = (0.5 * EPS, 0.5 * EPS, 0.5 * EPS);
/// The same under Vulkan's precision rules: u = eps (rounding toward zero allowed), quotients
/// within 2.5 ULP, roots as 1 / inversesqrt within 4.5 eps.
pub const VULKAN_ROUNDOFF: (f64, f64, f64) = (EPS, 2.5 * EPS, 4.5 * EPS);

const EPS: f64 = f32::EPSILON as f64;

/// How far apart one IEEE and one Vulkan computation may be, for a first-order `error` bound of
/// one computation given its (u, q, w): the sum of the two.
fn apart(error: impl Fn((f64, f64, f64)) -> f64) -> f64 {
    error(IEEE_ROUNDOFF) + error(VULKAN_ROUNDOFF)
}

/// First-order error of one computation of `kernel::sampling::sample_sphere_cone_v3`'s normal
/// (and of its point, in radii), for unit roundoff `u`, quotient error `q` and root error `w`,
/// every rounding aligned, where `sin_over_cos` is tan(theta_max) of the cone:
///
/// - the axis (c - p) / |c - p|: the difference u, |.|^2 5 u so its root 2.5 u + w, the
///   quotient q: a = 3.5 u + w + q, in direction and length;
/// - the frame of that axis: its own error 4 u + q (`BASIS_APART_EPS`'s derivation), and it
///   follows the axis with a Lipschitz constant below 2.3 (t.x = 1 + s x^2 a with |x a| <= 1
///   and |x^2 a^2| <= 1): 4 u + q + 2.3 a;
/// - sin(alpha) and cos(alpha), sums and products of non-negative terms: cos(beta) 4 u + q in
///   its square and w, sin(alpha) 7 u + 1.5 q + 2 w, and the other one's root of 1 - x^2
///   (x <= 1 / sqrt 2) adds u + w: 8 u + 1.5 q + 3 w;
/// - sin^2(theta_max) = r^2 / d^2 is off by 6 u + q relative (r^2, |c - p|^2, the quotient): it
///   moves theta by theta / 2 of that (at most 0.8 of it; beta does not move to first order),
///   and cos(theta_max) = sqrt(1 - sin^2) by sin^2 (6 u + q) / (2 cos), which turns the point at
///   the rim by that over sin(theta_max): (6 u + q) / 2 x tan(theta_max). This is the input's
///   conditioning (a receiver a gap g of the radius outside sees tan ~ 1 / sqrt(2 g)), which no
///   form of the sampler removes;
/// - the azimuth's cosine and sine 4 u, the normal's three products and two sums 4 u.
pub fn cone_normal_error(u: f64, q: f64, w: f64, sin_over_cos: f64) -> f64 {
    let axis = 3.5 * u + w + q;
    let frame = 4.0 * u + q + 2.3 * axis;
    let alpha = 8.0 * u + 1.5 * q + 3.0 * w;
    let cone = 0.8 * (6.0 * u + q) + 0.5 * (6.0 * u + q) * sin_over_cos;
    axis + frame + alpha + cone + 8.0 * u
}

/// How far apart the CPU's and a conformant device's `sample_sphere_cone` may be for the sphere
/// (`center`, `radius`) seen from `p`: (normals, positions per component), the sum of
/// [`cone_normal_error`] for an IEEE and a Vulkan computation (eps 24.6 and 81.2 plus 1.75 and
/// 4.25 of tan(theta_max)); a position c + r n adds r times that and its own roundings,
/// u (|c| + 2 r) per computation.
pub fn cone_points_apart(center: [f32; 3], radius: f32, p: [f32; 3]) -> (f64, f64) {
    let (c, r) = (d3(center), radius as f64);
    let sin2_max = (r * r / (c - d3(p)).length_squared()).min(1.0);
    let tan_max = (sin2_max / (1.0 - sin2_max)).sqrt();
    let normal = apart(|(u, q, w)| cone_normal_error(u, q, w, tan_max));
    let position = normal * r + APART_U * (c.abs().max_element() + 2.0 * r);
    (normal, position)
}

/// How far apart the CPU's and a conformant device's `sample_sphere_cone` densities may be for
/// the sphere (`center`, `radius`) seen from `p` (numbers `u1`, `u2`): the kernel's sampler run
/// on [`crate::ball_arithmetic::Ball`]s in IEEE and in Vulkan arithmetic. The density 1 / (2 pi
/// (1 - cos theta_max)) carries the receiver's conditioning near the sphere: sin^2(theta_max) =
/// r^2 / d^2 is off by a few eps relative, and cos(theta_max) = sqrt(1 - sin^2) moves by that
/// over 2 cos, so the density's relative error grows as 1 / (2 cos theta_max) there (to sqrt of
/// the rounding where the receiver is within rounding of the surface); the balls carry it.
pub fn cone_density_apart(center: [f32; 3], radius: f32, p: [f32; 3], u1: f32, u2: f32) -> f64 {
    let b = Ball::exact;
    let v = Ball::exact_v3;
    ieee_and_vulkan_apart(&|| {
        let s = kernel::sampling::sample_sphere_cone_v3(v(center), b(radius), v(p), b(u1), b(u2));
        [s.pdf_solid_angle]
    })[0]
}

/// First-order error of one computation of `kernel::phase::sample_v3`'s unit direction, per
/// component, for unit roundoff `u`, quotient error `q` and root error `w`, every rounding
/// aligned: 1 - g and 1 + g u each; d = (1 - g)(1 - u1) + (1 + g) u1 3 u; s = (1 - g)(1 + g) / d
/// 6 u + q; 1 - mu and 1 + mu (a product of three factors over d) 13 u + 2 q each; the sine
/// their product's root, 13.5 u + 2 q + w; mu = 1 - x (x <= 1) 14 u + 2 q absolute; the frame
/// 4 u + q, the azimuth's polynomials 4 u, t cos + b sin and its product with the sine 24.5 u
/// + 3 q + w; with travel mu and the sum 40.5 u + 5 q + w; the normalisation 2.5 u + q + w.
pub fn phase_direction_error(u: f64, q: f64, w: f64) -> f64 {
    43.0 * u + 6.0 * q + 2.0 * w
}

/// How far apart the CPU's and a conformant device's phase-sampled directions may be, per
/// component: [`phase_direction_error`] for one IEEE and one Vulkan computation (25.5 and 67
/// eps).
pub fn phase_directions_apart() -> f64 {
    apart(|(u, q, w)| phase_direction_error(u, q, w))
}

/// First-order error of one computation of `kernel::sampling::sample_sphere_v3`'s unit normal,
/// per component, for unit roundoff `u` and root error `w`: z = 2 u1 - 1 and 1 - u1 are exact
/// (u1 = (k + 1/2) 2^-23); the latitude's radius 2 sqrt(u1 (1 - u1)) u / 2 + w relative;
/// `cos_sin_turns` 4 u absolute (its reduction exact, its polynomials' roundings); their
/// product u: 5.5 u + w.
pub fn sphere_normal_error(u: f64, w: f64) -> f64 {
    5.5 * u + w
}

/// How far apart the CPU's and a conformant device's `sample_sphere` may be for the sphere
/// (`center`, `radius`): (normals, positions per component), [`sphere_normal_error`] for one
/// IEEE and one Vulkan computation (3.25 and 10 eps); a position c + r n adds r times that and
/// its own roundings, u (|c| + 2 r) per computation.
pub fn sphere_points_apart(center: [f32; 3], radius: f32) -> (f64, f64) {
    let normal = apart(|(u, _, w)| sphere_normal_error(u, w));
    let c = d3(center).abs().max_element();
    let r = radius as f64;
    (normal, normal * r + APART_U * (c + 2.0 * r))
}

/// First-order error of one computation of `kernel::sampling::sample_lobe_v3`'s direction, per
/// component, for unit roundoff `u`, quotient error `q`, root error `w` and azimuth `phi`: the
/// sine sqrt((1 - c)(1 + c)) 1.5 u + w; the azimuth phi / (2 pi) rounded (|phi| u in angle,
/// beside the constant's rounding, which every device shares) and `cos_sin_turns` 4 u; the
/// frame 4 u + q; the products and sums 4 u: 13.5 u + q + w + |phi| u.
pub fn lobe_direction_error(u: f64, q: f64, w: f64, phi: f64) -> f64 {
    13.5 * u + q + w + phi.abs() * u
}

/// How far apart the CPU's and a conformant device's `sample_lobe` may be at azimuth `phi`, per
/// component: [`lobe_direction_error`] for one IEEE and one Vulkan computation
/// (28.25 + 1.5 |phi| eps).
pub fn lobe_directions_apart(phi: f32) -> f64 {
    apart(|(u, q, w)| lobe_direction_error(u, q, w, phi as f64))
}

/// How far apart the CPU's and a conformant device's `geometry_factor` G = |(n_a . d)(n_b . d)|
/// / (d . d)^2 may be, for points |d|^2 = `d2` apart (derived in
/// `tests/tests/vulkan_precision.rs`): 12 eps / |d|^2 + 21 eps G.
pub fn geometry_factor_apart(d2: f64, g: f64) -> f64 {
    f32::EPSILON as f64 * (12.0 / d2 + 21.0 * g)
}

/// The roundoff of one IEEE and one Vulkan computation added: u (eps / 2 and eps) and a
/// quotient's relative error (eps / 2 and 2.5 eps). A quantity computed by both is apart by at
/// most its error bound with these.
const APART_U: f64 = IEEE_ROUNDOFF.0 + VULKAN_ROUNDOFF.0;
const APART_Q: f64 = IEEE_ROUNDOFF.1 + VULKAN_ROUNDOFF.1;

fn d3(v: [f32; 3]) -> glam::DVec3 {
    glam::Vec3::from_array(v).as_dvec3()
}

/// Whether `kernel::intersect::triangle` (Moller-Trumbore) of this ray may say hit on one device
/// and miss on another: a barycentric, their sum, or t within rounding of its limit, or the
/// determinant within rounding of 0. Exact values in `f64` from the `f32` inputs; error bounds
/// of each computation (u its unit roundoff, q its quotient's error): the cross products within
/// 3 u |a||b| (and tvec's own rounding u), so U = tvec . pvec within 7 u |tvec||d||e2|, V = d .
/// qvec within 7 u |d||tvec||e1|, T = e2 . qvec within 7 u |e2||tvec||e1|, det within 6 u
/// |e1||d||e2|; a barycentric X / det within (dX + |X / det| d(det)) / |det| + (q + u) |X / det|.
pub fn triangle_hit_may_flip(
    origin: [f32; 3],
    dir: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    t_min: f32,
    t_max: f32,
) -> bool {
    let (o, d, p0, e1, e2) = (d3(origin), d3(dir), d3(p0), d3(e1), d3(e2));
    let (u, q) = (APART_U, APART_Q);
    let pvec = d.cross(e2);
    let det = e1.dot(pvec);
    let tvec = o - p0;
    let qvec = tvec.cross(e1);
    let (nd, ne1, ne2, nt) = (d.length(), e1.length(), e2.length(), tvec.length());
    let d_det = 6.0 * u * ne1 * nd * ne2;
    if det.abs() <= d_det {
        return true;
    }
    let quotient = |x: f64, dx: f64| {
        let value = x / det;
        (
            value,
            (dx + value.abs() * d_det) / det.abs() + (q + u) * value.abs(),
        )
    };
    let (bu, du) = quotient(tvec.dot(pvec), 7.0 * u * nt * nd * ne2);
    let (bv, dv) = quotient(d.dot(qvec), 7.0 * u * nd * nt * ne1);
    let (t, dt) = quotient(e2.dot(qvec), 7.0 * u * ne2 * nt * ne1);
    let dsum = du + dv + u * (bu + bv).abs();
    bu.abs() <= du
        || (1.0 - bu).abs() <= du
        || bv.abs() <= dv
        || (1.0 - bu - bv).abs() <= dsum
        || (t - t_min as f64).abs() <= dt
        || (t_max as f64 - t).abs() <= dt
}

/// Whether `kernel::intersect::sphere` of this ray may say hit on one device and miss on
/// another: the ray within rounding of tangent, or a root within rounding of t_min or t_max.
/// Exact values in `f64`; error bounds of each computation: f = o - c within u |f|, the
/// perpendicular f - d (f . d) / (d . d) within 6 u |f| (a dot product, a quotient, a product
/// and a difference), so the margin r^2 - |perp|^2 within 2 r 6 u |f| + 4 u r^2 near tangency;
/// a root, at half = sqrt(margin / a) from the closest point, within 16 (u + q) (|f| + r) / |d|
/// (the stable quadratic: a square root and two quotients) plus the margin's error times
/// d(half)/d(margin) = 1 / (2 a half), which grows without bound toward tangency.
pub fn sphere_hit_may_flip(
    origin: [f32; 3],
    dir: [f32; 3],
    center: [f32; 3],
    radius: f32,
    t_min: f32,
    t_max: f32,
) -> bool {
    let (o, d, c, r) = (d3(origin), d3(dir), d3(center), radius as f64);
    let (u, q) = (APART_U, APART_Q);
    let f = o - c;
    let a = d.dot(d);
    let perp = f - d * (f.dot(d) / a);
    let margin = r * r - perp.length_squared();
    let d_margin = 12.0 * u * r * f.length() + 4.0 * u * r * r;
    if margin.abs() <= d_margin {
        return true;
    }
    if margin < 0.0 {
        return false;
    }
    // The roots along -/+ half, half = sqrt(margin / a): the margin's error moves half by
    // d_margin / (2 a half) (near tangency this dominates), the rest by 16 (u + q) of the sizes.
    let along = -f.dot(d) / a;
    let half = (margin / a).sqrt();
    let dt = 16.0 * (u + q) * (f.length() + r) / a.sqrt() + d_margin / (2.0 * a * half);
    [along - half, along + half]
        .iter()
        .any(|&t| (t - t_min as f64).abs() <= dt || (t_max as f64 - t).abs() <= dt)
}

/// How far apart the CPU's and a conformant device's `camera_ray_direction` may be, per
/// component, for camera axes `forward`, `right`, `up` and the position `offset` inside pixel
/// `pixel` of an image of `size` pixels (derived in `tests/tests/vulkan_precision.rs`): eps
/// ([10.5 (|right| + |up|) + 4.5 S] / |v| + 11.85), S = |forward| + |x||right| + |y||up|, with
/// (x, y) the image-plane position in [-1, 1] and v the unnormalised direction.
pub fn camera_direction_apart(
    forward: [f32; 3],
    right: [f32; 3],
    up: [f32; 3],
    size: (f32, f32),
    pixel: (f32, f32),
    offset: (f32, f32),
) -> f64 {
    let x = 2.0 * ((pixel.0 as f64 + offset.0 as f64) / size.0 as f64) - 1.0;
    let y = 1.0 - 2.0 * ((pixel.1 as f64 + offset.1 as f64) / size.1 as f64);
    let (f, r, u) = (d3(forward), d3(right), d3(up));
    let v = f + r * x + u * y;
    let s = f.length() + x.abs() * r.length() + y.abs() * u.length();
    f32::EPSILON as f64 * ((10.5 * (r.length() + u.length()) + 4.5 * s) / v.length() + 11.85)
}

/// How far apart the CPU's and a conformant device's cosine-sampled direction (per component)
/// and its density may be, for uniform number `u1` (c = sqrt(u1), s = sqrt(1 - u1); derived in
/// `tests/tests/vulkan_precision.rs`): eps (33 s + 11.1 c) and 21 eps.
pub fn cosine_sample_apart(u1: f32) -> (f64, f64) {
    let u1 = u1 as f64;
    let eps = f32::EPSILON as f64;
    (
        eps * (33.0 * (1.0 - u1).sqrt() + 11.1 * u1.sqrt()),
        21.0 * eps,
    )
}

/// How far apart the CPU's and a conformant device's Fresnel reflectances may be, for the
/// probe's record (cosine `cos`, index `eta`, extinction `k`, Schlick's `f0`): [conductor,
/// dielectric F, its cos_t, Schlick's three channels], each the largest distance between the
/// kernel's own functions run on [`crate::ball_arithmetic::Ball`]s in IEEE and in Vulkan
/// arithmetic (every way their comparisons may go: the clamp of the cosine, total internal
/// reflection). The balls carry each input's conditioning: the conductor's a^2 + b^2 and a are
/// roots of differences, the dielectric's cos_t a root that vanishes at the critical angle.
pub fn fresnel_apart(cos: f32, eta: f32, k: f32, f0: [f32; 3]) -> [f64; 6] {
    use kernel::bsdf::fresnel;
    let b = Ball::exact;
    ieee_and_vulkan_apart(&|| {
        let (f, cos_t) = fresnel::dielectric(b(cos), b(eta));
        let s = f0.map(|f0| fresnel::schlick_f90_channel(b(f0), b(1.0), b(cos)));
        [
            fresnel::conductor(b(cos), b(eta), b(k)),
            f,
            cos_t,
            s[0],
            s[1],
            s[2],
        ]
    })
}

/// How far apart the CPU's and a conformant device's normal-mapped normals may be, per
/// component, for the probe's record (unit `base` normal, one `tangent` at all three vertices,
/// handedness `sign`, barycentrics `bary`, `texel`, `scale`): the largest distance between
/// `kernel::surface::mapped_normal_v3` run on [`crate::ball_arithmetic::Ball`]s in IEEE and in
/// Vulkan arithmetic, every way its two tests (the tangent's and the result's direction) may
/// go. The tangent's component across the normal, t - n (n . t), cancels where they are nearly
/// parallel; the balls carry it, and where it may vanish the result is any unit vector (or the
/// base normal): apart by at most 2 per component, which caps the bound.
pub fn mapped_normal_apart(
    base: [f32; 3],
    tangent: [f32; 3],
    sign: f32,
    bary: (f32, f32),
    texel: [f32; 3],
    scale: f32,
) -> [f64; 3] {
    let b = Ball::exact;
    let v = Ball::exact_v3;
    ieee_and_vulkan_apart(&|| {
        let n = kernel::surface::mapped_normal_v3(
            v(base),
            [v(tangent); 3],
            b(sign),
            (b(bary.0), b(bary.1)),
            v(texel),
            b(scale),
        );
        [n.x, n.y, n.z]
    })
    .map(|apart| apart.min(UNIT_APART))
}

/// The most two unit vectors' components may differ by, with each vector's normalisation
/// rounded (a component of a computed unit vector is within a few eps of [-1, 1]).
const UNIT_APART: f64 = 2.0 + 64.0 * f32::EPSILON as f64;

/// How far apart the CPU's and a conformant device's microfacet functions may be, for the
/// probe's record (unit mean normal `n`, roughness `alpha`, unit `wo`, a normal's cosine `cos`
/// and sine squared `sin2`, numbers `u1`, `u2`): [the visible normal's three components, D,
/// G1, the reflected density], the largest distance between `kernel::bsdf::microfacet`'s
/// functions run on [`crate::ball_arithmetic::Ball`]s in IEEE and in Vulkan arithmetic (every
/// way their tests may go; the azimuth's cosine and sine within the four roundings
/// `cos_sin_turns` keeps to). The balls carry the lobe's own conditioning: the stretch by
/// alpha, D's (sin^2 + alpha^2 cos^2)^2 near the peak of a smooth lobe. The visible normal is a
/// unit vector: apart by at most 2 per component, which caps its bound.
pub fn microfacet_apart(
    n: [f32; 3],
    alpha: f32,
    wo: [f32; 3],
    (cos, sin2): (f32, f32),
    (u1, u2): (f32, f32),
) -> [f64; 6] {
    use kernel::bsdf::microfacet::{ggx_d, ggx_g1, pdf_reflected, sample_visible_normal_v3};
    let b = Ball::exact;
    let v = Ball::exact_v3;
    let mut apart = ieee_and_vulkan_apart(&|| {
        let h = sample_visible_normal_v3(v(n), v(wo), b(alpha), b(u1), b(u2));
        [
            h.x,
            h.y,
            h.z,
            ggx_d(b(cos), b(sin2), b(alpha)),
            ggx_g1(b(cos), b(alpha)),
            pdf_reflected(v(n).dot(v(wo)), (b(cos), b(sin2)), b(alpha)),
        ]
    });
    for a in &mut apart[..3] {
        *a = a.min(UNIT_APART);
    }
    apart
}

/// A probe record whose eight outputs the kernel's own code computes over any scalar [`Real`]
/// (the CPU's `f32`, a device model, balls).
pub trait ProbeOutputs {
    /// out0 then out1, as the probe writes them.
    fn outputs<R: Real<Bits = u32>>(&self) -> [R; 8];
}

/// A record of the BSDF probes (`kernel::probe::function::BSDF_EVAL`, `BSDF_SAMPLE`): the
/// material's kind, `complex` bits and packed clear coat (`kernel::probe::probe_bsdf_inputs`),
/// unit normal `n`, roughness `alpha`, unit `wo`, index ratio `eta`, `third` = wi (eval) or
/// (u_lobe, u1, u2) (sample), and the GGX albedos (E, E_avg)
/// (`kernel::probe::probe_glossy_albedo`).
#[derive(Clone, Copy, Debug)]
pub struct BsdfRecord {
    pub sample: bool,
    pub kind: u32,
    pub complex: u32,
    pub coat: u32,
    pub n: [f32; 3],
    pub alpha: f32,
    pub wo: [f32; 3],
    pub eta: f32,
    pub third: [f32; 3],
    pub albedo: (f32, f32),
}

/// The probe's outputs for this record, computed over any scalar [`Real`] by the kernel's own
/// code (the material's resolution and the albedos included): eval's (f cos, pdf, 0, 0, 0, 0),
/// or sample's (wi, pdf, weight, eta2).
impl ProbeOutputs for BsdfRecord {
    fn outputs<R: Real<Bits = u32>>(&self) -> [R; 8] {
        use kernel::bsdf::{eval_v3, sample_v3};
        use kernel::features::Dynamic;
        use kernel::probe::{probe_bsdf_inputs, probe_glossy_albedo};
        let m = probe_bsdf_inputs::<R>(self.kind, self.complex, self.alpha, self.eta, self.coat);
        let albedo = probe_glossy_albedo::<R>(self.albedo.0, self.albedo.1);
        let v = |x: [f32; 3]| V3::new(R::splat(x[0]), R::splat(x[1]), R::splat(x[2]));
        let (n, wo, eta) = (v(self.n), v(self.wo), R::splat(self.eta));
        let zero = R::splat(0.0);
        if self.sample {
            let u = (
                R::splat(self.third[0]),
                R::splat(self.third[1]),
                R::splat(self.third[2]),
            );
            let s = sample_v3(Dynamic(0), &m, n, wo, eta, albedo, u);
            [
                s.wi.x, s.wi.y, s.wi.z, s.pdf, s.weight.x, s.weight.y, s.weight.z, s.eta2,
            ]
        } else {
            let (f, pdf) = eval_v3(Dynamic(0), &m, n, wo, v(self.third), eta, albedo);
            [f.x, f.y, f.z, pdf, zero, zero, zero, zero]
        }
    }
}

/// How far apart the CPU's and a conformant device's `bsdf::eval` or `bsdf::sample` may be for
/// the probe's record `r`, per output (out0 then out1): the largest distance between the
/// kernel's own code run on [`crate::ball_arithmetic::Ball`]s in IEEE and in Vulkan arithmetic,
/// every way its tests may go (a lobe choice within rounding of its threshold takes either
/// lobe: the other sample is among the ways). The glTF material's resolution (its roughness
/// sqrt(alpha), Kd, Ks and alpha) and the probe's albedos are computed in the same arithmetic,
/// as a device computes them. The balls carry each lobe's conditioning (a sharp lobe's density,
/// the refraction's Jacobian near an index-matched interface); a sampled direction is a unit
/// vector, apart by at most 2 per component, which caps its bound; a delta lobe's density
/// (infinite in both) is not apart.
pub fn bsdf_apart(r: &BsdfRecord) -> [f64; 8] {
    let mut apart = ieee_and_vulkan_apart(&|| r.outputs::<Ball>());
    if r.sample {
        for a in &mut apart[..3] {
            *a = a.min(UNIT_APART);
        }
    }
    apart
}

/// A record of the punctual-light probe (`kernel::probe::function::PUNCTUAL_LIGHT`): receiver
/// `x`, selection probability `select_pmf`, the spot light's `position`, `axis` and spot
/// (scale, offset), and the bounding sphere (centre, radius) a directional light along `axis`
/// is placed beyond.
#[derive(Clone, Copy, Debug)]
pub struct PunctualRecord {
    pub x: [f32; 3],
    pub select_pmf: f32,
    pub position: [f32; 3],
    pub axis: [f32; 3],
    pub spot: (f32, f32),
    pub bounds: [f32; 4],
}

/// The probe's outputs computed over any scalar [`Real`] by the kernel's own code
/// (`light::punctual::direction_and_density`, `spot_attenuation_v3`,
/// `light::directional::far_point`): (normal, pdf, attenuation, the directional light's point).
impl ProbeOutputs for PunctualRecord {
    fn outputs<R: Real<Bits = u32>>(&self) -> [R; 8] {
        use kernel::light::{directional::far_point, punctual};
        let v = |x: [f32; 3]| V3::new(R::splat(x[0]), R::splat(x[1]), R::splat(x[2]));
        let axis = v(self.axis);
        let (normal, pdf) =
            punctual::direction_and_density(v(self.position), R::splat(self.select_pmf), v(self.x));
        let attenuation = punctual::spot_attenuation_v3(
            axis,
            R::splat(self.spot.0),
            R::splat(self.spot.1),
            normal,
        );
        let b = self.bounds;
        let far = far_point(axis, v([b[0], b[1], b[2]]), R::splat(b[3]), v(self.x));
        [
            normal.x,
            normal.y,
            normal.z,
            pdf,
            attenuation,
            far.x,
            far.y,
            far.z,
        ]
    }
}

/// How far apart the CPU's and a conformant device's punctual and directional light samples
/// may be for the probe's record `r`, per output (out0 then out1): the kernel's code run on
/// [`crate::ball_arithmetic::Ball`]s in IEEE and in Vulkan arithmetic, every way its tests may
/// go. The balls carry the spot's conditioning (the attenuation's cancellation where the
/// transition between the cones is narrow: its slope is the spot's scale) and the directional
/// light's point's magnitude (the receiver's distance plus twice the scene's bounding radius);
/// the normal is a unit vector, apart by at most 2 per component.
pub fn punctual_apart(r: &PunctualRecord) -> [f64; 8] {
    let mut apart = ieee_and_vulkan_apart(&|| r.outputs::<Ball>());
    for a in &mut apart[..3] {
        *a = a.min(UNIT_APART);
    }
    apart
}

/// How far apart the CPU's and a conformant device's phase function `kernel::phase::eval_v3`
/// may be, for asymmetry `g` and unit `wo`, `wi`: the largest distance between it run on
/// [`crate::ball_arithmetic::Ball`]s in IEEE and in Vulkan arithmetic (both ways of the
/// isotropic test of |g|). Near the peak of a strongly forward phase function 1 + g^2 - 2 g cos
/// cancels, and the density is its -3/2 power: the balls carry that.
pub fn phase_density_apart(g: f32, wo: [f32; 3], wi: [f32; 3]) -> f64 {
    let b = Ball::exact;
    let v = Ball::exact_v3;
    ieee_and_vulkan_apart(&|| [kernel::phase::eval_v3(b(g), v(wo), v(wi))])[0]
}

/// How far apart the CPU's and a conformant device's texture footprint and bilinear blend may
/// be (`kernel::texture::footprint` and `bilerp`, the probe's layout: coordinates `uv`, a
/// `width` x `height` image, wrap modes, texel values in [0, 1]): per output, (x0, x1, y0, y1,
/// the blend's three channels, fx), infinite for an axis's indices and fx where the texel
/// coordinate lies within both computations' rounding of a texel centre boundary (there the
/// floor may differ, and fx with it by 1: the same blend, by another pair of texels, since the
/// probe's image has a value per texel, `kernel::probe::probe_image`; when it gave its four
/// values per slot of the footprint, `vulkan_precision.rs`' `textures` found a device's
/// v = 0.10486576 on 596 rows taking rows 532 and 533 at weight 0.99994 against the CPU's 533
/// and 534 at 0, and so blending other values).
///
/// Along an axis of n texels: the wrapped coordinate (a difference and a fold) is off by at
/// most two roundings, 2 u; x = u' n - 1/2 (or (1 - v') n - 1/2) adds n times that, the product's
/// rounding u n and the difference's u (n + 1/2): x, and fx = x - floor(x) (exact), are off by
/// u (4 n + 1/2) per computation. The blend is Lipschitz in x and y with constant 2 max|c| (1
/// here; continuous across texel boundaries, the wrap included), and its roundings (the two
/// weights 1 - f, four products and two sums per level, two levels) are at most 9 u max|c|. A
/// fused multiply-add only removes roundings.
pub fn texture_apart(uv: [f32; 2], width: u32, height: u32, wrap_u: u32, wrap_v: u32) -> [f64; 8] {
    // x from the CPU's wrapped coordinate, which is within 2 u of the exact one: a boundary
    // nearer than both computations' error plus that may be crossed by either.
    let axis = |t: f32, n: u32, mode: u32, flipped: bool| {
        let unit = kernel::texture::unit_coordinate(t, mode) as f64;
        let n = n as f64;
        let x = if flipped { 1.0 - unit } else { unit } * n - 0.5;
        let dx = APART_U * (4.0 * n + 0.5);
        let f = x - x.floor();
        let at_boundary = f.min(1.0 - f) <= dx + 2.0 * IEEE_ROUNDOFF.0 * n;
        (dx, at_boundary)
    };
    let (dx, x_boundary) = axis(uv[0], width, wrap_u, false);
    let (dy, y_boundary) = axis(uv[1], height, wrap_v, true);
    let index = |boundary: bool| if boundary { f64::INFINITY } else { 0.0 };
    let blend = 9.0 * APART_U + 2.0 * (dx + dy);
    [
        index(x_boundary),
        index(x_boundary),
        index(y_boundary),
        index(y_boundary),
        blend,
        blend,
        blend,
        if x_boundary { f64::INFINITY } else { dx },
    ]
}

/// What `kernel::probe` computes for a ray against a sphere, over any [`Real`]: (t, the hit
/// re-projected onto the sphere), the point 0 on a miss (t < 0). On `f32` it is the probe's
/// result; on balls or on a model of a device, theirs.
pub fn sphere_probe<R: Real<Bits = u32>>(
    origin: V3<R>,
    dir: V3<R>,
    center: V3<R>,
    radius: R,
    t_min: R,
    t_max: R,
) -> [R; 4] {
    let t = kernel::intersect::sphere(origin, dir, center, radius, t_min, t_max);
    if t.at_least(R::splat(0.0)) != 0 {
        let p = kernel::geometry::reproject_to_sphere_v3(origin + dir * t, center, radius);
        [t, p.x, p.y, p.z]
    } else {
        [t, R::splat(0.0), R::splat(0.0), R::splat(0.0)]
    }
}

/// What `kernel::probe` computes for a ray against a triangle within (0, `t_max`), over any
/// [`Real`]: (t, u, v, the hit point's error bound, the hit point p0 + u e1 + v e2), all but t
/// 0 on a miss.
pub fn triangle_probe<R: Real<Bits = u32>>(
    origin: V3<R>,
    dir: V3<R>,
    p0: V3<R>,
    e1: V3<R>,
    e2: V3<R>,
    t_max: R,
) -> [R; 7] {
    let zero = R::splat(0.0);
    let (t, u, v) = kernel::intersect::triangle(origin, dir, p0, e1, e2, zero, t_max);
    if t.at_least(zero) != 0 {
        let condition = kernel::geometry::triangle_error_condition_v3(e1, e2);
        let scale = kernel::geometry::triangle_watertight_scale_v3(e1, e2);
        let error = kernel::geometry::triangle_point_error_v3(p0, e1, e2, u, v, condition, scale);
        let p = kernel::geometry::triangle_point_v3(p0, e1, e2, u, v);
        [t, u, v, error, p.x, p.y, p.z]
    } else {
        [t, zero, zero, zero, zero, zero, zero]
    }
}

/// How far apart the CPU's and a conformant device's [`sphere_probe`] may be for the ray
/// (`origin`, `dir`) and the sphere (`center`, `radius`) within (`t_min`, `t_max`): the probe
/// run on [`crate::ball_arithmetic::Ball`]s in IEEE and in Vulkan arithmetic, every way its
/// tests may go. The balls carry the discriminant's conditioning near a tangent; where a root
/// lies within rounding of a limit (an origin on the sphere) the ways include the other root
/// and a miss, so the two may rightly be a root apart there.
pub fn sphere_hit_apart(
    origin: [f32; 3],
    dir: [f32; 3],
    center: [f32; 3],
    radius: f32,
    t_min: f32,
    t_max: f32,
) -> [f64; 4] {
    let (b, v) = (Ball::exact, Ball::exact_v3);
    ieee_and_vulkan_apart(&|| {
        sphere_probe(v(origin), v(dir), v(center), b(radius), b(t_min), b(t_max))
    })
}

/// How far apart the CPU's and a conformant device's [`triangle_probe`] may be for the ray
/// (`origin`, `dir`) and the triangle (`p0`, `e1`, `e2`) within (0, `t_max`): the probe run on
/// [`crate::ball_arithmetic::Ball`]s in IEEE and in Vulkan arithmetic, every way its tests may
/// go (a ray within rounding of an edge or a limit may hit on one and miss on the other: the
/// miss's outputs are among the ways).
pub fn triangle_hit_apart(
    origin: [f32; 3],
    dir: [f32; 3],
    p0: [f32; 3],
    e1: [f32; 3],
    e2: [f32; 3],
    t_max: f32,
) -> [f64; 7] {
    let (b, v) = (Ball::exact, Ball::exact_v3);
    ieee_and_vulkan_apart(&|| triangle_probe(v(origin), v(dir), v(p0), v(e1), v(e2), b(t_max)))
}

/// A record of the environment-map probe (`kernel::probe::function::ENVIRONMENT`): the map's
/// rotation (cos, sin) about +y, the uniform numbers (u1, u2), the drawn row's marginal CDF
/// (r0, r1) and column's conditional CDF (c0, c1), a unit direction `d` to look up, and the
/// integers (width, height, row, column).
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentRecord {
    pub rotation: [f32; 2],
    pub u: (f32, f32),
    pub row_cdf: [f32; 2],
    pub column_cdf: [f32; 2],
    pub d: [f32; 3],
    pub size: (u32, u32),
    pub row: u32,
    pub column: u32,
}

/// The probe's outputs computed over any scalar [`Real`] by the kernel's own code
/// (`kernel::probe::probe_environment`): the direction and density drawn in the texel, and
/// `d`'s map coordinates and texel.
impl ProbeOutputs for EnvironmentRecord {
    fn outputs<R: Real<Bits = u32>>(&self) -> [R; 8] {
        use kernel::environment::{DrawnTexel, MapShape};
        let c = R::splat;
        let map = MapShape {
            rotation: self.rotation.map(c),
            width: self.size.0,
            height: self.size.1,
        };
        let drawn = DrawnTexel {
            row: self.row,
            row_cdf: self.row_cdf.map(c),
            u2: c(self.u.1),
            column: self.column,
            column_cdf: self.column_cdf.map(c),
            u1: c(self.u.0),
        };
        kernel::probe::probe_environment(
            map,
            drawn,
            V3::new(c(self.d[0]), c(self.d[1]), c(self.d[2])),
        )
    }
}

/// How far apart the CPU's and a conformant device's environment-map samples and look-ups may
/// be for the probe's record `r`, per output (out0 then out1): the kernel's code run on
/// [`crate::ball_arithmetic::Ball`]s in IEEE and in Vulkan arithmetic, every way its tests
/// and conversions may go. The balls carry the density's 1 / sin theta near the poles and the
/// texel a direction within rounding of a texel's edge may read on either side (its index
/// then apart by 1, or by the width across a row); the drawn direction is a unit vector, apart
/// by at most 2 per component.
pub fn environment_apart(r: &EnvironmentRecord) -> [f64; 8] {
    let mut apart = ieee_and_vulkan_apart(&|| r.outputs::<Ball>());
    for a in &mut apart[..3] {
        *a = a.min(UNIT_APART);
    }
    apart
}
