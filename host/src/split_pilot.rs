//! The split table of a render (`kernel::split`): how many times the paths of each 16 x 16
//! tile continue from their first vertex. `split = auto` learns it from a pilot render on the
//! render's own backend; `split = N` gives every tile N.
//!
//! # The pilot
//! A render of [`pilot_spp`] samples per pixel under `split_mode::PILOT`, with the independent
//! sampler and its own seed (so nothing of it is in the image, and the image's samples stay
//! independent of the table: the table is a function of the scene and the settings, every part
//! of a render learns the same one, and the image is unbiased whatever the table says). Each
//! pilot sample splits in two and reports y1, y2 (the two unsplit estimates' luminances) and
//! the first continuation's rounds of ray casts; per pixel the film's sums give
//! - V_a = Var(E[L | prefix]) = Cov(y1, y2) = (Var(y1 + y2) - 2 Var(y1)) / 2,
//! - V_b = E[Var(C | prefix)] = Var(y1) - V_a,
//! - the continuation's cost c_b, its mean rounds, and the prefix's, c_a = [`PREFIX_COST`],
//!
//! so that with n continuations a sample's variance is V_a + V_b / n at cost c_a + n c_b
//! (`kernel::split`'s derivation). Variances are weighted by 1 / (mean^2 + 0.01), the weight
//! of `twinpath diff`'s relMSE, and summed per tile.
//!
//! # The choice
//! Each tile takes the n in 1..=`MAX_CONTINUATIONS` that minimises e_t(n) + lambda t_t(n)
//! (its weighted variance plus lambda times its cost), and lambda is the one of a fixed grid
//! whose choices minimise the image's error times its time, (sum e_t)(sum t_t): the
//! efficiency of the whole image, the measure of Vorba and Křivánek 2016 and Rath et al. 2022
//! taken over the image rather than per path. Every table of one n everywhere is among the
//! choices, so in the model the table never loses to `split = off` or to any fixed `split = N`
//! (docs/performance.md measures it).

use crate::backend::SampleBackend;
use crate::film::Film;
use crate::scene::{Scene, SPLIT_TILE};
use crate::settings::{RenderSettings, Sampler, Split};
use anyhow::Result;
use indicatif::ProgressBar;
use kernel::scene::split_mode;
use kernel::split::MAX_CONTINUATIONS;

/// What the prefix of a sample costs, in rounds of ray casts (`kernel::split::
/// continuation_rounds` counts a continuation's): its camera ray's round, cheaper than an
/// average round (coherent rays, its shadow ray cast in continuation 0's first round), less
/// what each further continuation costs beyond its rounds. Measured against time in
/// docs/performance.md.
pub const PREFIX_COST: f64 = 0.5;

/// Mixed into the render's seed for the pilot's: the pilot draws numbers no image sample draws.
const PILOT_SEED: u32 = 0x9e37_79b9;

/// Samples per pixel of the pilot of a render of `spp`: a thirty-second, at least 2 (a
/// variance needs two) and at most 8.
pub fn pilot_spp(spp: u32) -> u32 {
    (spp / 32).clamp(2, 8)
}

/// Tiles of the split table of a `width` x `height` image: columns and rows.
pub fn tile_grid(width: u32, height: u32) -> (u32, u32) {
    (width.div_ceil(SPLIT_TILE), height.div_ceil(SPLIT_TILE))
}

/// The split table `settings.split` asks for, `None` where paths do not split: N everywhere for
/// `split = N`, the pilot's choice (rendered on `backend`, whose film it leaves empty, its
/// samples counted on `progress`) for `auto`.
pub fn split_table(
    backend: &mut dyn SampleBackend,
    scene: &Scene,
    settings: &RenderSettings,
    progress: Option<&ProgressBar>,
) -> Result<Option<Vec<u32>>> {
    let (columns, rows) = tile_grid(scene.camera.width, scene.camera.height);
    let tiles = (columns * rows) as usize;
    match settings.split {
        Split::Off => Ok(None),
        Split::Fixed(n) => Ok(Some(vec![n; tiles])),
        Split::Auto => {
            let film = pilot_film(backend, scene, settings, progress)?;
            backend.clear_film()?;
            let stats = tile_statistics(&film, columns, rows);
            Ok(Some(choose(&stats)))
        }
    }
}

/// The pilot render's film (see the module comment).
fn pilot_film(
    backend: &mut dyn SampleBackend,
    scene: &Scene,
    settings: &RenderSettings,
    progress: Option<&ProgressBar>,
) -> Result<Film> {
    let pilot = RenderSettings {
        seed: settings.seed ^ PILOT_SEED,
        sampler: Sampler::Independent,
        adaptive_target: 0.0,
        ..*settings
    };
    let spp = pilot_spp(settings.spp);
    let mut done = 0;
    while done < spp {
        let count = backend.next_pass(done, spp);
        let mut params = scene.params(&pilot, done, count);
        params.split.mode = split_mode::PILOT;
        backend.add_samples(&params, done, count, progress)?;
        done += count;
    }
    backend.read_film()
}

/// A tile's pilot statistics: weighted variance before and after the first vertex's
/// continuation (V_a, V_b summed over its pixels), and the prefix's and continuation's costs
/// (summed likewise).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TileStatistics {
    pub prefix_variance: f64,
    pub continuation_variance: f64,
    pub prefix_cost: f64,
    pub continuation_cost: f64,
}

impl TileStatistics {
    /// The tile's weighted variance with `n` continuations.
    pub fn error(&self, n: u32) -> f64 {
        self.prefix_variance + self.continuation_variance / n as f64
    }

    /// The tile's cost with `n` continuations.
    pub fn cost(&self, n: u32) -> f64 {
        self.prefix_cost + n as f64 * self.continuation_cost
    }
}

/// Each tile's statistics (row by row) from the pilot's film (values (y1, rounds, y1 + y2)).
/// A pixel's relMSE weight is 1 / (m^2 + 0.01) with m the mean of its 5 x 5 neighbourhood's
/// y1 (a pixel's own few samples would weigh it by their own noise: the pixels whose samples
/// happened to miss a rare bright path would weigh most, and the continuation's variance,
/// which such paths carry, would read low).
pub fn tile_statistics(film: &Film, columns: u32, rows: u32) -> Vec<TileStatistics> {
    let (w, h) = (film.width as i64, film.height as i64);
    let mean = |i: usize, c: usize| film.sum[i][c].to_f64() / film.count[i].max(1) as f64;
    let local_mean = |px: i64, py: i64| {
        let (mut sum, mut n) = (0.0, 0u32);
        for y in (py - 2).max(0)..(py + 3).min(h) {
            for x in (px - 2).max(0)..(px + 3).min(w) {
                let i = (y * w + x) as usize;
                sum += film.sum[i][0].to_f64();
                n += film.count[i];
            }
        }
        sum / n.max(1) as f64
    };
    let mut tiles = vec![TileStatistics::default(); (columns * rows) as usize];
    for py in 0..h {
        for px in 0..w {
            let i = (py * w + px) as usize;
            let n = film.count[i] as f64;
            if n < 2.0 {
                continue;
            }
            let variance = |c: usize| (film.sum_sq[i][c] - n * mean(i, c) * mean(i, c)) / (n - 1.0);
            let covariance = (variance(2) - 2.0 * variance(0)) / 2.0;
            let m = local_mean(px, py);
            let weight = 1.0 / (m * m + 0.01);
            let (tx, ty) = (px as u32 / SPLIT_TILE, py as u32 / SPLIT_TILE);
            let tile = &mut tiles[(ty * columns + tx) as usize];
            tile.prefix_variance += weight * covariance;
            tile.continuation_variance += weight * (variance(0) - covariance);
            tile.prefix_cost += PREFIX_COST;
            tile.continuation_cost += mean(i, 1);
        }
    }
    // Estimates of variances, each a difference of noisy sums: kept where they are variances.
    for t in &mut tiles {
        t.prefix_variance = t.prefix_variance.max(0.0);
        t.continuation_variance = t.continuation_variance.max(0.0);
    }
    tiles
}

/// The split table for these tiles (see the module comment): of the tables with one n
/// everywhere and those that take per tile the n minimising e_t(n) + lambda t_t(n), lambda
/// from a grid of 641 factors e^-8..e^8 of the image's variance over its cost, the one with
/// the least (sum e_t)(sum t_t). Ties go to the smaller uniform n, then to the earlier
/// lambda; so the table never scores worse than any one n everywhere.
pub fn choose(tiles: &[TileStatistics]) -> Vec<u32> {
    let pick = |lambda: f64| -> Vec<u32> {
        tiles
            .iter()
            .map(|t| {
                (1..=MAX_CONTINUATIONS)
                    .map(|n| (n, t.error(n) + lambda * t.cost(n)))
                    .fold(
                        (1, f64::INFINITY),
                        |best, c| if c.1 < best.1 { c } else { best },
                    )
                    .0
            })
            .collect()
    };
    let score = |table: &[u32]| -> f64 {
        let error: f64 = tiles.iter().zip(table).map(|(t, &n)| t.error(n)).sum();
        let cost: f64 = tiles.iter().zip(table).map(|(t, &n)| t.cost(n)).sum();
        error * cost
    };
    let mut best = vec![1; tiles.len()];
    let mut best_score = score(&best);
    for n in 2..=MAX_CONTINUATIONS {
        let table = vec![n; tiles.len()];
        let s = score(&table);
        if s < best_score {
            (best, best_score) = (table, s);
        }
    }
    let error: f64 = tiles.iter().map(|t| t.error(1)).sum();
    let cost: f64 = tiles.iter().map(|t| t.cost(1)).sum();
    if !(error > 0.0 && cost > 0.0) {
        return best;
    }
    for k in 0..=640 {
        let lambda = error / cost * (-8.0 + 16.0 * k as f64 / 640.0).exp();
        let table = pick(lambda);
        let s = score(&table);
        if s < best_score {
            (best, best_score) = (table, s);
        }
    }
    best
}
