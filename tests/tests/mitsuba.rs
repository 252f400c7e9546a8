//! Agreement with an independent renderer: `scenes/cornell.toml` against Mitsuba 3's converged
//! render of the same scene (../shared/reference/cornell_spheres, 13312 spp). Both estimators
//! are unbiased, so the images must agree within noise: a per-pixel z-test with our per-pixel
//! variance plus the reference's (from its two independent halves).

use twinpath::cpu::CpuRenderer;
use twinpath::film::{diff_images, Film, RgbImage};
use twinpath::scene::Scene;
use twinpath_tests::stats::pixel_z_test;
use twinpath_tests::{repo_root, with_independent_samples, z_critical};

const SPP: u32 = 1024;

#[test]
fn cornell_agrees_with_mitsuba_reference() {
    let reference_dir = repo_root().join("../shared/reference/cornell_spheres");
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

    let scene =
        with_independent_samples(Scene::load(&repo_root().join("scenes/cornell.toml")).unwrap());
    assert_eq!(
        (scene.camera.width, scene.camera.height),
        (reference.width, reference.height)
    );
    let cpu = CpuRenderer::new(&scene);
    let mut film = Film::new(scene.camera.width, scene.camera.height);
    cpu.render_into(&scene.params(0, SPP), 0, SPP, &mut film, None);
    assert_eq!(film.discarded, 0, "non-finite samples");
    let image = RgbImage::from_film(&film);
    let var = film.variance_of_mean();

    // Per channel |z| <= z at alpha = 1e-3 per pixel (3 channels): a correct renderer passes
    // about 99.9% of pixels; the issue asks for at least 99.5%.
    let z_max = z_critical(1e-3, 3);
    let t = pixel_z_test(&image, &var, &reference, Some(&reference_var), z_max);
    let d = diff_images(&image, &reference).unwrap();
    // The mean over the whole image, z-tested with the summed variances.
    let n = (3 * image.pixels.len()) as f64;
    let total_var: f64 = var
        .iter()
        .chain(&reference_var)
        .flatten()
        .map(|&v| v as f64)
        .sum();
    let z_mean = t.mean_signed_diff / (total_var.sqrt() / n);
    println!(
        "cornell {SPP} spp vs Mitsuba: {:.3}% of pixels pass |z| <= {z_max:.2} (max |z| {:.2}); \
         mean signed difference {:+.3e} (z = {z_mean:+.2}); relMSE {:.3e}, RMSE {:.3e}",
        100.0 * t.pass_fraction(),
        t.max_abs_z,
        t.mean_signed_diff,
        d.relmse,
        d.rmse
    );
    assert!(
        t.pass_fraction() >= 0.995,
        "only {:.3}% of pixels pass",
        100.0 * t.pass_fraction()
    );
    assert!(
        z_mean.abs() < z_critical(1e-3, 1),
        "image means differ: z = {z_mean:.2}"
    );
}
