//! A second set of texture coordinates (glTF's `TEXCOORD_1`, which Blender's exporter writes
//! for a mesh's second UV map): a texture whose `texCoord` is 1 reads it
//! (`texture::flags::SECOND_SET`), from a record after the triangle's others
//! (`shading_flags::SECOND_UVS`, `features::SECOND_UVS`).
//!
//! 1. The records: the second set (v flipped) after the main record and the vertex colours; a
//!    light's coordinates are its emission texture's set; a material reading set 1 on a
//!    primitive without it is an error naming the primitive.
//! 2. A Lambertian triangle under the white sky whose base colour texture (2 x 1, black and
//!    white, clamped) reads set 1, along which u runs from 1/4 to 3/4 (no clamping: the
//!    bilinear value is 2u - 1/2, linear in the barycentrics), while set 0 is (0, 0)
//!    everywhere: each pixel's exact value is the base factor times that, averaged over the
//!    pixel. Both backends match it by z-test; set 0's value (black) is rejected by far.

use kernel::scene::shading_flags;
use serde_json::json;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::gltf_writer::GltfWriter;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_film_matches, load_scene_bytes, max_abs_z, pixel_quadrature,
    plane_triangle_barycentrics, render_film, with_independent_samples,
};

const BASE: f32 = 0.9;
const P: [[f32; 3]; 3] = [[-4.0, -3.0, 0.0], [4.0, -3.0, 0.0], [0.0, 4.0, 0.0]];
/// Set 1's u at the three vertices (v is 1/2 throughout).
const U1: [f32; 3] = [0.25, 0.75, 0.5];

/// A glTF file: triangle `P` with TEXCOORD_0 (0, 0) and TEXCOORD_1 (`U1`, 1/2) (`second`:
/// whether the primitive has it), and COLOR_0 where `colours`; a Lambertian material whose
/// base colour texture reads set 1 (and, where `emissive`, which emits through the same
/// texture on set 1); a camera at (0, 0, 3) looking down -z.
fn file(second: bool, colours: bool, emissive: bool) -> Vec<u8> {
    let mut g = GltfWriter::new();
    let img = image::RgbImage::from_raw(2, 1, vec![0, 0, 0, 255, 255, 255]).unwrap();
    let mut png = std::io::Cursor::new(Vec::new());
    img.write_to(&mut png, image::ImageFormat::Png).unwrap();
    let t = g.png_texture(png.get_ref());
    let clamp = g.push("samplers", json!({ "wrapS": 33071, "wrapT": 33071 }));
    g.json["textures"][t]["sampler"] = json!(clamp);
    let mut material = json!({
        "pbrMetallicRoughness": { "baseColorFactor": [BASE, BASE, BASE, 1.0],
            "metallicFactor": 0.0, "baseColorTexture": { "index": t, "texCoord": 1 } },
        "extensions": { "KHR_materials_specular": { "specularFactor": 0.0 } }
    });
    if emissive {
        material["emissiveFactor"] = json!([1.0, 1.0, 1.0]);
        material["emissiveTexture"] = json!({ "index": t, "texCoord": 1 });
    }
    g.json["extensionsUsed"] = json!(["KHR_materials_specular"]);
    let m = g.push("materials", material);
    let mesh = g.mesh(
        &P,
        Some(&[[0.0, 0.0, 1.0]; 3]),
        Some(&[[0.0, 0.0]; 3]),
        &[0, 1, 2],
        Some(m),
    );
    if second {
        let uv1: Vec<f32> = U1.iter().flat_map(|&u| [u, 0.5]).collect();
        let a = g.floats(&uv1, "VEC2");
        g.json["meshes"][mesh]["primitives"][0]["attributes"]["TEXCOORD_1"] = json!(a);
    }
    if colours {
        let a = g.floats(&[1.0; 9], "VEC3");
        g.json["meshes"][mesh]["primitives"][0]["attributes"]["COLOR_0"] = json!(a);
    }
    g.scene_of(mesh, 3.0);
    g.glb()
}

fn load(bytes: &[u8], name: &str) -> Result<SceneFile, twinpath::scene::SceneError> {
    load_scene_bytes("sets", name, bytes)
}

#[test]
fn the_second_set_is_a_record_after_the_others_and_a_lights_coordinates() {
    for colours in [false, true] {
        let s = load(&file(true, colours, false), "records.glb").unwrap_or_else(|e| panic!("{e}"));
        let tri = s.scene.triangles[0];
        let main = s.scene.shading[tri.shading as usize];
        assert!(main.flags & shading_flags::SECOND_UVS != 0);
        assert_eq!(main.flags & shading_flags::VERTEX_COLOURS != 0, colours);
        assert_eq!(
            [main.uv0, main.uv1, main.uv2],
            [[0.0, 1.0]; 3],
            "set 0, v flipped"
        );
        let after = 1 + colours as usize;
        let rec = s.scene.shading[tri.shading as usize + after];
        assert_eq!(
            [rec.uv0, rec.uv1, rec.uv2],
            U1.map(|u| [u, 0.5]),
            "set 1, v flipped (1 - 1/2)"
        );
        assert!(s.features() & kernel::features::SECOND_UVS != 0);
        assert!(!s.scene.notes.iter().any(|n| n.contains("TEXCOORD")));
    }
    let s = load(&file(true, false, true), "light.glb").unwrap_or_else(|e| panic!("{e}"));
    let light = s.scene.lights[0];
    assert_eq!(
        light.uv,
        [U1[0], 0.5, U1[1], 0.5, U1[2], 0.5],
        "the emission texture's set"
    );
    let e = load(&file(false, false, false), "missing.glb")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("meshes[0].primitives[0]") && e.contains("TEXCOORD_1"),
        "{e}"
    );
}

#[test]
fn a_texture_on_the_second_set_reads_it_on_both_backends() {
    let mut scene = with_independent_samples(
        load(&file(true, false, false), "plane.glb").unwrap_or_else(|e| panic!("{e}")),
    );
    scene.scene.camera = scene.scene.camera.resized(Some(24), Some(18)).unwrap();
    // The red channel at the plane point each quadrature ray meets: BASE x (2 u1 - 1/2), u1
    // interpolated by the point's barycentrics (None outside the triangle); set 0 reads black.
    let value = |second: bool| {
        pixel_quadrature(&scene.scene, 8, move |eye, d| {
            let (b1, b2) = plane_triangle_barycentrics(P, eye, d)?;
            let u1 = U1[0] as f64 * (1.0 - b1 - b2) + U1[1] as f64 * b1 + U1[2] as f64 * b2;
            Some(BASE as f64 * if second { 2.0 * u1 - 0.5 } else { 0.0 })
        })
    };
    let (exact, first_set) = (value(true), value(false));
    assert!(exact.iter().filter(|e| e.is_some()).count() > 100);
    for backend in [Backend::Cpu, Backend::Gpu] {
        let film = render_film(&scene, backend, 256);
        assert_film_matches(&film, &exact, &format!("{backend:?}"));
        let wrong = max_abs_z(&film.mean(), &film.variance_of_mean(), &first_set);
        assert!(
            wrong > 20.0,
            "{backend:?}: set 0 read instead not rejected ({wrong})"
        );
    }
    assert_validation_clean();
}
