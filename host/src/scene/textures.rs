//! Image textures of a scene (`kd_map`, `ks_map`, `alpha_map`, `emission_map`): PNG, JPEG, EXR
//! or HDR images loaded with `image` into the one texture table the kernel reads
//! (`kernel::texture` describes its layout). 8-bit images keep one word per texel (decoded by
//! the table's sRGB or linear byte tables), float images three.

use super::error::SceneError;
use kernel::texture::{
    flags, GGX_ALBEDO, LINEAR_TABLE, RECORDS, RECORD_WORDS, SHEEN_LTC, SRGB_TABLE,
};
use std::path::{Path, PathBuf};

/// The first character of a record's name that is a table the renderer adds (the GGX albedo
/// table, `super::ggx_albedo`; the sheen table, `super::sheen_ltc`), not an image of the scene:
/// no file name starts with it.
pub const TABLE_NAME_START: char = '<';

/// Largest texture side accepted.
pub const MAX_TEXTURE_SIDE: u32 = 16384;

/// The texture table and what went into it.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureTable {
    /// The kernel's table: header, decoding tables, records, texels.
    pub words: Vec<u32>,
    /// Each texture: its file, its flags, its size.
    pub textures: Vec<TextureInfo>,
}

/// One texture of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureInfo {
    pub path: PathBuf,
    /// How the scene uses it (a file used twice the same way is one texture).
    pub usage: TextureUse,
    pub flags: u32,
    pub width: u32,
    pub height: u32,
}

/// How a texture is read: as colour (sRGB-encoded 8-bit images) or as linear data, how
/// coordinates outside [0, 1] wrap along u and v (`kernel::texture::wrap`), the map the
/// coordinates go through first, if any (glTF's `KHR_texture_transform`), and whether it reads
/// the second set of texture coordinates (glTF's `TEXCOORD_1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TextureUse {
    pub colour: bool,
    pub wrap: [u32; 2],
    pub transform: Option<UvTransform>,
    pub second_set: bool,
}

/// An affine map of texture coordinates in the kernel's convention (v up), row-major
/// [a, b, c, d, e, f]: (u, v) -> (a u + b v + c, d u + e v + f); equal when bit for bit equal.
#[derive(Clone, Copy, Debug)]
pub struct UvTransform(pub [f32; 6]);

impl PartialEq for UvTransform {
    fn eq(&self, other: &Self) -> bool {
        self.0.map(f32::to_bits) == other.0.map(f32::to_bits)
    }
}

impl Eq for UvTransform {}

impl UvTransform {
    /// The map that changes nothing.
    pub const IDENTITY: Self = Self([1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
}

/// The texels of a new record: its own, or those of record k (the same image, read through
/// another decoding table, wrap mode or coordinate map).
pub enum Texels<'a> {
    Own(&'a [u32]),
    SharedWith(usize),
}

/// The sRGB decoding of byte `b` (IEC 61966-2-1), in f64.
pub fn srgb_to_linear(b: u8) -> f64 {
    let c = b as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

impl Default for TextureTable {
    fn default() -> Self {
        Self::new()
    }
}

impl TextureTable {
    /// An empty table: no textures (no GGX albedo table either), the decoding tables in place.
    pub fn new() -> Self {
        let mut words = vec![0u32; RECORDS];
        words[GGX_ALBEDO] = kernel::scene::NONE;
        words[SHEEN_LTC] = kernel::scene::NONE;
        for b in 0..=255u8 {
            words[SRGB_TABLE + b as usize] = (srgb_to_linear(b) as f32).to_bits();
            words[LINEAR_TABLE + b as usize] = ((b as f64 / 255.0) as f32).to_bits();
        }
        Self {
            words,
            textures: Vec::new(),
        }
    }

    /// The scene's images: every record but the tables the renderer adds
    /// ([`TABLE_NAME_START`]).
    pub fn images(&self) -> impl Iterator<Item = &TextureInfo> {
        self.textures
            .iter()
            .filter(|t| !t.path.to_string_lossy().starts_with(TABLE_NAME_START))
    }

    /// Bytes the kernel's table takes.
    pub fn bytes(&self) -> usize {
        4 * self.words.len()
    }

    /// The index of the texture of `path` used as `usage`, loading it on first use (`field`
    /// names the scene's field in errors). The table is rebuilt with the new record, since
    /// records precede texels.
    pub fn add(&mut self, path: &Path, usage: TextureUse, field: &str) -> Result<u32, SceneError> {
        // The same file used the same way: no need to read it again.
        if let Some(k) = self.find(path, usage) {
            return Ok(k);
        }
        let err = |msg: String| SceneError::new(path, None, field, msg);
        let bytes = super::inputs::read(path).map_err(|e| err(format!("cannot read: {e}")))?;
        let image = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| err(format!("cannot read: {e}")))?
            .decode()
            .map_err(|e| {
                err(format!(
                    "not a readable PNG, JPEG, WebP, EXR or HDR image: {e}"
                ))
            })?;
        self.add_image(path, image, usage, field)
    }

    /// The texture already loaded from `path` for `usage`, if any.
    fn find(&self, path: &Path, usage: TextureUse) -> Option<u32> {
        self.textures
            .iter()
            .position(|t| t.path == path && t.usage == usage)
            .map(|k| k as u32)
    }

    /// Adds one of the renderer's own float tables (`name` starts with [`TABLE_NAME_START`]),
    /// `width` x `height` texels, texel (i, j) = `texel(i, j)`, clamped at its edges, and records
    /// its index in the table's header word `header`; returns the index. The kernel reads it
    /// at its nodes (`kernel::texture::at_nodes`).
    pub fn add_table(
        &mut self,
        name: &str,
        (width, height): (usize, usize),
        texel: impl Fn(usize, usize) -> [f32; 3],
        header: usize,
    ) -> Result<u32, SceneError> {
        let mut image = image::Rgb32FImage::new(width as u32, height as u32);
        for j in 0..height {
            for i in 0..width {
                image.put_pixel(i as u32, j as u32, image::Rgb(texel(i, j)));
            }
        }
        let usage = TextureUse {
            colour: false,
            wrap: [kernel::texture::wrap::CLAMP; 2],
            transform: None,
            second_set: false,
        };
        let index = self.add_image(
            Path::new(name),
            image::DynamicImage::ImageRgb32F(image),
            usage,
            name,
        )?;
        self.words[header] = index;
        Ok(index)
    }

    /// The index of decoded `image` used as `usage`, named `path` (a file, or a glTF file's
    /// image as `file#images[k]`): one record per name and use.
    pub fn add_image(
        &mut self,
        path: &Path,
        image: image::DynamicImage,
        usage: TextureUse,
        field: &str,
    ) -> Result<u32, SceneError> {
        if let Some(k) = self.find(path, usage) {
            return Ok(k);
        }
        let err = |msg: String| SceneError::new(path, None, field, msg);
        let (width, height) = (image.width(), image.height());
        if width == 0 || height == 0 || width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
            return Err(err(format!(
                "{width} x {height} texels: each side must be within 1..={MAX_TEXTURE_SIDE}"
            )));
        }
        let float = matches!(
            image.color(),
            image::ColorType::Rgb32F | image::ColorType::Rgba32F
        );
        let mut tex_flags = flags::wrap(usage.wrap[0], usage.wrap[1]);
        if usage.transform.is_some() {
            tex_flags |= flags::TRANSFORM;
        }
        if usage.second_set {
            tex_flags |= flags::SECOND_SET;
        }
        let texels: Vec<u32> = if float {
            tex_flags |= flags::FLOAT;
            let rgb = image.into_rgb32f();
            // A scene's image holds radiance or factors (non-negative); the renderer's own
            // tables may hold any finite number (the sheen table's B is negative).
            let table = path.to_string_lossy().starts_with(TABLE_NAME_START);
            if let Some((k, p)) = rgb
                .pixels()
                .enumerate()
                .find(|(_, p)| !p.0.iter().all(|c| c.is_finite() && (table || *c >= 0.0)))
            {
                return Err(err(format!(
                    "texel ({}, {}) is {:?}: values must be finite and non-negative",
                    k as u32 % width,
                    k as u32 / width,
                    p.0
                )));
            }
            rgb.pixels().flat_map(|p| p.0.map(f32::to_bits)).collect()
        } else {
            if usage.colour {
                tex_flags |= flags::SRGB;
            }
            image
                .into_rgba8()
                .pixels()
                .map(|p| u32::from_le_bytes(p.0))
                .collect()
        };
        // Used another way that reads the same (a float image as colour and as linear data).
        if let Some(k) = self.textures.iter().position(|t| {
            t.path == path && t.flags == tex_flags && t.usage.transform == usage.transform
        }) {
            return Ok(k as u32);
        }
        // The same texels under another decoding, wrap mode or coordinate map: shared, not
        // copied (an 8-bit image's words are its bytes whichever table decodes them).
        let source = match self
            .textures
            .iter()
            .position(|t| t.path == path && t.flags & flags::FLOAT == tex_flags & flags::FLOAT)
        {
            Some(k) => Texels::SharedWith(k),
            None => Texels::Own(&texels),
        };
        self.push(path, usage, tex_flags, width, height, source);
        Ok(self.textures.len() as u32 - 1)
    }

    /// The largest value of texture `index` in each channel (decoded as the kernel decodes it).
    pub fn peak(&self, index: u32) -> glam::Vec3 {
        let r = RECORDS + RECORD_WORDS * index as usize;
        let (first, w, h, tex_flags) = (
            self.words[r] as usize,
            self.words[r + 1] as usize,
            self.words[r + 2] as usize,
            self.words[r + 3],
        );
        let mut peak = glam::Vec3::ZERO;
        if tex_flags & flags::FLOAT != 0 {
            for t in self.words[first..first + 3 * w * h].chunks(3) {
                peak = peak.max(glam::Vec3::from_array(
                    [0, 1, 2].map(|k| f32::from_bits(t[k])),
                ));
            }
        } else {
            let base = if tex_flags & flags::SRGB != 0 {
                SRGB_TABLE
            } else {
                LINEAR_TABLE
            };
            for &word in &self.words[first..first + w * h] {
                let c = [0, 8, 16]
                    .map(|s| f32::from_bits(self.words[base + ((word >> s) & 0xff) as usize]));
                peak = peak.max(glam::Vec3::from_array(c));
            }
        }
        peak
    }

    /// Whether texture `k` reads the second set of texture coordinates.
    pub fn reads_second_set(&self, k: u32) -> bool {
        self.textures[k as usize].flags & flags::SECOND_SET != 0
    }

    /// Appends a texture of `width` x `height` texels (its own `texels` in the kernel's
    /// encoding for `tex_flags`, or an earlier record's) and rebuilds the table.
    pub fn push(
        &mut self,
        path: &Path,
        usage: TextureUse,
        tex_flags: u32,
        width: u32,
        height: u32,
        texels: Texels,
    ) {
        // The texels of the textures so far, after their records.
        let old_records = RECORDS + RECORD_WORDS * self.textures.len();
        let old_texels = self.words.split_off(old_records);
        self.textures.push(TextureInfo {
            path: path.to_path_buf(),
            usage,
            flags: tex_flags,
            width,
            height,
        });
        let n = self.textures.len();
        let shift = RECORD_WORDS as u32;
        self.words[0] = n as u32;
        for k in 0..n - 1 {
            self.words[RECORDS + RECORD_WORDS * k] += shift;
        }
        let (first, own) = match texels {
            Texels::Own(t) => ((RECORDS + RECORD_WORDS * n + old_texels.len()) as u32, t),
            Texels::SharedWith(k) => (self.words[RECORDS + RECORD_WORDS * k], &[][..]),
        };
        let map = usage.transform.unwrap_or(UvTransform::IDENTITY).0;
        self.words
            .extend_from_slice(&[first, width, height, tex_flags]);
        self.words.extend(map.map(f32::to_bits));
        self.words.extend_from_slice(&old_texels);
        self.words.extend_from_slice(own);
    }
}
