//! A device's own world-to-object map: Vulkan takes only an instance's `object_to_world`
//! ("Ray Traversal" asks only that it be invertible) and leaves how the implementation inverts
//! it unspecified. Lavapipe inverts the 4 x 4 matrix in `f32` by Gaussian elimination with
//! partial pivoting (Mesa's `util_invert_mat4x4`); [`gaussian_elimination_inverse`] does the
//! same kind of computation (not its operation order), so that the tests can map rays back as
//! such a device does instead of by the stored inverse, which is rounded from an `f64` one.
//! RADV and ANV invert it on the GPU, in their acceleration-structure build shaders, by GLSL's
//! `inverse()`, which Mesa's compiler expands as the adjugate over the determinant;
//! [`adjugate_inverse`] computes that way, over any arithmetic (the tests run it under
//! `vulkan_arithmetic::Vk32`, the arithmetic such a shader has).

use std::ops::{Add, Div, Mul, Sub};

/// The inverse of the affine map `object_to_world` (3 x 4, row-major, `[linear | translation]`,
/// as `kernel::scene::Instance` stores it), in the same layout, computed in `f32`: the 4 x 4
/// matrix with bottom row (0, 0, 0, 1) reduced by Gauss-Jordan elimination with partial
/// pivoting (each column's largest remaining entry is the pivot), the identity carried along.
pub fn gaussian_elimination_inverse(object_to_world: &[f32; 12]) -> [f32; 12] {
    let mut rows = [[0f32; 8]; 4];
    for (i, row) in rows.iter_mut().enumerate() {
        if i < 3 {
            row[..4].copy_from_slice(&object_to_world[4 * i..4 * i + 4]);
        } else {
            row[3] = 1.0;
        }
        row[4 + i] = 1.0;
    }
    for c in 0..4 {
        let pivot = (c..4)
            .max_by(|&a, &b| rows[a][c].abs().total_cmp(&rows[b][c].abs()))
            .unwrap_or(c);
        rows.swap(c, pivot);
        let pivot_row = rows[c];
        for row in rows.iter_mut().skip(c + 1) {
            let factor = row[c] / pivot_row[c];
            for (x, p) in row.iter_mut().zip(pivot_row).skip(c) {
                *x -= factor * p;
            }
        }
    }
    for c in (0..4).rev() {
        let scale = 1.0 / rows[c][c];
        for x in rows[c].iter_mut() {
            *x *= scale;
        }
        let pivot_row = rows[c];
        for row in rows.iter_mut().take(c) {
            let factor = row[c];
            for (x, p) in row.iter_mut().zip(pivot_row) {
                *x -= factor * p;
            }
        }
    }
    let mut inverse = [0f32; 12];
    for i in 0..3 {
        inverse[4 * i..4 * i + 4].copy_from_slice(&rows[i][4..]);
    }
    inverse
}

/// The inverse of the affine map `object_to_world` (layout as for
/// [`gaussian_elimination_inverse`]) as the adjugate of the 4 x 4 matrix (bottom row
/// (0, 0, 0, 1)) times the reciprocal of its determinant, computed in `T`: the twelve 2 x 2
/// minors of the top two rows and of the bottom two (Laplace's expansion by complementary
/// minors), the determinant as the sum of their six products, each entry of the adjugate as
/// three products of an entry with a minor. No pivoting: its error grows with the products of
/// the entries over the determinant, not only with the condition number.
pub fn adjugate_inverse<T>(object_to_world: &[f32; 12]) -> [f32; 12]
where
    T: Copy + From<f32> + Add<Output = T> + Sub<Output = T> + Mul<Output = T> + Div<Output = T>,
    f32: From<T>,
{
    let m = object_to_world;
    let e = |r: usize, c: usize| -> T {
        T::from(match r {
            3 => [0.0, 0.0, 0.0, 1.0][c],
            _ => m[4 * r + c],
        })
    };
    let minor = |r: usize, (c, d): (usize, usize)| e(r, c) * e(r + 1, d) - e(r + 1, c) * e(r, d);
    let pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
    let top = pairs.map(|p| minor(0, p));
    let bottom = pairs.map(|p| minor(2, p));
    // Each pair's complement among the four columns is pairs[5 - i], with the sign of the
    // permutation (pairs 1 and 4 odd).
    let det = top[0] * bottom[5] - top[1] * bottom[4] + top[2] * bottom[3] + top[3] * bottom[2]
        - top[4] * bottom[1]
        + top[5] * bottom[0];
    let reciprocal = T::from(1.0) / det;
    // Entry (i, j) of the inverse is the cofactor of (j, i) over the determinant: (-1)^(i + j)
    // times the minor without row j and column i, expanded along the row that row j was paired
    // with (the first row left for j = 0, 1; the last for j = 2, 3, whose cofactor signs run
    // +, -, + either way) against the other pair's 2 x 2 minors.
    let index = |a: usize, b: usize| pairs.iter().position(|&p| p == (a, b)).unwrap();
    let cofactor = |j: usize, i: usize| -> T {
        let (row, minors) = match j {
            0 => (1, &bottom),
            1 => (0, &bottom),
            2 => (3, &top),
            _ => (2, &top),
        };
        let c: Vec<usize> = (0..4).filter(|&c| c != i).collect();
        let expansion = e(row, c[0]) * minors[index(c[1], c[2])]
            - e(row, c[1]) * minors[index(c[0], c[2])]
            + e(row, c[2]) * minors[index(c[0], c[1])];
        if (i + j) % 2 == 1 {
            T::from(0.0) - expansion
        } else {
            expansion
        }
    };
    let mut inverse = [0f32; 12];
    for i in 0..3 {
        for j in 0..4 {
            inverse[4 * i + j] = f32::from(cofactor(j, i) * reciprocal);
        }
    }
    inverse
}

/// `instance` as lavapipe holds it: its `world_to_object` replaced by
/// [`gaussian_elimination_inverse`] of its `object_to_world`, so that
/// `kernel::instance::ray_to_object` maps a ray as the device's traversal does.
pub fn as_lavapipe_inverts(instance: &kernel::scene::Instance) -> kernel::scene::Instance {
    kernel::scene::Instance {
        world_to_object: gaussian_elimination_inverse(&instance.object_to_world),
        ..*instance
    }
}

/// `instance` as RADV or ANV holds it: its `world_to_object` replaced by [`adjugate_inverse`] of
/// its `object_to_world`, computed in `T` (`vulkan_arithmetic::Vk32` for a shader's arithmetic).
pub fn as_an_adjugate_device_inverts<T>(
    instance: &kernel::scene::Instance,
) -> kernel::scene::Instance
where
    T: Copy + From<f32> + Add<Output = T> + Sub<Output = T> + Mul<Output = T> + Div<Output = T>,
    f32: From<T>,
{
    kernel::scene::Instance {
        world_to_object: adjugate_inverse::<T>(&instance.object_to_world),
        ..*instance
    }
}

/// What [`as_devices_invert`] returns, in order: the inversion and the arithmetic it ran in.
pub const DEVICE_INVERSES: [&str; 4] = [
    "Gaussian elimination in IEEE f32 (lavapipe)",
    "the adjugate under Vulkan arithmetic (RADV, ANV)",
    "the adjugate at Vulkan's worst rounding, quotients up",
    "the adjugate at Vulkan's worst rounding, quotients down",
];

/// `instance` as each kind of device the tests model may hold it ([`DEVICE_INVERSES`]):
/// lavapipe's inverse ([`as_lavapipe_inverts`], computed on the host CPU), and the adjugate
/// ([`as_an_adjugate_device_inverts`]) computed in `Vk32` at random liberties and at the worst
/// rounding leaning each way, as a build shader may compute it. The calling thread's model of
/// Vulkan's arithmetic is left as it was.
pub fn as_devices_invert(instance: &kernel::scene::Instance) -> [kernel::scene::Instance; 4] {
    use crate::vulkan_arithmetic::{with_model, Model, Vk32};
    let adjugate = |model, lean| {
        with_model(model, lean, || {
            as_an_adjugate_device_inverts::<Vk32>(instance)
        })
    };
    [
        as_lavapipe_inverts(instance),
        adjugate(Model::VULKAN, 1),
        adjugate(Model::VULKAN_WORST, 1),
        adjugate(Model::VULKAN_WORST, -1),
    ]
}

/// `instance`'s stored `object_to_world` as an exact `f64` matrix: the map the device places the
/// mesh by, whose inverse (in `f64`) is the exact X the kernel's bounds are stated against.
pub fn stored_object_to_world(instance: &kernel::scene::Instance) -> glam::DMat4 {
    use glam::DVec4;
    let f = instance.object_to_world.map(|x| x as f64);
    glam::DMat4::from_cols(
        DVec4::new(f[0], f[4], f[8], 0.0),
        DVec4::new(f[1], f[5], f[9], 0.0),
        DVec4::new(f[2], f[6], f[10], 0.0),
        DVec4::new(f[3], f[7], f[11], 1.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both inverses of a sheared, scaled, translated map: M B = I within 10^-5 (checked in
    /// `f64`), so each computes the inverse it says, signs and layout included.
    #[test]
    fn both_inverses_invert() {
        let m: [f32; 12] = [
            2.0, 0.3, -0.5, 4.0, //
            0.1, -1.5, 0.7, -2.0, //
            -0.4, 0.2, 3.0, 0.5,
        ];
        let full = |a: &[f32; 12], r: usize, c: usize| -> f64 {
            if r == 3 {
                [0.0, 0.0, 0.0, 1.0][c]
            } else {
                a[4 * r + c] as f64
            }
        };
        for b in [
            gaussian_elimination_inverse(&m),
            adjugate_inverse::<f32>(&m),
        ] {
            for r in 0..4 {
                for c in 0..4 {
                    let product: f64 = (0..4).map(|k| full(&m, r, k) * full(&b, k, c)).sum();
                    let want = if r == c { 1.0 } else { 0.0 };
                    assert!((product - want).abs() < 1e-5, "({r}, {c}): {product}");
                }
            }
        }
    }
}
