//! The Owen-scrambled Sobol sampler (`kernel::sobol`, `sampler = "sobol"`): its building blocks
//! against their definitions, the net property of every power-of-two prefix, uniformity and
//! independence across pixels and dimensions (chi-square), and, on a closed-form scene on both
//! backends, that images stay unbiased while their variance drops.

use glam::Vec3;
use kernel::rng::SampleRng;
use kernel::scene::sampler;
use kernel::sobol::{
    laine_karras, owen_scramble, reverse_bits, sobol_pair, sobol_second_dimension_reversed,
    sobol_single,
};
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{chi_square, plane_exact, plane_under_light, render_film, z_critical};

/// A small splitmix64 for test inputs.
struct Inputs(u64);

impl Inputs {
    fn next(&mut self) -> u32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 32) as u32
    }
}

#[test]
fn bit_reversal_and_second_dimension_match_their_definitions() {
    // Sobol's second dimension from its direction numbers (Joe and Kuo's m_k = 1, 3, 5, 15,
    // 17, 51, ...: v_1 = 1/2, v_k = v_(k-1) xor v_(k-1)/2) and the index's bits, one by one.
    let by_direction_numbers = |mut i: u32| {
        let (mut v, mut x) = (1u32 << 31, 0u32);
        while i != 0 {
            if i & 1 != 0 {
                x ^= v;
            }
            i >>= 1;
            v ^= v >> 1;
        }
        x
    };
    let m = [1u32, 3, 5, 15, 17, 51, 85, 255];
    for (k, &mk) in m.iter().enumerate() {
        assert_eq!(by_direction_numbers(1 << k), mk << (31 - k), "v_{}", k + 1);
    }
    let mut g = Inputs(1);
    for i in (0..1 << 16).chain((0..1_000_000).map(|_| g.next())) {
        assert_eq!(reverse_bits(i), i.reverse_bits());
        assert_eq!(
            reverse_bits(sobol_second_dimension_reversed(i)),
            by_direction_numbers(i),
            "index {i:#x}"
        );
    }
}

#[test]
fn owen_scramble_is_a_nested_bijection() {
    // Two fractions that share their first k digits share the first k digits of their
    // scrambles (each digit depends only on the ones before it), and a digit where they
    // differ first stays different: the scramble is a bijection that maps each aligned
    // interval onto one of the same length.
    let mut g = Inputs(2);
    for _ in 0..200_000 {
        let (x, seed) = (g.next(), g.next());
        let k = g.next() % 32;
        let y = x ^ (1 << (31 - k)) ^ g.next().checked_shr(k + 1).unwrap_or(0);
        let (sx, sy) = (owen_scramble(x, seed), owen_scramble(y, seed));
        let differ = sx ^ sy;
        assert_eq!(
            differ.leading_zeros(),
            k,
            "x {x:#x} y {y:#x} seed {seed:#x}"
        );
        // laine_karras carries upward only: bits below a change are unchanged.
        let lk = laine_karras(x, seed) ^ laine_karras(x ^ (1 << k), seed);
        assert_eq!(lk.trailing_zeros(), k);
    }
}

/// Whether `points` (2^k of them, 32-bit fractions) form a (0,k,2)-net: every elementary box
/// 2^-a by 2^-(k-a) holds exactly one point.
fn is_net(points: &[(u32, u32)], k: u32) -> bool {
    (0..=k).all(|a| {
        let mut seen = vec![false; 1 << k];
        points.iter().all(|&(x, y)| {
            let (bx, by) = (
                if a == 0 { 0 } else { x >> (32 - a) },
                if a == k { 0 } else { y >> (32 - (k - a)) },
            );
            let cell = ((bx << (k - a)) | by) as usize;
            !std::mem::replace(&mut seen[cell], true)
        })
    })
}

#[test]
fn every_power_of_two_prefix_is_a_net() {
    let mut g = Inputs(3);
    for _ in 0..300 {
        let (seed, pixel, dimension) = (g.next(), g.next(), g.next() % 64);
        let points: Vec<(u32, u32)> = (0..1024)
            .map(|s| sobol_pair(seed, pixel, s, dimension))
            .collect();
        for k in 0..=10 {
            assert!(
                is_net(&points[..1 << k], k),
                "seed {seed} pixel {pixel} dimension {dimension}: first 2^{k} points are no net"
            );
            let mut xs: Vec<u32> = (0..1 << k)
                .map(|s| sobol_single(seed, pixel, s, dimension) >> (32 - k).min(31))
                .collect();
            xs.sort();
            if k > 0 {
                assert!(xs.iter().enumerate().all(|(i, &x)| x == i as u32));
            }
        }
        // The 1D sequence is the pair's first coordinate.
        assert_eq!(sobol_single(seed, pixel, 7, dimension), points[7].0);
    }
}

const ALPHA: f64 = 0.01;
const CHI_TESTS: f64 = 3.0;

fn assert_uniform(name: &str, cells: &[f64]) {
    let n: f64 = cells.iter().sum();
    let expected = vec![n / cells.len() as f64; cells.len()];
    let (stat, dof, p) = chi_square(cells, &expected);
    let threshold = 1.0 - (1.0 - ALPHA).powf(1.0 / CHI_TESTS);
    println!("{name}: chi2 = {stat:.1}, dof = {dof}, p = {p:.4}");
    assert!(p > threshold, "{name}: not uniform (p {p:.2e})");
}

#[test]
fn points_are_uniform_across_pixels_and_dimensions_are_independent() {
    // One sample index of 200k pixels: the scrambles make each point uniform in [0,1)^2.
    const BINS: u32 = 16;
    let bin = |x: f32| ((x * BINS as f32) as u32).min(BINS - 1) as usize;
    let mut one_pair = vec![0.0; (BINS * BINS) as usize];
    // Two different dimensions of the same sample: independent scrambles and shuffles.
    let mut across = vec![0.0; (BINS * BINS) as usize];
    // The same dimension and sample of neighbouring pixels: independent scrambles.
    let mut neighbours = vec![0.0; (BINS * BINS) as usize];
    for pixel in 0..200_000u32 {
        let sample = pixel % 37;
        let mut rng = SampleRng::with_sampler(9, pixel, sample, sampler::SOBOL);
        rng.seek(4);
        let (x, y) = rng.next_2d();
        one_pair[bin(x) * BINS as usize + bin(y)] += 1.0;
        rng.seek(10);
        let z = rng.next_f32();
        across[bin(x) * BINS as usize + bin(z)] += 1.0;
        let mut next = SampleRng::with_sampler(9, pixel + 1, sample, sampler::SOBOL);
        next.seek(4);
        neighbours[bin(x) * BINS as usize + bin(next.next_2d().0)] += 1.0;
    }
    assert_uniform("one pair over pixels", &one_pair);
    assert_uniform("dimensions 4 and 10", &across);
    assert_uniform("neighbouring pixels", &neighbours);
}

const KD: f32 = 0.6;
const SEEDS: u32 = 8;

fn plane_scene(sampler: &str, seed: u32) -> SceneFile {
    plane_scene_with(sampler, seed, "")
}

/// The plane scene with extra `[render]` lines.
fn plane_scene_with(sampler: &str, seed: u32, render: &str) -> SceneFile {
    plane_under_light(
        "eye = [0, 9, 9]\nlook_at = [0, 0, -1]\nup = [0, 1, 0]\nvfov = 70\nwidth = 48\nheight = 48",
        &format!("seed = {seed}\nsampler = \"{sampler}\"\n{render}"),
        KD,
        2.0,
        0.5,
        5.0,
    )
}

/// Renders the plane scene with `SEEDS` seeds; per pixel (red channel) the mean over seeds and
/// the variance of that mean from the seeds' spread (valid whatever the sampler: different
/// seeds scramble independently).
fn seed_statistics(sampler: &str, backend: Backend, spp: u32) -> (Vec<f64>, Vec<f64>) {
    spread_over_seeds(
        (0..SEEDS)
            .map(|s| render_film(&plane_scene(sampler, 100 + s), backend, spp).mean())
            .collect(),
    )
}

/// Per pixel (red channel) of images of independent seeds: the mean, and its variance from
/// the seeds' spread.
fn spread_over_seeds(films: Vec<Vec<[f32; 3]>>) -> (Vec<f64>, Vec<f64>) {
    let pixels = films[0].len();
    let k = SEEDS as f64;
    (0..pixels)
        .map(|p| {
            let m = films.iter().map(|f| f[p][0] as f64).sum::<f64>() / k;
            let v = films
                .iter()
                .map(|f| (f[p][0] as f64 - m).powi(2))
                .sum::<f64>()
                / (k - 1.0);
            (m, v / k)
        })
        .unzip()
}

/// All pixels with a closed form together: z of the summed difference from it (a sum of many
/// independent pixel errors is normal, and its variance, summed 7-dof estimates over > 1500
/// pixels, is well known), the same z if the image were 0.5% low (the test's power), and the
/// summed variance.
fn image_z(mean: &[f64], var: &[f64], exact: &[Option<f64>]) -> (f64, f64, f64) {
    let (mut d, mut v, mut e_sum) = (0.0, 0.0, 0.0);
    for (i, e) in exact.iter().enumerate() {
        if let Some(e) = e {
            d += mean[i] - e;
            v += var[i];
            e_sum += e;
        }
    }
    (d / v.sqrt(), (d - 0.005 * e_sum) / v.sqrt(), v)
}

#[test]
fn sobol_images_are_unbiased_and_less_noisy_on_both_backends() {
    let scene = plane_scene("sobol", 0);
    let exact = plane_exact(
        &scene.scene,
        KD,
        &[twinpath_tests::Lamp {
            center: Vec3::new(0.0, 2.0, 0.0),
            radius: 0.5,
            radiance: 5.0,
        }],
    );
    assert!(exact.iter().filter(|e| e.is_some()).count() > 1500);
    let z_max = z_critical(1e-3, 4);
    for backend in [Backend::Cpu, Backend::Gpu] {
        let mut spread = Vec::new();
        for sampler in ["independent", "sobol"] {
            let (mean, var) = seed_statistics(sampler, backend, 64);
            let (z, z_biased, v) = image_z(&mean, &var, &exact);
            println!(
                "{backend:?} {sampler}: image vs closed form z = {z:+.2}; with a 0.5% bias z = {z_biased:+.1}; summed variance of the mean {v:.3e}"
            );
            assert!(z.abs() < z_max, "{backend:?} {sampler}: biased, z = {z:.2}");
            assert!(
                z_biased.abs() > z_max,
                "{backend:?} {sampler}: the test cannot see a 0.5% bias"
            );
            spread.push(v);
        }
        // Stratified points integrate this smooth 4D integrand (pixel area, light cone) far
        // better than independent ones at 64 spp: at least halve the variance.
        let ratio = spread[1] / spread[0];
        println!("{backend:?}: variance sobol / independent = {ratio:.3}");
        assert!(ratio < 0.5, "{backend:?}: Sobol variance ratio {ratio:.3}");
    }
    assert_validation_clean();
}

#[test]
fn adaptive_sampling_with_sobol_points_stays_unbiased_on_both_backends() {
    // The stopping rule reads the pilot samples; with Sobol points, samples of one pixel are
    // stratified jointly, so pilots drawn from the image's own sequence would be dependent on
    // the image samples and stopping on them could bias the image.
    let lamp = twinpath_tests::Lamp {
        center: Vec3::new(0.0, 2.0, 0.0),
        radius: 0.5,
        radiance: 5.0,
    };
    let exact = plane_exact(&plane_scene("sobol", 0).scene, KD, &[lamp]);
    let max_spp = 256;
    for backend in [Backend::Cpu, Backend::Gpu] {
        let mut stopped_early = 0;
        let films = (0..SEEDS)
            .map(|s| {
                let scene = plane_scene_with("sobol", 300 + s, "adaptive_target = 0.003");
                let film = render_film(&scene, backend, max_spp);
                assert_eq!(film.discarded, 0);
                stopped_early += film
                    .samples_per_pixel()
                    .iter()
                    .filter(|&&n| n < max_spp)
                    .count();
                film.mean()
            })
            .collect();
        let pixels = (SEEDS as usize * exact.len()) as f64;
        println!(
            "{backend:?}: {:.1}% of pixel renders stopped early",
            100.0 * stopped_early as f64 / pixels
        );
        assert!(stopped_early as f64 > 0.25 * pixels && (stopped_early as f64) < pixels);
        let (mean, var) = spread_over_seeds(films);
        let (z, z_biased, _) = image_z(&mean, &var, &exact);
        println!("{backend:?}: adaptive Sobol image vs closed form z = {z:+.2} (0.5% bias: {z_biased:+.1})");
        let z_max = z_critical(1e-3, 2);
        assert!(z.abs() < z_max, "{backend:?}: biased, z = {z:.2}");
        assert!(
            z_biased.abs() > z_max,
            "{backend:?}: cannot see a 0.5% bias"
        );
    }
    assert_validation_clean();
}
