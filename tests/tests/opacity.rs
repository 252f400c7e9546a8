//! Surfaces with holes (glTF's `alphaMode`, `kernel::opacity`): a MASK cuts the surface where
//! its base colour's alpha is below `alphaCutoff`, a BLEND is there with probability alpha, on
//! camera rays, bounce rays and shadow rays, through world-space and instanced triangles, on
//! both backends (the CPU's leaf test, the GPU's any-hit shaders).
//!
//! 1. The materials: each alphaMode onto `Material::opacity`, the feature bit, the notes.
//! 2. A MASK in closed form: a black plane whose base colour texture (2 x 1 texels, alpha 0 and
//!    200/255, clamped) fades in along u, cut at 0.3, in front of the white sky. The alpha is
//!    linear (never sRGB-decoded) and bilinear, so the plane is there exactly right of
//!    u* = 1/4 + 0.15 x 255/200; a pixel shows the sky on the fraction of it left of that line
//!    (the plane faces the film, so a pixel's x maps affinely onto the plane). Pixels wholly on
//!    one side are noiseless (0 or 1, exactly); the others are z-tested. The sRGB-decoded
//!    alpha's line, 6 pixels to the right, is rejected.
//! 3. A BLEND in closed form, through instances and on shadow rays: a white Lambertian floor
//!    (albedo rho) under two black planes of alpha a (one mesh placed twice: instances), lit by
//!    the white sky and a directional light straight down of irradiance pi: every floor pixel
//!    is rho (1 - a)^2 (1 + pi / pi), for the layers' transmittance is (1 - a)^2 whatever the
//!    direction (`kernel::opacity`'s derivation). One layer's (1 - a) and opaque layers' 0 are
//!    rejected. The GPU renders it specialized and generic (every hit group with its any-hit
//!    shader).
//! 4. Emitters with holes: a light's samples carry its coverage (`opacity::coverage`), a hit
//!    finds it where it is there, under the same MIS weights. A black BLEND emitter of alpha
//!    1/2 over a white floor (no sky: a TOML scene including the file) lights the floor as an
//!    opaque one of half its emission does; a MASK emitter whose texture's alpha cuts it at
//!    u = 1/2 as an opaque emitter of its left half. Per-pixel z-tests of the two renders, on
//!    both backends; the holes ignored (the full emission, the whole square) rejected.

use glam::Vec3;
use serde_json::{json, Value};
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::gltf_writer::GltfWriter;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_film_matches, assert_noiseless_pixels, load_scene_bytes, max_abs_z, render_film,
    with_independent_samples,
};

/// The MASK's cutoff and the texture's second alpha byte.
const CUTOFF: f64 = 0.3;
const ALPHA_BYTE: u8 = 200;

fn load(bytes: &[u8], name: &str) -> SceneFile {
    load_scene_bytes("opacity", name, bytes).unwrap_or_else(|e| panic!("{e}"))
}

/// A material that reflects nothing (base colour black, metallic 0, specular factor 0) with
/// `extra` merged in.
fn black(extra: Value) -> Value {
    let mut m = json!({
        "pbrMetallicRoughness": { "baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0 },
        "extensions": { "KHR_materials_specular": { "specularFactor": 0.0 } }
    });
    for (k, v) in extra.as_object().unwrap() {
        if k == "pbrMetallicRoughness" {
            for (k2, v2) in v.as_object().unwrap() {
                m[k][k2] = v2.clone();
            }
        } else {
            m[k] = v.clone();
        }
    }
    m
}

/// A square of side 2 `half` at z = 0 facing +z, `n` x `n` quads (uv from 0 to 1 across it).
fn square(g: &mut GltfWriter, half: f32, n: u32, material: usize) -> usize {
    let (mut p, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..=n {
        for i in 0..=n {
            let (s, t) = (i as f32 / n as f32, j as f32 / n as f32);
            p.push([-half + 2.0 * half * s, -half + 2.0 * half * t, 0.0]);
            // glTF's v runs down the image.
            uv.push([s, 1.0 - t]);
        }
    }
    for j in 0..n {
        for i in 0..n {
            let k = j * (n + 1) + i;
            idx.extend([k, k + 1, k + n + 2, k, k + n + 2, k + n + 1]);
        }
    }
    let normals = vec![[0.0, 0.0, 1.0]; p.len()];
    g.mesh(&p, Some(&normals), Some(&uv), &idx, Some(material))
}

/// Adds a perspective camera node at height `z` looking down -z; its node index.
fn camera(g: &mut GltfWriter, z: f32) -> usize {
    let cam = g.push(
        "cameras",
        json!({ "name": "camera", "type": "perspective",
                "perspective": { "yfov": 0.9, "aspectRatio": 1.3333, "znear": 0.01 } }),
    );
    g.push(
        "nodes",
        json!({ "camera": cam, "translation": [0.0, 0.0, z] }),
    )
}

/// The MASK scene of the module's item 2: the plane spans [-2, 2]^2 (so the view from the
/// camera's height 1.35, about 1.7 x 1.3 wide, lies inside it), its texture fading in along u.
fn mask_file() -> Vec<u8> {
    let mut g = GltfWriter::new();
    g.json["extensionsUsed"] = json!(["KHR_materials_specular"]);
    let img = image::RgbaImage::from_raw(2, 1, vec![0, 0, 0, 0, 0, 0, 0, ALPHA_BYTE]).unwrap();
    let mut png = std::io::Cursor::new(Vec::new());
    img.write_to(&mut png, image::ImageFormat::Png).unwrap();
    let t = g.png_texture(png.get_ref());
    let clamp = g.push("samplers", json!({ "wrapS": 33071, "wrapT": 33071 }));
    g.json["textures"][t]["sampler"] = json!(clamp);
    let m = g.push(
        "materials",
        black(json!({
            "pbrMetallicRoughness": { "baseColorTexture": { "index": t } },
            "alphaMode": "MASK", "alphaCutoff": CUTOFF
        })),
    );
    let mesh = square(&mut g, 2.0, 1, m);
    let plane = g.push("nodes", json!({ "mesh": mesh }));
    let cam = camera(&mut g, 1.35);
    g.push("scenes", json!({ "nodes": [plane, cam] }));
    g.glb()
}

/// The BLEND scene of the module's item 3: floor at z = 0 (albedo `RHO`), two layers of the
/// same 18-triangle mesh (instanced) of alpha `A` at z = 1 and 1.5, all 2 x 10^4 wide, a
/// directional light straight down of pi x 683 lux (irradiance pi W/m^2 in standard units),
/// the camera at z = 0.5.
const RHO: f64 = 0.5;
const A: f64 = 0.4;
fn blend_file() -> Vec<u8> {
    let mut g = GltfWriter::new();
    g.json["extensionsUsed"] = json!(["KHR_materials_specular", "KHR_lights_punctual"]);
    let floor_m = g.push(
        "materials",
        black(json!({ "pbrMetallicRoughness": { "baseColorFactor": [RHO, RHO, RHO, 1.0] } })),
    );
    let layer_m = g.push(
        "materials",
        black(json!({
            "pbrMetallicRoughness": { "baseColorFactor": [0.0, 0.0, 0.0, A] },
            "alphaMode": "BLEND"
        })),
    );
    let floor = square(&mut g, 1e4, 1, floor_m);
    let layer = square(&mut g, 1e4, 3, layer_m);
    g.json["extensions"] = json!({ "KHR_lights_punctual": { "lights": [
        { "type": "directional", "intensity": std::f64::consts::PI * 683.0 }
    ] } });
    let mut nodes = vec![
        g.push("nodes", json!({ "mesh": floor })),
        g.push(
            "nodes",
            json!({ "mesh": layer, "translation": [0.0, 0.0, 1.0] }),
        ),
        g.push(
            "nodes",
            json!({ "mesh": layer, "translation": [0.0, 0.0, 1.5] }),
        ),
        // glTF's lights shine down their node's -z.
        g.push(
            "nodes",
            json!({ "extensions": { "KHR_lights_punctual": { "light": 0 } } }),
        ),
    ];
    nodes.push(camera(&mut g, 0.5));
    g.push("scenes", json!({ "nodes": nodes }));
    g.glb()
}

#[test]
fn alpha_modes_become_the_materials_opacity() {
    let cases = [
        (json!({}), 0.0),
        (json!({ "alphaMode": "OPAQUE", "alphaCutoff": 0.7 }), 0.0),
        (json!({ "alphaMode": "MASK" }), 0.5),
        (
            json!({ "alphaMode": "MASK", "alphaCutoff": 0.3,
                    "pbrMetallicRoughness": { "baseColorFactor": [1.0, 1.0, 1.0, 0.6] } }),
            0.5,
        ),
        (json!({ "alphaMode": "MASK", "alphaCutoff": 0.0 }), 0.0),
        (
            json!({ "alphaMode": "MASK",
                    "pbrMetallicRoughness": { "baseColorFactor": [1.0, 1.0, 1.0, 0.0] } }),
            2.0,
        ),
        (
            json!({ "alphaMode": "BLEND",
                    "pbrMetallicRoughness": { "baseColorFactor": [1.0, 1.0, 1.0, 0.4] } }),
            -0.4,
        ),
        (json!({ "alphaMode": "BLEND" }), 0.0),
        (
            json!({ "alphaMode": "BLEND",
                    "pbrMetallicRoughness": { "baseColorFactor": [1.0, 1.0, 1.0, 0.0] } }),
            2.0,
        ),
    ];
    for (extra, want) in cases {
        let mut g = GltfWriter::new();
        g.json["extensionsUsed"] = json!(["KHR_materials_specular"]);
        let m = g.push("materials", black(extra.clone()));
        let mesh = square(&mut g, 1.0, 1, m);
        let node = g.push("nodes", json!({ "mesh": mesh }));
        g.push("scenes", json!({ "nodes": [node] }));
        let s = load(&g.glb(), "modes.glb");
        let got = s.scene.materials[0].opacity;
        assert!(
            (got - want).abs() < 1e-6,
            "{extra}: opacity {got}, want {want}"
        );
        let bit = s.features() & kernel::features::OPACITY != 0;
        assert_eq!(bit, want != 0.0, "{extra}: the OPACITY bit");
        assert!(
            !s.scene.notes.iter().any(|n| n.contains("alphaMode")),
            "{extra}"
        );
    }
    // A negative cutoff is an error naming the field.
    let mut g = GltfWriter::new();
    let m = g.push(
        "materials",
        json!({ "alphaMode": "MASK", "alphaCutoff": -0.5 }),
    );
    let mesh = square(&mut g, 1.0, 1, m);
    let node = g.push("nodes", json!({ "mesh": mesh }));
    g.push("scenes", json!({ "nodes": [node] }));
    let e = load_scene_bytes("opacity", "negative.glb", &g.glb())
        .unwrap_err()
        .to_string();
    assert!(e.contains("alphaCutoff"), "{e}");
    // An emitter keeps its holes, and its lights name their material.
    let mut g = GltfWriter::new();
    let m = g.push(
        "materials",
        json!({ "alphaMode": "BLEND", "emissiveFactor": [1.0, 1.0, 1.0],
                "pbrMetallicRoughness": { "baseColorFactor": [1.0, 1.0, 1.0, 0.5] } }),
    );
    let mesh = square(&mut g, 1.0, 1, m);
    let node = g.push("nodes", json!({ "mesh": mesh }));
    g.push("scenes", json!({ "nodes": [node] }));
    let s = load(&g.glb(), "emitter.glb");
    assert_eq!(s.scene.materials[0].opacity, -0.5);
    assert!(s.scene.lights.iter().all(|l| l.material == 0));
    assert!(!s.scene.notes.iter().any(|n| n.contains("alphaMode")));
}

/// The plane's x where a ray from `eye` along `d` meets z = 0.
fn plane_x(eye: Vec3, d: Vec3) -> f64 {
    eye.x as f64 + d.x as f64 * (-eye.z as f64 / d.z as f64)
}

/// Per pixel, the fraction of its area whose ray meets the plane left of x = `x_cut` (the
/// MASK's hole, which shows the white sky), as `(value, noiseless)`.
fn sky_fraction(scene: &twinpath::scene::Scene, x_cut: f64) -> Vec<(f64, bool)> {
    let cam = scene.camera.to_kernel();
    let (w, h) = (scene.camera.width, scene.camera.height);
    let eye = Vec3::new(cam.eye[0], cam.eye[1], cam.eye[2]);
    (0..w * h)
        .map(|i| {
            let (px, py) = (i % w, i / w);
            let x = |u: f32| {
                plane_x(
                    eye,
                    kernel::camera::camera_ray_direction(&cam, w, h, px, py, u, 0.5),
                )
            };
            let (x0, x1) = (x(0.0), x(1.0));
            assert!(x1 > x0);
            let f = ((x_cut - x0) / (x1 - x0)).clamp(0.0, 1.0);
            (f, f == 0.0 || f == 1.0)
        })
        .collect()
}

#[test]
fn a_mask_cuts_the_plane_where_the_linear_alpha_is_below_the_cutoff_on_both_backends() {
    let mut scene = with_independent_samples(load(&mask_file(), "mask.glb"));
    scene.scene.camera = scene.scene.camera.resized(Some(48), Some(36)).unwrap();
    assert!(scene.features() & kernel::features::OPACITY != 0);
    // u* along the plane (u = (x + 2) / 4): alpha(u) = clamp(2u - 1/2, 0, 1) x byte / 255.
    let cut = |alpha: f64| 4.0 * (0.25 + 0.5 * CUTOFF / alpha) - 2.0;
    let linear = sky_fraction(&scene.scene, cut(ALPHA_BYTE as f64 / 255.0));
    let srgb = sky_fraction(
        &scene.scene,
        cut(twinpath::scene::textures::srgb_to_linear(ALPHA_BYTE)),
    );
    let noiseless: Vec<Option<f64>> = linear.iter().map(|&(f, n)| n.then_some(f)).collect();
    let noisy: Vec<Option<f64>> = linear.iter().map(|&(f, n)| (!n).then_some(f)).collect();
    let wrong: Vec<Option<f64>> = srgb.iter().map(|&(f, _)| Some(f)).collect();
    assert!(noiseless.iter().flatten().any(|&f| f == 0.0));
    assert!(noiseless.iter().flatten().any(|&f| f == 1.0));
    assert!(noisy.iter().flatten().count() >= 36);
    for backend in [Backend::Cpu, Backend::Gpu] {
        let film = render_film(&scene, backend, 256);
        assert_noiseless_pixels(&film, &noiseless, &format!("{backend:?}"));
        assert_film_matches(&film, &noisy, &format!("{backend:?} boundary"));
        let mean = film.mean();
        let off = wrong
            .iter()
            .enumerate()
            .filter(|(i, w)| (mean[*i][0] as f64 - w.unwrap()).abs() > 0.5)
            .count();
        assert!(
            off >= 36 * 4,
            "{backend:?}: sRGB-decoded alpha not rejected ({off} pixels off)"
        );
    }
    assert_validation_clean();
}

#[test]
fn blended_instanced_layers_transmit_one_minus_alpha_each_on_both_backends() {
    let mut scene = with_independent_samples(load(&blend_file(), "blend.glb"));
    scene.scene.camera = scene.scene.camera.resized(Some(24), Some(18)).unwrap();
    assert_eq!(
        scene.scene.instances.len(),
        2,
        "the layers are one mesh, placed twice"
    );
    let pixels = 24 * 18;
    let value = |t: f64| vec![Some(RHO * t * 2.0); pixels];
    let exact = value((1.0 - A) * (1.0 - A));
    for (backend, specialize) in [
        (Backend::Cpu, true),
        (Backend::Gpu, true),
        (Backend::Gpu, false),
    ] {
        let mut s = scene.clone();
        s.settings.specialize = specialize;
        let label = format!("{backend:?} specialize {specialize}");
        let film = render_film(&s, backend, 512);
        assert_film_matches(&film, &exact, &label);
        // The wrong answers fail the test the right one passes: some pixel beyond the same
        // Sidak-corrected bound (the test has the power to tell them apart; measured 19.8 and
        // more, against a bound of 4.7).
        let (mean, var) = (film.mean(), film.variance_of_mean());
        let bound = twinpath_tests::z_critical(1e-3, pixels);
        for (wrong, what) in [(1.0 - A, "one layer"), (0.0, "opaque layers")] {
            let z = max_abs_z(&mean, &var, &value(wrong));
            println!("{label}: {what}: max |z| {z:.1} (rejected beyond {bound:.2})");
            assert!(z > bound, "{label}: {what} not rejected ({z})");
        }
    }
    assert_validation_clean();
}

/// A white Lambertian floor (8 wide, z = 0: the camera sees a 0.6-wide part of it, and nothing
/// else in the scene reflects) under a square emitting downward from its front face alone at
/// z = 1 (black, emissive strength `strength`, `half` its half-width in x,
/// its centre at x = `centre`; `extra` adds to its material, given the writer to add a texture
/// to), the camera at z = 0.5 looking down; as a TOML scene including the file (black
/// background), 24 x 18 pixels.
fn emitter_scene(
    name: &str,
    strength: f32,
    half: f32,
    centre: f32,
    extra: impl FnOnce(&mut GltfWriter) -> Value,
) -> SceneFile {
    let mut g = GltfWriter::new();
    g.json["extensionsUsed"] = json!(["KHR_materials_specular", "KHR_materials_emissive_strength"]);
    let floor_m = g.push(
        "materials",
        black(json!({ "pbrMetallicRoughness": { "baseColorFactor": [1.0, 1.0, 1.0, 1.0] } })),
    );
    let mut lamp = black(extra(&mut g));
    lamp["emissiveFactor"] = json!([1.0, 1.0, 1.0]);
    lamp["extensions"]["KHR_materials_emissive_strength"] = json!({ "emissiveStrength": strength });
    lamp["doubleSided"] = json!(false);
    let lamp_m = g.push("materials", lamp);
    // Not 10^4 wide: a hit point's error bound is isotropic and grows with the triangle's
    // coordinates, so on such a floor paths leave 0.02 above it and the lamp's BSDF-sampled
    // light is 2% too bright (docs/robustness.md, "Known limits"), which the MIS weights of the
    // two lamps compared here would weigh differently.
    let floor = square(&mut g, 4.0, 1, floor_m);
    let lamp_mesh = square(&mut g, 1.0, 1, lamp_m);
    let nodes = vec![
        g.push("nodes", json!({ "mesh": floor })),
        // Half a turn about x: the square's front face (+z) looks down; its u still runs along
        // x, from x = centre - half to centre + half.
        g.push(
            "nodes",
            json!({ "mesh": lamp_mesh, "translation": [centre, 0.0, 1.0],
                    "rotation": [1.0, 0.0, 0.0, 0.0], "scale": [half, 1.0, 1.0] }),
        ),
        camera(&mut g, 0.5),
    ];
    g.push("scenes", json!({ "nodes": nodes }));
    let dir = std::env::temp_dir().join(format!("twinpath-opacity-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(format!("{name}.glb")), g.glb()).unwrap();
    let toml = format!(
        "[camera]\ngltf = \"camera\"\nwidth = 24\nheight = 18\n[[gltf]]\nfile = \"{name}.glb\"\n"
    );
    with_independent_samples(
        twinpath::scene::parse_scene(&toml, &dir.join(format!("{name}.toml")))
            .unwrap_or_else(|e| panic!("{e}")),
    )
}

/// Asserts that renders `a` and `b` agree per pixel (99.5% within the z bound, as `cycles.rs`
/// compares) and in their means, on both backends, and that `wrong` disagrees with `a`.
fn assert_same_light(a: &SceneFile, b: &SceneFile, wrong: &SceneFile, label: &str) {
    use twinpath::film::{Film, RgbImage};
    use twinpath_tests::stats::pixel_z_test;
    use twinpath_tests::{image_mean_z, z_critical};
    let image = |f: &Film| RgbImage {
        width: 24,
        height: 18,
        pixels: f.mean(),
    };
    for backend in [Backend::Cpu, Backend::Gpu] {
        let fa = render_film(a, backend, 1024);
        let against = |f: &Film| {
            pixel_z_test(
                &image(&fa),
                &fa.variance_of_mean(),
                &image(f),
                Some(&f.variance_of_mean()),
                z_critical(1e-3, 3),
            )
        };
        let fb = render_film(b, backend, 1024);
        let same = against(&fb);
        let mean_z = image_mean_z(&fa, &fb);
        let other = against(&render_film(wrong, backend, 1024));
        println!(
            "{label} {backend:?}: {:.2}% of pixels pass, image means z {mean_z:+.2}; holes \
             ignored: {:.2}% pass",
            100.0 * same.pass_fraction(),
            100.0 * other.pass_fraction()
        );
        assert!(same.pass_fraction() >= 0.995, "{label} {backend:?}");
        assert!(mean_z.abs() < z_critical(1e-3, 1), "{label} {backend:?}");
        assert!(
            other.pass_fraction() < 0.5,
            "{label} {backend:?}: holes ignored not rejected"
        );
    }
    assert_validation_clean();
}

#[test]
fn emitters_with_holes_light_as_their_coverage_on_both_backends() {
    // BLEND alpha 1/2 at strength 4 against opaque at strength 2 (wrong: opaque at 4).
    let blend = |_: &mut GltfWriter| {
        json!({ "pbrMetallicRoughness": { "baseColorFactor": [0.0, 0.0, 0.0, 0.5] },
                "alphaMode": "BLEND" })
    };
    let a = emitter_scene("lamp_blend", 4.0, 1.0, 0.0, blend);
    assert!(a.features() & kernel::features::OPACITY != 0);
    let b = emitter_scene("lamp_half", 2.0, 1.0, 0.0, |_| json!({}));
    let wrong = emitter_scene("lamp_full", 4.0, 1.0, 0.0, |_| json!({}));
    assert_same_light(&a, &b, &wrong, "BLEND emitter");
    // MASK: alpha 1 then 0 along u (2 x 1 texels, clamped), cut at 1/2: exactly the left half
    // (x < 0) is there; against an opaque square over x in [-1, 0] (wrong: the whole square).
    let mask = |g: &mut GltfWriter| {
        let img = image::RgbaImage::from_raw(2, 1, vec![0, 0, 0, 255, 0, 0, 0, 0]).unwrap();
        let mut png = std::io::Cursor::new(Vec::new());
        img.write_to(&mut png, image::ImageFormat::Png).unwrap();
        let t = g.png_texture(png.get_ref());
        let clamp = g.push("samplers", json!({ "wrapS": 33071, "wrapT": 33071 }));
        g.json["textures"][t]["sampler"] = json!(clamp);
        json!({ "pbrMetallicRoughness": { "baseColorTexture": { "index": t } },
                "alphaMode": "MASK", "alphaCutoff": 0.5 })
    };
    let a = emitter_scene("lamp_mask", 4.0, 1.0, 0.0, mask);
    let b = emitter_scene("lamp_left", 4.0, 0.5, -0.5, |_| json!({}));
    assert_same_light(&a, &b, &wrong, "MASK emitter");
}

/// The CPU's packets of sixteen paths pass through holes as one path at a time does (each
/// lane's candidates asked of its own ray, `cpu/packet_presence.rs`): the MASK plane, the
/// instanced BLEND layers under the directional light (shadow segments through both layers)
/// and the BLEND emitter render the same films, bit for bit, with packets on and off.
#[test]
fn packets_through_holes_give_the_one_path_images() {
    let small = |mut s: SceneFile| {
        s.scene.camera = s.scene.camera.resized(Some(24), Some(18)).unwrap();
        s
    };
    let blend = |_: &mut GltfWriter| {
        json!({ "pbrMetallicRoughness": { "baseColorFactor": [0.0, 0.0, 0.0, 0.5] },
                "alphaMode": "BLEND" })
    };
    let scenes = [
        ("MASK plane", small(load(&mask_file(), "mask_packets.glb"))),
        (
            "instanced BLEND layers",
            small(load(&blend_file(), "blend_packets.glb")),
        ),
        (
            "BLEND emitter",
            emitter_scene("lamp_blend_packets", 4.0, 1.0, 0.0, blend),
        ),
    ];
    for (name, scene) in scenes {
        twinpath_tests::assert_bvh_packets_give_the_one_path_image(name, &scene, 16, "holes");
    }
}
