//! Loading a scene file: TOML or glTF by its extension, with the record of every file read
//! (`inputs`), and the built-in default scene.

use super::error::{self, SceneError};
use super::flat_scene::SceneFile;
use super::toml::{parse_scene, parse_scene_with_camera, DEFAULT_SCENE_NAME, DEFAULT_SCENE_TOML};
use super::{gltf, grazing_domain, inputs};
use crate::settings::RenderSettings;
use kernel::scene::RenderParams;
use std::path::Path;

impl SceneFile {
    /// Reads and validates a scene file: TOML, or glTF (`.gltf`, `.glb`: its first
    /// perspective camera); meshes are resolved relative to its folder.
    pub fn load(path: &Path) -> Result<SceneFile, SceneError> {
        Self::load_with_camera(path, None)
    }

    /// [`SceneFile::load`] seen through the perspective camera named `camera`: of the glTF
    /// file, or of a TOML scene's `[[gltf]]` files (instead of its `[camera]` table). The
    /// scene's notes end with those of `grazing_domain`.
    pub fn load_with_camera(path: &Path, camera: Option<&str>) -> Result<SceneFile, SceneError> {
        let (file, files) = inputs::recording(|| Self::read(path, camera));
        let mut file = file?;
        file.scene.inputs = files;
        let beyond = grazing_domain::notes(&file.scene);
        file.scene.notes.extend(beyond);
        Ok(file)
    }

    /// [`SceneFile::load_with_camera`] without the record of the files read.
    fn read(path: &Path, camera: Option<&str>) -> Result<SceneFile, SceneError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        if matches!(ext.as_deref(), Some("gltf" | "glb")) {
            return Ok(SceneFile {
                scene: gltf::load(path, camera)?,
                settings: RenderSettings::default(),
            });
        }
        let text = inputs::read(path)
            .map_err(|e| SceneError::new(path, None, "file", format!("cannot read: {e}")))?;
        let text = String::from_utf8(text).map_err(|e| {
            let line = error::line_of(
                &String::from_utf8_lossy(e.as_bytes()),
                e.utf8_error().valid_up_to(),
            );
            SceneError::new(path, Some(line), "file", "not valid UTF-8 text")
        })?;
        parse_scene_with_camera(&text, path, camera)
    }

    /// [`super::Scene::params`] with the file's settings.
    pub fn params(&self, sample_offset: u32, samples_per_launch: u32) -> RenderParams {
        self.scene
            .params(&self.settings, sample_offset, samples_per_launch)
    }

    /// [`super::Scene::features`] with the file's settings.
    pub fn features(&self) -> u32 {
        self.scene.features(&self.settings)
    }

    /// The built-in default scene (the Cornell scene of `scenes/cornell.toml`).
    pub fn builtin_default() -> SceneFile {
        let mut file = parse_scene(DEFAULT_SCENE_TOML, Path::new(DEFAULT_SCENE_NAME))
            .expect("the built-in scene is valid (checked by a test)");
        file.scene.inputs = vec![inputs::InputFile {
            path: DEFAULT_SCENE_NAME.into(),
            hash: blake3::hash(DEFAULT_SCENE_TOML.as_bytes()),
        }];
        file
    }
}
