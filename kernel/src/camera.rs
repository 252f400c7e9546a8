//! The pinhole camera: pixel and sub-pixel position to a primary ray.

use crate::scene::Camera;
use spirv_std::glam::Vec3;

/// Unit direction of the ray through image position (px + u, py + v) of a width x height image,
/// where (px, py) is the pixel (column from the left, row from the top) and (u, v) in [0, 1)^2
/// the position inside it. The image plane spans [-1, 1]^2 in camera units, y up, so row 0 is
/// the top and the image is not mirrored (right = forward x up).
#[inline]
pub fn camera_ray_direction(
    camera: &Camera,
    width: u32,
    height: u32,
    px: u32,
    py: u32,
    u: f32,
    v: f32,
) -> Vec3 {
    let x = 2.0 * ((px as f32 + u) / width as f32) - 1.0;
    let y = 1.0 - 2.0 * ((py as f32 + v) / height as f32);
    let forward = Vec3::new(camera.forward[0], camera.forward[1], camera.forward[2]);
    let right = Vec3::new(camera.right[0], camera.right[1], camera.right[2]);
    let up = Vec3::new(camera.up[0], camera.up[1], camera.up[2]);
    (forward + x * right + y * up).normalize()
}

/// The camera's position.
#[inline]
pub fn camera_origin(camera: &Camera) -> Vec3 {
    Vec3::new(camera.eye[0], camera.eye[1], camera.eye[2])
}
