//! The media's free flights under Vulkan's `log`: the unit exponential number -ln(1 - u) that
//! every flight distance and every delta-tracking step is drawn from
//! (`kernel::free_flight::unit_exponential`) is never negative and stays within the error
//! `tests/tests/gpu_functions.rs` allows a device's flights, for every number the kernel's
//! random streams give (`kernel::rng::u32_to_unit_f32`: (k + 1/2) 2^-23).

use super::{any_device, f};
use kernel::free_flight::unit_exponential;
use kernel::real::Exponential;
use kernel::rng::u32_to_unit_f32;
use twinpath_tests::vulkan_arithmetic::{set_model, Model};
use twinpath_tests::SplitMix;

/// The uniform numbers to try: the smallest and largest few the streams give (where 1 - u is
/// nearest 1, and where the logarithm is largest), every power of two between, and random ones.
fn numbers() -> Vec<f32> {
    let mut k: Vec<u32> = (0..64).chain((1u32 << 23) - 64..1 << 23).collect();
    k.extend((0..23).map(|e| 1 << e));
    let mut g = SplitMix(71);
    k.extend((0..100_000).map(|_| (g.u64() >> 41) as u32));
    k.into_iter().map(|k| u32_to_unit_f32(k << 9)).collect()
}

#[test]
fn flights_never_run_backwards_and_stay_within_their_error_under_vulkan_arithmetic() {
    let eps = f32::EPSILON as f64;
    let (mut worst_of_bound, mut backwards_unclamped, mut tried) = (0f64, 0usize, 0usize);
    for case in 0..3 {
        any_device(case);
        for &u in &numbers() {
            // What the kernel computes on such a device, and the same numbers without the clamp.
            let t = unit_exponential(f(u)).value;
            let raw = -(f(1.0) - f(u)).ln().value;
            backwards_unclamped += (raw < 0.0) as usize;
            tried += 1;
            assert!(t >= 0.0 && t.is_finite(), "u = {u}: -ln(1 - u) = {t}");
            // 1 - u is exact for the streams' numbers ((2^24 - 2k - 1) 2^-24 in any rounding),
            // and `log` errs by 2^-21 absolutely on [0.5, 2] or 3 ULP beyond
            // (docs/robustness.md); the clamp only moves a negative result toward the exact
            // one, which is positive.
            let exact = -(-(u as f64)).ln_1p();
            let bound = 2f64.powi(-21) + 3.0 * eps * exact;
            let off = (t as f64 - exact).abs();
            assert!(off <= bound, "u = {u}: {t} against {exact}, bound {bound}");
            worst_of_bound = worst_of_bound.max(off / bound);
        }
    }
    println!(
        "{tried} flights: the largest error {worst_of_bound:.3} of the bound; \
         {backwards_unclamped} would run backwards without the clamp"
    );
    // The test can fail: such a device does return positive logarithms just below 1, which the
    // kernel's clamp turns into a flight of length 0.
    assert!(backwards_unclamped > 0);

    // IEEE arithmetic: the f32 kernel's numbers bit for bit, none negative, none clamped.
    set_model(Model::IEEE);
    for &u in &numbers() {
        let t = unit_exponential(f(u)).value;
        assert_eq!(t.to_bits(), unit_exponential(u).to_bits(), "u = {u}");
        assert_eq!(t, -(1.0 - u).ln(), "u = {u}");
        assert!(-(1.0 - u).ln() >= 0.0);
    }
    set_model(Model::VULKAN);
}

/// The exact flight (in `f64`, u's logarithm exact) of the same inputs as
/// `kernel::free_flight::sample_v3`: whether it collides, its t, weight and ratios.
fn exact_flight(
    sigma_t: [f64; 3],
    sigma_s: [f64; 3],
    d: f64,
    hero: usize,
    u: f64,
    ratios: [f64; 3],
) -> (bool, f64, [f64; 3], [f64; 3]) {
    let t = -(-u).ln_1p() / sigma_t[hero];
    let scattered = t < d;
    let at = if scattered { t } else { d };
    let tr = sigma_t.map(|s| (-s * at).exp());
    let p: [f64; 3] = std::array::from_fn(|k| if scattered { sigma_t[k] * tr[k] } else { tr[k] });
    let f: [f64; 3] = std::array::from_fn(|k| if scattered { sigma_s[k] * tr[k] } else { tr[k] });
    let q: [f64; 3] = std::array::from_fn(|k| ratios[k] * p[k]);
    let m = (q[0] + q[1] + q[2]) / 3.0;
    (scattered, at, f.map(|x| x / m), q.map(|x| x / m))
}

/// Free flights in a homogeneous medium (`free_flight::sample_v3`: the distance, the
/// transmittances, the weight and the technique ratios) under IEEE arithmetic and every Vulkan
/// model are within their derived errors of the exact flight (docs/robustness.md, "The media's
/// flights"): t within (2^-21 / sigma_h + 3 eps t)(1 + 2.5 eps) + 2.5 eps t (the logarithm's
/// absolute error near 1, its 3 ULP beyond, the division's 2.5 ULP; 1 - u is exact for the
/// streams' numbers), and each weight
/// and ratio relatively within 2 (sigma_max 2^-21 / sigma_h + (3 + 8.5 x) eps) + 10 eps, x the
/// largest exponent sigma_k t: each exponent carries t's error times sigma_k, its product's
/// rounding (x eps) and exp's 3 + 2 x ULP, and a weight is a quotient of such transmittances
/// through a mean (products, two sums, a division). The same flights against the CPU's are
/// within what `gpu_functions.rs` allows a device (its MEDIUM bounds, derived by hand per record).
#[test]
fn flights_are_within_their_error_of_the_exact_flight_under_every_arithmetic() {
    use kernel::free_flight::sample_v3;
    use kernel::real::V3;
    let eps = f32::EPSILON as f64;
    let mut g = SplitMix(72);
    let log_uniform = |g: &mut SplitMix, lo: f32, hi: f32| lo * (hi / lo).powf(g.unit());
    let (mut worst_t, mut worst_w, mut tried) = (0f64, 0f64, 0usize);
    let (mut worst_gpu_t, mut worst_gpu_w) = (0f64, 0f64);
    for case in 0..4 * 50_000 {
        let sigma_t: [f32; 3] = std::array::from_fn(|_| log_uniform(&mut g, 1e-3, 1e2));
        let sigma_s: [f32; 3] = std::array::from_fn(|k| sigma_t[k] * g.unit());
        let d = if g.unit() < 0.25 {
            f32::MAX
        } else {
            log_uniform(&mut g, 1e-3, 1e3)
        };
        let hero = (g.u64() % 3) as usize;
        let u = u32_to_unit_f32(g.u64() as u32);
        let ratios: [f32; 3] = if g.unit() < 0.5 {
            [1.0; 3]
        } else {
            let r: [f32; 3] = std::array::from_fn(|_| 0.2 + 2.6 * g.unit());
            let mean = (r[0] + r[1] + r[2]) / 3.0;
            r.map(|x| x / mean)
        };
        let wide = |a: [f32; 3]| a.map(|x| x as f64);
        let (scattered, t, weight, new_ratios) = exact_flight(
            wide(sigma_t),
            wide(sigma_s),
            d as f64,
            hero,
            u as f64,
            wide(ratios),
        );
        let sigma_h = sigma_t[hero] as f64;
        let sigma_max = wide(sigma_t).into_iter().fold(0.0, f64::max);
        let x = wide(sigma_t).iter().map(|s| s * t).fold(0.0, f64::max);
        let dt = (2f64.powi(-21) / sigma_h + 3.0 * eps * t) * (1.0 + 2.5 * eps) + 2.5 * eps * t;
        // Beyond exponent 80 transmittances near the smallest normal float, which a device may
        // flush; and within dt of the surface a device may decide the other way.
        if x > 80.0 || (d as f64 - t).abs() <= 2.0 * dt && scattered {
            continue;
        }
        if case % 4 == 0 {
            set_model(Model::IEEE);
        } else {
            any_device(case % 4 - 1);
        }
        let v = |a: [f32; 3]| V3::new(f(a[0]), f(a[1]), f(a[2]));
        let flight = sample_v3(v(sigma_t), v(sigma_s), f(d), hero as u32, f(u), v(ratios));
        tried += 1;
        assert_eq!(
            flight.scattered != 0,
            scattered,
            "case {case}: t {t} against d {d}"
        );
        let t_off = (flight.t.value as f64 - t).abs();
        assert!(
            t_off <= dt,
            "case {case}: t {} against {t}, bound {dt}",
            flight.t.value
        );
        worst_t = worst_t.max(t_off / dt);
        // What `gpu_functions.rs` allows a device against the CPU (`allowed_abs`, MEDIUM).
        let cpu = kernel::free_flight::sample(
            sigma_t.into(),
            sigma_s.into(),
            d,
            hero as u32,
            u,
            ratios.into(),
        );
        let ln = (1.0 - u as f64).ln();
        let gpu_dt = (2f64.powi(-21) + 3.0 * eps * ln.abs()) / sigma_h;
        let gpu_t = gpu_dt + 2.0 * eps * flight.t.value as f64;
        let t_apart = (flight.t.value as f64 - cpu.t as f64).abs();
        worst_gpu_t = worst_gpu_t.max(t_apart / gpu_t);
        let gpu_rel = 2.0 * (sigma_max * gpu_dt + (3.0 + 2.0 * x.min(88.0)) * eps) + 8.0 * eps;
        let values =
            |w: V3<twinpath_tests::vulkan_arithmetic::Vk32>| [w.x.value, w.y.value, w.z.value];
        let device_weight = values(flight.weight);
        for (w, w_cpu) in device_weight.into_iter().zip(cpu.weight.to_array()) {
            let allowed = (w as f64 * gpu_rel).max(3e-25);
            worst_gpu_w = worst_gpu_w.max((w - w_cpu).abs() as f64 / allowed);
        }
        let rel = 2.0 * (sigma_max * 2f64.powi(-21) / sigma_h + (3.0 + 8.5 * x) * eps) + 10.0 * eps;
        for (name, got, exact) in [
            ("weight", device_weight, weight),
            ("ratios", values(flight.ratios), new_ratios),
        ] {
            for k in 0..3 {
                // Relative, or absolute where the exact value is 0 (no scattering in a channel).
                let off = if exact[k] == 0.0 {
                    got[k].abs() as f64
                } else {
                    (got[k] as f64 - exact[k]).abs() / exact[k].abs()
                };
                assert!(
                    off <= rel,
                    "case {case}: {name}[{k}] {} against {}, relative {off:e}, bound {rel:e}",
                    got[k],
                    exact[k]
                );
                worst_w = worst_w.max(off / rel);
            }
        }
    }
    set_model(Model::VULKAN);
    println!(
        "{tried} flights: t at most {worst_t:.3} of its bound, weights and ratios {worst_w:.3} of theirs; \
         against the CPU, of gpu_functions' bounds: t {worst_gpu_t:.3}, weights {worst_gpu_w:.3}"
    );
    assert!(tried > 100_000);
    // So the equivalence test's bounds hold for every device this model stands for.
    assert!(worst_gpu_t <= 1.0 && worst_gpu_w <= 1.0);
}
