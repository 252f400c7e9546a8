//! The `[media]` table, the `[scene]` table's `medium` and the shapes' `interior`: named media
//! and the closed shapes they fill. A medium inside a sphere or a closed mesh whose material is
//! a dielectric (or an `interface`, a dielectric of index 1: no surface at all) becomes that
//! material's interior (`Material::interior_absorption`, `kernel::medium`), one copy of the
//! material per medium it holds.
//!
//! What renders today: media that absorb (`sigma_a`, per scene unit of length, RGB). Media
//! that scatter (`sigma_s`, `g`), grids (`grid`, `scale`) and a medium around the scene
//! (`[scene] medium`) are read and refused with an error naming the field, rather than
//! rendered without them.

use super::checker::{Checker, V3};
use crate::scene::builder::SceneTables;
use crate::scene::SceneError;
use kernel::scene::{material_kind, Material};
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// One `[media]` entry.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MediumFile {
    /// The absorption coefficient per scene unit of length, RGB (default 0).
    pub sigma_a: Option<V3>,
    /// The scattering coefficient (default 0) and the Henyey-Greenstein asymmetry `g`.
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

/// The file's media by name: their absorption coefficients.
#[derive(Default)]
pub(super) struct Media {
    absorption: BTreeMap<String, [f32; 3]>,
}

/// Reads `[media]` and `[scene]`.
pub(super) fn parse_media(
    ck: &Checker,
    media: &BTreeMap<String, Spanned<MediumFile>>,
    scene: Option<&Spanned<SceneSection>>,
) -> Result<Media, SceneError> {
    let mut out = Media::default();
    for (name, m) in media {
        let field = format!("media.{name}");
        let mf = m.get_ref();
        let not_yet = |span: std::ops::Range<usize>, key: &str, what: &str| {
            Err(ck.err(
                span,
                &format!("{field}.{key}"),
                format!("{what} is not rendered yet: only media that absorb (sigma_a) are"),
            ))
        };
        if let Some(s) = &mf.sigma_s {
            let s = ck.color(s, &format!("{field}.sigma_s"), None)?;
            if s.max_element() > 0.0 {
                return not_yet(m.span(), "sigma_s", "a medium that scatters");
            }
        }
        if let Some(g) = &mf.g {
            return not_yet(g.span(), "g", "a phase function");
        }
        if let Some(grid) = &mf.grid {
            return not_yet(grid.span(), "grid", "a density grid");
        }
        if let Some(scale) = &mf.scale {
            return not_yet(scale.span(), "scale", "a density grid's scale");
        }
        let sigma_a = match &mf.sigma_a {
            Some(s) => ck.color(s, &format!("{field}.sigma_a"), None)?,
            None => glam::Vec3::ZERO,
        };
        out.absorption.insert(name.clone(), sigma_a.to_array());
    }
    if let Some(medium) = scene.and_then(|s| s.get_ref().medium.as_ref()) {
        return Err(ck.err(
            medium.span(),
            "scene.medium",
            "a medium around the scene (fog) is not rendered yet: media fill closed shapes \
             (interior = NAME)",
        ));
    }
    Ok(out)
}

/// The material of a closed shape whose material is `material` (named by `material_name`)
/// holding the medium `interior` names, if any: `material` itself without one; with one, the
/// copy of that dielectric holding it. `field` is the shape's table (`sphere[i]`).
pub(super) fn with_interior(
    ck: &Checker,
    media: &Media,
    tables: &mut SceneTables,
    (material, material_name): (u32, &Spanned<String>),
    interior: Option<&Spanned<String>>,
    field: &str,
) -> Result<u32, SceneError> {
    let Some(interior) = interior else {
        return Ok(material);
    };
    let field = format!("{field}.interior");
    let Some(&absorption) = media.absorption.get(interior.get_ref()) else {
        let known: Vec<&str> = media.absorption.keys().map(String::as_str).collect();
        return Err(ck.err(
            interior.span(),
            &field,
            format!(
                "unknown medium '{}' (defined in [media]: {})",
                interior.get_ref(),
                known.join(", ")
            ),
        ));
    };
    if !tables.is_dielectric(material) {
        return Err(ck.err(
            interior.span(),
            &field,
            format!(
                "the shape's material '{}' is not a dielectric: a medium needs a boundary, a \
                 dielectric or an interface (interface = true)",
                material_name.get_ref()
            ),
        ));
    }
    Ok(tables.with_interior(material, interior.get_ref(), absorption))
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
