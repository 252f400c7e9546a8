//! The `[materials]` table of a scene file: each entry checked field by field and made a
//! kernel [`Material`] (README "Scene format"; the models in `docs/materials.md`).

use super::checker::{Checker, V3};
use crate::scene::builder::SceneTables;
use crate::scene::limits::{IOR_RANGE, MAX_ALPHA};
use crate::scene::textures::{TextureTable, TextureUse};
use crate::scene::SceneError;
use glam::Vec3;
use kernel::scene::{material_kind, texture_slot, Material, NONE};
use kernel::texture::wrap;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

/// Named conductors: RGB (eta, k) as Mitsuba 3 reduces its measured spectra (the `eta` and `k`
/// of `mi.traverse` of `{"type": "conductor", "material": ...}` in the `scalar_rgb` variant,
/// Mitsuba 3.6), so both renderers use the same numbers.
pub const METALS: [(&str, [f32; 3], [f32; 3]); 4] = [
    (
        "gold",
        [0.143036, 0.375307, 1.44205],
        [3.983, 2.38556, 1.60336],
    ),
    (
        "silver",
        [0.155276, 0.116728, 0.138388],
        [4.82835, 3.12222, 2.1469],
    ),
    (
        "copper",
        [0.201005, 0.92375, 1.10222],
        [3.91326, 2.45305, 2.14209],
    ),
    (
        "aluminium",
        [1.6575, 0.880405, 0.521244],
        [9.22381, 6.2695, 4.837],
    ),
];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MaterialFile {
    pub kd: Option<V3>,
    pub ks: Option<V3>,
    pub alpha: Option<Spanned<f32>>,
    pub conductor: Option<Spanned<toml::Value>>,
    pub dielectric: Option<Spanned<DielectricFile>>,
    /// No surface at all, only where a medium begins and ends (`interior`): a smooth
    /// dielectric of index 1, alone in its entry.
    pub interface: Option<Spanned<bool>>,
    pub emission: Option<V3>,
    /// With `emission`, on quads and meshes: both faces emit (default: the front face).
    pub two_sided: Option<Spanned<bool>>,
    /// Image textures multiplying kd, ks, alpha (its red channel) and emission (each factor
    /// defaults to 1 where its map is given), relative to the scene file.
    pub kd_map: Option<Spanned<String>>,
    pub ks_map: Option<Spanned<String>>,
    pub alpha_map: Option<Spanned<String>>,
    pub emission_map: Option<Spanned<String>>,
    /// How the maps continue outside [0, 1]: "repeat" (default), "clamp" or "mirror".
    pub wrap: Option<Spanned<String>>,
    /// glTF's metallic-roughness material (`material_kind::METALLIC_ROUGHNESS`): base colour,
    /// metalness and perceptual roughness (alpha = roughness^2), each optional (defaults 1, as
    /// in glTF), with glTF's maps: the base colour (sRGB) and the metallic-roughness map (linear;
    /// blue metalness, green roughness).
    pub base_color: Option<V3>,
    pub metallic: Option<Spanned<f32>>,
    pub roughness: Option<Spanned<f32>>,
    pub base_color_map: Option<Spanned<String>>,
    pub metallic_roughness_map: Option<Spanned<String>>,
    /// Its clear coat (glTF's `KHR_materials_clearcoat`): weight and perceptual roughness,
    /// each in [0, 1], default 0.
    pub clearcoat: Option<Spanned<f32>>,
    pub clearcoat_roughness: Option<Spanned<f32>>,
    /// Its sheen (glTF's `KHR_materials_sheen`): colour (linear RGB in [0, 1], default black:
    /// none) and roughness in [0, 1] (default 0).
    pub sheen: Option<V3>,
    pub sheen_roughness: Option<Spanned<f32>>,
    /// A tangent-space normal map (linear; glTF's `normalTexture`, OpenGL's +y convention) and
    /// its x/y scale (default 1), for any reflecting material on triangles.
    pub normal_map: Option<Spanned<String>>,
    pub normal_scale: Option<Spanned<f32>>,
}

impl MaterialFile {
    /// Whether the entry describes glTF's metallic-roughness material.
    pub fn is_metallic_roughness(&self) -> bool {
        self.base_color.is_some()
            || self.metallic.is_some()
            || self.roughness.is_some()
            || self.base_color_map.is_some()
            || self.metallic_roughness_map.is_some()
            || self.clearcoat.is_some()
            || self.clearcoat_roughness.is_some()
            || self.sheen.is_some()
            || self.sheen_roughness.is_some()
    }

    /// The keys of the other kinds (Lambertian, Kd + Ks, metal, glass, light), each with
    /// whether the entry gives it.
    fn other_kind_keys(&self) -> [(&'static str, bool); 11] {
        [
            ("kd", self.kd.is_some()),
            ("ks", self.ks.is_some()),
            ("alpha", self.alpha.is_some()),
            ("conductor", self.conductor.is_some()),
            ("dielectric", self.dielectric.is_some()),
            ("emission", self.emission.is_some()),
            ("two_sided", self.two_sided.is_some()),
            ("kd_map", self.kd_map.is_some()),
            ("ks_map", self.ks_map.is_some()),
            ("alpha_map", self.alpha_map.is_some()),
            ("emission_map", self.emission_map.is_some()),
        ]
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DielectricFile {
    pub ior: Spanned<f32>,
}

/// Adds the file's materials to `tables`, in name order, with their textures (relative to
/// `base_dir`).
pub(super) fn add_materials(
    ck: &Checker,
    materials: &BTreeMap<String, Spanned<MaterialFile>>,
    base_dir: &Path,
    tables: &mut SceneTables,
) -> Result<(), SceneError> {
    for (name, m) in materials {
        let field = format!("materials.{name}");
        let mut material = material(ck, &field, m)?;
        attach_textures(ck, &field, m, base_dir, &mut tables.textures, &mut material)?;
        let two_sided = m.get_ref().two_sided.as_ref().is_some_and(|t| *t.get_ref());
        tables.add_material(name.clone(), material, two_sided);
    }
    Ok(())
}

/// The index of the material `s` names (at `field`) among `names`.
pub(super) fn find_material(
    ck: &Checker,
    names: &[String],
    s: &Spanned<String>,
    field: &str,
) -> Result<u32, SceneError> {
    names
        .iter()
        .position(|n| n == s.get_ref())
        .map(|i| i as u32)
        .ok_or_else(|| {
            ck.err(
                s.span(),
                field,
                format!(
                    "unknown material '{}' (defined: {})",
                    s.get_ref(),
                    names.join(", ")
                ),
            )
        })
}

/// The material `field` (`materials.NAME`) of entry `m`.
pub(super) fn material(
    ck: &Checker,
    field: &str,
    m: &Spanned<MaterialFile>,
) -> Result<Material, SceneError> {
    let mf = m.get_ref();
    let whole = |msg: &str| ck.err(m.span(), field, msg);
    if let Some(interface) = &mf.interface {
        let surface_keys = mf.is_metallic_roughness()
            || mf.normal_map.is_some()
            || mf.other_kind_keys().iter().any(|k| k.1);
        return super::media::interface_material(ck, field, interface, m.span(), surface_keys);
    }
    if mf.is_metallic_roughness() {
        return metallic_roughness(ck, field, m);
    }
    let kinds = [
        mf.ks.is_some(),
        mf.conductor.is_some(),
        mf.dielectric.is_some(),
        mf.emission.is_some(),
    ];
    if kinds.iter().filter(|&&k| k).count() > 1 {
        return Err(whole(
            "gives more than one of ks, conductor, dielectric and emission: choose one kind",
        ));
    }
    let alpha = match &mf.alpha {
        None if mf.alpha_map.is_some() => Some(1.0),
        Some(a) => {
            let x = *a.get_ref();
            if !(0.0..=MAX_ALPHA).contains(&x) {
                return Err(ck.err(
                    a.span(),
                    &format!("{field}.alpha"),
                    format!("{x} is outside 0..={MAX_ALPHA}"),
                ));
            }
            Some(x)
        }
        None => None,
    };
    if mf.emission.is_some() || mf.emission_map.is_some() {
        if alpha.is_some() || mf.ks_map.is_some() {
            return Err(whole(
                "has emission and a glossy lobe: a light reflects as a diffuse surface (kd, \
                 kd_map) or not at all",
            ));
        }
        let radiance = match &mf.emission {
            Some(e) => ck.color(e, &format!("{field}.emission"), None)?,
            None => Vec3::ONE,
        };
        // A light that also reflects diffusely (kd), as a Principled BSDF with emission does.
        let kd = match &mf.kd {
            Some(kd) => ck.color(kd, &format!("{field}.kd"), Some(1.0))?,
            None if mf.kd_map.is_some() => Vec3::ONE,
            None => Vec3::ZERO,
        };
        let mut out = Material::diffuse(kd.to_array());
        out.emission = radiance.to_array();
        return Ok(out);
    }
    if let Some(t) = &mf.two_sided {
        return Err(ck.err(
            t.span(),
            &format!("{field}.two_sided"),
            "belongs to emitters: only a light's faces can be one- or two-sided (surfaces \
             reflect on both sides)",
        ));
    }
    if mf.conductor.is_some() || mf.dielectric.is_some() {
        if mf.kd.is_some() {
            return Err(whole(
                "kd belongs to diffuse and kd + ks materials, not to metal or glass",
            ));
        }
        let mut out = Material::diffuse([0.0; 3]);
        out.alpha = alpha.unwrap_or(0.0);
        if let Some(c) = &mf.conductor {
            conductor(ck, &format!("{field}.conductor"), c, &mut out)?;
        } else if let Some(d) = &mf.dielectric {
            let ior = *d.get_ref().ior.get_ref();
            let (lo, hi) = IOR_RANGE;
            if !(lo..=hi).contains(&ior) {
                return Err(ck.err(
                    d.get_ref().ior.span(),
                    &format!("{field}.dielectric.ior"),
                    format!("{ior} is outside {lo}..={hi}"),
                ));
            }
            out.kind = material_kind::DIELECTRIC;
            out.ior = ior;
        }
        return Ok(out);
    }
    let kd = match &mf.kd {
        Some(kd) => Some(ck.color(kd, &format!("{field}.kd"), Some(1.0))?),
        None if mf.kd_map.is_some() => Some(Vec3::ONE),
        None => None,
    };
    if mf.ks.is_none() && mf.ks_map.is_some() {
        return Err(whole("has ks_map but no ks: give the specular factor"));
    }
    match (&mf.ks, kd, alpha) {
        (None, Some(kd), None) => Ok(Material::diffuse(kd.to_array())),
        (None, Some(_), Some(_)) => Err(whole(
            "has alpha but no ks: a rough lobe needs ks (or conductor, or dielectric)",
        )),
        (None, None, _) => Err(whole(
            "needs kd, kd + ks + alpha, conductor, dielectric or emission",
        )),
        (Some(ks), kd, alpha) => {
            let ks_field = format!("{field}.ks");
            let ks_value = ck.color(ks, &ks_field, Some(1.0))?;
            let kd = kd.unwrap_or(Vec3::ZERO);
            let Some(alpha) = alpha else {
                return Err(whole(
                    "has ks but no alpha: give the glossy lobe's roughness",
                ));
            };
            let sum = kd + ks_value;
            if sum.max_element() > 1.0 {
                return Err(ck.err(
                    ks.span(),
                    &ks_field,
                    format!(
                        "kd + ks = {:?} exceeds 1 in a channel: the surface would reflect more \
                         than it receives",
                        sum.to_array()
                    ),
                ));
            }
            let mut out = Material::diffuse(kd.to_array());
            out.kind = material_kind::GLOSSY;
            out.specular = ks_value.to_array();
            out.alpha = alpha;
            Ok(out)
        }
    }
}

/// glTF's metallic-roughness material: `base_color` (default white), `metallic` and
/// `roughness` (each in [0, 1], default 1, glTF's defaults) and their maps, a clear coat
/// (`clearcoat`, `clearcoat_roughness`, default 0), a sheen (`sheen`, default black, and
/// `sheen_roughness`, default 0); nothing of the other kinds beside them.
fn metallic_roughness(
    ck: &Checker,
    field: &str,
    m: &Spanned<MaterialFile>,
) -> Result<Material, SceneError> {
    let mf = m.get_ref();
    if let Some((name, _)) = mf.other_kind_keys().iter().find(|o| o.1) {
        return Err(ck.err(
            m.span(),
            field,
            format!(
                "mixes {name} with glTF's metallic-roughness fields (base_color, metallic, \
                 roughness and their maps): choose one kind"
            ),
        ));
    }
    let unit = |v: &Option<Spanned<f32>>, name: &str, default: f32| -> Result<f32, SceneError> {
        match v {
            None => Ok(default),
            Some(x) => {
                let value = *x.get_ref();
                if (0.0..=1.0).contains(&value) {
                    Ok(value)
                } else {
                    Err(ck.err(
                        x.span(),
                        &format!("{field}.{name}"),
                        format!("{value} is outside 0..=1"),
                    ))
                }
            }
        }
    };
    let base = match &mf.base_color {
        Some(b) => ck.color(b, &format!("{field}.base_color"), Some(1.0))?,
        None => Vec3::ONE,
    };
    let mut out = Material::diffuse(base.to_array());
    out.kind = material_kind::METALLIC_ROUGHNESS;
    out.metallic = unit(&mf.metallic, "metallic", 1.0)?;
    out.roughness = unit(&mf.roughness, "roughness", 1.0)?;
    let coat = unit(&mf.clearcoat, "clearcoat", 0.0)?;
    let coat_roughness = unit(&mf.clearcoat_roughness, "clearcoat_roughness", 0.0)?;
    if coat > 0.0 {
        out.coat = Material::pack_coat(coat, coat_roughness);
    }
    let sheen = match &mf.sheen {
        Some(c) => ck.color(c, &format!("{field}.sheen"), Some(1.0))?,
        None => Vec3::ZERO,
    };
    out.set_sheen(
        sheen.to_array(),
        unit(&mf.sheen_roughness, "sheen_roughness", 0.0)?,
    );
    Ok(out)
}

/// A conductor: a metal's name, `{ eta = [...], k = [...] }` or `{ reflectance = [...] }`.
fn conductor(
    ck: &Checker,
    field: &str,
    c: &Spanned<toml::Value>,
    out: &mut Material,
) -> Result<(), SceneError> {
    out.kind = material_kind::CONDUCTOR;
    let names: Vec<&str> = METALS.iter().map(|m| m.0).collect();
    let bad = |msg: String| ck.err(c.span(), field, msg);
    match c.get_ref() {
        toml::Value::String(name) => {
            let Some((_, eta, k)) = METALS.iter().find(|m| m.0 == name) else {
                return Err(bad(format!(
                    "unknown metal '{name}' (known: {})",
                    names.join(", ")
                )));
            };
            out.eta = *eta;
            out.k = *k;
            Ok(())
        }
        toml::Value::Table(t) => {
            let rgb = |key: &str| -> Result<Option<Vec3>, SceneError> {
                let Some(v) = t.get(key) else { return Ok(None) };
                let a = v
                    .as_array()
                    .filter(|a| a.len() == 3)
                    .and_then(|a| {
                        a.iter()
                            .map(|x| x.as_float().or(x.as_integer().map(|i| i as f64)))
                            .collect::<Option<Vec<f64>>>()
                    })
                    .ok_or_else(|| bad(format!("{key} must be [r, g, b] numbers")))?;
                let v = Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
                if !v.is_finite() || v.min_element() < 0.0 {
                    return Err(bad(format!("{key} = {:?} must be finite and >= 0", v.to_array())));
                }
                Ok(Some(v))
            };
            if let Some(key) = t
                .keys()
                .find(|k| !["eta", "k", "reflectance"].contains(&k.as_str()))
            {
                return Err(bad(format!(
                    "unknown field '{key}' (expected eta and k, or reflectance)"
                )));
            }
            match (rgb("eta")?, rgb("k")?, rgb("reflectance")?) {
                (Some(eta), Some(k), None) => {
                    if !(eta.min_element() > 0.0) {
                        return Err(bad("eta must be > 0 in every channel".into()));
                    }
                    out.eta = eta.to_array();
                    out.k = k.to_array();
                    Ok(())
                }
                (None, None, Some(r)) => {
                    if r.max_element() > 1.0 {
                        return Err(bad(format!(
                            "reflectance {:?} has a component above 1",
                            r.to_array()
                        )));
                    }
                    out.specular = r.to_array();
                    Ok(())
                }
                _ => Err(bad(
                    "needs eta and k together, or reflectance alone".into(),
                )),
            }
        }
        _ => Err(bad(format!(
            "must be a metal's name ({}), {{ eta = [...], k = [...] }} or {{ reflectance = [...] }}",
            names.join(", ")
        ))),
    }
}

/// The textures of entry `m` (`kd_map`, `ks_map`, `alpha_map`, `emission_map`,
/// `base_color_map`, `metallic_roughness_map`, `normal_map` with `normal_scale`, `wrap`), added
/// to `table` and recorded in `out.textures`. A colour map for kd or ks must not reflect more
/// than it receives: its largest value times the factor stays within 1 (and kd + ks within 1).
pub(super) fn attach_textures(
    ck: &Checker,
    field: &str,
    m: &Spanned<MaterialFile>,
    base_dir: &Path,
    table: &mut TextureTable,
    out: &mut Material,
) -> Result<(), SceneError> {
    let mf = m.get_ref();
    let mode = match &mf.wrap {
        None => wrap::REPEAT,
        Some(w) => match w.get_ref().as_str() {
            "repeat" => wrap::REPEAT,
            "clamp" => wrap::CLAMP,
            "mirror" => wrap::MIRROR,
            other => {
                return Err(ck.err(
                    w.span(),
                    &format!("{field}.wrap"),
                    format!("unknown wrap '{other}' (expected repeat, clamp or mirror)"),
                ))
            }
        },
    };
    let maps = [
        (&mf.kd_map, "kd_map", texture_slot::KD, true),
        (&mf.base_color_map, "base_color_map", texture_slot::KD, true),
        (&mf.ks_map, "ks_map", texture_slot::KS, true),
        (
            &mf.metallic_roughness_map,
            "metallic_roughness_map",
            texture_slot::KS,
            false,
        ),
        (&mf.alpha_map, "alpha_map", texture_slot::ALPHA, false),
        (
            &mf.emission_map,
            "emission_map",
            texture_slot::EMISSION,
            true,
        ),
        (&mf.normal_map, "normal_map", texture_slot::NORMAL, false),
    ];
    let mut peak = [Vec3::ONE; texture_slot::COUNT];
    for (map, name, slot, colour) in maps {
        let Some(map) = map else { continue };
        let map_field = format!("{field}.{name}");
        if slot == texture_slot::NORMAL {
            if out.emission != [0.0; 3] {
                return Err(ck.err(
                    map.span(),
                    &map_field,
                    "belongs to reflecting surfaces: a light has no shading normal",
                ));
            }
        } else if ![
            material_kind::DIFFUSE,
            material_kind::GLOSSY,
            material_kind::METALLIC_ROUGHNESS,
        ]
        .contains(&out.kind)
        {
            return Err(ck.err(
                map.span(),
                &map_field,
                "textures apply to diffuse, kd + ks, metallic-roughness and emitting materials",
            ));
        }
        let file = base_dir.join(map.get_ref());
        if !file.is_file() {
            return Err(ck.err(
                map.span(),
                &map_field,
                format!("texture file {} does not exist", file.display()),
            ));
        }
        let index = table.add(
            &file,
            TextureUse {
                colour,
                wrap: [mode; 2],
                transform: None,
                second_set: false,
            },
            &map_field,
        )?;
        peak[slot] = table.peak(index);
        out.textures[slot] = index;
    }
    if let Some(scale) = &mf.normal_scale {
        let value = *scale.get_ref();
        let scale_field = format!("{field}.normal_scale");
        if mf.normal_map.is_none() {
            return Err(ck.err(
                scale.span(),
                &scale_field,
                "belongs to normal_map: the material has none",
            ));
        }
        if !value.is_finite() {
            return Err(ck.err(scale.span(), &scale_field, format!("{value} is not finite")));
        }
        out.normal_scale = value;
    }
    if let Some(w) = &mf.wrap {
        if out.textures.iter().all(|&t| t == NONE) {
            return Err(ck.err(
                w.span(),
                &format!("{field}.wrap"),
                "belongs to textures: the material has no map",
            ));
        }
    }
    // glTF's material reflects at most its base colour (Appendix B), whatever the metalness.
    let reflected = if out.kind == material_kind::METALLIC_ROUGHNESS {
        Vec3::from(out.albedo) * peak[texture_slot::KD]
    } else {
        Vec3::from(out.albedo) * peak[texture_slot::KD]
            + Vec3::from(out.specular) * peak[texture_slot::KS]
    };
    if out.emission == [0.0; 3] && reflected.max_element() > 1.0 {
        return Err(ck.err(
            m.span(),
            field,
            format!(
                "kd and ks with their maps reach {:?} in a channel: the surface would reflect \
                 more than it receives",
                reflected.to_array()
            ),
        ));
    }
    Ok(())
}
