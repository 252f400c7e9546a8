//! A glTF node's mesh: its triangle primitives read into the tables (flattened into world
//! space, or stored once and instanced where several nodes use it), with their materials.

use super::accessor::{read_colour, read_floats, read_indices, read_uv};
use super::import::{Import, MAX_TRIANGLES};
use crate::scene::closed_surface::check_closed_outward;
use crate::scene::instancing::{flattening_reason, instance_record, INSTANCE_MIN_TRIANGLES};
use crate::scene::soup::TriangleSoup;
use crate::scene::transform::Transform;
use crate::scene::SceneError;
use glam::DMat4;
use gltf::mesh::Mode;
use kernel::scene::Instance;

impl Import<'_> {
    /// Adds every primitive of `mesh` as placed by `node` at `world`: flattened into world
    /// space, or as an instance of the mesh stored once where several nodes use it, it has at
    /// least [`INSTANCE_MIN_TRIANGLES`] triangles, none of its materials emits (an emissive
    /// triangle is a light, whose record is in world space) and the placement's map is one a
    /// device's inverse is shown to keep (`instancing::flattening_reason`; beyond it, while the
    /// mesh's flattened copies stay within their budget, `SceneTables::flattens`).
    pub(super) fn add_mesh(
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
            let placement = instance_record(&transform.unwrap_or_default(), 0);
            let flattened = match flattening_reason(&placement) {
                None => false,
                Some(reason) => {
                    let name = format!("{}#meshes[{}]", self.path.display(), mesh.index());
                    let triangles = declared_triangles(mesh) as usize;
                    self.tables.flattens(&name, triangles, reason)
                }
            };
            if !flattened {
                return self.add_instance(node, mesh, placement);
            }
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
    pub(super) fn instanceable(&mut self, mesh: &gltf::Mesh) -> Result<bool, SceneError> {
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

    /// Places the glTF mesh `mesh` (stored once, in object space, on its first use) as an
    /// instance whose record is `placement` (`instancing::instance_record`).
    fn add_instance(
        &mut self,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
        placement: Instance,
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
        self.tables.add_instance(index, placement).map_err(|msg| {
            SceneError::new(&self.path, None, format!("nodes[{}]", node.index()), msg)
        })
    }

    /// The kernel material of primitive `p` (added on its first use).
    fn material_of(&mut self, p: &gltf::Primitive) -> Result<u32, SceneError> {
        let gltf_material = p.material().index();
        if let Some(&m) = self.materials.get(&gltf_material) {
            return Ok(m);
        }
        let m = super::material::material(self, gltf_material.map(|_| p.material()))?;
        let name = match (gltf_material, p.material().name()) {
            (None, _) => "gltf default".to_string(),
            (Some(i), Some(n)) => format!("{n} (materials[{i}])"),
            (Some(i), None) => format!("materials[{i}]"),
        };
        // Where it emits, glTF's doubleSided: both faces emit.
        let index = self
            .tables
            .add_material(name, m, p.material().double_sided());
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
        if self.tables.reads_second_set(material) && soup.uvs1.is_empty() {
            return Err(SceneError::new(
                &self.path,
                None,
                field,
                "its material has a texture that reads TEXCOORD_1 but the primitive has none",
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

    /// The triangles of primitive `p` in object space, with its normals, texture coordinates
    /// (v flipped: glTF's origin is the image's top left, the kernel's its bottom left),
    /// tangents and vertex colours.
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
        let uvs1 = match p.get(&gltf::Semantic::TexCoords(1)) {
            Some(a) => Some(read_uv(&self.path, &a, &self.buffers)?),
            None => None,
        };
        let tangents = match p.get(&gltf::Semantic::Tangents) {
            Some(a) => Some(read_floats::<4>(&self.path, &a, &self.buffers)?),
            None => None,
        };
        let colours = match p.get(&gltf::Semantic::Colors(0)) {
            Some(a) => Some(read_colour(&self.path, &a, &self.buffers)?),
            None => None,
        };
        for (name, len) in [
            ("NORMAL", normals.as_ref().map(|v| v.len())),
            ("TEXCOORD_0", uvs.as_ref().map(|v| v.len())),
            ("TEXCOORD_1", uvs1.as_ref().map(|v| v.len())),
            ("TANGENT", tangents.as_ref().map(|v| v.len())),
            ("COLOR_0", colours.as_ref().map(|v| v.len())),
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
        let flipped = |v: Vec<[f32; 2]>| -> Vec<[[f32; 2]; 3]> {
            triangles
                .iter()
                .map(|t| t.map(|i| [v[i as usize][0], 1.0 - v[i as usize][1]]))
                .collect()
        };
        Ok(TriangleSoup {
            triangles: triangles.iter().map(|t| corner(t, &positions)).collect(),
            normals: normals.map_or_else(Vec::new, |v| {
                triangles.iter().map(|t| corner(t, &v)).collect()
            }),
            uvs: uvs.map_or_else(Vec::new, flipped),
            tangents: tangents.map_or_else(Vec::new, |v| {
                triangles.iter().map(|t| t.map(|i| v[i as usize])).collect()
            }),
            colours: colours.map_or_else(Vec::new, |v| {
                triangles.iter().map(|t| corner(t, &v)).collect()
            }),
            uvs1: uvs1.map_or_else(Vec::new, flipped),
        })
    }
}

/// The triangles `mesh` declares (from its accessors' counts, before reading them).
pub(super) fn declared_triangles(mesh: &gltf::Mesh) -> u64 {
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
