//! The bench harness: a sweep's rows, its CSV and its plot, and that error falls with spp.

use twinpath::bench::{run_bench, write_csv, write_plot, BenchConfig, Variant};
use twinpath::film::{diff_images, RgbImage};
use twinpath::render::{render, Backend, RenderOptions};
use twinpath::scene::SceneFile;

#[test]
fn bench_sweeps_writes_csv_and_plot() {
    let mut scene = SceneFile::builtin_default();
    scene.scene.camera.width = 32;
    scene.scene.camera.height = 32;
    // A reference for the test: 256 spp of the same small scene.
    let mut r = scene.clone();
    r.settings.spp = 256;
    r.settings.seed = 999;
    let reference = RgbImage::from_film(
        &render(
            &r.scene,
            &r.settings,
            &RenderOptions {
                backend: Backend::Cpu,
                ..Default::default()
            },
        )
        .unwrap()
        .film,
    );
    let variants = vec![
        Variant::parse("seed:mis=half,light_sampling=area", &scene.settings).unwrap(),
        Variant::parse("default", &scene.settings).unwrap(),
    ];
    assert!(Variant::parse("x:mis=sometimes", &scene.settings).is_err());
    assert!(Variant::parse("x:rr=1.5", &scene.settings).is_err());
    let cfg = BenchConfig {
        variants,
        backends: vec![Backend::Cpu],
        max_spp: 8,
        max_seconds: 1e9,
        seeds: 2,
    };
    let rows = run_bench(&scene.scene, &reference, &cfg, |_| {}).unwrap();
    // 2 variants x spp 1, 2, 4, 8 x 2 seeds.
    assert_eq!(rows.len(), 2 * 4 * 2);
    for row in &rows {
        assert!(row.relmse > 0.0 && row.render_s > 0.0);
        assert!((row.efficiency * row.relmse * row.render_s - 1.0).abs() < 1e-9);
    }
    // The error is the one `twinpath diff` reports, for the same render.
    let first = &rows[0];
    let mut s = scene.clone();
    s.settings = cfg.variants[0].settings;
    s.settings.spp = first.spp;
    s.settings.seed = first.seed;
    let again = render(
        &s.scene,
        &s.settings,
        &RenderOptions {
            backend: Backend::Cpu,
            ..Default::default()
        },
    )
    .unwrap();
    let d = diff_images(&RgbImage::from_film(&again.film), &reference).unwrap();
    assert_eq!(d.relmse, first.relmse);
    // Error falls with samples: each variant's mean relMSE at 8 spp is below its 1 spp one.
    for v in ["seed", "default"] {
        let mean_at = |spp| {
            let r: Vec<f64> = rows
                .iter()
                .filter(|r| r.variant == v && r.spp == spp)
                .map(|r| r.relmse)
                .collect();
            r.iter().sum::<f64>() / r.len() as f64
        };
        assert!(
            mean_at(8) < mean_at(1),
            "{v}: {} vs {}",
            mean_at(8),
            mean_at(1)
        );
    }
    let dir = std::env::temp_dir().join(format!("twinpath-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    write_csv(&rows, &dir.join("bench.csv")).unwrap();
    let csv = std::fs::read_to_string(dir.join("bench.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + rows.len());
    assert!(csv.starts_with("variant,backend,spp,seed,setup_s,render_s,relmse,rmse,efficiency\n"));
    assert!(write_plot(&rows, "test", &dir.join("bench.png")).unwrap());
    let png = image::open(dir.join("bench.png")).unwrap();
    assert_eq!((png.width(), png.height()), (900, 600));
    // Rows whose renders equal the reference (relMSE 0) have no place on a log scale: no plot,
    // and no error.
    let exact: Vec<_> = rows
        .iter()
        .map(|r| twinpath::bench::BenchRow {
            relmse: 0.0,
            ..r.clone()
        })
        .collect();
    let none = dir.join("none.png");
    assert!(!write_plot(&exact, "test", &none).unwrap());
    assert!(!none.exists());
}

/// `twinpath diff`'s z of the mean difference: the mean of the pixels' channel means over its
/// standard error (sample variance over the pixels); small for noise alone, large for a bias.
#[test]
fn diff_z_tells_a_bias_from_noise() {
    let image = |pixels: Vec<[f32; 3]>, width: u32| RgbImage {
        width,
        height: pixels.len() as u32 / width,
        pixels,
    };
    // Pixel differences 1 and 3: mean 2, sample variance 2, standard error 1, z = 2.
    let d = diff_images(
        &image(vec![[1.0; 3], [3.0, 2.0, 4.0]], 2),
        &image(vec![[0.0; 3]; 2], 2),
    )
    .unwrap();
    assert_eq!((d.mean_signed, d.mean_z), (2.0, 2.0));
    // Identical images: no spread, z 0.
    let same = image(vec![[0.25, 0.5, 0.75]; 16], 4);
    assert_eq!(diff_images(&same, &same).unwrap().mean_z, 0.0);
    // Uniform noise of +-0.1 per channel on 64 x 64 pixels, then the same plus a bias of 0.01:
    // the standard error is 0.1 / sqrt(3) / sqrt(3) / 64 = 5.2e-4, so the bias reads z ~ 19.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut noise = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32 * 0.2 - 0.1
    };
    let noisy: Vec<[f32; 3]> = (0..64 * 64)
        .map(|_| [0.5 + noise(), 0.5 + noise(), 0.5 + noise()])
        .collect();
    let reference = image(vec![[0.5; 3]; 64 * 64], 64);
    let unbiased = diff_images(&image(noisy.clone(), 64), &reference).unwrap();
    assert!(unbiased.mean_z.abs() < 4.0, "z = {}", unbiased.mean_z);
    let biased: Vec<[f32; 3]> = noisy.iter().map(|p| p.map(|v| v + 0.01)).collect();
    let biased = diff_images(&image(biased, 64), &reference).unwrap();
    assert!(biased.mean_z > 12.0, "z = {}", biased.mean_z);
}
