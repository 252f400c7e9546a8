//! The `[background]` table: a uniform radiance, or an environment map.

use super::checker::{Checker, V3};
use crate::scene::environment::EnvironmentMap;
use crate::scene::SceneError;
use glam::Vec3;
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BackgroundFile {
    /// A uniform environment.
    pub radiance: Option<V3>,
    /// An equirectangular environment map (EXR or HDR), relative to the scene file.
    pub map: Option<Spanned<String>>,
    /// Factor on the map's texels (default 1).
    pub scale: Option<Spanned<f32>>,
    /// The map's rotation about the up axis (+y), degrees (default 0).
    pub rotation: Option<Spanned<f32>>,
}

/// The `[background]` table: a uniform radiance, or an environment map with its scale and
/// rotation (exactly one of the two).
pub(super) fn background(
    ck: &Checker,
    b: &BackgroundFile,
    base_dir: &Path,
) -> Result<(Vec3, Option<EnvironmentMap>), SceneError> {
    match (&b.radiance, &b.map) {
        (Some(r), None) => {
            if let Some(s) = b.scale.as_ref().or(b.rotation.as_ref()) {
                return Err(ck.err(
                    s.span(),
                    "background",
                    "scale and rotation belong to a map, not to a uniform radiance",
                ));
            }
            Ok((ck.color(r, "background.radiance", None)?, None))
        }
        (None, Some(m)) => {
            let map_path = base_dir.join(m.get_ref());
            if !map_path.is_file() {
                return Err(ck.err(
                    m.span(),
                    "background.map",
                    format!("map file {} does not exist", map_path.display()),
                ));
            }
            let mut map = EnvironmentMap::load(&map_path, "background.map")?;
            if let Some(s) = &b.scale {
                let k = *s.get_ref();
                if !(k >= 0.0 && k.is_finite()) {
                    return Err(ck.err(
                        s.span(),
                        "background.scale",
                        format!("{k} must be a non-negative finite number"),
                    ));
                }
                map.scale = k;
            }
            if let Some(r) = &b.rotation {
                let deg = *r.get_ref();
                if !deg.is_finite() {
                    return Err(ck.err(r.span(), "background.rotation", "is not finite"));
                }
                map.rotation_degrees = deg;
            }
            Ok((Vec3::ZERO, Some(map)))
        }
        (Some(_), Some(m)) => Err(ck.err(
            m.span(),
            "background",
            "gives both radiance and map: choose one",
        )),
        (None, None) => Err(SceneError::new(
            ck.path,
            None,
            "background",
            "needs radiance or map",
        )),
    }
}
