//! Environment maps read by a device that flushes denormals to zero. The sampler
//! (`kernel::environment::sample`) compares uniform numbers with the stored CDFs and divides by
//! their differences; the density MIS asks for (`environment::pdf`) multiplies two such
//! differences. A CDF entry, a difference or a product below 2^-126 would read or compute as 0
//! on such a device: a sample or a density unlike an IEEE device's. The host stores every CDF
//! entry as 0 or at least `CDF_FLOOR` (2^-32), from which every value the two functions compute
//! is 0 or normal (`docs/robustness.md`, "Environment-map tables"); so on a device that is IEEE
//! but for flushing, both give the IEEE result bit for bit. Checked here on maps whose dynamic
//! range (10^-40 to 10^37) puts CDF entries among the denormals without the floor, under
//! [`Vk32`] flushing every denormal input and result on a coin flip: the search, the drawn
//! direction and its density for 2 x 10^5 draws per map (the extreme uniform numbers
//! included), and the density at every texel's centre. Without the floor the density fails
//! (texels whose CDF step is denormal), and the table's own check fails first.

use super::{back, f};
use glam::Vec3;
use kernel::environment::{
    direction_in_texel, map_coordinates, pdf, sample, texel_density, texel_of, DrawnTexel, MapShape,
};
use kernel::real::Real;
use kernel::rng::u32_to_unit_f32;
use kernel::scene::{light_sampling, RenderParams};
use twinpath::scene::environment::EnvironmentMap;
use twinpath_tests::vulkan_arithmetic::{seed, set_model, Model, Vk32};
use twinpath_tests::{scene_from_toml, SplitMix};

/// A device that computes as IEEE-754 does but may flush any denormal input or result to a zero
/// of either sign: the one liberty this file is about (the others are bounded elsewhere:
/// `ball_bounds.rs`'s `environment_apart`).
const FLUSHING: Model = Model {
    flush_denormals: true,
    ..Model::IEEE
};

/// The least non-zero CDF entry the derivation needs (`docs/robustness.md`, "Environment-map
/// tables": every difference then at least 2^-55, every density at least 2^-115); the host's
/// `CDF_FLOOR` must be at least this.
const LEAST_ENTRY: f64 = 1.0 / 4_294_967_296.0;

/// A scene to carry a map into `RenderParams` (its geometry is not used).
const SCENE: &str = r#"
[camera]
eye = [0.0, 1.0, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
width = 4
height = 4
[materials]
grey = { kd = [0.5, 0.5, 0.5] }
[[sphere]]
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "grey"
"#;

fn params_of(map: &EnvironmentMap) -> RenderParams {
    let mut scene = scene_from_toml(SCENE);
    scene.scene.set_environment(Some(map.clone()));
    scene.params(0, 1)
}

/// `map`'s shape as the sampler sees it, its rotation's (cos, sin) read by `real`.
fn shape_of<R>(map: &EnvironmentMap, params: &RenderParams, real: fn(f32) -> R) -> MapShape<R> {
    MapShape {
        rotation: params.environment.rotation.map(real),
        width: map.width,
        height: map.height,
    }
}

/// A grey map (luminance = the value) of `w` x `h` texels of `texel(i, j)`.
fn grey_map(w: u32, h: u32, rotation: f32, texel: impl Fn(u32, u32) -> f32) -> EnvironmentMap {
    let mut m = EnvironmentMap::constant(w, h, [0.0; 3]);
    m.rotation_degrees = rotation;
    for j in 0..h {
        for i in 0..w {
            m.texels[(j * w + i) as usize] = [texel(i, j); 3];
        }
    }
    m
}

/// Maps whose CDFs reach among the denormals without the floor: (1) every row dark but for its
/// last texel (10^37), its first texel 10^-3 to 10^-10 (conditional CDFs' first steps 10^-40
/// to 10^-47), the first row all 10^-6 (the marginal's first step about 10^-44); (2) every
/// texel log-uniform from 10^-38 to 10^37, a tenth of them black, rotated 30 degrees.
fn hostile_maps() -> Vec<(&'static str, EnvironmentMap)> {
    let dark_rows = grey_map(64, 24, 0.0, |i, j| {
        if j == 0 {
            1e-6
        } else if i == 0 {
            1e-3 * 10f32.powi(-((j % 8) as i32))
        } else if i == 63 {
            1e37
        } else {
            0.0
        }
    });
    let mut g = SplitMix(77);
    let values: Vec<f32> = (0..48 * 32)
        .map(|_| {
            if g.unit() < 0.1 {
                0.0
            } else {
                10f32.powf(-38.0 + 75.0 * g.unit())
            }
        })
        .collect();
    let wild = grey_map(48, 32, 30.0, |i, j| values[(j * 48 + i) as usize]);
    vec![
        ("dark rows, one bright column", dark_rows),
        ("log-uniform, 75 decades", wild),
    ]
}

/// The stored CDFs of `map`'s table: the marginal one and each row's conditional one.
fn cdfs(map: &EnvironmentMap, table: &[f32]) -> Vec<Vec<f32>> {
    let (w, h) = (map.width as usize, map.height as usize);
    let layout = map.layout();
    let m = layout.marginal() as usize;
    let mut out = vec![table[m..m + h + 1].to_vec()];
    for j in 0..map.height {
        let c = layout.conditional(j) as usize;
        out.push(table[c..c + w + 1].to_vec());
    }
    out
}

/// The largest k in [0, n) with cdf[k] <= u, compared as the device compares (the entries and u
/// read as [`Vk32`]s, which a flushing device may read as 0 where they are denormal).
fn device_search(cdf: &[f32], u: Vk32) -> u32 {
    let n = cdf.len() - 1;
    (0..n)
        .rev()
        .find(|&k| f(cdf[k]).at_most(u) != 0)
        .unwrap_or(0) as u32
}

/// `environment::pdf`'s density of direction `d`, its arithmetic on [`Vk32`]: the texel's
/// coordinates, the differences of the stored CDF entries around it (`all`, [`cdfs`] of the
/// map's table), [`texel_density`].
fn device_pdf(map: &EnvironmentMap, params: &RenderParams, all: &[Vec<f32>], d: Vec3) -> f32 {
    let (w, h) = (map.width, map.height);
    let rotation = params.environment.rotation.map(f);
    let (u, v, sin_theta) = map_coordinates(rotation, super::v(d));
    if !(sin_theta.value > 0.0) {
        return 0.0;
    }
    let (i, j) = texel_of(w, h, u, v);
    let (row, column) = (&all[0], &all[1 + j as usize]);
    let p_row = f(row[j as usize + 1]) - f(row[j as usize]);
    let p_column = f(column[i as usize + 1]) - f(column[i as usize]);
    texel_density(p_row, p_column, f((w * h) as f32), sin_theta).value
}

#[test]
fn stored_cdfs_are_zero_or_at_least_the_floor() {
    for (name, map) in hostile_maps() {
        let table = map.table();
        for cdf in cdfs(&map, &table) {
            assert_eq!((cdf[0], *cdf.last().unwrap()), (0.0, 1.0), "{name}");
            assert!(cdf.windows(2).all(|p| p[0] <= p[1]), "{name}: a CDF falls");
            for &c in &cdf {
                assert!(
                    c == 0.0 || c as f64 >= LEAST_ENTRY,
                    "{name}: a CDF entry {c:e} below {LEAST_ENTRY:e}"
                );
            }
        }
    }
}

#[test]
fn a_device_that_flushes_denormals_samples_environment_maps_as_ieee_does() {
    seed(35);
    for (name, map) in hostile_maps() {
        let params = params_of(&map);
        let table = map.table();
        let all = cdfs(&map, &table);
        let shape = shape_of(&map, &params, f);
        let mut g = SplitMix(11);
        let mut flushed_reads = 0u32;
        let draws = 200_000;
        for k in 0..draws {
            // The extreme uniform numbers (2^-24 and 1 - 2^-24) first, then random ones.
            let (b1, b2) = match k {
                0 => (0, 0),
                1 => (u32::MAX, u32::MAX),
                2 => (0, u32::MAX),
                _ => (g.u64() as u32, g.u64() as u32),
            };
            let (u1, u2) = (u32_to_unit_f32(b1), u32_to_unit_f32(b2));
            let ieee = sample(&params, &table, light_sampling::SOLID_ANGLE, u1, u2);
            let ieee_pdf = pdf(&params, &table, light_sampling::SOLID_ANGLE, ieee.direction);

            set_model(FLUSHING);
            let row = device_search(&all[0], f(u2));
            let conditional = &all[1 + row as usize];
            let column = device_search(conditional, f(u1));
            flushed_reads += [all[0][row as usize], conditional[column as usize]]
                .iter()
                .filter(|c| c.is_subnormal())
                .count() as u32;
            let drawn = DrawnTexel {
                row,
                row_cdf: [f(all[0][row as usize]), f(all[0][row as usize + 1])],
                u2: f(u2),
                column,
                column_cdf: [
                    f(conditional[column as usize]),
                    f(conditional[column as usize + 1]),
                ],
                u1: f(u1),
            };
            let (direction, density) = direction_in_texel(shape, drawn);
            let device = back(direction);
            assert_eq!(
                (device.to_array().map(f32::to_bits), density.value.to_bits()),
                (
                    ieee.direction.to_array().map(f32::to_bits),
                    ieee.pdf.to_bits()
                ),
                "{name}: u = ({u1:e}, {u2:e}), texel ({column}, {row}): the device drew \
                 {device} with density {:e}, IEEE {} with {:e}",
                density.value,
                ieee.direction,
                ieee.pdf
            );
            let device_density = device_pdf(&map, &params, &all, ieee.direction);
            assert_eq!(
                device_density.to_bits(),
                ieee_pdf.to_bits(),
                "{name}: the density of a drawn direction {}: {device_density:e} on the \
                 device, {ieee_pdf:e} under IEEE",
                ieee.direction
            );
        }
        assert_eq!(
            flushed_reads, 0,
            "{name}: a drawn texel's CDF entry is denormal"
        );
    }
}

#[test]
fn a_device_that_flushes_denormals_gives_every_texel_the_ieee_density() {
    seed(36);
    for (name, map) in hostile_maps() {
        let params = params_of(&map);
        let table = map.table();
        let all = cdfs(&map, &table);
        let shape = shape_of(&map, &params, |x| x);
        let (mut floored, mut least) = (0, f32::INFINITY);
        for j in 0..map.height {
            for i in 0..map.width {
                // The texel's centre: the sampler's direction half way through a bin spanning
                // [0, 1) (its arithmetic, not its probabilities).
                let centre = DrawnTexel {
                    row: j,
                    row_cdf: [0.0, 1.0],
                    u2: 0.5,
                    column: i,
                    column_cdf: [0.0, 1.0],
                    u1: 0.5,
                };
                let d: Vec3 = direction_in_texel(shape, centre).0.into();
                set_model(Model::IEEE);
                let ieee = pdf(&params, &table, light_sampling::SOLID_ANGLE, d);
                assert_eq!(
                    device_pdf(&map, &params, &all, d).to_bits(),
                    ieee.to_bits(),
                    "{name}: the IEEE model does not compute environment::pdf"
                );
                set_model(FLUSHING);
                let device = device_pdf(&map, &params, &all, d);
                assert_eq!(
                    device.to_bits(),
                    ieee.to_bits(),
                    "{name}: texel ({i}, {j}): density {device:e} on the device, {ieee:e} \
                     under IEEE"
                );
                let lit = map.texels[(j * map.width + i) as usize][0] > 0.0;
                floored += (lit && ieee == 0.0) as u32;
                if ieee > 0.0 {
                    least = least.min(ieee);
                }
            }
        }
        // Lit texels whose probability the floor took: the map reaches below it, so the
        // check covers the table's smallest steps.
        println!("{name}: {floored} lit texels of density 0, the least density {least:e}");
        assert!(floored > 0, "{name}: no lit texel below the floor");
    }
}

#[test]
fn the_floor_leaves_the_shipped_skies_unchanged() {
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    for file in ["sky.hdr", "sky_soft.hdr"] {
        let map = EnvironmentMap::load(&scenes.join(file), "map").expect(file);
        // Every texel lit, so every CDF entry after the first is positive unless the floor
        // took it: none may be 0.
        assert!(
            map.texels.iter().all(|t| t.iter().any(|&c| c > 0.0)),
            "{file} has black texels: this check needs none"
        );
        let table = map.table();
        for cdf in cdfs(&map, &table) {
            assert!(
                cdf[1..].iter().all(|&c| c > 0.0),
                "{file}: a CDF entry lost to the floor"
            );
        }
    }
}
