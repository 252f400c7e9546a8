//! Splitting at the first vertex (`kernel::split`, `host::split_pilot`): unbiased on both
//! backends, the same samples on both, and not an image changed where it does not split.
//!
//! - A white furnace reads its background exactly in every sample with 2, 3 and 4
//!   continuations and the learned table: the continuations' sum over n is exact, and no
//!   continuation is lost (CPU packets, one path, GPU).
//! - The plane under two lamps, a closed form, z-tested pixel by pixel with 3 continuations and
//!   the learned table on every backend (`assert_backends_agree_with`): the first vertex's
//!   part, carried by continuation 0 times n, is right.
//! - Cornell's image mean, most of it carried by the continuations, is the unsplit render's.
//! - The CPU's packets (continuations queued and filled into spare lanes) give the one-path
//!   image bit for bit, on small scenes, a medium and scenes through the BVH.
//! - One continuation everywhere is the unsplit render, bit for bit, on both backends; the GPU
//!   computes the CPU's samples (on a device of the CPU's arithmetic).
//! - The table's choice never scores worse than one n everywhere (the model it minimises).

use glam::Vec3;
use twinpath::film::Film;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath::settings::Split;
use twinpath::split_pilot::{choose, TileStatistics};
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_backends_agree_with, assert_bvh_packets_give_the_one_path_image, assert_films_identical,
    assert_packets_give_the_one_path_image, image_mean_z, plane_exact, plane_under_lamps,
    render_film, repo_root, white_furnace, with_independent_samples, z_critical, Lamp,
};

/// The furnace's background: a power of two, so that sums of it and their quotients by 2, 3
/// and 4 are exact in f32.
const LB: f32 = 0.5;

fn with_split(scene: &SceneFile, split: Split) -> SceneFile {
    let mut s = scene.clone();
    s.settings.split = split;
    s
}

/// The Cornell room with every albedo 1 and no light under a uniform background Lb, throughput
/// roulette, `size` x `size` pixels.
fn furnace(size: u32) -> SceneFile {
    let scene = white_furnace("seed = 6\nroulette = \"throughput\"", size, size, LB);
    assert!(scene.scene.lights.is_empty());
    scene
}

fn assert_every_sample_reads_the_background(film: &Film, spp: u32, label: &str) {
    assert_eq!(film.discarded, 0, "{label}: non-finite samples");
    let (mean, var) = (film.mean(), film.variance_of_mean());
    let bad: Vec<usize> = (0..mean.len())
        .filter(|&i| mean[i] != [LB; 3] || var[i] != [0.0; 3] || film.count[i] != spp)
        .collect();
    assert!(
        bad.is_empty(),
        "{label}: {} of {} pixels are not exactly {LB}; the first: {:?}",
        bad.len(),
        mean.len(),
        bad.first().map(|&i| (i, mean[i], var[i], film.count[i]))
    );
}

#[test]
fn a_split_white_furnace_reads_its_background_in_every_sample() {
    let scene = furnace(32);
    for split in [
        Split::Fixed(2),
        Split::Fixed(3),
        Split::Fixed(4),
        Split::Auto,
    ] {
        let split_scene = with_split(&scene, split);
        let mut one_path = split_scene.clone();
        one_path.settings.packets = false;
        for (label, s, backend, spp) in [
            ("cpu packets", &split_scene, Backend::Cpu, 256),
            ("cpu one path", &one_path, Backend::Cpu, 64),
            ("gpu", &split_scene, Backend::Gpu, 32),
        ] {
            let film = render_film(s, backend, spp);
            let label = format!("{label}, split {}", split.name());
            assert_every_sample_reads_the_background(&film, spp, &label);
            println!("{label}: {spp} spp, every sample {LB}");
        }
    }
    assert_validation_clean();
}

/// Two lamps over the diffuse plane (`plane_exact`'s closed form), the camera above at an
/// angle.
fn two_lamps() -> (SceneFile, Vec<Option<[f64; 3]>>) {
    const KD: f32 = 0.6;
    let lamps = [
        Lamp {
            center: Vec3::new(-1.5, 2.0, 0.0),
            radius: 0.5,
            radiance: 5.0,
        },
        Lamp {
            center: Vec3::new(2.0, 1.5, -1.0),
            radius: 0.3,
            radiance: 12.0,
        },
    ];
    let scene = plane_under_lamps(
        "eye = [0, 9, 9]\nlook_at = [0, 0, -1]\nup = [0, 1, 0]\nvfov = 70\nwidth = 40\nheight = 40",
        "seed = 9",
        KD,
        &lamps,
    );
    let exact = plane_exact(&scene.scene, KD, &lamps)
        .into_iter()
        .map(|e| e.map(|v| [v; 3]))
        .collect::<Vec<_>>();
    assert!(exact.iter().flatten().count() > 1000);
    (scene, exact)
}

#[test]
fn split_paths_match_the_plane_under_two_lamps_on_every_backend() {
    let (scene, exact) = two_lamps();
    for split in [Split::Fixed(3), Split::Auto] {
        println!("split = {}", split.name());
        assert_backends_agree_with(&with_split(&scene, split), &exact, 128);
    }
    assert_validation_clean();
}

#[test]
fn a_split_cornell_box_has_the_unsplit_image_mean() {
    // Most of Cornell's light arrives after the first vertex (docs/performance.md: V_b and V_c
    // are 91% of its variance), so here the continuations carry the image, and the MIS
    // weights of lights their extensions find (continuations 1 to n - 1 take no light sample
    // at the first vertex) weigh in. Independent samples: each image's noise is known.
    let scene = with_independent_samples(small("cornell.toml", 40));
    let off = render_film(&scene, Backend::Cpu, 256);
    for (split, seed) in [(Split::Fixed(3), 21), (Split::Auto, 22)] {
        let mut other = with_split(&scene, split);
        other.settings.seed = seed;
        let film = render_film(&other, Backend::Cpu, 256);
        let z = image_mean_z(&off, &film);
        println!("cornell, split {} against off: z = {z:+.2}", split.name());
        assert!(z.abs() < z_critical(1e-3, 2), "z = {z:.2}");
    }
}

fn small(name: &str, size: u32) -> SceneFile {
    let mut s = SceneFile::load(&repo_root().join("scenes").join(name)).unwrap();
    s.scene.camera.width = size;
    s.scene.camera.height = size;
    s
}

#[test]
fn packets_give_the_one_path_image_with_split_paths() {
    for split in [
        Split::Fixed(2),
        Split::Fixed(3),
        Split::Fixed(4),
        Split::Auto,
    ] {
        let name = |scene: &str| format!("{scene}, split {}", split.name());
        for scene in ["cornell.toml", "cornell_materials.toml", "cornell_fog.toml"] {
            let s = with_split(&small(scene, 40), split);
            assert_packets_give_the_one_path_image(&name(scene), &s, 16);
        }
        let s = with_split(&small("meshes.toml", 40), split);
        assert_bvh_packets_give_the_one_path_image(&name("meshes.toml"), &s, 8, "a mesh scene");
    }
    // Mixed tables: the learned one of a 48 x 48 Cornell at 64 spp (its pilot has 2 samples per
    // pixel), whose tiles differ.
    let s = with_split(&small("cornell.toml", 48), Split::Auto);
    assert_packets_give_the_one_path_image("cornell 48, split auto", &s, 64);
}

#[test]
fn one_continuation_is_the_unsplit_render_on_both_backends() {
    let scene = small("cornell_materials.toml", 40);
    for (backend, spp) in [(Backend::Cpu, 16), (Backend::Gpu, 4)] {
        let off = render_film(&scene, backend, spp);
        let one = render_film(&with_split(&scene, Split::Fixed(1)), backend, spp);
        assert_films_identical(&off, &one, &format!("{backend:?}: split 1 vs off"));
    }
    assert_validation_clean();
}

#[test]
fn the_gpu_computes_the_cpus_split_samples() {
    let scene = with_split(&small("cornell_materials.toml", 40), Split::Fixed(3));
    let cpu = render_film(&scene, Backend::Cpu, 8);
    let gpu = render_film(&scene, Backend::Gpu, 8);
    assert_eq!((cpu.discarded, gpu.discarded), (0, 0));
    assert_eq!(cpu.count, gpu.count);
    let (a, b) = (cpu.mean(), gpu.mean());
    let equal = a
        .iter()
        .zip(&b)
        .filter(|(x, y)| (0..3).all(|c| (x[c] - y[c]).abs() <= 1e-4 * x[c].abs().max(y[c].abs())))
        .count();
    let fraction = equal as f64 / a.len() as f64;
    println!(
        "split 3, cpu vs gpu: {:.4}% of pixels equal to 1e-4",
        100.0 * fraction
    );
    if twinpath_tests::gpu::device_is_ieee() {
        assert!(fraction >= 0.999, "only {:.4}% equal", 100.0 * fraction);
    }
    assert_validation_clean();
}

/// The table's score in the model: the image's weighted variance times its cost.
fn score(tiles: &[TileStatistics], table: &[u32]) -> f64 {
    let error: f64 = tiles.iter().zip(table).map(|(t, &n)| t.error(n)).sum();
    let cost: f64 = tiles.iter().zip(table).map(|(t, &n)| t.cost(n)).sum();
    error * cost
}

fn tile(prefix_variance: f64, continuation_variance: f64) -> TileStatistics {
    TileStatistics {
        prefix_variance,
        continuation_variance,
        prefix_cost: 1.0,
        continuation_cost: 1.0,
    }
}

#[test]
fn the_split_table_follows_where_the_variance_lies() {
    // All variance after the vertex: efficiency 1 / (n (1 + n) / n) grows with n, so 4.
    assert_eq!(choose(&[tile(0.0, 1.0); 3]), vec![4; 3]);
    // All before it: continuations only cost.
    assert_eq!(choose(&[tile(1.0, 0.0); 3]), vec![1; 3]);
    // Nothing to learn from: no split.
    assert_eq!(choose(&[tile(0.0, 0.0); 2]), vec![1; 2]);
    // One of each: (1 + 1/n)(n + 3) is least at n = 2 (7.5 against 8, 8 and 8.75).
    assert_eq!(choose(&[tile(0.0, 1.0), tile(1.0, 0.0)]), vec![2, 1]);
}

#[test]
fn the_split_table_never_scores_worse_than_one_n_everywhere() {
    // Random tiles of widely spread variances and costs (a fixed generator: repeatable).
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut unit = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..200 {
        let tiles: Vec<TileStatistics> = (0..12)
            .map(|_| TileStatistics {
                prefix_variance: (8.0 * unit() - 4.0).exp(),
                continuation_variance: (8.0 * unit() - 4.0).exp(),
                prefix_cost: 0.5 + unit(),
                continuation_cost: 1.0 + 3.0 * unit(),
            })
            .collect();
        let table = choose(&tiles);
        assert!(table.iter().all(|&n| (1..=4).contains(&n)));
        for n in 1..=4 {
            assert!(
                score(&tiles, &table) <= score(&tiles, &vec![n; tiles.len()]) * (1.0 + 1e-12),
                "the table {table:?} scores worse than {n} everywhere"
            );
        }
    }
}

/// The progress bar counts every sample a render renders, the pilot of `split = auto`
/// included, and ends at its length (`render::samples_to_count`): on both backends, with and
/// without the pilot, for a whole render and for a part.
#[test]
fn the_progress_bar_counts_the_pilot_and_ends_full() {
    use twinpath::render::{render_counting, samples_to_count, RenderOptions};
    use twinpath::sample_range::SampleRange;
    for backend in [Backend::Cpu, Backend::Gpu] {
        for split in [Split::Off, Split::Fixed(2), Split::Auto] {
            for samples in [None, Some(SampleRange { start: 8, end: 24 })] {
                let mut s = with_split(&small("cornell.toml", 24), split);
                s.settings.spp = 64;
                let opts = RenderOptions {
                    backend,
                    samples,
                    ..RenderOptions::default()
                };
                let total = samples_to_count(&s.scene, &s.settings, &opts);
                let bar = indicatif::ProgressBar::hidden();
                bar.set_length(total);
                let out = render_counting(&s.scene, &s.settings, &opts, Some(&bar)).unwrap();
                assert!(!out.interrupted);
                let pilot = if split == Split::Auto { 2 } else { 0 };
                let spp = samples.map_or(64, |r| r.len());
                assert_eq!(
                    total,
                    24 * 24 * (spp + pilot) as u64,
                    "{backend:?} {split:?}"
                );
                assert_eq!(bar.position(), total, "{backend:?} {split:?} {samples:?}");
            }
        }
    }
}
