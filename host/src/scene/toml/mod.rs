//! The TOML scene format (see README "Scene format"), parsed with serde and checked field by
//! field; every error carries the file, the line of the offending value and the field's path.
//! One module per table (`camera`, `settings` for `[render]`, `materials`, `shapes` for
//! spheres and quads, `meshes`, `lights`, `includes` for glTF files, `background`), each
//! adding what it describes to the one builder (`crate::scene::builder`).

mod background;
mod camera;
mod checker;
mod includes;
mod lights;
mod materials;
mod media;
mod meshes;
mod settings;
mod shapes;
pub(crate) mod transform;

pub use materials::METALS;

use super::builder::SceneTables;
use super::error::{line_of, SceneError};
use super::flat_scene::SceneFile;
use checker::Checker;
use glam::Vec3;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

/// The built-in default scene: the Cornell scene of `scenes/cornell.toml`, embedded.
pub const DEFAULT_SCENE_TOML: &str = include_str!("../../../../scenes/cornell.toml");
/// The name errors and outputs use for the built-in scene.
pub const DEFAULT_SCENE_NAME: &str = "cornell.toml";

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlScene {
    camera: Spanned<camera::CameraFile>,
    /// Settings by name (`crate::settings`), each value with its place in the file.
    #[serde(default)]
    render: BTreeMap<String, Spanned<toml::Value>>,
    #[serde(default)]
    materials: BTreeMap<String, Spanned<materials::MaterialFile>>,
    #[serde(default)]
    media: BTreeMap<String, Spanned<media::MediumFile>>,
    scene: Option<Spanned<media::SceneSection>>,
    #[serde(default)]
    sphere: Vec<Spanned<shapes::SphereFile>>,
    #[serde(default)]
    quad: Vec<Spanned<shapes::QuadFile>>,
    #[serde(default)]
    mesh: Vec<Spanned<meshes::MeshFile>>,
    #[serde(default)]
    gltf: Vec<Spanned<includes::GltfFile>>,
    #[serde(default)]
    light: Vec<Spanned<lights::LightFile>>,
    #[serde(default)]
    background: Option<background::BackgroundFile>,
}

/// Parses and validates scene text; `path` names the file in errors and anchors the paths of
/// the files it names (meshes, textures, glTF files, maps).
pub fn parse_scene(text: &str, path: &Path) -> Result<SceneFile, SceneError> {
    parse_scene_with_camera(text, path, None)
}

/// [`parse_scene`] seen through the perspective camera named `camera` of the scene's `[[gltf]]`
/// files (`--camera NAME`) instead of its `[camera]` table.
pub fn parse_scene_with_camera(
    text: &str,
    path: &Path,
    camera: Option<&str>,
) -> Result<SceneFile, SceneError> {
    let file: TomlScene = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| line_of(text, s.start));
        let field = "syntax";
        SceneError::new(path, line, field, e.message().trim().to_string())
    })?;
    let ck = Checker { path, text };
    let base_dir = path.parent().unwrap_or(Path::new("."));
    let settings = settings::render_settings(&ck, &file.render)?;
    let mut tables = SceneTables::default();
    materials::add_materials(&ck, &file.materials, base_dir, &mut tables)?;
    let media = media::parse_media(&ck, &file.media, file.scene.as_ref(), base_dir, &mut tables)?;
    shapes::add_spheres(&ck, &file.sphere, &media, &mut tables)?;
    shapes::add_quads(&ck, &file.quad, &mut tables)?;
    meshes::add_meshes(&ck, &file.mesh, &media, base_dir, &mut tables)?;
    lights::add_lights(&ck, &file.light, &mut tables)?;
    let (notes, gltf_cameras) = includes::add_gltf(&ck, &file.gltf, base_dir, &mut tables)?;
    let camera = match camera {
        Some(name) => camera::gltf_camera(&ck, None, name, &gltf_cameras)?,
        None => camera::camera(&ck, &file.camera, &gltf_cameras)?,
    };
    media::camera_outside_media(&ck, file.camera.span(), &camera, &tables)?;
    let (background, environment) = match &file.background {
        Some(b) => background::background(&ck, b, base_dir)?,
        None => (Vec3::ZERO, None),
    };
    let mut scene = tables.finish(path.display().to_string(), camera, background, environment);
    scene.notes.extend(notes);
    Ok(SceneFile { scene, settings })
}
