//! A TOML shape's transform fields: `scale` (a number or [x, y, z]), `rotate` ([degrees,
//! axis x, y, z], about an axis through the origin, counter-clockwise looking down the axis),
//! `translate`, applied in that order (M = T R S, glTF's order), or a row-major 4 x 4 affine
//! `matrix` instead.

use super::checker::Checker;
use crate::scene::transform::Transform;
use crate::scene::SceneError;
use glam::{DMat3, DVec3, Mat3, Vec3};
use toml::Spanned;

/// The transform fields of a shape's table (`transform::TransformFields`).
macro_rules! transform_fields {
    ($f:expr) => {
        $crate::scene::toml::transform::TransformFields {
            scale: $f.scale.as_ref(),
            rotate: $f.rotate.as_ref(),
            translate: $f.translate.as_ref(),
            matrix: $f.matrix.as_ref(),
        }
    };
}

pub(super) use transform_fields;

/// The transform fields of one shape as the file gives them.
pub(super) struct TransformFields<'a> {
    pub scale: Option<&'a Spanned<toml::Value>>,
    pub rotate: Option<&'a Spanned<[f32; 4]>>,
    pub translate: Option<&'a Spanned<[f32; 3]>>,
    pub matrix: Option<&'a Spanned<[[f32; 4]; 4]>>,
}

impl TransformFields<'_> {
    /// Whether any transform field is given (without one, a shape is used as written).
    pub fn is_given(&self) -> bool {
        self.scale.is_some()
            || self.rotate.is_some()
            || self.translate.is_some()
            || self.matrix.is_some()
    }
}

/// The transform of shape `field` (e.g. `mesh[2]`) from its fields, checked: finite numbers,
/// no zero scale, a rotation axis of non-zero length, `matrix` alone and affine and invertible.
pub(super) fn parse_transform(
    ck: &Checker,
    field: &str,
    f: &TransformFields,
) -> Result<Transform, SceneError> {
    let mut t = Transform::default();
    if let Some(m) = f.matrix {
        if let Some(span) = f
            .scale
            .map(|s| s.span())
            .or(f.rotate.map(|r| r.span()))
            .or(f.translate.map(|t| t.span()))
        {
            return Err(ck.err(
                span,
                &format!("{field}.matrix"),
                "give a matrix or scale/rotate/translate, not both",
            ));
        }
        let rows = m.get_ref();
        let err = |msg: &str| ck.err(m.span(), &format!("{field}.matrix"), msg);
        if !rows.iter().flatten().all(|x| x.is_finite()) {
            return Err(err("has a number that is not finite"));
        }
        if rows[3] != [0.0, 0.0, 0.0, 1.0] {
            return Err(err(
                "last row must be [0, 0, 0, 1] (an affine transform: no projection)",
            ));
        }
        let linear = Mat3::from_cols(
            Vec3::new(rows[0][0], rows[1][0], rows[2][0]),
            Vec3::new(rows[0][1], rows[1][1], rows[2][1]),
            Vec3::new(rows[0][2], rows[1][2], rows[2][2]),
        );
        if !(linear.as_dmat3().determinant().abs() > 1e-30) {
            return Err(err("is singular: it flattens the shape"));
        }
        t.linear = Some(linear);
        t.translation = Vec3::new(rows[0][3], rows[1][3], rows[2][3]);
        return Ok(t);
    }
    if let Some(s) = f.scale {
        let err = |msg: &str| ck.err(s.span(), &format!("{field}.scale"), msg);
        let v = match s.get_ref() {
            toml::Value::Float(x) => Vec3::splat(*x as f32),
            toml::Value::Integer(i) => Vec3::splat(*i as f32),
            toml::Value::Array(a) if a.len() == 3 => {
                let c: Option<Vec<f32>> = a
                    .iter()
                    .map(|x| x.as_float().or(x.as_integer().map(|i| i as f64)))
                    .map(|x| x.map(|x| x as f32))
                    .collect();
                let c = c.ok_or_else(|| err("must be a number or [x, y, z] numbers"))?;
                Vec3::new(c[0], c[1], c[2])
            }
            _ => return Err(err("must be a number or [x, y, z] numbers")),
        };
        if !(v.is_finite() && v.abs().min_element() > 0.0) {
            return Err(err("must be finite and non-zero in every axis"));
        }
        t.scale = v;
    }
    if let Some(r) = f.rotate {
        let [degrees, x, y, z] = *r.get_ref();
        let axis = DVec3::new(x as f64, y as f64, z as f64);
        if !(degrees.is_finite() && axis.is_finite() && axis.length() > 0.0) {
            return Err(ck.err(
                r.span(),
                &format!("{field}.rotate"),
                "must be [degrees, x, y, z] with finite numbers and a non-zero axis",
            ));
        }
        let m = DMat3::from_axis_angle(axis.normalize(), (degrees as f64).to_radians());
        t.linear = Some(m.as_mat3());
    }
    if let Some(tr) = f.translate {
        let v = Vec3::from(*tr.get_ref());
        if !v.is_finite() {
            return Err(ck.err(tr.span(), &format!("{field}.translate"), "must be finite"));
        }
        t.translation = v;
    }
    Ok(t)
}
