//! glTF 2.0 scenes (`.gltf` with external or embedded buffers, and `.glb`): the default scene's
//! node hierarchy read into the scene's tables (a mesh shared by nodes stored once, as
//! instances: `super::instancing`), with its transforms, triangle meshes,
//! materials (`material`), textures and cameras. A glTF file is a scene by itself
//! (`twinpath render model.glb`) or part of a TOML scene (`[[gltf]]`). docs/gltf.md lists what
//! is read, approximated and ignored; what a file uses that is approximated or ignored is noted
//! in `Scene::notes`.

mod accessor;
mod camera;
mod images;
mod import;
mod light_units;
mod lights;
mod material;
mod meshes;
mod textures;

pub use camera::{GltfCamera, IMAGE_HEIGHT, IMAGE_WIDTH};
pub use import::MAX_TRIANGLES;
pub use light_units::{LightUnits, LUMENS_PER_WATT};

use camera::framing_camera;
use import::Import;
use meshes::declared_triangles;

use super::builder::SceneTables;
use super::inputs;
use super::instancing::INSTANCE_MIN_TRIANGLES;
use super::transform::Transform;
use super::{Scene, SceneError};
use glam::{DMat4, DQuat, DVec3, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// The extensions read (docs/gltf.md); any other a file uses is noted, and one it requires is
/// an error.
pub const SUPPORTED_EXTENSIONS: [&str; 10] = [
    "EXT_texture_webp",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_emissive_strength",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_texture_transform",
    "KHR_lights_punctual",
];

/// Reads the document and its buffers (external ones relative to `base`, refused without
/// one), checks the extensions it requires, notes those it uses that are not read.
fn parse_document(
    path: &Path,
    bytes: &[u8],
    base: Option<&Path>,
    notes: &mut Vec<String>,
) -> Result<(gltf::Document, Vec<gltf::buffer::Data>), SceneError> {
    let err = |field: &str, msg: String| SceneError::new(path, None, field, msg);
    // A GLB header declaring fewer bytes than the header itself: the gltf crate subtracts the
    // header's size from it unchecked (a panic under overflow checks, the fuzz build's).
    if bytes.starts_with(b"glTF") {
        let declared = bytes
            .get(8..12)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        if !declared.is_some_and(|n| n >= 12) {
            return Err(err(
                "file",
                format!(
                    "not a valid glTF 2.0 file: a GLB header declaring {declared:?} bytes (at \
                     least its own 12)"
                ),
            ));
        }
    }
    let invalid = |e: gltf::Error| err("file", format!("not a valid glTF 2.0 file: {e}"));
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(invalid)?;
    // The crate's validation indexes the accessor of every POSITION attribute before checking
    // that it exists (a panic on a dangling index): checked here first.
    let json = gltf.document.into_json();
    for (i, mesh) in json.meshes.iter().enumerate() {
        for (j, p) in mesh.primitives.iter().enumerate() {
            if let Some(k) = p
                .attributes
                .values()
                .map(|a| a.value())
                .find(|&k| k >= json.accessors.len())
            {
                return Err(err(
                    &format!("meshes[{i}].primitives[{j}].attributes"),
                    format!("accessor {k} does not exist"),
                ));
            }
        }
    }
    let mut json = json;
    image_sources(path, &mut json)?;
    if let Some(e) = json
        .extensions_required
        .iter()
        .find(|e| !SUPPORTED_EXTENSIONS.contains(&e.as_str()))
    {
        return Err(err(
            "extensionsRequired",
            format!("requires {e}, which twinpath does not read"),
        ));
    }
    // Read here (`image_sources`) but unknown to the gltf crate, whose validation refuses an
    // unknown required extension.
    json.extensions_required
        .retain(|e| e.as_str() != "EXT_texture_webp");
    let document = gltf::Document::from_json(json).map_err(invalid)?;
    let ignored: Vec<&str> = document
        .extensions_used()
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
        .collect();
    if !ignored.is_empty() {
        notes.push(format!(
            "{}: extensions ignored: {}",
            path.display(),
            ignored.join(", ")
        ));
    }
    let buffers = gltf::import_buffers(&document, base, gltf.blob)
        .map_err(|e| err("buffers", format!("cannot read: {e}")))?;
    // The gltf crate read the external buffers itself: record them for the part files.
    for (buffer, data) in document.buffers().zip(&buffers) {
        if let (gltf::buffer::Source::Uri(uri), Some(base)) = (buffer.source(), base) {
            if !uri.starts_with("data:") {
                inputs::record(&base.join(uri), &data.0);
            }
        }
    }
    Ok((document, buffers))
}

/// Gives each texture whose image only an extension names its image: `EXT_texture_webp`'s
/// (which Blender's exporter writes for WebP images, without a PNG fallback unless asked).
/// A texture only `KHR_texture_basisu` names (KTX2) is an error naming it. A texture with its
/// own `source` keeps it (the extensions' fallback rule).
fn image_sources(path: &Path, json: &mut gltf::json::Root) -> Result<(), SceneError> {
    for (i, t) in json.textures.iter_mut().enumerate() {
        if t.source.value() != u32::MAX as usize {
            continue;
        }
        let named = |ext: &str| {
            t.extensions
                .as_ref()
                .and_then(|e| e.others.get(ext))
                .and_then(|v| v.get("source"))
                .and_then(|s| s.as_u64())
                .and_then(|s| u32::try_from(s).ok())
        };
        if let Some(k) = named("EXT_texture_webp") {
            t.source = gltf::json::Index::new(k);
        } else if named("KHR_texture_basisu").is_some() {
            return Err(SceneError::new(
                path,
                None,
                format!("textures[{i}]"),
                "is a KTX2 (Basis Universal) image, KHR_texture_basisu, which twinpath does not \
                 read: export the file's images as PNG, JPEG or WebP",
            ));
        }
    }
    Ok(())
}

/// Loads glTF file `path` as a whole scene: its default scene's meshes under a uniform white
/// sky, seen through the perspective camera named `camera` (default:
/// the first; without any, a camera framing the scene).
pub fn load(path: &Path, camera: Option<&str>) -> Result<Scene, SceneError> {
    let bytes = inputs::read(path)
        .map_err(|e| SceneError::new(path, None, "file", format!("cannot read: {e}")))?;
    let base = path.parent().unwrap_or(Path::new("."));
    load_bytes(path, &bytes, Some(base), camera)
}

/// [`load`] of a file's `bytes` (`path` names it; external buffers and images are read
/// relative to `base`, and refused without one, as the fuzz target runs).
pub fn load_bytes(
    path: &Path,
    bytes: &[u8],
    base: Option<&Path>,
    camera: Option<&str>,
) -> Result<Scene, SceneError> {
    let mut tables = SceneTables::default();
    let mut notes = Vec::new();
    let cameras = import(
        &mut tables,
        path,
        bytes,
        base,
        None,
        LightUnits::Standard,
        &mut notes,
    )?;
    let desc = match camera {
        Some(name) => {
            cameras
                .iter()
                .find(|c| c.name == name)
                .ok_or_else(|| {
                    let names: Vec<&str> = cameras.iter().map(|c| c.name.as_str()).collect();
                    SceneError::new(
                        path,
                        None,
                        "cameras",
                        format!(
                            "no perspective camera named '{name}' (the file has: {})",
                            if names.is_empty() {
                                "none".to_string()
                            } else {
                                names.join(", ")
                            }
                        ),
                    )
                })?
                .desc
        }
        None => match cameras.first() {
            Some(c) => c.desc,
            None => {
                notes.push(format!(
                    "{}: no perspective camera; a camera frames the scene from +z",
                    path.display()
                ));
                framing_camera(&tables).ok_or_else(|| {
                    SceneError::new(path, None, "scenes", "has no triangles to render")
                })?
            }
        },
    };
    let mut scene = tables.finish(path.display().to_string(), desc, Vec3::ONE, None);
    scene.notes.extend(notes);
    Ok(scene)
}

/// Reads glTF file `path` into `tables` under `transform` (a TOML scene's `[[gltf]]`), its
/// lights in `light_units`; the file's perspective cameras, placed in the scene.
pub(super) fn include(
    tables: &mut SceneTables,
    path: &Path,
    transform: Option<&Transform>,
    light_units: LightUnits,
    notes: &mut Vec<String>,
) -> Result<Vec<GltfCamera>, SceneError> {
    let bytes = inputs::read(path)
        .map_err(|e| SceneError::new(path, None, "file", format!("cannot read: {e}")))?;
    let base = path.parent().unwrap_or(Path::new("."));
    import(
        tables,
        path,
        &bytes,
        Some(base),
        transform,
        light_units,
        notes,
    )
}

/// Reads the glTF file of `bytes` into `tables` (see [`load_bytes`] for `base`).
fn import(
    tables: &mut SceneTables,
    path: &Path,
    bytes: &[u8],
    base: Option<&Path>,
    transform: Option<&Transform>,
    light_units: LightUnits,
    notes: &mut Vec<String>,
) -> Result<Vec<GltfCamera>, SceneError> {
    let (document, buffers) = parse_document(path, bytes, base, notes)?;
    let mut imp = Import {
        path: path.to_path_buf(),
        base: base.map(Path::to_path_buf),
        document,
        buffers,
        tables,
        notes,
        light_units,
        materials: HashMap::new(),
        mesh_uses: HashMap::new(),
        instanceable: HashMap::new(),
        instanced: HashMap::new(),
    };
    imp.walk(transform.map_or(DMat4::IDENTITY, |t| t.matrix()))
}

/// A node's own transform in f64: its matrix, or T R S with the rotation normalised.
fn local_matrix(path: &Path, node: &gltf::Node) -> Result<DMat4, SceneError> {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => Ok(DMat4::from_cols_array_2d(
            &matrix.map(|c| c.map(|x| x as f64)),
        )),
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let q = DQuat::from_array(rotation.map(|x| x as f64));
            if !(q.length() > 0.0) || !q.is_finite() {
                return Err(SceneError::new(
                    path,
                    None,
                    format!("nodes[{}].rotation", node.index()),
                    format!("{rotation:?} is not a rotation quaternion"),
                ));
            }
            Ok(DMat4::from_scale_rotation_translation(
                DVec3::from(scale.map(|x| x as f64)),
                q.normalize(),
                DVec3::from(translation.map(|x| x as f64)),
            ))
        }
    }
}

impl Import<'_> {
    /// Walks the default scene's node forest (every root node when the file has no scene)
    /// under `root`, adding each mesh instance; the perspective cameras.
    fn walk(&mut self, root: DMat4) -> Result<Vec<GltfCamera>, SceneError> {
        let doc = self.document.clone();
        let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(scene) => scene.nodes().collect(),
            None => {
                let mut child = vec![false; doc.nodes().len()];
                for n in doc.nodes() {
                    for c in n.children() {
                        child[c.index()] = true;
                    }
                }
                doc.nodes().filter(|n| !child[n.index()]).collect()
            }
        };
        self.check_triangle_budget(&roots)?;
        let mut visited = vec![false; doc.nodes().len()];
        let mut stack: Vec<(gltf::Node, DMat4)> =
            roots.into_iter().rev().map(|n| (n, root)).collect();
        let mut cameras = Vec::new();
        while let Some((node, parent)) = stack.pop() {
            let k = node.index();
            if std::mem::replace(&mut visited[k], true) {
                return Err(SceneError::new(
                    &self.path,
                    None,
                    format!("nodes[{k}]"),
                    "is reached twice: the node hierarchy must be a forest without cycles \
                     (glTF 2.0, 'Nodes and Hierarchy')",
                ));
            }
            let world = parent * local_matrix(&self.path, &node)?;
            if let Some(mesh) = node.mesh() {
                self.add_mesh(&node, &mesh, world)?;
            }
            if let Some(camera) = node.camera() {
                if let Some(c) = self.camera(&node, &camera, world)? {
                    cameras.push(c);
                }
            }
            if let Some(light) = node.light() {
                self.add_light(&node, &light, world)?;
            }
            for child in node.children().collect::<Vec<_>>().into_iter().rev() {
                stack.push((child, world));
            }
        }
        Ok(cameras)
    }

    /// Counts the nodes that use each mesh ([`Import::mesh_uses`]) and refuses a node forest
    /// whose meshes would store more than [`MAX_TRIANGLES`] triangles, counted from the
    /// accessors' declared counts before any geometry is read or allocated: a mesh several
    /// nodes use counts once where it will be instanced ([`Import::instanceable`]), once per
    /// node where it will be flattened (cycles end the count; [`Import::walk`] reports them).
    fn check_triangle_budget(&mut self, roots: &[gltf::Node]) -> Result<(), SceneError> {
        let mut visited = vec![false; self.document.nodes().len()];
        let mut stack: Vec<gltf::Node> = roots.to_vec();
        let mut total = self.tables.triangles.len() as u64;
        while let Some(node) = stack.pop() {
            if std::mem::replace(&mut visited[node.index()], true) {
                continue;
            }
            if let Some(mesh) = node.mesh() {
                let uses = self.mesh_uses.entry(mesh.index()).or_insert(0);
                *uses += 1;
                let first_use = *uses == 1;
                if first_use || !self.instanceable(&mesh)? {
                    total = total.saturating_add(declared_triangles(&mesh));
                }
            }
            if total > MAX_TRIANGLES as u64 {
                return Err(SceneError::new(
                    &self.path,
                    None,
                    "nodes",
                    format!(
                        "its meshes would store more than {MAX_TRIANGLES} triangles (a mesh \
                         used by several nodes is stored once unless it emits light or has \
                         fewer than {INSTANCE_MIN_TRIANGLES} triangles)"
                    ),
                ));
            }
            stack.extend(node.children());
        }
        Ok(())
    }
}
