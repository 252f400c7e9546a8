//! Lights that also reflect (glTF's emissive materials, which keep their base colour as a
//! Principled BSDF with emission does in Blender; TOML's `emission` + `kd`): a path that finds
//! one adds its emission and goes on (`features::REFLECTING_LIGHTS`, `Material::reflects`).
//!
//! Inside a closed box whose six walls all emit Le from both faces and reflect diffusely with
//! albedo rho, every wall sees only walls, so the radiance is the same everywhere and
//! L = Le + rho L: L = Le / (1 - rho) in every pixel (the white furnace with emission). Each
//! pixel's mean is z-tested against it on both backends; the same images read as Le (lights
//! that end the path, as before) are rejected by far. glTF's emissive material keeps its base
//! colour and its specular layer.

use serde_json::json;
use std::path::Path;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::gltf_writer::GltfWriter;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_film_matches, max_abs_z, render_film, scene_from_toml, with_independent_samples,
};

const LE: f64 = 0.5;
const RHO: f64 = 0.6;

/// The unit box [0, 1]^3 as six two-sided quads of material "wall", seen from inside.
fn glowing_box() -> SceneFile {
    let quads = [
        ([0, 0, 0], [1, 0, 0], [0, 1, 0]),
        ([0, 0, 1], [1, 0, 0], [0, 1, 0]),
        ([0, 0, 0], [0, 1, 0], [0, 0, 1]),
        ([1, 0, 0], [0, 1, 0], [0, 0, 1]),
        ([0, 0, 0], [1, 0, 0], [0, 0, 1]),
        ([0, 1, 0], [1, 0, 0], [0, 0, 1]),
    ];
    let mut text = format!(
        "[camera]\neye = [0.3, 0.4, 0.8]\nlook_at = [0.9, 0.6, 0.1]\nup = [0, 1, 0]\nvfov = 80\n\
         width = 16\nheight = 12\n[materials]\nwall = {{ kd = [{RHO}, {RHO}, {RHO}], emission = \
         [{LE}, {LE}, {LE}], two_sided = true }}\n"
    );
    for (corner, e1, e2) in quads {
        text += &format!(
            "[[quad]]\ncorner = {corner:?}\nedge1 = {e1:?}\nedge2 = {e2:?}\nmaterial = \"wall\"\n"
        );
    }
    with_independent_samples(scene_from_toml(&text))
}

#[test]
fn a_box_of_glowing_diffuse_walls_reads_le_over_one_minus_rho_on_both_backends() {
    let scene = glowing_box();
    assert!(scene.features() & kernel::features::REFLECTING_LIGHTS != 0);
    let n = (scene.scene.camera.width * scene.scene.camera.height) as usize;
    let exact = vec![Some(LE / (1.0 - RHO)); n];
    let ends_at_the_light = vec![Some(LE); n];
    for backend in [Backend::Cpu, Backend::Gpu] {
        let film = render_film(&scene, backend, 512);
        assert_eq!(film.discarded, 0);
        let z = assert_film_matches(&film, &exact, &format!("{backend:?}"));
        let wrong = max_abs_z(&film.mean(), &film.variance_of_mean(), &ends_at_the_light);
        println!("{backend:?}: overall z {z:+.2}; reading Le instead: max |z| {wrong:.0}");
        assert!(
            wrong > 50.0,
            "{backend:?}: lights that end the path not rejected"
        );
    }
    assert_validation_clean();
}

#[test]
fn a_gltf_emissive_material_keeps_its_base_colour_and_specular_layer() {
    let mut g = GltfWriter::new();
    let m = g.push(
        "materials",
        json!({ "pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.25, 0.125, 1.0],
                "metallicFactor": 0.0 },
                "emissiveFactor": [1.0, 1.0, 1.0], "doubleSided": true }),
    );
    let mesh = g.mesh(
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        None,
        None,
        &[0, 1, 2],
        Some(m),
    );
    g.push("nodes", json!({ "mesh": mesh }));
    g.push("scenes", json!({ "nodes": [0] }));
    let scene =
        twinpath::scene::gltf::load_bytes(Path::new("emissive.glb"), &g.glb(), None, None).unwrap();
    let material = scene.materials[0];
    assert_eq!(
        material.kind,
        kernel::scene::material_kind::METALLIC_ROUGHNESS
    );
    assert_eq!(material.albedo, [0.5, 0.25, 0.125]);
    assert_eq!(material.emission, [1.0; 3]);
    let triangle_lights = scene
        .lights
        .iter()
        .filter(|l| l.kind == kernel::scene::light_kind::TRIANGLE)
        .count();
    assert_eq!(triangle_lights, 1, "its triangle is a light");
    assert!(
        scene
            .lights
            .iter()
            .filter(|l| l.kind == kernel::scene::light_kind::TRIANGLE)
            .all(|l| l.two_sided == 1),
        "doubleSided: both faces emit"
    );
    assert!(material.reflects());
    assert!(
        scene.notes.iter().all(|n| !n.contains("base colour")),
        "{:?}",
        scene.notes
    );
}
