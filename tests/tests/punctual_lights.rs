//! Point and spot lights (`kernel::scene::light_kind::PUNCTUAL`, glTF's `KHR_lights_punctual`):
//! delta lights that next-event estimation alone finds.
//!
//! 1. A diffuse plane under a point light and a sphere light together matches its closed form
//!    per pixel on both backends: kd I cos / (pi d^2) for the point light (its irradiance; no
//!    BSDF sample can meet it, so its light sample carries MIS weight 1 under every heuristic),
//!    plus the sphere's kd L (r/D)^2 cos. A point light falling off as 1/d instead is rejected.
//! 2. A spot light follows glTF's falloff, clamp((cos - cos_outer) / (cos_inner - cos_outer),
//!    0, 1)^2, per pixel on both backends.
//! 3. glTF's lights are placed by their nodes; bad lights are errors naming the field.

use glam::Vec3;
use serde_json::json;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::gltf_writer::GltfWriter;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_film_matches, assert_film_matches_with_variance, assert_noiseless_pixels, max_abs_z,
    pixel_quadrature, render_film, scene_from_toml, variance_of_mean_from,
    with_independent_samples,
};

const KD: f32 = 0.6;
const CAMERA: &str =
    "eye = [0, 3, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 50\nwidth = 24\nheight = 18";

/// The plane y = 0 under `lights` (TOML `[[light]]` and `[[sphere]]` entries): direct light
/// only, as nothing but the plane reflects and the background is black.
fn plane(lights: &str, render: &str) -> SceneFile {
    with_independent_samples(scene_from_toml(&format!(
        "[camera]\n{CAMERA}\n[render]\n{render}\n[materials]\nplane = {{ kd = [{KD}, {KD}, {KD}] }}\nlamp = {{ emission = [5, 5, 5] }}\n[[quad]]\ncorner = [-100, 0, 100]\nedge1 = [200, 0, 0]\nedge2 = [0, 0, -200]\nmaterial = \"plane\"\n{lights}"
    )))
}

/// Each pixel's exact value: `radiance_at(x)` at the plane point x each quadrature ray meets
/// (`None` for a pixel any of whose rays misses the plane or sees the sphere light).
fn exact(scene: &SceneFile, radiance_at: impl Fn(glam::DVec3) -> Option<f64>) -> Vec<Option<f64>> {
    pixel_quadrature(&scene.scene, 16, |eye, d| {
        let t =
            kernel::geometry::intersect_sphere(eye, d, SPHERE, SPHERE_R as f32, 0.0, f32::INFINITY);
        if d.y >= 0.0 || t >= 0.0 {
            return None;
        }
        radiance_at((eye + d * (-eye.y / d.y)).as_dvec3())
    })
}

const POINT: Vec3 = Vec3::new(0.5, 1.5, 0.25);
const POINT_I: f64 = 3.0;
const SPHERE: Vec3 = Vec3::new(-1.0, 2.0, -0.5);
const SPHERE_R: f64 = 0.2;

fn point_term(x: glam::DVec3, exponent: i32) -> f64 {
    let to = POINT.as_dvec3() - x;
    let d = to.length();
    KD as f64 / std::f64::consts::PI * POINT_I * (to.y / d) / d.powi(exponent)
}

fn sphere_term(x: glam::DVec3) -> f64 {
    let to = SPHERE.as_dvec3() - x;
    let d = to.length();
    KD as f64 * 5.0 * (SPHERE_R / d).powi(2) * (to.y / d)
}

#[test]
fn a_plane_under_a_point_and_a_sphere_light_matches_its_closed_form_on_both_backends() {
    let point = format!(
        "[[light]]\nposition = [{}, {}, {}]\nintensity = [{POINT_I}, {POINT_I}, {POINT_I}]\n",
        POINT.x, POINT.y, POINT.z
    );
    let sphere = format!(
        "[[sphere]]\ncenter = [{}, {}, {}]\nradius = {SPHERE_R}\nmaterial = \"lamp\"\n",
        SPHERE.x, SPHERE.y, SPHERE.z
    );
    // The power heuristic and constant weights ("half", where the point light alone lights the
    // plane: the sphere's BSDF half would be heavy-tailed in far pixels) must all give the point
    // light weight 1; light selection by power and uniformly.
    for (render, with_sphere) in [
        ("mis = \"power\"", true),
        ("light_selection = \"uniform\"", true),
        ("mis = \"half\"", false),
    ] {
        let lights = if with_sphere {
            format!("{point}{sphere}")
        } else {
            point.clone()
        };
        let scene = plane(&lights, render);
        assert_eq!(scene.scene.lights.len(), 1 + with_sphere as usize);
        let sphere_part = |x: glam::DVec3| if with_sphere { sphere_term(x) } else { 0.0 };
        let want = exact(&scene, |x| Some(point_term(x, 2) + sphere_part(x)));
        let wrong = exact(&scene, |x| Some(point_term(x, 1) + sphere_part(x)));
        // Far pixels see the small sphere light by rare BSDF samples (under "half" they carry
        // half its light): heavy-tailed, so each pixel's variance comes from an independent
        // render with 16 times the samples.
        let mut other = scene.clone();
        other.settings.seed = 977;
        let source = render_film(&other, Backend::Cpu, 4096);
        for (backend, spp) in [(Backend::Cpu, 256), (Backend::Gpu, 256)] {
            let film = render_film(&scene, backend, spp);
            let var = variance_of_mean_from(&source, &film);
            assert_film_matches_with_variance(
                &film,
                &want,
                var.clone(),
                &format!("point + sphere, {render}, {backend:?}"),
            );
            let mean = film.mean();
            let worst = max_abs_z(&mean, &var, &wrong);
            assert!(
                worst > 20.0,
                "{render}, {backend:?}: 1/d falloff not rejected (max |z| {worst})"
            );
        }
    }
    assert_validation_clean();
}

#[test]
fn a_spot_light_follows_gltf_falloff_on_both_backends() {
    // Straight down from (0, 2, 0): inner 15 degrees, outer 35 degrees.
    let (inner, outer) = (15f64.to_radians(), 35f64.to_radians());
    let scene = plane(
        "[[light]]\nposition = [0, 2, 0]\nintensity = [4, 4, 4]\ndirection = [0, -1, 0]\ninner_angle = 15\nouter_angle = 35\n",
        "",
    );
    let falloff =
        |c: f64| (((c - outer.cos()) / (inner.cos() - outer.cos())).clamp(0.0, 1.0)).powi(2);
    let value = |x: glam::DVec3, attenuation: &dyn Fn(f64) -> f64| {
        let to = glam::DVec3::new(0.0, 2.0, 0.0) - x;
        let d = to.length();
        let cos = to.y / d;
        Some(KD as f64 / std::f64::consts::PI * 4.0 * attenuation(cos) * cos / (d * d))
    };
    // Pixels that straddle the cone's edge are left out: a few of their samples are lit, and
    // a pixel's own sample variance misses exactly the lit samples it lacks (heavy tails).
    let inside = |x: glam::DVec3| value(x, &falloff).filter(|&v| v > 0.0);
    let outside = |x: glam::DVec3| value(x, &falloff).filter(|&v| v == 0.0);
    let want: Vec<Option<f64>> = exact(&scene, inside)
        .into_iter()
        .zip(exact(&scene, outside))
        .map(|(a, b)| a.or(b))
        .collect();
    assert!(
        want.iter().flatten().filter(|v| **v == 0.0).count() > 20,
        "pixels outside the cone"
    );
    assert!(
        want.iter().flatten().filter(|v| **v > 0.0).count() > 10,
        "pixels inside the cone"
    );
    let linear = |c: f64| ((c - outer.cos()) / (inner.cos() - outer.cos())).clamp(0.0, 1.0);
    let wrong = exact(&scene, |x| value(x, &linear));
    // Pixels wholly outside the cone are exactly black (no variance to z-test them by).
    let dark: Vec<usize> = (0..want.len()).filter(|&i| want[i] == Some(0.0)).collect();
    let lit: Vec<Option<f64>> = want.iter().map(|v| v.filter(|&v| v > 0.0)).collect();
    for (backend, spp) in [(Backend::Cpu, 256), (Backend::Gpu, 256)] {
        let film = render_film(&scene, backend, spp);
        let mean = film.mean();
        for &i in &dark {
            assert_eq!(
                mean[i][0], 0.0,
                "spot, {backend:?}: pixel {i} outside the cone is lit"
            );
        }
        assert_film_matches(&film, &lit, &format!("spot, {backend:?}"));
        let var = film.variance_of_mean();
        let wrong_where_lit: Vec<Option<f64>> =
            wrong.iter().zip(&lit).map(|(w, l)| l.and(*w)).collect();
        let worst = max_abs_z(&mean, &var, &wrong_where_lit);
        assert!(
            worst > 10.0,
            "{backend:?}: an unsquared falloff not rejected (max |z| {worst})"
        );
    }
    assert_validation_clean();
}

#[test]
fn gltf_lights_are_placed_by_their_nodes_and_checked() {
    let dir = std::env::temp_dir().join(format!("twinpath-punctual-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = |lights: serde_json::Value, name: &str| {
        let mut g = GltfWriter::new();
        g.mesh(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
            None,
            None,
            &[0, 1, 2],
            None,
        );
        g.json["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        g.json["extensions"] = json!({ "KHR_lights_punctual": { "lights": lights } });
        // A parent translated to (0, 2, 0) and rotated -90 degrees about x: a child's -z (the
        // spot's axis) points down, -y.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        g.push("nodes", json!({ "mesh": 0 }));
        g.push("nodes", json!({ "translation": [0.0, 2.0, 0.0], "rotation": [-h, 0.0, 0.0, h], "children": [2, 3] }));
        g.push(
            "nodes",
            json!({ "extensions": { "KHR_lights_punctual": { "light": 0 } } }),
        );
        g.push("nodes", json!({ "translation": [1.0, 0.0, 0.0], "extensions": { "KHR_lights_punctual": { "light": 1 } } }));
        g.push("scenes", json!({ "nodes": [0, 1] }));
        let path = dir.join(name);
        std::fs::write(&path, g.glb()).unwrap();
        SceneFile::load(&path)
    };
    let scene = file(
        json!([
            { "type": "spot", "color": [1.0, 0.5, 0.25], "intensity": 8.0 * 683.0,
              "spot": { "innerConeAngle": 0.2, "outerConeAngle": 0.6 } },
            { "type": "point", "intensity": 2.0 * 683.0, "range": 10.0 }
        ]),
        "lights.glb",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.scene.lights.len(), 2);
    let (spot, point) = (scene.scene.lights[0], scene.scene.lights[1]);
    assert_eq!(spot.kind, kernel::scene::light_kind::PUNCTUAL);
    assert!((Vec3::from(spot.position) - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-6);
    assert!(
        (Vec3::from(spot.edge1) - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-6,
        "axis {:?}",
        spot.edge1
    );
    assert_eq!(spot.radiance, [8.0, 4.0, 2.0]);
    let scale = 1.0 / (0.2f32.cos() - 0.6f32.cos());
    assert!(
        (spot.edge2[0] - scale).abs() < 1e-4 * scale
            && (spot.edge2[1] + 0.6f32.cos() * scale).abs() < 1e-4 * scale
    );
    assert!((Vec3::from(point.position) - Vec3::new(1.0, 2.0, 0.0)).length() < 1e-6);
    assert_eq!(
        (point.edge2[0], point.edge2[1]),
        (0.0, 1.0),
        "a point light: no falloff"
    );
    assert!(
        scene
            .scene
            .notes
            .iter()
            .any(|n| n.contains("range ignored")),
        "{:?}",
        scene.scene.notes
    );
    assert!(
        !scene
            .scene
            .notes
            .iter()
            .any(|n| n.contains("extensions ignored")),
        "KHR_lights_punctual is read: {:?}",
        scene.scene.notes
    );
    assert!(scene.features() & kernel::features::PUNCTUAL_LIGHTS != 0);
    // Bad cones and intensities name the light.
    let e = file(json!([{ "type": "spot", "spot": { "innerConeAngle": 0.7, "outerConeAngle": 0.6 } }, { "type": "point" }]), "bad.glb")
        .unwrap_err()
        .to_string();
    assert!(e.contains("KHR_lights_punctual.lights[0]"), "{e}");
    // A directional light shines down its node's -z (here -y), colour x intensity / 683 its
    // irradiance (lux to W/m^2), from beyond the scene's bounding sphere (the triangle's: centre
    // (0.5, 0, -0.5), radius sqrt(1/2)).
    let s = file(
        json!([{ "type": "directional", "color": [1.0, 0.5, 0.5], "intensity": 3.0 * 683.0 }, { "type": "point" }]),
        "dir.glb",
    )
    .unwrap();
    assert_eq!(s.scene.lights.len(), 2);
    let d = s.scene.lights[0];
    assert_eq!(d.kind, kernel::scene::light_kind::DIRECTIONAL);
    assert!((Vec3::from(d.edge1) - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-6);
    assert_eq!(d.radiance, [3.0, 1.5, 1.5]);
    assert!((Vec3::from(d.position) - Vec3::new(0.5, 0.0, -0.5)).length() < 1e-6);
    assert!(
        (d.radius - 0.5f32.sqrt()).abs() < 1e-6,
        "radius {}",
        d.radius
    );
    assert!(
        !s.scene.notes.iter().any(|n| n.contains("directional")),
        "{:?}",
        s.scene.notes
    );

    // The other conventions of Blender's exporter, chosen by a TOML include: "unitless" takes
    // the values as W/sr and W/m^2, "raw" takes a point light's as Blender's watts (W / 4 pi
    // per steradian); a name outside the list is an error naming the field.
    let include = |glb: &str, units: &str| {
        let toml =
            format!("[camera]\n{CAMERA}\n[[gltf]]\nfile = \"{glb}\"\nlight_units = \"{units}\"\n");
        twinpath::scene::parse_scene(&toml, &dir.join("units.toml"))
    };
    let pi4 = 4.0 * std::f32::consts::PI;
    for (name, spot_i, directional_e) in [
        ("standard", 8.0, None),
        ("unitless", 8.0 * 683.0, None),
        ("raw", 8.0 * 683.0 / pi4, None),
        ("raw", 0.0, Some(3.0 * 683.0)),
    ] {
        let glb = if directional_e.is_some() {
            "dir.glb"
        } else {
            "lights.glb"
        };
        let s = include(glb, name).unwrap_or_else(|e| panic!("{e}"));
        let l = s.scene.lights[0];
        let expected = directional_e.unwrap_or(spot_i);
        assert!(
            (l.radiance[0] - expected).abs() <= 1e-6 * expected,
            "{name}: {} against {expected}",
            l.radiance[0]
        );
    }
    let e = include("lights.glb", "lumens").unwrap_err().to_string();
    assert!(
        e.contains("gltf[0].light_units") && e.contains("standard, unitless, raw"),
        "{e}"
    );
}

/// The plane y = 0 with a sphere of radius `OCCLUDER_R` above it at (0, 1, 0), under a directional
/// light of irradiance E travelling along `TRAVEL`; direct light only (`max_depth = 1`), black
/// background: each plane point gets kd E cos / pi, or nothing in the sphere's shadow.
const TRAVEL: Vec3 = Vec3::new(0.3, -1.0, 0.6);
const OCCLUDER_R: f32 = 0.7;
const E: f64 = 2.5;

#[test]
fn a_directional_light_and_its_shadow_match_the_closed_form_on_both_backends() {
    let scene = with_independent_samples(scene_from_toml(&format!(
        "[camera]\n{CAMERA}\n[render]\nmax_depth = 1\n[materials]\nplane = {{ kd = [{KD}, {KD}, {KD}] }}\n[[quad]]\ncorner = [-100, 0, 100]\nedge1 = [200, 0, 0]\nedge2 = [0, 0, -200]\nmaterial = \"plane\"\n[[sphere]]\ncenter = [0, 1, 0]\nradius = {OCCLUDER_R}\nmaterial = \"plane\"\n[[light]]\ndirection = [{}, {}, {}]\nirradiance = [{E}, {E}, {E}]\n",
        TRAVEL.x, TRAVEL.y, TRAVEL.z
    )));
    assert_eq!(scene.scene.lights.len(), 1);
    assert!(scene.scene.lights[0].radius >= 100.0, "bounds the plane");
    let toward = -TRAVEL.as_dvec3().normalize();
    let lit = KD as f64 / std::f64::consts::PI * E * toward.y;
    // Per quadrature point: the plane point, whether the sphere shadows it, or None where the
    // ray meets the sphere or misses the plane.
    let at = |eye: Vec3, d: Vec3| -> Option<bool> {
        let sphere =
            kernel::geometry::intersect_sphere(eye, d, Vec3::Y, OCCLUDER_R, 0.0, f32::INFINITY);
        if d.y >= 0.0 || sphere >= 0.0 {
            return None;
        }
        let x = (eye + d * (-eye.y / d.y)).as_dvec3();
        // The shadow ray x + s toward meets the sphere where |x + s toward - c|^2 = r^2.
        let oc = x - glam::DVec3::Y;
        let b = oc.dot(toward);
        let disc = b * b - (oc.length_squared() - (OCCLUDER_R as f64).powi(2));
        Some(disc > 0.0 && -b + disc.sqrt() > 0.0)
    };
    let shadowed = pixel_quadrature(&scene.scene, 16, |eye, d| {
        at(eye, d).map(|s| s as u8 as f64)
    });
    let want: Vec<Option<f64>> = shadowed
        .iter()
        .map(|f| f.filter(|&f| f == 0.0).map(|_| lit))
        .collect();
    let dark: Vec<usize> = (0..shadowed.len())
        .filter(|&i| shadowed[i] == Some(1.0))
        .collect();
    assert!(
        dark.len() >= 4 && want.iter().flatten().count() > want.len() / 2,
        "{} pixels in full shadow",
        dark.len()
    );
    let wrong_cos = KD as f64 / std::f64::consts::PI * E;
    for backend in [Backend::Cpu, Backend::Gpu] {
        // A lit pixel's every sample is kd E cos / pi whatever its position.
        let film = render_film(&scene, backend, 64);
        assert_noiseless_pixels(&film, &want, &format!("{backend:?}, lit"));
        let mean = film.mean();
        for &i in &dark {
            assert_eq!(
                mean[i][0], 0.0,
                "{backend:?}: pixel {i} lies in full shadow"
            );
        }
        // Irradiance without the receiver's cosine is rejected: every lit pixel is exact up to
        // its pixel footprint, so its mean is far from kd E / pi.
        let i = want.iter().position(|w| w.is_some()).unwrap();
        assert!(
            (mean[i][0] as f64 - wrong_cos).abs() > 0.05 * wrong_cos,
            "{backend:?}: {} vs kd E / pi {wrong_cos}",
            mean[i][0]
        );
    }
    assert_validation_clean();
}

#[test]
fn toml_light_errors_name_the_field() {
    let text = |light: &str| {
        format!(
            "[camera]\n{CAMERA}\n[materials]\nm = {{ kd = [0.5, 0.5, 0.5] }}\n[[light]]\n{light}\n"
        )
    };
    for (light, expected) in [
        ("position = [0, 1, 0]\nintensity = [-1, 1, 1]", "light[0].intensity"),
        ("position = [0, 1, 0]\nintensity = [1, 1, 1]\ninner_angle = 10", "give its direction"),
        ("position = [0, 1, 0]\nintensity = [1, 1, 1]\ndirection = [0, 0, 0]", "light[0].direction"),
        ("position = [0, 1, 0]\nintensity = [1, 1, 1]\ndirection = [0, -1, 0]\ninner_angle = 40\nouter_angle = 30", "below outer_angle"),
        ("position = [0, 1, 0]\nintensity = [1, 1, 1]\ndirection = [0, -1, 0]\nouter_angle = 120", "light[0].outer_angle"),
        ("direction = [0, -1, 0]\nirradiance = [1, 1, 1]\nposition = [0, 1, 0]", "a direction and an irradiance only"),
        ("irradiance = [1, 1, 1]", "needs the direction its light travels"),
        ("direction = [0, 0, 0]\nirradiance = [1, 1, 1]", "light[0].direction"),
        ("direction = [0, -1, 0]\nirradiance = [1, -1, 1]", "light[0].irradiance"),
        ("direction = [0, -1, 0]", "needs position and intensity"),
    ] {
        let e = twinpath::scene::parse_scene(&text(light), std::path::Path::new("t.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(expected), "{light}: '{e}' lacks '{expected}'");
    }
}
