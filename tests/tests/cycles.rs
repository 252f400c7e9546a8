//! Blender's scenes as Cycles renders them: feature scenes built in Blender 5.3 the way a user
//! builds them, exported by Blender's own glTF exporter and rendered by Cycles with unbiased
//! settings (`scripts/cycles_fixtures.py`; tests/reference/cycles/<scene>/ holds scene.glb,
//! the two independent halves of the Cycles image and meta.json), rendered here on both backends
//! through the file's own camera and compared with the Cycles image as `mitsuba.rs` compares
//! with Mitsuba: a per-pixel z-test (our variance plus the reference's, from its halves) that
//! 99.5% of pixels must pass at alpha = 1e-3, and the image means within their errors.
//!
//! - `point`: a 100 W point light over a floor whose Principled BSDF has Specular IOR Level 0
//!   (exported as `KHR_materials_specular` factor 0: a Lambertian floor in both renderers). The
//!   file says 5435 cd; read as W/sr it was 683 times too bright.
//! - `sun`: a sun of strength 3 W/m^2 (the file: 2049 lux).
//! - `spot`: a 200 W spot, 60 degrees, blend 0.3. glTF's falloff (which twinpath follows) and
//!   Blender's smoothstep agree where both are 1 (inside glTF's inner cone) and 0 (outside the
//!   outer one): those pixels are compared; the ring between is measured and printed
//!   (docs/gltf.md, "Light units").
//! - `emission`: a quad whose Principled BSDF emits at strength 5 (black base colour), seen by
//!   the camera and lighting the floor (`KHR_materials_emissive_strength`).
//! - `mapping`: an image texture through a Mapping node (offset, 30 degrees, scale 2 x 1.5),
//!   which the exporter writes as `KHR_texture_transform` in `extensionsRequired`.
//! - `colour`: a Color Attribute (float, per vertex) driving the base colour: `COLOR_0`.
//! - `glowing_wall`: a wall whose Principled BSDF emits and reflects (base colour 0.7) beside a
//!   lit floor: the emissive material keeps its surface, and light bounces between the two.
//! - `cutout`: a square over the floor whose texture's alpha is clipped at 0.5 (Math nodes
//!   "Less Than" and "Subtract" into Alpha, as a leaf's cut-out is set up), which the exporter
//!   writes as `alphaMode` MASK: its holes show the floor and let the light through. The same
//!   render with the holes ignored (the square opaque) is rejected.
//! - `blend`: a square over the floor whose Principled BSDF has Alpha 0.4, which the exporter
//!   writes as `alphaMode` BLEND: seen and passed through 60% of the time. The same render
//!   with the square opaque is rejected.
//! - `coat`: two red Principled spheres under a Coat of weight 1, rough (0.6) and smooth (0):
//!   `KHR_materials_clearcoat`. Means within 2%; the per-pixel test is measured, not asserted
//!   (Cycles' layering under a rough coat differs, docs/gltf.md). The same render without the
//!   coats is rejected.
//! - `sheen`: two spheres under a Principled Sheen of weight 1 (white, roughness 0.5, over dark
//!   blue; orange, roughness 1, over grey): `KHR_materials_sheen`, Cycles' fibre-layer sheen
//!   (`bsdf::sheen`). The same render without the sheens is rejected.
//! - `rough_metal`: two spheres of Principled metal, roughness 0.5 (gold) and 0.9 (light grey),
//!   on a lit floor: Cycles' multiscatter GGX, which twinpath's compensation
//!   (`bsdf::multiple_scattering`) matches. The same render with single scattering alone (the
//!   albedo table taken out) is rejected.

use glam::Vec3;
use twinpath::film::RgbImage;
use twinpath::render::Backend;
use twinpath::scene::{parse_scene, SceneFile};
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::stats::{pixel_z_test, variance_of_channel_mean};
use twinpath_tests::{
    assert_films_identical, pixel_quadrature, render_film, repo_root, variance_of_mean_from,
    with_independent_samples, z_critical,
};

const SPP: u32 = 1024;

/// A fixture's scene (its glTF file through its camera, at the reference's size, black
/// background as the fixture's world) and its Cycles reference with per-pixel variance.
struct Fixture {
    name: &'static str,
    scene: SceneFile,
    reference: RgbImage,
    reference_var: Vec<[f32; 3]>,
}

fn fixture(name: &'static str) -> Fixture {
    let dir = repo_root().join("tests/reference/cycles").join(name);
    let read = |f: &str| RgbImage::read(&dir.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
    let (a, b) = (read("cycles_half_a.exr"), read("cycles_half_b.exr"));
    // The reference is the halves' mean; its variance per pixel (a - b)^2 / 4.
    let reference = RgbImage {
        width: a.width,
        height: a.height,
        pixels: a
            .pixels
            .iter()
            .zip(&b.pixels)
            .map(|(a, b)| std::array::from_fn(|c| (a[c] + b[c]) / 2.0))
            .collect(),
    };
    let reference_var = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(a, b)| std::array::from_fn(|c| (a[c] - b[c]) * (a[c] - b[c]) / 4.0))
        .collect();
    let toml = format!(
        "[camera]\ngltf = \"camera\"\nwidth = {}\nheight = {}\n[[gltf]]\nfile = \"scene.glb\"\n",
        reference.width, reference.height
    );
    let scene = parse_scene(&toml, &dir.join("fixture.toml")).unwrap_or_else(|e| panic!("{e}"));
    Fixture {
        name,
        scene: with_independent_samples(scene),
        reference,
        reference_var,
    }
}

/// Renders `f` on `backend` and compares the pixels `compared` selects (all: `None`) with the
/// Cycles reference, whose variance is taken as at least (`floor` x its value)^2 (the accuracy
/// of a reference pixel without noise); returns our image's mean over those pixels over
/// Cycles'. Our variance is the render's own; where `heavy_tailed` (pixels whose light comes
/// mostly by rare paths, whose sample variance is low exactly when a render missed those
/// paths), the larger of that and an independent render's of four times the samples
/// (`variance_of_mean_from`), so that neither render's luck sets it alone.
fn compare(
    f: &Fixture,
    backend: Backend,
    label: &str,
    compared: Option<&[bool]>,
    floor: f32,
    heavy_tailed: bool,
    spp: u32,
) -> f64 {
    let m = measure(f, backend, label, compared, floor, heavy_tailed, spp);
    assert!(
        m.pass_fraction >= 0.995,
        "{label} ({backend:?}): only {:.2}% of pixels pass",
        100.0 * m.pass_fraction
    );
    assert!(
        m.z_mean.abs() < z_critical(1e-3, 1),
        "{label} ({backend:?}): image means differ, z = {:.2}",
        m.z_mean
    );
    m.ratio
}

/// What [`compare`] measures: the fraction of pixels that pass the per-pixel z-test, the z of
/// the image means' difference, and our mean over Cycles'.
struct Agreement {
    pass_fraction: f64,
    z_mean: f64,
    ratio: f64,
}

/// [`compare`]'s render and statistics, printed, without its assertions.
#[allow(clippy::too_many_arguments)]
fn measure(
    f: &Fixture,
    backend: Backend,
    label: &str,
    compared: Option<&[bool]>,
    floor: f32,
    heavy_tailed: bool,
    spp: u32,
) -> Agreement {
    let film = render_film(&f.scene, backend, spp);
    assert_eq!(film.discarded, 0, "{label}: non-finite samples");
    let mut var = film.variance_of_mean();
    if heavy_tailed {
        let mut other = f.scene.clone();
        other.settings.seed += 1;
        let independent = variance_of_mean_from(&render_film(&other, backend, 4 * spp), &film);
        for (v, w) in var.iter_mut().zip(independent) {
            *v = std::array::from_fn(|c| v[c].max(w[c]));
        }
    }
    let mean = film.mean();
    let keep: Vec<usize> = (0..mean.len())
        .filter(|&i| compared.is_none_or(|c| c[i]))
        .collect();
    let pick = |px: &[[f32; 3]]| RgbImage {
        width: keep.len() as u32,
        height: 1,
        pixels: keep.iter().map(|&i| px[i]).collect(),
    };
    let (ours, theirs) = (pick(&mean), pick(&f.reference.pixels));
    let ours_var = pick(&var).pixels;
    let theirs_var: Vec<[f32; 3]> = theirs
        .pixels
        .iter()
        .zip(pick(&f.reference_var).pixels)
        .map(|(p, v)| std::array::from_fn(|c| v[c].max((floor * p[c]).powi(2))))
        .collect();
    let t = pixel_z_test(
        &ours,
        &ours_var,
        &theirs,
        Some(&theirs_var),
        z_critical(1e-3, 3),
    );
    // The image means, each with the variance of its mean: pixels are independent, a pixel's
    // channels may be fully correlated (`variance_of_channel_mean`).
    let n = (3 * keep.len()) as f64;
    let sum = |img: &[[f32; 3]]| img.iter().flatten().map(|&x| x as f64).sum::<f64>() / n;
    let (m_ours, m_theirs) = (sum(&ours.pixels), sum(&theirs.pixels));
    // The floor is a systematic accuracy: averaging over pixels does not shrink it.
    let systematic = (floor as f64 * m_theirs).powi(2);
    let v = variance_of_channel_mean(&ours_var)
        + variance_of_channel_mean(&pick(&f.reference_var).pixels)
        + systematic;
    let z_mean = (m_ours - m_theirs) / v.sqrt();
    println!(
        "{label} ({backend:?}, {} pixels): {:.2}% pass, max |z| {:.2}; mean {m_ours:.5} vs \
         Cycles {m_theirs:.5} (ratio {:.4}, z {z_mean:+.2})",
        keep.len(),
        100.0 * t.pass_fraction(),
        t.max_abs_z,
        m_ours / m_theirs
    );
    Agreement {
        pass_fraction: t.pass_fraction(),
        z_mean,
        ratio: m_ours / m_theirs,
    }
}

/// Fixture `name` compared with Cycles on both backends (`heavy_tailed` as for [`compare`]),
/// the GPU's validation layers clean; the fixture, for what else its test checks.
fn agrees_with_cycles(name: &'static str, heavy_tailed: bool) -> Fixture {
    let f = fixture(name);
    for backend in [Backend::Cpu, Backend::Gpu] {
        compare(&f, backend, name, None, 0.0, heavy_tailed, SPP);
    }
    assert_validation_clean();
    f
}

#[test]
fn a_blender_point_light_in_watts_renders_as_cycles_renders_it() {
    agrees_with_cycles("point", false);
}

/// The sun lights the floor uniformly, so a pixel the floor fills has no noise in either
/// renderer: there the closed form kd E cos / pi decides. twinpath meets it to 1e-5 on both
/// backends; Cycles' own deviation from it (measured here: 2.0e-4, its f32 arithmetic) is
/// the accuracy of the reference's noiseless pixels in the comparison.
#[test]
fn a_blender_sun_renders_as_cycles_renders_it() {
    let f = fixture("sun");
    let sun = f.scene.scene.lights[0];
    assert_eq!(sun.kind, kernel::scene::light_kind::DIRECTIONAL);
    let kd = 0.800000011920929f64;
    let exact = kd / std::f64::consts::PI
        * sun.radiance[0] as f64
        * -(Vec3::from(sun.edge1).as_dvec3().normalize().y);
    let filled: Vec<bool> = pixel_quadrature(&f.scene.scene, 4, |eye, d| {
        let (eye, d) = (eye.as_dvec3(), d.as_dvec3());
        let x = eye + d * (-eye.y / d.y);
        (d.y < 0.0 && x.x.abs() < 4.0 && x.z.abs() < 4.0).then_some(0.0)
    })
    .iter()
    .map(Option::is_some)
    .collect();
    let deviation = |px: &[[f32; 3]]| -> f64 {
        px.iter()
            .zip(&filled)
            .filter(|(_, f)| **f)
            .flat_map(|(p, _)| p.iter().map(|&c| (c as f64 / exact - 1.0).abs()))
            .fold(0.0, f64::max)
    };
    assert!(filled.iter().filter(|&&x| x).count() > 300);
    let cycles_deviation = deviation(&f.reference.pixels);
    println!("sun: Cycles deviates from kd E cos / pi = {exact:.6} by {cycles_deviation:.2e}");
    for backend in [Backend::Cpu, Backend::Gpu] {
        let ours = deviation(&render_film(&f.scene, backend, 16).mean());
        assert!(ours < 1e-5, "{backend:?}: {ours:.2e} from the closed form");
        compare(
            &f,
            backend,
            "sun",
            None,
            cycles_deviation as f32,
            false,
            SPP,
        );
    }
    assert_validation_clean();
}

#[test]
fn a_blender_emissive_principled_bsdf_renders_as_cycles_renders_it() {
    agrees_with_cycles("emission", false);
}

#[test]
fn a_blender_texture_through_a_mapping_node_renders_as_cycles_renders_it() {
    let f = agrees_with_cycles("mapping", false);
    // The map is read under `features::TEXTURE_TRANSFORMS`: the specialized path and the
    // generic one (which reads every record's flags) give the same bits.
    assert!(f.scene.features() & kernel::features::TEXTURE_TRANSFORMS != 0);
    let mut generic = f.scene.clone();
    generic.settings.specialize = false;
    assert_films_identical(
        &render_film(&f.scene, Backend::Cpu, 16),
        &render_film(&generic, Backend::Cpu, 16),
        "specialized against generic",
    );
}

#[test]
fn a_blender_color_attribute_renders_as_cycles_renders_it() {
    agrees_with_cycles("colour", false);
}

#[test]
fn a_blender_surface_that_emits_and_reflects_renders_as_cycles_renders_it() {
    agrees_with_cycles("glowing_wall", false);
}

#[test]
fn a_blender_alpha_clipped_texture_renders_as_cycles_renders_it() {
    // The floor's green light comes by the leaf's underside from the patches lit through the
    // holes: three bounces, rare, heavy-tailed.
    let f = agrees_with_cycles("cutout", true);
    let m = &f.scene.scene.materials;
    assert!(m.iter().any(|m| m.opacity == 0.5), "the file's MASK: {m:?}");
    assert_opaque_rejected(&f, "cutout");
}

#[test]
fn a_blender_alpha_blended_surface_renders_as_cycles_renders_it() {
    let f = agrees_with_cycles("blend", true);
    let m = &f.scene.scene.materials;
    assert!(
        m.iter().any(|m| (m.opacity + 0.4).abs() < 1e-6),
        "the file's BLEND: {m:?}"
    );
    assert_opaque_rejected(&f, "blend");
}

#[test]
fn a_blender_rough_metal_renders_as_cycles_renders_it() {
    // The floor's light reflected by the spheres from the point light (a glossy caustic) is
    // heavy-tailed.
    let f = agrees_with_cycles("rough_metal", true);
    // Without the table the kernel gives nothing back (`GlossyAlbedo::NONE`): single scattering.
    let mut single = f.scene.clone();
    single.scene.textures.words[kernel::texture::GGX_ALBEDO] = kernel::scene::NONE;
    assert_rejected(&f, &single, "rough_metal, single scattering");
    // Per roughness: the pixels each sphere fills, each set compared as the image is, and
    // single scattering's ratio printed.
    per_sphere(
        &f,
        &single,
        [(-0.75, "roughness 0.5"), (0.75, "roughness 0.9")],
    );
}

#[test]
fn a_blender_clear_coat_renders_as_cycles_renders_it() {
    // As `rough_metal`: the floor lit through the spheres' coats.
    // Cycles' coat takes a base's share by an estimate of its reflectance that twinpath's does
    // not reproduce (docs/gltf.md, "Against Cycles"): the means are held to the 2%, the
    // per-pixel agreement measured and printed.
    let f = fixture("coat");
    for backend in [Backend::Cpu, Backend::Gpu] {
        let m = measure(&f, backend, "coat", None, 0.0, true, SPP);
        assert!(
            (m.ratio - 1.0).abs() < 0.02,
            "coat ({backend:?}): means {:.4} apart",
            m.ratio
        );
    }
    assert_validation_clean();
    let coats: Vec<_> = f.scene.scene.materials.iter().map(|m| m.coat).collect();
    assert!(coats.iter().filter(|&&c| c != 0).count() == 2, "{coats:?}");
    let mut bare = f.scene.clone();
    for m in &mut bare.scene.materials {
        m.coat = 0;
    }
    assert_rejected(&f, &bare, "coat, coats removed");
}

#[test]
fn a_blender_sheen_renders_as_cycles_renders_it() {
    // The floor lit through the spheres' sheen: heavy-tailed as `coat`.
    let f = agrees_with_cycles("sheen", true);
    let sheens = f
        .scene
        .scene
        .materials
        .iter()
        .filter(|m| m.has_sheen())
        .count();
    assert_eq!(sheens, 2, "the file's KHR_materials_sheen");
    let mut bare = f.scene.clone();
    for m in &mut bare.scene.materials {
        m.set_sheen([0.0; 3], 0.0);
    }
    assert_rejected(&f, &bare, "sheen, sheens removed");
    per_sphere(
        &f,
        &bare,
        [(-0.75, "white sheen 0.5"), (0.75, "orange sheen 1")],
    );
}

/// Compares the pixels each of fixture `f`'s two spheres fills (Blender's (x, 0, 0.6), radius
/// 0.6, is glTF's (x, 0.6, 0)) with Cycles' as the whole image is compared (CPU), and prints
/// how `changed` (its scene without the feature) compares there.
fn per_sphere(f: &Fixture, changed: &SceneFile, spheres: [(f64, &str); 2]) {
    let changed_film = render_film(changed, Backend::Cpu, SPP);
    for (x, what) in spheres {
        let centre = glam::DVec3::new(x, 0.6, 0.0);
        let mask: Vec<bool> = pixel_quadrature(&f.scene.scene, 4, |eye, d| {
            let (o, d) = (eye.as_dvec3() - centre, d.as_dvec3().normalize());
            let b = o.dot(d);
            (b * b - (o.dot(o) - 0.36) > 0.0 && b < 0.0).then_some(0.0)
        })
        .iter()
        .map(Option::is_some)
        .collect();
        let label = format!("{}, the sphere of {what}", f.name);
        let ratio = compare(f, Backend::Cpu, &label, Some(&mask), 0.0, true, SPP);
        let sum = |p: &[[f32; 3]]| {
            p.iter()
                .zip(&mask)
                .filter(|m| *m.1)
                .flat_map(|(p, _)| p.iter().map(|&x| x as f64))
                .sum::<f64>()
        };
        let changed_ratio = sum(&changed_film.mean()) / sum(&f.reference.pixels);
        println!(
            "{label}: {} pixels, twinpath / Cycles {ratio:.4}, without the feature \
             {changed_ratio:.4}",
            mask.iter().filter(|&&m| m).count()
        );
    }
}

/// Renders fixture `f` with every material's holes ignored (opaque, as before `alphaMode` was
/// read) and asserts that Cycles' image rejects it: under 90% of pixels pass.
fn assert_opaque_rejected(f: &Fixture, name: &str) {
    let mut opaque = f.scene.clone();
    for m in &mut opaque.scene.materials {
        m.opacity = 0.0;
    }
    assert_rejected(f, &opaque, &format!("{name}, holes ignored"));
}

/// Renders `changed` (fixture `f`'s scene, changed) on the CPU and asserts that Cycles' image
/// rejects it: under 90% of pixels pass.
fn assert_rejected(f: &Fixture, changed: &SceneFile, name: &str) {
    let film = render_film(changed, Backend::Cpu, SPP);
    let t = pixel_z_test(
        &RgbImage {
            width: f.reference.width,
            height: f.reference.height,
            pixels: film.mean(),
        },
        &film.variance_of_mean(),
        &f.reference,
        Some(&f.reference_var),
        z_critical(1e-3, 3),
    );
    let mean = |p: &[[f32; 3]]| p.iter().flatten().map(|&x| x as f64).sum::<f64>();
    println!(
        "{name}: {:.2}% pass, mean ratio to Cycles {:.4}",
        100.0 * t.pass_fraction(),
        mean(&film.mean()) / mean(&f.reference.pixels)
    );
    assert!(
        t.pass_fraction() < 0.9,
        "{name}: not rejected: {:.2}% pass",
        100.0 * t.pass_fraction()
    );
}

#[test]
fn a_blender_spot_light_renders_as_cycles_renders_it_where_the_falloffs_agree() {
    let f = fixture("spot");
    let spot = f.scene.scene.lights[0];
    let axis = Vec3::from(spot.edge1).as_dvec3();
    let position = Vec3::from(spot.position).as_dvec3();
    // The light stores glTF's falloff as clamp(cos * scale + offset, 0, 1)^2.
    let (scale, offset) = (spot.edge2[0] as f64, spot.edge2[1] as f64);
    let cos_outer = -offset / scale;
    let cos_inner = cos_outer + 1.0 / scale;
    // Each pixel's floor points (y = 0) as cosines to the spot's axis; a pixel some ray of
    // which misses the floor is compared too (neither renderer lights it there).
    let cosines = |select: fn(f64, f64, f64) -> bool| -> Vec<bool> {
        pixel_quadrature(&f.scene.scene, 8, |eye, d| {
            let (eye, d) = (eye.as_dvec3(), d.as_dvec3());
            if d.y >= 0.0 {
                return Some(0.0);
            }
            let x = eye + d * (-eye.y / d.y);
            let c = (x - position).normalize().dot(axis);
            select(c, cos_inner, cos_outer).then_some(0.0)
        })
        .iter()
        .map(Option::is_some)
        .collect()
    };
    let full = cosines(|c, inner, _| c >= inner);
    let dark = cosines(|c, _, outer| c <= outer);
    let agree: Vec<bool> = full.iter().zip(&dark).map(|(a, b)| *a || *b).collect();
    let ring: Vec<bool> = agree.iter().map(|a| !a).collect();
    assert!(
        full.iter().filter(|&&x| x).count() >= 20,
        "the fixture's inner cone covers too few pixels: {} (cos inner {cos_inner}, outer {cos_outer}, axis {axis}, at {position})",
        full.iter().filter(|&&x| x).count()
    );
    for backend in [Backend::Cpu, Backend::Gpu] {
        compare(
            &f,
            backend,
            "spot (where the falloffs agree)",
            Some(&agree),
            0.0,
            false,
            SPP,
        );
        // The ring between the cones: glTF's (cos - cos_o)^2 / (cos_i - cos_o)^2 against
        // Blender's smoothstep over its blend; measured, not asserted (docs/gltf.md).
        let film = render_film(&f.scene, backend, SPP);
        let mean = film.mean();
        let sum = |px: &[[f32; 3]]| -> f64 {
            px.iter()
                .zip(&ring)
                .filter(|(_, r)| **r)
                .map(|(p, _)| p[0] as f64)
                .sum()
        };
        println!(
            "spot ({backend:?}): the ring between the cones, twinpath / Cycles = {:.3}",
            sum(&mean) / sum(&f.reference.pixels)
        );
    }
    assert_validation_clean();
}
