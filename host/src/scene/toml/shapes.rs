//! The `[[sphere]]` and `[[quad]]` tables: spheres (emissive ones become lights) and
//! quads, two triangles each (each triangle of an emissive one a light).

use super::checker::{Checker, V3};
use super::materials::find_material;
use super::media::{with_media, Media};
use super::transform::{parse_transform, transform_fields};
use crate::scene::builder::{wound, SceneTables};
use crate::scene::light_table::sphere_light;
use crate::scene::limits::{MAX_COORDINATE, MIN_RADIUS};
use crate::scene::{SceneError, TriangleGroup};
use kernel::scene::{ShadingTriangle, Sphere, NONE};
use serde::Deserialize;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SphereFile {
    pub center: V3,
    pub radius: Spanned<f32>,
    pub material: Spanned<String>,
    /// The medium inside (a `[media]` name; the material must be a dielectric or interface).
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

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct QuadFile {
    pub corner: V3,
    edge1: V3,
    edge2: V3,
    pub material: Spanned<String>,
    /// Optional transform (`transform::parse_transform`): scale (a number or [x, y, z]), then
    /// rotate ([degrees, axis x, y, z]), then translate; or a row-major 4 x 4 affine matrix.
    pub scale: Option<Spanned<toml::Value>>,
    pub rotate: Option<Spanned<[f32; 4]>>,
    pub translate: Option<V3>,
    pub matrix: Option<Spanned<[[f32; 4]; 4]>>,
}

/// Adds the file's spheres to `tables`.
pub(super) fn add_spheres(
    ck: &Checker,
    spheres: &[Spanned<SphereFile>],
    media: &Media,
    tables: &mut SceneTables,
) -> Result<(), SceneError> {
    for (i, s) in spheres.iter().enumerate() {
        let sf = s.get_ref();
        let center = ck.vec3(&sf.center, &format!("sphere[{i}].center"))?;
        let radius = *sf.radius.get_ref();
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(ck.err(
                sf.radius.span(),
                &format!("sphere[{i}].radius"),
                format!("{radius} must be a positive finite number"),
            ));
        }
        if !(MIN_RADIUS..=MAX_COORDINATE).contains(&radius) {
            return Err(ck.err(
                sf.radius.span(),
                &format!("sphere[{i}].radius"),
                format!("{radius:e} is outside {MIN_RADIUS:e}..={MAX_COORDINATE:e} (the range the renderer supports)"),
            ));
        }
        let (center, radius) = if transform_fields!(sf).is_given() {
            let field = format!("sphere[{i}]");
            let t = parse_transform(ck, &field, &transform_fields!(sf))?;
            let Some(k) = t.uniform_scale() else {
                return Err(ck.err(
                    s.span(),
                    &field,
                    "a sphere takes a uniform scale and rotations only (it would become an \
                     ellipsoid)",
                ));
            };
            let (c, r) = (t.point(center), radius * k);
            if !(MIN_RADIUS..=MAX_COORDINATE).contains(&r) || c.abs().max_element() > MAX_COORDINATE
            {
                return Err(ck.err(
                    s.span(),
                    &field,
                    format!("transformed, centre {c} and radius {r:e} leave the range the renderer supports"),
                ));
            }
            (c, r)
        } else {
            (center, radius)
        };
        let material = find_material(
            ck,
            &tables.material_names,
            &sf.material,
            &format!("sphere[{i}].material"),
        )?;
        let material = with_media(
            ck,
            media,
            tables,
            (material, &sf.material),
            (sf.interior.as_ref(), sf.exterior.as_ref()),
            &format!("sphere[{i}]"),
        )?;
        if tables.is_textured(material) {
            return Err(ck.err(
                sf.material.span(),
                &format!("sphere[{i}].material"),
                format!(
                    "'{}' has textures: spheres have no texture coordinates (textures are for \
                     quads and meshes)",
                    sf.material.get_ref()
                ),
            ));
        }
        if tables.two_sided[material as usize] {
            return Err(ck.err(
                sf.material.span(),
                &format!("sphere[{i}].material"),
                format!(
                    "'{}' is two-sided: a sphere emits from its outside only (two_sided is for \
                     quads and meshes)",
                    sf.material.get_ref()
                ),
            ));
        }
        let light = if tables.is_emissive(material) {
            tables.lights.push(sphere_light(
                center,
                radius,
                tables.materials[material as usize].emission,
            ));
            (tables.lights.len() - 1) as u32
        } else {
            NONE
        };
        tables.spheres.push(Sphere {
            center: center.to_array(),
            radius,
            material,
            light,
            _pad: [0; 2],
        });
    }
    Ok(())
}

/// Adds the file's quads to `tables`, as one triangle group.
pub(super) fn add_quads(
    ck: &Checker,
    quads: &[Spanned<QuadFile>],
    tables: &mut SceneTables,
) -> Result<(), SceneError> {
    // A quad's texture coordinates: (0, 0) at its corner, (1, 0) along edge1, (0, 1) along edge2.
    let quad_uv = |corners: [[f32; 2]; 3]| ShadingTriangle {
        normal0: [0.0; 3],
        normal1: [0.0; 3],
        normal2: [0.0; 3],
        uv0: corners[0],
        uv1: corners[1],
        uv2: corners[2],
        flags: 0,
    };
    let quads_start = tables.triangles.len();
    for (i, q) in quads.iter().enumerate() {
        let qf = q.get_ref();
        let field = format!("quad[{i}]");
        let mut corner = ck.vec3(&qf.corner, &format!("{field}.corner"))?;
        let mut e1 = ck.vec3(&qf.edge1, &format!("{field}.edge1"))?;
        let mut e2 = ck.vec3(&qf.edge2, &format!("{field}.edge2"))?;
        let mut mirror = false;
        if transform_fields!(qf).is_given() {
            let t = parse_transform(ck, &field, &transform_fields!(qf))?;
            corner = t.point(corner);
            e1 = t.vector(e1);
            e2 = t.vector(e2);
            mirror = t.mirrors();
            if [corner, corner + e1 + e2]
                .iter()
                .any(|p| p.abs().max_element() > MAX_COORDINATE)
            {
                return Err(ck.err(
                    q.span(),
                    &field,
                    format!("a corner lies beyond {MAX_COORDINATE:e} after the transform"),
                ));
            }
        }
        let area = e1.cross(e2).length();
        if !(area > 0.0) || !area.is_finite() {
            return Err(ck.err(
                qf.edge2.span(),
                &format!("{field}.edge2"),
                "edges are zero or parallel: the quad has zero area",
            ));
        }
        let material = find_material(
            ck,
            &tables.material_names,
            &qf.material,
            &format!("{field}.material"),
        )?;
        if tables.is_dielectric(material) {
            return Err(ck.err(
                qf.material.span(),
                &format!("{field}.material"),
                format!(
                    "'{}' is a dielectric: it needs a closed surface (a sphere or a closed mesh) \
                     to have an inside, and a quad has none",
                    qf.material.get_ref()
                ),
            ));
        }
        let textured = tables.is_textured(material);
        // A mirroring transform reverses the winding, which keeps the front face the side the
        // untransformed quad's front maps to.
        tables.push_triangle(
            wound([corner, corner + e1, corner + e1 + e2], mirror),
            material,
            textured.then(|| quad_uv(wound([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], mirror))),
            None,
        );
        tables.push_triangle(
            wound([corner, corner + e1 + e2, corner + e2], mirror),
            material,
            textured.then(|| quad_uv(wound([[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]], mirror))),
            None,
        );
    }
    if tables.triangles.len() > quads_start {
        tables.triangle_groups.push(TriangleGroup {
            name: "quads".into(),
            range: quads_start..tables.triangles.len(),
        });
    }
    Ok(())
}
