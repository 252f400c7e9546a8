//! Density grids of heterogeneous media (TOML `[media]`'s `grid`): every grid of a scene in one
//! `u32` buffer (the grid table), the density at a point, and the walk through a grid's
//! majorant cells that delta and ratio tracking (`crate::delta_tracking`) step along.
//!
//! A grid medium's coefficients (`crate::medium::Medium`) are per unit density: at a point of
//! density rho its extinction is rho sigma_t. The grid fills an axis-aligned box in world space
//! (the file's bounds); outside the box the density is 0. Voxel (i, j, k) of a grid of
//! resolution (nx, ny, nz) is centred at `min + (i + 1/2, j + 1/2, k + 1/2) / (nx, ny, nz) *
//! (max - min)`; between centres the density is trilinear, and between the outermost centres and
//! the box's faces it is the outermost voxels' (clamped to the edge: Mitsuba 3's `gridvolume`
//! with its default filter and wrap mode).
//!
//! Each grid has a coarse *majorant grid* over the same box: cell c's value bounds the density
//! at every point of the cell from above (the maximum of the voxels the trilinear filter reads
//! there, which the host computes and raises by 2^-13 of itself so that rounding of the filter
//! on either backend cannot exceed it). Delta tracking draws tentative collisions against it,
//! cell by cell (pbrt-v4, 4th ed., section 11.4.3, `DDAMajorantIterator`; Amanatides and Woo's
//! 3D DDA, Eurographics 1987).
//!
//! Layout of the table (the host's `density_grid` module builds it):
//! - word 0: the number of grids (a table always has it, so no record starts at word 0 and a
//!   medium's grid word 0 means "homogeneous");
//! - a grid's record, [`RECORD_WORDS`] words: the box's min x, y, z and max x, y, z (f32
//!   bits), the voxel resolution x, y, z, the majorant resolution x, y, z, the word of the
//!   first voxel and the word of the first majorant cell, two unused words;
//! - voxels and majorant cells: f32 bits, x fastest, then y, then z.

use spirv_std::glam::{IVec3, UVec3, Vec3};

/// Words per grid record.
pub const RECORD_WORDS: usize = 16;
/// Word offsets inside a record.
pub const MIN: usize = 0;
pub const MAX: usize = 3;
pub const RESOLUTION: usize = 6;
pub const MAJORANT_RESOLUTION: usize = 9;
pub const VOXELS: usize = 12;
pub const MAJORANTS: usize = 13;
/// How much the host raises each majorant cell above the largest voxel it covers: a factor
/// 1 + 2^-13, far above the rounding of an eight-term convex combination in f32 (a few units
/// in the last place, 2^-23 each), also under Vulkan's precision rules.
pub const MAJORANT_MARGIN: f32 = 1.0 + 1.0 / 8192.0;

/// One grid of the table: the record at word `record`.
#[derive(Clone, Copy)]
pub struct DensityGrid<'a> {
    words: &'a [u32],
    record: usize,
}

impl<'a> DensityGrid<'a> {
    /// The grid whose record is at word `record` of `words`.
    #[inline]
    pub fn at(words: &'a [u32], record: u32) -> Self {
        Self {
            words,
            record: record as usize,
        }
    }

    #[inline]
    fn float(&self, k: usize) -> f32 {
        f32::from_bits(self.words[self.record + k])
    }

    #[inline]
    fn vec(&self, k: usize) -> Vec3 {
        Vec3::new(self.float(k), self.float(k + 1), self.float(k + 2))
    }

    #[inline]
    fn uvec(&self, k: usize) -> UVec3 {
        let w = self.words;
        let r = self.record + k;
        UVec3::new(w[r], w[r + 1], w[r + 2])
    }

    /// The box's corners.
    #[inline]
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.vec(MIN), self.vec(MAX))
    }

    /// The voxel resolution.
    #[inline]
    pub fn resolution(&self) -> UVec3 {
        self.uvec(RESOLUTION)
    }

    /// The majorant grid's resolution.
    #[inline]
    pub fn majorant_resolution(&self) -> UVec3 {
        self.uvec(MAJORANT_RESOLUTION)
    }

    #[inline]
    fn voxel(&self, first: usize, n: UVec3, i: u32, j: u32, k: u32) -> f32 {
        let index = ((k * n.y + j) * n.x + i) as usize;
        f32::from_bits(self.words[first + index])
    }

    /// The density at world point `p` (see the module's documentation: trilinear between
    /// voxel centres, clamped to the edge inside the box, 0 outside it).
    pub fn density(&self, p: Vec3) -> f32 {
        let (lo, hi) = self.bounds();
        if p.x < lo.x || p.y < lo.y || p.z < lo.z || p.x > hi.x || p.y > hi.y || p.z > hi.z {
            return 0.0;
        }
        self.density_inside(p)
    }

    /// The density at `p` taken to lie inside the box (a point of a walk's piece: one a
    /// rounding error outside it reads the face's density, not 0).
    pub fn density_inside(&self, p: Vec3) -> f32 {
        let (lo, hi) = self.bounds();
        let n = self.resolution();
        let last = (n - UVec3::ONE).as_vec3();
        let x = ((p - lo) / (hi - lo) * n.as_vec3() - Vec3::splat(0.5))
            .max(Vec3::ZERO)
            .min(last);
        let base = x.floor();
        let f = x - base;
        let i0 = base.as_uvec3();
        let i1 = (i0 + UVec3::ONE).min(n - UVec3::ONE);
        let first = self.words[self.record + VOXELS] as usize;
        let v = |i: u32, j: u32, k: u32| self.voxel(first, n, i, j, k);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let c00 = lerp(v(i0.x, i0.y, i0.z), v(i1.x, i0.y, i0.z), f.x);
        let c10 = lerp(v(i0.x, i1.y, i0.z), v(i1.x, i1.y, i0.z), f.x);
        let c01 = lerp(v(i0.x, i0.y, i1.z), v(i1.x, i0.y, i1.z), f.x);
        let c11 = lerp(v(i0.x, i1.y, i1.z), v(i1.x, i1.y, i1.z), f.x);
        lerp(lerp(c00, c10, f.y), lerp(c01, c11, f.y), f.z)
    }

    /// The majorant of majorant cell `cell` (each component below the majorant resolution).
    #[inline]
    pub fn majorant(&self, cell: UVec3) -> f32 {
        let first = self.words[self.record + MAJORANTS] as usize;
        self.voxel(first, self.majorant_resolution(), cell.x, cell.y, cell.z)
    }
}

/// The integral of the density along `origin + t dir` (`dir` of unit length) for t in
/// [0, `t_max`]: exact, to rounding. Between the planes through the voxel centres (and the
/// box's faces) the filter reads the same eight voxels with weights linear in each
/// coordinate, so along a ray the density is a cubic in t there, which Simpson's rule
/// integrates exactly; the walk visits those pieces in order ([`CellWalk`] over the grid of
/// resolution + 1 cells whose faces are those planes).
pub fn optical_depth(grid: &DensityGrid, origin: Vec3, dir: Vec3, t_max: f32) -> f32 {
    let (lo, hi) = grid.bounds();
    let cells = grid.resolution() + UVec3::ONE;
    let mut walk = CellWalk::new((lo, hi), cells, 0.5, (origin, dir), (0.0, t_max));
    let mut tau = 0.0;
    let mut start = f32::NAN;
    while walk.more() {
        let piece = walk.next_piece();
        let h = piece.t1 - piece.t0;
        if start.is_nan() {
            start = grid.density_inside(origin + dir * piece.t0);
        }
        let mid = grid.density_inside(origin + dir * (piece.t0 + 0.5 * h));
        let end = grid.density_inside(origin + dir * piece.t1);
        tau += h * (1.0 / 6.0) * (start + 4.0 * mid + end);
        start = end;
    }
    tau
}

/// A piece of a ray inside one cell of a [`CellWalk`]: parameters `t0` to `t1`, and the cell.
#[derive(Clone, Copy, Debug)]
pub struct CellPiece {
    pub t0: f32,
    pub t1: f32,
    pub cell: UVec3,
}

/// The walk of a ray `origin + t dir` (t from `t_min` to `t_max`, clipped to a box) through
/// a regular grid of cells over the box, in order (Amanatides and Woo's 3D DDA): each
/// [`CellWalk::next_piece`] is the next cell's piece.
#[derive(Clone, Copy, Debug)]
pub struct CellWalk {
    cell: IVec3,
    step: IVec3,
    cells: IVec3,
    /// The parameter at which the ray leaves the current cell across each axis's next plane.
    t_next: Vec3,
    /// The parameter the ray takes to cross one cell along each axis.
    t_delta: Vec3,
    t: f32,
    t_end: f32,
}

impl CellWalk {
    /// The walk of `origin + t dir` (`dir` need not be normalised: parameters are in its
    /// units) for t in [`t_min`, `t_max`] inside the box `lo` to `hi`, through `cells` cells
    /// per axis of size (hi - lo) / (cells - 2 `shift`), the box's min corner at cell
    /// coordinate `shift` (0: the cells tile the box; 1/2: their faces pass through the centres
    /// of a grid of cells - 1 voxels).
    pub fn new(
        (lo, hi): (Vec3, Vec3),
        cells: UVec3,
        shift: f32,
        (origin, dir): (Vec3, Vec3),
        (t_min, t_max): (f32, f32),
    ) -> Self {
        let count = cells.as_ivec3();
        // The box's slabs, axis by axis (an axis the ray runs parallel to clips it only when
        // the origin lies outside that slab).
        let mut t0 = t_min;
        let mut t1 = t_max;
        let clip = |o: f32, d: f32, a: f32, b: f32, t0: &mut f32, t1: &mut f32| {
            if d == 0.0 {
                if o < a || o > b {
                    *t1 = -1.0;
                }
            } else {
                let (ta, tb) = ((a - o) / d, (b - o) / d);
                *t0 = t0.max(ta.min(tb));
                *t1 = t1.min(ta.max(tb));
            }
        };
        clip(origin.x, dir.x, lo.x, hi.x, &mut t0, &mut t1);
        clip(origin.y, dir.y, lo.y, hi.y, &mut t0, &mut t1);
        clip(origin.z, dir.z, lo.z, hi.z, &mut t0, &mut t1);
        // Cell coordinates: (p - lo) * scale + shift, one unit per cell.
        let scale = (cells.as_vec3() - Vec3::splat(2.0 * shift)) / (hi - lo);
        let o = (origin - lo) * scale + Vec3::splat(shift);
        let d = dir * scale;
        let entry = o + d * t0;
        let cell = entry
            .floor()
            .as_ivec3()
            .max(IVec3::ZERO)
            .min(count - IVec3::ONE);
        let axis = |o: f32, d: f32, c: i32| -> (i32, f32, f32) {
            if d > 0.0 {
                (1, ((c + 1) as f32 - o) / d, 1.0 / d)
            } else if d < 0.0 {
                (-1, (c as f32 - o) / d, -1.0 / d)
            } else {
                (0, f32::MAX, f32::MAX)
            }
        };
        let (sx, nx, dx) = axis(o.x, d.x, cell.x);
        let (sy, ny, dy) = axis(o.y, d.y, cell.y);
        let (sz, nz, dz) = axis(o.z, d.z, cell.z);
        Self {
            cell,
            step: IVec3::new(sx, sy, sz),
            cells: count,
            t_next: Vec3::new(nx, ny, nz),
            t_delta: Vec3::new(dx, dy, dz),
            t: t0,
            t_end: t1,
        }
    }

    /// Whether pieces are left.
    #[inline]
    pub fn more(&self) -> bool {
        self.t < self.t_end
    }

    /// The next piece (call only while [`CellWalk::more`]); pieces follow each other (each
    /// starts where the last ended).
    pub fn next_piece(&mut self) -> CellPiece {
        let t_next = self.t_next;
        let (axis, t_exit) = if t_next.x <= t_next.y && t_next.x <= t_next.z {
            (0, t_next.x)
        } else if t_next.y <= t_next.z {
            (1, t_next.y)
        } else {
            (2, t_next.z)
        };
        let t1 = t_exit.min(self.t_end).max(self.t);
        let piece = CellPiece {
            t0: self.t,
            t1,
            cell: self.cell.as_uvec3(),
        };
        self.t = t1;
        let (c, n) = if axis == 0 {
            self.cell.x += self.step.x;
            self.t_next.x += self.t_delta.x;
            (self.cell.x, self.cells.x)
        } else if axis == 1 {
            self.cell.y += self.step.y;
            self.t_next.y += self.t_delta.y;
            (self.cell.y, self.cells.y)
        } else {
            self.cell.z += self.step.z;
            self.t_next.z += self.t_delta.z;
            (self.cell.z, self.cells.z)
        };
        if c < 0 || c >= n {
            self.t = self.t_end;
        }
        piece
    }
}

/// A piece of a ray inside one majorant cell: parameters `t0` to `t1` and the cell's
/// majorant density.
#[derive(Clone, Copy, Debug)]
pub struct MajorantSegment {
    pub t0: f32,
    pub t1: f32,
    pub majorant: f32,
}

/// The walk of a ray through a grid's majorant cells ([`CellWalk`]): pieces outside the box
/// are skipped (the density is 0 there).
#[derive(Clone, Copy, Debug)]
pub struct MajorantWalk {
    walk: CellWalk,
}

impl MajorantWalk {
    /// The walk of `origin + t dir` for t in [`t_min`, `t_max`] through `grid`'s majorant
    /// cells.
    pub fn new(grid: &DensityGrid, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self {
        let cells = grid.majorant_resolution();
        let ray = (origin, dir);
        Self {
            walk: CellWalk::new(grid.bounds(), cells, 0.0, ray, (t_min, t_max)),
        }
    }

    /// Whether pieces are left.
    #[inline]
    pub fn more(&self) -> bool {
        self.walk.more()
    }

    /// The next piece (call only while [`MajorantWalk::more`]).
    #[inline]
    pub fn next(&mut self, grid: &DensityGrid) -> MajorantSegment {
        let piece = self.walk.next_piece();
        MajorantSegment {
            t0: piece.t0,
            t1: piece.t1,
            majorant: grid.majorant(piece.cell),
        }
    }
}
