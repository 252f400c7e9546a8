//! Normal maps' tangent frames (`kernel::surface::mapped_normal_v3`) under Vulkan's arithmetic:
//! a tangent within rounding of the normal it stands on has no direction across it, and every
//! arithmetic must agree on that. Gram-Schmidt leaves t - n (n . t), which there is rounding
//! only: a frame built on it points wherever the rounding does, so the CPU and a device would
//! map the point to unrelated normals (the H200 did, on tangents parallel to the normal:
//! `docs/gpu.md`). The kernel leaves such a point unmapped (`MIN_TANGENT_SINE`).

use super::{any_device, back, cases, f, v};
use kernel::surface::mapped_normal_v3;
use twinpath_tests::placements::Placements as Gen;
use twinpath_tests::vulkan_arithmetic::{set_model, Model};
use twinpath_tests::SplitMix;

/// Tangents along the normal (either way, 0.01 to 100 long) moved off it by up to 8 eps of
/// their length, in any direction, with any texel, scale and handedness: under IEEE arithmetic
/// and every model of a device, the mapped normal is the base normal itself, bit for bit.
#[test]
fn tangents_within_rounding_of_the_normal_leave_the_point_unmapped_under_every_arithmetic() {
    let mut g = Gen(SplitMix(113));
    let eps = f32::EPSILON;
    for k in 0..cases() / 4 {
        let n = g.dir();
        let length = [1.0, 0.01, 100.0][k % 3] * if k % 2 == 0 { 1.0 } else { -1.0 };
        let t = (n + g.dir() * (8.0 * eps * g.unit())) * length;
        let texel = glam::Vec3::new(g.unit(), g.unit(), g.unit());
        let (scale, sign) = (4.0 * g.unit(), if g.unit() < 0.5 { 1.0 } else { -1.0 });
        let (u, w) = (0.5 * g.unit(), 0.5 * g.unit());
        for model in 0..4 {
            if model == 0 {
                set_model(Model::IEEE);
            } else {
                any_device(model - 1);
            }
            let m = mapped_normal_v3(v(n), [v(t); 3], f(sign), (f(u), f(w)), v(texel), f(scale));
            assert_eq!(back(m), n, "model {model}: n {n}, t {t}");
        }
    }
    set_model(Model::VULKAN);
}
