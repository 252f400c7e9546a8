//! Heterogeneous media (density grids: `kernel::density_grid`, `kernel::delta_tracking`,
//! `twinpath::scene::density_grid`): the majorants bound the density, the optical depth and
//! delta tracking's collisions against closed forms (exact, z-tests, chi-square),
//! closed-form renders on both backends, and the `.vol` reader's errors.
//!
//! The closed form: a grid whose voxels hold a + sum over axes of b_axis (i_axis + 1/2) /
//! n_axis, a function linear in each coordinate, which the trilinear filter reproduces exactly
//! between the voxel centres; clamped to the edge it is a + sum b_axis clamp(u_axis, 1 / (2
//! n_axis), 1 - 1 / (2 n_axis)) in the box's unit coordinates u. Along a ray that is piecewise
//! linear in the distance, with breaks where a coordinate passes a clamp and at the box's
//! faces, so its integral (the optical depth per unit extinction) is exact from the midpoints
//! of those pieces.

use glam::{DVec3, Vec3};
use kernel::delta_tracking::{self, TrackingStream};
use kernel::density_grid::{optical_depth, DensityGrid, MajorantWalk};
use kernel::free_flight::hero_channel;
use twinpath::scene::density_grid::{DenseGrid, GridTable};
use twinpath::scene::SceneFile;
use twinpath_tests::{
    assert_backends_agree_with, assert_chi_square_fits, pixel_quadrature, scene_from_toml,
    z_critical,
};

/// The linear ramp a + sum b_axis u_axis of the module's documentation over the box `min` to
/// `max` at resolution `n`.
struct Ramp {
    a: f64,
    b: [f64; 3],
    min: DVec3,
    max: DVec3,
    n: [u32; 3],
}

impl Ramp {
    fn grid(&self) -> DenseGrid {
        let [nx, ny, nz] = self.n;
        let mut voxels = Vec::new();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let u = [
                        (i as f64 + 0.5) / nx as f64,
                        (j as f64 + 0.5) / ny as f64,
                        (k as f64 + 0.5) / nz as f64,
                    ];
                    voxels.push((self.a + (0..3).map(|c| self.b[c] * u[c]).sum::<f64>()) as f32);
                }
            }
        }
        DenseGrid {
            min: self.min.as_vec3(),
            max: self.max.as_vec3(),
            resolution: self.n,
            voxels,
        }
    }

    /// The density at `p`, in f64: 0 outside the box.
    fn density(&self, p: DVec3) -> f64 {
        let u = (p - self.min) / (self.max - self.min);
        if u.min_element() < 0.0 || u.max_element() > 1.0 {
            return 0.0;
        }
        let mut rho = self.a;
        for c in 0..3 {
            let h = 0.5 / self.n[c] as f64;
            rho += self.b[c] * u[c].clamp(h, 1.0 - h);
        }
        rho
    }

    /// The integral of the density along `o + s d` for s in [0, t] (`d` of unit length).
    fn optical_depth(&self, o: DVec3, d: DVec3, t: f64) -> f64 {
        let mut breaks = vec![0.0, t];
        for c in 0..3 {
            if d[c] == 0.0 {
                continue;
            }
            let h = 0.5 / self.n[c] as f64;
            let size = self.max[c] - self.min[c];
            for u in [0.0, h, 1.0 - h, 1.0] {
                let s = (self.min[c] + u * size - o[c]) / d[c];
                if s > 0.0 && s < t {
                    breaks.push(s);
                }
            }
        }
        breaks.sort_by(f64::total_cmp);
        breaks
            .windows(2)
            .map(|w| (w[1] - w[0]) * self.density(o + d * (0.5 * (w[0] + w[1]))))
            .sum()
    }
}

/// A ramp over the box (-1, -0.5, -0.75) to (1, 0.5, 0.75) whose density runs from 0.05 to
/// 2.05 (much less in the corner where every axis is low: null collisions are common there).
fn ramp() -> Ramp {
    Ramp {
        a: 0.05,
        b: [1.2, 0.5, 0.3],
        min: DVec3::new(-1.0, -0.5, -0.75),
        max: DVec3::new(1.0, 0.5, 0.75),
        n: [12, 7, 5],
    }
}

fn table(grid: &DenseGrid) -> (GridTable, u32) {
    let mut table = GridTable::default();
    let record = table.add(grid).expect("fits");
    (table, record)
}

/// Rays through the ramp's box: from outside to beyond it, starting inside it, ending inside
/// it, along an axis, and one missing it.
fn rays() -> Vec<(DVec3, DVec3, f64)> {
    let d = |x: f64, y: f64, z: f64| DVec3::new(x, y, z).normalize();
    vec![
        (DVec3::new(-2.0, -0.3, -0.2), d(1.0, 0.2, 0.15), 4.0),
        (DVec3::new(0.2, 0.1, 0.0), d(-0.3, 0.5, 0.8), 3.0),
        (DVec3::new(-1.5, 0.2, 0.3), d(1.0, -0.1, -0.05), 1.9),
        (DVec3::new(-3.0, 0.0, 0.0), d(1.0, 0.0, 0.0), 6.0),
        (DVec3::new(-3.0, 2.0, 0.0), d(1.0, 0.0, 0.0), 6.0),
    ]
}

/// A stream of uniform numbers in [0, 1) from `seed` (a 64-bit linear congruential generator,
/// Knuth's MMIX constants): the tests' random grids and rays.
fn uniforms(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 33) as f64) / (1u64 << 31) as f64
    }
}

/// A grid of random densities (seeded by `seed`) with empty regions and spikes, over the box
/// (-1, -2, 0.5) to (2, 1, 1.5).
fn random_grid(seed: u64) -> DenseGrid {
    let mut next = uniforms(seed);
    let n = [17u32, 9, 13];
    let voxels: Vec<f32> = (0..n[0] * n[1] * n[2])
        .map(|_| {
            let r = next();
            if r < 0.4 {
                0.0
            } else if r > 0.98 {
                (50.0 * next()) as f32
            } else {
                next() as f32
            }
        })
        .collect();
    DenseGrid {
        min: Vec3::new(-1.0, -2.0, 0.5),
        max: Vec3::new(2.0, 1.0, 1.5),
        resolution: n,
        voxels,
    }
}

/// Every point of every piece of the walk has a density at most its cell's majorant, the
/// pieces tile the part of the ray inside the box, and the majorants are not loose by more
/// than the voxels around the cell allow (a majorant of the grid's maximum everywhere would
/// pass the bound but make every cell as slow as the densest).
#[test]
fn the_majorant_walk_bounds_the_density_and_tiles_the_ray() {
    let grid = random_grid(12345);
    let mut next = uniforms(4242u64);
    let (table, record) = table(&grid);
    let view = DensityGrid::at(&table.words, record);
    let max = grid.voxels.iter().fold(0f32, |a, &b| a.max(b));
    let (mut points, mut below_max) = (0, 0);
    for r in 0..400 {
        let o = Vec3::new(
            (next() * 6.0 - 2.5) as f32,
            (next() * 6.0 - 3.5) as f32,
            (next() * 4.0 - 1.0) as f32,
        );
        let target = Vec3::new(
            (next() * 3.0 - 1.0) as f32,
            (next() * 3.0 - 2.0) as f32,
            (next() + 0.5) as f32,
        );
        let d = (target - o).normalize();
        let end = if r % 3 == 0 { 2.0 } else { f32::MAX };
        let mut walk = MajorantWalk::new(&view, o, d, 0.0, end);
        let mut last: Option<f32> = None;
        while walk.more() {
            let s = walk.next(&view);
            if let Some(t) = last {
                assert_eq!(s.t0, t, "pieces follow each other");
            }
            last = Some(s.t1);
            assert!(s.t1 >= s.t0);
            below_max += (s.majorant < max) as u32;
            for k in 0..=16 {
                let t = s.t0 + (s.t1 - s.t0) * k as f32 / 16.0;
                let rho = view.density(o + d * t);
                points += 1;
                assert!(
                    rho <= s.majorant,
                    "ray {r}: density {rho} above its cell's majorant {} at t = {t}",
                    s.majorant
                );
            }
        }
    }
    println!("{points} points; {below_max} pieces below the grid's maximum");
    assert!(
        points > 10_000,
        "{points} points on the rays inside the box"
    );
    assert!(below_max > 100, "the majorant grid is finer than one bound");
}

/// The optical depth along a ray (`kernel::density_grid::optical_depth`, Simpson's rule on
/// the pieces between voxel-centre planes) is the ramp's exact integral, to f32 rounding, on
/// every ray: inside, through, ending inside, along an axis, missing.
#[test]
fn the_optical_depth_of_a_ramp_is_exact() {
    let ramp = ramp();
    let (table, record) = table(&ramp.grid());
    let view = DensityGrid::at(&table.words, record);
    for (r, &(o, d, end)) in rays().iter().enumerate() {
        let want = ramp.optical_depth(o, d, end);
        let got = optical_depth(&view, o.as_vec3(), d.as_vec3(), end as f32) as f64;
        println!("ray {r}: tau {got:.7} vs {want:.7}");
        assert!(
            (got - want).abs() <= 2e-6 * want.max(1.0),
            "ray {r}: {got} vs {want}"
        );
    }
}

/// On a grid of random densities (no closed form), the optical depth matches a fine midpoint
/// rule of the kernel's own density: Simpson's rule is exact only where each piece holds one
/// cubic, so pieces cut anywhere but at the voxel-centre planes would miss it by the kinks.
#[test]
fn the_optical_depth_of_a_random_grid_matches_a_fine_quadrature() {
    let grid = random_grid(777);
    let (table, record) = table(&grid);
    let view = DensityGrid::at(&table.words, record);
    let mut next = uniforms(99u64);
    for r in 0..12 {
        let o = Vec3::new(-2.0, (next() * 3.0 - 2.0) as f32, (next() + 0.5) as f32);
        let target = Vec3::new(3.0, (next() * 3.0 - 2.0) as f32, (next() + 0.5) as f32);
        let d = (target - o).normalize();
        let end = (target - o).length() * if r % 2 == 0 { 1.0 } else { 0.6 };
        let got = optical_depth(&view, o, d, end) as f64;
        let pieces = 400_000;
        let h = end as f64 / pieces as f64;
        let want: f64 = (0..pieces)
            .map(|k| {
                let t = (k as f64 + 0.5) * h;
                h * view.density(o + d * t as f32) as f64
            })
            .sum();
        println!("ray {r}: tau {got:.6} vs {want:.6}");
        assert!(
            (got - want).abs() <= 2e-5 * want.max(1.0),
            "ray {r}: {got} vs {want}"
        );
    }
}

/// Delta tracking (`kernel::delta_tracking::flight`) in a grey medium: the first real collision
/// has density sigma rho(t) exp(-sigma tau(t)) and the flight passes the end with probability
/// exp(-sigma tau(end)) (chi-square over 40 distance bins and the pass); the weight is
/// sigma_s / sigma_t at a collision and 1 at the pass, exactly.
#[test]
fn delta_tracking_collides_where_the_density_says_in_a_grey_ramp() {
    let ramp = ramp();
    let (table, record) = table(&ramp.grid());
    let view = DensityGrid::at(&table.words, record);
    let (sigma, albedo) = (1.3f32, 0.7f32);
    let (sigma_t, sigma_s) = (Vec3::splat(sigma), Vec3::splat(sigma * albedo));
    const N: u32 = 400_000;
    const BINS: usize = 40;
    for (r, &(o, d, end)) in rays().iter().enumerate().take(3) {
        let mut observed = vec![0.0; BINS + 1];
        for i in 0..N {
            let mut stream = TrackingStream::new(0x51ed_270b ^ r as u32, i);
            let hero = hero_channel((i % 3) as f32 / 3.0 + 0.1);
            let ray = (o.as_vec3(), d.as_vec3(), end as f32);
            let f = delta_tracking::flight(
                (sigma_t, sigma_s),
                &view,
                ray,
                hero,
                &mut stream,
                Vec3::ONE,
            );
            let want = if f.scattered { albedo } else { 1.0 };
            assert!(
                (f.weight - Vec3::splat(want)).abs().max_element() < 1e-5,
                "ray {r}: weight {} where {want}",
                f.weight
            );
            let b = if f.scattered {
                ((f.t as f64 / end * BINS as f64) as usize).min(BINS - 1)
            } else {
                BINS
            };
            observed[b] += 1.0;
        }
        let survive = |t: f64| (-(sigma as f64) * ramp.optical_depth(o, d, t)).exp();
        let mut expected: Vec<f64> = (0..BINS)
            .map(|b| {
                let (t0, t1) = (
                    b as f64 / BINS as f64 * end,
                    (b + 1) as f64 / BINS as f64 * end,
                );
                N as f64 * (survive(t0) - survive(t1))
            })
            .collect();
        expected.push(N as f64 * survive(end));
        assert_chi_square_fits(
            &format!("delta tracking ray {r}"),
            &observed,
            &expected,
            0.01,
            4.0,
        );
    }
}

/// Delta tracking in a chromatic medium, each channel drawn by the path's hero channel and
/// weighed by the balance heuristic over the three (`kernel::delta_tracking`): for every
/// channel c, the mean weight of flights that collide in a stretch of the ray is the integral
/// over it of sigma_s,c rho exp(-sigma_t,c tau), and that of flights that pass is
/// exp(-sigma_t,c tau(end)) (z-tests, family-wise 1e-3). Drawing with one channel's
/// extinction and weighing as if it were the path's own would fail these in the others.
#[test]
fn delta_tracking_weighs_each_channel_by_its_own_extinction() {
    let ramp = ramp();
    let (table, record) = table(&ramp.grid());
    let view = DensityGrid::at(&table.words, record);
    let sigma_t = Vec3::new(0.3, 1.1, 2.6);
    let sigma_s = Vec3::new(0.25, 0.6, 2.0);
    const N: u32 = 300_000;
    const STRETCHES: usize = 4;
    let (o, d, end) = rays()[0];
    let mut sums = [DVec3::ZERO; STRETCHES + 1];
    let mut squares = [DVec3::ZERO; STRETCHES + 1];
    for i in 0..N {
        let mut stream = TrackingStream::new(0x2c1b_3c6d, i);
        let hero = hero_channel(stream.next_f32());
        let ray = (o.as_vec3(), d.as_vec3(), end as f32);
        let f =
            delta_tracking::flight((sigma_t, sigma_s), &view, ray, hero, &mut stream, Vec3::ONE);
        let b = if f.scattered {
            ((f.t as f64 / end * STRETCHES as f64) as usize).min(STRETCHES - 1)
        } else {
            STRETCHES
        };
        let w = f.weight.as_dvec3();
        sums[b] += w;
        squares[b] += w * w;
    }
    // The exact expectations, by the midpoint rule on a fine subdivision of each stretch (the
    // integrand is smooth between the ramp's breaks; 4000 pieces put its error far below the
    // estimate's).
    let z_max = z_critical(1e-3, 3 * (STRETCHES + 1));
    for b in 0..=STRETCHES {
        for c in 0..3 {
            let (st, ss) = (sigma_t[c] as f64, sigma_s[c] as f64);
            let want = if b == STRETCHES {
                (-st * ramp.optical_depth(o, d, end)).exp()
            } else {
                let (t0, t1) = (
                    b as f64 / STRETCHES as f64 * end,
                    (b + 1) as f64 / STRETCHES as f64 * end,
                );
                let pieces = 4000;
                let h = (t1 - t0) / pieces as f64;
                (0..pieces)
                    .map(|k| {
                        let t = t0 + (k as f64 + 0.5) * h;
                        h * ss * ramp.density(o + d * t) * (-st * ramp.optical_depth(o, d, t)).exp()
                    })
                    .sum()
            };
            let mean = sums[b][c] / N as f64;
            let var = (squares[b][c] / N as f64 - mean * mean) / N as f64;
            if var == 0.0 {
                // A stretch before the box: no collision there, and none expected.
                assert!(mean == 0.0 && want == 0.0, "stretch {b}: {mean} vs {want}");
                continue;
            }
            let z = (mean - want) / var.sqrt();
            println!("stretch {b} channel {c}: {mean:.5} vs {want:.5} (z = {z:+.2})");
            assert!(
                z.abs() < z_max,
                "stretch {b} channel {c}: {mean:.5} vs {want:.5}, z = {z:.2}"
            );
        }
    }
}

/// The `.vol` reader: a grid written and read back is the same grid; a file of the wrong kind
/// is refused with what is wrong and where.
#[test]
fn vol_files_round_trip_and_bad_ones_say_where() {
    let grid = ramp().grid();
    let bytes = grid.to_vol();
    assert_eq!(DenseGrid::parse_vol(&bytes, 1.0).unwrap(), grid);
    let doubled = DenseGrid::parse_vol(&bytes, 2.0).unwrap();
    assert_eq!(doubled.voxels[7], 2.0 * grid.voxels[7]);
    let refused = |mutate: &dyn Fn(&mut Vec<u8>), needle: &str| {
        let mut b = bytes.clone();
        mutate(&mut b);
        let e = DenseGrid::parse_vol(&b, 1.0).unwrap_err();
        assert!(e.contains(needle), "{e:?} should mention {needle:?}");
    };
    refused(&|b| b[0] = b'X', "VOL");
    refused(&|b| b[3] = 2, "version 2");
    refused(&|b| b[4] = 2, "encoding 2");
    refused(&|b| b[20] = 3, "3 channels");
    refused(&|b| b.truncate(b.len() - 4), "bytes, where");
    refused(
        &|b| b[36..40].copy_from_slice(&(-5.0f32).to_le_bytes()),
        "box",
    );
    refused(
        &|b| b[48 + 4 * 5..48 + 4 * 6].copy_from_slice(&(-1.0f32).to_le_bytes()),
        "voxel (5, 0, 0)",
    );
    refused(
        &|b| b[48..52].copy_from_slice(&f32::NAN.to_le_bytes()),
        "voxel (0, 0, 0)",
    );
}

/// An OpenVDB file as Blender's OpenVDB library writes it (tests/fixtures/grid_ramp.vdb, made by
/// scripts/vdb_fixture.py: voxels 0.1 + 0.01 i + 0.02 j + 0.03 k over a small index box, an 8^3
/// tile of 0.5, voxel size 0.1, translation (0.3, -0.2, 0.5)) is read as that density: each
/// voxel's value at its centre's world position, the tile's 512 voxels, 0 where no voxel is
/// active, and the dense box one background voxel wider than the active ones on every side.
#[test]
fn openvdb_files_are_read_with_their_transform_and_tiles() {
    let path = twinpath_tests::repo_root().join("tests/fixtures/grid_ramp.vdb");
    let grid = DenseGrid::read(&path, 2.0).expect("reads");
    // Active indices: x -2..=15 (the ramp from -2, the tile to 15), y 0..=7, z 0..=7; plus one
    // on every side.
    assert_eq!(grid.resolution, [20, 10, 10]);
    let centre = |i: i32, j: i32, k: i32| {
        Vec3::new(
            0.1 * i as f32 + 0.3,
            0.1 * j as f32 - 0.2,
            0.1 * k as f32 + 0.5,
        )
    };
    let corner = centre(-3, -1, -1) - Vec3::splat(0.05);
    assert!(
        (grid.min - corner).abs().max_element() < 1e-6,
        "{} vs {corner}",
        grid.min
    );
    let (table, record) = table(&grid);
    let view = DensityGrid::at(&table.words, record);
    for i in -2..4 {
        for j in 1..6 {
            for k in 3..7 {
                let want = 2.0 * (0.1 + 0.01 * i as f32 + 0.02 * j as f32 + 0.03 * k as f32);
                let got = view.density(centre(i, j, k));
                assert!(
                    (got - want).abs() < 1e-5,
                    "voxel ({i}, {j}, {k}): {got} vs {want}"
                );
            }
        }
    }
    for (i, j, k) in [(8, 0, 0), (15, 7, 7), (11, 4, 2)] {
        assert!(
            (view.density(centre(i, j, k)) - 1.0).abs() < 1e-6,
            "tile voxel ({i}, {j}, {k})"
        );
    }
    for (i, j, k) in [(5, 3, 4), (-2, 0, 3), (0, 3, 0), (16, 2, 2)] {
        assert_eq!(
            view.density(centre(i, j, k)),
            0.0,
            "inactive voxel ({i}, {j}, {k})"
        );
    }
    // Not OpenVDB, and an OpenVDB file without a density grid's name, say so.
    let e = DenseGrid::parse_vdb(b"not a vdb file at all", 1.0).unwrap_err();
    assert!(e.contains("not an OpenVDB file"), "{e}");
    let e = DenseGrid::read(std::path::Path::new("smoke.nvdb"), 1.0).unwrap_err();
    assert!(e.contains(".vol") && e.contains(".vdb"), "{e}");
}

/// Writes the ramp's grid to a file of this test binary's own and returns its path.
fn ramp_file(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("twinpath-grids-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, ramp().grid().to_vol()).unwrap();
    path
}

const SIZE: u32 = 20;
const L: f64 = 0.8;

/// A scene filled with a grid medium (`medium`, the `[media]` entry's coefficients) seen in a
/// uniform environment of radiance L; no lights, no surfaces.
fn fog_scene(grid: &std::path::Path, medium: &str) -> SceneFile {
    scene_from_toml(&format!(
        r#"
[camera]
eye = [-0.6, 0.9, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 45.0
width = {SIZE}
height = {SIZE}

[render]
seed = 21
roulette = "throughput"
rr_start_depth = 1
sampler = "independent"

[media]
smoke = {{ grid = {grid:?}, {medium} }}

[scene]
medium = "smoke"

[background]
radiance = [{L}, {L}, {L}]
"#
    ))
}

/// A camera in an absorbing grid medium (the scene's) sees the environment through it:
/// L exp(-sigma_a tau) along each ray, tau the ramp's exact optical depth (16 x 16 quadrature
/// per pixel), on both backends. A grid read with the wrong orientation, the wrong voxel
/// centres or without its clamp to the edge changes tau by far more than the test resolves.
#[test]
fn a_camera_in_an_absorbing_grid_sees_exp_of_minus_the_optical_depth() {
    let sigma_a = [0.5, 1.2, 2.4];
    let path = ramp_file("absorbing.vol");
    let medium = format!("sigma_a = {sigma_a:?}");
    let file = fog_scene(&path, &medium);
    let ramp = ramp();
    let channel = |c: usize| {
        pixel_quadrature(&file.scene, 16, |e, d| {
            let tau = ramp.optical_depth(e.as_dvec3(), d.as_dvec3().normalize(), 100.0);
            Some(L * (-sigma_a[c] * tau).exp())
        })
    };
    let (r, g, b) = (channel(0), channel(1), channel(2));
    // The share of each pixel's rays that cross the box: pixels on its silhouette mix rare
    // crossings into L and are left out (as in `media.rs`).
    let crossing = pixel_quadrature(&file.scene, 16, |e, d| {
        let tau = ramp.optical_depth(e.as_dvec3(), d.as_dvec3().normalize(), 100.0);
        Some(if tau > 0.0 { 1.0 } else { 0.0 })
    });
    let exact: Vec<Option<[f64; 3]>> = (0..r.len())
        .map(|i| {
            let share = crossing[i].unwrap();
            (share == 0.0 || share == 1.0).then(|| [r[i].unwrap(), g[i].unwrap(), b[i].unwrap()])
        })
        .collect();
    let tested = exact.iter().flatten().filter(|p| p[0] < L).count();
    assert!(tested > 150, "{tested} pixels see the grid whole");
    let darkest = exact
        .iter()
        .flatten()
        .map(|p| p[2])
        .fold(f64::MAX, f64::min);
    assert!(darkest < 0.2 * L, "the grid absorbs visibly ({darkest})");
    assert_backends_agree_with(&file, &exact, 64);
}

/// A white furnace in a grid medium that only scatters (albedo 1, chromatic, forward
/// Henyey-Greenstein): every path ends in the environment with all its energy, so each pixel
/// is L exactly in expectation, whatever the density; on both backends. This exercises delta
/// tracking's null and real collisions, next-event estimation through the grid by ratio
/// tracking, and their MIS against phase sampling: a lost or doubled share of any fails it.
#[test]
fn a_grid_medium_that_only_scatters_is_invisible_in_a_uniform_environment() {
    let path = ramp_file("scattering.vol");
    let file = fog_scene(&path, "sigma_s = [1.0, 2.0, 3.0], g = 0.5");
    let exact = vec![Some([L; 3]); (SIZE * SIZE) as usize];
    assert_backends_agree_with(&file, &exact, 64);
}

/// A grid file is one of the scene's inputs (`twinpath::scene::inputs`), whichever its format:
/// part files record it, so that parts rendered from different grids do not merge.
#[test]
fn grid_files_are_recorded_as_the_scenes_inputs() {
    for name in ["inputs.vol", "inputs.vdb"] {
        let grid = if name.ends_with(".vol") {
            ramp_file(name)
        } else {
            twinpath_tests::repo_root().join("tests/fixtures/grid_ramp.vdb")
        };
        // Beside the temporary grids, never in the repository.
        let scene_path = ramp_file("inputs.vol").with_file_name(format!("{name}.toml"));
        std::fs::write(
            &scene_path,
            format!(
                "[camera]\neye = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
                 vfov = 40.0\nwidth = 4\nheight = 4\n\n[media]\nsmoke = {{ grid = {grid:?}, \
                 sigma_a = [1.0, 1.0, 1.0] }}\n\n[scene]\nmedium = \"smoke\"\n"
            ),
        )
        .unwrap();
        let file = SceneFile::load(&scene_path).expect("loads");
        let read: Vec<_> = file.scene.inputs.iter().map(|f| f.path.clone()).collect();
        assert!(
            read.contains(&grid),
            "{name}: inputs {read:?} lack {grid:?}"
        );
    }
}
