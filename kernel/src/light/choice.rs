//! Choosing a light from one uniform number: the light table's alias table (Walker 1977;
//! Vose 1991; pbrt-v4 `AliasTable::Sample`), built by the host (`scene/light_table.rs`).

use crate::scene::Light;

/// Picks a light index from one uniform number in O(1): slot i = floor(u n) is chosen
/// uniformly, and the rest of u, rescaled to [0, 1), keeps light i with probability
/// `alias_threshold[i]`, else gives `alias[i]`. Light i is then chosen with probability
/// (threshold_i + sum over slots j aliasing to i of (1 - threshold_j)) / n, which the host's
/// construction makes equal to `select_pmf[i]`.
#[inline]
pub fn choose_light(lights: &[Light], light_count: u32, u: f32) -> u32 {
    if light_count == 1 {
        return 0;
    }
    let scaled = u * light_count as f32;
    let slot = (scaled as u32).min(light_count - 1);
    // The fractional part, clamped below 1 (u close to 1 rounds scaled up to n).
    let rest = (scaled - slot as f32).min(ONE_MINUS_EPSILON);
    let l = &lights[slot as usize];
    if rest < l.alias_threshold {
        slot
    } else {
        l.alias
    }
}

/// The largest f32 below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;
