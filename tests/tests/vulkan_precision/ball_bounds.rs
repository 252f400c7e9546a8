//! Bounds by ball arithmetic (`twinpath_tests::ball_arithmetic`), which bounds a kernel
//! function's error in one arithmetic by running the function on balls: the balls against the
//! model of a Vulkan device, and with them the functions bounded so (Fresnel reflectances,
//! the microfacet functions, normal-mapped normals, the intersections, the phase function, the
//! BSDFs, the punctual lights and the environment map, written over `Real`): a conformant
//! device's results differ from the CPU's by no more than the balls allow.

use super::{any_device, cases};
use kernel::bsdf::fresnel;
use kernel::real::Real;
use twinpath_tests::ball_arithmetic::{computations, Ball, Roundoff};
use twinpath_tests::device_class::{
    fresnel_apart, sphere_hit_apart, sphere_probe, triangle_hit_apart, triangle_probe, ProbeOutputs,
};
use twinpath_tests::probe_inputs::ProbeInputs;
use twinpath_tests::vulkan_arithmetic::{seed, set_model, Model, Vk32};
use twinpath_tests::SplitMix;

/// Sets the arithmetic of the next computations: the CPU's (IEEE) for `None`, else
/// [`any_device`]`(k)` for `Some(k)`.
fn arithmetic(model: Option<usize>) {
    match model {
        None => set_model(Model::IEEE),
        Some(k) => any_device(k),
    }
}

/// How far a device's `device` is from the CPU's `cpu` (0 where they are equal, as the same
/// infinity), asserting that it is within the balls' bound `apart`; `what` names the output
/// for the message.
fn apart_within(what: impl FnOnce() -> String, cpu: f32, device: f32, apart: f64) -> f64 {
    let d = if cpu == device {
        0.0
    } else {
        (cpu as f64 - device as f64).abs()
    };
    assert!(
        d <= apart,
        "{}: CPU {cpu:e}, device {device:e}, {d:e} apart against {apart:e}",
        what()
    );
    d
}

/// Probe record `r`'s outputs computed by the CPU (IEEE arithmetic, which `Vk32` reproduces
/// bit for bit: checked) and by [`any_device`]`(k)`.
fn cpu_and_device(r: &impl ProbeOutputs, k: usize) -> ([f32; 8], [f32; 8]) {
    let run = |model: Option<usize>| {
        arithmetic(model);
        r.outputs::<Vk32>().map(|x| x.value)
    };
    let cpu = run(None);
    assert_eq!(cpu, r.outputs::<f32>(), "Vk32 under IEEE is the f32 kernel");
    (cpu, run(Some(k)))
}

/// Every result the models of a device (and IEEE arithmetic) return for sums, products,
/// quotients, roots and their chains lies in the ball computed for that arithmetic; and the
/// Vulkan models leave IEEE's balls (so the Vulkan roundoff is needed). Operands span 2^-130
/// (denormal) to 2^40, of both signs, with cancelling sums among them.
#[test]
fn balls_hold_every_result_a_device_may_return() {
    let mut g = SplitMix(41);
    seed(41);
    let mut outside_ieee = 0;
    let mut worst = [0f64; 2];
    for k in 0..cases() {
        let mut x = || {
            let m = 2f32.powi((g.unit() * 170.0) as i32 - 130) * (0.5 + g.unit());
            if g.unit() < 0.5 {
                -m
            } else {
                m
            }
        };
        let (a, b, c, d) = (x(), x(), x(), x());
        // A chain with a cancelling difference, a quotient and a root.
        fn chain<R: Real>(a: R, b: R, c: R, d: R) -> [R; 5] {
            let s = a * b + c;
            let q = s / d;
            let r = (q * q + a).sqrt();
            let cancel = (a + c) - c;
            [s, q, r, cancel, (r - cancel) * d]
        }
        for (model, roundoff) in [(None, Roundoff::IEEE), (Some(k), Roundoff::VULKAN)] {
            arithmetic(model);
            let got = chain(Vk32::new(a), Vk32::new(b), Vk32::new(c), Vk32::new(d));
            let b_ = Ball::exact;
            let balls = computations(roundoff, &|| chain(b_(a), b_(b), b_(c), b_(d)));
            let ieee = computations(Roundoff::IEEE, &|| chain(b_(a), b_(b), b_(c), b_(d)));
            for (i, got) in got.iter().enumerate() {
                let got = got.value as f64;
                if !got.is_finite() {
                    continue;
                }
                let ball = balls[0][i];
                assert!(
                    ball.holds(got),
                    "{roundoff:?}: output {i} of ({a:e}, {b:e}, {c:e}, {d:e}): {got:e} outside {ball:?}"
                );
                if ball.radius > 0.0 && ball.radius.is_finite() {
                    let w = &mut worst[model.is_some() as usize];
                    *w = w.max((got - ball.mid).abs() / ball.radius);
                }
                outside_ieee += (model.is_some() && !ieee[0][i].holds(got)) as usize;
            }
        }
    }
    set_model(Model::VULKAN);
    println!("ball arithmetic: results at most {worst:.3?} of the ball's radius (IEEE, Vulkan models); {outside_ieee} Vulkan results outside IEEE's balls");
    assert!(outside_ieee > 0, "the models never leave IEEE's balls");
}

/// The kernel's Fresnel reflectances (conductor, dielectric with its refracted cosine,
/// Schlick's) under the models of a device differ from the CPU's by at most
/// [`fresnel_apart`], the balls' bound for one IEEE and one Vulkan computation; under the
/// models some differ by more than two IEEE computations could, so the Vulkan roundoff is
/// needed, and by more than the 8 ULP or 8 eps devices were held to before.
/// Inputs as `gpu_functions.rs` draws them, plus cosines within 10^-6 of total internal
/// reflection's critical angle (where cos_t is the root of a vanishing difference).
#[test]
fn fresnel_reflectances_differ_from_the_cpu_within_their_balls() {
    let mut g = SplitMix(43);
    seed(43);
    let (mut worst, mut beyond_ieee, mut worst_eps) = (0f64, 0usize, 0f64);
    let mut beyond_ieee_class = 0usize;
    for k in 0..cases() {
        let pick = |g: &mut SplitMix, xs: &[f32]| xs[(g.u64() % xs.len() as u64) as usize];
        let u = g.unit();
        let eta = pick(&mut g, &[1.5, 1.0 / 1.5, 1.0001, 0.1 + 9.9 * u]);
        let critical = (1.0 - eta * eta).max(0.0).sqrt();
        let near_critical = critical + (g.unit() - 0.5) * 2e-6;
        let (u1, u2, u3) = (g.unit(), g.unit(), g.unit());
        let cos = pick(&mut g, &[0.0, 1.0, 1e-4, u1, u2.sqrt(), near_critical]);
        let k_ext = pick(&mut g, &[0.0, 10.0 * u3]);
        let f0 = [g.unit(), g.unit(), g.unit()];
        let reflectances = |model: Option<usize>| {
            arithmetic(model);
            let x = Vk32::new;
            let (f, cos_t) = fresnel::dielectric(x(cos), x(eta));
            let s = f0.map(|f0| fresnel::schlick_f90_channel(x(f0), x(1.0), x(cos)).value);
            [
                fresnel::conductor(x(cos), x(eta), x(k_ext)).value,
                f.value,
                cos_t.value,
                s[0],
                s[1],
                s[2],
            ]
        };
        let cpu = reflectances(None);
        let device = reflectances(Some(k));
        // The CPU's f32 functions are the IEEE computation.
        assert_eq!(cpu[0], fresnel::conductor(cos, eta, k_ext));
        let apart = fresnel_apart(cos, eta, k_ext, f0);
        let b = Ball::exact;
        let two_ieee = computations(Roundoff::IEEE, &|| {
            let (f, cos_t) = fresnel::dielectric(b(cos), b(eta));
            [fresnel::conductor(b(cos), b(eta), b(k_ext)), f, cos_t]
        });
        for i in 0..6 {
            let d = apart_within(
                || format!("output {i} of (cos {cos:e}, eta {eta:e}, k {k_ext:e}, f0 {f0:?})"),
                cpu[i],
                device[i],
                apart[i],
            );
            if apart[i] > 0.0 {
                worst = worst.max(d / apart[i]);
            }
            worst_eps = worst_eps.max(d / f32::EPSILON as f64);
            if i < 3 {
                let ieee_apart = two_ieee
                    .iter()
                    .map(|w| 2.0 * w[i].radius)
                    .fold(0.0, f64::max);
                beyond_ieee += (d > ieee_apart) as usize;
            }
            // The bound devices were held to before (`gpu_functions.rs`' IEEE class).
            let ulps = (cpu[i].to_bits() as i64 - device[i].to_bits() as i64).unsigned_abs();
            beyond_ieee_class += (ulps > 8 && d > 8.0 * f32::EPSILON as f64) as usize;
        }
    }
    set_model(Model::VULKAN);
    println!("fresnel, a device against the CPU: at most {worst:.3} of the balls' bound (largest difference {worst_eps:.1} eps); {beyond_ieee} reflectances beyond two IEEE computations' bound, {beyond_ieee_class} outputs beyond the IEEE class's 8 ULP or 8 eps");
    assert!(
        beyond_ieee > 0,
        "no device differs by more than IEEE arithmetic allows"
    );
    assert!(
        beyond_ieee_class > 0,
        "the IEEE class's bound holds for devices"
    );
}

/// The kernel's normal-mapped normal (`kernel::surface::mapped_normal_v3`) under the models of
/// a device differs from the CPU's by at most [`mapped_normal_apart`], the balls' bound for one
/// IEEE and one Vulkan computation, per component, a bound the models reach to 0.85 of itself
/// (they stay within the bound devices were held to before, 16 eps of the tangent's component
/// across the normal, which was not derived for them). The balls lose the tangent's direction
/// (any unit vector: apart by 2) only within 10^-4 of parallel, where the IEEE class's bound
/// is as weak (16 eps x 10^4). Inputs as `gpu_functions.rs` draws them (unit base normals,
/// tangents of length 0.01 to 100 at any angle to it, texels, scales 0 to 4, both
/// handednesses), a third of the tangents within 10^-3 to 10^-6 of parallel to the normal.
#[test]
fn mapped_normals_differ_from_the_cpu_within_their_balls() {
    use glam::Vec3;
    use kernel::real::V3;
    use kernel::surface::mapped_normal_v3;
    use twinpath_tests::device_class::mapped_normal_apart;
    let mut g = twinpath_tests::placements::Placements(SplitMix(47));
    seed(47);
    let (mut worst, mut of_ieee_class, mut worst_eps, mut capped) = (0f64, 0f64, 0f64, 0usize);
    for k in 0..cases() {
        let n = g.dir();
        let length = [1.0, 0.01, 100.0][k % 3];
        let t = if k % 3 == 0 {
            (n + g.dir() * 10f32.powf(-3.0 - 3.0 * g.unit())) * length
        } else {
            (g.dir() + n * (4.0 * g.unit() - 2.0)) * length
        };
        let texel = [g.unit(), g.unit(), g.unit()];
        let scale = [1.0, 0.0, 0.5, 2.0, 4.0, 4.0 * g.unit()][k % 6];
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        let (u, v) = (0.5 * g.unit(), 0.5 * g.unit());
        let normal = |model: Option<usize>| {
            arithmetic(model);
            let x = Vk32::new;
            let w = |a: Vec3| V3::new(x(a.x), x(a.y), x(a.z));
            let m = mapped_normal_v3(
                w(n),
                [w(t); 3],
                x(sign),
                (x(u), x(v)),
                V3::new(x(texel[0]), x(texel[1]), x(texel[2])),
                x(scale),
            );
            [m.x.value, m.y.value, m.z.value]
        };
        let cpu = normal(None);
        let device = normal(Some(k));
        let apart = mapped_normal_apart(n.to_array(), t.to_array(), sign, (u, v), texel, scale);
        // The bound devices were held to before (`gpu_functions.rs`' IEEE class): 16 eps,
        // relative to the tangent's component across the normal.
        let (nd, td) = (n.as_dvec3(), t.as_dvec3());
        let across = (td - nd * nd.dot(td)).length();
        let ieee_class = 16.0 * f32::EPSILON as f64 * (td.length() / across).max(1.0);
        for i in 0..3 {
            let d = apart_within(
                || {
                    format!("component {i} of (n {n}, t {t}, sign {sign}, bary ({u}, {v}), texel {texel:?}, scale {scale})")
                },
                cpu[i],
                device[i],
                apart[i],
            );
            worst = worst.max(d / apart[i].max(f64::MIN_POSITIVE));
            // Only a tangent within 10^-4 of parallel to the normal may lose its direction.
            if apart[i] >= 2.0 {
                capped += 1;
                assert!(across < 1e-4 * td.length(), "{n} {t}: bounded only by 2");
            }
            worst_eps = worst_eps.max(d / f32::EPSILON as f64);
            of_ieee_class = of_ieee_class.max(d / ieee_class);
        }
    }
    set_model(Model::VULKAN);
    println!("mapped normals, a device against the CPU: at most {worst:.3} of the balls' bound (largest difference {worst_eps:.1} eps), {of_ieee_class:.3} of the IEEE class's; {capped} components bounded only by 2 (the tangent's direction lost in rounding)");
}

/// The kernel's microfacet functions (the visible-normal sampler, D, G1 and the reflected
/// density, `kernel::bsdf::microfacet`) under the models of a device differ from the CPU's by
/// at most [`microfacet_apart`], the balls' bound for one IEEE and one Vulkan computation.
/// Inputs as `gpu_functions.rs` draws them: normals on, near (10^-7 to 10^-4) and off the
/// axes, roughness from 10^-3 to 1, `wo` within 10^-7 to 10^-3 radians of grazing half the
/// time, cosines 0, 1, 10^-4 and any. Some differ by more than the IEEE class's 64 ULP or 64
/// eps; the density is unbounded only where n . wo is within 10^-5 of 0 (a quotient by it).
#[test]
fn microfacet_functions_differ_from_the_cpu_within_their_balls() {
    use glam::Vec3;
    use kernel::bsdf::microfacet::{ggx_d, ggx_g1, pdf_reflected, sample_visible_normal_v3};
    use kernel::real::V3;
    use twinpath_tests::device_class::microfacet_apart;
    let mut g = twinpath_tests::placements::Placements(SplitMix(53));
    seed(53);
    let (mut worst, mut worst_eps, mut beyond_ieee_class, mut capped) = (0f64, 0f64, 0, 0);
    let mut unbounded = 0;
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for k in 0..cases() {
        let axis = axes[k % 6];
        let n = match k % 3 {
            0 => axis,
            1 => (axis + g.dir() * 10f32.powf(-7.0 + 3.0 * g.unit())).normalize(),
            _ => g.dir(),
        };
        let alpha = [1e-3, 0.05, 0.3, 1.0, 1e-3 + g.unit()][k % 5].min(1.0);
        let d = g.dir();
        let wo = if k % 2 == 0 {
            let t = (d - n * d.dot(n)).normalize_or(n.any_orthonormal_vector());
            (t + n * 10f32.powf(-7.0 + 4.0 * g.unit())).normalize()
        } else if d.dot(n) < 0.0 {
            -d
        } else {
            d
        };
        let u = g.unit();
        let cos = [0.0, 1.0, 1e-4, u, u.sqrt()][(k / 5) % 5];
        let sin2 = (1.0 - cos * cos).max(0.0);
        let (u1, u2) = (g.unit(), g.unit());
        let outputs = |model: Option<usize>| {
            arithmetic(model);
            let x = Vk32::new;
            let w = |a: Vec3| V3::new(x(a.x), x(a.y), x(a.z));
            let h = sample_visible_normal_v3(w(n), w(wo), x(alpha), x(u1), x(u2));
            [
                h.x.value,
                h.y.value,
                h.z.value,
                ggx_d(x(cos), x(sin2), x(alpha)).value,
                ggx_g1(x(cos), x(alpha)).value,
                pdf_reflected(w(n).dot(w(wo)), (x(cos), x(sin2)), x(alpha)).value,
            ]
        };
        let cpu = outputs(None);
        let device = outputs(Some(k));
        let apart = microfacet_apart(n.to_array(), alpha, wo.to_array(), (cos, sin2), (u1, u2));
        for i in 0..6 {
            if apart[i] == f64::INFINITY {
                // A quotient by a ball holding 0 (the density at n . wo within rounding of
                // 0): any value, NaN included.
                unbounded += 1;
                let cos_o = n.as_dvec3().dot(wo.as_dvec3());
                assert!(
                    i == 5 && cos_o.abs() < 1e-5,
                    "{n} {wo}: output {i} unbounded"
                );
                continue;
            }
            let d = apart_within(
                || {
                    format!(
                        "output {i} of (n {n}, alpha {alpha}, wo {wo}, cos {cos}, u ({u1}, {u2}))"
                    )
                },
                cpu[i],
                device[i],
                apart[i],
            );
            worst = worst.max(d / apart[i].max(f64::MIN_POSITIVE));
            worst_eps = worst_eps.max(d / f32::EPSILON as f64);
            capped += (i < 3 && apart[i] >= 2.0) as usize;
            // The bound devices were held to before (`gpu_functions.rs`' IEEE class): 64 ULP
            // or 64 eps, 1% relative below alpha = 0.01.
            let ulps = (cpu[i].to_bits() as i64 - device[i].to_bits() as i64).unsigned_abs();
            let loose = alpha < 0.01 && d <= 1e-2 * cpu[i].abs().max(device[i].abs()) as f64;
            beyond_ieee_class += (ulps > 64 && d > 64.0 * f32::EPSILON as f64 && !loose) as usize;
        }
    }
    set_model(Model::VULKAN);
    println!("microfacets, a device against the CPU: at most {worst:.3} of the balls' bound (largest difference {worst_eps:.1} eps); {beyond_ieee_class} outputs beyond the IEEE class's 64 ULP or 64 eps; {capped} visible-normal components bounded only by 2, {unbounded} densities unbounded (n . wo within rounding of 0)");
    assert!(
        beyond_ieee_class > 0,
        "the IEEE class's bound holds for devices"
    );
}

/// The phase function (`kernel::phase::eval_v3`, the density of every phase-sampled direction)
/// under the models of a device differs from the CPU's by at most
/// [`phase_density_apart`](twinpath_tests::device_class::phase_density_apart), the balls' bound
/// for one IEEE and one Vulkan computation; the models leave the IEEE class's (8 + 6 g /
/// (1 + g^2 - 2 g cos)) eps relative. Inputs: g over (-1, 1) with its ends and the isotropic
/// range, unit directions, a third of them within 10^-4 of the peak (wi = -wo).
#[test]
fn phase_densities_differ_from_the_cpu_within_their_balls() {
    use glam::Vec3;
    use kernel::real::V3;
    use twinpath_tests::device_class::phase_density_apart;
    let mut g_ = twinpath_tests::placements::Placements(SplitMix(61));
    seed(61);
    let (mut worst, mut beyond_ieee_class) = (0f64, 0usize);
    for k in 0..cases() {
        let g = match k % 5 {
            0 => 0.0,
            1 => 5e-4,
            2 => 0.99,
            3 => -0.99,
            _ => 0.999 * (2.0 * g_.unit() - 1.0),
        };
        let wo = g_.dir();
        let wi = if k % 3 == 0 {
            (-wo + g_.dir() * 10f32.powf(-4.0 * g_.unit())).normalize()
        } else {
            g_.dir()
        };
        let density = |model: Option<usize>| {
            arithmetic(model);
            let w = |a: Vec3| V3::new(Vk32::new(a.x), Vk32::new(a.y), Vk32::new(a.z));
            kernel::phase::eval_v3(Vk32::new(g), w(wo), w(wi)).value
        };
        let (cpu, device) = (density(None), density(Some(k)));
        let apart = phase_density_apart(g, wo.to_array(), wi.to_array());
        let d = (cpu as f64 - device as f64).abs();
        assert!(
            d <= apart,
            "(g {g}, wo {wo}, wi {wi}): CPU {cpu:e}, device {device:e}, {d:e} apart against {apart:e}"
        );
        worst = worst.max(d / apart.max(f64::MIN_POSITIVE));
        let cos = -(wi.as_dvec3().dot(wo.as_dvec3()));
        let gg = g as f64;
        let relative =
            (8.0 + 6.0 * gg.abs() / (1.0 + gg * gg - 2.0 * gg * cos)) * f32::EPSILON as f64;
        beyond_ieee_class += (d > relative * cpu.abs().max(device.abs()) as f64) as usize;
    }
    set_model(Model::VULKAN);
    println!("phase densities, a device against the CPU: at most {worst:.3} of the balls' bound; {beyond_ieee_class} beyond the IEEE class's");
    assert!(
        beyond_ieee_class > 0,
        "the IEEE class's bound holds for devices"
    );
}

/// The intersection probes (`kernel::intersect::sphere` with the hit re-projected onto the
/// sphere; `kernel::intersect::triangle` with the hit point and its error bound) under the
/// models of a device differ from the CPU's by at most [`sphere_hit_apart`] and
/// [`triangle_hit_apart`], the balls' bounds, wherever both hit; some by more than the 64 ULP
/// devices were held to before. Rays as `gpu_functions.rs` draws them: origins on a sphere,
/// inside it or far from it, directions toward it or grazing (within 10^-7 to 10^-3 of the
/// tangent plane); triangles hit anywhere, from grazing directions, and near their edges.
#[test]
fn intersections_differ_from_the_cpu_within_their_balls() {
    let mut g = SplitMix(47);
    seed(47);
    let (mut worst, mut beyond_64_ulp, mut both_hit) = (0f64, 0usize, 0usize);
    let x = Vk32::new;
    let xv = |v: glam::Vec3| kernel::real::V3::new(x(v.x), x(v.y), x(v.z));
    let mut check = |cpu: &[f32], device: &[f32], apart: &[f64], what: &str| {
        both_hit += 1;
        for i in 0..cpu.len() {
            let d = apart_within(
                || format!("{what}: output {i}"),
                cpu[i],
                device[i],
                apart[i],
            );
            if apart[i] > 0.0 && apart[i].is_finite() {
                worst = worst.max(d / apart[i]);
            }
        }
        beyond_64_ulp += (cpu[0].to_bits().abs_diff(device[0].to_bits()) > 64) as usize;
    };
    for k in 0..cases() / 4 {
        let scale = |g: &mut SplitMix| 10f32.powf(6.0 * g.unit() - 3.0);
        let vec = |g: &mut SplitMix| {
            glam::Vec3::new(g.unit() - 0.5, g.unit() - 0.5, g.unit() - 0.5) * 2.0
        };
        let grazing = |g: &mut SplitMix, n: glam::Vec3| {
            let t = (g.direction() - n * 0.5)
                .reject_from(n)
                .normalize_or(n.any_orthonormal_vector());
            let sign = if g.unit() < 0.5 { -1.0 } else { 1.0 };
            (t + n * sign * 10f32.powf(4.0 * g.unit() - 7.0)).normalize()
        };
        // A sphere.
        let r = scale(&mut g);
        let c = vec(&mut g) * scale(&mut g);
        let n = g.direction();
        let o = match k % 3 {
            0 => c + n * r,
            1 => c + vec(&mut g) * r * 0.5,
            _ => c + n * r * (1.5 + 1e4 * g.unit()),
        };
        let d = if k % 2 == 0 {
            grazing(&mut g, n)
        } else {
            (c - o + vec(&mut g) * r).normalize_or(n)
        };
        let sphere = |model: Option<usize>| {
            arithmetic(model);
            let (o, d, c) = (xv(o), xv(d), xv(c));
            sphere_probe(o, d, c, x(r), x(0.0), x(f32::INFINITY)).map(|y| y.value)
        };
        let (cpu, device) = (sphere(None), sphere(Some(k)));
        if cpu[0] >= 0.0 && device[0] >= 0.0 {
            let apart = sphere_hit_apart(o.into(), d.into(), c.into(), r, 0.0, f32::INFINITY);
            check(
                &cpu,
                &device,
                &apart,
                &format!("sphere o {o} d {d} c {c} r {r}"),
            );
        }
        // A triangle, hit anywhere or near an edge, from any direction or a grazing one.
        let s = scale(&mut g);
        let p0 = vec(&mut g) * s * 3.0;
        let (e1, e2) = (vec(&mut g) * s, vec(&mut g) * s);
        let normal = e1.cross(e2).normalize_or(glam::Vec3::Z);
        let (a, b) = if k % 4 == 0 {
            let w = g.unit();
            (w, (1.0 - w) * (1.0 - 1e-6 * g.unit()))
        } else {
            (g.unit() * 0.5, g.unit() * 0.5)
        };
        let target = p0 + e1 * a + e2 * b;
        let o = target + grazing(&mut g, normal) * s * 10.0 * g.unit();
        let d = (target - o).normalize_or(g.direction());
        let t_max = if k % 5 == 0 { 1e30 } else { f32::INFINITY };
        let triangle = |model: Option<usize>| {
            arithmetic(model);
            triangle_probe(xv(o), xv(d), xv(p0), xv(e1), xv(e2), x(t_max)).map(|y| y.value)
        };
        let (cpu, device) = (triangle(None), triangle(Some(k)));
        if cpu[0] >= 0.0 && device[0] >= 0.0 {
            let apart =
                triangle_hit_apart(o.into(), d.into(), p0.into(), e1.into(), e2.into(), t_max);
            check(
                &cpu,
                &device,
                &apart,
                &format!("triangle o {o} d {d} p0 {p0} e1 {e1} e2 {e2}"),
            );
        }
    }
    set_model(Model::VULKAN);
    println!("intersections: {both_hit} hit on both, at most {worst:.6} of their balls; {beyond_64_ulp} t beyond 64 ULP");
    assert!(
        beyond_64_ulp > 0,
        "the models never leave the former 64 ULP"
    );
}

/// `bsdf::eval` and `bsdf::sample` as a whole (every material kind the probe builds: the
/// Lambertian, the Kd + Ks mixture, conductors with a complex index or a constant reflectance,
/// glass, and glTF's material with its coloured layer, clear coat and sheen, resolved on the
/// device), run by the kernel's own generic code under the models of a device, differ from the
/// CPU's by at most [`bsdf_apart`], the balls' bound for one IEEE and one Vulkan computation.
/// Records as `gpu_functions.rs` draws them: normals on, near (10^-7 to 10^-4) and off the
/// axes, roughness 0, 10^-3, 0.05, 0.3, 1 and any, index ratios 1.5, 1 / 1.5 and 1.0001, `wo`
/// and `wi` within 10^-7 to 10^-3 radians of grazing half the time. Some outputs differ by more
/// than the IEEE class's bound (64 ULP or 64 eps for eval, 2048 ULP or 64 eps for sample, with
/// its relative allowance on sharp lobes and index-matched glass), which is why devices are held
/// to the balls.
#[test]
fn bsdfs_differ_from_the_cpu_within_their_balls() {
    use glam::Vec3;
    use twinpath_tests::device_class::{bsdf_apart, BsdfRecord};
    let mut g = twinpath_tests::placements::Placements(SplitMix(59));
    seed(59);
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    let dir = |g: &mut twinpath_tests::placements::Placements, k: usize| match k % 3 {
        0 => axes[(k / 3) % 6],
        1 => (axes[(k / 3) % 6] + g.dir() * 10f32.powf(-7.0 + 3.0 * g.unit())).normalize(),
        _ => g.dir(),
    };
    let grazing = |g: &mut twinpath_tests::placements::Placements, n: Vec3, d: Vec3| {
        if g.unit() < 0.5 {
            let t = (d - n * d.dot(n)).normalize_or(n.any_orthonormal_vector());
            let side = if g.unit() < 0.5 { 1.0 } else { -1.0 };
            (t + n * side * 10f32.powf(-7.0 + 4.0 * g.unit())).normalize()
        } else {
            d
        }
    };
    let (mut worst, mut beyond_ieee_class, mut unbounded, mut outputs) = (0f64, 0, 0, 0);
    let mut worst_at = String::new();
    for k in 0..cases() {
        let n = dir(&mut g, k);
        let alpha = [0.0, 1e-3, 0.05, 0.3, 1.0, 1e-3 + g.unit()][(k / 2) % 6].min(1.0);
        let eta = [1.5, 1.0 / 1.5, 1.0001][(k / 12) % 3];
        let d = g.dir();
        let wo = grazing(&mut g, n, d);
        let wo = if wo.dot(n) < 0.0 { -wo } else { wo };
        let sample = k % 2 == 1;
        let third = if sample {
            [g.unit(), g.unit(), g.unit()]
        } else {
            let d = g.dir();
            grazing(&mut g, n, d).to_array()
        };
        let e = [
            (1.0, 1.0),
            (0.3, 0.37),
            (0.3 + 0.7 * g.unit(), 0.37 + 0.63 * g.unit()),
        ][k % 3];
        let r = BsdfRecord {
            sample,
            kind: ((k / 36) % 5) as u32,
            complex: ((k / 180) % 8) as u32,
            coat: kernel::scene::Material::pack_coat(0.8, alpha.sqrt()),
            n: n.to_array(),
            alpha,
            wo: wo.to_array(),
            eta,
            third,
            albedo: e,
        };
        let (cpu, device) = cpu_and_device(&r, k);
        // No NaN, no negative value or weight, a positive eta^2, under any arithmetic: what
        // the path multiplies its throughput by stays a number (the same checks as
        // `properties.rs` makes of the CPU's).
        for (i, x) in device.iter().enumerate() {
            assert!(!x.is_nan(), "output {i} of {r:?} NaN on a device");
            let non_negative = if sample { (3..7).contains(&i) } else { i < 4 };
            assert!(
                !non_negative || *x >= 0.0,
                "output {i} of {r:?}: {x} on a device"
            );
        }
        assert!(!sample || device[7] > 0.0, "eta^2 {} of {r:?}", device[7]);
        let apart = bsdf_apart(&r);
        let one_way = [Roundoff::IEEE, Roundoff::VULKAN]
            .into_iter()
            .all(|a| computations(a, &|| r.outputs::<Ball>()).len() == 1);
        let sharp =
            alpha < if sample { 0.045 } else { 0.01 } || (r.kind == 3 && (eta - 1.0).abs() < 1e-3);
        for i in 0..8 {
            outputs += 1;
            if apart[i] == f64::INFINITY {
                unbounded += 1;
                continue;
            }
            // Equal (a delta lobe's infinite density in both) is not apart.
            let d = apart_within(
                || format!("output {i} of {r:?}"),
                cpu[i],
                device[i],
                apart[i],
            );
            // Where neither arithmetic has an uncertain test (one way each), how close the
            // models come to the balls says how tight they are; elsewhere the bound is the
            // distance between ways, which a model meets by taking the other one.
            if one_way && d / apart[i].max(f64::MIN_POSITIVE) > worst {
                worst = d / apart[i].max(f64::MIN_POSITIVE);
                worst_at = format!(
                    "output {i} of {r:?}: CPU {:e}, device {:e}, bound {:e}",
                    cpu[i], device[i], apart[i]
                );
            }
            // The bound devices were held to before (`gpu_functions.rs`' IEEE class).
            let ulps = (cpu[i].to_bits() as i64 - device[i].to_bits() as i64).unsigned_abs();
            let max_ulps = if sample { 2048 } else { 64 };
            let relative = if sample { 5e-2 } else { 1e-2 };
            let loose = sharp && d <= relative * cpu[i].abs().max(device[i].abs()) as f64;
            beyond_ieee_class +=
                (ulps > max_ulps && d > 64.0 * f32::EPSILON as f64 && !loose) as usize;
        }
    }
    set_model(Model::VULKAN);
    println!("bsdf::eval and bsdf::sample, a device against the CPU: at most {worst:.3} of the balls' bound where each arithmetic has one way ({worst_at}); {beyond_ieee_class} of {outputs} outputs beyond the IEEE class's bound; {unbounded} unbounded");
    assert!(
        beyond_ieee_class > 0,
        "the IEEE class's bound holds for devices"
    );
    assert!(
        unbounded * 20 < outputs,
        "{unbounded} of {outputs} outputs unbounded: the balls say too little"
    );
}

/// The point and spot light's sample (its direction, density and falloff) and the directional
/// light's far point (`kernel::light::punctual`, `directional`) under the models of a device
/// differ from the CPU's by at most [`punctual_apart`], the balls' bound for one IEEE and one
/// Vulkan computation. Records as `gpu_functions.rs` draws them (`ProbeInputs::punctual_record`):
/// receivers and lights 10^-6 to
/// 10^6 apart and from the origin, receivers at the light, point lights and spots whose cones
/// are 10^-4 to 1 apart in cosine. The falloff near a narrow transition moves by its slope
/// times the cosine's rounding, beyond the IEEE class's 8 eps times its magnitudes.
#[test]
fn punctual_lights_differ_from_the_cpu_within_their_balls() {
    use twinpath_tests::device_class::punctual_apart;
    let mut g = ProbeInputs(SplitMix(67));
    seed(67);
    let (mut worst, mut beyond_ieee_class, mut outputs) = (0f64, 0, 0);
    for k in 0..cases() {
        let r = g.punctual_record();
        let (spot, x) = (r.spot, glam::Vec3::from(r.x));
        let centre = glam::Vec3::new(r.bounds[0], r.bounds[1], r.bounds[2]);
        let (cpu, device) = cpu_and_device(&r, k);
        let apart = punctual_apart(&r);
        for i in 0..8 {
            outputs += 1;
            assert!(apart[i].is_finite(), "output {i} of {r:?} unbounded");
            let d = apart_within(
                || format!("output {i} of {r:?}"),
                cpu[i],
                device[i],
                apart[i],
            );
            worst = worst.max(d / apart[i].max(f64::MIN_POSITIVE));
            // The bound devices were held to before (`gpu_functions.rs`' IEEE class).
            let eps = f32::EPSILON as f64;
            let ieee_class = match i {
                4 => 8.0 * eps * (1.0 + spot.0.abs() as f64 + spot.1.abs() as f64),
                5..=7 => {
                    let to_centre = (x - centre).length() as f64;
                    8.0 * eps * (x.length() as f64 + 2.0 * (r.bounds[3] as f64 + to_centre))
                }
                _ => 8.0 * eps,
            };
            let ulps = (cpu[i].to_bits() as i64 - device[i].to_bits() as i64).unsigned_abs();
            beyond_ieee_class += (ulps > 8 && d > ieee_class) as usize;
        }
    }
    set_model(Model::VULKAN);
    println!("punctual and directional lights, a device against the CPU: at most {worst:.3} of the balls' bound; {beyond_ieee_class} of {outputs} outputs beyond the IEEE class's bound");
    assert!(
        beyond_ieee_class > 0,
        "the IEEE class's bound holds for devices"
    );
}

/// The environment map's sample within a texel (its direction and density) and its look-up of
/// a direction (map coordinates, sin theta and the texel read: `kernel::environment`, through
/// `kernel::probe::probe_environment`) under the models of a device differ from the CPU's by at
/// most [`environment_apart`], the balls' bound for one IEEE and one Vulkan computation; and
/// the density a sample carries is finite and positive along every way a Vulkan computation
/// may take (so no light sample of the map is lost or divides by 0 on any device). Records as
/// `gpu_functions.rs` draws them (`ProbeInputs::environment_record`): maps of 1 to 2048 texels
/// a side, rotated or not, the drawn
/// bins wide, narrow (down to 10^-7) and whole, directions on and near the axes (the poles, the
/// seam). A texel's look-up within rounding of its edge, or of the seam, reads either side on a
/// device, beyond the IEEE class's 8 eps.
#[test]
fn environment_samples_differ_from_the_cpu_within_their_balls() {
    use twinpath_tests::device_class::environment_apart;
    let mut g = ProbeInputs(SplitMix(71));
    seed(71);
    let (mut worst, mut beyond_ieee_class, mut outputs, mut other_texel) = (0f64, 0, 0, 0);
    let mut unbounded = [0usize; 8];
    let mut beyond_per_output = [0usize; 8];
    for k in 0..cases() {
        let r = g.environment_record();
        for way in computations(Roundoff::VULKAN, &|| r.outputs::<Ball>()) {
            let pdf = way[3];
            assert!(
                pdf.radius.is_finite() && pdf.mid - pdf.radius > 0.0,
                "the density drawn for {r:?} may be {pdf:?} on a device"
            );
        }
        let (cpu, device) = cpu_and_device(&r, k);
        let apart = environment_apart(&r);
        other_texel += (cpu[7] != device[7]) as usize;
        for i in 0..8 {
            outputs += 1;
            let d = apart_within(
                || format!("output {i} of {r:?}"),
                cpu[i],
                device[i],
                apart[i],
            );
            // (The texel's index is apart by a whole texel or not at all.)
            if apart[i].is_finite() && i < 7 {
                worst = worst.max(d / apart[i].max(f64::MIN_POSITIVE));
            }
            unbounded[i] += apart[i].is_infinite() as usize;
            // The bound devices were held to before (`gpu_functions.rs`' IEEE class).
            let ulps = (cpu[i].to_bits() as i64 - device[i].to_bits() as i64).unsigned_abs();
            let beyond = ulps > 8 && d > 8.0 * f32::EPSILON as f64;
            beyond_ieee_class += beyond as usize;
            beyond_per_output[i] += beyond as usize;
        }
    }
    set_model(Model::VULKAN);
    println!(
        "environment map: outputs beyond the IEEE class's bound, per output {beyond_per_output:?}"
    );
    println!("environment map, a device against the CPU: at most {worst:.3} of the balls' bound; {beyond_ieee_class} of {outputs} outputs beyond the IEEE class's bound; {other_texel} look-ups in another texel; unbounded per output {unbounded:?}");
    assert!(
        beyond_ieee_class > 0,
        "the IEEE class's bound holds for devices"
    );
}
