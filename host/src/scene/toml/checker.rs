//! Checks a TOML scene's values and reports errors at their line, with the field's path.

use crate::scene::error::{line_of, SceneError};
use crate::scene::limits::MAX_COORDINATE;
use glam::Vec3;
use std::path::Path;
use toml::Spanned;

/// A point, direction or colour as the file gives it, with its place in the file.
pub(super) type V3 = Spanned<[f32; 3]>;

/// Checks values and reports errors at their line.
pub(super) struct Checker<'a> {
    pub path: &'a Path,
    pub text: &'a str,
}

impl Checker<'_> {
    pub fn err(
        &self,
        span: std::ops::Range<usize>,
        field: &str,
        msg: impl Into<String>,
    ) -> SceneError {
        SceneError::new(self.path, Some(line_of(self.text, span.start)), field, msg)
    }

    pub fn vec3(&self, v: &V3, field: &str) -> Result<Vec3, SceneError> {
        let a = *v.get_ref();
        if !a.iter().all(|c| c.is_finite()) {
            Err(self.err(v.span(), field, format!("{a:?} is not finite")))
        } else if !a.iter().all(|c| c.abs() <= MAX_COORDINATE) {
            Err(self.err(
                v.span(),
                field,
                format!("{a:?} has a component beyond {MAX_COORDINATE:e} (the range the renderer supports)"),
            ))
        } else {
            Ok(Vec3::from(a))
        }
    }

    pub fn color(&self, v: &V3, field: &str, max: Option<f32>) -> Result<Vec3, SceneError> {
        let c = self.vec3(v, field)?;
        if c.min_element() < 0.0 {
            return Err(self.err(
                v.span(),
                field,
                format!("{:?} has a negative component", c.to_array()),
            ));
        }
        if let Some(max) = max {
            if c.max_element() > max {
                return Err(self.err(
                    v.span(),
                    field,
                    format!("{:?} has a component above {max} (a surface cannot reflect more than it receives)", c.to_array()),
                ));
            }
        }
        Ok(c)
    }

    pub fn int(
        &self,
        v: &Spanned<i64>,
        field: &str,
        min: i64,
        max: i64,
    ) -> Result<u32, SceneError> {
        let x = *v.get_ref();
        if x < min || x > max {
            Err(self.err(v.span(), field, format!("{x} is outside {min}..={max}")))
        } else {
            Ok(x as u32)
        }
    }
}
