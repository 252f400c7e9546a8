//! The surface at a hit as the estimator sees it: the shading normal and texture coordinates
//! interpolated from the triangle's vertex attributes (`scene::ShadingTriangle`), and the
//! material with its textures applied there (`crate::texture`).
//!
//! Shading normals follow pbrt-v4 (`Triangle::InteractionFromIntersection`,
//! `SurfaceInteraction::SetShadingGeometry`, `BSDF`): the normal is the barycentric blend of
//! the vertex normals, normalised; the BSDF is evaluated and sampled in its frame only, the
//! cosine is the shading normal's, and a ray leaves offset along the *geometric* normal, on the
//! side its direction goes. The geometric normal stays authoritative for the side (inside and
//! outside of glass, the front of a light); the shading normal is turned to the side `wo` is
//! on, as pbrt-v4's two-sided BxDFs mirror `wo`'s hemisphere. Where the two normals disagree
//! about a direction (it is above one plane and below the other) pbrt-v4 lets the ray through
//! the surface: light leaks in through a thin wall, and rays enter the inside of closed meshes.
//! Here such a direction carries nothing (`path::PathState::vertex`; Veach's thesis, section
//! 5.3, and pbrt-v3's `BSDF::f` decide reflection against transmission by the geometric normal
//! the same way): no leaks, at the price of a little energy lost where the normals disagree,
//! which is near silhouettes of coarse meshes (docs/materials.md, "Shading normals").

use crate::features::FeatureSet;
use crate::path::SurfaceHit;
use crate::scene::{Material, ShadingTriangle, NONE};
use crate::texture::textured_material;
#[cfg(target_arch = "spirv")]
use crate::Float;
use spirv_std::glam::{Vec2, Vec3};

/// Barycentric blend of `a`, `b`, `c` at barycentrics (b1, b2) of the second and third.
#[inline]
pub fn blend3(a: Vec3, b: Vec3, c: Vec3, bary: Vec2) -> Vec3 {
    a * (1.0 - bary.x - bary.y) + b * bary.x + c * bary.y
}

/// Barycentric blend of texture coordinates.
#[inline]
pub fn blend2(a: Vec2, b: Vec2, c: Vec2, bary: Vec2) -> Vec2 {
    a * (1.0 - bary.x - bary.y) + b * bary.x + c * bary.y
}

/// The shading normal of `tri` at barycentrics `bary` (unit; `None`-like: the zero vector where
/// the blend has no direction, as opposite vertex normals can give).
#[inline]
pub fn interpolated_normal(tri: &ShadingTriangle, bary: Vec2) -> Vec3 {
    let n = blend3(
        Vec3::from(tri.normal0),
        Vec3::from(tri.normal1),
        Vec3::from(tri.normal2),
        bary,
    );
    let len2 = n.dot(n);
    if len2 > 0.0 && len2.is_finite() {
        n / len2.sqrt()
    } else {
        Vec3::ZERO
    }
}

/// The texture coordinates of `tri` at barycentrics `bary`.
#[inline]
pub fn interpolated_uv(tri: &ShadingTriangle, bary: Vec2) -> Vec2 {
    blend2(
        Vec2::from(tri.uv0),
        Vec2::from(tri.uv1),
        Vec2::from(tri.uv2),
        bary,
    )
}

/// The material at `hit` (a copy of its table entry; textures applied where the scene has
/// any), after filling `hit`'s shading normal (`smooth` where its triangle has vertex normals
/// that give one) and texture coordinates. A miss gets a black placeholder, never read.
#[inline]
pub fn shade<F: FeatureSet>(
    features: F,
    hit: &mut SurfaceHit,
    materials: &[Material],
    shading: &[ShadingTriangle],
    textures: &[u32],
) -> Material {
    if !hit.is_hit() {
        return Material::diffuse([0.0; 3]);
    }
    let material = materials[hit.material as usize];
    if !(features.shading_normals() || features.textures()) || hit.shading == NONE {
        return material;
    }
    let tri = shading[hit.shading as usize];
    if features.shading_normals() && tri.has_normals != 0 {
        let n = interpolated_normal(&tri, hit.barycentrics);
        if n != Vec3::ZERO {
            hit.shading_normal = n;
            hit.smooth = true;
        }
    }
    if features.textures() {
        hit.uv = interpolated_uv(&tri, hit.barycentrics);
        return textured_material(&material, textures, hit.uv);
    }
    material
}
