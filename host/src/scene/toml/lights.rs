//! The `[[light]]` table: point, spot and directional lights (glTF's `KHR_lights_punctual`
//! kinds).

use super::checker::{Checker, V3};
use crate::scene::builder::SceneTables;
use crate::scene::light_table;
use crate::scene::SceneError;
use serde::Deserialize;
use toml::Spanned;

/// A point light, or with `direction` a spot light (glTF's `KHR_lights_punctual`): radiant
/// `intensity` (per steradian, RGB) at `position`; a spot's falloff runs from `inner_angle` to
/// `outer_angle` (cone half-angles in degrees, glTF's defaults 0 and 45).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LightFile {
    pub position: Option<V3>,
    pub intensity: Option<V3>,
    /// A directional light's irradiance (with `direction`, without `position`).
    pub irradiance: Option<V3>,
    pub direction: Option<V3>,
    pub inner_angle: Option<Spanned<f32>>,
    pub outer_angle: Option<Spanned<f32>>,
}

/// Adds the file's lights to `tables`.
pub(super) fn add_lights(
    ck: &Checker,
    lights: &[Spanned<LightFile>],
    tables: &mut SceneTables,
) -> Result<(), SceneError> {
    for (i, l) in lights.iter().enumerate() {
        let lf = l.get_ref();
        let field = format!("light[{i}]");
        if let Some(irradiance) = &lf.irradiance {
            // A directional light: a direction and an irradiance, nothing else.
            let extra = [
                ("position", lf.position.is_some()),
                ("intensity", lf.intensity.is_some()),
                ("inner_angle", lf.inner_angle.is_some()),
                ("outer_angle", lf.outer_angle.is_some()),
            ];
            if let Some((name, _)) = extra.iter().find(|e| e.1) {
                return Err(ck.err(
                    l.span(),
                    &field,
                    format!(
                        "gives irradiance (a directional light) and {name}: a directional light \
                         has a direction and an irradiance only"
                    ),
                ));
            }
            let Some(d) = &lf.direction else {
                return Err(ck.err(
                    l.span(),
                    &field,
                    "a directional light (irradiance) needs the direction its light travels",
                ));
            };
            let travel = ck.vec3(d, &format!("{field}.direction"))?;
            if !(travel.length() > 0.0) {
                return Err(ck.err(d.span(), &format!("{field}.direction"), "is zero"));
            }
            let e = ck.color(irradiance, &format!("{field}.irradiance"), None)?;
            tables
                .lights
                .push(light_table::directional_light(travel, e.to_array()));
            continue;
        }
        let (Some(position), Some(intensity)) = (&lf.position, &lf.intensity) else {
            return Err(ck.err(
                l.span(),
                &field,
                "needs position and intensity (a point or spot light) or direction and \
                 irradiance (a directional light)",
            ));
        };
        let position = ck.vec3(position, &format!("{field}.position"))?;
        let intensity = ck.color(intensity, &format!("{field}.intensity"), None)?;
        let angle = |a: &Option<Spanned<f32>>, name: &str, default: f32| match a {
            None => Ok(default),
            Some(x) => {
                let v = *x.get_ref();
                if (0.0..=90.0).contains(&v) {
                    Ok(v)
                } else {
                    Err(ck.err(
                        x.span(),
                        &format!("{field}.{name}"),
                        format!("{v} is outside 0..=90 degrees"),
                    ))
                }
            }
        };
        let cone = match &lf.direction {
            None => {
                if let Some(a) = lf.inner_angle.as_ref().or(lf.outer_angle.as_ref()) {
                    return Err(ck.err(
                        a.span(),
                        &field,
                        "cone angles belong to a spot light: give its direction",
                    ));
                }
                None
            }
            Some(d) => {
                let axis = ck.vec3(d, &format!("{field}.direction"))?;
                if !(axis.length() > 0.0) {
                    return Err(ck.err(d.span(), &format!("{field}.direction"), "is zero"));
                }
                let inner = angle(&lf.inner_angle, "inner_angle", 0.0)?;
                let outer = angle(&lf.outer_angle, "outer_angle", 45.0)?;
                if !(inner < outer) {
                    return Err(ck.err(
                        l.span(),
                        &field,
                        format!("inner_angle {inner} must be below outer_angle {outer}"),
                    ));
                }
                Some((axis, inner.to_radians(), outer.to_radians()))
            }
        };
        tables.lights.push(light_table::punctual_light(
            position,
            intensity.to_array(),
            cone,
        ));
    }
    Ok(())
}
