//! The scene's tables as a loader fills them: materials, spheres, triangles with their shading
//! records, lights and textures. The TOML format and glTF files feed the same builder, so a
//! triangle becomes the same kernel records (and a light) whichever file it came from.

use super::density_grid::GridTable;
use super::environment::EnvironmentMap;
use super::ggx_albedo;
use super::instancing::{instance_box, instances_box, mesh_box, FlattenedCopies, MAX_INSTANCES};
use super::light_table::{place_directional_lights, triangle_light};
use super::limits::MAX_COORDINATE;
use super::sheen_ltc;
use super::soup::TriangleSoup;
use super::tangents::{face_tangent, mikktspace_tangents};
use super::textures::TextureTable;
use super::transform::Transform;
use super::{CameraDesc, Scene, TriangleGroup};
use bytemuck::Zeroable;
use glam::Vec3;
use kernel::medium::Medium;
use kernel::scene::{
    material_kind, shading_flags, texture_slot, Instance, Light, Material, ShadingTriangle, Sphere,
    Triangle, NONE,
};

/// The tables of a scene being loaded.
#[derive(Default)]
pub(super) struct SceneTables {
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    /// Per material: whether its triangles, where it emits, emit from both faces.
    pub two_sided: Vec<bool>,
    pub spheres: Vec<Sphere>,
    pub triangles: Vec<Triangle>,
    pub triangle_groups: Vec<TriangleGroup>,
    pub lights: Vec<Light>,
    pub shading: Vec<ShadingTriangle>,
    pub textures: TextureTable,
    /// Instanced meshes' object-space triangles (`finish` appends them after the world-space
    /// ones), the meshes' ranges in it, and the instances with the mesh each places.
    pub mesh_triangles: Vec<Triangle>,
    pub meshes: Vec<TriangleGroup>,
    /// Each instanced mesh's object-space box, grown as its parts are added (placing a mesh
    /// maps it; the triangles are not read again per instance).
    pub mesh_boxes: Vec<(Vec3, Vec3)>,
    pub instances: Vec<Instance>,
    pub instance_meshes: Vec<u32>,
    /// Meshes of which placements would be flattened instead of instanced
    /// (`instancing::flattening_reason`), with how many were.
    pub flattened: Vec<FlattenedCopies>,
    /// The media table (`kernel::medium`): vacuum first once any medium is added
    /// ([`SceneTables::add_medium`]), and the medium filling the scene (0: vacuum).
    pub media: Vec<Medium>,
    pub scene_medium: u32,
    /// The media's density grids (`kernel::density_grid`).
    pub grids: GridTable,
}

/// Records of the media table: a material holds an index in 16 bits, and the exterior's plus 1.
const MAX_MEDIA: usize = 0xffff;

/// Where a loaded triangle goes: the world-space table, or an instanced mesh in object space.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Space {
    World,
    Object,
}

/// `corners` in reverse winding (the second and third swapped) where `mirror`: a mirroring
/// transform flips a triangle's front face, and reversing the winding flips it back (glTF 2.0,
/// "Transformations").
pub(super) fn wound<T: Copy>(corners: [T; 3], mirror: bool) -> [T; 3] {
    if mirror {
        [corners[0], corners[2], corners[1]]
    } else {
        corners
    }
}

impl SceneTables {
    /// Adds a material under `name`, whose triangles, where it emits, emit from both faces if
    /// `two_sided` (copied into each one's `Light::two_sided`); its index.
    pub fn add_material(&mut self, name: String, material: Material, two_sided: bool) -> u32 {
        self.materials.push(material);
        self.material_names.push(name);
        self.two_sided.push(two_sided);
        (self.materials.len() - 1) as u32
    }

    /// Adds `medium` to the media table (after vacuum, record 0) unless it holds it already;
    /// its index, or `None` where the table is full (a material holds an index in 16 bits,
    /// `Material::coat`: 65535 records). A medium that attenuates nothing is vacuum: 0.
    pub fn add_medium(&mut self, medium: Medium) -> Option<u32> {
        if !medium.attenuates() {
            return Some(kernel::medium::VACUUM);
        }
        if self.media.is_empty() {
            self.media.push(Medium::VACUUM);
        }
        if let Some(k) = self.media.iter().position(|m| *m == medium) {
            return Some(k as u32);
        }
        if self.media.len() >= MAX_MEDIA {
            return None;
        }
        self.media.push(medium);
        Some((self.media.len() - 1) as u32)
    }

    /// The index of dielectric `m` with the medium `interior` inside and the medium `exterior`
    /// outside (each a name and an index into the media table, or none: vacuum inside, the
    /// scene's outside; `Material::interior_medium`, `Material::exterior_medium`): `m` itself
    /// where that is what `m` says, else a copy named "MATERIAL holding INSIDE in OUTSIDE",
    /// made once per combination.
    pub fn with_media(
        &mut self,
        m: u32,
        interior: Option<(&str, u32)>,
        exterior: Option<(&str, u32)>,
    ) -> u32 {
        let mut material = self.materials[m as usize];
        let mut name = self.material_names[m as usize].clone();
        if let Some((medium_name, medium)) = interior {
            material.set_interior_medium(medium);
            name = format!("{name} holding {medium_name}");
        }
        if let Some((medium_name, medium)) = exterior {
            material.set_exterior_medium(medium);
            name = format!("{name} in {medium_name}");
        }
        if material == self.materials[m as usize] {
            return m;
        }
        if let Some(k) = self.material_names.iter().position(|n| *n == name) {
            return k as u32;
        }
        let two_sided = self.two_sided[m as usize];
        self.add_material(name, material, two_sided)
    }

    pub fn is_emissive(&self, m: u32) -> bool {
        self.materials[m as usize].emission.iter().any(|&c| c > 0.0)
    }

    pub fn is_dielectric(&self, m: u32) -> bool {
        self.materials[m as usize].kind == material_kind::DIELECTRIC
    }

    pub fn is_textured(&self, m: u32) -> bool {
        self.materials[m as usize]
            .textures
            .iter()
            .any(|&t| t != NONE)
    }

    /// Whether a texture of material `m` reads the second set of texture coordinates (its
    /// triangles then carry a record of them: `shading_flags::SECOND_UVS`).
    pub fn reads_second_set(&self, m: u32) -> bool {
        self.materials[m as usize]
            .textures
            .iter()
            .any(|&t| t != NONE && self.textures.reads_second_set(t))
    }

    /// Whether material `m` has a normal map (its triangles then carry a tangent frame).
    fn is_normal_mapped(&self, m: u32) -> bool {
        self.materials[m as usize].textures[texture_slot::NORMAL] != NONE
    }

    /// Appends the triangle with vertices `p` and `material`, its shading record `attributes`
    /// if it has one, and its light if the material emits. A triangle whose material has a
    /// normal map always gets a record (texture coordinates 0 where it has none), followed by
    /// its tangent frame (`ShadingTriangle::tangent_frame`): the file's vertex tangents and sign
    /// (`tangents`, world space) where it gives usable ones, else `tangents::face_tangent`'s.
    pub fn push_triangle(
        &mut self,
        p: [Vec3; 3],
        material: u32,
        attributes: Option<ShadingTriangle>,
        tangents: Option<([Vec3; 3], f32)>,
    ) {
        let none = Trailing::default();
        self.push_triangle_to(Space::World, p, material, attributes, tangents, none);
    }

    /// [`SceneTables::push_triangle`] into the world-space table or (`Space::Object`, never a
    /// light) the instanced meshes' table, with the `trailing` records where it has them (after
    /// its own and its tangent frame: `ShadingTriangle::vertex_colours`, then the second
    /// texture coordinates; `attributes` then carries `shading_flags::VERTEX_COLOURS` and
    /// `SECOND_UVS`).
    fn push_triangle_to(
        &mut self,
        space: Space,
        p: [Vec3; 3],
        material: u32,
        attributes: Option<ShadingTriangle>,
        tangents: Option<([Vec3; 3], f32)>,
        trailing: Trailing,
    ) {
        let mut tri = super::triangle(p, material);
        let m = self.materials[material as usize];
        let normal_mapped = self.is_normal_mapped(material);
        let attributes = match attributes {
            None if normal_mapped => Some(ShadingTriangle::zeroed()),
            a => a,
        };
        if let Some(a) = attributes {
            tri.shading = self.shading.len() as u32;
            self.shading.push(a);
            if normal_mapped {
                let usable = |t: &([Vec3; 3], f32)| {
                    t.0.iter().all(|v| v.length() > 0.0 && v.is_finite()) && t.1 != 0.0
                };
                let frame = match tangents.filter(usable) {
                    Some((t, sign)) => {
                        ShadingTriangle::tangent_frame(t.map(|v| v.to_array()), sign.signum())
                    }
                    None => {
                        let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
                        let (t, sign) = face_tangent(p, [a.uv0, a.uv1, a.uv2], normal);
                        ShadingTriangle::tangent_frame([t; 3], sign)
                    }
                };
                self.shading.push(frame);
            }
            if let Some(c) = trailing.colours {
                debug_assert!(a.flags & shading_flags::VERTEX_COLOURS != 0);
                self.shading.push(ShadingTriangle::vertex_colours(c));
            }
            if let Some(t) = trailing.second_uvs {
                debug_assert!(a.flags & shading_flags::SECOND_UVS != 0);
                self.shading.push(ShadingTriangle {
                    uv0: t[0],
                    uv1: t[1],
                    uv2: t[2],
                    ..ShadingTriangle::zeroed()
                });
            }
        }
        if space == Space::Object {
            debug_assert!(!self.is_emissive(material), "instanced meshes do not emit");
            self.mesh_triangles.push(tri);
            return;
        }
        if self.is_emissive(material) {
            tri.light = self.lights.len() as u32;
            let two_sided = self.two_sided[material as usize];
            let mut light = triangle_light(&tri, m.emission, two_sided);
            light.material = material;
            if let Some(a) = attributes {
                // The emission texture's own set of coordinates (without one, the base
                // colour's, whose alpha the light's holes read).
                let reads_second = |slot: usize| {
                    let t = m.textures[slot];
                    t != NONE && self.textures.reads_second_set(t)
                };
                let second = if m.textures[texture_slot::EMISSION] != NONE {
                    reads_second(texture_slot::EMISSION)
                } else {
                    reads_second(texture_slot::KD)
                };
                let uv = match trailing.second_uvs {
                    Some(t) if second => t,
                    _ => [a.uv0, a.uv1, a.uv2],
                };
                light.uv = uv.concat().try_into().expect("six numbers");
                light.emission_texture = m.textures[texture_slot::EMISSION];
            }
            self.lights.push(light);
        }
        self.triangles.push(tri);
    }

    /// Appends a mesh's triangles, transformed by `transform` (normals by its inverse
    /// transpose, the winding reversed where it mirrors), with their vertex normals and, where
    /// the material is textured, texture coordinates; zero-area triangles are dropped (they
    /// cannot be hit). The group `name` records their range. Err(k, message): triangle k leaves
    /// the supported coordinate range.
    pub fn push_mesh(
        &mut self,
        name: String,
        soup: &TriangleSoup,
        transform: Option<&Transform>,
        material: u32,
    ) -> Result<(), (usize, String)> {
        let start = self.triangles.len();
        self.push_soup(Space::World, soup, transform, material)?;
        self.triangle_groups.push(TriangleGroup {
            name,
            range: start..self.triangles.len(),
        });
        Ok(())
    }

    /// Starts an instanced mesh `name`: the parts [`SceneTables::push_mesh_part`] adds until
    /// the next call make mesh number (the returned index) for [`SceneTables::add_instance`].
    pub fn begin_instanced_mesh(&mut self, name: String) -> u32 {
        let start = self.mesh_triangles.len();
        self.meshes.push(TriangleGroup {
            name,
            range: start..start,
        });
        self.mesh_boxes
            .push((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)));
        (self.meshes.len() - 1) as u32
    }

    /// Adds `soup` in object space, of a material that does not emit, to the mesh begun last
    /// (zero-area triangles dropped). Err(k, message) as for [`SceneTables::push_mesh`].
    pub fn push_mesh_part(
        &mut self,
        soup: &TriangleSoup,
        material: u32,
    ) -> Result<(), (usize, String)> {
        let start = self.mesh_triangles.len();
        self.push_soup(Space::Object, soup, None, material)?;
        let end = self.mesh_triangles.len();
        self.meshes
            .last_mut()
            .expect("begin_instanced_mesh comes first")
            .range
            .end = end;
        let (lo, hi) = mesh_box(&self.mesh_triangles[start..end]);
        let grown = self.mesh_boxes.last_mut().expect("one box per mesh");
        *grown = (grown.0.min(lo), grown.1.max(hi));
        Ok(())
    }

    /// Whether a placement of mesh `name` (of `triangles` triangles), which would have been
    /// instanced but for `reason`, is flattened into world space: while the mesh's flattened
    /// copies stay within `instancing::MAX_FLATTENED_PLACEMENTS` and `MAX_FLATTENED_TRIANGLES`.
    /// Recorded either way; `finish` turns the records into one note per mesh.
    pub fn flattens(&mut self, name: &str, triangles: usize, reason: String) -> bool {
        let at = match self.flattened.iter().position(|f| f.name == name) {
            Some(k) => k,
            None => {
                self.flattened.push(FlattenedCopies::new(name, reason));
                self.flattened.len() - 1
            }
        };
        self.flattened[at].admit(triangles)
    }

    /// Places instanced mesh `mesh` by `placement`, the record `instancing::instance_record`
    /// makes of the placement's transform (its `first_triangle` is set here; nothing is placed
    /// for a mesh without triangles).
    /// Err: the mesh's placed box leaves the supported coordinate range, or the scene has
    /// [`MAX_INSTANCES`] already.
    pub fn add_instance(&mut self, mesh: u32, placement: Instance) -> Result<(), String> {
        if self.instances.len() >= MAX_INSTANCES {
            return Err(format!(
                "more than {MAX_INSTANCES} instances (the GPU names them by 24 bits)"
            ));
        }
        let range = self.meshes[mesh as usize].range.clone();
        if range.is_empty() {
            // Nothing to place (every triangle of the mesh had zero area).
            return Ok(());
        }
        // The mesh's triangles move when `finish` appends them; it adds the offset.
        let record = Instance {
            first_triangle: range.start as u32,
            ..placement
        };
        let (lo, hi) = instance_box(&record, self.mesh_boxes[mesh as usize]);
        if !(lo.abs().max(hi.abs()).max_element() <= MAX_COORDINATE) {
            return Err(format!("the placed mesh reaches beyond {MAX_COORDINATE:e}"));
        }
        self.instances.push(record);
        self.instance_meshes.push(mesh);
        Ok(())
    }

    /// Adds `soup`'s triangles, transformed, to the table of `space` (see
    /// [`SceneTables::push_mesh`]).
    fn push_soup(
        &mut self,
        space: Space,
        soup: &TriangleSoup,
        transform: Option<&Transform>,
        material: u32,
    ) -> Result<(), (usize, String)> {
        let mirror = transform.is_some_and(|t| t.mirrors());
        let textured = self.is_textured(material);
        let second_set = self.reads_second_set(material);
        // A normal-mapped mesh with vertex normals and texture coordinates but no tangents of
        // its own gets MikkTSpace's (glTF 2.0, "Meshes"; Blender's), whatever its format.
        let generated = (self.is_normal_mapped(material) && soup.tangents.is_empty())
            .then(|| mikktspace_tangents(soup))
            .flatten();
        let file_tangents = generated.as_deref().unwrap_or(&soup.tangents);
        for (k, t) in soup.triangles.iter().enumerate() {
            let p = t.map(|v| match transform {
                Some(m) => m.point(Vec3::from(v)),
                None => Vec3::from(v),
            });
            if p.iter().any(|v| !(v.abs().max_element() <= MAX_COORDINATE)) {
                return Err((
                    k,
                    format!("a vertex lies beyond {MAX_COORDINATE:e} after the transform"),
                ));
            }
            let p = wound(p, mirror);
            if !((p[1] - p[0]).cross(p[2] - p[0]).length() > 0.0) {
                continue;
            }
            let normals = soup.normals.get(k).map(|n| {
                wound(
                    n.map(|n| match transform {
                        Some(m) => m.normal(Vec3::from(n)).to_array(),
                        None => n,
                    }),
                    mirror,
                )
            });
            let uvs = soup
                .uvs
                .get(k)
                .filter(|_| textured)
                .map(|t| wound(*t, mirror));
            // A file's tangents (glTF TANGENT) map as directions, T' = M T; their sign flips
            // where M mirrors: (N' x T') . (M B) = det(M) w |M^-T N| for B = w N x T and
            // N' along M^-T N (docs/materials.md, "Normal maps").
            let tangents = file_tangents.get(k).filter(|_| textured).map(|t| {
                let mapped = wound(
                    t.map(|c| {
                        let v = Vec3::new(c[0], c[1], c[2]);
                        match transform {
                            Some(m) => m.vector(v),
                            None => v,
                        }
                    }),
                    mirror,
                );
                let sign = if mirror { -t[0][3] } else { t[0][3] };
                (mapped, sign)
            });
            let colours = soup.colours.get(k).map(|c| wound(*c, mirror));
            let second_uvs = soup
                .uvs1
                .get(k)
                .filter(|_| second_set)
                .map(|t| wound(*t, mirror));
            let attributes = (normals.is_some() || uvs.is_some() || colours.is_some()).then(|| {
                let n = normals.unwrap_or([[0.0; 3]; 3]);
                let t = uvs.unwrap_or([[0.0; 2]; 3]);
                let mut flags = 0;
                if normals.is_some() {
                    flags |= shading_flags::NORMALS;
                }
                if colours.is_some() {
                    flags |= shading_flags::VERTEX_COLOURS;
                }
                if second_uvs.is_some() {
                    flags |= shading_flags::SECOND_UVS;
                }
                ShadingTriangle {
                    normal0: n[0],
                    normal1: n[1],
                    normal2: n[2],
                    uv0: t[0],
                    uv1: t[1],
                    uv2: t[2],
                    flags,
                }
            });
            let trailing = Trailing {
                colours,
                second_uvs,
            };
            self.push_triangle_to(space, p, material, attributes, tangents, trailing);
        }
        Ok(())
    }

    /// The scene: the tables with the environment map's light last (the light selection is
    /// the settings', assigned by `Scene::light_table`); the instanced meshes' triangles follow
    /// the world-space ones in the triangle table.
    pub fn finish(
        mut self,
        name: String,
        camera: CameraDesc,
        background: Vec3,
        environment: Option<EnvironmentMap>,
    ) -> Scene {
        let world = self.triangles.len();
        self.triangles.append(&mut self.mesh_triangles);
        for m in &mut self.meshes {
            m.range = m.range.start + world..m.range.end + world;
        }
        for inst in &mut self.instances {
            inst.first_triangle += world as u32;
        }
        let instanced = instances_box(&self.mesh_boxes, &self.instances, &self.instance_meshes);
        let world_triangles = &self.triangles[..world];
        place_directional_lights(&mut self.lights, &self.spheres, world_triangles, instanced);
        if let Some(map) = &environment {
            let light = map.light(&self.spheres, world_triangles, instanced);
            self.lights.push(light);
        }
        if self
            .materials
            .iter()
            .any(|m| m.kind == material_kind::METALLIC_ROUGHNESS)
        {
            ggx_albedo::add_to(&mut self.textures).expect("the GGX albedo table is a texture");
        }
        if self
            .materials
            .iter()
            .any(|m| m.kind == material_kind::METALLIC_ROUGHNESS && m.has_sheen())
        {
            sheen_ltc::add_to(&mut self.textures).expect("the sheen table is a texture");
        }
        Scene {
            name,
            camera,
            background,
            materials: self.materials,
            material_names: self.material_names,
            spheres: self.spheres,
            triangles: self.triangles,
            triangle_groups: self.triangle_groups,
            lights: self.lights,
            environment,
            shading: self.shading,
            textures: self.textures,
            meshes: self.meshes,
            instances: self.instances,
            instance_meshes: self.instance_meshes,
            media: if self.media.is_empty() {
                vec![Medium::VACUUM]
            } else {
                self.media
            },
            medium: self.scene_medium,
            grids: self.grids,
            notes: self.flattened.iter().map(FlattenedCopies::note).collect(),
            inputs: Vec::new(),
        }
    }
}

/// The records that follow a triangle's shading record (after its tangent frame), where it has
/// them: vertex colours (`shading_flags::VERTEX_COLOURS`) and a second set of texture
/// coordinates (`shading_flags::SECOND_UVS`).
#[derive(Clone, Copy, Debug, Default)]
struct Trailing {
    colours: Option<[[f32; 3]; 3]>,
    second_uvs: Option<[[f32; 2]; 3]>,
}
