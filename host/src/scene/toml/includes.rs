//! The `[[gltf]]` table: a glTF file's default scene as part of this one, under an optional
//! transform (`crate::scene::gltf::include`).

use super::checker::{Checker, V3};
use super::transform::{parse_transform, transform_fields};
use crate::scene::builder::SceneTables;
use crate::scene::gltf::{self, GltfCamera};
use crate::scene::SceneError;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// A glTF file's default scene as part of this one (`gltf::include`): its meshes with
/// their own materials, under an optional transform; its perspective cameras, placed by the
/// same transform, are the ones `[camera] gltf = "NAME"` and `--camera NAME` choose from.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct GltfFile {
    pub file: Spanned<String>,
    pub scale: Option<Spanned<toml::Value>>,
    pub rotate: Option<Spanned<[f32; 4]>>,
    pub translate: Option<V3>,
    pub matrix: Option<Spanned<[[f32; 4]; 4]>>,
    /// How the file's `KHR_lights_punctual` intensities read (`gltf::LightUnits::NAMES`;
    /// default "standard": candela and lux).
    pub light_units: Option<Spanned<String>>,
}

/// A perspective camera of an included glTF file, placed in the scene, and the file.
pub(super) struct IncludedCamera {
    pub camera: GltfCamera,
    pub file: PathBuf,
}

/// Adds the meshes, materials and lights of the included files to `tables` (relative to
/// `base_dir`); returns what the glTF loader noted and the files' perspective cameras, each
/// with the file it came from.
pub(super) fn add_gltf(
    ck: &Checker,
    includes: &[Spanned<GltfFile>],
    base_dir: &Path,
    tables: &mut SceneTables,
) -> Result<(Vec<String>, Vec<IncludedCamera>), SceneError> {
    let mut notes = Vec::new();
    let mut cameras = Vec::new();
    for (i, g) in includes.iter().enumerate() {
        let gf = g.get_ref();
        let field = format!("gltf[{i}]");
        let gltf_path = base_dir.join(gf.file.get_ref());
        if !gltf_path.is_file() {
            return Err(ck.err(
                gf.file.span(),
                &format!("{field}.file"),
                format!("glTF file {} does not exist", gltf_path.display()),
            ));
        }
        let transform = if transform_fields!(gf).is_given() {
            Some(parse_transform(ck, &field, &transform_fields!(gf))?)
        } else {
            None
        };
        let light_units = match &gf.light_units {
            None => gltf::LightUnits::default(),
            Some(name) => gltf::LightUnits::from_name(name.get_ref()).ok_or_else(|| {
                ck.err(
                    name.span(),
                    &format!("{field}.light_units"),
                    format!(
                        "'{}' is not one of {}",
                        name.get_ref(),
                        gltf::LightUnits::NAMES.join(", ")
                    ),
                )
            })?,
        };
        let file_cameras = gltf::include(
            tables,
            &gltf_path,
            transform.as_ref(),
            light_units,
            &mut notes,
        )?;
        for camera in file_cameras {
            cameras.push(IncludedCamera {
                camera,
                file: gltf_path.clone(),
            });
        }
    }
    Ok((notes, cameras))
}
