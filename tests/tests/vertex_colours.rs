//! Vertex colours (glTF's `COLOR_0`, which Blender's exporter writes for a Color Attribute that
//! drives the base colour): they multiply the base colour, interpolated across each triangle
//! like the normals (`ShadingTriangle::vertex_colours`, `features::VERTEX_COLOURS`).
//!
//! 1. The records: float VEC3 and normalised-byte VEC4 colours read alike (alpha dropped), the
//!    colour record after the tangent frame of a normal-mapped material, out-of-range colours an
//!    error naming the accessor.
//! 2. A Lambertian triangle (metallic 0, `KHR_materials_specular` factor 0) under the uniform
//!    white sky a glTF file alone is lit by reflects its albedo: each pixel's exact value is
//!    base x the interpolated colour, averaged over the pixel. Both backends match it by
//!    z-test; the same images against the base colour alone (colours ignored) fail by far.

use glam::DVec3;
use kernel::scene::{shading_flags, texture_slot, NONE};
use serde_json::json;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::gltf_writer::GltfWriter;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_film_matches, load_scene_bytes, max_abs_z, pixel_quadrature,
    plane_triangle_barycentrics, render_film, with_independent_samples,
};

const BASE: [f32; 3] = [0.9, 0.8, 0.7];
const P: [[f32; 3]; 3] = [[-4.0, -3.0, 0.0], [4.0, -3.0, 0.0], [0.0, 4.0, 0.0]];
const C: [[f32; 3]; 3] = [[0.9, 0.2, 0.1], [0.1, 0.8, 0.3], [0.5, 0.3, 0.7]];

/// A glTF file: one triangle `P` with `COLOR_0` (given by `colour`, which adds the accessor and
/// returns its index), a Lambertian metallic-roughness material (with a normal map where
/// `normal_map`), a camera at (0, 0, 3) looking down -z.
fn file(colour: impl Fn(&mut GltfWriter) -> usize, normal_map: bool) -> Vec<u8> {
    let mut g = GltfWriter::new();
    let mut material = json!({
        "pbrMetallicRoughness": { "baseColorFactor": [BASE[0], BASE[1], BASE[2], 1.0],
            "metallicFactor": 0.0 },
        "extensions": { "KHR_materials_specular": { "specularFactor": 0.0 } }
    });
    if normal_map {
        let flat = image::RgbImage::from_pixel(2, 2, image::Rgb([128, 128, 255]));
        let mut png = std::io::Cursor::new(Vec::new());
        flat.write_to(&mut png, image::ImageFormat::Png).unwrap();
        let t = g.png_texture(png.get_ref());
        material["normalTexture"] = json!({ "index": t });
    }
    g.json["extensionsUsed"] = json!(["KHR_materials_specular"]);
    let m = g.push("materials", material);
    let uvs = [[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]];
    let mesh = g.mesh(
        &P,
        Some(&[[0.0, 0.0, 1.0]; 3]),
        Some(&uvs),
        &[0, 1, 2],
        Some(m),
    );
    let a = colour(&mut g);
    g.json["meshes"][mesh]["primitives"][0]["attributes"]["COLOR_0"] = json!(a);
    g.scene_of(mesh, 3.0);
    g.glb()
}

fn float_colours(g: &mut GltfWriter) -> usize {
    g.floats(&C.concat(), "VEC3")
}

fn byte_colours(g: &mut GltfWriter) -> usize {
    let bytes: Vec<u8> = C
        .iter()
        .flat_map(|c| [c[0], c[1], c[2], 1.0].map(|x| (x * 255.0).round() as u8))
        .collect();
    let view = g.view(&bytes);
    g.push(
        "accessors",
        json!({ "bufferView": view, "componentType": 5121, "normalized": true, "count": 3,
                "type": "VEC4" }),
    )
}

fn load(bytes: &[u8], name: &str) -> Result<SceneFile, twinpath::scene::SceneError> {
    load_scene_bytes("colours", name, bytes)
}

#[test]
fn vertex_colours_are_read_into_a_record_after_the_tangent_frame() {
    for (colour, tolerance) in [
        (float_colours as fn(&mut GltfWriter) -> usize, 0.0),
        (byte_colours, 1.0 / 255.0),
    ] {
        for normal_map in [false, true] {
            let s =
                load(&file(colour, normal_map), "records.glb").unwrap_or_else(|e| panic!("{e}"));
            let tri = s.scene.triangles[0];
            let main = s.scene.shading[tri.shading as usize];
            assert_eq!(
                main.flags,
                shading_flags::NORMALS | shading_flags::VERTEX_COLOURS
            );
            let mapped = s.scene.materials[0].textures[texture_slot::NORMAL] != NONE;
            assert_eq!(mapped, normal_map);
            let after = if mapped { 2 } else { 1 };
            let rec = s.scene.shading[tri.shading as usize + after];
            for (got, want) in [rec.normal0, rec.normal1, rec.normal2].iter().zip(&C) {
                for c in 0..3 {
                    assert!(
                        (got[c] - want[c]).abs() <= tolerance,
                        "{got:?} against {want:?}"
                    );
                }
            }
            assert!(s.features() & kernel::features::VERTEX_COLOURS != 0);
        }
    }
    let e = load(
        &file(
            |g| {
                g.floats(
                    &[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0; 3]].concat(),
                    "VEC3",
                )
            },
            false,
        ),
        "bad.glb",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("accessors[") && e.contains("0..=1"), "{e}");
}

#[test]
fn vertex_colours_multiply_the_base_colour_on_both_backends() {
    let mut scene =
        with_independent_samples(load(&file(float_colours, false), "plane.glb").unwrap());
    scene.scene.camera = scene.scene.camera.resized(Some(24), Some(18)).unwrap();
    // The red channel at the plane point each quadrature ray meets: base x the colour
    // interpolated by the point's barycentrics in the triangle (None outside it).
    let value = |with_colours: bool| {
        pixel_quadrature(&scene.scene, 8, move |eye, d| {
            let (b1, b2) = plane_triangle_barycentrics(P, eye, d)?;
            let c = DVec3::from(C[0].map(f64::from)) * (1.0 - b1 - b2)
                + DVec3::from(C[1].map(f64::from)) * b1
                + DVec3::from(C[2].map(f64::from)) * b2;
            Some(BASE[0] as f64 * if with_colours { c.x } else { 1.0 })
        })
    };
    let (exact, ignored) = (value(true), value(false));
    assert!(exact.iter().filter(|e| e.is_some()).count() > 200);
    for backend in [Backend::Cpu, Backend::Gpu] {
        let film = render_film(&scene, backend, 256);
        assert_film_matches(&film, &exact, &format!("{backend:?}"));
        let wrong = max_abs_z(&film.mean(), &film.variance_of_mean(), &ignored);
        assert!(
            wrong > 20.0,
            "{backend:?}: colours ignored not rejected ({wrong})"
        );
    }
    assert_validation_clean();
}
