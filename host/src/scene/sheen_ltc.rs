//! The sheen table of `kernel::bsdf::sheen`: per view cosine mu and sheen roughness alpha, the
//! linearly transformed cosine (A, B) and the reflectance R of the fibre layer that Cycles'
//! Principled sheen models (Zeltner, Burley and Chiang 2022), at [`COSINES`] cosines
//! mu = j / 31 by [`ROUGHNESSES`] roughnesses alpha = i / 31 (node 0 of each at 0.01, where the
//! layer is defined). The values are the committed
//! [`sheen_ltc_table`](super::sheen_ltc_table), derived from the layer's physics by
//! `twinpath_tests::sheen_fit` (a random walk for R, a fit for (A, B); the example
//! `sheen_ltc_table` writes it, `tests/tests/sheen.rs` checks sampled nodes against it).
//! [`add_to`] puts it in a scene's texture table (word `kernel::texture::SHEEN_LTC`).

use super::error::SceneError;
pub use super::sheen_ltc_table::LTC;
use super::textures::TextureTable;

/// Nodes along roughness (the table's width).
pub const ROUGHNESSES: usize = 32;
/// Nodes along the cosine of the view (the table's height).
pub const COSINES: usize = 32;

/// The texture table's name for the sheen table (not a file: it starts with
/// `textures::TABLE_NAME_START`).
pub const NAME: &str = "<sheen table>";

/// The sheen roughness of column `i`: i / 31, 0.01 at i = 0 (the layer of roughness 0 has no
/// fibres to fit).
pub fn roughness_of(i: usize) -> f64 {
    (i as f64 / (ROUGHNESSES - 1) as f64).max(0.01)
}

/// The view cosine of row `j`: j / 31, 0.01 at j = 0 (light arriving exactly along the surface
/// never enters the layer).
pub fn cosine_of(j: usize) -> f64 {
    (j as f64 / (COSINES - 1) as f64).max(0.01)
}

/// Adds the table to `textures` as a float texture (width: roughness, height: cosine; texel
/// (A, B, R)) and records it in the table's header; returns its index.
pub fn add_to(textures: &mut TextureTable) -> Result<u32, SceneError> {
    textures.add_table(
        NAME,
        (ROUGHNESSES, COSINES),
        |i, j| LTC[j][i],
        kernel::texture::SHEEN_LTC,
    )
}
