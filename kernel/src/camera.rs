//! The camera: pixel and sub-pixel position to a primary ray, through a pinhole or a thin lens.

use crate::real::{Real, V3};
use crate::sampling::sample_concentric_disk;
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
    let vec = |a: [f32; 4]| V3::new(a[0], a[1], a[2]);
    let (forward, right, up) = (vec(camera.forward), vec(camera.right), vec(camera.up));
    let size = (width as f32, height as f32);
    image_plane_direction(forward, right, up, size, (px as f32, py as f32), (u, v)).into()
}

/// The unit direction through position `offset` inside pixel `pixel` (column and row from the
/// top left, as floats) of an image of `size` pixels, for a camera of axes `forward`, `right`,
/// `up`: the arithmetic of [`camera_ray_direction`], over any [`Real`] (the kernel's `f32`, or a
/// test's model of a device's arithmetic), normalised as glam normalises ([`V3::normalize`]).
#[inline]
pub fn image_plane_direction<R: Real>(
    forward: V3<R>,
    right: V3<R>,
    up: V3<R>,
    size: (f32, f32),
    pixel: (f32, f32),
    offset: (R, R),
) -> V3<R> {
    let (one, two) = (R::splat(1.0), R::splat(2.0));
    let x = two * ((R::splat(pixel.0) + offset.0) / R::splat(size.0)) - one;
    let y = one - two * ((R::splat(pixel.1) + offset.1) / R::splat(size.1));
    let d = forward + right * x + up * y;
    d.normalize()
}

/// The camera's position.
#[inline]
pub fn camera_origin(camera: &Camera) -> Vec3 {
    Vec3::new(camera.eye[0], camera.eye[1], camera.eye[2])
}

/// The thin lens's radius (0: a pinhole).
#[inline]
pub fn lens_radius(camera: &Camera) -> f32 {
    camera.eye[3]
}

/// The camera ray through a thin lens of radius `lens_radius(camera)` focused at distance
/// `camera.forward[3]` along the view axis, for the pinhole ray direction `dir` (unit, from
/// [`camera_ray_direction`]) and the lens point (u1, u2): (origin, unit direction).
///
/// A thin lens maps every point of the plane of focus to one image point (the ideal lens of
/// geometric optics; pbrt-v4 `PerspectiveCamera::GenerateRay`, 5.2.3, models it so): the ray
/// through the pinhole along `dir` meets that plane at eye + dir (f / (dir . forward)), and the
/// ray from any lens point toward that focus point belongs to the same image point. The lens
/// point is uniform on the disk of the lens, in the plane spanned by the camera's right and up
/// axes (Shirley and Chiu's concentric map, `sampling::sample_concentric_disk`), so a point at
/// distance d along the axis is imaged as a disk of diameter
/// 2 r |1/f - 1/d| in image-plane units (the plane at distance 1, where the image spans
/// tan(vfov/2) above the axis): the circle of confusion.
#[inline]
pub fn thin_lens_ray(camera: &Camera, dir: Vec3, u1: f32, u2: f32) -> (Vec3, Vec3) {
    let eye = camera_origin(camera);
    let forward = Vec3::new(camera.forward[0], camera.forward[1], camera.forward[2]);
    let right = Vec3::new(camera.right[0], camera.right[1], camera.right[2]).normalize();
    let up = Vec3::new(camera.up[0], camera.up[1], camera.up[2]).normalize();
    let focus = eye + dir * (camera.forward[3] / dir.dot(forward));
    let (x, y) = sample_concentric_disk(u1, u2);
    let origin = eye + lens_radius(camera) * (x * right + y * up);
    (origin, (focus - origin).normalize())
}
