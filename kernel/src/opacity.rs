//! Surfaces with holes: glTF's `alphaMode` MASK (a cutout, present where the base colour's
//! alpha reaches `alphaCutoff`) and BLEND (present with probability alpha), decided for each
//! candidate hit while a ray traverses the scene, so that a ray's closest hit and a shadow
//! ray's verdict are those of the surfaces present. Both backends ask [`covers`]: the GPU in
//! the any-hit shaders of the ray-tracing pipeline (`crate::shaders`), the CPU in its BVH's
//! leaf test. `Material::opacity` holds the mode and its number.
//!
//! BLEND is stochastic transparency (Enderton, Sintorn, Shirley and Luebke 2010, "Stochastic
//! Transparency"; pbrt-v4 tests alpha the same way, `GeometricPrimitive::Intersect`, with a
//! number hashed from the ray): a candidate of alpha a is present when a uniform number u,
//! drawn for that candidate alone, is below a. The candidates along a ray draw independently,
//! so the nearest present one is candidate i with probability a_i x prod over the nearer j of
//! (1 - a_j), and a shadow ray is unoccluded with probability prod_j (1 - a_j): the layered
//! surfaces' transmittance. An estimator that follows the traversal's answer is therefore
//! unbiased for Blender's mix of the surface with a transparent BSDF (alpha of the surface,
//! 1 - alpha of the scene behind), with no weight to carry. The number is a hash of the ray's
//! bits and the candidate ([`CandidateRay::draw`]): the same in every traversal order, the same
//! when Vulkan runs an any-hit shader twice for one candidate (it may, without
//! `NO_DUPLICATE_ANY_HIT_INVOCATION`), the same in the CPU's scalar and packet traversals; and
//! each ray of a path is a new ray (its bits come from the path's own random numbers), so each
//! draws anew.

use crate::features::FeatureSet;
use crate::hash::pcg4d;
use crate::rng::u32_to_unit_f32;
use crate::scene::{texture_slot, Material, ShadingTriangle, Triangle, NONE};
use crate::surface::tex_coords;
use crate::texture::{alpha_in, TexCoords};
use spirv_std::glam::{Vec2, Vec3};

/// The tables [`covers`] reads: the scene's materials, shading records (texture coordinates)
/// and texture table.
#[derive(Clone, Copy)]
pub struct HoleTables<'a> {
    pub materials: &'a [Material],
    pub shading: &'a [ShadingTriangle],
    pub textures: &'a [u32],
}

/// A candidate hit: the world-space ray (as it was traced) and the triangle it met: its index
/// in the triangle table, or in its mesh for an instanced triangle, whose instance is
/// `instance` (`NONE` for a world-space triangle).
#[derive(Clone, Copy, Debug)]
pub struct CandidateRay {
    pub origin: Vec3,
    pub dir: Vec3,
    pub triangle: u32,
    pub instance: u32,
}

impl CandidateRay {
    /// The candidate's uniform number in (0, 1): two rounds of `pcg4d`, over the origin's bits
    /// and the triangle, then with the direction's bits and the instance mixed in.
    #[inline]
    pub fn draw(&self) -> f32 {
        let (o, d) = (self.origin, self.dir);
        let h = pcg4d([o.x.to_bits(), o.y.to_bits(), o.z.to_bits(), self.triangle]);
        let h = pcg4d([
            h[0] ^ d.x.to_bits(),
            h[1] ^ d.y.to_bits(),
            h[2] ^ d.z.to_bits(),
            h[3] ^ self.instance,
        ]);
        u32_to_unit_f32(h[0])
    }
}

/// Whether triangle `tri`, met by `ray` at barycentrics `bary`, is there (see the module's
/// documentation): always for a material of opacity 0; for MASK when the `KD` texture's alpha
/// at the point (1 without a texture or texture coordinates) is at least the material's
/// number; for BLEND when the candidate's number is below the factor's alpha times the
/// texture's.
#[inline]
pub fn covers<F: FeatureSet>(
    features: F,
    tables: &HoleTables,
    tri: &Triangle,
    bary: Vec2,
    ray: &CandidateRay,
) -> bool {
    let material = &tables.materials[tri.material as usize];
    if !material.has_holes() {
        return true;
    }
    let mut alpha = 1.0;
    if tri.shading != NONE {
        let coords = tex_coords(features, tables.shading, tri.shading, material, bary);
        alpha = texture_alpha(features, tables.textures, material, coords);
    }
    // A MASK's presence is 0 or 1 and needs no number; a BLEND draws one.
    let p = presence(material.opacity, alpha);
    p >= 1.0 || (p > 0.0 && ray.draw() < p)
}

/// The expected presence of material `material` (an index, or `NONE`: 1) at a point of
/// texture coordinates `uv`: 1 without holes; for MASK 1 where [`covers`] says it is there,
/// else 0; for BLEND the probability that it is there, the factor's alpha times the texture's.
/// A triangle light's samples are weighed by it (`light::triangle`): where a ray passing the
/// point finds the surface with probability c, a sample of the point carries c times its
/// emission, which keeps the light's two strategies (light and BSDF samples) unbiased under
/// the same MIS weights.
#[inline]
pub fn coverage<F: FeatureSet>(
    features: F,
    materials: &[Material],
    textures: &[u32],
    material: u32,
    uv: Vec2,
) -> f32 {
    if material == NONE {
        return 1.0;
    }
    let m = &materials[material as usize];
    if !m.has_holes() {
        return 1.0;
    }
    presence(
        m.opacity,
        texture_alpha(features, textures, m, TexCoords::one(uv)),
    )
}

/// The probability that a surface of opacity `t` (`Material::opacity`, not 0) is there where
/// its texture's alpha is `alpha`: a MASK's 1 where alpha reaches t, else 0; a BLEND's -t x
/// alpha. The one definition [`covers`] and [`coverage`] share.
#[inline]
fn presence(t: f32, alpha: f32) -> f32 {
    if t > 0.0 {
        if alpha >= t {
            1.0
        } else {
            0.0
        }
    } else {
        -t * alpha
    }
}

/// The alpha of `material`'s `KD` texture at `coords` (1 without one, or in a scene without
/// textures).
#[inline]
fn texture_alpha<F: FeatureSet>(
    features: F,
    textures: &[u32],
    material: &Material,
    coords: TexCoords,
) -> f32 {
    let map = material.textures[texture_slot::KD];
    if features.textures() && map != NONE {
        alpha_in(features, textures, map, coords)
    } else {
        1.0
    }
}
