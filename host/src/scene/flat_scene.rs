//! The scene every format's load produces: the kernel's flat tables (materials, spheres,
//! triangles, instances, lights, shading records, textures, the environment map) and the
//! camera, and what the backends derive from them with the render settings they are handed
//! (the launch parameters, the feature bits, the light table with its selection
//! probabilities). The settings are not part of the scene: a file's `[render]` table is read
//! beside it (`super::SceneFile`).

use super::density_grid::GridTable;
use super::environment;
use super::inputs;
use super::instancing;
use super::light_table;
use super::limits;
use super::textures;
use crate::settings::{RenderSettings, Split};
use glam::Vec3;
use kernel::scene::{
    split_mode, AdaptiveParams, Camera, EnvironmentParams, Instance, IntegratorParams, Light,
    Material, RenderParams, SampleParams, ShadingTriangle, Sphere, SplitParams, Triangle,
};
use std::ops::Range;

/// The camera as the scene file gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraDesc {
    pub eye: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Full vertical field of view, degrees.
    pub vfov_degrees: f32,
    pub width: u32,
    pub height: u32,
    /// Diameter of the thin lens (0: a pinhole).
    pub aperture: f32,
    /// Distance along the view axis of the plane in focus.
    pub focus_distance: f32,
}

impl CameraDesc {
    /// The camera with image size `width` x `height` where given (the command line's
    /// `--width`, `--height`): one alone keeps the aspect ratio (the other side rounded, at
    /// least 1); the vertical field of view stays. Err: a side outside 1..=2^15 (the scene
    /// file's own limit), naming the option.
    pub fn resized(&self, width: Option<u32>, height: Option<u32>) -> Result<CameraDesc, String> {
        let max = limits::MAX_IMAGE_SIDE as u32;
        for (name, v) in [("--width", width), ("--height", height)] {
            if let Some(v) = v {
                if !(1..=max).contains(&v) {
                    return Err(format!("{name} {v}: must be 1 to {max} pixels"));
                }
            }
        }
        let aspect = self.width as f64 / self.height as f64;
        let side = |x: f64| (x.round() as u32).clamp(1, max);
        let (w, h) = match (width, height) {
            (Some(w), Some(h)) => (w, h),
            (Some(w), None) => (w, side(w as f64 / aspect)),
            (None, Some(h)) => (side(h as f64 * aspect), h),
            (None, None) => (self.width, self.height),
        };
        Ok(CameraDesc {
            width: w,
            height: h,
            ..*self
        })
    }

    /// The kernel's camera: forward, and right/up scaled by the image plane's half-extents; the
    /// lens radius and the focus distance in the spare fourth components (`kernel::scene::Camera`).
    pub fn to_kernel(&self) -> Camera {
        let forward = (self.look_at - self.eye).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        let half_h = (0.5 * self.vfov_degrees.to_radians()).tan();
        let half_w = half_h * self.width as f32 / self.height as f32;
        let v4 = |v: Vec3| [v.x, v.y, v.z, 0.0];
        Camera {
            eye: [self.eye.x, self.eye.y, self.eye.z, 0.5 * self.aperture],
            forward: [forward.x, forward.y, forward.z, self.focus_distance],
            right: v4(right * half_w),
            up: v4(up * half_h),
        }
    }
}

/// The side of a tile of the split table (`kernel::split`), in pixels.
pub const SPLIT_TILE: u32 = 16;

/// With adaptive sampling, every PILOT_PERIOD-th sample is a pilot (`kernel::adaptive`).
pub const PILOT_PERIOD: u32 = 4;
/// Pilot samples before a pixel may stop (16 samples in all).
pub const MIN_PILOT_SAMPLES: u32 = 4;
/// Samples per pixel per adaptive pass: both backends decide at the same sample indices.
pub const ADAPTIVE_PASS: u32 = 8;

/// The kernel's triangle with vertices `p` (p0 and the edges p1 - p0, p2 - p0) and `material`,
/// not a light (`light` is set where it emits). Every triangle record is made here: the
/// plane-side test (`kernel::plane_side`) relies on the edges being these `f32` differences of
/// vertices, whose sum with p0 gives the acceleration structure's vertices back exactly where
/// they lie within a factor of two of p0.
pub fn triangle(p: [Vec3; 3], material: u32) -> Triangle {
    Triangle {
        p0: p[0].to_array(),
        material,
        edge1: (p[1] - p[0]).to_array(),
        light: kernel::scene::NONE,
        edge2: (p[2] - p[0]).to_array(),
        shading: kernel::scene::NONE,
    }
}

/// A contiguous run of triangles from one source (a mesh, or the scene's quads).
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleGroup {
    pub name: String,
    pub range: Range<usize>,
}

/// A validated scene in the kernel's flat layout.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Where it came from (a file path, or the built-in scene's name).
    pub name: String,
    pub camera: CameraDesc,
    pub background: Vec3,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    pub spheres: Vec<Sphere>,
    /// The world-space triangles, then the instanced meshes' object-space ones
    /// ([`Scene::world_triangle_count`] tells them apart).
    pub triangles: Vec<Triangle>,
    /// Runs of world-space triangles by source.
    pub triangle_groups: Vec<TriangleGroup>,
    /// The instanced meshes: runs of object-space triangles, each placed by instances.
    pub meshes: Vec<TriangleGroup>,
    /// The placements of instanced meshes (`instancing`), and the mesh each places.
    pub instances: Vec<Instance>,
    pub instance_meshes: Vec<u32>,
    /// The lights, their selection fields unset (`select_pmf`, `alias_threshold`, `alias`):
    /// [`Scene::light_table`] fills them for the settings' selection policy.
    pub lights: Vec<Light>,
    /// The environment map, if `[background] map` names one (its light is the last entry of
    /// `lights`).
    pub environment: Option<environment::EnvironmentMap>,
    /// Vertex normals and texture coordinates of the triangles that have them
    /// (`Triangle::shading` indexes it).
    pub shading: Vec<ShadingTriangle>,
    /// The materials' textures (`Material::textures` indexes it).
    pub textures: textures::TextureTable,
    /// The media table (`kernel::medium`; record 0 is vacuum, always there) and the medium
    /// filling the scene outside every closed shape, the camera's (0: vacuum).
    pub media: Vec<kernel::medium::Medium>,
    pub medium: u32,
    /// The media's density grids (`kernel::density_grid`; word 0 alone where there are none).
    pub grids: GridTable,
    /// What the loader approximated or ignored (glTF features twinpath does not read yet):
    /// shown to the user before a render.
    pub notes: Vec<String>,
    /// The files the scene was read from, with their hashes (`inputs`).
    pub inputs: Vec<inputs::InputFile>,
}

/// What a scene file gives: the scene, and the render settings its `[render]` table sets over
/// the defaults (a glTF file: the defaults). The two travel apart from here on: the settings
/// are handed to the backend beside the scene, never read out of it.
#[derive(Clone, Debug)]
pub struct SceneFile {
    pub scene: Scene,
    pub settings: RenderSettings,
}

impl Scene {
    /// The kernel parameters for a launch of `count` samples per pixel starting at sample
    /// index `first`, rendered with settings `r`.
    pub fn params(&self, r: &RenderSettings, first: u32, count: u32) -> RenderParams {
        let map = self.environment.as_ref();
        let rotation = map.map_or(0.0, |m| m.rotation_degrees).to_radians();
        RenderParams {
            camera: self.camera.to_kernel(),
            samples: SampleParams {
                width: self.camera.width,
                height: self.camera.height,
                seed: r.seed,
                first,
                count,
                sampler: r.sampler.code(),
            },
            integrator: IntegratorParams {
                light_count: self.lights.len() as u32,
                rr_mode: r.roulette.code(),
                rr_probability: r.rr_probability,
                rr_start_depth: r.roulette_start_depth(),
                mis_mode: r.mis.code(),
                max_depth: r.max_depth,
                light_sampling: r.light_sampling.code(),
            },
            adaptive: AdaptiveParams {
                target: r.adaptive_target,
                pilot_period: if r.adaptive() { PILOT_PERIOD } else { 0 },
                min_pilot_samples: MIN_PILOT_SAMPLES,
            },
            environment: EnvironmentParams {
                background: [self.background.x, self.background.y, self.background.z, 0.0],
                width: map.map_or(0, |m| m.width),
                height: map.map_or(0, |m| m.height),
                light: if map.is_some() {
                    self.lights.len() as u32 - 1
                } else {
                    kernel::scene::NONE
                },
                scale: map.map_or(1.0, |m| m.scale),
                rotation: [rotation.cos(), rotation.sin()],
                medium: self.medium,
                _pad: 0,
            },
            split: SplitParams {
                mode: if r.split == Split::Off {
                    split_mode::OFF
                } else {
                    split_mode::TABLE
                },
                tile_size: SPLIT_TILE,
                tile_columns: self.camera.width.div_ceil(SPLIT_TILE),
                _pad: 0,
            },
        }
    }

    /// Number of world-space triangles: the triangle table's first entries (the instanced
    /// meshes' follow).
    pub fn world_triangle_count(&self) -> usize {
        self.meshes
            .first()
            .map_or(self.triangles.len(), |m| m.range.start)
    }

    /// The world-space box of every instance (empty without instances).
    pub fn instanced_box(&self) -> (Vec3, Vec3) {
        let boxes: Vec<(Vec3, Vec3)> = self
            .meshes
            .iter()
            .map(|m| instancing::mesh_box(&self.triangles[m.range.clone()]))
            .collect();
        instancing::instances_box(&boxes, &self.instances, &self.instance_meshes)
    }

    /// The instance table as the kernel binds it (see [`bindable`]).
    pub fn instance_table(&self) -> Vec<Instance> {
        bindable(&self.instances)
    }

    /// Replaces the environment map (and its light, the last entry of `lights`): scenes built
    /// in code (tests) give maps this way.
    pub fn set_environment(&mut self, map: Option<environment::EnvironmentMap>) {
        if self.environment.take().is_some() {
            self.lights.pop();
        }
        if let Some(m) = &map {
            let world = &self.triangles[..self.world_triangle_count()];
            let light = m.light(&self.spheres, world, self.instanced_box());
            self.lights.push(light);
        }
        self.environment = map;
    }

    /// The environment table (`kernel::environment`): the map's texels and CDFs, or one zero
    /// (a storage buffer needs a number behind it) without a map.
    pub fn environment_table(&self) -> Vec<f32> {
        self.environment
            .as_ref()
            .map_or_else(|| vec![0.0], |m| m.table())
    }

    /// The shading table as the kernel binds it (see [`bindable`]).
    pub fn shading_table(&self) -> Vec<ShadingTriangle> {
        bindable(&self.shading)
    }

    /// Bytes of the scene's tables on either backend: triangles, spheres, shading records,
    /// materials, lights, textures, the environment map, instances, media and density grids
    /// (what `twinpath info` reports).
    pub fn table_bytes(&self) -> [(&'static str, usize); 10] {
        use std::mem::size_of;
        [
            ("triangles", self.triangles.len() * size_of::<Triangle>()),
            ("instances", self.instances.len() * size_of::<Instance>()),
            ("spheres", self.spheres.len() * size_of::<Sphere>()),
            ("shading", self.shading.len() * size_of::<ShadingTriangle>()),
            ("materials", self.materials.len() * size_of::<Material>()),
            ("lights", self.lights.len() * size_of::<Light>()),
            ("textures", self.textures.bytes()),
            (
                "media",
                self.media.len() * size_of::<kernel::medium::Medium>(),
            ),
            ("grids", 4 * self.grids.words.len()),
            (
                "environment",
                self.environment.as_ref().map_or(0, |m| 4 * m.table_len()),
            ),
        ]
    }

    /// One line on the memory the scene's tables take on either backend: each non-empty table
    /// and the total, and the textures' count and sizes.
    pub fn memory_report(&self) -> String {
        let size = |b: usize| {
            if b < 1 << 20 {
                format!("{:.1} KiB", b as f64 / 1024.0)
            } else {
                format!("{:.1} MiB", b as f64 / (1024.0 * 1024.0))
            }
        };
        let tables = self.table_bytes();
        let total: usize = tables.iter().map(|t| t.1).sum();
        let images: Vec<String> = self
            .textures
            .images()
            .map(|t| format!("{}x{}", t.width, t.height))
            .collect();
        let mut parts: Vec<String> = tables
            .iter()
            // The media table holds vacuum alone in a scene without media: not worth a word.
            .filter(|t| t.1 > 0 && (t.0 != "textures" || !self.textures.textures.is_empty()))
            .filter(|t| t.0 != "media" || self.media.len() > 1)
            .filter(|t| t.0 != "grids" || !self.grids.is_empty())
            .map(|(name, b)| format!("{name} {}", size(*b)))
            .collect();
        if !images.is_empty() {
            let noun = if images.len() == 1 {
                "texture"
            } else {
                "textures"
            };
            parts.push(format!("{} {noun} ({})", images.len(), images.join(", ")));
        }
        if self.textures.images().count() < self.textures.textures.len() {
            parts.push("the GGX albedo table".to_string());
        }
        format!("{} in all: {}", size(total), parts.join(", "))
    }

    /// The kernel's feature bits for this scene rendered with `settings` (`kernel::features`;
    /// 0 with `specialize` off, the generic path).
    pub fn features(&self, settings: &RenderSettings) -> u32 {
        if settings.specialize {
            kernel::features::scene_features(&self.params(settings, 0, 1))
                | kernel::bsdf::material_features(&self.materials)
                | kernel::light::light_features(&self.lights)
                | kernel::features::surface_features(&self.materials, &self.shading)
                | kernel::texture::table_features(&self.textures.words)
                | if self.instances.is_empty() {
                    0
                } else {
                    kernel::features::INSTANCES
                }
        } else {
            0
        }
    }

    /// The light table as the kernel reads it: [`Scene::lights`] with the selection
    /// probabilities of `settings.light_selection`.
    pub fn light_table(&self, settings: &RenderSettings) -> Vec<Light> {
        let mut lights = self.lights.clone();
        light_table::assign_light_selection(&mut lights, settings.light_selection.code());
        lights
    }

    /// Number of pixels.
    pub fn pixel_count(&self) -> usize {
        self.camera.width as usize * self.camera.height as usize
    }
}

/// `records` as a storage buffer binds them: one zero record when empty (a buffer needs
/// something behind it; the kernel never reads it, no index pointing there).
fn bindable<T: bytemuck::Pod>(records: &[T]) -> Vec<T> {
    if records.is_empty() {
        vec![T::zeroed()]
    } else {
        records.to_vec()
    }
}
