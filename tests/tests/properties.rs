//! Property tests of every kernel function (proptest), with generators that favour the edges:
//! unit vectors on and near the axes (including exactly -Z), grazing directions, denormals and
//! magnitudes from 1e-30 to 1e30, coincident points. 10^6 cases per property by default;
//! `TWINPATH_PROP_CASES=100000000 cargo test --test properties` is the long run.
//!
//! The cases are drawn from a fixed seed unless `TWINPATH_PROP_SEED` says otherwise (a number,
//! or `random` for a fresh seed, printed so that a failure can be replayed): the same commit
//! then passes or fails the same way in every CI run, while exploring runs look further.
//! Invariants: unit results stay unit (within 8 eps), cosines in [-1, 1], pdfs finite and
//! non-negative, samples inside their domain, no NaN or infinity out of finite input.

#![feature(portable_simd)]

use glam::Vec3;
use kernel::bsdf::lambert::{eval_scattering, pdf_brdf, sample_brdf};
use kernel::frame::orthonormal_basis;
use kernel::geometry::{
    area_to_solid_angle_pdf, geometry_factor, intersect_sphere, intersect_triangle,
    intersect_triangle_uv, offset_ray_origin, shadow_ray_end, sphere_point_error, triangle_offsets,
    triangle_point, triangle_point_error,
};
use kernel::light::triangle::{pdf as pdf_triangle_light, sample as sample_triangle_light};
use kernel::probe::probe_triangle_light;
use kernel::rng::{pcg4d, u32_to_unit_f32};
use kernel::sampling::{
    cone_one_minus_cos, pdf_sphere_cone, power_heuristic, sample_lobe, sample_sphere,
    sample_sphere_cone,
};
use kernel::scene::light_sampling;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::hash::BuildHasher;
use std::simd::f32x4;
use twinpath::cpu::internals::{Ray4, Spheres4, Triangles4};

/// The seed of the cases when `TWINPATH_PROP_SEED` is unset.
const DEFAULT_SEED: u64 = 0x7477_696e_7061_7468;

/// The cases' seed: `TWINPATH_PROP_SEED` as a number, a fresh one for `random` (printed), or
/// [`DEFAULT_SEED`]. Anything else is an error, not a silent fallback.
fn prop_seed() -> u64 {
    match std::env::var("TWINPATH_PROP_SEED") {
        Err(_) => DEFAULT_SEED,
        Ok(s) if s == "random" => {
            let seed = std::collections::hash_map::RandomState::new().hash_one(0u8);
            eprintln!("TWINPATH_PROP_SEED={seed} (replay a failure with this)");
            seed
        }
        Ok(s) => s
            .parse()
            .unwrap_or_else(|_| panic!("TWINPATH_PROP_SEED={s:?}: expected a u64 or `random`")),
    }
}

fn config() -> ProptestConfig {
    let cases = std::env::var("TWINPATH_PROP_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    ProptestConfig {
        cases,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(prop_seed()),
        ..ProptestConfig::default()
    }
}

const UNIT_TOL: f32 = 8.0 * f32::EPSILON;

/// Magnitudes 10^U(lo, hi) with either sign, plus exact zeros and denormals.
fn scalar(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    prop_oneof![
        8 => (lo..hi, any::<bool>()).prop_map(|(e, neg)| if neg { -(10f32.powf(e)) } else { 10f32.powf(e) }),
        1 => Just(0.0f32),
        1 => (1u32..0x0080_0000).prop_map(f32::from_bits), // denormals
    ]
}

/// Unit vectors: exactly on an axis, within 1e-7..1e-2 of one, or anywhere.
fn unit() -> impl Strategy<Value = Vec3> {
    let axes = prop_oneof![
        Just(Vec3::X),
        Just(-Vec3::X),
        Just(Vec3::Y),
        Just(-Vec3::Y),
        Just(Vec3::Z),
        Just(-Vec3::Z)
    ];
    prop_oneof![
        2 => axes.clone(),
        3 => (axes, -7.0f32..-2.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
            .prop_map(|(a, e, x, y, z)| (a + 10f32.powf(e) * Vec3::new(x, y, z)).normalize()),
        5 => (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
            .prop_filter("nonzero", |(x, y, z)| x * x + y * y + z * z > 1e-6)
            .prop_map(|(x, y, z)| Vec3::new(x, y, z).normalize()),
    ]
}

/// Points with coordinates spanning 1e-30..1e30 (and zeros, denormals).
fn point(lo: f32, hi: f32) -> impl Strategy<Value = Vec3> {
    (scalar(lo, hi), scalar(lo, hi), scalar(lo, hi)).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// GGX roughness: exactly 0, at and around the delta threshold, 10^U(-3, 0), exactly 1.
fn roughness() -> impl Strategy<Value = f32> {
    prop_oneof![
        1 => Just(0.0f32),
        1 => prop_oneof![Just(9.99e-4f32), Just(1e-3), Just(1.001e-3)],
        6 => (-3.0f32..0.0).prop_map(|e| 10f32.powf(e)),
        1 => Just(1.0f32),
    ]
}

/// A dielectric's relative index: 1.5 and 1/1.5, within 10^U(-7, -2) of 1 on either side, any
/// in 0.1..10.
fn relative_index() -> impl Strategy<Value = f32> {
    prop_oneof![
        2 => prop_oneof![Just(1.5f32), Just(1.0 / 1.5)],
        2 => (-7.0f32..-2.0, any::<bool>()).prop_map(|(e, up)| if up { 1.0 + 10f32.powf(e) } else { 1.0 - 10f32.powf(e) }),
        1 => 0.1f32..10.0,
    ]
}

/// A unit normal and a direction on its side: anywhere, or grazing it within 10^U(-7, -1).
fn normal_and_outgoing() -> impl Strategy<Value = (Vec3, Vec3)> {
    (unit(), unit(), -7.0f32..-1.0, any::<bool>()).prop_map(|(n, d, e, graze)| {
        let wo = if graze {
            let t = (d - n * d.dot(n)).normalize_or(kernel::frame::orthonormal_basis(n).0);
            (t + n * 10f32.powf(e)).normalize()
        } else {
            d
        };
        (n, if wo.dot(n) < 0.0 { -wo } else { wo })
    })
}

fn is_unit(v: Vec3) -> bool {
    (v.length() - 1.0).abs() <= UNIT_TOL
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn orthonormal_basis_is_orthonormal(n in unit()) {
        let (t, b) = orthonormal_basis(n);
        prop_assert!(is_unit(t) && is_unit(b), "{t} {b}");
        prop_assert!(t.dot(n).abs() <= UNIT_TOL && b.dot(n).abs() <= UNIT_TOL && t.dot(b).abs() <= UNIT_TOL);
        prop_assert!((t.cross(b) - n).length() <= 2.0 * UNIT_TOL);
    }

    #[test]
    fn sample_lobe_is_unit_with_the_requested_cosine(a in unit(), c in -1.0f32..=1.0, phi in 0.0f32..std::f32::consts::TAU) {
        let w = sample_lobe(a, c, phi);
        prop_assert!(is_unit(w), "{w}");
        prop_assert!((w.dot(a) - c).abs() <= 2.0 * UNIT_TOL, "cos {} vs {c}", w.dot(a));
    }

    #[test]
    fn brdf_sampling_stays_in_the_hemisphere(n in unit(), u1 in 0.0f32..1.0, u2 in 0.0f32..1.0, wi in unit(), albedo in 0.0f32..=1.0) {
        let w = sample_brdf(n, u1, u2);
        prop_assert!(is_unit(w));
        prop_assert!(w.dot(n) >= -UNIT_TOL);
        let pdf = pdf_brdf(n, w);
        prop_assert!((0.0..=std::f32::consts::FRAC_1_PI * (1.0 + UNIT_TOL)).contains(&pdf));
        let f = eval_scattering(n, wi, Vec3::splat(albedo));
        prop_assert!(f.is_finite() && f.min_element() >= 0.0 && f.max_element() <= albedo * std::f32::consts::FRAC_1_PI * (1.0 + UNIT_TOL));
        let p = pdf_brdf(n, wi);
        prop_assert!(p.is_finite() && p >= 0.0);
    }

    #[test]
    fn bsdfs_are_finite_and_non_negative(
        (n, wo) in normal_and_outgoing(),
        wi in unit(),
        kind in 1u32..4,
        complex in 0u32..4,
        alpha in roughness(),
        eta in relative_index(),
        u in (0.0f32..1.0, 0.0f32..1.0, 0.0f32..1.0),
    ) {
        let m = kernel::probe::probe_material(kind, complex, alpha, eta);
        let a = twinpath_tests::ggx_table::albedo(&m, n, wo);
        let (f, pdf) = kernel::bsdf::eval(kernel::features::Dynamic(0), &m, n, wo, wi, eta, a);
        prop_assert!(f.is_finite() && f.min_element() >= 0.0, "eval {f} for {m:?}");
        prop_assert!(pdf.is_finite() && pdf >= 0.0, "pdf {pdf} for {m:?}");
        let s = kernel::bsdf::sample(kernel::features::Dynamic(0), &m, n, wo, eta, a, u.0, u.1, u.2);
        prop_assert!(s.weight.is_finite() && s.weight.min_element() >= 0.0, "weight {} for {m:?}", s.weight);
        prop_assert!(s.eta2.is_finite() && s.eta2 > 0.0);
        if s.weight.max_element() > 0.0 {
            prop_assert!(is_unit(s.wi) || (s.wi.length() - 1.0).abs() < 1e-5, "wi {} ({})", s.wi, s.wi.length());
            // Delta lobes only where the roughness says so; else a finite positive density.
            if s.pdf == kernel::bsdf::DELTA_PDF {
                prop_assert!(alpha < kernel::bsdf::DELTA_ALPHA, "delta at alpha {alpha}");
            } else {
                prop_assert!(s.pdf.is_finite() && s.pdf > 0.0, "pdf {} for {m:?}", s.pdf);
            }
            // The direction is on the side the sample says.
            prop_assert!((s.wi.dot(n) < 0.0) == s.transmitted || s.wi.dot(n) == 0.0);
        }
    }

    #[test]
    fn sphere_samples_are_on_the_sphere(c in point(-15.0, 15.0), r in 1e-15f32..1e15, u1 in 0.0f32..1.0, u2 in 0.0f32..1.0) {
        let s = sample_sphere(c, r, u1, u2);
        prop_assert!(s.position.is_finite() && is_unit(s.normal), "{:?}", s);
        // On the sphere to within the rounding of c + r n.
        let err = sphere_point_error(c, r);
        prop_assert!(((s.position - c) - r * s.normal).abs().max_element() <= err);
    }

    #[test]
    fn cone_samples_face_the_receiver_with_finite_pdf(c in point(-15.0, 15.0), r in 1e-15f32..1e9, d in unit(), k in -5.0f32..6.0, u1 in 0.0f32..1.0, u2 in 0.0f32..1.0) {
        // Within the scene domain: coordinates and distances up to 1e15 (scene validation), and
        // a radius above the precision of the light's own position (0.1 of |c|).
        let r = r.max(0.1 * c.abs().max_element());
        let x = c + d * r * (1.0 + 10f32.powf(k)).min(1e15 / r);
        prop_assume!((x - c).length() > r);
        let s = sample_sphere_cone(c, r, x, u1, u2);
        prop_assert!(s.point.position.is_finite() && is_unit(s.point.normal));
        prop_assert!(s.pdf_solid_angle.is_finite() && s.pdf_solid_angle > 0.0, "pdf {}", s.pdf_solid_angle);
        prop_assert_eq!(s.pdf_solid_angle, pdf_sphere_cone(c, r, x));
        let omc = cone_one_minus_cos(r, (x - c).length_squared());
        prop_assert!(omc > 0.0 && omc <= 1.0);
        // The sampled point faces the receiver (up to the point's rounding).
        let to_x = x - s.point.position;
        prop_assert!(s.point.normal.dot(to_x) >= -sphere_point_error(c, r));
    }

    /// Triangle lights of any shape and size (edges along the same or nearly the same axis,
    /// 1e-6 to 1e6 long), receivers near, far, in
    /// the plane and on the triangle, both modes: a finite point on the triangle, a unit normal,
    /// and a finite, non-negative pdf equal to what MIS computes for that point.
    #[test]
    fn triangle_light_samples_are_finite_and_on_the_light(p0 in point(-6.0, 6.0), d1 in unit(), s1 in -6.0f32..6.0, d2 in unit(), s2 in -6.0f32..6.0, d in unit(), k in -8.0f32..6.0, in_plane in any::<bool>(), solid_angle in any::<bool>(), two_sided in any::<bool>(), u1 in 0.0f32..1.0, u2 in 0.0f32..1.0) {
        let (e1, e2) = (d1 * 10f32.powf(s1), d2 * 10f32.powf(s2));
        let cross = e1.cross(e2);
        // Only triangles with a normal f32 can normalise, |e1 x e2|^2 a normal float (a hit's
        // normal is the same `triangle_normal`); parallel edges (often drawn) are skipped.
        if !(cross.length_squared() >= f32::MIN_POSITIVE && cross.length().is_finite()) {
            return Ok(());
        }
        let size = e1.length().max(e2.length());
        let centroid = p0 + (e1 + e2) / 3.0;
        let x = if in_plane {
            p0 + u2 * e1 + u1 * e2 + (d - cross.normalize() * d.dot(cross.normalize())) * size * 10f32.powf(k)
        } else {
            centroid + d * size * 10f32.powf(k)
        };
        // Within the scene domain (coordinates up to 1e15).
        prop_assume!(x.abs().max_element() <= 1e15 && (p0 + e1).abs().max_element() <= 1e15 && (p0 + e2).abs().max_element() <= 1e15);
        let mode = if solid_angle { light_sampling::SOLID_ANGLE } else { light_sampling::AREA };
        let l = probe_triangle_light(p0, e1, e2, two_sided as u32);
        let s = sample_triangle_light(&l, 0, mode, x, u1, u2);
        prop_assert!(s.point.position.is_finite() && is_unit(s.point.normal), "{:?}", s);
        prop_assert!(s.pdf_solid_angle.is_finite() && s.pdf_solid_angle >= 0.0, "pdf {}", s.pdf_solid_angle);
        prop_assert_eq!(s.pdf_solid_angle.to_bits(), pdf_triangle_light(&l, mode, x, s.point.position, s.point.normal).to_bits());
        // On the triangle's plane to within the error bound of its points.
        let err = triangle_point_error(p0, e1, e2, 1.0, 1.0);
        prop_assert!((s.point.position - p0).dot(cross.normalize()).abs() <= 4.0 * err, "off the plane by {}", (s.point.position - p0).dot(cross.normalize()));
    }

    #[test]
    fn geometry_factor_and_pdf_conversion_are_finite(pa in point(-30.0, 30.0), na in unit(), pb in point(-30.0, 30.0), nb in unit(), same in any::<bool>(), pdf in 0.0f32..1e6) {
        let pb = if same { pa } else { pb };
        let g = geometry_factor(pa, na, pb, nb);
        prop_assert!(g.is_finite() && g >= 0.0, "G = {g}");
        let p = area_to_solid_angle_pdf(pdf, pa, pb, nb);
        prop_assert!(p.is_finite() && p >= 0.0, "pdf = {p}");
    }

    #[test]
    fn power_heuristic_is_a_weight(a in 0.0f32..f32::MAX, b in 0.0f32..f32::MAX) {
        let w = power_heuristic(a, b);
        prop_assert!(w.is_finite() && (0.0..=1.0).contains(&w), "w({a}, {b}) = {w}");
    }

    #[test]
    fn ray_sphere_returns_a_root_in_range_or_none(o in point(-30.0, 30.0), d in unit(), c in point(-30.0, 30.0), r in 1e-30f32..1e30) {
        let t = intersect_sphere(o, d, c, r, 0.0, f32::INFINITY);
        prop_assert!(t == -1.0 || (t > 0.0 && t.is_finite()), "t = {t}");
    }

    #[test]
    fn ray_triangle_returns_barycentrics_inside(o in point(-30.0, 30.0), d in unit(), p0 in point(-30.0, 30.0), e1 in point(-30.0, 30.0), e2 in point(-30.0, 30.0)) {
        let h = intersect_triangle_uv(o, d, p0, e1, e2, 0.0, f32::INFINITY);
        prop_assert!(h.t == -1.0 || (h.t > 0.0 && h.t.is_finite()));
        if h.t > 0.0 {
            prop_assert!(h.u >= 0.0 && h.v >= 0.0 && h.u + h.v <= 1.0);
            let err = triangle_point_error(p0, e1, e2, h.u, h.v);
            let p = triangle_point(p0, e1, e2, h.u, h.v);
            prop_assert!(!err.is_nan() && err >= 0.0 && !p.is_nan());
            let (offset, grazing) = triangle_offsets(p0, e1, e2, h.u, h.v);
            prop_assert!(offset >= 0.0 && grazing >= 0.0, "heights {offset}, {grazing}");
        }
    }

    /// The CPU traversal's four-lane Moller-Trumbore gives, in every lane, the kernel's scalar
    /// answer bit for bit (hits, misses, t), so the SIMD path cannot change a pixel. Half the
    /// rays aim at a point of the first triangle so that hits are common.
    #[test]
    fn four_lane_triangle_test_is_bit_identical_to_the_kernel(
        o in point(-30.0, 30.0),
        d in unit(),
        aim in any::<bool>(),
        a in 0.0f32..1.0,
        b in 0.0f32..1.0,
        tris in prop::array::uniform4((point(-30.0, 30.0), point(-30.0, 30.0), point(-30.0, 30.0))),
        t_max in prop_oneof![Just(f32::INFINITY), scalar(-30.0, 30.0).prop_map(f32::abs)],
    ) {
        let d = if aim {
            let (p0, e1, e2) = tris[0];
            let target = triangle_point(p0, e1, e2, a * (1.0 - b), b);
            (target - o).try_normalize().unwrap_or(d)
        } else {
            d
        };
        let lane = |v: [Vec3; 4], axis: usize| f32x4::from_array(v.map(|p| p[axis]));
        let (p0s, e1s, e2s) = (tris.map(|t| t.0), tris.map(|t| t.1), tris.map(|t| t.2));
        let four = Triangles4 {
            p0: [0, 1, 2].map(|k| lane(p0s, k)),
            edge1: [0, 1, 2].map(|k| lane(e1s, k)),
            edge2: [0, 1, 2].map(|k| lane(e2s, k)),
        };
        let simd = Ray4::new(o, d).triangles(&four, 0.0, t_max).to_array();
        for i in 0..4 {
            let scalar = intersect_triangle(o, d, p0s[i], e1s[i], e2s[i], 0.0, t_max);
            prop_assert_eq!(simd[i].to_bits(), scalar.to_bits(), "lane {}: {} vs {}", i, simd[i], scalar);
        }
    }

    /// The samplers written over `kernel::real::Real` give, in every SIMD lane, the `f32`
    /// result bit for bit (the CPU's packets take their light samples and BRDF directions from
    /// lanes; the images must not change): the cone sample's point, normal and pdf, the
    /// cosine-weighted direction, and the azimuth's cosine and sine. Lane 0 is sampled as the
    /// cone test above samples; the other lanes mix in other receivers, normals and numbers.
    #[test]
    fn lane_samplers_are_bit_identical_to_the_f32_ones(
        c in point(-15.0, 15.0),
        r in 1e-15f32..1e9,
        ds in prop::array::uniform4(unit()),
        ks in prop::array::uniform4(-5.0f32..6.0),
        us in prop::array::uniform4((0.0f32..1.0, 0.0f32..1.0)),
        ns in prop::array::uniform4(unit()),
    ) {
        use kernel::real::V3;
        use kernel::sampling::{sample_cosine_hemisphere, sample_cosine_hemisphere_v3, sample_sphere_cone_v3};
        use kernel::turns::cos_sin_turns;
        let r = r.max(0.1 * c.abs().max_element());
        let xs = [0, 1, 2, 3].map(|i| c + ds[i] * r * (1.0 + 10f32.powf(ks[i])).min(1e15 / r));
        let lanes = |f: &dyn Fn(usize) -> f32| f32x4::from_array([0, 1, 2, 3].map(f));
        let v3 = |v: [Vec3; 4]| V3::new(lanes(&|i| v[i].x), lanes(&|i| v[i].y), lanes(&|i| v[i].z));
        let lane3 = |v: V3<f32x4>, i: usize| Vec3::new(v.x[i], v.y[i], v.z[i]);
        let (u1, u2) = (lanes(&|i| us[i].0), lanes(&|i| us[i].1));
        let cone = sample_sphere_cone_v3(v3([c; 4]), f32x4::splat(r), v3(xs), u1, u2);
        let dirs = sample_cosine_hemisphere_v3(v3(ns), u1, u2);
        let (cos, sin) = cos_sin_turns(u2);
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        for i in 0..4 {
            let (a, b) = us[i];
            // Receivers inside the sphere are the caller's to avoid; both forms must still agree.
            let s = sample_sphere_cone(c, r, xs[i], a, b);
            prop_assert_eq!(bits(lane3(cone.position, i)), bits(s.point.position), "lane {} position", i);
            prop_assert_eq!(bits(lane3(cone.normal, i)), bits(s.point.normal), "lane {} normal", i);
            prop_assert_eq!(cone.pdf_solid_angle[i].to_bits(), s.pdf_solid_angle.to_bits(), "lane {} pdf", i);
            let w = sample_cosine_hemisphere(ns[i], a, b);
            prop_assert_eq!(bits(lane3(dirs, i)), bits(w), "lane {} direction", i);
            let (c1, s1) = cos_sin_turns(b);
            prop_assert_eq!((cos[i].to_bits(), sin[i].to_bits()), (c1.to_bits(), s1.to_bits()), "lane {} azimuth", i);
        }
    }

    /// The same for the four-lane sphere test: each lane is the kernel's `intersect_sphere`
    /// bit for bit. Half the rays aim at a point near the first sphere's centre.
    #[test]
    fn four_lane_sphere_test_is_bit_identical_to_the_kernel(
        o in point(-30.0, 30.0),
        d in unit(),
        aim in any::<bool>(),
        jitter in point(-30.0, 30.0),
        spheres in prop::array::uniform4((point(-30.0, 30.0), scalar(-30.0, 30.0).prop_map(f32::abs))),
        t_max in prop_oneof![Just(f32::INFINITY), scalar(-30.0, 30.0).prop_map(f32::abs)],
    ) {
        let d = if aim {
            let (c, r) = spheres[0];
            (c + r * jitter.clamp_length_max(1.0) - o).try_normalize().unwrap_or(d)
        } else {
            d
        };
        let four = Spheres4 {
            center: [0, 1, 2].map(|k| f32x4::from_array(spheres.map(|s| s.0[k]))),
            radius: f32x4::from_array(spheres.map(|s| s.1)),
        };
        let simd = Ray4::new(o, d).spheres(&four, 0.0, t_max).to_array();
        for i in 0..4 {
            let scalar = intersect_sphere(o, d, spheres[i].0, spheres[i].1, 0.0, t_max);
            prop_assert_eq!(simd[i].to_bits(), scalar.to_bits(), "lane {}: {} vs {}", i, simd[i], scalar);
        }
    }

    #[test]
    fn offsets_leave_on_the_normal_side(p in point(-30.0, 30.0), n in unit(), e in scalar(-30.0, 25.0), target in point(-30.0, 30.0)) {
        // Error bounds are at most a few eps of the coordinates: up to 1e25 against 1e30.
        let err = e.abs();
        let q = offset_ray_origin(p, n, err);
        prop_assert!(q.is_finite(), "{q}");
        prop_assert!((q - p).dot(n) > 0.0, "{p} -> {q} along {n}");
        // Shadow rays join two points of a scene: within the domain (1e15), their end is finite.
        let (p, target) = (p.clamp(Vec3::splat(-1e15), Vec3::splat(1e15)), target.clamp(Vec3::splat(-1e15), Vec3::splat(1e15)));
        let end = shadow_ray_end(p, target, n, err.min(1e10));
        prop_assert!(end.is_finite(), "{end}");
    }

    #[test]
    fn random_numbers_are_in_the_open_unit_interval(w in any::<[u32; 4]>()) {
        let h = pcg4d(w);
        for x in h {
            let u = u32_to_unit_f32(x);
            prop_assert!(u > 0.0 && u < 1.0, "{x:#x} -> {u}");
        }
    }
}

/// Every one of the 2^23 numbers the root gives (`rng::u32_to_unit_f32` reads the top 23 bits)
/// is the exact midpoint (k + 1/2) 2^-23 of its interval, strictly inside (0, 1), and its
/// mirror 1 - u is one of them too: no sampler can be handed 0 or 1, whatever it does with u.
#[test]
fn every_random_number_is_an_exact_midpoint_strictly_inside_the_unit_interval() {
    for k in 0u32..1 << 23 {
        let (low, high) = (u32_to_unit_f32(k << 9), u32_to_unit_f32(k << 9 | 0x1ff));
        assert_eq!(
            low.to_bits(),
            high.to_bits(),
            "bits below the top 23 matter at k = {k}"
        );
        assert_eq!(low as f64, (k as f64 + 0.5) / 8_388_608.0, "k = {k}");
        assert!(low > 0.0 && low < 1.0);
        let mirror = u32_to_unit_f32(((1 << 23) - 1 - k) << 9);
        assert_eq!(1.0 - low, mirror, "k = {k}");
    }
    assert_eq!(u32_to_unit_f32(0), 2f32.powi(-24));
    assert_eq!(u32_to_unit_f32(u32::MAX), 1.0 - 2f32.powi(-24));
}

/// The case `ray_triangle_returns_barycentrics_inside` found (CI, 2026-11-22): a sliver whose
/// sin(theta) is denormal (1/sin overflowed to infinity), hit at its corner u = v = 0, gave a
/// NaN error bound (0 x inf). The bound must be a number, at least the corner's own rounding.
#[test]
fn triangle_point_error_of_a_denormal_sliver_is_not_nan() {
    let o = Vec3::new(1.0059377e-20, 0.0, 0.0);
    let d = Vec3::new(-0.0, -1.0, -0.0);
    let p0 = Vec3::new(7.4105455e-21, -1.0, 0.0);
    let e1 = Vec3::new(3.15264e18, 0.0, 0.0);
    let e2 = Vec3::new(375248440000000.0, 3.578063e-29, 1e-45);
    let h = intersect_triangle_uv(o, d, p0, e1, e2, 0.0, f32::INFINITY);
    assert!(h.t > 0.0, "the ray hits the sliver (t = {})", h.t);
    let err = triangle_point_error(p0, e1, e2, h.u, h.v);
    let p = triangle_point(p0, e1, e2, h.u, h.v);
    let (offset, grazing) = triangle_offsets(p0, e1, e2, h.u, h.v);
    assert!(
        offset >= 0.0 && grazing >= 0.0,
        "heights {offset}, {grazing}"
    );
    assert!(
        err >= f32::EPSILON * p0.abs().max_element() && !p.is_nan(),
        "u = {}, v = {}, error bound {err}, point {p}",
        h.u,
        h.v
    );
}

/// The case `ray_triangle_returns_barycentrics_inside` found (2026-12-06): edges whose cross
/// product overflows (beyond the scene's domain of 1e15) give a normal that is not a number,
/// and the height of rays leaving the hit (`geometry::triangle_offsets_v3`, which multiplies a
/// sliver's bound by |n|_1) was NaN. Both heights must be numbers, at least 0.
#[test]
fn triangle_offsets_of_an_overflowing_triangle_are_numbers() {
    let o = Vec3::new(6.705678e-24, 1.0, 0.0);
    let d = Vec3::new(0.0, 0.0, 1.0);
    let p0 = Vec3::new(2.8628497e-22, 1.0, 1.0);
    let e1 = Vec3::new(1.0, 9.12061e24, 1.0);
    let e2 = Vec3::new(-1.0, 1.0, 2.3864183e22);
    let h = intersect_triangle_uv(o, d, p0, e1, e2, 0.0, f32::INFINITY);
    assert!(h.t > 0.0, "the ray hits the triangle (t = {})", h.t);
    let (offset, grazing) = triangle_offsets(p0, e1, e2, h.u, h.v);
    assert!(
        offset >= 0.0 && grazing >= 0.0,
        "heights {offset}, {grazing}"
    );
}
