//! Density grids for heterogeneous media: reading a grid file and laying grids out in the
//! kernel's grid table (`kernel::density_grid`: the layout, the filter and the majorants).
//!
//! The file format is Mitsuba's `.vol` (documented with Mitsuba 0.6's `gridvolume` and read by
//! Mitsuba 3's, so one file serves both renderers): the bytes `VOL`, the version byte 3, then
//! little-endian 32-bit integers encoding (1: f32 values, 3: u8 values read as value / 255),
//! x, y and z resolution and channel count (1: a density), six f32 (the box: min x, y, z, max
//! x, y, z, in world units), then the values, x fastest, then y, then z. twinpath places the
//! grid in the file's box (Mitsuba 3 does so with `use_grid_bbox = true`). OpenVDB files
//! (`.vdb`, what Blender's volume caches are) are read by the `vdb-rs` crate, their "density"
//! grid made dense ([`DenseGrid::parse_vdb`]).

use glam::Vec3;
use kernel::density_grid::{
    MAJORANTS, MAJORANT_RESOLUTION, MAX, MIN, RECORD_WORDS, RESOLUTION, VOXELS,
};
use std::path::Path;

/// A dense grid of densities over an axis-aligned box.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseGrid {
    pub min: Vec3,
    pub max: Vec3,
    pub resolution: [u32; 3],
    /// Densities, x fastest, then y, then z: finite and non-negative.
    pub voxels: Vec<f32>,
}

/// Voxels per majorant cell along an axis (fewer cells where the grid has fewer voxels), and
/// the most majorant cells along an axis: a finer majorant grid means fewer null collisions and
/// more cells to step through.
const VOXELS_PER_MAJORANT: u32 = 4;
const MAX_MAJORANT_CELLS: u32 = 64;

/// Largest voxel count accepted (2^28, a GiB of f32): the table is indexed by u32 words.
const MAX_VOXELS: u64 = 1 << 28;

impl DenseGrid {
    /// A `.vol` file's bytes (see the module's documentation) as a grid, its densities
    /// multiplied by `scale`. The error says what is wrong and where in the file.
    pub fn parse_vol(bytes: &[u8], scale: f32) -> Result<Self, String> {
        const HEADER: usize = 48;
        if bytes.len() < HEADER || &bytes[..3] != b"VOL" {
            return Err(
                "not a .vol grid (it must start with the bytes VOL and a 48-byte header)".into(),
            );
        }
        if bytes[3] != 3 {
            return Err(format!(
                "byte 3: version {} (twinpath reads version 3)",
                bytes[3]
            ));
        }
        let int = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let float = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let encoding = int(4);
        let value_bytes = match encoding {
            1 => 4,
            3 => 1,
            e => {
                return Err(format!(
                    "byte 4: encoding {e} (twinpath reads 1, f32, and 3, u8; not 2, f16, nor 4, \
                     directions)"
                ))
            }
        };
        let (nx, ny, nz, channels) = (int(8), int(12), int(16), int(20));
        if channels != 1 {
            return Err(format!(
                "byte 20: {channels} channels (a density grid has one; colour comes from the \
                 medium's sigma_a and sigma_s)"
            ));
        }
        if nx < 1 || ny < 1 || nz < 1 {
            return Err(format!("bytes 8-19: resolution {nx} x {ny} x {nz}"));
        }
        let count = nx as u64 * ny as u64 * nz as u64;
        if count > MAX_VOXELS {
            return Err(format!(
                "{count} voxels: more than the {MAX_VOXELS} twinpath holds"
            ));
        }
        let min = Vec3::new(float(24), float(28), float(32));
        let max = Vec3::new(float(36), float(40), float(44));
        if !(min.is_finite() && max.is_finite() && min.cmplt(max).all()) {
            return Err(format!(
                "bytes 24-47: the box {min} to {max} is empty or not finite"
            ));
        }
        let expected = HEADER + count as usize * value_bytes;
        if bytes.len() != expected {
            return Err(format!(
                "{} bytes, where a {nx} x {ny} x {nz} grid of {value_bytes}-byte values takes \
                 {expected}",
                bytes.len()
            ));
        }
        let data = &bytes[HEADER..];
        let mut voxels = Vec::with_capacity(count as usize);
        for i in 0..count as usize {
            let v = if value_bytes == 4 {
                f32::from_le_bytes(data[4 * i..4 * i + 4].try_into().unwrap())
            } else {
                data[i] as f32 / 255.0
            } * scale;
            if !(v.is_finite() && v >= 0.0) {
                let (x, y, z) = (
                    i % nx as usize,
                    (i / nx as usize) % ny as usize,
                    i / (nx * ny) as usize,
                );
                return Err(format!(
                    "voxel ({x}, {y}, {z}) (byte {}): density {v} (densities are finite and \
                     non-negative)",
                    HEADER + i * value_bytes
                ));
            }
            voxels.push(v);
        }
        Ok(Self {
            min,
            max,
            resolution: [nx as u32, ny as u32, nz as u32],
            voxels,
        })
    }

    /// The float grid named "density" of an OpenVDB file's bytes (the `vdb-rs` crate;
    /// Blender's volume caches hold one), its densities multiplied by `scale`. The sparse grid
    /// becomes a dense one over the box of its active voxels and tiles with one inactive voxel
    /// (0, the background of a density) more on every side, so the filter fades to 0 at the
    /// edge as OpenVDB's trilinear sampler does. Placement: the grid's own transform (a
    /// voxel's index (i, j, k) is its centre, at scale x (i, j, k) + translation); transforms
    /// other than scale and translation are refused.
    pub fn parse_vdb(bytes: &[u8], scale: f32) -> Result<Self, String> {
        use vdb_rs::{Map, VdbReader};
        // The reader panics on transforms it does not know rather than returning an error.
        let read = std::panic::catch_unwind(|| -> Result<_, String> {
            let mut reader = VdbReader::new(std::io::Cursor::new(bytes))
                .map_err(|e| format!("not an OpenVDB file: {e}"))?;
            let names = reader.available_grids();
            if !names.iter().any(|n| n == "density") {
                return Err(format!(
                    "no grid named \"density\" (the file holds: {})",
                    names.join(", ")
                ));
            }
            reader
                .read_grid::<f32>("density")
                .map_err(|e| format!("its density grid: {e}"))
        });
        let grid = read.map_err(|_| {
            "its density grid has a transform or layout the OpenVDB reader does not know (twinpath \
             reads scale-and-translate transforms)"
                .to_string()
        })??;
        let (size, translation) = match &grid.transform {
            Map::UniformScaleMap { scale_values, .. } => (*scale_values, [0.0; 3]),
            Map::ScaleTranslateMap {
                scale_values,
                translation,
                ..
            } => (*scale_values, [translation.x, translation.y, translation.z]),
        };
        let size = [size.x, size.y, size.z];
        if size.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(format!(
                "voxel size {size:?}: twinpath reads positive scales only"
            ));
        }
        // The box of the active voxels and tiles, in index space (each item's level says how
        // many voxels it spans along each axis).
        let items: Vec<([i64; 3], i64, f32)> = grid
            .iter()
            .map(|(p, v, level)| {
                let at = [p.x as i64, p.y as i64, p.z as i64];
                (at, level.scale() as i64, v)
            })
            .collect();
        if items.is_empty() {
            return Err("its density grid has no active voxels".into());
        }
        let mut lo = [i64::MAX; 3];
        let mut hi = [i64::MIN; 3];
        for (at, span, _) in &items {
            for c in 0..3 {
                lo[c] = lo[c].min(at[c]);
                hi[c] = hi[c].max(at[c] + span - 1);
            }
        }
        // One background voxel more on every side.
        let first = lo.map(|l| l - 1);
        let n = [0, 1, 2].map(|c| (hi[c] - lo[c] + 3) as u64);
        let count = n[0] * n[1] * n[2];
        if count > MAX_VOXELS {
            return Err(format!(
                "its active voxels span {} x {} x {} voxels: more than the {MAX_VOXELS} twinpath \
                 holds as a dense grid",
                n[0], n[1], n[2]
            ));
        }
        let mut voxels = vec![0f32; count as usize];
        for (at, span, v) in &items {
            let v = v * scale;
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!(
                    "voxel {at:?}: density {v} (densities are finite and non-negative)"
                ));
            }
            for z in at[2]..at[2] + span {
                for y in at[1]..at[1] + span {
                    for x in at[0]..at[0] + span {
                        let (i, j, k) = (x - first[0], y - first[1], z - first[2]);
                        voxels[((k as u64 * n[1] + j as u64) * n[0] + i as u64) as usize] = v;
                    }
                }
            }
        }
        // Voxel index i's centre is at size i + translation; the dense grid's box reaches half
        // a voxel beyond its outermost centres.
        let corner =
            |c: usize, index: i64| (size[c] * (index as f64 - 0.5) + translation[c]) as f32;
        Ok(Self {
            min: Vec3::new(
                corner(0, first[0]),
                corner(1, first[1]),
                corner(2, first[2]),
            ),
            max: Vec3::new(
                corner(0, first[0] + n[0] as i64),
                corner(1, first[1] + n[1] as i64),
                corner(2, first[2] + n[2] as i64),
            ),
            resolution: n.map(|v| v as u32),
            voxels,
        })
    }

    /// Reads the grid file at `path` (recorded as one of the scene's inputs, `super::inputs`)
    /// by its extension: `.vol` ([`DenseGrid::parse_vol`]) or `.vdb`
    /// ([`DenseGrid::parse_vdb`]), its densities multiplied by `scale`.
    pub fn read(path: &Path, scale: f32) -> Result<Self, String> {
        let parse = match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("vol") => Self::parse_vol,
            Some(e) if e.eq_ignore_ascii_case("vdb") => Self::parse_vdb,
            _ => {
                return Err(format!(
                    "{}: a grid file is a .vol (Mitsuba's dense grid) or a .vdb (OpenVDB)",
                    path.display()
                ))
            }
        };
        let bytes = super::inputs::read(path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        parse(&bytes, scale).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// The `.vol` bytes of this grid (f32 encoding): what [`DenseGrid::parse_vol`] reads.
    pub fn to_vol(&self) -> Vec<u8> {
        let mut out = b"VOL\x03".to_vec();
        let [nx, ny, nz] = self.resolution;
        for i in [1, nx as i32, ny as i32, nz as i32, 1] {
            out.extend(i.to_le_bytes());
        }
        for f in self.min.to_array().into_iter().chain(self.max.to_array()) {
            out.extend(f.to_le_bytes());
        }
        for v in &self.voxels {
            out.extend(v.to_le_bytes());
        }
        out
    }

    /// The majorant grid's resolution along each axis.
    pub fn majorant_resolution(&self) -> [u32; 3] {
        self.resolution
            .map(|n| n.div_ceil(VOXELS_PER_MAJORANT).clamp(1, MAX_MAJORANT_CELLS))
    }

    /// The majorant grid (`kernel::density_grid`): each cell the largest voxel the trilinear
    /// filter reads at any point of the cell, with one voxel more on every side (points the
    /// kernel's cell walk places in a cell may lie a rounding error outside it). Nothing is
    /// added for the filter's rounding: it never reads above its largest voxel
    /// (`kernel::density_grid::DensityGrid::density_inside_v3`).
    pub fn majorants(&self) -> Vec<f32> {
        let n = self.resolution;
        let m = self.majorant_resolution();
        // The voxels along one axis that cell c reads: centres at (i + 1/2) / n of the box.
        let range = |axis: usize, c: u32| {
            let (n, m) = (n[axis] as f64, m[axis] as f64);
            let a = (c as f64 / m * n - 0.5).floor() - 1.0;
            let b = ((c + 1) as f64 / m * n - 0.5).floor() + 2.0;
            (a.max(0.0) as u32, b.min(n - 1.0).max(0.0) as u32)
        };
        let mut out = Vec::with_capacity((m[0] * m[1] * m[2]) as usize);
        for cz in 0..m[2] {
            let (z0, z1) = range(2, cz);
            for cy in 0..m[1] {
                let (y0, y1) = range(1, cy);
                for cx in 0..m[0] {
                    let (x0, x1) = range(0, cx);
                    let mut most = 0.0f32;
                    for z in z0..=z1 {
                        for y in y0..=y1 {
                            let row = ((z * n[1] + y) * n[0]) as usize;
                            for x in x0..=x1 {
                                most = most.max(self.voxels[row + x as usize]);
                            }
                        }
                    }
                    out.push(most);
                }
            }
        }
        out
    }
}

/// The grid table as the kernel binds it: word 0 the number of grids, then per grid its
/// record, voxels and majorants (`kernel::density_grid`).
#[derive(Clone, Debug, PartialEq)]
pub struct GridTable {
    pub words: Vec<u32>,
}

impl Default for GridTable {
    fn default() -> Self {
        Self { words: vec![0] }
    }
}

impl GridTable {
    /// Appends `grid` and returns the word of its record (never 0), or None where the table
    /// would pass 2^32 words.
    pub fn add(&mut self, grid: &DenseGrid) -> Option<u32> {
        let majorants = grid.majorants();
        let record = self.words.len();
        let voxels = record + RECORD_WORDS;
        let first_majorant = voxels + grid.voxels.len();
        if first_majorant + majorants.len() > u32::MAX as usize {
            return None;
        }
        let majorant_resolution = grid.majorant_resolution();
        let mut head = [0u32; RECORD_WORDS];
        for k in 0..3 {
            head[MIN + k] = grid.min[k].to_bits();
            head[MAX + k] = grid.max[k].to_bits();
            head[RESOLUTION + k] = grid.resolution[k];
            head[MAJORANT_RESOLUTION + k] = majorant_resolution[k];
        }
        head[VOXELS] = voxels as u32;
        head[MAJORANTS] = first_majorant as u32;
        self.words.extend(head);
        self.words.extend(grid.voxels.iter().map(|v| v.to_bits()));
        self.words.extend(majorants.iter().map(|v| v.to_bits()));
        self.words[0] += 1;
        Some(record as u32)
    }

    /// The number of grids.
    pub fn len(&self) -> usize {
        self.words[0] as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
