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
    let missing = |field: &str| {
        ck.err(
            camera.span(),
            &format!("camera.{field}"),
            "missing (give eye, look_at, up, vfov, width and height, or gltf = \"NAME\" for a \
             camera of the [[gltf]] files)",
        )
    };
    let (Some(eye), Some(look_at), Some(up), Some(vfov_s)) =
        (&cam.eye, &cam.look_at, &cam.up, &cam.vfov)
    else {
        let field = [
            ("eye", cam.eye.is_none()),
            ("look_at", cam.look_at.is_none()),
            ("up", cam.up.is_none()),
            ("vfov", cam.vfov.is_none()),
        ]
        .into_iter()
        .find(|f| f.1)
        .map_or("eye", |f| f.0);
        return Err(missing(field));
    };
    let (Some(width), Some(height)) = (&cam.width, &cam.height) else {
        return Err(missing(if cam.width.is_none() {
            "width"
        } else {
            "height"
        }));
    };
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
    let (aperture, focus_distance) = lens(ck, cam, Some(forward.length()))?;
    Ok(CameraDesc {
        eye,
        look_at: look_at_v,
        up: up_v,
        vfov_degrees: vfov,
        width,
        height,
        aperture,
        focus_distance,
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
    let (span, field) = match table.and_then(|t| t.get_ref().gltf.as_ref()) {
        Some(g) => (g.span(), "camera.gltf"),
        None => (0..0, "camera"),
    };
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
        return Err(match table {
            Some(_) => ck.err(span, field, msg),
            None => SceneError::new(ck.path, None, field, msg),
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
    let (aperture, focus_distance) = lens(ck, cam, None)?;
    desc.aperture = aperture;
    if cam.focus_distance.is_some() {
        desc.focus_distance = focus_distance;
    }
    Ok(desc)
}

/// The lens: aperture (default 0) and focus distance (default `default_focus`; without one, a
/// thin lens needs the table's).
fn lens(
    ck: &Checker,
    cam: &CameraFile,
    default_focus: Option<f32>,
) -> Result<(f32, f32), SceneError> {
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
        None => match (default_focus, &cam.aperture) {
            (Some(d), _) => d,
            (None, Some(a)) if *a.get_ref() > 0.0 => {
                return Err(ck.err(
                    a.span(),
                    "camera.focus_distance",
                    "missing: a thin lens on a glTF camera needs the distance in focus",
                ))
            }
            (None, _) => 1.0,
        },
    };
    Ok((aperture, focus_distance))
}
