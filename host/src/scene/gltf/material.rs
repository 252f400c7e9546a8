//! glTF materials onto the kernel's: the metallic-roughness model as the specification's
//! Appendix B defines it (`material_kind::METALLIC_ROUGHNESS`), its dielectric layer as
//! `KHR_materials_specular` and `KHR_materials_ior` change it, its clear coat
//! (`KHR_materials_clearcoat`), emissive materials as lights,
//! `KHR_materials_transmission` with `KHR_materials_ior` as the dielectric. What is approximated
//! or ignored is noted (`Scene::notes`); docs/gltf.md lists it.

use super::import::Import;
use super::textures::{normal_texture, texture};
use crate::scene::limits::IOR_RANGE;
use crate::scene::SceneError;
use glam::Vec3;
use kernel::medium::Medium;
use kernel::scene::{material_kind, texture_slot, Material};

/// The kernel material for glTF material `m` (`None`: the specification's default material,
/// white, metallic 1, roughness 1), its textures loaded.
pub(super) fn material(
    imp: &mut Import,
    m: Option<gltf::Material>,
) -> Result<Material, SceneError> {
    let Some(m) = m else {
        let mut out = Material::diffuse([1.0; 3]);
        out.kind = material_kind::METALLIC_ROUGHNESS;
        out.metallic = 1.0;
        out.roughness = 1.0;
        return Ok(out);
    };
    let field = format!("materials[{}]", m.index().unwrap_or(0));
    let label = match m.name() {
        Some(n) => format!("{field} ('{n}')"),
        None => field.clone(),
    };
    let path = imp.path.clone();
    let err = |msg: String| SceneError::new(&path, None, field.clone(), msg);
    let pbr = m.pbr_metallic_roughness();
    let unit = |x: f32, name: &str| -> Result<f32, SceneError> {
        if (0.0..=1.0).contains(&x) {
            Ok(x)
        } else {
            Err(err(format!("{name} {x} is outside 0..=1")))
        }
    };
    let base = pbr.base_color_factor();
    let base_rgb = Vec3::new(base[0], base[1], base[2]);
    for c in base {
        unit(c, "baseColorFactor component")?;
    }
    let metallic = unit(pbr.metallic_factor(), "metallicFactor")?;
    let roughness = unit(pbr.roughness_factor(), "roughnessFactor")?;
    if m.occlusion_texture().is_some() {
        imp.note(format!(
            "{label}: occlusionTexture ignored (a path tracer computes occlusion)"
        ));
    }

    let strength = m.emissive_strength().unwrap_or(1.0);
    if !(strength >= 0.0 && strength.is_finite()) {
        return Err(err(format!(
            "KHR_materials_emissive_strength {strength} must be finite and >= 0"
        )));
    }
    let emission = Vec3::from(m.emissive_factor()) * strength;
    if !(emission.is_finite() && emission.min_element() >= 0.0) {
        return Err(err(format!(
            "emissiveFactor x strength {:?} must be finite and >= 0",
            emission.to_array()
        )));
    }
    let emits = emission.max_element() > 0.0;

    if let Some(t) = m.transmission() {
        if t.transmission_factor() > 0.0 && emits {
            imp.note(format!(
                "{label}: emits and transmits: rendered as a light on the opaque material"
            ));
        } else if t.transmission_factor() > 0.0 {
            let ior = m.ior().unwrap_or(1.5);
            let (lo, hi) = IOR_RANGE;
            if !(lo..=hi).contains(&ior) {
                return Err(err(format!(
                    "KHR_materials_ior {ior} is outside {lo}..={hi}"
                )));
            }
            if t.transmission_factor() < 1.0 || t.transmission_texture().is_some() {
                imp.note(format!(
                    "{label}: transmission {} (and any transmission texture) rendered as fully \
                     transmissive glass",
                    t.transmission_factor()
                ));
            }
            if base_rgb != Vec3::ONE || pbr.base_color_texture().is_some() || metallic > 0.0 {
                imp.note(format!(
                    "{label}: glass ignores the base colour and metalness (clear glass)"
                ));
            }
            if m.alpha_mode() != gltf::material::AlphaMode::Opaque {
                imp.note(format!(
                    "{label}: glass ignores its alphaMode {:?} (no holes)",
                    m.alpha_mode()
                ));
            }
            let mut out = Material::diffuse([0.0; 3]);
            out.kind = material_kind::DIELECTRIC;
            out.ior = ior;
            out.alpha = roughness * roughness;
            let sigma_a = volume_absorption(imp, &label, &m, &err)?;
            match imp.tables.add_medium(Medium::new(sigma_a, [0.0; 3], 0.0)) {
                Some(medium) => out.set_interior_medium(medium),
                None => imp.note(format!(
                    "{label}: KHR_materials_volume dropped: the scene has 65534 other media \
                     (rendered as clear glass)"
                )),
            }
            return normal_map(imp, &label, &m, out);
        }
    }

    let mut out = Material::diffuse(base_rgb.to_array());
    out.kind = material_kind::METALLIC_ROUGHNESS;
    out.metallic = metallic;
    out.roughness = roughness;
    (out.layer_f0, out.layer_f90) = dielectric_layer(imp, &label, &m, &err)?;
    out.coat = clear_coat(imp, &label, &m, &err)?;
    if let Some((colour, roughness)) = sheen(imp, &label, &m, &err)? {
        out.set_sheen(colour, roughness);
    }
    out.opacity = opacity(&m, base[3], pbr.base_color_texture().is_some(), &err)?;
    if emits {
        // A light (its triangles in the light table) that reflects as its material does, as
        // a Principled BSDF with emission does in Blender.
        out.emission = emission.to_array();
        if let Some(info) = m.emissive_texture() {
            out.textures[texture_slot::EMISSION] = texture(imp, &label, &info, true)?;
        }
    }
    if let Some(info) = pbr.base_color_texture() {
        out.textures[texture_slot::KD] = texture(imp, &label, &info, true)?;
    }
    if let Some(info) = pbr.metallic_roughness_texture() {
        out.textures[texture_slot::KS] = texture(imp, &label, &info, false)?;
    }
    normal_map(imp, &label, &m, out)
}

/// `Material::opacity` of material `m` (`kernel::opacity`) from its `alphaMode`, its
/// `alphaCutoff` and its base colour's alpha `alpha` (a base colour texture's alpha multiplies
/// it where `textured`): OPAQUE, a MASK of cutoff 0 and a BLEND of alpha 1 without a texture
/// are 0 (present everywhere); a MASK is alphaCutoff / alpha and a BLEND -alpha, either of
/// alpha 0 being 2 (present nowhere: no alpha reaches it).
fn opacity(
    m: &gltf::Material,
    alpha: f32,
    textured: bool,
    err: &dyn Fn(String) -> SceneError,
) -> Result<f32, SceneError> {
    use gltf::material::AlphaMode;
    const NOWHERE: f32 = 2.0;
    Ok(match m.alpha_mode() {
        AlphaMode::Opaque => 0.0,
        AlphaMode::Mask => {
            let cutoff = m.alpha_cutoff().unwrap_or(0.5);
            if !(cutoff >= 0.0 && cutoff.is_finite()) {
                return Err(err(format!("alphaCutoff {cutoff} must be finite and >= 0")));
            }
            if cutoff == 0.0 {
                0.0
            } else if alpha == 0.0 {
                NOWHERE
            } else {
                (cutoff / alpha).min(NOWHERE)
            }
        }
        AlphaMode::Blend if alpha == 1.0 && !textured => 0.0,
        AlphaMode::Blend if alpha == 0.0 => NOWHERE,
        AlphaMode::Blend => -alpha,
    })
}

/// The dielectric layer of opaque material `m` (`Material::layer_f0`, `layer_f90`): its
/// reflectance at normal incidence min(((ior - 1) / (ior + 1))^2 x specularColorFactor, 1) x
/// specularFactor and at grazing incidence specularFactor (`KHR_materials_ior`, default 1.5;
/// `KHR_materials_specular`, defaults 1 and white). The extension's two textures are noted and
/// their factors used.
fn dielectric_layer(
    imp: &mut Import,
    label: &str,
    m: &gltf::Material,
    err: &dyn Fn(String) -> SceneError,
) -> Result<([f32; 3], f32), SceneError> {
    let ior = m.ior().unwrap_or(1.5);
    // The specification allows 0 (the specular-glossiness conversion: F0 = 1) and any index
    // >= 1.
    if !(ior == 0.0 || (1.0..=IOR_RANGE.1).contains(&ior)) {
        return Err(err(format!(
            "KHR_materials_ior {ior} of an opaque material must be 0 or within 1..={}",
            IOR_RANGE.1
        )));
    }
    let (factor, colour) = match m.specular() {
        None => (1.0, [1.0; 3]),
        Some(s) => {
            if s.specular_texture().is_some() || s.specular_color_texture().is_some() {
                imp.note(format!(
                    "{label}: KHR_materials_specular textures ignored (its factors are used)"
                ));
            }
            (s.specular_factor(), s.specular_color_factor())
        }
    };
    if !(0.0..=1.0).contains(&factor) {
        return Err(err(format!(
            "KHR_materials_specular.specularFactor {factor} is outside 0..=1"
        )));
    }
    if !colour.iter().all(|c| c.is_finite() && *c >= 0.0) {
        return Err(err(format!(
            "KHR_materials_specular.specularColorFactor {colour:?} must be finite and >= 0"
        )));
    }
    let f0 = ((ior as f64 - 1.0) / (ior as f64 + 1.0)).powi(2);
    let layer_f0 = colour.map(|c| ((f0 * c as f64).min(1.0) * factor as f64) as f32);
    Ok((layer_f0, factor))
}

/// The `Material::coat` word of opaque material `m`'s `KHR_materials_clearcoat`
/// (`clearcoatFactor` and `clearcoatRoughnessFactor`, defaults 0; each within 0..=1), 0
/// without one. The `gltf` crate does not read the extension: its JSON is read here. Its
/// textures (weight, roughness, normal) are noted and the factors used.
fn clear_coat(
    imp: &mut Import,
    label: &str,
    m: &gltf::Material,
    err: &dyn Fn(String) -> SceneError,
) -> Result<u32, SceneError> {
    let extension = "KHR_materials_clearcoat";
    let Some(coat) = m.extension_value(extension) else {
        return Ok(0);
    };
    let (weight, roughness) = (
        unit_number(coat, extension, "clearcoatFactor", err)?,
        unit_number(coat, extension, "clearcoatRoughnessFactor", err)?,
    );
    let textures = [
        "clearcoatTexture",
        "clearcoatRoughnessTexture",
        "clearcoatNormalTexture",
    ];
    if weight > 0.0 && textures.iter().any(|t| coat.get(*t).is_some()) {
        imp.note(format!(
            "{label}: KHR_materials_clearcoat textures ignored (its factors are used; the coat \
             shades with the surface's normal)"
        ));
    }
    Ok(if weight > 0.0 {
        Material::pack_coat(weight, roughness)
    } else {
        0
    })
}

/// The absorption coefficient of transmissive material `m`'s `KHR_materials_volume`: the
/// medium inside the mesh, sigma_a = -ln(attenuationColor) / attenuationDistance per channel
/// (the extension's definition; distance in world units, default infinite: none), zero without
/// the extension. `thicknessFactor` and its texture are for rasterisers that cannot trace the
/// thickness (the extension says path tracers ignore them). A colour of 0 absorbs everything at
/// once, which no coefficient says: it is read as 1e-6 (noted).
fn volume_absorption(
    imp: &mut Import,
    label: &str,
    m: &gltf::Material,
    err: &dyn Fn(String) -> SceneError,
) -> Result<[f32; 3], SceneError> {
    let extension = "KHR_materials_volume";
    let Some(volume) = m.extension_value(extension) else {
        return Ok([0.0; 3]);
    };
    let distance = match volume.get("attenuationDistance") {
        None => return Ok([0.0; 3]),
        Some(v) => match v.as_f64() {
            Some(d) if d > 0.0 && d.is_finite() => d,
            _ => {
                return Err(err(format!(
                    "{extension}.attenuationDistance {v} must be a positive number"
                )))
            }
        },
    };
    let colour = unit_rgb(volume, extension, "attenuationColor", [1.0; 3], err)?;
    if colour.contains(&0.0) {
        imp.note(format!(
            "{label}: {extension}.attenuationColor has a channel of 0 (all absorbed at once): \
             read as 1e-6"
        ));
    }
    Ok(colour.map(|c| (-(c.max(1e-6) as f64).ln() / distance) as f32))
}

/// Number `key` of extension `extension`'s JSON `value` (0 where absent), within 0..=1.
fn unit_number(
    value: &gltf::json::Value,
    extension: &str,
    key: &str,
    err: &dyn Fn(String) -> SceneError,
) -> Result<f32, SceneError> {
    match value.get(key) {
        None => Ok(0.0),
        Some(v) => match v.as_f64() {
            Some(x) if (0.0..=1.0).contains(&x) => Ok(x as f32),
            _ => Err(err(format!(
                "{extension}.{key} {v} must be a number within 0..=1"
            ))),
        },
    }
}

/// Colour `key` of extension `extension`'s JSON `value` (`default` where absent): three numbers
/// within 0..=1.
fn unit_rgb(
    value: &gltf::json::Value,
    extension: &str,
    key: &str,
    default: [f32; 3],
    err: &dyn Fn(String) -> SceneError,
) -> Result<[f32; 3], SceneError> {
    let Some(v) = value.get(key) else {
        return Ok(default);
    };
    let c: Option<Vec<f64>> = v
        .as_array()
        .map(|a| a.iter().filter_map(|x| x.as_f64()).collect());
    match c.as_deref() {
        Some(&[r, g, b]) if [r, g, b].iter().all(|x| (0.0..=1.0).contains(x)) => {
            Ok([r as f32, g as f32, b as f32])
        }
        _ => Err(err(format!(
            "{extension}.{key} {v} must be three numbers within 0..=1"
        ))),
    }
}

/// Opaque material `m`'s `KHR_materials_sheen` (`sheenColorFactor`, default black: no sheen;
/// `sheenRoughnessFactor`, default 0; each within 0..=1), read from its JSON as the `gltf`
/// crate does not read the extension. Its textures are noted and the factors used.
fn sheen(
    imp: &mut Import,
    label: &str,
    m: &gltf::Material,
    err: &dyn Fn(String) -> SceneError,
) -> Result<Option<([f32; 3], f32)>, SceneError> {
    let extension = "KHR_materials_sheen";
    let Some(sheen) = m.extension_value(extension) else {
        return Ok(None);
    };
    let colour = unit_rgb(sheen, extension, "sheenColorFactor", [0.0; 3], err)?;
    let roughness = unit_number(sheen, extension, "sheenRoughnessFactor", err)?;
    if colour == [0.0; 3] {
        return Ok(None);
    }
    if ["sheenColorTexture", "sheenRoughnessTexture"]
        .iter()
        .any(|t| sheen.get(*t).is_some())
    {
        imp.note(format!(
            "{label}: KHR_materials_sheen textures ignored (its factors are used)"
        ));
    }
    Ok(Some((colour, roughness)))
}

/// `out` with glTF material `m`'s `normalTexture` (linear) and its scale, where it has one.
fn normal_map(
    imp: &mut Import,
    label: &str,
    m: &gltf::Material,
    mut out: Material,
) -> Result<Material, SceneError> {
    let Some(n) = m.normal_texture() else {
        return Ok(out);
    };
    if !n.scale().is_finite() {
        return Err(SceneError::new(
            &imp.path,
            None,
            format!("materials[{}].normalTexture.scale", m.index().unwrap_or(0)),
            format!("{} is not finite", n.scale()),
        ));
    }
    out.textures[texture_slot::NORMAL] = normal_texture(imp, label, &n)?;
    out.normal_scale = n.scale();
    Ok(out)
}
