//! The image tiles threads take one at a time, and what a tile's samples give.

use crate::backend::RayCounts;
use crate::film::PixelSums;

/// Side of the square image tiles that threads take one at a time.
pub const TILE: u32 = 16;

/// What a tile's samples give: each pixel's sums, in row order, and the rays traced.
pub(crate) type TileSums = (Vec<PixelSums>, RayCounts);
