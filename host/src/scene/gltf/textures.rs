//! A glTF material's texture reference (`textureInfo`, `normalTextureInfo`) onto the texture
//! table: its image, its sampler's wrap modes and its `KHR_texture_transform`, the map of
//! texture coordinates the kernel applies before the lookup (`kernel::texture`).

use super::import::Import;
use crate::scene::textures::{TextureUse, UvTransform};
use crate::scene::SceneError;
use gltf::texture::WrappingMode;
use kernel::texture::wrap;

/// The texture table's index of the image behind `info`, read as colour (sRGB) or linear data.
pub(super) fn texture(
    imp: &mut Import,
    label: &str,
    info: &gltf::texture::Info,
    colour: bool,
) -> Result<u32, SceneError> {
    let transform = info.texture_transform().map(|t| TextureTransform {
        offset: t.offset(),
        rotation: t.rotation(),
        scale: t.scale(),
        tex_coord: t.tex_coord(),
    });
    texture_of(
        imp,
        label,
        info.texture(),
        info.tex_coord(),
        transform,
        colour,
    )
}

/// The texture table's index of a normal map's image (linear data). The `gltf` crate does not
/// type `KHR_texture_transform` on normal textures: it is read from the extension's JSON.
pub(super) fn normal_texture(
    imp: &mut Import,
    label: &str,
    n: &gltf::material::NormalTexture,
) -> Result<u32, SceneError> {
    let transform = match n.extension_value("KHR_texture_transform") {
        None => None,
        Some(json) => Some(TextureTransform::from_json(json).ok_or_else(|| {
            SceneError::new(
                &imp.path,
                None,
                format!("{label}.normalTexture.extensions.KHR_texture_transform"),
                format!("{json} is not a texture transform (offset, rotation, scale, texCoord)"),
            )
        })?),
    };
    texture_of(imp, label, n.texture(), n.tex_coord(), transform, false)
}

/// `KHR_texture_transform` as the file gives it, in glTF's texture space (v down):
/// uv' = T(offset) R(rotation) S(scale) uv with R's rows (cos, sin), (-sin, cos), the
/// convention Blender's exporter and the extension's reference implementation use.
#[derive(Clone, Copy, Debug, PartialEq)]
struct TextureTransform {
    offset: [f32; 2],
    rotation: f32,
    scale: [f32; 2],
    tex_coord: Option<u32>,
}

impl TextureTransform {
    /// The extension's JSON object (every field optional); `None` if a field has the wrong
    /// type.
    fn from_json(json: &gltf::json::Value) -> Option<Self> {
        let pair = |key: &str, default: [f32; 2]| -> Option<[f32; 2]> {
            match json.get(key) {
                None => Some(default),
                Some(v) => {
                    let a = v.as_array().filter(|a| a.len() == 2)?;
                    Some([a[0].as_f64()? as f32, a[1].as_f64()? as f32])
                }
            }
        };
        let rotation = match json.get("rotation") {
            None => 0.0,
            Some(v) => v.as_f64()? as f32,
        };
        let tex_coord = match json.get("texCoord") {
            None => None,
            Some(v) => Some(u32::try_from(v.as_u64()?).ok()?),
        };
        json.is_object().then_some(())?;
        Some(Self {
            offset: pair("offset", [0.0, 0.0])?,
            rotation,
            scale: pair("scale", [1.0, 1.0])?,
            tex_coord,
        })
    }

    /// The same map in the kernel's texture space (v up: v_kernel = 1 - v_glTF), F M F with
    /// F(u, v) = (u, 1 - v), composed in f64; `None` for the identity (no map in the record).
    fn kernel_map(&self) -> Option<UvTransform> {
        let (s, c) = (self.rotation as f64).sin_cos();
        let [sx, sy] = self.scale.map(f64::from);
        let [ox, oy] = self.offset.map(f64::from);
        // M's rows: (c sx, s sy, ox), (-s sx, c sy, oy).
        let (m00, m01, m02) = (c * sx, s * sy, ox);
        let (m10, m11, m12) = (-s * sx, c * sy, oy);
        // (+ 0.0: a negative zero becomes 0, so equal maps are equal records.)
        let map = [m00, -m01, m01 + m02, -m10, m11, 1.0 - m11 - m12].map(|x| x as f32 + 0.0);
        let map = UvTransform(map);
        (map != UvTransform::IDENTITY).then_some(map)
    }
}

/// The texture table's index of texture `tex` read with texture coordinates `tex_coord` through
/// `transform`, as colour or linear data, wrapping as its sampler's `wrapS` and `wrapT` say.
fn texture_of(
    imp: &mut Import,
    label: &str,
    tex: gltf::Texture,
    tex_coord: u32,
    transform: Option<TextureTransform>,
    colour: bool,
) -> Result<u32, SceneError> {
    let tex_coord = transform.and_then(|t| t.tex_coord).unwrap_or(tex_coord);
    if tex_coord > 1 {
        imp.note(format!(
            "{label}: textures[{}] names TEXCOORD_{tex_coord}; TEXCOORD_0 is used",
            tex.index(),
        ));
    }
    let map = match transform {
        None => None,
        Some(t) => {
            let finite =
                t.offset.iter().chain(&t.scale).all(|x| x.is_finite()) && t.rotation.is_finite();
            if !finite {
                return Err(SceneError::new(
                    &imp.path,
                    None,
                    format!("{label}: textures[{}] KHR_texture_transform", tex.index()),
                    format!("{t:?} is not finite"),
                ));
            }
            t.kernel_map()
        }
    };
    let sampler = tex.sampler();
    let mode = |m: WrappingMode| match m {
        WrappingMode::Repeat => wrap::REPEAT,
        WrappingMode::ClampToEdge => wrap::CLAMP,
        WrappingMode::MirroredRepeat => wrap::MIRROR,
    };
    let usage = TextureUse {
        colour,
        wrap: [mode(sampler.wrap_s()), mode(sampler.wrap_t())],
        transform: map,
        second_set: tex_coord == 1,
    };
    imp.image(tex.source().index(), usage)
}
