//! Transforms of the scene file's shapes: `scale` (a number or [x, y, z]), `rotate` ([degrees,
//! axis x, y, z], about an axis through the origin, counter-clockwise looking down the axis),
//! `translate`, applied in that order (M = T R S, glTF's order), or a row-major 4 x 4 affine
//! `matrix` instead. Applied when the scene loads: the kernel's tables are in world space.

use super::error::SceneError;
use super::file::Checker;
use glam::{DMat3, DMat4, DVec3, DVec4, Mat3, Vec3};
use toml::Spanned;

/// An affine transform x -> linear x + translation, with the normals' matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// The linear part (scale, then rotation), or `None` for the identity, so shapes without a
    /// rotation or matrix keep the plain arithmetic `p * scale + translate` bit for bit.
    pub linear: Option<Mat3>,
    /// A per-axis scale applied before `linear` when the transform was given as TRS.
    pub scale: Vec3,
    pub translation: Vec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self {
            linear: None,
            scale: Vec3::ONE,
            translation: Vec3::ZERO,
        }
    }
}

impl Transform {
    /// The image of point `p`.
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.vector(p) + self.translation
    }

    /// The image of direction `v` (no translation).
    pub fn vector(&self, v: Vec3) -> Vec3 {
        let s = v * self.scale;
        match self.linear {
            Some(m) => m * s,
            None => s,
        }
    }

    /// The full linear part in f64.
    fn linear_f64(&self) -> DMat3 {
        let m = self.linear.map_or(DMat3::IDENTITY, |m| m.as_dmat3());
        m * DMat3::from_diagonal(self.scale.as_dvec3())
    }

    /// The image of normal `n` (the inverse transpose of the linear part), not normalised.
    pub fn normal(&self, n: Vec3) -> Vec3 {
        let m = self.linear_f64().inverse().transpose();
        (m * n.as_dvec3()).as_vec3()
    }

    /// Whether the transform mirrors (negative determinant): triangles' winding must then be
    /// reversed to keep their front face (glTF 2.0, "Transformations").
    pub fn mirrors(&self) -> bool {
        self.linear_f64().determinant() < 0.0
    }

    /// The 4 x 4 matrix of the transform, in f64.
    pub fn matrix(&self) -> DMat4 {
        let l = self.linear_f64();
        DMat4::from_cols(
            l.x_axis.extend(0.0),
            l.y_axis.extend(0.0),
            l.z_axis.extend(0.0),
            self.translation.as_dvec3().extend(1.0),
        )
    }

    /// The transform of affine matrix `m` (f64, as glTF's node hierarchy composes them):
    /// `None` for the identity (shapes keep their coordinates bit for bit). Err: a number that
    /// is not finite, a projective last row, or a singular linear part.
    pub fn affine(m: DMat4) -> Result<Option<Transform>, &'static str> {
        if !m.is_finite() {
            return Err("has a number that is not finite");
        }
        if m.row(3) != DVec4::W {
            return Err("is not affine (its last row is not [0, 0, 0, 1])");
        }
        if m == DMat4::IDENTITY {
            return Ok(None);
        }
        let linear = DMat3::from_mat4(m);
        if !(linear.determinant().abs() > 1e-30) || !linear.as_mat3().is_finite() {
            return Err("is singular: it flattens the shape");
        }
        Ok(Some(Transform {
            linear: Some(linear.as_mat3()),
            scale: Vec3::ONE,
            translation: m.w_axis.truncate().as_vec3(),
        }))
    }

    /// The factor a sphere's radius takes, if the linear part is a uniform scale times a
    /// rotation (within 1e-6 relative); `None` otherwise (a sphere would become an ellipsoid).
    pub fn uniform_scale(&self) -> Option<f32> {
        let m = self.linear_f64();
        let lengths = [m.x_axis.length(), m.y_axis.length(), m.z_axis.length()];
        let s = lengths[0];
        let orthogonal = m.x_axis.dot(m.y_axis).abs() <= 1e-6 * s * s
            && m.y_axis.dot(m.z_axis).abs() <= 1e-6 * s * s
            && m.z_axis.dot(m.x_axis).abs() <= 1e-6 * s * s;
        let equal = lengths.iter().all(|l| (l - s).abs() <= 1e-6 * s);
        (orthogonal && equal).then_some(s as f32)
    }
}

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
