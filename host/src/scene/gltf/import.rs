//! One glTF file being read into the scene's tables: the state every part of the import
//! (`meshes`, `material`, `images`, `camera`, `lights`) reads and adds to, and the limit on
//! what it may add. The node walk that drives them is in `mod.rs`.

use super::LightUnits;
use crate::scene::builder::SceneTables;
use gltf::Document;
use std::collections::HashMap;
use std::path::PathBuf;

/// Most triangles a scene may flatten its glTF meshes into (48 bytes each on either backend,
/// 3 GiB): a file that instances a large mesh many times is refused before it is expanded.
pub const MAX_TRIANGLES: usize = 1 << 26;

/// One glTF file being read into `tables`.
pub(super) struct Import<'a> {
    pub(super) path: PathBuf,
    /// Where external images are read from (none: refused).
    pub(super) base: Option<PathBuf>,
    pub(super) document: Document,
    pub(super) buffers: Vec<gltf::buffer::Data>,
    pub(super) tables: &'a mut SceneTables,
    pub(super) notes: &'a mut Vec<String>,
    /// How the file's light intensities read.
    pub(super) light_units: LightUnits,
    /// Kernel material of each glTF material index (`None`: the default material).
    pub(super) materials: HashMap<Option<usize>, u32>,
    /// How many nodes of the scene use each mesh (by glTF index).
    pub(super) mesh_uses: HashMap<usize, usize>,
    /// [`Import::instanceable`]'s answer for each mesh asked about (asked once per node).
    pub(super) instanceable: HashMap<usize, bool>,
    /// The instanced mesh (`SceneTables::begin_instanced_mesh`) of each glTF mesh stored once.
    pub(super) instanced: HashMap<usize, u32>,
}

impl Import<'_> {
    /// Records `note` once.
    pub(super) fn note(&mut self, note: String) {
        let note = format!("{}: {note}", self.path.display());
        if !self.notes.contains(&note) {
            self.notes.push(note);
        }
    }
}
