//! The `[camera]` table: a pinhole or thin-lens camera and the image size.

use super::checker::{Checker, V3};
use crate::scene::limits::{MAX_COORDINATE, MAX_IMAGE_SIDE};
use crate::scene::{CameraDesc, SceneError};
use serde::Deserialize;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraFile {
    pub eye: V3,
    pub look_at: V3,
    pub up: V3,
    pub vfov: Spanned<f32>,
    pub width: Spanned<i64>,
    pub height: Spanned<i64>,
    /// Thin-lens diameter (default 0: a pinhole).
    pub aperture: Option<Spanned<f32>>,
    /// Distance of the plane in focus along the view axis (default: |look_at - eye|).
    pub focus_distance: Option<Spanned<f32>>,
}

/// The camera the table describes, checked.
pub(super) fn camera(ck: &Checker, camera: &Spanned<CameraFile>) -> Result<CameraDesc, SceneError> {
    let cam = camera.get_ref();
    let eye = ck.vec3(&cam.eye, "camera.eye")?;
    let look_at = ck.vec3(&cam.look_at, "camera.look_at")?;
    let up = ck.vec3(&cam.up, "camera.up")?;
    let vfov = *cam.vfov.get_ref();
    if !(vfov > 0.0 && vfov < 180.0) {
        return Err(ck.err(
            cam.vfov.span(),
            "camera.vfov",
            format!("{vfov} is not in (0, 180) degrees"),
        ));
    }
    let width = ck.int(&cam.width, "camera.width", 1, MAX_IMAGE_SIDE)?;
    let height = ck.int(&cam.height, "camera.height", 1, MAX_IMAGE_SIDE)?;
    let forward = look_at - eye;
    if !(forward.length() > 0.0) || !forward.normalize().is_finite() {
        return Err(ck.err(
            cam.look_at.span(),
            "camera.look_at",
            "equals camera.eye: no viewing direction",
        ));
    }
    let right = forward.normalize().cross(up);
    if !(right.length() > 1e-6 * up.length()) || !right.normalize().is_finite() {
        return Err(ck.err(
            cam.up.span(),
            "camera.up",
            "is zero or parallel to the viewing direction",
        ));
    }
    let aperture = match &cam.aperture {
        Some(a) => {
            let x = *a.get_ref();
            if !(0.0..=MAX_COORDINATE).contains(&x) {
                return Err(ck.err(
                    a.span(),
                    "camera.aperture",
                    format!("{x} is not a lens diameter in 0..={MAX_COORDINATE:e}"),
                ));
            }
            x
        }
        None => 0.0,
    };
    let focus_distance = match &cam.focus_distance {
        Some(f) => {
            let x = *f.get_ref();
            if !(x > 0.0 && x <= MAX_COORDINATE) {
                return Err(ck.err(
                    f.span(),
                    "camera.focus_distance",
                    format!("{x} is not a distance in (0, {MAX_COORDINATE:e}]"),
                ));
            }
            x
        }
        None => forward.length(),
    };
    Ok(CameraDesc {
        eye,
        look_at,
        up,
        vfov_degrees: vfov,
        width,
        height,
        aperture,
        focus_distance,
    })
}
