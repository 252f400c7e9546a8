//! A device's own world-to-object map: Vulkan takes only an instance's `object_to_world`
//! ("Ray Traversal" asks only that it be invertible) and leaves how the implementation inverts
//! it unspecified. Lavapipe inverts the 4 x 4 matrix in `f32` by Gaussian elimination with
//! partial pivoting (Mesa's `util_invert_mat4x4`); [`gaussian_elimination_inverse`] does the
//! same kind of computation (not its operation order), so that the tests can map rays back as
//! such a device does instead of by the stored inverse, which is rounded from an `f64` one.

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

/// `instance` as such a device holds it: its `world_to_object` replaced by
/// [`gaussian_elimination_inverse`] of its `object_to_world`, so that
/// `kernel::instance::ray_to_object` maps a ray as the device's traversal does.
pub fn as_the_device_inverts(instance: &kernel::scene::Instance) -> kernel::scene::Instance {
    kernel::scene::Instance {
        world_to_object: gaussian_elimination_inverse(&instance.object_to_world),
        ..*instance
    }
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
