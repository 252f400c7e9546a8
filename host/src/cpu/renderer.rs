//! The CPU renderer: a scene's tables and BVH, and the image's tiles rendered in parallel
//! (rayon), each tile one path at a time or sixteen at once (`packet_paths`), under the
//! scene's feature bits as a const generic (one monomorphised path per common combination).

use super::bvh::{Bvh, HoleTables};
use super::bvh_packet::PacketsThroughHoles;
use super::bvh_tracer::BvhTracer;
use super::packet::{PacketTracer, SmallScene};
use super::packet_paths::tile_by_packets;
use super::tile::{TileSums, TILE};
use crate::backend::RayCounts;
use crate::film::{Film, PixelSums};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use glam::Vec3;
use indicatif::ProgressBar;
use kernel::features::{self, Dynamic, DynamicWithout, FeatureSet, Static};
use kernel::medium::Medium;
use kernel::path::render_sample;
use kernel::scene::{split_mode, Light, Material, RenderParams, ShadingTriangle};
use kernel::split::render_split_sample;
use kernel::{SceneView, Tracer};
use rayon::prelude::*;
use std::ops::Range;

/// A scene prepared for CPU rendering.
pub struct CpuRenderer {
    pub bvh: Bvh,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    /// The environment table (`kernel::environment`; one number without a map).
    pub environment: Vec<f32>,
    /// The shading table (`kernel::scene::ShadingTriangle`) and the texture table
    /// (`kernel::texture`).
    pub shading: Vec<ShadingTriangle>,
    pub textures: Vec<u32>,
    /// The media table (`kernel::medium`).
    pub media: Vec<Medium>,
    /// The grid table (`kernel::density_grid`).
    pub grids: Vec<u32>,
    /// The kernel's feature bits (`kernel::features`; 0: generic path), without
    /// `features::ADAPTIVE` (the GPU's ray generation reads it; this film counts pilots itself)
    /// and `features::SPLIT` (asked of the parameters here).
    pub features: u32,
    /// The split table (`kernel::split`; `[1]`: no split).
    pub splits: Vec<u32>,
    /// How a tile's samples are computed, chosen once when the renderer is built.
    pub tiles: TileStrategy,
    /// Whether a material has holes (`Material::has_holes`): rays then pass through the
    /// candidates that are not there ([`CpuRenderer::tracer`]).
    pub holes: bool,
}

/// How the CPU renderer computes a tile's samples. All give the same image bit for bit
/// (`tests/tests/packets.rs`); packets are faster (docs/performance.md).
pub enum TileStrategy {
    /// One path at a time through the BVH: with `packets` off.
    OnePath,
    /// Sixteen paths at a time, their rays tested against every primitive by SIMD lanes
    /// (`packet_paths.rs`): for scenes of at most `packet::MAX_PRIMITIVES` primitives, no
    /// instances and no holes unless the scene's `packets` setting is off. Holds all the
    /// primitives.
    Packets(SmallScene),
    /// Sixteen paths at a time, their rays traced through the BVH as packets
    /// (`bvh_packet.rs`, instances included, through the holes of materials that have them,
    /// `packet_presence.rs`): for larger scenes and scenes with instances or holes unless
    /// `packets` is off.
    BvhPackets,
}

/// `match bits { combo => body with f = Static::<combo>, ..., other => body with Dynamic(other) }`
/// (`DynamicWithout::<{ MEDIA }>(other)` where `other` is specialised and has no media).
macro_rules! monomorphised {
    ($bits:expr, $f:ident => $body:expr; $($combo:expr),+) => {
        match $bits {
            $(x if x == $combo => {
                let $f = Static::<{ $combo }>;
                $body
            })+
            other if other & features::SPECIALIZED != 0 && other & features::MEDIA == 0 => {
                let $f = DynamicWithout::<{ features::MEDIA }>(other);
                $body
            }
            other => {
                let $f = Dynamic(other);
                $body
            }
        }
    };
}

/// The feature combinations with their own monomorphised `trace_path`: every combination of
/// the scene features (lights: none, one, several; background; constant or throughput
/// roulette; Lambertian only with sphere lights, or anything: [`EXTENDED`]) under the default
/// MIS (power) and light sampling (by solid angle). Others run the [`Dynamic`] path with the
/// same bits.
macro_rules! with_features {
    ($bits:expr, $f:ident => $body:expr) => {{
        const BASE: u32 = features::SPECIALIZED | features::MIS_POWER | features::LIGHT_SOLID_ANGLE;
        const L: u32 = features::LIGHTS;
        const L1: u32 = features::LIGHTS | features::SINGLE_LIGHT;
        const B: u32 = features::BACKGROUND;
        const R: u32 = features::RR_THROUGHPUT;
        const M: u32 = EXTENDED;
        monomorphised!($bits, $f => $body;
            BASE, BASE | B, BASE | R, BASE | B | R,
            BASE | L, BASE | L | B, BASE | L | R, BASE | L | B | R,
            BASE | L1, BASE | L1 | B, BASE | L1 | R, BASE | L1 | B | R,
            BASE | M, BASE | B | M, BASE | R | M, BASE | B | R | M,
            BASE | L | M, BASE | L | B | M, BASE | L | R | M, BASE | L | B | R | M,
            BASE | L1 | M, BASE | L1 | B | M, BASE | L1 | R | M, BASE | L1 | B | R | M)
    }};
}

/// The feature bits beyond the diffuse renderer's: other materials than the Lambertian,
/// triangle lights, a thin lens, an environment map, shading normals and textures. (Normal maps
/// and delta lights are not among them: scenes with those run the [`Dynamic`] path, so that
/// scenes without them do not carry their checks; docs/performance.md measures both.)
const EXTENDED: u32 = features::MATERIALS
    | features::TRIANGLE_LIGHTS
    | features::THIN_LENS
    | features::ENVIRONMENT
    | features::SHADING_NORMALS
    | features::TEXTURES;

/// `bits` with every [`EXTENDED`] bit set if any is: the CPU compiles one path for scenes with
/// other materials, triangle lights, a lens or an environment map (such a bit only keeps code,
/// which the material's `kind`, the light's `kind`, the lens radius and the map's size then skip
/// where absent), not one per combination of them.
fn with_all_extended(bits: u32) -> u32 {
    if bits & EXTENDED != 0 {
        bits | EXTENDED
    } else {
        bits
    }
}

impl CpuRenderer {
    /// Builds the BVH over the scene's spheres, triangles and instances (and, for a small
    /// scene without instances, the packets' copy of its primitives), and picks the
    /// [`TileStrategy`] for `settings`.
    pub fn new(scene: &Scene, settings: &RenderSettings) -> Self {
        Self::with_bvh(scene, settings, Bvh::build_scene(scene))
    }

    /// [`Self::new`] over `bvh`, already built over `scene` by [`Bvh::build_scene`] (for
    /// `bench::rays`, which times the build apart).
    pub fn with_bvh(scene: &Scene, settings: &RenderSettings, bvh: Bvh) -> Self {
        // Primitive ids as the BVH numbers them (`Bvh::surface` reads them).
        let holes = scene.materials.iter().any(Material::has_holes);
        let tiles = if !settings.packets {
            TileStrategy::OnePath
        } else if holes || !scene.instances.is_empty() {
            TileStrategy::BvhPackets
        } else if let Some(small) = SmallScene::if_small(&bvh.spheres, &bvh.triangles) {
            TileStrategy::Packets(small)
        } else {
            TileStrategy::BvhPackets
        };
        Self {
            bvh,
            materials: scene.materials.clone(),
            lights: scene.light_table(settings),
            environment: scene.environment_table(),
            shading: scene.shading_table(),
            textures: scene.textures.words.clone(),
            media: scene.media.clone(),
            grids: scene.grids.words.clone(),
            features: with_all_extended(
                scene.features(settings) & !(features::ADAPTIVE | features::SPLIT),
            ),
            splits: vec![1],
            tiles,
            holes,
        }
    }

    /// The [`Tracer`] of one path at a time over the BVH: through the holes of materials that
    /// have them (`kernel::opacity`).
    pub fn tracer(&self) -> BvhTracer<'_> {
        let mut tracer = BvhTracer::new(&self.bvh);
        if self.holes {
            tracer.holes = Some(self.hole_tables());
        }
        tracer
    }

    /// The tables that say where the materials with holes are not there (`kernel::opacity`).
    fn hole_tables(&self) -> HoleTables<'_> {
        HoleTables {
            materials: &self.materials,
            shading: &self.shading,
            textures: &self.textures,
        }
    }

    /// One sample of one pixel, exactly as the GPU's ray-generation shader computes it.
    pub fn sample(&self, params: &RenderParams, px: u32, py: u32, sample: u32) -> Vec3 {
        let mut tracer = self.tracer();
        with_features!(self.features, f => self.sample_with(f, &mut tracer, params, px, py, sample))
    }

    /// [`Self::sample`] under `features` with its rays traced by `tracer` (which may record
    /// them, as `bench::rays::path_rays` does, and must answer as the BVH does).
    #[inline]
    pub fn sample_with<F: FeatureSet, T: Tracer>(
        &self,
        features: F,
        tracer: &mut T,
        params: &RenderParams,
        px: u32,
        py: u32,
        sample: u32,
    ) -> Vec3 {
        let scene = self.view(params);
        if params.split.mode == split_mode::OFF {
            render_sample(tracer, features, &scene, px, py, sample)
        } else {
            render_split_sample(tracer, features, &scene, px, py, sample, true)
        }
    }

    /// The scene's tables as the kernel reads them, with the render's parameters.
    pub fn view<'a>(&'a self, params: &'a RenderParams) -> SceneView<'a> {
        SceneView {
            params,
            materials: &self.materials,
            lights: &self.lights,
            environment: &self.environment,
            shading: &self.shading,
            textures: &self.textures,
            instances: self.bvh.instances(),
            media: &self.media,
            grids: &self.grids,
            splits: &self.splits,
        }
    }

    /// Adds samples `first..first + count` of every pixel to `film`, tiles in parallel.
    /// Non-finite samples are not added; they are counted in `film.discarded`. With adaptive
    /// sampling (`kernel::adaptive::is_adaptive`), pixels the film says have converged are skipped
    /// and pilot samples go to the film's pilot sums (`kernel::adaptive`). Returns the rays
    /// traced.
    pub fn render_into(
        &self,
        params: &RenderParams,
        first: u32,
        count: u32,
        film: &mut Film,
        progress: Option<&ProgressBar>,
    ) -> RayCounts {
        with_features!(self.features, f => self.render_tiles(f, params, first, count, film, progress))
    }

    fn render_tiles<F: FeatureSet + Sync>(
        &self,
        features: F,
        params: &RenderParams,
        first: u32,
        count: u32,
        film: &mut Film,
        progress: Option<&ProgressBar>,
    ) -> RayCounts {
        let samples = first..first + count;
        match &self.tiles {
            TileStrategy::OnePath => {
                self.render_tiles_by(params, film, progress, |pixels, film| {
                    self.tile_by_paths(features, params, pixels, first, count, film)
                })
            }
            TileStrategy::Packets(small) => {
                self.render_packet_tiles(features, small, params, samples, film, progress)
            }
            TileStrategy::BvhPackets if self.holes => {
                let tracer = PacketsThroughHoles {
                    bvh: &self.bvh,
                    tables: self.hole_tables(),
                };
                self.render_packet_tiles(features, &tracer, params, samples, film, progress)
            }
            TileStrategy::BvhPackets => {
                self.render_packet_tiles(features, &self.bvh, params, samples, film, progress)
            }
        }
    }

    /// [`Self::render_tiles_by`] sixteen paths at a time (`packet_paths.rs`), samples
    /// `samples` of each pixel, their rays traced by `tracer`.
    fn render_packet_tiles<F: FeatureSet + Sync, T: PacketTracer>(
        &self,
        features: F,
        tracer: &T,
        params: &RenderParams,
        samples: Range<u32>,
        film: &mut Film,
        progress: Option<&ProgressBar>,
    ) -> RayCounts {
        self.render_tiles_by(params, film, progress, |pixels, film| {
            let view = self.view(params);
            tile_by_packets(
                features,
                tracer,
                &view,
                &self.bvh,
                pixels,
                samples.clone(),
                film,
            )
        })
    }

    /// Runs `tile` on every image tile in parallel (it returns each pixel's sums, in row
    /// order, reading `film` only to skip converged pixels, and the rays it traced), adds the
    /// sums to `film` and returns the rays.
    fn render_tiles_by<T>(
        &self,
        params: &RenderParams,
        film: &mut Film,
        progress: Option<&ProgressBar>,
        tile: T,
    ) -> RayCounts
    where
        T: Fn(&mut dyn Iterator<Item = (u32, u32)>, &Film) -> TileSums + Sync,
    {
        let (w, h) = (params.samples.width, params.samples.height);
        let tile_pixels = move |tx: u32, ty: u32| {
            (ty * TILE..((ty + 1) * TILE).min(h))
                .flat_map(move |py| (tx * TILE..((tx + 1) * TILE).min(w)).map(move |px| (px, py)))
        };
        let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
            .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx, ty)))
            .collect();
        let film_ref = &*film;
        let results: Vec<((u32, u32), TileSums)> = tiles
            .par_iter()
            .map(|&(tx, ty)| {
                let (sums, rays) = tile(&mut tile_pixels(tx, ty), film_ref);
                if let Some(p) = progress {
                    p.inc(
                        sums.iter()
                            .map(|s| (s.count + s.pilot_count + s.discarded) as u64)
                            .sum(),
                    );
                }
                ((tx, ty), (sums, rays))
            })
            .collect();
        let mut rays = RayCounts::default();
        for ((tx, ty), (sums, tile_rays)) in results {
            for ((px, py), s) in tile_pixels(tx, ty).zip(&sums) {
                film.add_sums(px, py, s);
            }
            rays += tile_rays;
        }
        rays
    }

    /// Samples `first..first + count` of each of `pixels` (skipping those `film` says have
    /// converged, under adaptive sampling), one path at a time, in sample order; returns each
    /// pixel's sums and the rays traced.
    fn tile_by_paths<F: FeatureSet>(
        &self,
        features: F,
        params: &RenderParams,
        pixels: &mut dyn Iterator<Item = (u32, u32)>,
        first: u32,
        count: u32,
        film: &Film,
    ) -> TileSums {
        let adaptive = kernel::adaptive::is_adaptive(params);
        let mut tracer = self.tracer();
        let sums = pixels
            .map(|(px, py)| {
                let mut acc = PixelSums::default();
                if !(adaptive && film.converged(params, px, py)) {
                    for s in first..first + count {
                        let l = self.sample_with(features, &mut tracer, params, px, py, s);
                        acc.add_sample(params, s, l);
                    }
                }
                acc
            })
            .collect();
        (sums, tracer.rays)
    }
}
