//! The environment map of `[background] map = ...`: an equirectangular image (linear OpenEXR,
//! or Radiance .hdr) loaded with `image`, and the environment table the kernel samples it by
//! (`kernel::environment`: texels, the marginal CDF over rows, each row's conditional CDF).

use super::error::SceneError;
use super::light_table::{scene_bounds, sphere_light};
use kernel::environment::TableLayout;
use kernel::scene::{light_kind, Light, Sphere, Triangle};
use std::path::Path;

/// Largest map side accepted (a 16k x 8k map is 1.5 GiB of f32 RGB already).
pub const MAX_MAP_SIDE: u32 = 16384;

/// An environment map: linear RGB texels, row 0 looking straight up (`kernel::environment`).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    pub width: u32,
    pub height: u32,
    /// Row-major RGB, each component finite and >= 0.
    pub texels: Vec<[f32; 3]>,
    /// Factor on every texel (`[background] scale`).
    pub scale: f32,
    /// Rotation about the up axis (+y), degrees (`[background] rotation`).
    pub rotation_degrees: f32,
}

impl EnvironmentMap {
    /// Loads `path` (`.exr` linear, `.hdr` Radiance RGBE): its texels must be finite and
    /// non-negative, its sides within [`MAX_MAP_SIDE`].
    pub fn load(path: &Path, field: &str) -> Result<Self, SceneError> {
        let err = |msg: String| SceneError::new(path, None, field, msg);
        let bytes = super::inputs::read(path).map_err(|e| err(format!("cannot read: {e}")))?;
        let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| err(format!("cannot read: {e}")))?;
        let image = reader
            .decode()
            .map_err(|e| err(format!("not a readable EXR or HDR image: {e}")))?
            .into_rgb32f();
        let (width, height) = image.dimensions();
        if width == 0 || height == 0 || width > MAX_MAP_SIDE || height > MAX_MAP_SIDE {
            return Err(err(format!(
                "{width} x {height} texels: each side must be within 1..={MAX_MAP_SIDE}"
            )));
        }
        let texels: Vec<[f32; 3]> = image.pixels().map(|p| p.0).collect();
        if let Some(k) = texels
            .iter()
            .position(|t| !t.iter().all(|c| c.is_finite() && *c >= 0.0))
        {
            return Err(err(format!(
                "texel ({}, {}) is {:?}: radiance must be finite and non-negative",
                k as u32 % width,
                k as u32 / width,
                texels[k]
            )));
        }
        Ok(Self {
            width,
            height,
            texels,
            scale: 1.0,
            rotation_degrees: 0.0,
        })
    }

    /// A map of one colour, `w` x `h` texels (tests; a constant background as a map).
    pub fn constant(w: u32, h: u32, rgb: [f32; 3]) -> Self {
        Self {
            width: w,
            height: h,
            texels: vec![rgb; (w * h) as usize],
            scale: 1.0,
            rotation_degrees: 0.0,
        }
    }

    /// sin theta at the centre of row `j` (theta from straight up).
    fn row_sin(&self, j: u32) -> f64 {
        (std::f64::consts::PI * (j as f64 + 0.5) / self.height as f64).sin()
    }

    /// The environment table (`kernel::environment`): texels, the marginal CDF over rows, each
    /// row's conditional CDF, from the weights luminance x sin theta (row centre), in f64 then
    /// rounded, with every CDF's first entry exactly 0 and last exactly 1. A row (or a whole
    /// map) of zero weight gets a uniform CDF, which the zero-probability bins above it make
    /// unreachable (or, for an all-black map, harmless: it sends no light).
    pub fn table(&self) -> Vec<f32> {
        let (w, h) = (self.width as usize, self.height as usize);
        let layout = self.layout();
        let mut out = Vec::with_capacity(self.table_len());
        out.extend(self.texels.iter().flatten());
        let luminance =
            |t: &[f32; 3]| 0.2126 * t[0] as f64 + 0.7152 * t[1] as f64 + 0.0722 * t[2] as f64;
        let weights: Vec<Vec<f64>> = (0..h)
            .map(|j| {
                let s = self.row_sin(j as u32);
                self.texels[j * w..(j + 1) * w]
                    .iter()
                    .map(|t| luminance(t) * s)
                    .collect()
            })
            .collect();
        let row_sums: Vec<f64> = weights.iter().map(|r| r.iter().sum()).collect();
        assert_eq!(out.len(), layout.marginal() as usize);
        out.extend(cdf(&row_sums));
        for (j, row) in weights.iter().enumerate() {
            assert_eq!(out.len(), layout.conditional(j as u32) as usize);
            out.extend(cdf(row));
        }
        assert_eq!(out.len(), self.table_len());
        out
    }

    /// Where [`EnvironmentMap::table`]'s parts start, as the kernel reads them.
    pub fn layout(&self) -> TableLayout {
        TableLayout {
            width: self.width,
            height: self.height,
        }
    }

    /// The number of entries of [`EnvironmentMap::table`]: the texels (3 w h), the marginal CDF
    /// (h + 1) and each row's conditional CDF (w + 1 each).
    pub fn table_len(&self) -> usize {
        self.layout().entries() as usize
    }

    /// The environment map's entry in the light table: the sphere bounding the scene's geometry
    /// (which shadow rays toward the map leave), and its mean radiance, so that selection by power
    /// weighs it as a sphere of that radiance around the scene.
    pub fn light(
        &self,
        spheres: &[Sphere],
        triangles: &[Triangle],
        instanced: (glam::Vec3, glam::Vec3),
    ) -> Light {
        let (center, radius) = scene_bounds(spheres, triangles, instanced);
        let mut l = sphere_light(center, radius, self.mean_radiance());
        l.kind = light_kind::ENVIRONMENT;
        l
    }

    /// The mean radiance over the sphere of directions (solid-angle weighted, scale applied):
    /// the environment light's `radiance` for selection by power.
    pub fn mean_radiance(&self) -> [f32; 3] {
        let (w, h) = (self.width as usize, self.height as usize);
        let mut sum = [0.0f64; 3];
        let mut total = 0.0;
        for j in 0..h {
            let s = self.row_sin(j as u32);
            for t in &self.texels[j * w..(j + 1) * w] {
                for c in 0..3 {
                    sum[c] += t[c] as f64 * s;
                }
                total += s;
            }
        }
        sum.map(|x| (x / total * self.scale as f64) as f32)
    }
}

/// The smallest non-zero entry of a stored CDF: entries below it are stored as 0.
///
/// Why: a device may flush denormals to zero (Vulkan without float controls), so the sampler
/// and its density must never meet one. With every entry 0 or at least 2^-32, a bin's
/// probability (a difference of two entries) is 0 or at least 2^-55, a texel's (row times
/// column) 0 or at least 2^-110, and its density (times the texel count, over 2 pi^2 sin
/// theta) at least 2^-115: every value the kernel's `environment::sample` and `pdf` compute is
/// 0 or normal, so a flushing device computes what an IEEE one does (`docs/robustness.md`,
/// "Environment-map tables"). Only a CDF's first bins can fall below it (a CDF rises): their
/// probability goes to the first bin whose upper entry reaches 2^-32, they get 0, the sampler
/// never chooses them and `pdf` reads 0 there, which leaves their light to the BSDF strategy
/// under MIS (unbiased, as for any texel of zero probability). A table changes only where a
/// CDF's first non-zero entry lies below 2^-32: a row whose first lit texels hold less than
/// 2^-32 of its weight, or a map whose first lit rows hold less than 2^-32 of its own.
const CDF_FLOOR: f64 = 1.0 / 4_294_967_296.0;

/// The CDF of `weights`: n + 1 numbers from exactly 0 to exactly 1 (uniform if they sum to 0),
/// each 0 or at least [`CDF_FLOOR`].
fn cdf(weights: &[f64]) -> Vec<f32> {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    let mut out = Vec::with_capacity(n + 1);
    let mut running = 0.0;
    out.push(0.0);
    for (k, w) in weights.iter().enumerate() {
        running += if total > 0.0 { *w } else { 1.0 };
        let value = running / if total > 0.0 { total } else { n as f64 };
        out.push(if k + 1 == n {
            1.0
        } else if value < CDF_FLOOR {
            0.0
        } else {
            value.min(1.0) as f32
        });
    }
    out
}
