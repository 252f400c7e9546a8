//! Triangle meshes from OBJ (`obj`, via `tobj`) and PLY (`ply`: ASCII and binary, read here)
//! files, as triangle soups every format places (a TOML `[[mesh]]`, a glTF primitive's
//! triangles are read by `crate::scene::gltf`).

use crate::scene::error::SceneError;
mod obj;
mod obj_indices;
mod ply;

pub use obj::parse_obj;
pub use ply::{parse_ply, MAX_PLY_ELEMENTS};

use super::soup::TriangleSoup;

use std::path::Path;

/// Loads an OBJ or PLY file by its extension.
pub fn load_mesh(path: &Path) -> Result<TriangleSoup, SceneError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("obj") => {
            let bytes = super::inputs::read(path)
                .map_err(|e| SceneError::new(path, None, "file", format!("cannot read: {e}")))?;
            parse_obj(path, &bytes)
        }
        Some("ply") => {
            let bytes = super::inputs::read(path)
                .map_err(|e| SceneError::new(path, None, "file", format!("cannot read: {e}")))?;
            parse_ply(path, &bytes)
        }
        _ => Err(SceneError::new(
            path,
            None,
            "file",
            "unknown mesh format (expected .obj or .ply)",
        )),
    }
}
