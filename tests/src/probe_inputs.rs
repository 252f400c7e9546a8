//! The inputs of the GPU function probes (`tests/tests/gpu_functions.rs`) and of the bounds by
//! ball arithmetic checked against models of a device (`vulkan_precision/ball_bounds.rs`), drawn
//! one way for both: edge-favouring numbers on top of [`SplitMix`], and the records of the probes
//! whose bounds both tests check, with their layout as `kernel::probe` reads and writes it.

use crate::device_class::{EnvironmentRecord, PunctualRecord};
use crate::SplitMix;
use glam::Vec3;

/// Edge-favouring inputs on top of [`SplitMix`] (independent of the kernel's RNG under test).
pub struct ProbeInputs(pub SplitMix);

impl ProbeInputs {
    pub fn u64(&mut self) -> u64 {
        self.0.u64()
    }
    pub fn unit(&mut self) -> f32 {
        self.0.unit()
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
    pub fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[(self.u64() % xs.len() as u64) as usize]
    }
    /// A magnitude 10^U(-6, 6).
    pub fn scale(&mut self) -> f32 {
        10f32.powf(self.range(-6.0, 6.0))
    }
    pub fn vec(&mut self) -> Vec3 {
        Vec3::new(
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
        )
    }
    /// Unit vectors: uniform, exactly on an axis, or within 1e-4..1e-7 of one.
    pub fn dir(&mut self) -> Vec3 {
        let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        match self.u64() % 4 {
            0 => self.pick(&axes),
            1 => {
                let eps = 10f32.powf(self.range(-7.0, -4.0));
                (self.pick(&axes) + eps * self.vec()).normalize()
            }
            _ => loop {
                let v = self.vec();
                if v.length_squared() > 1e-6 && v.length_squared() <= 1.0 {
                    break v.normalize();
                }
            },
        }
    }
    /// A unit direction grazing the plane of `n` (within 1e-3 .. 1e-7 radians), or any.
    pub fn grazing(&mut self, n: Vec3) -> Vec3 {
        let d = self.dir();
        if self.u64().is_multiple_of(2) {
            let t = (d - n * d.dot(n)).normalize_or(Vec3::X);
            (t + n * 10f32.powf(self.range(-7.0, -3.0)) * self.pick(&[1.0, -1.0])).normalize()
        } else {
            d
        }
    }
}

/// A probe record's row: a vector and a fourth number.
fn row(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

impl ProbeInputs {
    /// A punctual or directional light's record: receivers and lights 10^-6 to 10^6 apart and
    /// from the origin, a receiver at the light (density 0) now and then, point lights (scale 0,
    /// offset 1) and spots whose cones are wide or narrow apart (the falloff's slope
    /// 1 / (cos inner - cos outer) up to 10^4), selection pmfs of 1, 1/4 and any.
    pub fn punctual_record(&mut self) -> PunctualRecord {
        let x = self.vec() * self.scale();
        let position = if self.u64().is_multiple_of(16) {
            x
        } else {
            x + self.dir() * self.scale()
        };
        let axis = self.dir();
        let spot = if self.u64().is_multiple_of(4) {
            (0.0, 1.0)
        } else {
            let outer = self.range(-0.9, 0.99);
            let any = 0.01 + (0.999 - outer) * self.unit();
            let width = self.pick(&[1e-4, 1e-2, any]);
            let scale = 1.0 / width.min(0.999 - outer);
            (scale, -outer * scale)
        };
        let centre = self.vec() * self.scale();
        let any = self.range(1e-3, 1.0);
        let select_pmf = self.pick(&[1.0, 0.25, any]);
        let radius = self.scale();
        PunctualRecord {
            x: x.to_array(),
            select_pmf,
            position: position.to_array(),
            axis: axis.to_array(),
            spot,
            bounds: [centre.x, centre.y, centre.z, radius],
        }
    }

    /// An environment map's record: maps from one texel to 2048 on a side, rotated or not; the
    /// drawn row's and column's CDF bins wide, narrow (down to 1e-7) and whole, the uniform
    /// number anywhere in its bin (its lower end included, as the sampler's search allows);
    /// directions on and near the axes (the poles, the seam at u = 0).
    pub fn environment_record(&mut self) -> EnvironmentRecord {
        let size = |g: &mut Self| g.pick(&[1.0, 2.0, 3.0, 7.0, 64.0, 1000.0, 2048.0]) as u32;
        let (width, height) = (size(self), size(self));
        let (row, column) = (
            (self.u64() % height as u64) as u32,
            (self.u64() % width as u64) as u32,
        );
        // Bin i of n: the first one's lower end 0, the last one's upper end 1 (the host's CDFs
        // run from 0 to 1).
        let bin = |g: &mut Self, i: u32, n: u32| {
            let lo = g.unit();
            let lo = if i == 0 { 0.0 } else { g.pick(&[0.0, lo]) };
            let any = g.range(0.0, 1.0 - lo);
            let hi = g.pick(&[1.0, (lo + 1e-7).min(1.0), (lo + 1e-3).min(1.0), lo + any]);
            let hi = if hi > lo && i + 1 < n { hi } else { 1.0 };
            let u = lo + (hi - lo) * g.unit();
            // In (0, 1) and in [lo, hi), as `u32_to_unit_f32`'s numbers and `find_interval`
            // give it.
            let u = if u < hi { u } else { lo };
            (lo, hi, u.max(0.5 / 8_388_608.0))
        };
        let ((r0, r1, u2), (c0, c1, u1)) = (bin(self, row, height), bin(self, column, width));
        let angle = self.range(-3.2, 3.2);
        let angle = self.pick(&[0.0, angle]);
        EnvironmentRecord {
            rotation: [angle.cos(), angle.sin()],
            u: (u1, u2),
            row_cdf: [r0, r1],
            column_cdf: [c0, c1],
            d: self.dir().to_array(),
            size: (width, height),
            row,
            column,
        }
    }
}

impl PunctualRecord {
    /// The record as the probe reads it.
    pub fn to_probe(&self) -> [[u32; 4]; 4] {
        let v = Vec3::from;
        [
            row(v(self.x), self.select_pmf),
            row(v(self.position), self.spot.0),
            row(v(self.axis), self.spot.1),
            self.bounds,
        ]
        .map(|r| r.map(f32::to_bits))
    }

    /// The record the probe read from `r`.
    pub fn from_probe(r: &[[u32; 4]; 4]) -> Self {
        let f = |i: usize, j: usize| f32::from_bits(r[i][j]);
        let v = |i: usize| [f(i, 0), f(i, 1), f(i, 2)];
        Self {
            x: v(0),
            select_pmf: f(0, 3),
            position: v(1),
            axis: v(2),
            spot: (f(1, 3), f(2, 3)),
            bounds: [f(3, 0), f(3, 1), f(3, 2), f(3, 3)],
        }
    }
}

impl EnvironmentRecord {
    /// The record as the probe reads it.
    pub fn to_probe(&self) -> [[u32; 4]; 4] {
        let [c, s] = self.rotation;
        let mut r = [
            [c, s, self.u.0, self.u.1],
            [
                self.row_cdf[0],
                self.row_cdf[1],
                self.column_cdf[0],
                self.column_cdf[1],
            ],
            row(Vec3::from(self.d), 0.0),
            [0.0; 4],
        ]
        .map(|r| r.map(f32::to_bits));
        r[3] = [self.size.0, self.size.1, self.row, self.column];
        r
    }

    /// The record the probe read from `r`.
    pub fn from_probe(r: &[[u32; 4]; 4]) -> Self {
        let f = |i: usize, j: usize| f32::from_bits(r[i][j]);
        Self {
            rotation: [f(0, 0), f(0, 1)],
            u: (f(0, 2), f(0, 3)),
            row_cdf: [f(1, 0), f(1, 1)],
            column_cdf: [f(1, 2), f(1, 3)],
            d: [f(2, 0), f(2, 1), f(2, 2)],
            size: (r[3][0], r[3][1]),
            row: r[3][2],
            column: r[3][3],
        }
    }
}
