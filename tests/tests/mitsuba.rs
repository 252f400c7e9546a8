//! Agreement with an independent renderer: `scenes/cornell.toml` against Mitsuba 3's converged
//! render of the same scene (tests/reference/cornell_spheres, 13312 spp), and
//! `scenes/cornell_materials.toml` (a rough gold and a glass sphere) against Mitsuba's
//! `roughconductor` and `dielectric` (tests/reference/cornell_materials, 8192 spp, rendered by
//! `scripts/mitsuba_reference.sh cornell_materials`), and `scenes/cornell_fog.toml` (that scene
//! in a scattering fog, the glass holding an absorbing juice) against Mitsuba's `volpathmis`
//! (tests/reference/cornell_fog, 4096 spp), and `scenes/cornell_smoke.toml` (a density grid)
//! against its `volpath` (tests/reference/cornell_smoke, 4096 spp). Both estimators are
//! unbiased, so the
//! images must agree within noise: a per-pixel z-test with our per-pixel variance plus the
//! reference's (from its two independent halves).

use statrs::distribution::{ContinuousCDF, StudentsT};
use twinpath::cpu::CpuRenderer;
use twinpath::film::{diff_images, Film, RgbImage};
use twinpath::scene::SceneFile;
use twinpath_tests::stats::{pixel_z_test, variance_of_channel_mean};
use twinpath_tests::{repo_root, with_independent_samples, z_critical};

const SPP: u32 = 1024;
const BATCHES: u32 = 16;

#[test]
fn cornell_agrees_with_mitsuba_reference() {
    agrees_with_mitsuba(
        "scenes/cornell.toml",
        &repo_root().join("tests/reference/cornell_spheres"),
        SPP,
        1,
    );
}

#[test]
fn cornell_with_gold_and_glass_agrees_with_mitsuba_reference() {
    agrees_with_mitsuba(
        "scenes/cornell_materials.toml",
        &repo_root().join("tests/reference/cornell_materials"),
        SPP,
        1,
    );
}

/// Participating media against Mitsuba 3's `volpathmis` (its spectral-MIS volumetric path
/// tracer): a fog that scatters (chromatic sigma_a and sigma_s, Henyey-Greenstein g = 0.5)
/// fills the world, the camera included, and the glass sphere holds an absorbing juice: free
/// flights, phase sampling, next-event estimation from medium vertices and through the fog, the
/// media changing at the glass. Compared by 2 x 2 blocks of pixels: light that reaches the fog
/// through the glass (a volumetric caustic, found by phase sampling alone, in both renderers)
/// makes each pixel's estimate heavy-tailed, usually low and rarely far high, so that at 1024
/// spp a pixel's own variance understates its error (measured: 99.24% of pixels pass, every
/// failure below the reference, while the image means agree at t = +1.66); four pixels' samples
/// together are near enough to normal.
#[test]
fn cornell_in_fog_agrees_with_mitsuba_volpathmis_reference() {
    agrees_with_mitsuba(
        "scenes/cornell_fog.toml",
        &repo_root().join("tests/reference/cornell_fog"),
        SPP,
        2,
    );
}

/// A heterogeneous medium against Mitsuba 3: the Cornell room filled with a puff of smoke, a
/// 32^3 density grid (scenes/smoke.vol; Mitsuba's `gridvolume` reads the same file and its box,
/// trilinear, clamped) times sigma_t 3.2 in every channel with a coloured albedo (0.8125,
/// 0.875, 0.9375; Henyey-Greenstein g = 0.4): delta tracking against the majorant grid, null
/// and real collisions, next-event estimation through the smoke with its exact optical depth.
/// The reference is Mitsuba's plain `volpath` (tests/reference/cornell_smoke, 4096 spp): its
/// `volpathmis` reads 1.2% low in a closed furnace with fog where `volpath` and twinpath read
/// the closed form (docs/media.md), and `volpath` is unbiased where sigma_t is grey.
#[test]
fn cornell_in_smoke_agrees_with_mitsuba_volpath_reference() {
    agrees_with_mitsuba(
        "scenes/cornell_smoke.toml",
        &repo_root().join("tests/reference/cornell_smoke"),
        SPP,
        1,
    );
}

/// The means of `block` x `block` pixels of `image` (its size a multiple of `block`) and the
/// variances of those means from the pixels' variances `var` (the pixels independent).
fn blocks(image: &RgbImage, var: &[[f32; 3]], block: u32) -> (RgbImage, Vec<[f32; 3]>) {
    let (w, h) = (image.width / block, image.height / block);
    let n = (block * block) as f32;
    let mut pixels = vec![[0f32; 3]; (w * h) as usize];
    let mut vars = vec![[0f32; 3]; (w * h) as usize];
    for y in 0..image.height {
        for x in 0..image.width {
            let (i, k) = (
                (y * image.width + x) as usize,
                ((y / block) * w + x / block) as usize,
            );
            for c in 0..3 {
                pixels[k][c] += image.pixels[i][c] / n;
                vars[k][c] += var[i][c] / (n * n);
            }
        }
    }
    let image = RgbImage {
        width: w,
        height: h,
        pixels,
    };
    (image, vars)
}

/// Renders `scene` (relative to the repository) at `spp` and compares it with the Mitsuba
/// reference in `reference_dir` (mitsuba_ref.exr and its halves), pixel by pixel or by blocks
/// of `block` x `block` pixels.
fn agrees_with_mitsuba(scene_file: &str, reference_dir: &std::path::Path, spp: u32, block: u32) {
    let reference = RgbImage::read(&reference_dir.join("mitsuba_ref.exr")).unwrap();
    let half_a = RgbImage::read(&reference_dir.join("mitsuba_ref_half_a.exr")).unwrap();
    let half_b = RgbImage::read(&reference_dir.join("mitsuba_ref_half_b.exr")).unwrap();
    // Variance of the full reference (mean of the halves) per pixel: (a - b)^2 / 4.
    let reference_var: Vec<[f32; 3]> = half_a
        .pixels
        .iter()
        .zip(&half_b.pixels)
        .map(|(a, b)| std::array::from_fn(|c| (a[c] - b[c]) * (a[c] - b[c]) / 4.0))
        .collect();

    let scene = with_independent_samples(SceneFile::load(&repo_root().join(scene_file)).unwrap());
    assert_eq!(
        (scene.scene.camera.width, scene.scene.camera.height),
        (reference.width, reference.height)
    );
    // BATCHES independent renders of SPP / BATCHES samples (consecutive sample ranges of the
    // independent sampler): their mean is the image, and the spread of their image means is the
    // image mean's error (batch means). A render's own per-pixel variances understate the
    // heavy tails of caustics (light through the glass sphere, found only by BSDF sampling):
    // summed, they made a correct image's mean read z = +3.6.
    let cpu = CpuRenderer::new(&scene.scene, &scene.settings);
    let per = spp / BATCHES;
    let films: Vec<Film> = (0..BATCHES)
        .map(|k| {
            let mut film = Film::new(scene.scene.camera.width, scene.scene.camera.height);
            cpu.render_into(&scene.params(k * per, per), k * per, per, &mut film, None);
            assert_eq!(film.discarded, 0, "non-finite samples");
            film
        })
        .collect();
    let b = BATCHES as f32;
    let means: Vec<Vec<[f32; 3]>> = films.iter().map(Film::mean).collect();
    let vars: Vec<Vec<[f32; 3]>> = films.iter().map(Film::variance_of_mean).collect();
    let image = RgbImage {
        width: scene.scene.camera.width,
        height: scene.scene.camera.height,
        pixels: (0..reference.pixels.len())
            .map(|i| std::array::from_fn(|c| means.iter().map(|m| m[i][c]).sum::<f32>() / b))
            .collect(),
    };
    let var: Vec<[f32; 3]> = (0..reference.pixels.len())
        .map(|i| std::array::from_fn(|c| vars.iter().map(|v| v[i][c]).sum::<f32>() / (b * b)))
        .collect();

    // Per channel |z| <= z at alpha = 1e-3 per pixel (3 channels): a correct renderer passes
    // about 99.9% of pixels; the issue asks for at least 99.5%.
    let z_max = z_critical(1e-3, 3);
    let (test_image, test_var) = blocks(&image, &var, block);
    let (test_reference, test_reference_var) = blocks(&reference, &reference_var, block);
    let t = pixel_z_test(
        &test_image,
        &test_var,
        &test_reference,
        Some(&test_reference_var),
        z_max,
    );
    let d = diff_images(&image, &reference).unwrap();
    // The image means: ours from the spread of the batches' (t with BATCHES - 1 degrees of
    // freedom), the reference's from its halves pixel by pixel, a pixel's channels taken as
    // possibly fully correlated (`variance_of_channel_mean`).
    let n = (3 * image.pixels.len()) as f64;
    let batch_means: Vec<f64> = means
        .iter()
        .map(|m| m.iter().flatten().map(|&x| x as f64).sum::<f64>() / n)
        .collect();
    let k = BATCHES as f64;
    let ours = batch_means.iter().sum::<f64>() / k;
    let ours_var = batch_means
        .iter()
        .map(|m| (m - ours) * (m - ours))
        .sum::<f64>()
        / (k - 1.0)
        / k;
    let reference_mean = reference
        .pixels
        .iter()
        .flatten()
        .map(|&x| x as f64)
        .sum::<f64>()
        / n;
    let reference_mean_var = variance_of_channel_mean(&reference_var);
    let z_mean = (ours - reference_mean) / (ours_var + reference_mean_var).sqrt();
    let t_max = StudentsT::new(0.0, 1.0, k - 1.0)
        .unwrap()
        .inverse_cdf(1.0 - 1e-3 / 2.0);
    println!(
        "{scene_file} {spp} spp vs Mitsuba: {:.3}% of {block} x {block} blocks pass |z| <= {z_max:.2} (max |z| {:.2}); \
         mean signed difference {:+.3e} (t = {z_mean:+.2}, bound {t_max:.2}); relMSE {:.3e}, RMSE {:.3e}",
        100.0 * t.pass_fraction(),
        t.max_abs_z,
        t.mean_signed_diff,
        d.relmse,
        d.rmse
    );
    assert!(
        t.pass_fraction() >= 0.995,
        "only {:.3}% of blocks pass",
        100.0 * t.pass_fraction()
    );
    assert!(z_mean.abs() < t_max, "image means differ: z = {z_mean:.2}");
}
