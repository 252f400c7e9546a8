//! The `[render]` table: render settings by name, each through the one vocabulary of
//! `crate::settings` (as `--set` and the flags are), in the file's order.

use super::checker::Checker;
use crate::scene::SceneError;
use crate::settings::RenderSettings;
use std::collections::BTreeMap;
use toml::Spanned;

/// The settings the table gives, over the defaults.
pub(super) fn render_settings(
    ck: &Checker,
    table: &BTreeMap<String, Spanned<toml::Value>>,
) -> Result<RenderSettings, SceneError> {
    let mut render = RenderSettings::default();
    let mut settings: Vec<_> = table.iter().collect();
    settings.sort_by_key(|(_, v)| v.span().start);
    for (key, value) in settings {
        let text = match value.get_ref() {
            toml::Value::String(s) => s.clone(),
            toml::Value::Integer(i) => i.to_string(),
            toml::Value::Float(f) => f.to_string(),
            toml::Value::Boolean(b) => b.to_string(),
            other => {
                return Err(ck.err(
                    value.span(),
                    &format!("render.{key}"),
                    format!("a {} is not a setting's value", other.type_str()),
                ))
            }
        };
        render
            .set(key, &text)
            .map_err(|m| ck.err(value.span(), &format!("render.{key}"), m))?;
    }
    Ok(render)
}
