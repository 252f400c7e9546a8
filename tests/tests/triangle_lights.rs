//! Triangle lights (emissive quads and meshes), tested as every light is:
//!
//! 1. Both samplers (uniform in area, and uniform in the spherical triangle, Arvo 1995) follow
//!    the density MIS uses for them (`light::triangle::pdf`): chi-square tests in solid
//!    angle, with expected counts from integrating that pdf function over each bin (a sub-triangle
//!    of the light, its solid angle by Van Oosterom and Strackee's formula in f64), so a sampler
//!    and a pdf that disagree fail, whichever is wrong; and every sample's pdf is that
//!    function's value at the point, bit for bit.
//! 2. The solid angle the kernel computes matches the closed form (Van Oosterom and Strackee,
//!    in f64) to a stated precision, and the mean of 1 / pdf over area samples estimates it.
//! 3. A diffuse plane under a rectangular light (a quad, two triangle lights) matches the closed
//!    form of a polygon's irradiance (Lambert's formula) pixel by pixel, on both backends, with
//!    either sampler.

use glam::{DVec3, Vec3};
use kernel::light::triangle::{
    pdf as pdf_triangle_light, sample as sample_triangle_light, spherical_triangle_used,
};
use kernel::rng::SampleRng;
use kernel::scene::{light_sampling, Triangle, NONE};
use kernel::spherical_triangle::{
    self, barycentrics_along, SphericalTriangle, MAX_SOLID_ANGLE, MIN_SOLID_ANGLE,
};
use std::f64::consts::PI;
use twinpath::render::Backend;
use twinpath::scene::light_table::triangle_light;
use twinpath::scene::SceneFile;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::triangle_bins::{barycentrics, bin_of, bins, solid_angle_f64, N};
use twinpath_tests::{assert_film_matches, chi_square, render_film, scene_from_toml, z_critical};

/// The kernel light of triangle `p` (chosen with probability 1).
fn light_of(p: [Vec3; 3], two_sided: bool) -> kernel::scene::Light {
    let tri = Triangle {
        p0: p[0].to_array(),
        material: 0,
        edge1: (p[1] - p[0]).to_array(),
        light: NONE,
        edge2: (p[2] - p[0]).to_array(),
        shading: kernel::scene::NONE,
    };
    let mut l = triangle_light(&tri, [1.0; 3], two_sided);
    l.select_pmf = 1.0;
    l
}

/// One triangle-light sampling case: the triangle, the receiver, and whether it is two-sided.
struct Case {
    name: &'static str,
    p: [Vec3; 3],
    x: Vec3,
    two_sided: bool,
    /// Whether the light's solid-angle mode samples it as a spherical triangle (else by area).
    spherical: bool,
}

fn cases() -> Vec<Case> {
    let right = [Vec3::ZERO, Vec3::X, Vec3::Y];
    vec![
        Case {
            name: "above, moderate solid angle",
            p: right,
            x: Vec3::new(0.2, 0.3, 1.0),
            two_sided: false,
            spherical: true,
        },
        Case {
            name: "close above, large solid angle",
            p: right,
            x: Vec3::new(0.3, 0.3, 0.03),
            two_sided: false,
            spherical: true,
        },
        Case {
            name: "oblique, outside the triangle's footprint",
            p: right,
            x: Vec3::new(3.0, -1.0, 0.5),
            two_sided: false,
            spherical: false,
        },
        Case {
            name: "sliver triangle",
            p: [Vec3::ZERO, Vec3::X, Vec3::new(0.5, 0.03, 0.0)],
            x: Vec3::new(0.4, 0.2, 0.3),
            two_sided: false,
            spherical: false,
        },
        Case {
            name: "far: below the spherical sampler's smallest solid angle",
            p: right,
            x: Vec3::new(0.1, 0.2, 60.0),
            two_sided: false,
            spherical: false,
        },
        // Just outside the band where light sampling leaves a receiver to BSDF sampling
        // (`within_plane_rounding`: 4 times the light's point bound, about 3.3e-5 here since
        // the bound holds a GPU's triangle test's rounding).
        Case {
            name: "edge-on, just above the plane beside an edge: a thin spherical triangle",
            p: right,
            x: Vec3::new(0.5, -0.02, 5e-5),
            two_sided: false,
            spherical: false,
        },
        Case {
            name: "two-sided, from behind",
            p: [
                Vec3::new(1.0, 2.0, 3.0),
                Vec3::new(2.5, 2.0, 3.0),
                Vec3::new(1.0, 3.0, 3.5),
            ],
            x: Vec3::new(1.5, 1.5, 2.0),
            two_sided: true,
            spherical: true,
        },
    ]
}

/// Expected bin counts of [`SAMPLES`] samples of light `l` for `case` under `mode`:
/// `pdf_triangle_light` integrated in solid angle over each bin ([`bins`]), by the midpoint rule
/// on 24 x 24 sub-triangles of it, each weighted by its solid angle in f64 (exact where the pdf is
/// constant).
fn expected_counts(l: &kernel::scene::Light, mode: u32, case: &Case) -> Vec<f64> {
    let p64 = case.p.map(|v| v.as_dvec3());
    let x64 = case.x.as_dvec3();
    let n = (case.p[1] - case.p[0])
        .cross(case.p[2] - case.p[0])
        .normalize();
    let fine = 24;
    let mut expected = vec![0.0; 2 * N * N];
    for (b, tri) in bins().iter().enumerate() {
        let Some(tri) = tri else { continue };
        let at = |(u, v): (f64, f64)| p64[0] + u * (p64[1] - p64[0]) + v * (p64[2] - p64[0]);
        let corner = tri.map(at);
        let (d1, d2) = (
            (corner[1] - corner[0]) / fine as f64,
            (corner[2] - corner[0]) / fine as f64,
        );
        for i in 0..fine {
            for j in 0..fine - i {
                let q = corner[0] + i as f64 * d1 + j as f64 * d2;
                let mut subs = vec![[q, q + d1, q + d2]];
                if i + j < fine - 1 {
                    subs.push([q + d1, q + d1 + d2, q + d2]);
                }
                for s in subs {
                    let c = (s[0] + s[1] + s[2]) / 3.0;
                    let facing = if case.two_sided && n.as_dvec3().dot(x64 - c) < 0.0 {
                        -n
                    } else {
                        n
                    };
                    let pdf = density(l, mode, case, c.as_vec3(), facing) as f64;
                    expected[b] += SAMPLES as f64 * pdf * solid_angle_f64(x64, s);
                }
            }
        }
    }
    expected
}

/// Bin counts of [`SAMPLES`] samples of light `l` for `case` under `mode` (stream `stream`),
/// checking each sample: its pdf is `pdf_triangle_light`'s at its point, bit for bit; its
/// normal is the triangle's, toward the receiver when two-sided; it lies on the triangle.
fn observed_counts(l: &kernel::scene::Light, mode: u32, case: &Case, stream: u32) -> Vec<f64> {
    let p64 = case.p.map(|v| v.as_dvec3());
    let x64 = case.x.as_dvec3();
    let n = (case.p[1] - case.p[0])
        .cross(case.p[2] - case.p[0])
        .normalize();
    let mut observed = vec![0.0; 2 * N * N];
    let mut r = SampleRng::new(4321, stream, 0);
    for _ in 0..SAMPLES {
        let (u1, u2) = (r.next_f32(), r.next_f32());
        let (y, normal, pdf) = sample_point(l, mode, case, u1, u2);
        assert_eq!(
            pdf.to_bits(),
            density(l, mode, case, y, normal).to_bits(),
            "{}: sample pdf and pdf_triangle_light differ at {y}",
            case.name
        );
        let facing = if case.two_sided && n.dot(case.x - y) < 0.0 {
            -n
        } else {
            n
        };
        assert!((normal - facing).length() < 1e-6, "{}: normal", case.name);
        let (u, v) = barycentrics(x64, (y.as_dvec3() - x64).normalize(), p64);
        assert!(
            u >= -1e-5 && v >= -1e-5 && u + v <= 1.0 + 1e-5,
            "{}: point {y} off the triangle (u {u}, v {v})",
            case.name
        );
        observed[bin_of(u, v)] += 1.0;
    }
    observed
}

const SAMPLES: u32 = 1_000_000;

/// In the tests' `mode`: the spherical-triangle sampler itself (`SphericalTriangle::sample`,
/// density 1 / solid angle), whatever the light would choose, so that it is tested on every
/// geometry its numerical limits admit, not only where the light uses it.
const SPHERICAL: u32 = 99;

/// `mode`'s point on light `l` for `case` and its solid-angle density.
fn sample_point(
    l: &kernel::scene::Light,
    mode: u32,
    case: &Case,
    u1: f32,
    u2: f32,
) -> (Vec3, Vec3, f32) {
    if mode == SPHERICAL {
        let (p0, e1, e2) = (case.p[0], case.p[1] - case.p[0], case.p[2] - case.p[0]);
        let t = SphericalTriangle::of(case.x, p0, e1, e2);
        let (u, v) = barycentrics_along(case.x, t.sample(u1, u2), p0, e1, e2);
        let y = kernel::geometry::triangle_point(p0, e1, e2, u, v);
        let n = e1.cross(e2).normalize();
        let n = if case.two_sided && n.dot(case.x - y) < 0.0 {
            -n
        } else {
            n
        };
        (y, n, 1.0 / t.solid_angle())
    } else {
        let s = sample_triangle_light(l, 0, mode, case.x, u1, u2);
        (s.point.position, s.point.normal, s.pdf_solid_angle)
    }
}

/// `mode`'s solid-angle density at light point `y` (normal `n`).
fn density(l: &kernel::scene::Light, mode: u32, case: &Case, y: Vec3, n: Vec3) -> f32 {
    if mode == SPHERICAL {
        1.0 / spherical_triangle::solid_angle(
            case.x,
            case.p[0],
            case.p[1] - case.p[0],
            case.p[2] - case.p[0],
        )
    } else {
        pdf_triangle_light(l, mode, case.x, y, n)
    }
}

#[test]
fn triangle_light_samplers_follow_their_pdf_in_solid_angle() {
    let cases = cases();
    let tests = 3 * cases.len();
    let threshold = 1.0 - (1.0 - 0.01f64).powf(1.0 / tests as f64);
    for (k, case) in cases.iter().enumerate() {
        let l = light_of(case.p, case.two_sided);
        let omega = spherical_triangle::solid_angle(
            case.x,
            case.p[0],
            case.p[1] - case.p[0],
            case.p[2] - case.p[0],
        );
        let raw = SphericalTriangle::of(
            case.x,
            case.p[0],
            case.p[1] - case.p[0],
            case.p[2] - case.p[0],
        )
        .sampled();
        for mode in [light_sampling::AREA, light_sampling::SOLID_ANGLE, SPHERICAL] {
            if mode == SPHERICAL && !raw {
                continue;
            }
            let label = format!(
                "{}, {} (solid angle {omega:.3e} sr)",
                case.name,
                match mode {
                    light_sampling::AREA => "area sampling",
                    light_sampling::SOLID_ANGLE => "the light's solid-angle mode",
                    _ => "the spherical-triangle sampler",
                }
            );
            let observed = observed_counts(&l, mode, case, (k * 3) as u32 + mode);
            let expected = expected_counts(&l, mode, case);
            let total: f64 = expected.iter().sum::<f64>() / SAMPLES as f64;
            assert!(
                (total - 1.0).abs() < 2e-3,
                "{label}: the pdf integrates to {total} over the triangle, not 1"
            );
            let (stat, dof, p) = chi_square(&observed, &expected);
            println!("{label}: chi2 = {stat:.1}, dof = {dof}, p = {p:.4}");
            assert!(
                p > threshold,
                "{label}: samples do not follow the pdf (chi2 {stat:.1}, dof {dof}, p {p:.2e})"
            );
        }
        // Which sampler the light's solid-angle mode uses: the spherical one where the estimate
        // reaches its threshold and the solid angle is within the numerical limits.
        let used = spherical_triangle_used(&l, light_sampling::SOLID_ANGLE, case.x).is_some();
        assert_eq!(used, case.spherical, "{}: sampler", case.name);
        assert!(
            !used || (MIN_SOLID_ANGLE..=MAX_SOLID_ANGLE).contains(&omega),
            "{}: thresholds",
            case.name
        );
    }
}

/// The chi-square test above has power: area samples tested against the spherical sampler's
/// density (uniform in solid angle) fail it where the two differ, close to a large triangle.
#[test]
fn chi_square_tells_area_from_solid_angle_sampling() {
    let case = &cases()[1];
    let l = light_of(case.p, case.two_sided);
    let observed = observed_counts(&l, light_sampling::AREA, case, 99);
    let wrong = expected_counts(&l, light_sampling::SOLID_ANGLE, case);
    let (stat, dof, p) = chi_square(&observed, &wrong);
    println!("area samples vs the solid-angle pdf: chi2 = {stat:.0}, dof = {dof}, p = {p:.1e}");
    assert!(
        p < 1e-6,
        "the test cannot tell the samplers apart (p = {p})"
    );
}

/// The kernel's solid angle against the closed form in f64 on random triangles and receivers
/// at every distance (1e-3 to 1e3 triangle sizes): within 64 eps relative times
/// (1 / h + 1 / sin theta), with h the sine of the receiver's elevation above the triangle's
/// plane and theta the triangle's angle at p0. The triple product the formula rests on is
/// proportional to h, which the rounding of the receiver's offsets moves by a few eps, and to
/// the triangle's normal, which the rounding of its edges moves by eps / sin theta; nothing
/// else loses digits, whatever the distance. Also an exact case: a triangle of the three unit
/// axis points seen from the origin spans one octant, pi / 2.
#[test]
fn solid_angle_matches_van_oosterom_strackee() {
    let octant =
        spherical_triangle::solid_angle(Vec3::ZERO, Vec3::X, Vec3::Y - Vec3::X, Vec3::Z - Vec3::X)
            as f64;
    assert!(
        (octant / (PI / 2.0) - 1.0).abs() < 4.0 * f32::EPSILON as f64,
        "octant: {octant}"
    );
    let mut g = twinpath_tests::SplitMix(99);
    let mut v = |s: f32| Vec3::new(g.unit() - 0.5, g.unit() - 0.5, g.unit() - 0.5) * s;
    let mut worst = 0.0f64;
    for k in 0..200_000 {
        let p = [v(2.0), v(2.0), v(2.0)];
        let centroid = (p[0] + p[1] + p[2]) / 3.0;
        let distance = 10f32.powf((k % 7) as f32 - 3.0);
        let x = centroid + v(2.0 * distance);
        let got = spherical_triangle::solid_angle(x, p[0], p[1] - p[0], p[2] - p[0]) as f64;
        let (x64, p64) = (x.as_dvec3(), p.map(|q| q.as_dvec3()));
        let want = solid_angle_f64(x64, p64);
        let (e1, e2) = (p64[1] - p64[0], p64[2] - p64[0]);
        let n = e1.cross(e2).normalize();
        let h = ((x64 - p64[0]).dot(n) / (x64 - p64[0]).length()).abs();
        if !(want > 0.0) || h < 1e-6 {
            continue;
        }
        // 1 / sin of the triangle's angle at p0: how much the rounding of its edges moves its
        // normal, and so the triple product.
        let condition = e1.length() * e2.length() / e1.cross(e2).length();
        let ratio = (got / want - 1.0).abs() / (f32::EPSILON as f64 * (1.0 / h + condition));
        worst = worst.max(ratio);
        assert!(
            ratio <= 64.0,
            "x {x}, triangle {p:?}: {got} vs {want} (h {h:.1e})"
        );
    }
    println!("solid_angle: worst relative error {worst:.2} eps (1 / h + 1 / sin theta)");
}

/// E[1 / pdf] of area sampling, in solid angle, is the solid angle: a z-test of the mean of
/// 1 / pdf against the closed form (the spherical sampler's 1 / pdf is the solid angle itself,
/// checked above).
#[test]
fn inverse_area_pdf_estimates_the_solid_angle() {
    let cases = cases();
    let z_max = z_critical(1e-3, cases.len());
    for (k, case) in cases.iter().enumerate() {
        let l = light_of(case.p, case.two_sided);
        let mut r = SampleRng::new(777, k as u32, 0);
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..SAMPLES {
            let s = sample_triangle_light(
                &l,
                0,
                light_sampling::AREA,
                case.x,
                r.next_f32(),
                r.next_f32(),
            );
            let w = 1.0 / s.pdf_solid_angle as f64;
            sum += w;
            sum2 += w * w;
        }
        let n = SAMPLES as f64;
        let mean = sum / n;
        let var = (sum2 / n - mean * mean) / (n - 1.0);
        let want = solid_angle_f64(case.x.as_dvec3(), case.p.map(|q| q.as_dvec3()));
        let z = (mean - want) / var.sqrt();
        println!(
            "{}: mean 1/pdf {mean:.6e} +- {:.1e}, solid angle {want:.6e}, z = {z:+.2}",
            case.name,
            var.sqrt()
        );
        assert!(z.abs() < z_max, "{}: |z| = {:.2}", case.name, z.abs());
    }
}

/// The rectangular light of the plane test: a quad at height H, corner (-A, H, -B), edges
/// (2A, 0, 0) and (0, 0, 2B), front face down, radiance L.
const KD: f32 = 0.6;
const H: f64 = 1.5;
const A: f64 = 0.8;
const B: f64 = 0.5;
const L: f64 = 3.0;

fn panel_scene(light_sampling: &str) -> SceneFile {
    let text = format!(
        r#"
        [camera]
        eye = [0, 6, 6]
        look_at = [0, 0, -0.5]
        up = [0, 1, 0]
        vfov = 60
        width = 40
        height = 40
        [render]
        seed = 11
        sampler = "independent"
        light_sampling = "{light_sampling}"
        [materials]
        plane = {{ kd = [{KD}, {KD}, {KD}] }}
        panel = {{ emission = [{L}, {L}, {L}] }}
        [[quad]]
        corner = [-100, 0, 100]
        edge1 = [200, 0, 0]
        edge2 = [0, 0, -200]
        material = "plane"
        [[quad]]
        corner = [{}, {H}, {}]
        edge1 = [{}, 0, 0]
        edge2 = [0, 0, {}]
        material = "panel"
        "#,
        -A,
        -B,
        2.0 * A,
        2.0 * B
    );
    scene_from_toml(&text)
}

/// Irradiance at plane point x (normal +y) from the Lambertian polygon `v` of radiance L,
/// entirely above x's tangent plane: Lambert's formula, E = (L / 2) sum_i theta_i (n . g_i),
/// with theta_i the angle the edge v_i v_{i+1} subtends at x and g_i the unit normal of the
/// plane through x and that edge (Lambert 1760; Arvo 1995, "Applications of Irradiance
/// Tensors", eq. 1).
fn polygon_irradiance(x: DVec3, v: &[DVec3]) -> f64 {
    let mut sum = 0.0;
    for i in 0..v.len() {
        let (a, b) = (
            (v[i] - x).normalize(),
            (v[(i + 1) % v.len()] - x).normalize(),
        );
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * a.cross(b).normalize().y;
    }
    L * 0.5 * sum.abs()
}

/// Exact pixel values of [`panel_scene`]: kd / pi times the panel's irradiance at the plane
/// point each camera ray meets, averaged over the pixel by a 16 x 16 midpoint quadrature (the
/// box filter); `None` where a quadrature ray meets the panel or misses the plane.
fn panel_exact(scene: &SceneFile) -> Vec<Option<f64>> {
    let panel = [
        DVec3::new(-A, H, -B),
        DVec3::new(A, H, -B),
        DVec3::new(A, H, B),
        DVec3::new(-A, H, B),
    ];
    twinpath_tests::pixel_quadrature(&scene.scene, 16, |eye, d| {
        let (eye, d) = (eye.as_dvec3(), d.as_dvec3());
        if d.y >= 0.0 {
            return None;
        }
        let at_panel = eye + d * ((H - eye.y) / d.y);
        if at_panel.x.abs() <= A * 1.01 && at_panel.z.abs() <= B * 1.01 {
            return None;
        }
        let x = eye + d * (-eye.y / d.y);
        Some(KD as f64 / PI * polygon_irradiance(x, &panel))
    })
}

#[test]
fn plane_under_rectangular_light_closed_form_on_both_backends() {
    for sampling in ["solid_angle", "area"] {
        let scene = panel_scene(sampling);
        assert_eq!(scene.scene.lights.len(), 2);
        let exact = panel_exact(&scene);
        assert!(exact.iter().filter(|e| e.is_some()).count() > 1000);
        for backend in [Backend::Cpu, Backend::Gpu] {
            let film = render_film(&scene, backend, 256);
            assert_eq!(film.discarded, 0);
            assert_film_matches(&film, &exact, &format!("{backend:?}, {sampling} sampling"));
        }
    }
    assert_validation_clean();
}
