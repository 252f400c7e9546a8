//! Density grids under a Vulkan device's arithmetic: the walk through a grid's cells
//! (`kernel::density_grid::CellWalk`, which delta tracking steps along its majorant cells and
//! the optical depth along the voxel-centre cells) and the trilinear density
//! (`DensityGrid::density_inside_v3`), run on [`Vk32`] as on IEEE `f32`.
//!
//! What delta tracking needs of them (`kernel::delta_tracking`): the walk ends, its pieces
//! follow each other in order inside the grid, and the density at every point a walk places in
//! a majorant cell is at most that cell's majorant. Otherwise a tentative collision would be
//! real with a probability rho / M above 1, which the kernel clamps (`rho.min(majorant)`),
//! silently biasing the medium. A point's cell coordinate carries the rounding of the crossing
//! parameters (a quotient, then one sum per cell stepped) and of `origin + t dir`, so it may lie
//! a little beyond its cell's face; the host's majorants cover one voxel more on every side
//! than the filter reads inside the cell (`twinpath::scene::density_grid::DenseGrid::majorants`),
//! and nothing for the filter's own rounding, which never reads above its largest voxel (the
//! second test). The first test fails without the extra voxel, under IEEE arithmetic already
//! (docs/robustness.md, "Under Vulkan's arithmetic").

use super::{f, use_model, v};
use glam::{UVec3, Vec3};
use kernel::density_grid::{CellPiece, CellWalk, DensityGrid};
use twinpath::scene::density_grid::{DenseGrid, GridTable};
use twinpath_tests::vulkan_arithmetic::{seed, Vk32};
use twinpath_tests::SplitMix;

/// A random grid: 1 to 24 voxels per axis, a box from 10^-3 to 10^3 on a side (each axis
/// within a factor of 10 of the others) centred up to 10^3 sizes away from the origin. Half
/// the grids are noise (densities empty (30%), spikes of 10^3 (5%) or uniform in [0, 1)); the
/// other half are blocks of 1 to 5 voxels a side, each of one density (0, 1/4, 1 or 10^3):
/// flat cells next to denser ones, where a point placed a rounding beyond its cell reads more
/// than the cell holds (in noise, a cell's largest voxel is rarely what a point near its face
/// reads).
fn random_grid(g: &mut SplitMix) -> DenseGrid {
    let resolution = [0; 3].map(|_| 1 + (g.u64() % 24) as u32);
    let size = 10f32.powf(-3.0 + 6.0 * g.unit());
    let sizes = Vec3::new(g.unit(), g.unit(), g.unit()).map(|u| size * 10f32.powf(u));
    let centre = g.direction() * size * 10f32.powf(3.0 * g.unit() - 1.0);
    let [nx, ny, nz] = resolution;
    let voxels = if g.unit() < 0.5 {
        (0..nx * ny * nz)
            .map(|_| match g.unit() {
                u if u < 0.3 => 0.0,
                u if u < 0.35 => 1e3,
                _ => g.unit(),
            })
            .collect()
    } else {
        let block = [0; 3].map(|_| 1 + (g.u64() % 5) as u32);
        let levels: Vec<f32> = (0..125)
            .map(|_| [0.0, 0.25, 1.0, 1e3][(g.u64() % 4) as usize])
            .collect();
        let mut voxels = Vec::new();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let b = [i / block[0], j / block[1], k / block[2]].map(|b| b % 5);
                    voxels.push(levels[(b[0] + 5 * b[1] + 25 * b[2]) as usize]);
                }
            }
        }
        voxels
    };
    DenseGrid {
        min: centre - sizes * 0.5,
        max: centre + sizes * 0.5,
        resolution,
        voxels,
    }
}

/// A random ray for `grid`: from inside its box or from outside it toward a point inside,
/// with one or two direction components zero or tiny in a fifth of the rays each; a unit
/// direction, and an end at the scene's end or somewhere along the box.
fn random_ray(g: &mut SplitMix, grid: &DenseGrid) -> (Vec3, Vec3, f32) {
    let size = grid.max - grid.min;
    let inside = |g: &mut SplitMix| grid.min + size * Vec3::new(g.unit(), g.unit(), g.unit());
    let target = inside(g);
    let origin = if g.unit() < 0.5 {
        inside(g)
    } else {
        target + g.direction() * size.length() * (1.0 + 3.0 * g.unit())
    };
    let mut dir = (target - origin).normalize_or(g.direction());
    match g.u64() % 10 {
        0 => dir[(g.u64() % 3) as usize] = 0.0,
        1 => dir[(g.u64() % 3) as usize] = 1e-7 * dir[(g.u64() % 3) as usize].signum(),
        2 => {
            let keep = (g.u64() % 3) as usize;
            for axis in 0..3 {
                if axis != keep {
                    dir[axis] = 0.0;
                }
            }
        }
        _ => {}
    }
    let dir = dir.normalize_or(Vec3::X);
    let end = if g.unit() < 0.5 {
        f32::MAX
    } else {
        size.length() * 3.0 * g.unit()
    };
    (origin, dir, end)
}

/// The pieces of a walk through `cells` cells per axis of `grid`'s box (shifted by `shift`),
/// under the arithmetic set now; panics where the walk breaks an invariant of `CellWalk`'s
/// documentation (cells outside the grid, a piece that does not start where the last ended or
/// ends before it starts, a step of more than one cell, more pieces than the cells allow).
fn walk(
    grid: &DensityGrid,
    cells: UVec3,
    shift: f32,
    (origin, dir, end): (Vec3, Vec3, f32),
) -> Vec<CellPiece<Vk32>> {
    let mut walk = CellWalk::<Vk32>::new(
        grid.bounds(),
        cells,
        shift,
        (v(origin), v(dir)),
        (f(0.0), f(end)),
    );
    let most = (cells.x + cells.y + cells.z) as usize;
    let mut pieces: Vec<CellPiece<Vk32>> = Vec::new();
    while walk.more() {
        let piece = walk.next_piece();
        assert!(
            pieces.len() < most,
            "a walk of more than {most} pieces through {cells} cells: {origin} {dir} {end}"
        );
        assert!(
            piece.cell.cmplt(cells).all(),
            "cell {} of {cells}",
            piece.cell
        );
        assert!(
            piece.t1.value >= piece.t0.value,
            "piece {piece:?} runs backwards"
        );
        if let Some(last) = pieces.last() {
            assert_eq!(piece.t0.value.to_bits(), last.t1.value.to_bits(), "a gap");
            let step = (piece.cell.as_ivec3() - last.cell.as_ivec3()).abs();
            assert_eq!(
                step.element_sum(),
                1,
                "from cell {} to {}",
                last.cell,
                piece.cell
            );
        }
        pieces.push(piece);
    }
    pieces
}

#[test]
fn grid_walks_keep_their_order_and_majorants_bound_every_density_under_vulkan_arithmetic() {
    let grids = super::cases() / 40;
    let mut g = SplitMix(0x6772_6964);
    let (mut points, mut apart, mut walks) = (0usize, 0usize, 0usize);
    let mut worst = 0.0f64;
    for case in 0..grids {
        let dense = random_grid(&mut g);
        let mut table = GridTable::default();
        let record = table.add(&dense).expect("fits");
        let grid = DensityGrid::at(&table.words, record);
        let majorant_cells = UVec3::from(dense.majorant_resolution());
        let voxel_cells = UVec3::from(dense.resolution) + UVec3::ONE;
        for _ in 0..4 {
            let ray = random_ray(&mut g, &dense);
            let fractions = [g.unit(), g.unit()];
            let mut ieee_ends: Vec<u32> = Vec::new();
            for model in 0..4 {
                use_model(model);
                seed((case * 16 + model) as u64);
                // The optical depth's walk: its invariants only.
                walk(&grid, voxel_cells, 0.5, ray);
                let pieces = walk(&grid, majorant_cells, 0.0, ray);
                walks += 1;
                let ends: Vec<u32> = pieces.iter().map(|p| p.t1.value.to_bits()).collect();
                if model == 0 {
                    ieee_ends = ends;
                } else if ends != ieee_ends {
                    apart += 1;
                }
                let (origin, dir) = (v(ray.0), v(ray.1));
                for piece in &pieces {
                    let majorant = grid.majorant(piece.cell);
                    let (t0, t1) = (piece.t0, piece.t1);
                    let mut at = vec![t0];
                    if t1.value < f32::MAX {
                        // A tentative collision t + left / rate may pass the piece's end by the
                        // rounding of the sum and the quotient: up to 4 ULP of t1.
                        let past = (1..=4).fold(t1.value, |t, _| t.next_up());
                        at.extend([t1, f(past)]);
                    }
                    if t1.value - t0.value < f32::MAX {
                        at.extend(fractions.map(|s| t0 + (t1 - t0) * f(s)));
                    }
                    for t in at {
                        let rho = grid.density_inside_v3(origin + dir * t);
                        points += 1;
                        worst = worst.max(rho.value as f64 / majorant as f64);
                        assert!(
                            rho.value <= majorant,
                            "model {model}: density {} above its cell's majorant {majorant} at \
                             t = {} in cell {} of {majorant_cells} ({} voxels), ray {ray:?}",
                            rho.value,
                            t.value,
                            piece.cell,
                            UVec3::from(dense.resolution),
                        );
                    }
                }
            }
        }
    }
    println!(
        "{walks} walks through {grids} grids, {points} points: densities at most {worst:.6} of \
         their majorants; {apart} of the device models' walks ended a piece elsewhere than IEEE"
    );
    // The models must take their liberties here too, or the test would prove nothing.
    assert!(
        apart > walks / 20,
        "only {apart} of {walks} walks differ from IEEE's"
    );
    assert!(points > 5 * walks, "{points} points in {walks} walks");
}

/// `Vk32`'s `floor` (`Real::floor`'s default, on the integer conversions) is the floor, exact,
/// under every model, at and between integers, for negative numbers too (normal numbers: a
/// device may flush a denormal to zero first).
#[test]
fn floor_is_exact_under_vulkan_arithmetic() {
    let mut g = SplitMix(7);
    for model in 0..4 {
        use_model(model);
        for _ in 0..100_000 {
            // Normal numbers and 0 (a device may flush a denormal input to a zero).
            let x = (g.unit() - 0.5) * 10f32.powf(7.0 * g.unit() - 1.0);
            for x in [x, x.round(), x.round().next_up(), x.round().next_down()] {
                if x != 0.0 && !x.is_normal() {
                    continue;
                }
                let floor = kernel::real::Real::floor(Vk32::new(x)).value;
                assert_eq!(floor, x.floor(), "floor({x}) under model {model}");
            }
        }
    }
}

/// The voxel values of [`the_filter_never_reads_above_its_largest_voxel_under_vulkan_arithmetic`]
/// for one binade: b, b's neighbours, half an ULP of b (b - that is a tie, which rounds up to b
/// where b's last bit is even), smaller values down to a denormal, and 0; in a quarter of the
/// grids all eight are b. A lerp a + (b - a) t rounds above b only if b - a rounds up by half
/// an ULP of b and the sum rounds up again.
fn adversarial_voxels(g: &mut SplitMix) -> [f32; 8] {
    let b = 10f32.powf(12.0 * g.unit() - 6.0);
    let half_ulp = (b.next_up() - b) / 2.0;
    let set = [
        b,
        b.next_up(),
        b.next_down(),
        half_ulp,
        b * g.unit(),
        f32::MIN_POSITIVE * g.unit(),
        0.0,
        b - half_ulp * 3.0,
    ];
    if g.unit() < 0.25 {
        return [b; 8];
    }
    [0; 8].map(|_| set[(g.u64() % set.len() as u64) as usize])
}

/// The eight voxels blended with the trilinear weights (1 - f) or f per axis, summed: a
/// filter the kernel does not use, whose computed weights may sum above 1. It shows that the
/// points of the test below find a filter that reads above its largest voxel.
fn weighted_filter(voxels: [f32; 8], [fx, fy, fz]: [Vk32; 3]) -> Vk32 {
    let one = f(1.0);
    let mut sum = f(0.0);
    for (i, &voxel) in voxels.iter().enumerate() {
        let w = |bit: usize, t: Vk32| if i >> bit & 1 == 1 { t } else { one - t };
        sum = sum + w(0, fx) * w(1, fy) * w(2, fz) * f(voxel);
    }
    sum
}

/// The trilinear filter (`DensityGrid::density_inside_v3`) reads at most its largest voxel and
/// at least 0, under IEEE arithmetic and every device model, so a majorant cell's largest voxel
/// is its majorant with nothing added (docs/robustness.md, "Under Vulkan's arithmetic"). Each
/// of its seven lerps a + (b - a) t, with t in [0, 1] and a, b >= 0, stays within [min(a, b),
/// max(a, b)] when the subtraction, the product and the sum are each correctly rounded, to
/// nearest or toward zero, fused or not (Vulkan's rules), which the derivation there shows; a
/// flushed denormal only lowers a value. Here: 2 x 2 x 2 grids of [`adversarial_voxels`],
/// points between the voxel centres, half of them a few ULP from the far ones. Shown to fail: the same
/// points through [`weighted_filter`] read above the largest voxel (asserted), so a filter
/// written so would need a margin on its majorants.
#[test]
fn the_filter_never_reads_above_its_largest_voxel_under_vulkan_arithmetic() {
    let mut g = SplitMix(0x6c65_7270);
    let (mut points, mut weighted_above) = (0usize, 0usize);
    let mut worst = 0.0f64;
    for case in 0..super::cases() / 5 {
        let voxels = adversarial_voxels(&mut g);
        let dense = DenseGrid {
            min: Vec3::ZERO,
            max: Vec3::splat(2.0),
            resolution: [2, 2, 2],
            voxels: voxels.to_vec(),
        };
        let mut table = GridTable::default();
        let record = table.add(&dense).expect("fits");
        let grid = DensityGrid::at(&table.words, record);
        let largest = voxels.iter().fold(0.0f32, |m, &x| m.max(x));
        // Voxel coordinates in [0, 1): uniform, or a few ULP below 1.
        let fraction = |g: &mut SplitMix| {
            if g.unit() < 0.5 {
                g.unit()
            } else {
                (0..g.u64() % 4).fold(1f32.next_down(), |t, _| t.next_down())
            }
        };
        let t = [0; 3].map(|_| fraction(&mut g));
        for model in 0..4 {
            use_model(model);
            seed((case * 4 + model) as u64);
            // Centres at 0.5 and 1.5: the point 0.5 + t reads coordinate t (to rounding).
            let p = Vec3::from(t.map(|t| 0.5 + t));
            let rho = grid.density_inside_v3(v(p)).value;
            points += 1;
            assert!(
                (0.0..=largest).contains(&rho),
                "model {model}: the filter reads {rho:e} of voxels {voxels:?} (largest \
                 {largest:e}) at coordinates {t:?}"
            );
            if largest > 0.0 {
                worst = worst.max(rho as f64 / largest as f64);
            }
            if weighted_filter(voxels, t.map(f)).value > largest {
                weighted_above += 1;
            }
        }
    }
    println!(
        "{points} points of 2 x 2 x 2 grids: the filter reads at most {worst} of the largest \
         voxel; the weighted filter read above it at {weighted_above}"
    );
    assert!(
        weighted_above > 0,
        "the points find no filter reading above its voxels"
    );
}
