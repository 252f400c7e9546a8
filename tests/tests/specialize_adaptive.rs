//! Skipping what a scene doesn't need: the specialized kernel paths (CPU const generics, GPU
//! specialization constant and missing hit groups) give the same images as the generic path,
//! bit for bit; and adaptive sampling stays unbiased on a closed-form scene on both backends.

use glam::Vec3;
use kernel::features;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath::settings::{LightSampling, Mis, Roulette};
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_film_matches_with_variance, assert_films_identical, equal_pixel_sums, image_mean_z,
    plane_exact, plane_under_lamps, render_film, repo_root, variance_of_mean_from,
    with_independent_samples, z_critical, Lamp,
};

fn small(mut s: SceneFile) -> SceneFile {
    s.scene.camera.width = 48;
    s.scene.camera.height = 48;
    s
}

/// `scenes/NAME.toml` at 48 x 48.
fn shipped(name: &str) -> SceneFile {
    let path = repo_root().join("scenes").join(format!("{name}.toml"));
    small(SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}")))
}

fn cornell() -> SceneFile {
    shipped("cornell")
}

/// Triangles only, no lights, a background: the "no spheres, no lights" case.
fn sky_meshes() -> SceneFile {
    shipped("sky_meshes")
}

/// Spheres only, several lights of different power.
fn many_lights() -> SceneFile {
    shipped("many_lights")
}

/// Every material kind.
fn materials() -> SceneFile {
    shipped("materials")
}

/// Cornell with a rough gold and a glass sphere: conductor and dielectric bits, no Kd + Ks.
fn cornell_materials() -> SceneFile {
    shipped("cornell_materials")
}

/// Cornell lit by a ceiling panel: triangle lights.
fn cornell_panel() -> SceneFile {
    shipped("cornell_panel")
}

/// Textured floor, wall and light; smooth meshes (shading normals).
fn textures() -> SceneFile {
    shipped("textures")
}

/// `scene` through a lens of diameter 0.2 focused on its spheres (3.5 from the eye).
fn thin_lens(mut scene: SceneFile) -> SceneFile {
    scene.scene.camera.aperture = 0.2;
    scene.scene.camera.focus_distance = 3.5;
    scene
}

fn scenes() -> Vec<(&'static str, SceneFile)> {
    let mut half = cornell();
    half.settings.mis = Mis::Half;
    half.settings.light_sampling = LightSampling::Area;
    let mut constant = cornell();
    constant.settings.roulette = Roulette::Constant;
    vec![
        ("cornell", cornell()),
        ("cornell, constant roulette", constant),
        ("cornell, half weights + area sampling", half),
        ("sky_meshes", sky_meshes()),
        ("many_lights", many_lights()),
        ("materials", materials()),
        ("cornell with gold and glass", cornell_materials()),
        ("cornell lit by a panel (triangle lights)", cornell_panel()),
        ("cornell through a thin lens", thin_lens(cornell())),
        ("an environment map", shipped("sky")),
        ("textures and smooth meshes", textures()),
    ]
}

#[test]
fn scene_analysis_finds_the_features_present() {
    let f = cornell().features();
    assert_eq!(
        f,
        features::SPECIALIZED
            | features::LIGHTS
            | features::SINGLE_LIGHT
            | features::MIS_POWER
            | features::LIGHT_SOLID_ANGLE
            | features::RR_THROUGHPUT
    );
    let f = sky_meshes().features();
    assert!(f & features::BACKGROUND != 0 && f & features::LIGHTS == 0);
    let f = many_lights().features();
    assert!(f & features::LIGHTS != 0 && f & features::SINGLE_LIGHT == 0);
    // One bit per material kind present; Cornell (Lambertian only) has none. The materials
    // scene has every kind but glTF's (whose bit `gltf.rs` checks).
    assert_eq!(
        materials().features() & features::MATERIALS,
        features::GLOSSY | features::CONDUCTOR | features::DIELECTRIC
    );
    assert_eq!(
        cornell_materials().features() & features::MATERIALS,
        features::CONDUCTOR | features::DIELECTRIC
    );
    // Triangle lights: their own bit, which sphere-lit scenes lack.
    assert_eq!(
        cornell_panel().features() & features::TRIANGLE_LIGHTS,
        features::TRIANGLE_LIGHTS
    );
    assert_eq!(cornell().features() & features::TRIANGLE_LIGHTS, 0);
    assert_eq!(cornell().features() & features::THIN_LENS, 0);
    assert_eq!(cornell().features() & features::ENVIRONMENT, 0);
    // Textures and shading normals: their own bits, which every other shipped scene lacks.
    assert_eq!(
        textures().features() & (features::TEXTURES | features::SHADING_NORMALS),
        features::TEXTURES | features::SHADING_NORMALS
    );
    assert_eq!(
        materials().features() & (features::TEXTURES | features::SHADING_NORMALS),
        0
    );
    let sky = shipped("sky");
    assert_eq!(
        sky.features() & (features::ENVIRONMENT | features::BACKGROUND | features::LIGHTS),
        features::ENVIRONMENT | features::BACKGROUND | features::LIGHTS
    );
    assert_eq!(
        thin_lens(cornell()).features() & features::THIN_LENS,
        features::THIN_LENS
    );
    let mut generic = cornell();
    generic.settings.specialize = false;
    assert_eq!(generic.features(), 0);
}

/// Every test scene rendered specialized and generic on `backend` at `spp`: identical films
/// on the CPU and on a device of the CPU's arithmetic. A Vulkan-class device compiles the two
/// pipelines separately and may round them differently (a multiply fused in one, not in the
/// other: `docs/robustness.md`), so there a ray within rounding of an edge may take another
/// path: equal pixels are reported, and the two image means, from independent seeds, are held
/// to agree within their noise.
fn assert_specialized_matches_generic(backend: Backend, spp: u32) {
    let list = scenes();
    let identical = backend == Backend::Cpu || twinpath_tests::gpu::device_is_ieee();
    for (name, scene) in &list {
        let mut generic = scene.clone();
        generic.settings.specialize = false;
        let a = render_film(scene, backend, spp);
        let b = render_film(&generic, backend, spp);
        if identical {
            assert_films_identical(&a, &b, name);
            println!(
                "{backend:?} {name}: features {:#x}: identical to the generic path",
                scene.features()
            );
            continue;
        }
        let same = equal_pixel_sums(&a, &b);
        let mut other = with_independent_samples(generic);
        other.settings.seed = scene.settings.seed.wrapping_add(1000);
        let b = render_film(&other, backend, spp);
        let a = render_film(&with_independent_samples(scene.clone()), backend, spp);
        let z = image_mean_z(&a, &b);
        println!(
            "{backend:?} {name}: a Vulkan-class device: {same} of {} pixel sums equal to the generic path's (same seed); image means z = {z:+.2} (independent seeds)",
            a.sum.len()
        );
        assert!(
            z.abs() < z_critical(1e-3, list.len()),
            "{name}: specialized and generic image means differ: z = {z:.2}"
        );
    }
}

#[test]
fn specialized_and_generic_paths_give_identical_images_on_the_cpu() {
    assert_specialized_matches_generic(Backend::Cpu, 8);
}

#[test]
fn specialized_and_generic_paths_give_identical_images_on_the_gpu() {
    assert_specialized_matches_generic(Backend::Gpu, 4);
    assert_validation_clean();
}

const KD: f32 = 0.6;

fn lamp() -> Lamp {
    Lamp {
        center: Vec3::new(0.0, 2.0, 0.0),
        radius: 0.5,
        radiance: 5.0,
    }
}

/// The plane under one lamp, with adaptive sampling at `target`.
fn adaptive_plane(target: f32) -> SceneFile {
    plane_under_lamps(
        "eye = [0, 9, 9]\nlook_at = [0, 0, -1]\nup = [0, 1, 0]\nvfov = 70\nwidth = 48\nheight = 48",
        &format!("seed = 11\nadaptive_target = {target}"),
        KD,
        &[lamp()],
    )
}

#[test]
fn adaptive_sampling_is_unbiased_on_the_closed_form_plane_on_both_backends() {
    let target = 0.004;
    let scene = adaptive_plane(target);
    let exact = plane_exact(&scene.scene, KD, &[lamp()]);
    let max_spp = 512;
    // Per-sample variances from an independent uniform render (another seed): a pixel that
    // stopped after few samples estimates its own variance poorly.
    let mut uniform = adaptive_plane(0.0);
    uniform.settings.seed += 1000;
    let variance_source = render_film(&uniform, Backend::Cpu, 1024);
    let mut maps = Vec::new();
    for backend in [Backend::Cpu, Backend::Gpu] {
        let film = render_film(&scene, backend, max_spp);
        assert_eq!(film.discarded, 0);
        let spp = film.samples_per_pixel();
        let stopped = spp.iter().filter(|&&n| n < max_spp).count();
        let mean_spp = spp.iter().map(|&n| n as f64).sum::<f64>() / spp.len() as f64;
        println!(
            "{backend:?}: adaptive target {target}: {stopped} of {} pixels stopped early, {mean_spp:.1} samples per pixel on average (min {}, max {})",
            spp.len(),
            spp.iter().min().unwrap(),
            spp.iter().max().unwrap()
        );
        // The test means something only if the sampler really adapted, both ways.
        assert!(stopped > spp.len() / 4 && stopped < spp.len());
        let distinct: std::collections::BTreeSet<u32> = spp.iter().copied().collect();
        assert!(distinct.len() >= 5, "stopping counts {distinct:?}");
        let var = variance_of_mean_from(&variance_source, &film);
        assert_film_matches_with_variance(
            &film,
            &exact,
            var.clone(),
            &format!("{backend:?}, adaptive"),
        );
        // Bias would hide in the pixels that stopped early: test each group of pixels that
        // stopped at the same count on its own.
        let mut groups: std::collections::BTreeMap<u32, (f64, f64)> = Default::default();
        let mean = film.mean();
        for (i, e) in exact.iter().enumerate() {
            if let Some(e) = e {
                let g = groups.entry(spp[i]).or_default();
                g.0 += mean[i][0] as f64 - e;
                g.1 += var[i][0] as f64;
            }
        }
        let big: Vec<_> = groups.iter().filter(|(_, g)| g.1 > 0.0).collect();
        let bound = z_critical(1e-3, big.len());
        for (n, (d, v)) in &big {
            let z = d / v.sqrt();
            println!("  pixels with {n} samples: z = {z:+.2}");
            assert!(
                z.abs() < bound,
                "{backend:?}: pixels stopped at {n} samples: z = {z:.2}"
            );
        }
        maps.push(spp);
    }
    // Both backends stop the same pixels at the same sample counts.
    let differ = maps[0].iter().zip(&maps[1]).filter(|(a, b)| a != b).count();
    println!("sample-count maps differ in {differ} pixels between CPU and GPU");
    assert!(differ <= maps[0].len() / 1000);
    assert_validation_clean();
}

#[test]
fn adaptive_sampling_off_gives_every_pixel_every_sample() {
    let scene = adaptive_plane(0.0);
    let film = render_film(&scene, Backend::Cpu, 16);
    assert!(film.samples_per_pixel().iter().all(|&n| n == 16));
    assert!(film.pilot_count.iter().all(|&n| n == 0));
}

#[test]
fn scene_without_spheres_and_lights_renders_on_both_backends() {
    // No sphere hit group, no sphere BLAS, no light sampling: a furnace-like check that the
    // specialized GPU pipeline still sees the triangles (same image as the CPU's).
    let scene = sky_meshes();
    assert!(scene.scene.spheres.is_empty() && scene.scene.lights.is_empty());
    let cpu = render_film(&scene, Backend::Cpu, 4);
    let gpu = render_film(&scene, Backend::Gpu, 4);
    let (a, b) = (cpu.mean(), gpu.mean());
    let close = a
        .iter()
        .zip(&b)
        .filter(|(x, y)| (0..3).all(|c| (x[c] - y[c]).abs() <= 1e-4 * x[c].abs().max(y[c].abs())))
        .count();
    println!(
        "sky_meshes: {close} of {} pixels equal on CPU and GPU",
        a.len()
    );
    assert!(close as f64 >= 0.999 * a.len() as f64);
    assert_validation_clean();
}
