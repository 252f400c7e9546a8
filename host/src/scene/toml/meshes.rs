//! The `[[mesh]]` table: OBJ and PLY meshes (`crate::scene::mesh`), placed by transforms;
//! a mesh several entries place with the same material is read once and, when large enough
//! and not emissive, instanced.

use super::checker::{Checker, V3};
use super::materials::find_material;
use super::media::{with_media, Media};
use super::transform::{parse_transform, transform_fields};
use crate::scene::builder::SceneTables;
use crate::scene::closed_surface::check_closed_outward;
use crate::scene::instancing::{flattening_reason, instance_record, INSTANCE_MIN_TRIANGLES};
use crate::scene::mesh::load_mesh;
use crate::scene::soup::TriangleSoup;
use crate::scene::SceneError;
use serde::Deserialize;
use std::collections::HashMap;
use std::path::Path;
use std::rc::Rc;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MeshFile {
    pub file: Spanned<String>,
    pub material: Spanned<String>,
    /// The medium inside (a `[media]` name; the material must be a dielectric or interface,
    /// and the mesh closed).
    pub interior: Option<Spanned<String>>,
    /// The medium outside it (a name in `[media]`; default: the scene's).
    pub exterior: Option<Spanned<String>>,
    /// Optional transform (`transform::parse_transform`): scale (a number or [x, y, z]), then
    /// rotate ([degrees, axis x, y, z]), then translate; or a row-major 4 x 4 affine matrix.
    pub scale: Option<Spanned<toml::Value>>,
    pub rotate: Option<Spanned<[f32; 4]>>,
    pub translate: Option<V3>,
    pub matrix: Option<Spanned<[[f32; 4]; 4]>>,
}

/// Adds the file's meshes to `tables`; mesh files are relative to `base_dir`.
pub(super) fn add_meshes(
    ck: &Checker,
    meshes: &[Spanned<MeshFile>],
    media: &Media,
    base_dir: &Path,
    tables: &mut SceneTables,
) -> Result<(), SceneError> {
    // A mesh file that several entries place with the same material is read once; from
    // INSTANCE_MIN_TRIANGLES triangles on and unless it emits, it is stored once and instanced,
    // but for placements a device's own inverse is not shown to keep
    // (`instancing::flattening_reason`), which are flattened with a note while the mesh's
    // flattened copies stay within their budget (`SceneTables::flattens`).
    let mesh_key = |mf: &MeshFile| {
        let interior = mf.interior.as_ref().map(|i| i.get_ref().as_str());
        let exterior = mf.exterior.as_ref().map(|i| i.get_ref().as_str());
        let material = format!("{} {interior:?} {exterior:?}", mf.material.get_ref());
        (mf.file.get_ref().clone(), material)
    };
    let mut mesh_uses: HashMap<(String, String), usize> = HashMap::new();
    for m in meshes {
        *mesh_uses.entry(mesh_key(m.get_ref())).or_insert(0) += 1;
    }
    let mut loaded: HashMap<(String, String), Rc<TriangleSoup>> = HashMap::new();
    let mut instanced: HashMap<(String, String), u32> = HashMap::new();
    for (i, m) in meshes.iter().enumerate() {
        let mf = m.get_ref();
        let field = format!("mesh[{i}]");
        let material = find_material(
            ck,
            &tables.material_names,
            &mf.material,
            &format!("{field}.material"),
        )?;
        let material = with_media(
            ck,
            media,
            tables,
            (material, &mf.material),
            (mf.interior.as_ref(), mf.exterior.as_ref()),
            &field,
        )?;
        let mesh_path = base_dir.join(mf.file.get_ref());
        if !mesh_path.is_file() {
            return Err(ck.err(
                mf.file.span(),
                &format!("{field}.file"),
                format!("mesh file {} does not exist", mesh_path.display()),
            ));
        }
        let transform = if transform_fields!(mf).is_given() {
            Some(parse_transform(ck, &field, &transform_fields!(mf))?)
        } else {
            None
        };
        let key = mesh_key(mf);
        let placement = instance_record(&transform.unwrap_or_default(), 0);
        let flattening = flattening_reason(&placement);
        if let (Some(&mesh), None) = (instanced.get(&key), &flattening) {
            tables
                .add_instance(mesh, placement)
                .map_err(|msg| ck.err(m.span(), &field, msg))?;
            continue;
        }
        let soup = match loaded.get(&key) {
            Some(soup) => soup.clone(),
            None => Rc::new(load_mesh(&mesh_path)?),
        };
        if tables.is_dielectric(material) {
            check_closed_outward(&soup.triangles).map_err(|msg| {
                SceneError::new(
                    &mesh_path,
                    None,
                    format!("{field} (material '{}')", mf.material.get_ref()),
                    msg,
                )
            })?;
        }
        if tables.is_textured(material) && soup.uvs.is_empty() {
            return Err(ck.err(
                mf.material.span(),
                &format!("{field}.material"),
                format!(
                    "'{}' has textures but {} has no texture coordinates (OBJ vt, PLY u v)",
                    mf.material.get_ref(),
                    mf.file.get_ref()
                ),
            ));
        }
        let triangle_err = |(k, msg): (usize, String)| {
            ck.err(mf.file.span(), &format!("{field} triangle {k}"), msg)
        };
        let shared = mesh_uses[&key] >= 2
            && soup.triangles.len() >= INSTANCE_MIN_TRIANGLES
            && !tables.is_emissive(material);
        let instance = shared
            && match flattening {
                None => true,
                Some(reason) => !tables.flattens(mf.file.get_ref(), soup.triangles.len(), reason),
            };
        if instance {
            let mesh = match instanced.get(&key) {
                Some(&mesh) => mesh,
                None => {
                    let mesh = tables.begin_instanced_mesh(mf.file.get_ref().clone());
                    tables
                        .push_mesh_part(&soup, material)
                        .map_err(triangle_err)?;
                    mesh
                }
            };
            tables
                .add_instance(mesh, placement)
                .map_err(|msg| ck.err(m.span(), &field, msg))?;
            instanced.insert(key.clone(), mesh);
            loaded.insert(key, soup);
            continue;
        }
        tables
            .push_mesh(
                mf.file.get_ref().clone(),
                &soup,
                transform.as_ref(),
                material,
            )
            .map_err(triangle_err)?;
        if mesh_uses[&key] >= 2 {
            loaded.insert(key, soup);
        }
    }
    Ok(())
}
