//! glTF 2.0 scenes (`.gltf` with external or embedded buffers, and `.glb`): the default scene's
//! node hierarchy read into the scene's tables (a mesh shared by nodes stored once, as
//! instances: `super::instancing`), with its transforms, triangle meshes,
//! materials (`material`), textures and cameras. A glTF file is a scene by itself
//! (`twinpath render model.glb`) or part of a TOML scene (`[[gltf]]`). docs/gltf.md lists what
//! is read, approximated and ignored; what a file uses that is approximated or ignored is noted
//! in `Scene::notes`.

mod accessor;
mod material;

use super::builder::SceneTables;
use super::closed_surface::check_closed_outward;
use super::file::MAX_IMAGE_SIDE;
use super::inputs;
use super::instancing::{instances_box, INSTANCE_MIN_TRIANGLES};
use super::mesh::TriangleSoup;
use super::textures::TextureUse;
use super::transform::Transform;
use super::{CameraDesc, Scene, SceneError};
use crate::settings::RenderSettings;
use accessor::{read_floats, read_indices, read_uv};
use glam::{DMat4, DQuat, DVec3, DVec4, Vec3};
use gltf::mesh::Mode;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Most triangles a scene may flatten its glTF meshes into (48 bytes each on either backend,
/// 3 GiB): a file that instances a large mesh many times is refused before it is expanded.
pub const MAX_TRIANGLES: usize = 1 << 26;

/// The extensions read (docs/gltf.md); any other a file uses is noted, and one it requires is
/// an error.
pub const SUPPORTED_EXTENSIONS: [&str; 4] = [
    "KHR_materials_emissive_strength",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_lights_punctual",
];

/// Image height of a scene whose glTF camera gives an aspect ratio (width follows from it), and
/// the 1280 x 720 of one that gives none.
pub const IMAGE_HEIGHT: u32 = 720;
pub const IMAGE_WIDTH: u32 = 1280;

/// A perspective camera of the file, placed by its node.
#[derive(Clone, Debug)]
pub struct GltfCamera {
    pub name: String,
    pub desc: CameraDesc,
}

/// One glTF file being read into `tables`.
pub(super) struct Import<'a> {
    path: PathBuf,
    /// Where external images are read from (none: refused).
    base: Option<PathBuf>,
    document: gltf::Document,
    buffers: Vec<gltf::buffer::Data>,
    tables: &'a mut SceneTables,
    notes: &'a mut Vec<String>,
    /// Kernel material of each glTF material index (`None`: the default material).
    materials: HashMap<Option<usize>, u32>,
    /// How many nodes of the scene use each mesh (by glTF index).
    mesh_uses: HashMap<usize, usize>,
    /// [`Import::instanceable`]'s answer for each mesh asked about (asked once per node).
    instanceable: HashMap<usize, bool>,
    /// The instanced mesh (`SceneTables::begin_instanced_mesh`) of each glTF mesh stored once.
    instanced: HashMap<usize, u32>,
}

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
    let document = gltf::Document::from_json(json).map_err(invalid)?;
    if let Some(e) = document
        .extensions_required()
        .find(|e| !SUPPORTED_EXTENSIONS.contains(e))
    {
        return Err(err(
            "extensionsRequired",
            format!("requires {e}, which twinpath does not read"),
        ));
    }
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

/// Loads glTF file `path` as a whole scene: its default scene's meshes under a uniform white
/// sky, default render settings, seen through the perspective camera named `camera` (default:
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
    let cameras = import(&mut tables, path, bytes, base, None, &mut notes)?;
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
    let mut scene = tables.finish(
        path.display().to_string(),
        desc,
        RenderSettings::default(),
        Vec3::ONE,
        None,
    );
    scene.notes = notes;
    Ok(scene)
}

/// Reads glTF file `path` into `tables` under `transform` (a TOML scene's `[[gltf]]`); the
/// file's perspective cameras, placed in the scene.
pub(super) fn include(
    tables: &mut SceneTables,
    path: &Path,
    transform: Option<&Transform>,
    notes: &mut Vec<String>,
) -> Result<Vec<GltfCamera>, SceneError> {
    let bytes = inputs::read(path)
        .map_err(|e| SceneError::new(path, None, "file", format!("cannot read: {e}")))?;
    let base = path.parent().unwrap_or(Path::new("."));
    import(tables, path, &bytes, Some(base), transform, notes)
}

/// Reads the glTF file of `bytes` into `tables` (see [`load_bytes`] for `base`).
fn import(
    tables: &mut SceneTables,
    path: &Path,
    bytes: &[u8],
    base: Option<&Path>,
    transform: Option<&Transform>,
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
    /// Records `note` once.
    fn note(&mut self, note: String) {
        let note = format!("{}: {note}", self.path.display());
        if !self.notes.contains(&note) {
            self.notes.push(note);
        }
    }

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

    /// Adds `KHR_lights_punctual` light `light` of `node` at `world`: a point or spot light at
    /// the node's origin, a spot pointing down the node's -z; colour x intensity is its radiant
    /// intensity (the extension's candela taken as RGB watts per steradian); `range` is ignored
    /// (physical falloff). A directional light shines down the node's -z with colour x
    /// intensity as its irradiance (lux taken as RGB watts per square metre).
    fn add_light(
        &mut self,
        node: &gltf::Node,
        light: &gltf::khr_lights_punctual::Light,
        world: DMat4,
    ) -> Result<(), SceneError> {
        use gltf::khr_lights_punctual::Kind;
        let field = format!("KHR_lights_punctual.lights[{}]", light.index());
        let path = self.path.clone();
        let err = |msg: String| SceneError::new(&path, None, field.clone(), msg);
        let intensity = Vec3::from(light.color()) * light.intensity();
        if !(intensity.is_finite() && intensity.min_element() >= 0.0) {
            return Err(err(format!(
                "colour x intensity {:?} must be finite and >= 0",
                intensity.to_array()
            )));
        }
        if light.range().is_some() {
            self.note(format!(
                "{field}: range ignored (light falls off as 1/d^2 everywhere)"
            ));
        }
        let position = (world * DVec4::W).truncate();
        let axis = (world * DVec4::new(0.0, 0.0, -1.0, 0.0)).truncate();
        if !(position.is_finite()
            && position.abs().max_element() <= super::file::MAX_COORDINATE as f64)
        {
            return Err(err(format!(
                "nodes[{}] places it at {position}, out of range",
                node.index()
            )));
        }
        let cone = match light.kind() {
            Kind::Directional => {
                if !(axis.length() > 0.0 && axis.is_finite()) {
                    return Err(err(format!(
                        "nodes[{}] gives the directional light no direction",
                        node.index()
                    )));
                }
                self.tables
                    .lights
                    .push(super::light_table::directional_light(
                        axis.as_vec3(),
                        intensity.to_array(),
                    ));
                return Ok(());
            }
            Kind::Point => None,
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                if !(0.0 <= inner_cone_angle
                    && inner_cone_angle < outer_cone_angle
                    && outer_cone_angle <= std::f32::consts::FRAC_PI_2)
                    || !(axis.length() > 0.0)
                {
                    return Err(err(format!(
                        "spot cone angles {inner_cone_angle}, {outer_cone_angle} must satisfy \
                         0 <= inner < outer <= pi/2"
                    )));
                }
                Some((
                    axis.normalize().as_vec3(),
                    inner_cone_angle,
                    outer_cone_angle,
                ))
            }
        };
        self.tables.lights.push(super::light_table::punctual_light(
            position.as_vec3(),
            intensity.to_array(),
            cone,
        ));
        Ok(())
    }

    /// Adds every primitive of `mesh` as placed by `node` at `world`: flattened into world
    /// space, or as an instance of the mesh stored once where several nodes use it, it has at
    /// least [`INSTANCE_MIN_TRIANGLES`] triangles and none of its materials emits (an emissive
    /// triangle is a light, whose record is in world space).
    fn add_mesh(
        &mut self,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
        world: DMat4,
    ) -> Result<(), SceneError> {
        let transform = Transform::affine(world).map_err(|msg| {
            SceneError::new(
                &self.path,
                None,
                format!("nodes[{}] (its transform in the scene)", node.index()),
                msg,
            )
        })?;
        let shared = self.mesh_uses.get(&mesh.index()).copied().unwrap_or(0) >= 2;
        if shared && self.instanceable(mesh)? {
            return self.add_instance(node, mesh, &transform.unwrap_or_default());
        }
        for p in mesh.primitives() {
            let field = format!("meshes[{}].primitives[{}]", mesh.index(), p.index());
            let soup = self.primitive(&p, &field)?;
            if self.tables.triangles.len() + soup.triangles.len() > MAX_TRIANGLES {
                return Err(SceneError::new(
                    &self.path,
                    None,
                    format!("nodes[{}]", node.index()),
                    format!(
                        "the scene would exceed {MAX_TRIANGLES} triangles once its mesh \
                         instances are flattened"
                    ),
                ));
            }
            let material = self.material_of(&p)?;
            self.check_primitive(&soup, material, &field)?;
            let name = format!("{}#{field}", self.path.display());
            self.tables
                .push_mesh(name, &soup, transform.as_ref(), material)
                .map_err(|(k, msg)| {
                    SceneError::new(&self.path, None, format!("{field} triangle {k}"), msg)
                })?;
        }
        Ok(())
    }

    /// Whether `mesh`, when several nodes use it, is stored once and instanced: it has at
    /// least [`INSTANCE_MIN_TRIANGLES`] triangles and none of its materials emits. Decided
    /// once per mesh.
    fn instanceable(&mut self, mesh: &gltf::Mesh) -> Result<bool, SceneError> {
        if let Some(&known) = self.instanceable.get(&mesh.index()) {
            return Ok(known);
        }
        let mut answer = declared_triangles(mesh) >= INSTANCE_MIN_TRIANGLES as u64;
        if answer {
            for p in mesh.primitives() {
                let m = self.material_of(&p)?;
                if self.tables.is_emissive(m) {
                    answer = false;
                    break;
                }
            }
        }
        self.instanceable.insert(mesh.index(), answer);
        Ok(answer)
    }

    /// Places the glTF mesh `mesh` (stored once, in object space, on its first use) at
    /// `transform` as an instance.
    fn add_instance(
        &mut self,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
        transform: &Transform,
    ) -> Result<(), SceneError> {
        let index = match self.instanced.get(&mesh.index()) {
            Some(&i) => i,
            None => {
                let name = format!("{}#meshes[{}]", self.path.display(), mesh.index());
                let index = self.tables.begin_instanced_mesh(name);
                for p in mesh.primitives() {
                    let field = format!("meshes[{}].primitives[{}]", mesh.index(), p.index());
                    let soup = self.primitive(&p, &field)?;
                    let material = self.material_of(&p)?;
                    self.check_primitive(&soup, material, &field)?;
                    self.tables
                        .push_mesh_part(&soup, material)
                        .map_err(|(k, msg)| {
                            SceneError::new(&self.path, None, format!("{field} triangle {k}"), msg)
                        })?;
                }
                self.instanced.insert(mesh.index(), index);
                index
            }
        };
        self.tables.add_instance(index, transform).map_err(|msg| {
            SceneError::new(&self.path, None, format!("nodes[{}]", node.index()), msg)
        })
    }

    /// The kernel material of primitive `p` (added on its first use).
    fn material_of(&mut self, p: &gltf::Primitive) -> Result<u32, SceneError> {
        let gltf_material = p.material().index();
        if let Some(&m) = self.materials.get(&gltf_material) {
            return Ok(m);
        }
        let m = material::material(self, gltf_material.map(|_| p.material()))?;
        let name = match (gltf_material, p.material().name()) {
            (None, _) => "gltf default".to_string(),
            (Some(i), Some(n)) => format!("{n} (materials[{i}])"),
            (Some(i), None) => format!("materials[{i}]"),
        };
        let index = self.tables.add_material(name, m);
        self.materials.insert(gltf_material, index);
        Ok(index)
    }

    /// Refuses primitive `field`'s triangles `soup` under `material` where the material needs
    /// what the primitive lacks: texture coordinates for textures, a closed outward surface
    /// for glass.
    fn check_primitive(
        &self,
        soup: &TriangleSoup,
        material: u32,
        field: &str,
    ) -> Result<(), SceneError> {
        if self.tables.is_textured(material) && soup.uvs.is_empty() {
            return Err(SceneError::new(
                &self.path,
                None,
                field,
                "its material has textures but the primitive has no TEXCOORD_0",
            ));
        }
        if self.tables.is_dielectric(material) {
            check_closed_outward(&soup.triangles).map_err(|msg| {
                SceneError::new(
                    &self.path,
                    None,
                    format!("{field} (a transmissive material: glass)"),
                    msg,
                )
            })?;
        }
        Ok(())
    }

    /// The triangles of primitive `p` in object space, with its normals and texture
    /// coordinates (v flipped: glTF's origin is the image's top left, the kernel's its bottom
    /// left).
    fn primitive(&self, p: &gltf::Primitive, field: &str) -> Result<TriangleSoup, SceneError> {
        let err = |msg: String| SceneError::new(&self.path, None, field, msg);
        let position = p
            .get(&gltf::Semantic::Positions)
            .ok_or_else(|| err("has no POSITION attribute".into()))?;
        let positions = read_floats::<3>(&self.path, &position, &self.buffers)?;
        let n = positions.len();
        let normals = match p.get(&gltf::Semantic::Normals) {
            Some(a) => Some(read_floats::<3>(&self.path, &a, &self.buffers)?),
            None => None,
        };
        let uvs = match p.get(&gltf::Semantic::TexCoords(0)) {
            Some(a) => Some(read_uv(&self.path, &a, &self.buffers)?),
            None => None,
        };
        let tangents = match p.get(&gltf::Semantic::Tangents) {
            Some(a) => Some(read_floats::<4>(&self.path, &a, &self.buffers)?),
            None => None,
        };
        for (name, len) in [
            ("NORMAL", normals.as_ref().map(|v| v.len())),
            ("TEXCOORD_0", uvs.as_ref().map(|v| v.len())),
            ("TANGENT", tangents.as_ref().map(|v| v.len())),
        ] {
            if let Some(len) = len.filter(|&l| l != n) {
                return Err(err(format!(
                    "{name} has {len} elements but POSITION has {n}"
                )));
            }
        }
        let indices: Vec<u32> = match p.indices() {
            Some(a) => read_indices(&self.path, &a, &self.buffers, n)?,
            None => (0..n as u32).collect(),
        };
        let triangles: Vec<[u32; 3]> = match p.mode() {
            Mode::Triangles => {
                if !indices.len().is_multiple_of(3) {
                    return Err(err(format!(
                        "TRIANGLES with {} indices (not a multiple of 3)",
                        indices.len()
                    )));
                }
                indices.as_chunks::<3>().0.to_vec()
            }
            // glTF 2.0, "Primitives": strip triangle i is (i, i + 1 + i % 2, i + 2 - i % 2),
            // fan triangle i is (i + 1, i + 2, 0).
            Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
                .map(|i| [indices[i], indices[i + 1 + i % 2], indices[i + 2 - i % 2]])
                .collect(),
            Mode::TriangleFan => (0..indices.len().saturating_sub(2))
                .map(|i| [indices[i + 1], indices[i + 2], indices[0]])
                .collect(),
            other => {
                return Err(err(format!(
                    "mode {other:?}: only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN are rendered"
                )))
            }
        };
        let corner = |t: &[u32; 3], v: &[[f32; 3]]| t.map(|i| v[i as usize]);
        Ok(TriangleSoup {
            triangles: triangles.iter().map(|t| corner(t, &positions)).collect(),
            normals: normals.map_or_else(Vec::new, |v| {
                triangles.iter().map(|t| corner(t, &v)).collect()
            }),
            uvs: uvs.map_or_else(Vec::new, |v| {
                triangles
                    .iter()
                    .map(|t| t.map(|i| [v[i as usize][0], 1.0 - v[i as usize][1]]))
                    .collect()
            }),
            tangents: tangents.map_or_else(Vec::new, |v| {
                triangles.iter().map(|t| t.map(|i| v[i as usize])).collect()
            }),
        })
    }

    /// Camera `camera` of `node` at `world`: perspective cameras only (orthographic ones are
    /// noted and skipped).
    fn camera(
        &mut self,
        node: &gltf::Node,
        camera: &gltf::Camera,
        world: DMat4,
    ) -> Result<Option<GltfCamera>, SceneError> {
        let name = camera
            .name()
            .map_or_else(|| format!("cameras[{}]", camera.index()), str::to_string);
        let gltf::camera::Projection::Perspective(p) = camera.projection() else {
            self.note(format!("camera '{name}' is orthographic: skipped"));
            return Ok(None);
        };
        let err = |msg: String| {
            SceneError::new(
                &self.path,
                None,
                format!("cameras[{}]", camera.index()),
                msg,
            )
        };
        let vfov = p.yfov().to_degrees();
        if !(vfov > 0.0 && vfov < 180.0) {
            return Err(err(format!("yfov {} is not in (0, pi)", p.yfov())));
        }
        let (width, height) = match p.aspect_ratio() {
            Some(a) => {
                let w = (a as f64 * IMAGE_HEIGHT as f64).round();
                if !(w >= 1.0 && w <= MAX_IMAGE_SIDE as f64) {
                    return Err(err(format!("aspectRatio {a} gives no image width")));
                }
                (w as u32, IMAGE_HEIGHT)
            }
            None => (IMAGE_WIDTH, IMAGE_HEIGHT),
        };
        let eye = (world * DVec4::W).truncate();
        let forward = (world * DVec4::new(0.0, 0.0, -1.0, 0.0)).truncate();
        let up = (world * DVec4::Y).truncate();
        if !(forward.length() > 0.0 && up.cross(forward).length() > 0.0) || !eye.is_finite() {
            return Err(SceneError::new(
                &self.path,
                None,
                format!("nodes[{}]", node.index()),
                "its transform leaves the camera no viewing direction",
            ));
        }
        let forward = forward.normalize();
        Ok(Some(GltfCamera {
            name,
            desc: CameraDesc {
                eye: eye.as_vec3(),
                look_at: (eye + forward).as_vec3(),
                up: up.normalize().as_vec3(),
                vfov_degrees: vfov,
                width,
                height,
                aperture: 0.0,
                focus_distance: 1.0,
            },
        }))
    }

    /// The texture table's index of image `k` used as `usage`: its bytes from a buffer view,
    /// a data URI or a file beside the glTF file, every index and range checked (the gltf
    /// crate's image import unwraps a missing mimeType and slices views unchecked), decoded by
    /// the `image` crate (PNG, JPEG and the formats it guesses).
    fn image(&mut self, k: usize, usage: TextureUse) -> Result<u32, SceneError> {
        let field = format!("images[{k}]");
        let err = |msg: String| SceneError::new(&self.path, None, field.clone(), msg);
        let json = self.document.as_json();
        let image = json
            .images
            .get(k)
            .ok_or_else(|| err("does not exist".into()))?;
        let bytes: std::borrow::Cow<[u8]> =
            if let Some(v) = &image.buffer_view {
                let view = json
                    .buffer_views
                    .get(v.value())
                    .ok_or_else(|| err(format!("its bufferView {} does not exist", v.value())))?;
                let buffer = self.buffers.get(view.buffer.value()).ok_or_else(|| {
                    err(format!("its buffer {} does not exist", view.buffer.value()))
                })?;
                let offset = view.byte_offset.map_or(0, |o| o.0) as usize;
                let range = offset..offset.saturating_add(view.byte_length.0 as usize);
                std::borrow::Cow::Borrowed(buffer.get(range).ok_or_else(|| {
                    err(format!(
                        "bufferViews[{}] lies outside its buffer of {} bytes",
                        v.value(),
                        buffer.len()
                    ))
                })?)
            } else if let Some(uri) = &image.uri {
                if let Some(data) = uri.strip_prefix("data:") {
                    let (_, encoded) = data
                        .split_once(";base64,")
                        .ok_or_else(|| err("a data URI that is not base64".into()))?;
                    std::borrow::Cow::Owned(
                        base64::decode(encoded).map_err(|e| err(format!("bad base64: {e}")))?,
                    )
                } else {
                    let base = self.base.as_ref().ok_or_else(|| {
                        err("names an external file, but there is no folder".into())
                    })?;
                    let file = base.join(uri);
                    std::borrow::Cow::Owned(
                        inputs::read(&file)
                            .map_err(|e| err(format!("cannot read {}: {e}", file.display())))?,
                    )
                }
            } else {
                return Err(err("has neither a bufferView nor a uri".into()));
            };
        let decoded = image::load_from_memory(&bytes)
            .map_err(|e| err(format!("not a readable image: {e}")))?;
        let name = PathBuf::from(format!("{}#{field}", self.path.display()));
        self.tables
            .textures
            .add_image(&name, decoded, usage, &field)
    }
}

/// The triangles `mesh` declares (from its accessors' counts, before reading them).
fn declared_triangles(mesh: &gltf::Mesh) -> u64 {
    let mut total = 0u64;
    for p in mesh.primitives() {
        let count = p
            .indices()
            .or_else(|| p.get(&gltf::Semantic::Positions))
            .map_or(0, |a| a.count() as u64);
        let triangles = match p.mode() {
            Mode::Triangles => count / 3,
            Mode::TriangleStrip | Mode::TriangleFan => count.saturating_sub(2),
            _ => 0,
        };
        total = total.saturating_add(triangles);
    }
    total
}

/// A camera that sees the whole scene from +z (up +y, 40 degrees vertical field of view,
/// 1280 x 720): for files without a perspective camera. `None` without triangles.
fn framing_camera(tables: &SceneTables) -> Option<CameraDesc> {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for t in &tables.triangles {
        let p0 = Vec3::from(t.p0);
        for p in [p0, p0 + Vec3::from(t.edge1), p0 + Vec3::from(t.edge2)] {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let (ilo, ihi) = instances_box(
        &tables.mesh_boxes,
        &tables.instances,
        &tables.instance_meshes,
    );
    (lo, hi) = (lo.min(ilo), hi.max(ihi));
    if !(lo.x <= hi.x) {
        return None;
    }
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-6);
    let vfov: f32 = 40.0;
    let distance = 1.1 * radius / (0.5 * vfov.to_radians()).sin();
    Some(CameraDesc {
        eye: centre + Vec3::Z * distance,
        look_at: centre,
        up: Vec3::Y,
        vfov_degrees: vfov,
        width: IMAGE_WIDTH,
        height: IMAGE_HEIGHT,
        aperture: 0.0,
        focus_distance: distance,
    })
}
