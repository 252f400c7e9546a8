//! No sample is lost or trapped: a white furnace reads its background in every pixel, exactly.
//!
//! Every albedo is 1, there is no light, the background is a uniform Lb and roulette reads the
//! throughput. Each BRDF weight is then exactly 1 (`brdf::sampled_brdf_weight`), throughput
//! roulette never ends a path (q = 1), and every path bounces until it leaves the open side of
//! the room and reads Lb. So every *sample* is exactly Lb, and so is every pixel's mean, with
//! zero variance: a single sample that ends early (a depth guard, a pdf cut-off, a path trapped
//! inside a sphere after a leak) shows as a pixel below Lb. Not a statistical test.
//!
//! The loss this guards against happened about once in two million samples: a cosine-sampled
//! direction drawn from u1 = 0 exactly (probability 2^-24 per bounce) is tangent to the
//! surface, its pdf is 0, and a pdf cut-off ended the path. Paths here average about 7.7
//! bounces (measured: that bug lost 46 samples in the CPU test's 10^8), so the CPU test expects
//! 46 losses under it and the GPU test, with 2^24 samples, about 7.7 (it misses all of them with
//! probability e^-7.7 = 5e-4). The GPU test is smaller because lavapipe, the Vulkan device CI
//! has, runs this furnace at 0.1 M samples/s (10^8 would take 17 minutes); the two backends
//! compute the same samples bit for bit (`gpu_render.rs`, `gpu_functions.rs`), and
//! `TWINPATH_FURNACE_GPU_SPP=24576` runs the GPU test at 10^8 samples too.

use twinpath::film::Film;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{render_film, white_furnace};

/// The background radiance: a power of two, so that sums and means of it are exact.
const LB: f32 = 0.5;
/// The image; the CPU test takes WIDTH x HEIGHT x CPU_SPP >= 10^8 samples.
const WIDTH: u32 = 64;
const HEIGHT: u32 = 64;
const CPU_SPP: u32 = 24_576;
/// The GPU test's default samples per pixel (2^24 samples in all).
const GPU_SPP: u32 = 4096;

/// The Cornell room (five quads, two diffuse spheres) with every albedo 1 and the light sphere
/// made a third white sphere; background Lb; throughput roulette.
fn furnace(sampler: &str, seed: u32) -> SceneFile {
    let render = format!("seed = {seed}\nroulette = \"throughput\"\nsampler = \"{sampler}\"");
    let scene = white_furnace(&render, WIDTH, HEIGHT, LB);
    assert!(scene.scene.lights.is_empty());
    assert_eq!(scene.scene.spheres.len(), 3);
    assert_eq!(scene.scene.triangles.len(), 10);
    scene
}

/// Asserts every pixel of `film` holds `spp` samples whose mean is exactly Lb and whose
/// variance is exactly 0 (so every sample was Lb); names the pixels that are not.
fn assert_every_sample_reads_the_background(film: &Film, spp: u32, label: &str) {
    assert_eq!(film.discarded, 0, "{label}: non-finite samples");
    let mean = film.mean();
    let var = film.variance_of_mean();
    let bad: Vec<String> = (0..mean.len())
        .filter(|&i| mean[i] != [LB; 3] || var[i] != [0.0; 3] || film.count[i] != spp)
        .map(|i| {
            format!(
                "pixel ({}, {}): mean {:?}, variance of the mean {:?}, {} samples",
                i as u32 % film.width,
                i as u32 / film.width,
                mean[i],
                var[i],
                film.count[i]
            )
        })
        .collect();
    assert!(
        bad.is_empty(),
        "{label}: {} of {} pixels are not exactly {LB} (a sample was lost):\n{}",
        bad.len(),
        mean.len(),
        bad.join("\n")
    );
}

#[test]
fn white_furnace_loses_no_sample_in_1e8_on_the_cpu() {
    assert!(WIDTH as u64 * HEIGHT as u64 * CPU_SPP as u64 >= 100_000_000);
    let film = render_film(&furnace("sobol", 4), Backend::Cpu, CPU_SPP);
    assert_every_sample_reads_the_background(&film, CPU_SPP, "CPU, Sobol");
}

#[test]
fn white_furnace_loses_no_sample_in_2e24_on_the_gpu() {
    let spp = std::env::var("TWINPATH_FURNACE_GPU_SPP")
        .map(|v| {
            v.parse()
                .expect("TWINPATH_FURNACE_GPU_SPP: samples per pixel")
        })
        .unwrap_or(GPU_SPP);
    let film = render_film(&furnace("independent", 12), Backend::Gpu, spp);
    assert_every_sample_reads_the_background(&film, spp, "GPU, independent");
    assert_validation_clean();
}
