//! The scene's tables as a loader fills them: materials, spheres, triangles with their shading
//! records, lights and textures. The TOML format and glTF files feed the same builder, so a
//! triangle becomes the same kernel records (and a light) whichever file it came from.

use super::environment::EnvironmentMap;
use super::file::MAX_COORDINATE;
use super::light_table::{assign_light_selection, place_directional_lights, triangle_light};
use super::mesh::TriangleSoup;
use super::tangents::face_tangent;
use super::textures::TextureTable;
use super::transform::Transform;
use super::{CameraDesc, Scene, TriangleGroup};
use crate::settings::RenderSettings;
use bytemuck::Zeroable;
use glam::Vec3;
use kernel::scene::{
    material_kind, texture_slot, Light, Material, ShadingTriangle, Sphere, Triangle, NONE,
};

/// The tables of a scene being loaded.
#[derive(Default)]
pub(super) struct SceneTables {
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    pub spheres: Vec<Sphere>,
    pub triangles: Vec<Triangle>,
    pub triangle_groups: Vec<TriangleGroup>,
    pub lights: Vec<Light>,
    pub shading: Vec<ShadingTriangle>,
    pub textures: TextureTable,
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
    /// Adds a material under `name`; its index.
    pub fn add_material(&mut self, name: String, material: Material) -> u32 {
        self.materials.push(material);
        self.material_names.push(name);
        (self.materials.len() - 1) as u32
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
        let mut tri = super::triangle(p, material);
        let m = self.materials[material as usize];
        let normal_mapped = m.textures[texture_slot::NORMAL] != NONE;
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
        }
        if self.is_emissive(material) {
            tri.light = self.lights.len() as u32;
            let mut light = triangle_light(&tri, m.emission, m.two_sided != 0);
            if let Some(a) = attributes {
                light.uv = [a.uv0, a.uv1, a.uv2]
                    .concat()
                    .try_into()
                    .expect("six numbers");
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
        let mirror = transform.is_some_and(|t| t.mirrors());
        let textured = self.is_textured(material);
        let start = self.triangles.len();
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
            let tangents = soup.tangents.get(k).filter(|_| textured).map(|t| {
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
            let attributes = (normals.is_some() || uvs.is_some()).then(|| {
                let n = normals.unwrap_or([[0.0; 3]; 3]);
                let t = uvs.unwrap_or([[0.0; 2]; 3]);
                ShadingTriangle {
                    normal0: n[0],
                    normal1: n[1],
                    normal2: n[2],
                    uv0: t[0],
                    uv1: t[1],
                    uv2: t[2],
                    has_normals: normals.is_some() as u32,
                }
            });
            self.push_triangle(p, material, attributes, tangents);
        }
        self.triangle_groups.push(TriangleGroup {
            name,
            range: start..self.triangles.len(),
        });
        Ok(())
    }

    /// The scene: the tables with the environment map's light last and the light selection
    /// assigned for `render.light_selection`.
    pub fn finish(
        mut self,
        name: String,
        camera: CameraDesc,
        render: RenderSettings,
        background: Vec3,
        environment: Option<EnvironmentMap>,
    ) -> Scene {
        place_directional_lights(&mut self.lights, &self.spheres, &self.triangles);
        if let Some(map) = &environment {
            self.lights.push(map.light(&self.spheres, &self.triangles));
        }
        assign_light_selection(&mut self.lights, render.light_selection.code());
        Scene {
            name,
            camera,
            render,
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
            notes: Vec::new(),
        }
    }
}
