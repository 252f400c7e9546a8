//! The media's free flights under Vulkan's `log`: the unit exponential number -ln(1 - u) that
//! every flight distance and every delta-tracking step is drawn from
//! (`kernel::free_flight::unit_exponential`) is never negative and stays within the error
//! `tests/tests/gpu_functions.rs` allows a device's flights, for every number the kernel's
//! random streams give (`kernel::rng::u32_to_unit_f32`: (k + 1/2) 2^-23).

use super::{any_device, f};
use kernel::free_flight::unit_exponential;
use kernel::real::Logarithm;
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
            // 1 - u rounds by at most eps relatively (so ln moves by eps), and `log` errs by
            // 2^-21 absolutely on [0.5, 2] or 3 ULP beyond (docs/robustness.md); the clamp only
            // moves a negative result toward the exact one, which is positive.
            let exact = -(-(u as f64)).ln_1p();
            let bound = 2f64.powi(-21) + eps + 3.0 * eps * exact;
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
