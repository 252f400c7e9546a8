//! Scenes: files validated and flattened into the kernel's `#[repr(C)]` tables. Neither
//! backend knows a file format. The formats are rooms of their own (`toml/`, `gltf/`, and
//! `mesh/` for the OBJ and PLY files both name), each adding what it reads to the one builder
//! (`builder`: the tables, their lights, instances and tangents), which knows no format; the
//! limits every format checks are in `limits`. Data flows one way: format -> builder -> Scene.

mod builder;
mod closed_surface;
pub mod density_grid;
pub mod environment;
mod error;
mod flat_scene;
pub mod ggx_albedo;
mod ggx_albedo_table;
pub mod gltf;
pub mod grazing_domain;
pub mod inputs;
pub mod instancing;
pub mod light_table;
pub mod limits;
mod load;
pub mod mesh;
pub mod sheen_ltc;
mod sheen_ltc_table;
pub mod soup;
mod tangents;
pub mod textures;
pub mod toml;
pub mod transform;

pub use error::SceneError;
pub use flat_scene::{
    triangle, CameraDesc, Scene, SceneFile, TriangleGroup, ADAPTIVE_PASS, MIN_PILOT_SAMPLES,
    PILOT_PERIOD, SPLIT_TILE,
};
pub use toml::{parse_scene, parse_scene_with_camera, DEFAULT_SCENE_NAME, DEFAULT_SCENE_TOML};
