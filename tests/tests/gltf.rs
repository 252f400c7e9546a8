//! glTF 2.0 import (`twinpath::scene::gltf`), proven on files the tests write
//! (`twinpath_tests::gltf_writer`):
//!
//! 1. Round trip: a mesh with normals, texture coordinates and a textured metallic-roughness
//!    material, stated once as TOML (a PLY file and `[materials]`) and once as glTF
//!    (`[[gltf]]`), gives the same kernel tables and the same image, bit for bit, on both
//!    backends.
//! 2. A glTF file is a scene by itself: its camera (node transform, yfov, aspect ratio), the
//!    default material, strips and fans, node transforms composed down the hierarchy.
//! 3. Appendix B: every mapping rule on a generated file or on the kernel's resolution.
//! 4. Hostile files are errors naming the file and the JSON path, never panics.

use glam::{DMat4, DQuat, DVec3, Vec2, Vec3};
use kernel::scene::{material_kind, texture_slot, Material, NONE};
use serde_json::json;
use std::path::{Path, PathBuf};
use twinpath::render::Backend;
use twinpath::scene::gltf::MAX_TRIANGLES;
use twinpath::scene::textures::{srgb_to_linear, TextureTable, TextureUse};
use twinpath::scene::SceneFile;
use twinpath_tests::gltf_writer::GltfWriter;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{assert_films_identical, render_film};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("twinpath-gltf-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 4 x 4 RGB PNG whose texel (i, j) has the given bytes.
fn png(f: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    let img = image::RgbImage::from_fn(4, 4, |i, j| image::Rgb(f(i, j)));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A small terrain: a 3 x 3 grid of vertices (8 triangles) bent up in the middle, with
/// normals and texture coordinates that are exact in binary (so 1 - (1 - v) = v).
struct Terrain {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    indices: Vec<u32>,
}

fn terrain() -> Terrain {
    let mut t = Terrain {
        positions: vec![],
        normals: vec![],
        uvs: vec![],
        indices: vec![],
    };
    for j in 0..3 {
        for i in 0..3 {
            let (x, z) = (i as f32 - 1.0, j as f32 - 1.0);
            let y = if i == 1 && j == 1 { 0.5 } else { 0.0 };
            t.positions.push([x, y, -z]);
            t.normals.push([0.25 * x, 1.0, 0.25 * z]);
            t.uvs.push([0.5 * i as f32, 0.5 * j as f32]);
        }
    }
    for j in 0..2u32 {
        for i in 0..2u32 {
            let a = j * 3 + i;
            t.indices.extend([a, a + 1, a + 4, a, a + 4, a + 3]);
        }
    }
    t
}

const CAMERA: &str = "[camera]\neye = [0, 2.5, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 45\nwidth = 24\nheight = 16\n";
const LAMP: &str = "[[quad]]\ncorner = [-0.5, 2, -0.5]\nedge1 = [0, 0, 1]\nedge2 = [1, 0, 0]\nmaterial = \"a_lamp\"\n";

/// The round trip's files: the textures, the PLY mesh and the glTF file of the same surface.
fn round_trip_files(dir: &Path) {
    let base = png(|i, j| [40 + 50 * i as u8, 200 - 40 * j as u8, 90]);
    let mr = png(|i, j| [0, 60 + 60 * j as u8, 255 - 60 * i as u8]);
    let normal = png(|i, j| [100 + 20 * i as u8, 150 - 15 * j as u8, 230]);
    std::fs::write(dir.join("base.png"), &base).unwrap();
    std::fs::write(dir.join("mr.png"), &mr).unwrap();
    std::fs::write(dir.join("normal.png"), &normal).unwrap();
    let t = terrain();
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        t.positions.len(),
        t.indices.len() / 3
    );
    for k in 0..t.positions.len() {
        let (p, n, uv) = (t.positions[k], t.normals[k], t.uvs[k]);
        ply += &format!(
            "{:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?}\n",
            p[0], p[1], p[2], n[0], n[1], n[2], uv[0], uv[1]
        );
    }
    for f in t.indices.chunks(3) {
        ply += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
    }
    std::fs::write(dir.join("terrain.ply"), ply).unwrap();

    let mut g = GltfWriter::new();
    let base_tex = g.png_texture(&base);
    let mr_tex = g.png_texture(&mr);
    let normal_tex = g.png_texture(&normal);
    let material = g.push(
        "materials",
        json!({ "name": "metal", "pbrMetallicRoughness": {
            "baseColorFactor": [0.9, 0.6, 0.3, 1.0], "metallicFactor": 0.75, "roughnessFactor": 0.5,
            "baseColorTexture": { "index": base_tex },
            "metallicRoughnessTexture": { "index": mr_tex } },
            "normalTexture": { "index": normal_tex, "scale": 0.8 } }),
    );
    let flipped: Vec<[f32; 2]> = t.uvs.iter().map(|uv| [uv[0], 1.0 - uv[1]]).collect();
    let mesh = g.mesh(
        &t.positions,
        Some(&t.normals),
        Some(&flipped),
        &t.indices,
        Some(material),
    );
    g.push("nodes", json!({ "mesh": mesh }));
    g.push("scenes", json!({ "nodes": [0] }));
    g.json["scene"] = json!(0);
    std::fs::write(dir.join("terrain.glb"), g.glb()).unwrap();
}

fn load(dir: &Path, name: &str, text: &str) -> SceneFile {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_scene_as_toml_and_as_gltf_renders_the_same_bits_on_both_backends() {
    let dir = temp_dir("round-trip");
    round_trip_files(&dir);
    let head = format!("{CAMERA}[render]\nspp = 4\n[background]\nradiance = [0.2, 0.2, 0.2]\n");
    let toml = load(
        &dir,
        "as_toml.toml",
        &format!(
            "{head}[materials]\na_lamp = {{ emission = [4, 4, 4] }}\nmetal = {{ base_color = [0.9, 0.6, 0.3], metallic = 0.75, roughness = 0.5, base_color_map = \"base.png\", metallic_roughness_map = \"mr.png\", normal_map = \"normal.png\", normal_scale = 0.8 }}\n{LAMP}[[mesh]]\nfile = \"terrain.ply\"\nmaterial = \"metal\"\n"
        ),
    );
    let gltf = load(
        &dir,
        "as_gltf.toml",
        &format!(
            "{head}[materials]\na_lamp = {{ emission = [4, 4, 4] }}\n{LAMP}[[gltf]]\nfile = \"terrain.glb\"\n"
        ),
    );
    assert_eq!(toml.scene.triangles.len(), 10);
    assert_eq!(toml.scene.triangles, gltf.scene.triangles, "triangles");
    assert_eq!(
        toml.scene.shading, gltf.scene.shading,
        "shading records and tangent frames"
    );
    // The mesh's 8 triangles have a record and a tangent frame each.
    assert_eq!(toml.scene.shading.len(), 16);
    assert!(toml
        .scene
        .shading
        .iter()
        .step_by(2)
        .all(|s| s.flags == kernel::scene::shading_flags::NORMALS));
    assert_eq!(toml.scene.materials[1].normal_scale, 0.8);
    assert_eq!(toml.scene.materials, gltf.scene.materials, "materials");
    assert_eq!(
        toml.scene.materials[1].kind,
        material_kind::METALLIC_ROUGHNESS
    );
    assert_eq!(toml.scene.lights, gltf.scene.lights, "lights");
    assert_eq!(
        toml.scene.textures.words, gltf.scene.textures.words,
        "texture table"
    );
    assert_eq!(toml.features(), gltf.features());
    let mr = kernel::features::METALLIC_ROUGHNESS
        | kernel::features::GLOSSY
        | kernel::features::NORMAL_MAPS;
    assert_eq!(toml.features() & mr, mr, "glTF's material keeps its code");
    for (backend, spp) in [(Backend::Cpu, 16), (Backend::Gpu, 4)] {
        let a = render_film(&toml, backend, spp);
        let b = render_film(&gltf, backend, spp);
        assert_films_identical(&a, &b, &format!("TOML vs glTF, {backend:?}"));
        assert!(
            a.mean().iter().any(|p| p[0] > 0.0),
            "a black image proves nothing"
        );
    }
    assert_validation_clean();
}

/// A glb of one triangle soup under a node hierarchy, with a camera.
fn camera_file(dir: &Path) -> PathBuf {
    let mut g = GltfWriter::new();
    // A fan and a strip: the unit square at z = 0 twice, side by side.
    let square = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let p = g.positions(&square);
    g.push(
        "meshes",
        json!({ "name": "fan", "primitives": [ { "attributes": { "POSITION": p }, "mode": 6 } ] }),
    );
    let strip = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    let q = g.positions(&strip);
    g.push(
        "meshes",
        json!({ "name": "strip", "primitives": [ { "attributes": { "POSITION": q }, "mode": 5 } ] }),
    );
    g.push(
        "cameras",
        json!({ "name": "side", "type": "perspective",
        "perspective": { "yfov": 0.5, "znear": 0.1 } }),
    );
    g.push(
        "cameras",
        json!({ "name": "main", "type": "perspective",
        "perspective": { "yfov": 0.7, "aspectRatio": 1.5, "znear": 0.1 } }),
    );
    // Node 0: the parent, translated and scaled; its children: the fan at the origin, the strip
    // translated by x = 2 (so at x = 2 * 2 + 3 after the parent), the camera rotated 90 degrees
    // about +y (looking down -x) at z = 5.
    g.push(
        "nodes",
        json!({ "translation": [3.0, 0.0, 0.0], "scale": [2.0, 2.0, 2.0],
        "children": [1, 2, 3] }),
    );
    g.push("nodes", json!({ "mesh": 0 }));
    g.push(
        "nodes",
        json!({ "mesh": 1, "translation": [2.0, 0.0, 0.0] }),
    );
    let h = std::f64::consts::FRAC_1_SQRT_2;
    g.push(
        "nodes",
        json!({ "camera": 1, "translation": [0.0, 0.0, 2.5],
        "rotation": [0.0, h, 0.0, h] }),
    );
    g.push("nodes", json!({ "camera": 0 }));
    g.push("scenes", json!({ "nodes": [0, 4] }));
    let path = dir.join("camera.glb");
    std::fs::write(&path, g.glb()).unwrap();
    path
}

#[test]
fn a_gltf_file_is_a_scene_with_its_camera_hierarchy_and_default_material() {
    let dir = temp_dir("camera");
    let path = camera_file(&dir);
    let scene = SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}"));
    // The first camera in the walk: node 3 (camera "main"), under the parent's T S.
    let c = scene.scene.camera;
    assert_eq!(
        (c.width, c.height),
        (1080, 720),
        "aspect ratio 1.5 at height 720"
    );
    assert!((c.vfov_degrees - 0.7f32.to_degrees()).abs() < 1e-5);
    assert!(
        (c.eye - Vec3::new(3.0, 0.0, 5.0)).length() < 1e-6,
        "eye {}",
        c.eye
    );
    let forward = (c.look_at - c.eye).normalize();
    assert!(
        (forward - Vec3::new(-1.0, 0.0, 0.0)).length() < 1e-6,
        "forward {forward}"
    );
    assert!((c.up - Vec3::Y).length() < 1e-6);
    // Fan and strip: two triangles each, the square scaled by 2 at x = 3 and x = 7.
    assert_eq!(scene.scene.triangles.len(), 4);
    let corners = |k: usize| {
        let t = scene.scene.triangles[k];
        let p0 = Vec3::from(t.p0);
        [p0, p0 + Vec3::from(t.edge1), p0 + Vec3::from(t.edge2)]
    };
    assert_eq!(
        corners(0),
        [
            Vec3::new(5.0, 0.0, 0.0),
            Vec3::new(5.0, 2.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0)
        ],
        "fan triangle 0 is (v1, v2, v0)"
    );
    assert_eq!(
        corners(2),
        [
            Vec3::new(7.0, 0.0, 0.0),
            Vec3::new(9.0, 0.0, 0.0),
            Vec3::new(7.0, 2.0, 0.0)
        ],
        "strip triangle 0 is (v0, v1, v2)"
    );
    assert_eq!(
        corners(3),
        [
            Vec3::new(9.0, 0.0, 0.0),
            Vec3::new(9.0, 2.0, 0.0),
            Vec3::new(7.0, 2.0, 0.0)
        ],
        "strip triangle 1 is (v1, v3, v2)"
    );
    // Every front face points +z (counter-clockwise seen from +z, as the file winds them).
    for k in 0..4 {
        let t = scene.scene.triangles[k];
        assert!(
            Vec3::from(t.edge1).cross(Vec3::from(t.edge2)).z > 0.0,
            "triangle {k} winding"
        );
    }
    // No material: the specification's default, white, metallic 1, roughness 1.
    assert_eq!(scene.scene.materials.len(), 1);
    let m = scene.scene.materials[0];
    assert_eq!(m.kind, material_kind::METALLIC_ROUGHNESS);
    assert_eq!((m.albedo, m.metallic, m.roughness), ([1.0; 3], 1.0, 1.0));
    assert_eq!(scene.scene.background, Vec3::ONE, "a white sky");
    // The other camera by name; an unknown name lists the cameras.
    let side = SceneFile::load_with_camera(&path, Some("side")).unwrap();
    assert_eq!(
        (side.scene.camera.width, side.scene.camera.height),
        (1280, 720)
    );
    assert!((side.scene.camera.eye - Vec3::ZERO).length() < 1e-6);
    let e = SceneFile::load_with_camera(&path, Some("nope"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no perspective camera named 'nope'") && e.contains("main, side"),
        "{e}"
    );
    // It renders on both backends (the sky around two grey squares).
    for backend in [Backend::Cpu, Backend::Gpu] {
        let mut s = scene.clone();
        s.scene.camera.width = 24;
        s.scene.camera.height = 16;
        let film = render_film(&s, backend, 2);
        let mean = film.mean();
        assert!(mean
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0)));
    }
    assert_validation_clean();
}

/// A glb with one material `material` on a closed tetrahedron (its faces wound outward).
fn material_file(dir: &Path, name: &str, material: serde_json::Value, used: &[&str]) -> PathBuf {
    let mut g = GltfWriter::new();
    let m = g.push("materials", material);
    let p = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mesh = g.mesh(
        &p,
        None,
        None,
        &[0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3],
        Some(m),
    );
    g.push("nodes", json!({ "mesh": mesh }));
    if !used.is_empty() {
        g.json["extensionsUsed"] = json!(used);
    }
    let path = dir.join(name);
    std::fs::write(&path, g.glb()).unwrap();
    path
}

#[test]
fn appendix_b_rules_each_hold() {
    let dir = temp_dir("appendix-b");
    let one = |name: &str, material: serde_json::Value, used: &[&str]| -> SceneFile {
        let path = material_file(&dir, name, material, used);
        SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}"))
    };
    // Factors as stored, glTF's defaults for what is absent.
    let s = one(
        "factors.glb",
        json!({ "pbrMetallicRoughness": {
        "baseColorFactor": [0.5, 0.25, 0.125, 1.0], "metallicFactor": 0.2 } }),
        &[],
    );
    let m = s.scene.materials[0];
    assert_eq!(m.kind, material_kind::METALLIC_ROUGHNESS);
    assert_eq!(
        (m.albedo, m.metallic, m.roughness),
        ([0.5, 0.25, 0.125], 0.2, 1.0)
    );
    // Resolution (what the BSDF sees): Kd = (1 - metallic) base, F0 = lerp(0.04, base,
    // metallic), alpha = roughness^2.
    let mut q = m;
    q.roughness = 0.5;
    let r = kernel::bsdf::metallic_roughness::resolve(&q);
    let expect_kd = [0.4, 0.2, 0.1];
    let expect_f0 = [0.032 + 0.1, 0.032 + 0.05, 0.032 + 0.025];
    for c in 0..3 {
        assert!((r.albedo[c] - expect_kd[c]).abs() < 1e-7);
        assert!((r.specular[c] - expect_f0[c]).abs() < 1e-7);
    }
    assert_eq!(r.alpha, 0.25, "alpha = roughness^2");
    // Emissive colour times KHR_materials_emissive_strength; doubleSided: both faces emit.
    let s = one(
        "emissive.glb",
        json!({ "emissiveFactor": [1.0, 0.5, 0.25], "doubleSided": true,
        "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 4.0 } } }),
        &["KHR_materials_emissive_strength"],
    );
    assert_eq!(s.scene.materials[0].emission, [4.0, 2.0, 1.0]);
    assert_eq!(s.scene.lights.len(), 4, "each triangle a light");
    assert!(
        s.scene.lights.iter().all(|l| l.two_sided == 1),
        "doubleSided"
    );
    // It keeps its surface: a light that reflects as a metallic-roughness material.
    assert_eq!(s.scene.materials[0].kind, material_kind::METALLIC_ROUGHNESS);
    assert!(s.scene.materials[0].reflects());
    // KHR_materials_transmission + KHR_materials_ior: the dielectric, alpha = roughness^2.
    let s = one(
        "glass.glb",
        json!({ "pbrMetallicRoughness": { "roughnessFactor": 0.5 },
        "extensions": { "KHR_materials_transmission": { "transmissionFactor": 1.0 },
                        "KHR_materials_ior": { "ior": 1.33 } } }),
        &["KHR_materials_transmission", "KHR_materials_ior"],
    );
    assert_eq!(s.scene.materials[0].kind, material_kind::DIELECTRIC);
    assert_eq!(
        (s.scene.materials[0].ior, s.scene.materials[0].alpha),
        (1.33, 0.25)
    );
    // An extension that is not read is noted once; one that is required is an error.
    let s = one("ignored.glb", json!({}), &["KHR_materials_iridescence"]);
    assert!(
        s.scene
            .notes
            .iter()
            .any(|n| n.contains("extensions ignored: KHR_materials_iridescence")),
        "{:?}",
        s.scene.notes
    );
    // Factors outside [0, 1] name the material.
    let path = material_file(
        &dir,
        "bad.glb",
        json!({ "pbrMetallicRoughness": { "metallicFactor": 1.5 } }),
        &[],
    );
    let e = SceneFile::load(&path).unwrap_err().to_string();
    assert!(
        e.contains("materials[0]") && e.contains("metallicFactor 1.5"),
        "{e}"
    );
}

#[test]
fn clear_coats_are_read_from_the_extension() {
    let dir = temp_dir("clearcoat");
    let coat = |extension: serde_json::Value| {
        let path = material_file(
            &dir,
            "coat.glb",
            json!({ "extensions": { "KHR_materials_clearcoat": extension } }),
            &["KHR_materials_clearcoat"],
        );
        SceneFile::load(&path)
    };
    // Factor and roughness, in 16-bit fixed point; no note of an ignored extension.
    let s = coat(json!({ "clearcoatFactor": 0.75, "clearcoatRoughnessFactor": 0.2 })).unwrap();
    let m = s.scene.materials[0];
    assert_eq!(m.kind, material_kind::METALLIC_ROUGHNESS);
    assert!(
        (m.coat_weight() - 0.75).abs() <= 0.5 / 65535.0,
        "{}",
        m.coat_weight()
    );
    assert!(
        (m.coat_roughness() - 0.2).abs() <= 0.5 / 65535.0,
        "{}",
        m.coat_roughness()
    );
    assert!(
        s.scene.notes.iter().all(|n| !n.contains("ignored")),
        "{:?}",
        s.scene.notes
    );
    // The defaults: no coat (factor 0), whatever the roughness.
    let s = coat(json!({ "clearcoatRoughnessFactor": 0.5 })).unwrap();
    assert_eq!(s.scene.materials[0].coat, 0);
    // Textures are noted, their factors used.
    let s = coat(json!({ "clearcoatFactor": 1.0, "clearcoatNormalTexture": { "index": 0 } }));
    let s = s.unwrap();
    assert!(s.scene.materials[0].coat_weight() == 1.0);
    assert!(
        s.scene
            .notes
            .iter()
            .any(|n| n.contains("KHR_materials_clearcoat textures ignored")),
        "{:?}",
        s.scene.notes
    );
    // Out of range: an error naming the material and the field.
    let e = coat(json!({ "clearcoatFactor": 1.5 }))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("materials[0]") && e.contains("clearcoatFactor 1.5"),
        "{e}"
    );
    // TOML: the same material's keys; a value out of range names the field.
    let toml = |entry: &str| {
        twinpath::scene::parse_scene(
            &format!(
                "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 8\nheight = 8\n[materials]\nc = {{ {entry} }}\n\
             [[sphere]]\ncenter = [0, 0, 0]\nradius = 1.0\nmaterial = \"c\"\n"
            ),
            Path::new("coat.toml"),
        )
    };
    let s =
        toml("base_color = [0.8, 0.1, 0.1], clearcoat = 0.5, clearcoat_roughness = 0.1").unwrap();
    let m = s.scene.materials[0];
    assert!((m.coat_weight() - 0.5).abs() <= 0.5 / 65535.0);
    assert!((m.coat_roughness() - 0.1).abs() <= 0.5 / 65535.0);
    let e = toml("clearcoat = 2.0").unwrap_err().to_string();
    assert!(
        e.contains("materials.c.clearcoat") && e.contains("outside 0..=1"),
        "{e}"
    );
}

#[test]
fn coloured_glass_is_read_from_the_volume_extension() {
    let dir = temp_dir("volume");
    let glass = |volume: serde_json::Value| {
        let path = material_file(
            &dir,
            "glass.glb",
            json!({ "extensions": {
                "KHR_materials_transmission": { "transmissionFactor": 1.0 },
                "KHR_materials_volume": volume } }),
            &["KHR_materials_transmission", "KHR_materials_volume"],
        );
        SceneFile::load(&path)
    };
    // sigma_a = -ln(colour) / distance, the thickness ignored (a path tracer traces it).
    let s = glass(json!({ "thicknessFactor": 0.1, "attenuationDistance": 2.0,
                          "attenuationColor": [0.5, 0.25, 1.0] }))
    .unwrap();
    let m = s.scene.materials[0];
    assert_eq!(m.kind, material_kind::DIELECTRIC);
    let want = [0.5f64, 0.25, 1.0].map(|c| (-c.ln() / 2.0) as f32);
    assert_eq!(s.scene.media[m.interior_medium() as usize].sigma_a, want);
    assert_ne!(
        s.scene.features(&s.settings) & kernel::features::MEDIA,
        0,
        "a scene with coloured glass tracks media"
    );
    assert!(
        s.scene.notes.iter().all(|n| !n.contains("ignored")),
        "{:?}",
        s.scene.notes
    );
    // Without a distance (infinite by default): clear glass.
    let s = glass(json!({ "attenuationColor": [0.5, 0.5, 0.5] })).unwrap();
    assert!(!s.scene.materials[0].has_interior_medium());
    // A colour of 0 is noted; bad values name the field.
    let s =
        glass(json!({ "attenuationDistance": 1.0, "attenuationColor": [0.0, 1.0, 1.0] })).unwrap();
    assert!(s.scene.notes.iter().any(|n| n.contains("read as 1e-6")));
    for (bad, field) in [
        (
            json!({ "attenuationDistance": -1.0 }),
            "attenuationDistance",
        ),
        (
            json!({ "attenuationDistance": 1.0, "attenuationColor": [2.0, 1.0, 1.0] }),
            "attenuationColor",
        ),
    ] {
        let e = glass(bad).unwrap_err().to_string();
        assert!(e.contains("materials[0]") && e.contains(field), "{e}");
    }
}

#[test]
fn sheens_are_read_from_the_extension() {
    let dir = temp_dir("sheen");
    let sheen = |extension: serde_json::Value| {
        let path = material_file(
            &dir,
            "sheen.glb",
            json!({ "extensions": { "KHR_materials_sheen": extension } }),
            &["KHR_materials_sheen"],
        );
        SceneFile::load(&path)
    };
    // Colour and roughness as written; no note of an ignored extension.
    let s =
        sheen(json!({ "sheenColorFactor": [1.0, 0.6, 0.3], "sheenRoughnessFactor": 0.4 })).unwrap();
    let m = s.scene.materials[0];
    assert_eq!(m.kind, material_kind::METALLIC_ROUGHNESS);
    assert_eq!(
        (m.sheen_colour(), m.sheen_roughness()),
        ([1.0, 0.6, 0.3], 0.4)
    );
    assert!(
        s.scene.notes.iter().all(|n| !n.contains("ignored")),
        "{:?}",
        s.scene.notes
    );
    // The scene carries the sheen table (and a scene without a sheen does not).
    let table = kernel::texture::SHEEN_LTC;
    assert_ne!(s.scene.textures.words[table], kernel::scene::NONE);
    let bare = sheen(json!({ "sheenRoughnessFactor": 0.5 })).unwrap();
    assert!(
        !bare.scene.materials[0].has_sheen(),
        "default colour black: none"
    );
    assert_eq!(bare.scene.textures.words[table], kernel::scene::NONE);
    // Textures are noted, the factors used.
    let s =
        sheen(json!({ "sheenColorFactor": [1.0, 1.0, 1.0], "sheenColorTexture": { "index": 0 } }))
            .unwrap();
    assert!(s.scene.materials[0].has_sheen());
    assert!(
        s.scene
            .notes
            .iter()
            .any(|n| n.contains("KHR_materials_sheen textures ignored")),
        "{:?}",
        s.scene.notes
    );
    // Out of range or malformed: an error naming the material and the field.
    for (bad, field) in [
        (
            json!({ "sheenColorFactor": [1.5, 0.0, 0.0] }),
            "sheenColorFactor",
        ),
        (
            json!({ "sheenColorFactor": [1.0, 0.0] }),
            "sheenColorFactor",
        ),
        (
            json!({ "sheenColorFactor": [1.0, 1.0, 1.0], "sheenRoughnessFactor": -0.1 }),
            "sheenRoughnessFactor",
        ),
    ] {
        let e = sheen(bad).unwrap_err().to_string();
        assert!(e.contains("materials[0]") && e.contains(field), "{e}");
    }
    // TOML: the same material's keys; a colour above 1 names the field.
    let toml = |entry: &str| {
        twinpath::scene::parse_scene(
            &format!(
                "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 8\nheight = 8\n[materials]\nc = {{ {entry} }}\n\
             [[sphere]]\ncenter = [0, 0, 0]\nradius = 1.0\nmaterial = \"c\"\n"
            ),
            Path::new("sheen.toml"),
        )
    };
    let s = toml("base_color = [0.1, 0.1, 0.4], sheen = [1, 1, 1], sheen_roughness = 0.5").unwrap();
    let m = s.scene.materials[0];
    assert_eq!((m.sheen_colour(), m.sheen_roughness()), ([1.0; 3], 0.5));
    let e = toml("sheen = [2, 0, 0]").unwrap_err().to_string();
    assert!(e.contains("materials.c.sheen"), "{e}");
}

#[test]
fn texture_channels_srgb_and_the_metallic_roughness_map() {
    // One texel each: base colour bytes (128, 64, 255) read as sRGB; the metallic-roughness
    // map's bytes (10, 128, 191) read linearly, green multiplying roughness and blue metallic
    // (red is unused).
    let dir = temp_dir("channels");
    let save = |name: &str, rgb: [u8; 3]| {
        let path = dir.join(name);
        image::RgbImage::from_pixel(1, 1, image::Rgb(rgb))
            .save(&path)
            .unwrap();
        path
    };
    let mut table = TextureTable::new();
    let base = table
        .add(
            &save("base.png", [128, 64, 255]),
            TextureUse {
                colour: true,
                wrap: [kernel::texture::wrap::REPEAT; 2],
                transform: None,
                second_set: false,
            },
            "b",
        )
        .unwrap();
    let mr = table
        .add(
            &save("mr.png", [10, 128, 191]),
            TextureUse {
                colour: false,
                wrap: [kernel::texture::wrap::REPEAT; 2],
                transform: None,
                second_set: false,
            },
            "m",
        )
        .unwrap();
    let mut m = Material::diffuse([0.5, 1.0, 0.8]);
    m.kind = material_kind::METALLIC_ROUGHNESS;
    m.metallic = 0.9;
    m.roughness = 0.6;
    m.textures[texture_slot::KD] = base;
    m.textures[texture_slot::KS] = mr;
    let record = kernel::scene::ShadingTriangle {
        normal0: [0.0; 3],
        normal1: [0.0; 3],
        normal2: [0.0; 3],
        uv0: [0.5, 0.5],
        uv1: [0.5, 0.5],
        uv2: [0.5, 0.5],
        flags: 0,
    };
    let (at, _) = twinpath_tests::shade_at(
        0,
        0,
        Vec2::new(0.3, 0.3),
        Vec3::Y,
        kernel::scene::NONE,
        &[m],
        &[record],
        &table.words,
        &[],
    );
    let base_linear = [128u8, 64, 255].map(srgb_to_linear);
    let metallic = 0.9 * 191.0 / 255.0;
    let roughness = 0.6 * 128.0 / 255.0;
    for c in 0..3 {
        let b = [0.5, 1.0, 0.8][c] * base_linear[c];
        let kd = (1.0 - metallic) * b;
        let f0 = 0.04 * (1.0 - metallic) + metallic * b;
        assert!(
            (at.albedo[c] as f64 - kd).abs() < 1e-6,
            "Kd[{c}] {} vs {kd}",
            at.albedo[c]
        );
        assert!(
            (at.specular[c] as f64 - f0).abs() < 1e-6,
            "F0[{c}] {} vs {f0}",
            at.specular[c]
        );
    }
    assert!(
        (at.alpha as f64 - roughness * roughness).abs() < 1e-6,
        "alpha {}",
        at.alpha
    );
    // Without the record (no texture coordinates) the factors alone are resolved.
    let (plain, _) = twinpath_tests::shade_at(
        0,
        NONE,
        Vec2::ZERO,
        Vec3::Y,
        kernel::scene::NONE,
        &[m],
        &[record],
        &table.words,
        &[],
    );
    assert!((plain.alpha - 0.36).abs() < 1e-7);
}

/// A change to a test file.
type Edit = dyn Fn(&mut GltfWriter);

/// A valid glb (one triangle, a node, a scene) whose JSON `edit` then breaks; the error.
fn hostile(edit: impl Fn(&mut GltfWriter)) -> String {
    let mut g = GltfWriter::new();
    g.mesh(
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        None,
        None,
        &[0, 1, 2],
        None,
    );
    g.push("nodes", json!({ "mesh": 0 }));
    g.push("scenes", json!({ "nodes": [0] }));
    edit(&mut g);
    let bytes = g.glb();
    match twinpath::scene::gltf::load_bytes(Path::new("hostile.glb"), &bytes, None, None) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    }
}

#[test]
fn hostile_gltf_files_are_errors_naming_the_place() {
    assert_eq!(hostile(|_| {}), "", "the unbroken file loads");
    let cases: Vec<(&str, Box<Edit>, &str)> = vec![
        (
            "count beyond the buffer",
            Box::new(|g| g.json["accessors"][0]["count"] = json!(1000)),
            "accessors[0]: 1000 elements",
        ),
        (
            "offset beyond the view",
            Box::new(|g| g.json["accessors"][0]["byteOffset"] = json!(4096)),
            "accessors[0]",
        ),
        (
            "view beyond the buffer",
            Box::new(|g| g.json["bufferViews"][0]["byteLength"] = json!(1 << 20)),
            "buffer",
        ),
        (
            "index out of range",
            Box::new(|g| {
                let i = g.indices(&[0, 1, 7]);
                g.json["meshes"][0]["primitives"][0]["indices"] = json!(i);
            }),
            "index 2 is 7, beyond the 3 vertices",
        ),
        (
            "a cycle",
            Box::new(|g| {
                g.push("nodes", json!({ "children": [2] }));
                g.push("nodes", json!({ "children": [1] }));
                g.json["scenes"][0]["nodes"] = json!([0, 1]);
            }),
            "is reached twice",
        ),
        (
            "points",
            Box::new(|g| g.json["meshes"][0]["primitives"][0]["mode"] = json!(0)),
            "meshes[0].primitives[0]: mode Points",
        ),
        (
            "positions as integers",
            Box::new(|g| g.json["accessors"][0]["componentType"] = json!(5125)),
            "expected VEC3 of FLOAT",
        ),
        (
            "a required extension",
            Box::new(|g| {
                g.json["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
                g.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
            }),
            "KHR_draco_mesh_compression",
        ),
        (
            "a projective node",
            Box::new(|g| {
                g.json["nodes"][0]["matrix"] =
                    json!([1, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])
            }),
            "not affine",
        ),
        (
            "a zero scale",
            Box::new(|g| g.json["nodes"][0]["scale"] = json!([0.0, 1.0, 1.0])),
            "singular",
        ),
        (
            "an external buffer without a folder",
            Box::new(|g| g.json["buffers"][0]["uri"] = json!("data.bin")),
            "buffers",
        ),
        (
            "a dangling POSITION accessor (a panic inside the gltf crate's validation)",
            Box::new(|g| {
                g.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(99)
            }),
            "meshes[0].primitives[0].attributes: accessor 99 does not exist",
        ),
        (
            "a missing mesh",
            Box::new(|g| g.json["nodes"][0]["mesh"] = json!(5)),
            "not a valid glTF",
        ),
    ];
    for (label, edit, expected) in cases {
        let e = hostile(edit);
        assert!(
            e.starts_with("hostile.glb: "),
            "{label}: error '{e}' does not name the file"
        );
        assert!(e.contains(expected), "{label}: '{e}' lacks '{expected}'");
    }
    // Garbage and truncation. (A GLB header declaring 1 byte, less than the header itself, is
    // the first crash the fuzzer found: the gltf crate subtracted 12 from it unchecked.)
    for bytes in [
        b"glTF\x02\0\0\0".to_vec(),
        b"glTF\x02\0\0\0\x01\0\0\0\0\0\0\0JSON{}".to_vec(),
        b"{ not json".to_vec(),
        vec![0u8; 7],
    ] {
        let e = twinpath::scene::gltf::load_bytes(Path::new("x.glb"), &bytes, None, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a valid glTF 2.0 file"), "{e}");
    }
}

/// A glTF file whose default scene has 10^6 nodes using one 100-triangle mesh (of an emissive
/// material where `emissive`), loaded.
fn a_million_nodes(emissive: bool) -> Result<SceneFile, String> {
    let mut g = GltfWriter::new();
    let positions: Vec<[f32; 3]> = (0..300)
        .map(|i| {
            let k = (i / 3) as f32;
            [[k, 0.0, 0.0], [k + 1.0, 0.0, 0.0], [k, 1.0, 0.0]][i % 3]
        })
        .collect();
    let indices: Vec<u32> = (0..300).collect();
    let material = emissive.then(|| g.push("materials", json!({ "emissiveFactor": [1, 1, 1] })));
    let mesh = g.mesh(&positions, None, None, &indices, material);
    for _ in 0..1_000_000 {
        g.push("nodes", json!({ "mesh": mesh, "translation": [0, 0, -2] }));
    }
    g.push(
        "scenes",
        json!({ "nodes": (0..1_000_000).collect::<Vec<_>>() }),
    );
    twinpath::scene::gltf::load_bytes(Path::new("million.glb"), &g.glb(), None, None)
        .map(|scene| SceneFile {
            scene,
            settings: Default::default(),
        })
        .map_err(|e| e.to_string())
}

#[test]
fn a_million_instances_are_stored_once_or_refused_before_they_are_flattened() {
    // 10^6 nodes instancing a 100-triangle mesh: the mesh is stored once, placed 10^6 times.
    let scene = a_million_nodes(false).expect("loads");
    assert_eq!(scene.scene.meshes.len(), 1);
    assert_eq!(scene.scene.instances.len(), 1_000_000);
    assert_eq!(scene.scene.triangles.len(), 100);
    // An emissive mesh is flattened (its lights are world-space records): 10^8 triangles,
    // beyond MAX_TRIANGLES; refused from the declared counts, without reading or allocating
    // the copies.
    let e = a_million_nodes(true).unwrap_err();
    assert!(
        e.contains(&format!("more than {MAX_TRIANGLES} triangles")),
        "{e}"
    );
}

#[test]
fn toml_includes_a_gltf_file_under_a_transform() {
    let dir = temp_dir("include");
    let path = camera_file(&dir);
    let plain = SceneFile::load(&path).unwrap();
    let include = |transform: &str| {
        load(
            &dir,
            "include.toml",
            &format!("{CAMERA}[[gltf]]\nfile = \"camera.glb\"\n{transform}"),
        )
    };
    // The file's own hierarchy, then the include's transform on top: rotate 90 degrees about
    // +z, then translate.
    let moved = include("rotate = [90, 0, 0, 1]\ntranslate = [0, 0, -4]\n");
    let m = DMat4::from_rotation_translation(
        DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2),
        DVec3::new(0.0, 0.0, -4.0),
    );
    assert_eq!(moved.scene.triangles.len(), plain.scene.triangles.len());
    for (a, b) in moved.scene.triangles.iter().zip(&plain.scene.triangles) {
        let want = m.transform_point3(Vec3::from(b.p0).as_dvec3());
        assert!(
            (Vec3::from(a.p0).as_dvec3() - want).length() < 1e-5,
            "{:?} vs {want}",
            a.p0
        );
    }
    // The TOML camera stays; a missing file names the field.
    assert_eq!(moved.scene.camera.width, 24);
    let e = twinpath::scene::parse_scene(
        &format!("{CAMERA}[[gltf]]\nfile = \"nope.glb\"\n"),
        &dir.join("x.toml"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("gltf[0].file") && e.contains("does not exist"),
        "{e}"
    );
}

#[test]
fn a_toml_scene_renders_through_its_gltf_files_camera() {
    let dir = temp_dir("toml_camera");
    let path = camera_file(&dir);
    let main = SceneFile::load_with_camera(&path, Some("main")).unwrap();
    let side = SceneFile::load_with_camera(&path, Some("side")).unwrap();
    let include = |camera: &str, transform: &str| {
        twinpath::scene::parse_scene(
            &format!("[camera]\n{camera}\n[[gltf]]\nfile = \"camera.glb\"\n{transform}"),
            &dir.join("x.toml"),
        )
    };
    // Without a transform: exactly the file's camera.
    let same = include("gltf = \"main\"", "").unwrap();
    assert_eq!(same.scene.camera, main.scene.camera);
    // Under the include's transform: moved with the meshes, the view unchanged otherwise.
    let moved = include("gltf = \"main\"", "translate = [1, 2, 3]\n").unwrap();
    let d = Vec3::new(1.0, 2.0, 3.0);
    let (a, b) = (moved.scene.camera, main.scene.camera);
    assert!((a.eye - (b.eye + d)).length() < 1e-5, "{a:?} vs {b:?}");
    assert!(
        (a.look_at - (b.look_at + d)).length() < 1e-5,
        "{a:?} vs {b:?}"
    );
    assert!((a.up - b.up).length() < 1e-6 && a.vfov_degrees == b.vfov_degrees);
    // The table's size (one side alone keeps the aspect ratio, 1.5 here) and lens.
    let sized = include(
        "gltf = \"main\"\nwidth = 300\naperture = 0.1\nfocus_distance = 2",
        "",
    )
    .unwrap();
    let c = sized.scene.camera;
    assert_eq!(
        (c.width, c.height, c.aperture, c.focus_distance),
        (300, 200, 0.1, 2.0)
    );
    assert_eq!((c.eye, c.vfov_degrees), (b.eye, b.vfov_degrees));
    // --camera on a TOML scene: the named camera as its file states it, replacing [camera].
    let toml_path = dir.join("with_camera.toml");
    std::fs::write(
        &toml_path,
        format!("{CAMERA}[[gltf]]\nfile = \"camera.glb\"\n"),
    )
    .unwrap();
    let by_flag = SceneFile::load_with_camera(&toml_path, Some("side")).unwrap();
    assert_eq!(by_flag.scene.camera, side.scene.camera);
    assert_eq!(SceneFile::load(&toml_path).unwrap().scene.camera.width, 24);
    // Errors name the field (and line) and list the cameras there are.
    let errors = [
        (
            "gltf = \"nope\"",
            "x.toml:2: camera.gltf: no perspective camera named 'nope'",
        ),
        (
            "gltf = \"main\"\neye = [0, 0, 1]",
            "x.toml:3: camera.eye: not with camera.gltf",
        ),
        (
            "gltf = \"main\"\naperture = 0.1",
            "camera.focus_distance: missing",
        ),
        (
            "eye = [0, 0, 1]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 8",
            "camera.height: missing",
        ),
        (
            "gltf = \"main\"\nheight = 0",
            "x.toml:3: camera.height: 0 is outside",
        ),
    ];
    for (camera, want) in errors {
        let e = include(camera, "").unwrap_err().to_string();
        assert!(e.contains(want), "{camera}: {e}");
    }
    let e = include("gltf = \"nope\"", "").unwrap_err().to_string();
    assert!(e.contains("'main' (") && e.contains("'side' ("), "{e}");
    let e = SceneFile::load_with_camera(&toml_path, Some("nope"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("camera: no perspective camera named 'nope'") && e.contains("'main'"),
        "{e}"
    );
    // The image: the TOML scene under the glTF file's white sky renders through the included
    // camera exactly what the file alone renders through its own.
    let through = include(
        "gltf = \"main\"\nwidth = 24\n[background]\nradiance = [1, 1, 1]",
        "",
    )
    .unwrap();
    let mut alone = main.clone();
    alone.scene.camera = alone.scene.camera.resized(Some(24), None).unwrap();
    assert_eq!(through.scene.camera, alone.scene.camera);
    assert_films_identical(
        &render_film(&through, Backend::Cpu, 4),
        &render_film(&alone, Backend::Cpu, 4),
        "TOML through the glTF camera vs the glTF file",
    );
}

#[test]
fn the_shipped_showcase_loads_and_renders_alike_on_both_backends() {
    let root = twinpath_tests::repo_root();
    let alone =
        SceneFile::load(&root.join("scenes/gltf/showcase.glb")).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        alone.scene.notes.iter().all(|n| !n.contains("ignored")),
        "{:?}",
        alone.scene.notes
    );
    assert_eq!(
        (alone.scene.camera.width, alone.scene.camera.height),
        (960, 720),
        "its own camera"
    );
    let mut scene =
        SceneFile::load(&root.join("scenes/gltf_showcase.toml")).unwrap_or_else(|e| panic!("{e}"));
    let f = scene.features();
    for (bit, name) in [
        (kernel::features::METALLIC_ROUGHNESS, "metallic-roughness"),
        (kernel::features::TEXTURES, "textures"),
        (kernel::features::SHADING_NORMALS, "smooth normals"),
        (kernel::features::PUNCTUAL_LIGHTS, "a spot light"),
        (kernel::features::NORMAL_MAPS, "a normal map"),
        (kernel::features::ENVIRONMENT, "the HDR sky"),
    ] {
        assert!(f & bit != 0, "the showcase lacks {name}");
    }
    scene.scene.camera.width = 32;
    scene.scene.camera.height = 24;
    let cpu = render_film(&scene, Backend::Cpu, 16);
    let gpu = render_film(&scene, Backend::Gpu, 16);
    let z = twinpath_tests::image_mean_z(&cpu, &gpu);
    println!("showcase: CPU vs GPU image mean z = {z:+.2}");
    assert!(
        z.abs() < 4.0,
        "CPU and GPU disagree on the showcase: z = {z}"
    );
    assert_validation_clean();
}

#[test]
fn sampler_wrap_modes_are_read_per_axis() {
    use kernel::texture::{flags, wrap};
    // Three textures of one image: MIRRORED_REPEAT x CLAMP_TO_EDGE, REPEAT x MIRRORED_REPEAT,
    // and no sampler (repeat both ways), on three materials.
    let mut g = GltfWriter::new();
    let image = png(|x, y| [(x * 60) as u8, (y * 60) as u8, 0]);
    let samplers = [
        g.push("samplers", json!({ "wrapS": 33648, "wrapT": 33071 })),
        g.push("samplers", json!({ "wrapS": 10497, "wrapT": 33648 })),
    ];
    let first = g.png_texture(&image);
    g.json["textures"][first]["sampler"] = json!(samplers[0]);
    let source = g.json["textures"][first]["source"].clone();
    let second = g.push(
        "textures",
        json!({ "source": source, "sampler": samplers[1] }),
    );
    let third = g.push("textures", json!({ "source": source }));
    let materials: Vec<usize> = [first, second, third]
        .iter()
        .map(|&t| {
            g.push(
                "materials",
                json!({ "pbrMetallicRoughness": { "baseColorTexture": { "index": t } } }),
            )
        })
        .collect();
    for (k, &m) in materials.iter().enumerate() {
        let mesh = g.mesh(
            &[
                [k as f32, 0.0, 0.0],
                [k as f32 + 1.0, 0.0, 0.0],
                [k as f32, 1.0, 0.0],
            ],
            None,
            Some(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
            &[0, 1, 2],
            Some(m),
        );
        g.push("nodes", json!({ "mesh": mesh }));
    }
    g.push("scenes", json!({ "nodes": [0, 1, 2] }));
    let scene =
        twinpath::scene::gltf::load_bytes(Path::new("samplers.glb"), &g.glb(), None, None).unwrap();
    // The file's images (the GGX albedo table its material brings is not one).
    let modes: Vec<u32> = scene
        .textures
        .images()
        .map(|t| t.flags & (flags::wrap(3, 3)))
        .collect();
    assert_eq!(
        modes,
        vec![
            flags::wrap(wrap::MIRROR, wrap::CLAMP),
            flags::wrap(wrap::REPEAT, wrap::MIRROR),
            flags::wrap(wrap::REPEAT, wrap::REPEAT)
        ]
    );
    assert!(
        scene.notes.iter().all(|n| !n.contains("wrap")),
        "{:?}",
        scene.notes
    );
}

/// `KHR_texture_transform` (which Blender's exporter writes, in `extensionsRequired`, for a
/// Mapping node): a file that requires it loads, and each texture's record maps the kernel's
/// coordinates as the extension maps glTF's, uv' = T(offset) R(rotation) S(scale) uv with R's
/// rows (cos, sin), (-sin, cos), computed here in f64 from the specification's formula through
/// v_kernel = 1 - v_glTF. The base colour and the normal map (whose transform the `gltf`
/// crate leaves as JSON) are mapped; an identity transform adds no map; the two records share
/// one image's texels; a malformed transform is an error naming the texture.
#[test]
fn texture_transforms_map_coordinates_as_the_extension_defines_them() {
    let build = |base_transform: serde_json::Value, normal_transform: serde_json::Value| {
        let mut g = GltfWriter::new();
        let t = g.png_texture(&png(|x, y| [(x * 60) as u8, (y * 60) as u8, 128]));
        g.json["extensionsUsed"] = json!(["KHR_texture_transform"]);
        g.json["extensionsRequired"] = json!(["KHR_texture_transform"]);
        let m = g.push(
            "materials",
            json!({
                "pbrMetallicRoughness": { "baseColorTexture": { "index": t,
                    "extensions": { "KHR_texture_transform": base_transform } } },
                "normalTexture": { "index": t,
                    "extensions": { "KHR_texture_transform": normal_transform } }
            }),
        );
        let mesh = g.mesh(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            Some(&[[0.0, 0.0, 1.0]; 3]),
            Some(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
            &[0, 1, 2],
            Some(m),
        );
        g.push("nodes", json!({ "mesh": mesh }));
        g.push("scenes", json!({ "nodes": [0] }));
        twinpath::scene::gltf::load_bytes(Path::new("transform.glb"), &g.glb(), None, None)
    };
    let (offset, rotation, scale) = ([0.25, -0.5], 0.6f64, [2.0, 0.5]);
    let scene = build(
        json!({ "offset": offset, "rotation": rotation, "scale": scale }),
        json!({ "scale": [3.0, 3.0] }),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        scene
            .notes
            .iter()
            .all(|n| !n.contains("KHR_texture_transform")),
        "{:?}",
        scene.notes
    );
    let m = scene.materials[0];
    let record = |slot: usize| scene.textures.textures[m.textures[slot] as usize].clone();
    let apply = |map: [f32; 6], p: glam::DVec2| {
        let a = map.map(f64::from);
        glam::DVec2::new(
            a[0] * p.x + a[1] * p.y + a[2],
            a[3] * p.x + a[4] * p.y + a[5],
        )
    };
    let gltf_map = |p: glam::DVec2, offset: [f64; 2], rotation: f64, scale: [f64; 2]| {
        let (s, c) = rotation.sin_cos();
        let (x, y) = (p.x * scale[0], p.y * scale[1]);
        glam::DVec2::new(c * x + s * y + offset[0], -s * x + c * y + offset[1])
    };
    let flip = |p: glam::DVec2| glam::DVec2::new(p.x, 1.0 - p.y);
    for (slot, (offset, rotation, scale)) in [
        (texture_slot::KD, (offset, rotation, scale)),
        (texture_slot::NORMAL, ([0.0, 0.0], 0.0, [3.0, 3.0])),
    ] {
        let map = record(slot).usage.transform.expect("a map").0;
        for p in [[0.0, 0.0], [1.0, 0.0], [0.3, 0.8], [-1.5, 2.25]] {
            let p = glam::DVec2::from(p);
            let want = flip(gltf_map(flip(p), offset, rotation, scale));
            let got = apply(map, p);
            assert!(
                (got - want).length() < 1e-6,
                "slot {slot} at {p}: {got} against {want}"
            );
        }
    }
    // One image: every record after the first shares its texels.
    let first_texel = |k: u32| {
        scene.textures.words[kernel::texture::RECORDS + kernel::texture::RECORD_WORDS * k as usize]
    };
    assert_eq!(
        first_texel(m.textures[texture_slot::KD]),
        first_texel(m.textures[texture_slot::NORMAL])
    );
    // The identity adds no map.
    let s = build(json!({}), json!({ "rotation": 0.0 })).unwrap();
    let m = s.materials[0];
    for slot in [texture_slot::KD, texture_slot::NORMAL] {
        let k = m.textures[slot] as usize;
        assert_eq!(s.textures.textures[k].usage.transform, None);
        assert_eq!(
            s.textures.textures[k].flags & kernel::texture::flags::TRANSFORM,
            0
        );
    }
    // Malformed: the error names the normal texture's extension.
    let e = build(json!({}), json!({ "scale": "big" }))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("normalTexture") && e.contains("KHR_texture_transform"),
        "{e}"
    );
}

/// Textures Blender can write: a WebP image that only `EXT_texture_webp` names (Blender's
/// exporter writes no PNG fallback unless asked, and requires the extension) loads, texel for
/// texel the PNG of the same pixels; a KTX2 image (`KHR_texture_basisu`) is an error naming the
/// texture, not a file refused as invalid.
#[test]
fn webp_textures_load_and_ktx2_textures_are_named() {
    let pixels = image::RgbImage::from_fn(4, 4, |x, y| {
        image::Rgb([(x * 60) as u8, (y * 60) as u8, 200])
    });
    let mut webp = std::io::Cursor::new(Vec::new());
    image::DynamicImage::ImageRgb8(pixels.clone())
        .write_to(&mut webp, image::ImageFormat::WebP)
        .unwrap();
    let build = |extension: &str, bytes: &[u8], mime: &str| {
        let mut g = GltfWriter::new();
        let view = g.view(bytes);
        let image = g.push("images", json!({ "bufferView": view, "mimeType": mime }));
        let texture = g.push(
            "textures",
            json!({ "extensions": { extension: { "source": image } } }),
        );
        g.json["extensionsUsed"] = json!([extension]);
        g.json["extensionsRequired"] = json!([extension]);
        let m = g.push(
            "materials",
            json!({ "pbrMetallicRoughness": { "baseColorTexture": { "index": texture } } }),
        );
        let mesh = g.mesh(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            None,
            Some(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
            &[0, 1, 2],
            Some(m),
        );
        g.push("nodes", json!({ "mesh": mesh }));
        g.push("scenes", json!({ "nodes": [0] }));
        twinpath::scene::gltf::load_bytes(Path::new("images.glb"), &g.glb(), None, None)
    };
    let scene =
        build("EXT_texture_webp", webp.get_ref(), "image/webp").unwrap_or_else(|e| panic!("{e}"));
    let k = scene.materials[0].textures[texture_slot::KD];
    assert_ne!(k, NONE);
    let mut table = TextureTable::new();
    let png_index = table
        .add_image(
            Path::new("png"),
            image::DynamicImage::ImageRgb8(pixels),
            scene.textures.textures[k as usize].usage,
            "png",
        )
        .unwrap();
    for uv in [
        Vec2::new(0.1, 0.2),
        Vec2::new(0.5, 0.5),
        Vec2::new(0.9, 0.7),
    ] {
        assert_eq!(
            kernel::texture::lookup(&scene.textures.words, k, uv),
            kernel::texture::lookup(&table.words, png_index, uv),
            "lossless WebP reads as its pixels at {uv}"
        );
    }
    let e = build("KHR_texture_basisu", b"not really ktx2", "image/ktx2")
        .unwrap_err()
        .to_string();
    assert!(e.contains("textures[0]") && e.contains("KTX2"), "{e}");
}
