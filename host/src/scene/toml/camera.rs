//! The `[camera]` table: a pinhole or thin-lens camera and the image size, or a perspective
//! camera of the scene's `[[gltf]]` files by name (`gltf = "NAME"`), so that a scene built
//! around a Blender export keeps its camera.

use super::checker::{Checker, V3};
use super::includes::IncludedCamera;
use crate::scene::limits::{MAX_COORDINATE, MAX_IMAGE_SIDE};
use crate::scene::{CameraDesc, SceneError};
use serde::Deserialize;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraFile {
    pub eye: Option<V3>,
    pub look_at: Option<V3>,
    pub up: Option<V3>,
    pub vfov: Option<Spanned<f32>>,
    /// A perspective camera of the included glTF files, by name, instead of eye, look_at, up
    /// and vfov.
    pub gltf: Option<Spanned<String>>,
    /// Image size (with `gltf`: optional, one alone keeps the camera's aspect ratio).
    pub width: Option<Spanned<i64>>,
    pub height: Option<Spanned<i64>>,
    /// Thin-lens diameter (default 0: a pinhole).
    pub aperture: Option<Spanned<f32>>,
    /// Distance of the plane in focus along the view axis (default: |look_at - eye|).
    pub focus_distance: Option<Spanned<f32>>,
}

/// The camera the table describes, checked; `gltf_cameras` are the included files' cameras
/// (with their files), which `gltf = "NAME"` chooses from.
pub(super) fn camera(
    ck: &Checker,
    camera: &Spanned<CameraFile>,
    gltf_cameras: &[IncludedCamera],
) -> Result<CameraDesc, SceneError> {
    let cam = camera.get_ref();
    if let Some(name) = &cam.gltf {
        return gltf_camera(ck, Some(camera), name.get_ref(), gltf_cameras);
    }
    let eye = required(ck, camera, &cam.eye, "eye")?;
    let look_at = required(ck, camera, &cam.look_at, "look_at")?;
    let up = required(ck, camera, &cam.up, "up")?;
    let vfov_s = required(ck, camera, &cam.vfov, "vfov")?;
    let width = required(ck, camera, &cam.width, "width")?;
    let height = required(ck, camera, &cam.height, "height")?;
    let eye = ck.vec3(eye, "camera.eye")?;
    let look_at_v = ck.vec3(look_at, "camera.look_at")?;
    let up_v = ck.vec3(up, "camera.up")?;
    let vfov = *vfov_s.get_ref();
    if !(vfov > 0.0 && vfov < 180.0) {
        return Err(ck.err(
            vfov_s.span(),
            "camera.vfov",
            format!("{vfov} is not in (0, 180) degrees"),
        ));
    }
    let width = ck.int(width, "camera.width", 1, MAX_IMAGE_SIDE)?;
    let height = ck.int(height, "camera.height", 1, MAX_IMAGE_SIDE)?;
    let forward = look_at_v - eye;
    if !(forward.length() > 0.0) || !forward.normalize().is_finite() {
        return Err(ck.err(
            look_at.span(),
            "camera.look_at",
            "equals camera.eye: no viewing direction",
        ));
    }
    let right = forward.normalize().cross(up_v);
    if !(right.length() > 1e-6 * up_v.length()) || !right.normalize().is_finite() {
        return Err(ck.err(
            up.span(),
            "camera.up",
            "is zero or parallel to the viewing direction",
        ));
    }
    let (aperture, focus_distance) = lens(ck, cam)?;
    Ok(CameraDesc {
        eye,
        look_at: look_at_v,
        up: up_v,
        vfov_degrees: vfov,
        width,
        height,
        aperture,
        focus_distance: focus_distance.unwrap_or(forward.length()),
    })
}

/// The table's `field`, or an error naming it as missing.
fn required<'a, T>(
    ck: &Checker,
    table: &Spanned<CameraFile>,
    value: &'a Option<T>,
    field: &str,
) -> Result<&'a T, SceneError> {
    value.as_ref().ok_or_else(|| {
        ck.err(
            table.span(),
            &format!("camera.{field}"),
            "missing (give eye, look_at, up, vfov, width and height, or gltf = \"NAME\" for a \
             camera of the [[gltf]] files)",
        )
    })
}

/// The included glTF files' perspective camera named `name`, with the table's image size and
/// lens where it gives them (`table`: none for `--camera NAME`, which uses the camera as the
/// file states it). An error lists the cameras there are.
pub(super) fn gltf_camera(
    ck: &Checker,
    table: Option<&Spanned<CameraFile>>,
    name: &str,
    gltf_cameras: &[IncludedCamera],
) -> Result<CameraDesc, SceneError> {
    let Some(found) = gltf_cameras.iter().find(|c| c.camera.name == name) else {
        let names: Vec<String> = gltf_cameras
            .iter()
            .map(|c| format!("'{}' ({})", c.camera.name, c.file.display()))
            .collect();
        let msg = format!(
            "no perspective camera named '{name}' in the scene's [[gltf]] files (they have: {})",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        );
        return Err(match table.and_then(|t| t.get_ref().gltf.as_ref()) {
            Some(g) => ck.err(g.span(), "camera.gltf", msg),
            None => SceneError::new(ck.path, None, "camera", msg),
        });
    };
    let mut desc = found.camera.desc;
    let Some(table) = table else {
        return Ok(desc);
    };
    let cam = table.get_ref();
    let placed = [
        ("eye", cam.eye.as_ref().map(|v| v.span())),
        ("look_at", cam.look_at.as_ref().map(|v| v.span())),
        ("up", cam.up.as_ref().map(|v| v.span())),
        ("vfov", cam.vfov.as_ref().map(|v| v.span())),
    ];
    if let Some((f, Some(s))) = placed.into_iter().find(|(_, s)| s.is_some()) {
        return Err(ck.err(
            s,
            &format!("camera.{f}"),
            "not with camera.gltf: the glTF camera places and frames the view",
        ));
    }
    let side = |v: &Option<Spanned<i64>>, f: &str| {
        v.as_ref()
            .map(|v| ck.int(v, f, 1, MAX_IMAGE_SIDE))
            .transpose()
    };
    let (width, height) = (
        side(&cam.width, "camera.width")?,
        side(&cam.height, "camera.height")?,
    );
    desc = desc
        .resized(width, height)
        .map_err(|m| ck.err(table.span(), "camera", m))?;
    let (aperture, focus_distance) = lens(ck, cam)?;
    desc.aperture = aperture;
    match (focus_distance, &cam.aperture) {
        (Some(d), _) => desc.focus_distance = d,
        (None, Some(a)) if aperture > 0.0 => {
            return Err(ck.err(
                a.span(),
                "camera.focus_distance",
                "missing: a thin lens on a glTF camera needs the distance in focus",
            ))
        }
        (None, _) => {}
    }
    Ok(desc)
}

/// The lens: the aperture (default 0) and the table's focus distance, if it gives one.
fn lens(ck: &Checker, cam: &CameraFile) -> Result<(f32, Option<f32>), SceneError> {
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
            Some(x)
        }
        None => None,
    };
    Ok((aperture, focus_distance))
}
