//! Image textures under a Vulkan device's arithmetic: the bilinear footprint (the wrapped
//! coordinate, the texel pair and the weight along each axis: `kernel::texture::footprint_of`)
//! and the blend (`bilerp_of`), run on [`Vk32`] as the GPU probe computes them, held to the
//! bound `gpu_functions.rs` holds a Vulkan-class device to (`device_class::texture_apart`,
//! derived by hand in its documentation): the texel indices and fx equal, and within u (4 n +
//! 1/2), unless the texel coordinate lies within the two computations' rounding of a texel
//! boundary; the blend of the probe's image (`kernel::probe::probe_image`, a value per texel)
//! within 9 u + 2 (dx + dy) everywhere, boundaries included (the blend is continuous there).

use super::{f, use_model};
use kernel::probe::probe_image;
use kernel::real::V3;
use kernel::texture::{bilerp, bilerp_of, footprint, footprint_of, wrap};
use twinpath_tests::device_class::texture_apart;
use twinpath_tests::vulkan_arithmetic::{seed, Vk32};
use twinpath_tests::SplitMix;

/// A texture coordinate: uniform over three periods (a third of them), near a texel centre
/// boundary of an image `n` texels wide (within a few ULP, a third), or far out (10^3, the
/// rest, with an occasional exact 0, 1 or non-finite value).
fn coordinate(g: &mut SplitMix, n: u32) -> f32 {
    match g.u64() % 20 {
        0 => [0.0, 1.0, -1.0, 0.5, f32::NAN, f32::INFINITY][(g.u64() % 6) as usize],
        1..=7 => 6.0 * g.unit() - 3.0,
        8..=14 => {
            let k = (g.u64() % (3 * n as u64 + 1)) as f32 - n as f32;
            let mut x = k / n as f32 + (if g.unit() < 0.5 { 0.0 } else { 0.5 / n as f32 });
            for _ in 0..g.u64() % 8 {
                x = if g.unit() < 0.5 {
                    x.next_up()
                } else {
                    x.next_down()
                };
            }
            x
        }
        _ => (g.unit() - 0.5) * 2e3,
    }
}

#[test]
fn texture_footprints_and_blends_stay_within_their_vulkan_bound() {
    let cases = super::cases();
    let mut g = SplitMix(0x7465_7874);
    let modes = [wrap::REPEAT, wrap::CLAMP, wrap::MIRROR];
    let (mut checked, mut unchecked, mut apart) = (0usize, 0usize, 0usize);
    let mut worst = [0.0f64; 2]; // of the blend's and of fx's bound
    for case in 0..cases {
        let size = |g: &mut SplitMix| 10f32.powf(g.unit() * 3.6).round().max(1.0) as u32;
        let (width, height) = (size(&mut g), size(&mut g));
        let (wrap_u, wrap_v) = (modes[(g.u64() % 3) as usize], modes[(g.u64() % 3) as usize]);
        let (u, v) = (coordinate(&mut g, width), coordinate(&mut g, height));
        let key = [g.u64() as u32, g.u64() as u32];
        let image = |x: u32, y: u32| probe_image(key[0], key[1], x, y);
        // The CPU: the kernel's f32 functions, as `kernel::probe` calls them.
        let cpu = footprint(glam::Vec2::new(u, v), width, height, wrap_u, wrap_v);
        let corners = |x0: u32, x1: u32, y0: u32, y1: u32| {
            [image(x0, y0), image(x1, y0), image(x0, y1), image(x1, y1)]
        };
        let c = corners(cpu.x0, cpu.x1, cpu.y0, cpu.y1);
        let cpu_blend = bilerp(c[0], c[1], c[2], c[3], cpu.fx, cpu.fy);
        let bound = texture_apart([u, v], width, height, wrap_u, wrap_v);
        for model in 1..4 {
            use_model(model);
            seed((case * 4 + model) as u64);
            let device = footprint_of(f(u), f(v), width, height, wrap_u, wrap_v);
            let c = corners(device.x0, device.x1, device.y0, device.y1);
            let cv = c.map(|c| V3::<Vk32>::new(f(c.x), f(c.y), f(c.z)));
            let blend = bilerp_of(cv[0], cv[1], cv[2], cv[3], device.fx, device.fy);
            let device_indices = [device.x0, device.x1, device.y0, device.y1];
            let cpu_indices = [cpu.x0, cpu.x1, cpu.y0, cpu.y1];
            for (k, (&a, &b)) in device_indices.iter().zip(&cpu_indices).enumerate() {
                assert!(
                    a == b || bound[k].is_infinite(),
                    "model {model}: index {k} {a} against the CPU's {b}: uv ({u}, {v}), \
                     {width} x {height}, wrap ({wrap_u}, {wrap_v})"
                );
            }
            let blend = [blend.x.value, blend.y.value, blend.z.value];
            let outputs = [
                (blend[0], cpu_blend.x, bound[4], 0),
                (blend[1], cpu_blend.y, bound[5], 0),
                (blend[2], cpu_blend.z, bound[6], 0),
                (device.fx.value, cpu.fx, bound[7], 1),
            ];
            for (device, cpu, bound, which) in outputs {
                if bound.is_infinite() {
                    unchecked += 1;
                    continue;
                }
                checked += 1;
                let d = (device as f64 - cpu as f64).abs();
                apart += (d > 0.0) as usize;
                worst[which] = worst[which].max(d / bound);
                assert!(
                    d <= bound,
                    "model {model}: {device} against the CPU's {cpu} ({d:e} apart, bound \
                     {bound:e}): uv ({u}, {v}), {width} x {height}, wrap ({wrap_u}, {wrap_v})"
                );
            }
        }
    }
    println!(
        "{checked} outputs checked ({unchecked} at a texel boundary, unchecked): the blend at \
         most {:.3} of its bound, fx {:.3}; {apart} differ from the CPU's",
        worst[0], worst[1]
    );
    // The models must take their liberties (the bound of an IEEE device, bit for bit, fails
    // on every output counted here), and most outputs must be checked: only fx goes unchecked,
    // at a boundary, and the coordinates near one are a third of the cases.
    assert!(
        apart > checked / 100,
        "only {apart} of {checked} outputs differ"
    );
    assert!(
        unchecked < checked / 8,
        "{unchecked} unchecked against {checked}"
    );
}
