//! A glTF image (in a buffer view, a data URI or a file beside the scene) decoded into the
//! texture table.

use super::import::Import;
use crate::scene::textures::TextureUse;
use crate::scene::SceneError;
use std::path::PathBuf;

impl Import<'_> {
    /// The texture table's index of image `k` used as `usage`: its bytes from a buffer view,
    /// a data URI or a file beside the glTF file, every index and range checked (the gltf
    /// crate's image import unwraps a missing mimeType and slices views unchecked), decoded by
    /// the `image` crate (PNG, JPEG and the formats it guesses).
    pub(super) fn image(&mut self, k: usize, usage: TextureUse) -> Result<u32, SceneError> {
        let field = format!("images[{k}]");
        let err = |msg: String| SceneError::new(&self.path, None, field.clone(), msg);
        let json = self.document.as_json();
        let image = json
            .images
            .get(k)
            .ok_or_else(|| err("does not exist".into()))?;
        let bytes: std::borrow::Cow<[u8]> =
            if let Some(v) = &image.buffer_view {
                let view = json
                    .buffer_views
                    .get(v.value())
                    .ok_or_else(|| err(format!("its bufferView {} does not exist", v.value())))?;
                let buffer = self.buffers.get(view.buffer.value()).ok_or_else(|| {
                    err(format!("its buffer {} does not exist", view.buffer.value()))
                })?;
                let offset = view.byte_offset.map_or(0, |o| o.0) as usize;
                let range = offset..offset.saturating_add(view.byte_length.0 as usize);
                std::borrow::Cow::Borrowed(buffer.get(range).ok_or_else(|| {
                    err(format!(
                        "bufferViews[{}] lies outside its buffer of {} bytes",
                        v.value(),
                        buffer.len()
                    ))
                })?)
            } else if let Some(uri) = &image.uri {
                if let Some(data) = uri.strip_prefix("data:") {
                    let (_, encoded) = data
                        .split_once(";base64,")
                        .ok_or_else(|| err("a data URI that is not base64".into()))?;
                    std::borrow::Cow::Owned(
                        base64::decode(encoded).map_err(|e| err(format!("bad base64: {e}")))?,
                    )
                } else {
                    let base = self.base.as_ref().ok_or_else(|| {
                        err("names an external file, but there is no folder".into())
                    })?;
                    let file = base.join(uri);
                    std::borrow::Cow::Owned(
                        crate::scene::inputs::read(&file)
                            .map_err(|e| err(format!("cannot read {}: {e}", file.display())))?,
                    )
                }
            } else {
                return Err(err("has neither a bufferView nor a uri".into()));
            };
        let decoded = image::load_from_memory(&bytes)
            .map_err(|e| err(format!("not a readable image: {e}")))?;
        let name = PathBuf::from(format!("{}#{field}", self.path.display()));
        self.tables
            .textures
            .add_image(&name, decoded, usage, &field)
    }
}
