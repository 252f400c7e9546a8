//! The `[media]` table, the `[scene]` table's `medium` and the shapes' `interior` and
//! `exterior`: named media, the closed shapes they fill or surround and the medium filling the
//! scene. A medium inside (outside) a sphere or a closed mesh whose material is a dielectric (or
//! an `interface`, a dielectric of index 1: no surface at all) becomes that material's interior
//! (exterior: `Material::interior_medium`, `Material::exterior_medium`, `kernel::medium`), one
//! copy of the material per combination.
//!
//! A medium is homogeneous (`sigma_a`, `sigma_s` per scene unit of length, RGB; `g`, the
//! Henyey-Greenstein asymmetry) or has a density grid (`grid`, a `.vol` or `.vdb` file, and
//! `scale`, its densities' factor: then the coefficients are per unit density).

use super::checker::{Checker, V3};
use crate::scene::builder::SceneTables;
use crate::scene::density_grid::DenseGrid;
use crate::scene::SceneError;
use kernel::geometry::intersect_triangle;
use kernel::medium::Medium;
use kernel::scene::{material_kind, Material};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

/// One `[media]` entry.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MediumFile {
    /// The absorption coefficient per scene unit of length, RGB (default 0).
    pub sigma_a: Option<V3>,
    /// The scattering coefficient (default 0) and the Henyey-Greenstein asymmetry `g`
    /// (default 0, isotropic).
    pub sigma_s: Option<V3>,
    pub g: Option<Spanned<f32>>,
    /// A density grid (a file) and the scale of its densities.
    pub grid: Option<Spanned<String>>,
    pub scale: Option<Spanned<f32>>,
}

/// The `[scene]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SceneSection {
    /// The medium outside every closed shape, the camera's.
    pub medium: Option<Spanned<String>>,
}

/// The file's media by name: their indices in the media table (0 for one that attenuates
/// nothing: vacuum).
#[derive(Default)]
pub(super) struct Media {
    index: BTreeMap<String, u32>,
}

impl Media {
    /// The medium `name` refers to (at `span`, the field `field`), or an error listing the
    /// media the file defines.
    fn get(&self, ck: &Checker, name: &Spanned<String>, field: &str) -> Result<u32, SceneError> {
        self.index.get(name.get_ref()).copied().ok_or_else(|| {
            let known: Vec<&str> = self.index.keys().map(String::as_str).collect();
            ck.err(
                name.span(),
                field,
                format!(
                    "unknown medium '{}' (defined in [media]: {})",
                    name.get_ref(),
                    known.join(", ")
                ),
            )
        })
    }
}

/// Reads `[media]` into the media table and `[scene]`'s medium (the scene's).
pub(super) fn parse_media(
    ck: &Checker,
    media: &BTreeMap<String, Spanned<MediumFile>>,
    scene: Option<&Spanned<SceneSection>>,
    base_dir: &Path,
    tables: &mut SceneTables,
) -> Result<Media, SceneError> {
    let mut out = Media::default();
    for (name, m) in media {
        let field = format!("media.{name}");
        let mf = m.get_ref();
        let grid = density_grid(ck, mf, &field, base_dir, tables)?;
        let coefficient = |v: &Option<V3>, key: &str| match v {
            Some(v) => ck.color(v, &format!("{field}.{key}"), None),
            None => Ok(glam::Vec3::ZERO),
        };
        // (`Checker::color` refuses negative and non-finite components.)
        let sigma_a = coefficient(&mf.sigma_a, "sigma_a")?;
        let sigma_s = coefficient(&mf.sigma_s, "sigma_s")?;
        let g = match &mf.g {
            Some(g) if !(g.get_ref().abs() < 1.0) => {
                return Err(ck.err(
                    g.span(),
                    &format!("{field}.g"),
                    format!(
                        "{} is not in (-1, 1): the Henyey-Greenstein asymmetry is a mean cosine \
                         (0 isotropic, toward 1 forward)",
                        g.get_ref()
                    ),
                ));
            }
            Some(g) => *g.get_ref(),
            None => 0.0,
        };
        let medium = Medium::new(sigma_a.to_array(), sigma_s.to_array(), g).with_grid(grid);
        let Some(index) = tables.add_medium(medium) else {
            return Err(ck.err(m.span(), &field, "more than 65534 media: the table is full"));
        };
        out.index.insert(name.clone(), index);
    }
    if let Some(medium) = scene.and_then(|s| s.get_ref().medium.as_ref()) {
        tables.scene_medium = out.get(ck, medium, "scene.medium")?;
    }
    Ok(out)
}

/// The density grid of medium `mf` (`field`: `media.NAME`), its `grid` file (relative to
/// `base_dir`) read with its `scale` and added to the grid table: the word of its record, or
/// 0 for a homogeneous medium.
fn density_grid(
    ck: &Checker,
    mf: &MediumFile,
    field: &str,
    base_dir: &Path,
    tables: &mut SceneTables,
) -> Result<u32, SceneError> {
    let scale = match &mf.scale {
        Some(s) if mf.grid.is_none() => {
            return Err(ck.err(
                s.span(),
                &format!("{field}.scale"),
                "scales a density grid's densities, and the medium has no grid (a homogeneous \
                 medium's coefficients are its own)",
            ));
        }
        Some(s) if !(s.get_ref().is_finite() && *s.get_ref() >= 0.0) => {
            return Err(ck.err(
                s.span(),
                &format!("{field}.scale"),
                format!("{} is not a finite non-negative number", s.get_ref()),
            ));
        }
        Some(s) => *s.get_ref(),
        None => 1.0,
    };
    let Some(grid) = &mf.grid else {
        return Ok(0);
    };
    let key = format!("{field}.grid");
    let path = base_dir.join(grid.get_ref());
    let dense = DenseGrid::read(&path, scale).map_err(|e| ck.err(grid.span(), &key, e))?;
    tables
        .grids
        .add(&dense)
        .ok_or_else(|| ck.err(grid.span(), &key, "the grid table passes 2^32 words"))
}

/// The material of a closed shape whose material is `material` (named by `material_name`)
/// with the medium `interior` names inside it and the one `exterior` names outside it, if
/// any (by default vacuum inside and the scene's medium outside): `material` itself without
/// either; else the copy of that dielectric with them (`SceneTables::with_media`). `field` is
/// the shape's table (`sphere[i]`).
pub(super) fn with_media(
    ck: &Checker,
    media: &Media,
    tables: &mut SceneTables,
    (material, material_name): (u32, &Spanned<String>),
    (interior, exterior): (Option<&Spanned<String>>, Option<&Spanned<String>>),
    field: &str,
) -> Result<u32, SceneError> {
    let mut named = [None, None];
    for (k, (key, name)) in [("interior", interior), ("exterior", exterior)]
        .into_iter()
        .enumerate()
    {
        let Some(name) = name else { continue };
        let field = format!("{field}.{key}");
        let medium = media.get(ck, name, &field)?;
        if !tables.is_dielectric(material) {
            return Err(ck.err(
                name.span(),
                &field,
                format!(
                    "the shape's material '{}' is not a dielectric: a medium needs a boundary, \
                     a dielectric or an interface (interface = true)",
                    material_name.get_ref()
                ),
            ));
        }
        named[k] = Some((name.get_ref().as_str(), medium));
    }
    Ok(tables.with_media(material, named[0], named[1]))
}

/// `interface = true` (the entry at `span`): a smooth dielectric of index 1 (light crosses it
/// unbent and unreflected; a medium's boundary), refused beside any surface key
/// (`surface_keys`).
pub(super) fn interface_material(
    ck: &Checker,
    field: &str,
    interface: &Spanned<bool>,
    span: std::ops::Range<usize>,
    surface_keys: bool,
) -> Result<Material, SceneError> {
    if !*interface.get_ref() {
        return Err(ck.err(
            interface.span(),
            &format!("{field}.interface"),
            "may only be true (omit it for a surface)",
        ));
    }
    if surface_keys {
        return Err(ck.err(
            span,
            field,
            "an interface has no surface: it takes no other key",
        ));
    }
    let mut out = Material::diffuse([0.0; 3]);
    out.kind = material_kind::DIELECTRIC;
    out.ior = 1.0;
    Ok(out)
}

/// Err where the camera's eye lies inside a sphere or a closed world-space mesh holding a
/// medium: a path starts in the scene's medium (`kernel::medium`), so a camera inside such a
/// shape would see its inside as if it were outside. A mesh's inside is found by parity: a ray
/// from the eye crosses the closed surfaces of a material an odd number of times when the eye
/// is inside one of them (closed shapes do not overlap); an instanced mesh likewise in its
/// instance's object space. `span` is the `[camera]` table's.
pub(super) fn camera_outside_media(
    ck: &Checker,
    span: std::ops::Range<usize>,
    camera: &crate::scene::CameraDesc,
    tables: &SceneTables,
) -> Result<(), SceneError> {
    let inside_error = |shape: String| {
        Err(ck.err(
            span.clone(),
            "camera.eye",
            format!(
                "is inside {shape}, which holds a medium: a camera starts in the scene's medium \
                 ([scene] medium), so put it outside, or fill the scene with that medium instead"
            ),
        ))
    };
    for (i, s) in tables.spheres.iter().enumerate() {
        let material = &tables.materials[s.material as usize];
        let inside = (camera.eye - glam::Vec3::from(s.center)).length() < s.radius;
        if material.has_interior_medium() && inside {
            return inside_error(format!("sphere[{i}]"));
        }
    }
    // One direction no axis-aligned or 45-degree surface holds, so that the ray meets edges and
    // vertices with probability zero.
    let dir = glam::Vec3::new(0.5377, 0.6147, 0.5771).normalize();
    let eye = camera.eye;
    if let Some(m) = odd_crossings(tables, &tables.triangles, eye, dir) {
        let name = &tables.material_names[m as usize];
        return inside_error(format!("a closed mesh of material '{name}'"));
    }
    // Instanced meshes: the same parity in each instance's object space (the eye and the
    // direction mapped by its world-to-object matrix; crossings keep their count).
    for (i, (record, &mesh)) in tables
        .instances
        .iter()
        .zip(&tables.instance_meshes)
        .enumerate()
    {
        let m = &record.world_to_object;
        let map = |v: glam::Vec3, w: f32| {
            glam::Vec3::new(
                m[0] * v.x + m[1] * v.y + m[2] * v.z + m[3] * w,
                m[4] * v.x + m[5] * v.y + m[6] * v.z + m[7] * w,
                m[8] * v.x + m[9] * v.y + m[10] * v.z + m[11] * w,
            )
        };
        let triangles = &tables.mesh_triangles[tables.meshes[mesh as usize].range.clone()];
        if let Some(m) = odd_crossings(tables, triangles, map(eye, 1.0), map(dir, 0.0)) {
            let name = &tables.material_names[m as usize];
            return inside_error(format!("instance {i}, a closed mesh of material '{name}'"));
        }
    }
    Ok(())
}

/// The first material holding a medium whose `triangles` the ray `o + t d` (t >= 0) crosses an
/// odd number of times: the one whose closed surface encloses `o`, if any.
fn odd_crossings(
    tables: &SceneTables,
    triangles: &[kernel::scene::Triangle],
    o: glam::Vec3,
    d: glam::Vec3,
) -> Option<u32> {
    let mut crossings: BTreeMap<u32, u32> = BTreeMap::new();
    for t in triangles {
        let (p0, e1, e2) = (t.p0.into(), t.edge1.into(), t.edge2.into());
        if tables.materials[t.material as usize].has_interior_medium()
            && intersect_triangle(o, d, p0, e1, e2, 0.0, f32::INFINITY) >= 0.0
        {
            *crossings.entry(t.material).or_insert(0) += 1;
        }
    }
    crossings
        .into_iter()
        .find(|&(_, n)| n % 2 == 1)
        .map(|(m, _)| m)
}
