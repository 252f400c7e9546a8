//! Scenes: files validated and flattened into the kernel's `#[repr(C)]` tables. Neither
//! backend knows a file format. The formats are rooms of their own (`toml/`, `gltf/`, and
//! `mesh/` for the OBJ and PLY files both name), each adding what it reads to the one builder
//! (`builder`: the tables, their lights, instances and tangents), which knows no format; the
//! limits every format checks are in `limits`. Data flows one way: format -> builder -> Scene.

mod builder;
mod closed_surface;
pub mod environment;
mod error;
mod flat_scene;
pub mod gltf;
pub mod inputs;
pub mod instancing;
pub mod light_table;
pub mod limits;
pub mod mesh;
pub mod soup;
mod tangents;
pub mod textures;
pub mod toml;
pub mod transform;

pub use error::SceneError;
pub use flat_scene::{
    triangle, CameraDesc, Scene, TriangleGroup, ADAPTIVE_PASS, MIN_PILOT_SAMPLES, PILOT_PERIOD,
};
pub use toml::{parse_scene, DEFAULT_SCENE_NAME, DEFAULT_SCENE_TOML};

use std::path::Path;

impl Scene {
    /// Reads and validates a scene file: TOML, or glTF (`.gltf`, `.glb`: its first
    /// perspective camera); meshes are resolved relative to its folder.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        Self::load_with_camera(path, None)
    }

    /// [`Scene::load`], a glTF file seen through its perspective camera named `camera`.
    pub fn load_with_camera(path: &Path, camera: Option<&str>) -> Result<Scene, SceneError> {
        let (scene, files) = inputs::recording(|| Self::read_scene(path, camera));
        let mut scene = scene?;
        scene.inputs = files;
        Ok(scene)
    }

    /// [`Scene::load_with_camera`] without the record of the files read.
    fn read_scene(path: &Path, camera: Option<&str>) -> Result<Scene, SceneError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        if matches!(ext.as_deref(), Some("gltf" | "glb")) {
            return gltf::load(path, camera);
        }
        if let Some(name) = camera {
            return Err(SceneError::new(
                path,
                None,
                "camera",
                format!("a camera name ('{name}') selects among a glTF file's cameras; a TOML scene has one"),
            ));
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
        parse_scene(&text, path)
    }

    /// The built-in default scene (the Cornell scene of `scenes/cornell.toml`).
    pub fn builtin_default() -> Scene {
        let mut scene = parse_scene(DEFAULT_SCENE_TOML, Path::new(DEFAULT_SCENE_NAME))
            .expect("the built-in scene is valid (checked by a test)");
        scene.inputs = vec![inputs::InputFile {
            path: DEFAULT_SCENE_NAME.into(),
            hash: blake3::hash(DEFAULT_SCENE_TOML.as_bytes()),
        }];
        scene
    }
}
