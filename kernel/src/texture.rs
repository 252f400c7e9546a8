//! Image textures: every texel of a scene in one `u32` buffer (the texture table), looked up and
//! bilinearly filtered by this shared code, so the CPU and the GPU compute the same value bit
//! for bit (no sampler objects, no descriptor indexing, no driver filtering).
//!
//! Layout of the table (`TextureTable` on the host builds it):
//! - word 0: the number of textures T;
//! - word [`GGX_ALBEDO`]: the record of the GGX albedo table (`bsdf::multiple_scattering`), a
//!   float texture read by [`at_nodes`], or `NONE`;
//! - word [`SHEEN_LTC`]: the record of the sheen table (`bsdf::sheen`), likewise, or `NONE`;
//! - words [`SRGB_TABLE`]..+256: the sRGB-decoded value of each byte (f32 bits; the host
//!   computes the IEC 61966-2-1 curve in f64), words [`LINEAR_TABLE`]..+256: byte / 255;
//! - words [`RECORDS`] + 10k..+10: texture k's record: first texel word, width, height, flags
//!   ([`flags`]), then an affine map of the texture coordinates (f32 bits, row-major a b c /
//!   d e f: u' = a u + b v + c, v' = d u + e v + f), read where `flags::TRANSFORM` is set
//!   (glTF's `KHR_texture_transform`); several records may share one image's texels;
//! - the texels: an 8-bit texture one word per texel (r | g << 8 | b << 16 | a << 24), a float
//!   texture three words (f32 bits of r, g, b); rows from the image's top, texels left to right.
//!
//! Texture coordinates: u from the image's left edge (0) to its right edge (1), v from its
//! bottom (0) to its top (1) (the OBJ and PLY convention); texel (i, j)'s centre is at
//! ((i + 1/2) / w, 1 - (j + 1/2) / h). Bilinear filtering between the four texel centres around
//! the point (pbrt-v4 `Image::Bilerp`, the same weights).

use crate::bsdf;
use crate::features::{Dynamic, FeatureSet};
use crate::real::{Real, V3};
use crate::scene::{texture_slot, Material, NONE};
use spirv_std::glam::{Vec2, Vec3};

/// Word holding the record of the GGX albedo table, or `NONE`.
pub const GGX_ALBEDO: usize = 1;
/// Word holding the record of the sheen table, or `NONE`.
pub const SHEEN_LTC: usize = 2;
/// Word of the sRGB decoding table.
pub const SRGB_TABLE: usize = 3;
/// Word of the linear decoding table (byte / 255).
pub const LINEAR_TABLE: usize = SRGB_TABLE + 256;
/// Word of texture 0's record.
pub const RECORDS: usize = LINEAR_TABLE + 256;
/// Words per texture record.
pub const RECORD_WORDS: usize = 10;
/// Word of a record's texture-coordinate map (six words).
pub const RECORD_TRANSFORM: usize = 4;

/// Bits of a texture record's flags word.
pub mod flags {
    /// Texels are three f32 words (an EXR or HDR image), else one RGBA8 word.
    pub const FLOAT: u32 = 1 << 0;
    /// 8-bit texels are sRGB-encoded (colour maps), else linear.
    pub const SRGB: u32 = 1 << 1;
    /// Bits 2-3: how u continues outside [0, 1] (one of `super::wrap`); bits 4-5: how v does.
    pub const WRAP_U_SHIFT: u32 = 2;
    pub const WRAP_V_SHIFT: u32 = 4;
    /// The record's texture-coordinate map applies (else the coordinates are used as given).
    pub const TRANSFORM: u32 = 1 << 6;
    /// The lookup reads the point's second texture coordinates (glTF's `TEXCOORD_1`,
    /// [`super::TexCoords::second`]).
    pub const SECOND_SET: u32 = 1 << 7;

    /// The flag bits of wrap modes `u` and `v` (`super::wrap`).
    pub const fn wrap(u: u32, v: u32) -> u32 {
        (u << WRAP_U_SHIFT) | (v << WRAP_V_SHIFT)
    }
}

/// How a texture continues outside [0, 1] along one axis (glTF's sampler `wrapS`, `wrapT`).
pub mod wrap {
    /// The image repeats (REPEAT).
    pub const REPEAT: u32 = 0;
    /// The edge texels continue (CLAMP_TO_EDGE).
    pub const CLAMP: u32 = 1;
    /// The image repeats mirrored every other time (MIRRORED_REPEAT).
    pub const MIRROR: u32 = 2;
}

/// A point's texture coordinates: glTF's `TEXCOORD_0` and `TEXCOORD_1` (the first again where
/// the triangle has no second set); each texture record says which it reads
/// ([`flags::SECOND_SET`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexCoords {
    pub first: Vec2,
    pub second: Vec2,
}

impl TexCoords {
    /// One set for every texture.
    #[inline]
    pub fn one(uv: Vec2) -> Self {
        Self {
            first: uv,
            second: uv,
        }
    }
}

/// The four texels around a point and the point's position between them: texel columns `x0`,
/// `x1` (x1 is x0's right neighbour, wrapped or clamped), rows `y0`, `y1` (y1 below y0), and the
/// weights `fx`, `fy` of x1 and y1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint<R = f32> {
    pub x0: u32,
    pub x1: u32,
    pub y0: u32,
    pub y1: u32,
    pub fx: R,
    pub fy: R,
}

/// The bilinear footprint of texture coordinates `uv` on a `width` x `height` image, u wrapping
/// as `wrap_u` and v as `wrap_v` (`wrap`): each coordinate first brought into [0, 1], so texel
/// indices are always in range whatever `uv` is (a non-finite coordinate reads as 0).
///
/// A mirrored repeat folds the coordinate (a triangle wave of period 2), then indexes as a
/// clamp does: across a fold the neighbour of an edge texel is that texel itself, and inside a
/// mirrored copy the folded coordinate's two texels and weights are the unfolded one's mirrored
/// (OpenGL 4.6, section 8.14.2, mirrors the texel indices instead; the two agree, tested
/// against that definition in f64).
#[inline]
pub fn footprint(uv: Vec2, width: u32, height: u32, wrap_u: u32, wrap_v: u32) -> Footprint {
    footprint_of(uv.x, uv.y, width, height, wrap_u, wrap_v)
}

/// [`footprint`] over any scalar [`Real`] (the `f32` instance is it, operation for operation),
/// so that tests run it under a Vulkan device's arithmetic. The indices are in range under any
/// arithmetic: the unit coordinate is clamped or reduced into [0, 1] and [`axis`] wraps or
/// clamps the indices it gets from it.
#[inline]
pub fn footprint_of<R: Real<Bits = u32>>(
    u: R,
    v: R,
    width: u32,
    height: u32,
    wrap_u: u32,
    wrap_v: u32,
) -> Footprint<R> {
    let (u, v) = (unit_coordinate_of(u, wrap_u), unit_coordinate_of(v, wrap_v));
    let half = R::splat(0.5);
    let (x0, x1, fx) = axis(
        u * R::splat(width as f32) - half,
        width,
        wrap_u != wrap::REPEAT,
    );
    let (y0, y1, fy) = axis(
        (R::splat(1.0) - v) * R::splat(height as f32) - half,
        height,
        wrap_v != wrap::REPEAT,
    );
    Footprint {
        x0,
        x1,
        y0,
        y1,
        fx,
        fy,
    }
}

/// `t` in [0, 1] by wrap mode `mode`: clamped, folded (t reduced modulo 2, then 2 - t beyond
/// 1), or its fractional part (which rounding may leave at 1, handled by [`axis`]); 0 for a
/// non-finite `t`.
#[inline]
pub fn unit_coordinate(t: f32, mode: u32) -> f32 {
    unit_coordinate_of(t, mode)
}

/// [`unit_coordinate`] over any scalar [`Real`].
#[inline]
pub fn unit_coordinate_of<R: Real<Bits = u32>>(t: R, mode: u32) -> R {
    let (zero, one, two) = (R::splat(0.0), R::splat(1.0), R::splat(2.0));
    if t.finite() == 0 {
        return zero;
    }
    if mode == wrap::REPEAT {
        t - t.floor()
    } else if mode == wrap::CLAMP {
        t.clamp(zero, one)
    } else {
        let r = t - two * (R::splat(0.5) * t).floor();
        if r.greater_than(one) != 0 {
            two - r
        } else {
            r
        }
    }
}

/// Along one axis of `n` texels, at continuous texel coordinate `x` in [-1/2, n - 1/2]: the two
/// texels whose centres enclose it and the second one's weight. Repeating, texel -1 is n - 1
/// and texel n is 0; clamping, both are the edge texel.
#[inline]
fn axis<R: Real<Bits = u32>>(x: R, n: u32, clamp: bool) -> (u32, u32, R) {
    let floor = x.floor();
    let f = x - floor;
    let last = n as i32 - 1;
    let i0 = floor.to_i32_bits() as i32;
    let i1 = i0 + 1;
    if clamp {
        (clamp_index(i0, last), clamp_index(i1, last), f)
    } else {
        (wrap_index(i0, last), wrap_index(i1, last), f)
    }
}

/// Texel index `i` in -1..=last + 1 clamped to 0..=last.
#[inline]
fn clamp_index(i: i32, last: i32) -> u32 {
    if i < 0 {
        0
    } else if i > last {
        last as u32
    } else {
        i as u32
    }
}

/// Texel index `i` in -1..=last + 1 wrapped into 0..=last (the image repeats).
#[inline]
fn wrap_index(i: i32, last: i32) -> u32 {
    if i < 0 {
        last as u32
    } else if i > last {
        (i - last - 1) as u32
    } else {
        i as u32
    }
}

/// Bilinear blend of the texel values `c00` (x0, y0), `c10` (x1, y0), `c01` (x0, y1) and `c11`
/// (x1, y1) at weights (fx, fy).
#[inline]
pub fn bilerp(c00: Vec3, c10: Vec3, c01: Vec3, c11: Vec3, fx: f32, fy: f32) -> Vec3 {
    let c = |c: Vec3| V3::from(c);
    bilerp_of(c(c00), c(c10), c(c01), c(c11), fx, fy).into()
}

/// [`bilerp`] over any scalar [`Real`].
#[inline]
pub fn bilerp_of<R: Real>(c00: V3<R>, c10: V3<R>, c01: V3<R>, c11: V3<R>, fx: R, fy: R) -> V3<R> {
    let one = R::splat(1.0);
    let top = c00 * (one - fx) + c10 * fx;
    let bottom = c01 * (one - fx) + c11 * fx;
    top * (one - fy) + bottom * fy
}

/// The value of texel (x, y) of texture `record` (its first word `offset`, its `width` and
/// `flags`): decoded through the table's sRGB or linear byte table, or read as f32.
#[inline(always)]
fn texel(table: &[u32], offset: u32, width: u32, tex_flags: u32, x: u32, y: u32) -> Vec3 {
    let index = y as usize * width as usize + x as usize;
    if tex_flags & flags::FLOAT != 0 {
        let w = offset as usize + 3 * index;
        Vec3::new(
            f32::from_bits(table[w]),
            f32::from_bits(table[w + 1]),
            f32::from_bits(table[w + 2]),
        )
    } else {
        let word = table[offset as usize + index];
        let base = if tex_flags & flags::SRGB != 0 {
            SRGB_TABLE
        } else {
            LINEAR_TABLE
        };
        Vec3::new(
            decoded(table, base, word),
            decoded(table, base, word >> 8),
            decoded(table, base, word >> 16),
        )
    }
}

/// The decoding table at `base`'s entry for the low byte of `word`.
#[inline]
fn decoded(table: &[u32], base: usize, word: u32) -> f32 {
    f32::from_bits(table[base + (word & 0xff) as usize])
}

/// Texture coordinates `uv` through the map of the record at word `r`:
/// (a u + b v + c, d u + e v + f).
#[inline]
fn transformed(table: &[u32], r: usize, uv: Vec2) -> Vec2 {
    let t = r + RECORD_TRANSFORM;
    let w = |k: usize| f32::from_bits(table[t + k]);
    Vec2::new(
        w(0) * uv.x + w(1) * uv.y + w(2),
        w(3) * uv.x + w(4) * uv.y + w(5),
    )
}

/// Texture `texture` of `table` at coordinates `uv` (through the record's map where it has
/// one), bilinearly filtered (RGB; linear values).
#[inline]
pub fn lookup(table: &[u32], texture: u32, uv: Vec2) -> Vec3 {
    lookup_in(Dynamic(0), table, texture, uv)
}

/// [`lookup`] in a scene of feature bits `features`: the record's map is looked at only where
/// the scene has one (`features::TEXTURE_TRANSFORMS`).
#[inline]
pub fn lookup_in<F: FeatureSet>(features: F, table: &[u32], texture: u32, uv: Vec2) -> Vec3 {
    lookup_at(features, table, texture, TexCoords::one(uv))
}

/// [`lookup_in`] at a point of texture coordinates `coords`, the texture reading the set its
/// record names (the second only in scenes with second sets, `features::SECOND_UVS`).
#[inline]
pub fn lookup_at<F: FeatureSet>(
    features: F,
    table: &[u32],
    texture: u32,
    coords: TexCoords,
) -> Vec3 {
    let (offset, width, tex_flags, f) = located(features, table, texture, coords);
    bilerp(
        texel(table, offset, width, tex_flags, f.x0, f.y0),
        texel(table, offset, width, tex_flags, f.x1, f.y0),
        texel(table, offset, width, tex_flags, f.x0, f.y1),
        texel(table, offset, width, tex_flags, f.x1, f.y1),
        f.fx,
        f.fy,
    )
}

/// Float texture `texture` read as a table of values at nodes: texel (i, j) (column i, row j
/// from the top) is the value at (x, y) = (i / (w - 1), j / (h - 1)); bilinear between the
/// nodes around (`x`, `y`), each clamped to [0, 1] (no texture coordinates, no wrap, no map).
#[inline]
pub fn at_nodes(table: &[u32], texture: u32, x: f32, y: f32) -> Vec3 {
    let r = RECORDS + RECORD_WORDS * texture as usize;
    let (offset, width, height, tex_flags) = (table[r], table[r + 1], table[r + 2], table[r + 3]);
    let (x0, x1, fx) = axis(x.clamp(0.0, 1.0) * (width - 1) as f32, width, true);
    let (y0, y1, fy) = axis(y.clamp(0.0, 1.0) * (height - 1) as f32, height, true);
    bilerp(
        texel(table, offset, width, tex_flags, x0, y0),
        texel(table, offset, width, tex_flags, x1, y0),
        texel(table, offset, width, tex_flags, x0, y1),
        texel(table, offset, width, tex_flags, x1, y1),
        fx,
        fy,
    )
}

/// (E(`mu`), E_avg, the coat's albedo) at perceptual roughness `roughness` (alpha =
/// roughness^2) from the GGX albedo table of `table` (its record at word [`GGX_ALBEDO`];
/// `bsdf::multiple_scattering`, `bsdf::coat`), bilinear in (roughness, sqrt(mu)) between its
/// nodes (roughness i / (w - 1), cosine (j / (h - 1))^2), clamped to them; all 1 where the table
/// has none (a scene without glTF's material). `table` is a whole table (its header at least).
#[inline]
pub fn ggx_albedo(table: &[u32], roughness: f32, mu: f32) -> Vec3 {
    let record = table[GGX_ALBEDO];
    if record == NONE {
        return Vec3::ONE;
    }
    at_nodes(table, record, roughness, Real::sqrt(mu))
}

/// The sheen's linearly transformed cosine (A, B, R) at sheen roughness `roughness` and view
/// cosine `mu` from the sheen table of `table` (its record at word [`SHEEN_LTC`];
/// `bsdf::sheen`), bilinear in (roughness, mu) between its nodes (roughness i / (w - 1),
/// cosine j / (h - 1)), clamped to them; zero (no sheen) where the table has none.
#[inline]
pub fn sheen_ltc(table: &[u32], roughness: f32, mu: f32) -> Vec3 {
    let record = table[SHEEN_LTC];
    if record == NONE {
        return Vec3::ZERO;
    }
    at_nodes(table, record, roughness, mu)
}

/// The alpha channel of texture `texture` at `uv`, bilinearly filtered as [`lookup_in`]
/// filters the colour: an 8-bit texel's fourth byte / 255 (alpha is linear, glTF 2.0 section
/// 3.9.2, even in an sRGB-encoded colour map); 1 for a float texture, which has none.
#[inline]
pub fn alpha_in<F: FeatureSet>(features: F, table: &[u32], texture: u32, coords: TexCoords) -> f32 {
    let (offset, width, tex_flags, f) = located(features, table, texture, coords);
    if tex_flags & flags::FLOAT != 0 {
        return 1.0;
    }
    let top = texel_alpha(table, offset, width, f.x0, f.y0) * (1.0 - f.fx)
        + texel_alpha(table, offset, width, f.x1, f.y0) * f.fx;
    let bottom = texel_alpha(table, offset, width, f.x0, f.y1) * (1.0 - f.fx)
        + texel_alpha(table, offset, width, f.x1, f.y1) * f.fx;
    top * (1.0 - f.fy) + bottom * f.fy
}

/// The alpha of 8-bit texel (x, y) of the texture whose first texel word is `offset`.
#[inline]
fn texel_alpha(table: &[u32], offset: u32, width: u32, x: u32, y: u32) -> f32 {
    let word = table[offset as usize + y as usize * width as usize + x as usize];
    decoded(table, LINEAR_TABLE, word >> 24)
}

/// Texture `texture`'s first texel word, width and flags, and the footprint on it of the set
/// of `coords` it reads (through the record's map where it has one and the scene has maps).
#[inline(always)]
fn located<F: FeatureSet>(
    features: F,
    table: &[u32],
    texture: u32,
    coords: TexCoords,
) -> (u32, u32, u32, Footprint) {
    let r = RECORDS + RECORD_WORDS * texture as usize;
    let (offset, width, height, tex_flags) = (table[r], table[r + 1], table[r + 2], table[r + 3]);
    let uv = if features.second_uvs() && tex_flags & flags::SECOND_SET != 0 {
        coords.second
    } else {
        coords.first
    };
    let uv = if features.texture_transforms() && tex_flags & flags::TRANSFORM != 0 {
        transformed(table, r, uv)
    } else {
        uv
    };
    let f = footprint(
        uv,
        width,
        height,
        (tex_flags >> flags::WRAP_U_SHIFT) & 3,
        (tex_flags >> flags::WRAP_V_SHIFT) & 3,
    );
    (offset, width, tex_flags, f)
}

/// `material` at a point of texture coordinates `coords`: each parameter with a texture multiplied
/// by the texture's value there (alpha by its red channel; for glTF's metallic-roughness
/// material the `KS` map's blue channel multiplies metallic and its green roughness).
#[inline]
pub fn textured_material<F: FeatureSet>(
    features: F,
    material: &Material,
    table: &[u32],
    coords: TexCoords,
) -> Material {
    let mut m = *material;
    let t = material.textures;
    if t[texture_slot::KD] != NONE {
        let value = lookup_at(features, table, t[texture_slot::KD], coords);
        m.albedo = (Vec3::from(m.albedo) * value).to_array();
    }
    if t[texture_slot::KS] != NONE {
        bsdf::apply_ks_texture(
            &mut m,
            lookup_at(features, table, t[texture_slot::KS], coords),
        );
    }
    if t[texture_slot::ALPHA] != NONE {
        m.alpha *= lookup_at(features, table, t[texture_slot::ALPHA], coords).x;
    }
    if t[texture_slot::EMISSION] != NONE {
        let value = lookup_at(features, table, t[texture_slot::EMISSION], coords);
        m.emission = (Vec3::from(m.emission) * value).to_array();
    }
    m
}

/// The feature bits the texture table `table` asks for: [`crate::features::TEXTURE_TRANSFORMS`]
/// if a record has a coordinate map. (Host side: the kernel reads the bits.)
#[cfg(not(target_arch = "spirv"))]
pub fn table_features(table: &[u32]) -> u32 {
    let count = table.first().copied().unwrap_or(0) as usize;
    let mapped = (0..count).any(|k| table[RECORDS + RECORD_WORDS * k + 3] & flags::TRANSFORM != 0);
    if mapped {
        crate::features::TEXTURE_TRANSFORMS
    } else {
        0
    }
}
