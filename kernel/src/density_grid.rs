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
//! there, which the host computes; the filter's rounding never reads above its largest voxel,
//! [`DensityGrid::density_inside_v3`]). Delta tracking draws tentative collisions against it,
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

use crate::real::{Real, V3};
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
    #[inline]
    pub fn density_inside(&self, p: Vec3) -> f32 {
        self.density_inside_v3(V3::from(p))
    }

    /// [`DensityGrid::density_inside`] over any scalar [`Real`] (the `f32` instance is it,
    /// operation for operation): the voxel coordinate clamped to the outermost centres, its
    /// floor as the first of the eight voxels read, and the trilinear blend as seven lerps
    /// a + (b - a) t with t = x - floor(x) < 1 (exact). Invariant: the result lies between 0
    /// and the largest of the eight voxels under any arithmetic whose subtraction, product and
    /// sum are correctly rounded, to nearest or toward zero, fused or not (Vulkan's rules;
    /// docs/robustness.md, "Under Vulkan's arithmetic"), so a majorant needs no margin for it.
    /// The form matters: a (1 - t) + b t, the eight weights' products summed, or t = 1 may
    /// read above it.
    pub fn density_inside_v3<R: Real<Bits = u32>>(&self, p: V3<R>) -> R {
        let (lo, hi) = self.bounds();
        let n = self.resolution();
        let last = (n - UVec3::ONE).as_vec3();
        let coordinate = |p: R, lo: f32, hi: f32, n: u32, last: f32| {
            ((p - R::splat(lo)) / (R::splat(hi) - R::splat(lo)) * R::splat(n as f32)
                - R::splat(0.5))
            .max(R::splat(0.0))
            .min(R::splat(last))
        };
        let x = coordinate(p.x, lo.x, hi.x, n.x, last.x);
        let y = coordinate(p.y, lo.y, hi.y, n.y, last.y);
        let z = coordinate(p.z, lo.z, hi.z, n.z, last.z);
        let (bx, by, bz) = (x.floor(), y.floor(), z.floor());
        let (fx, fy, fz) = (x - bx, y - by, z - bz);
        let i0 = UVec3::new(bx.to_i32_bits(), by.to_i32_bits(), bz.to_i32_bits());
        let i1 = (i0 + UVec3::ONE).min(n - UVec3::ONE);
        let first = self.words[self.record + VOXELS] as usize;
        let v = |i: u32, j: u32, k: u32| R::splat(self.voxel(first, n, i, j, k));
        let lerp = |a: R, b: R, t: R| a + (b - a) * t;
        let c00 = lerp(v(i0.x, i0.y, i0.z), v(i1.x, i0.y, i0.z), fx);
        let c10 = lerp(v(i0.x, i1.y, i0.z), v(i1.x, i1.y, i0.z), fx);
        let c01 = lerp(v(i0.x, i0.y, i1.z), v(i1.x, i0.y, i1.z), fx);
        let c11 = lerp(v(i0.x, i1.y, i1.z), v(i1.x, i1.y, i1.z), fx);
        lerp(lerp(c00, c10, fy), lerp(c01, c11, fy), fz)
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
    let ray = (V3::from(origin), V3::from(dir));
    let mut walk = CellWalk::new((lo, hi), cells, 0.5, ray, (0.0, t_max));
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
pub struct CellPiece<R = f32> {
    pub t0: R,
    pub t1: R,
    pub cell: UVec3,
}

/// The walk of a ray `origin + t dir` (t from `t_min` to `t_max`, clipped to a box) through
/// a regular grid of cells over the box, in order (Amanatides and Woo's 3D DDA): each
/// [`CellWalk::next_piece`] is the next cell's piece. Written over any scalar [`Real`], so
/// that tests run it under a Vulkan device's arithmetic; the kernel's is `CellWalk<f32>`.
///
/// Invariants under any arithmetic (each step is an integer step of one cell along one axis,
/// and the pieces' ends are clamped, not computed): the cells stay inside the grid, each
/// piece starts where the last ended and does not end before it starts, and the walk ends
/// after at most the sum of the cell counts of the three axes pieces.
#[derive(Clone, Copy, Debug)]
pub struct CellWalk<R = f32> {
    cell: IVec3,
    step: IVec3,
    cells: IVec3,
    /// The parameter at which the ray leaves the current cell across each axis's next plane.
    t_next: V3<R>,
    /// The parameter the ray takes to cross one cell along each axis.
    t_delta: V3<R>,
    t: R,
    t_end: R,
}

impl<R: Real<Bits = u32>> CellWalk<R> {
    /// The walk of `origin + t dir` (`dir` need not be normalised: parameters are in its
    /// units) for t in [`t_min`, `t_max`] inside the box `lo` to `hi`, through `cells` cells
    /// per axis of size (hi - lo) / (cells - 2 `shift`), the box's min corner at cell
    /// coordinate `shift` (0: the cells tile the box; 1/2: their faces pass through the centres
    /// of a grid of cells - 1 voxels).
    pub fn new(
        (lo, hi): (Vec3, Vec3),
        cells: UVec3,
        shift: f32,
        (origin, dir): (V3<R>, V3<R>),
        (t_min, t_max): (R, R),
    ) -> Self {
        let count = cells.as_ivec3();
        let zero = R::splat(0.0);
        // The box's slabs, axis by axis (an axis the ray runs parallel to clips it only when
        // the origin lies outside that slab).
        let mut t0 = t_min;
        let mut t1 = t_max;
        let clip = |o: R, d: R, a: f32, b: f32, t0: &mut R, t1: &mut R| {
            let (a, b) = (R::splat(a), R::splat(b));
            if d.not_equal(zero) == 0 {
                if (o.less_than(a) | o.greater_than(b)) != 0 {
                    *t1 = R::splat(-1.0);
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
        let (lo, hi) = (V3::<R>::splat(lo), V3::<R>::splat(hi));
        let size = hi - lo;
        let shift2 = R::splat(2.0 * shift);
        let scale = V3::new(
            (R::splat(cells.x as f32) - shift2) / size.x,
            (R::splat(cells.y as f32) - shift2) / size.y,
            (R::splat(cells.z as f32) - shift2) / size.z,
        );
        let shift = R::splat(shift);
        let o = (origin - lo) * scale + V3::new(shift, shift, shift);
        let d = dir * scale;
        let entry = o + d * t0;
        let floor = |x: R| x.floor().to_i32_bits() as i32;
        let cell = IVec3::new(floor(entry.x), floor(entry.y), floor(entry.z))
            .max(IVec3::ZERO)
            .min(count - IVec3::ONE);
        let one = R::splat(1.0);
        let axis = |o: R, d: R, c: i32| -> (i32, R, R) {
            if d.greater_than(zero) != 0 {
                (1, (R::from_i32_bits((c + 1) as u32) - o) / d, one / d)
            } else if d.less_than(zero) != 0 {
                (-1, (R::from_i32_bits(c as u32) - o) / d, -one / d)
            } else {
                (0, R::splat(f32::MAX), R::splat(f32::MAX))
            }
        };
        let (sx, nx, dx) = axis(o.x, d.x, cell.x);
        let (sy, ny, dy) = axis(o.y, d.y, cell.y);
        let (sz, nz, dz) = axis(o.z, d.z, cell.z);
        Self {
            cell,
            step: IVec3::new(sx, sy, sz),
            cells: count,
            t_next: V3::new(nx, ny, nz),
            t_delta: V3::new(dx, dy, dz),
            t: t0,
            t_end: t1,
        }
    }

    /// Whether pieces are left.
    #[inline]
    pub fn more(&self) -> bool {
        self.t.less_than(self.t_end) != 0
    }

    /// The next piece (call only while [`CellWalk::more`]); pieces follow each other (each
    /// starts where the last ended).
    pub fn next_piece(&mut self) -> CellPiece<R> {
        let t_next = self.t_next;
        let at_most = |a: R, b: R| a.at_most(b) != 0;
        let (axis, t_exit) = if at_most(t_next.x, t_next.y) && at_most(t_next.x, t_next.z) {
            (0, t_next.x)
        } else if at_most(t_next.y, t_next.z) {
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
            self.t_next.x = self.t_next.x + self.t_delta.x;
            (self.cell.x, self.cells.x)
        } else if axis == 1 {
            self.cell.y += self.step.y;
            self.t_next.y = self.t_next.y + self.t_delta.y;
            (self.cell.y, self.cells.y)
        } else {
            self.cell.z += self.step.z;
            self.t_next.z = self.t_next.z + self.t_delta.z;
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
        let ray = (V3::from(origin), V3::from(dir));
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
