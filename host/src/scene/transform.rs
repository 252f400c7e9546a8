//! The affine transforms that place shapes (a TOML shape's `scale`, `rotate`, `translate` or
//! `matrix`, `toml/transform.rs`; a glTF node's), applied when the scene loads: the kernel's
//! tables are in world space.

use glam::{DMat3, DMat4, DVec4, Mat3, Vec3};

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
