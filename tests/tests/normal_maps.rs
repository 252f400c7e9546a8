//! Normal maps (`texture_slot::NORMAL`, glTF's `normalTexture`; `kernel::surface::mapped_normal`):
//!
//! 1. The kernel's mapped normal is the glTF formula, computed here in f64 from the texel and
//!    the frame: n = normalize(T m.x + B m.y + N m.z), m = (2 texel - 1)(scale, scale, 1),
//!    T the tangent made orthogonal to N, B = sign N x T; through `surface::shade` it stands
//!    on the vertex-normal blend, or on the geometric normal where the triangle has none.
//! 2. A diffuse plane with a constant normal map under a point light matches its closed form,
//!    kd I max(0, n.l) / (pi d^2) with n the mapped normal, per pixel on both backends; the
//!    unmapped normal, a flipped bitangent and an ignored scale are each rejected.
//! 3. SceneFile-file errors name the field.

use glam::{DVec3, Vec2, Vec3};
use kernel::scene::{texture_slot, Material, ShadingTriangle};
use std::path::{Path, PathBuf};
use twinpath::render::Backend;
use twinpath::scene::textures::{TextureTable, TextureUse};
use twinpath::scene::SceneFile;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_film_matches, max_abs_z, pixel_quadrature, render_film, scene_from_toml,
    with_independent_samples,
};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("twinpath-nmap-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 2 x 2 PNG of one colour `rgb` in `dir`.
fn constant_png(dir: &Path, rgb: [u8; 3]) -> PathBuf {
    let path = dir.join(format!("n_{}_{}_{}.png", rgb[0], rgb[1], rgb[2]));
    image::RgbImage::from_pixel(2, 2, image::Rgb(rgb))
        .save(&path)
        .unwrap();
    path
}

/// The glTF formula in f64: the mapped normal for base normal `n`, tangent `t` (any length,
/// not necessarily orthogonal to `n`), bitangent sign `sign`, texel bytes `rgb` and `scale`.
fn reference(n: DVec3, t: DVec3, sign: f64, rgb: [u8; 3], scale: f64) -> DVec3 {
    let n = n.normalize();
    let t = (t - n * n.dot(t)).normalize();
    let b = n.cross(t) * sign;
    let m = rgb.map(|c| 2.0 * c as f64 / 255.0 - 1.0);
    (t * m[0] * scale + b * m[1] * scale + n * m[2]).normalize()
}

#[test]
fn the_mapped_normal_is_gltfs_formula() {
    let dir = temp_dir("formula");
    let cases: [([u8; 3], f32, f32, Vec3, Vec3); 5] = [
        ([128, 128, 255], 1.0, 1.0, Vec3::Y, Vec3::X),
        (
            [170, 90, 220],
            1.5,
            1.0,
            Vec3::new(0.2, 1.0, -0.1),
            Vec3::new(1.0, 0.3, 0.2),
        ),
        (
            [170, 90, 220],
            1.5,
            -1.0,
            Vec3::new(0.2, 1.0, -0.1),
            Vec3::new(1.0, 0.3, 0.2),
        ),
        (
            [20, 240, 140],
            0.5,
            1.0,
            Vec3::new(-0.6, 0.0, 0.8),
            Vec3::new(0.0, 2.0, 0.5),
        ),
        (
            [255, 0, 30],
            2.0,
            -1.0,
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.0, 0.0, 3.0),
        ),
    ];
    for (rgb, scale, sign, n, t) in cases {
        let mut table = TextureTable::new();
        let map = table
            .add(
                &constant_png(&dir, rgb),
                TextureUse {
                    colour: false,
                    wrap: [kernel::texture::wrap::REPEAT; 2],
                    transform: None,
                    second_set: false,
                },
                "n",
            )
            .unwrap();
        let mut m = Material::diffuse([0.5; 3]);
        m.textures[texture_slot::NORMAL] = map;
        m.normal_scale = scale;
        let frame = ShadingTriangle::tangent_frame([t.to_array(); 3], sign);
        let want = reference(n.as_dvec3(), t.as_dvec3(), sign as f64, rgb, scale as f64);
        let close = |got: Vec3, label: &str| {
            assert!(
                (got.as_dvec3() - want).length() < 2e-6,
                "{label} {rgb:?} scale {scale} sign {sign}: {got} vs {want}"
            );
        };
        // The function itself, and through `shade`: on the vertex normals' blend...
        close(
            kernel::surface::mapped_normal(
                n.normalize(),
                &frame,
                Vec2::new(0.2, 0.3),
                Vec3::from(rgb.map(|c| c as f32 / 255.0)),
                scale,
            ),
            "mapped_normal",
        );
        let smooth = ShadingTriangle {
            normal0: n.to_array(),
            normal1: n.to_array(),
            normal2: n.to_array(),
            uv0: [0.1, 0.1],
            uv1: [0.9, 0.2],
            uv2: [0.4, 0.8],
            flags: kernel::scene::shading_flags::NORMALS,
        };
        let (_, got) = twinpath_tests::shade_at(
            0,
            0,
            Vec2::new(0.2, 0.3),
            Vec3::Z,
            kernel::scene::NONE,
            &[m],
            &[smooth, frame],
            &table.words,
            &[],
        );
        close(got, "shade, vertex normals");
        // ...and on the geometric normal where the triangle has none.
        let flat = ShadingTriangle { flags: 0, ..smooth };
        let (_, got) = twinpath_tests::shade_at(
            0,
            0,
            Vec2::new(0.2, 0.3),
            n.normalize(),
            kernel::scene::NONE,
            &[m],
            &[flat, frame],
            &table.words,
            &[],
        );
        close(got, "shade, geometric normal");
    }
    // A tangent along the normal has no direction left: the point stays unmapped.
    let frame = ShadingTriangle::tangent_frame([[0.0, 2.0, 0.0]; 3], 1.0);
    let got =
        kernel::surface::mapped_normal(Vec3::Y, &frame, Vec2::ZERO, Vec3::new(0.9, 0.1, 0.5), 1.0);
    assert_eq!(got, Vec3::Y);
}

const KD: f64 = 0.6;
const LIGHT: DVec3 = DVec3::new(0.5, 1.5, 0.25);
const INTENSITY: f64 = 3.0;
const TEXEL: [u8; 3] = [170, 90, 220];
const SCALE: f64 = 1.5;

/// The plane y = 0 (a quad: u along +x, v along -z, so T = +x, B = -z, sign +1) with a
/// constant normal map under a point light; black background, so the light's NEE sample is
/// all a pixel gets.
fn mapped_plane(dir: &Path) -> SceneFile {
    let map = constant_png(dir, TEXEL);
    let text = format!(
        "[camera]\neye = [0, 3, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 50\nwidth = 24\nheight = 18\n\
         [render]\nseed = 5\n[materials]\nplane = {{ kd = [{KD}, {KD}, {KD}], normal_map = \"{}\", normal_scale = {SCALE} }}\n\
         [[quad]]\ncorner = [-100, 0, 100]\nedge1 = [200, 0, 0]\nedge2 = [0, 0, -200]\nmaterial = \"plane\"\n\
         [[light]]\nposition = [{}, {}, {}]\nintensity = [{INTENSITY}, {INTENSITY}, {INTENSITY}]\n",
        map.display(),
        LIGHT.x,
        LIGHT.y,
        LIGHT.z
    );
    let path = dir.join("plane.toml");
    std::fs::write(&path, text).unwrap();
    // Independent samples: a z-test's variance assumes them (Sobol points are stratified, and
    // their error is far below what their sample variance says: max |z| 0.02 with them).
    with_independent_samples(SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}")))
}

/// Each pixel's exact value with shading normal `n` at every point; `None` for pixels any of
/// whose quadrature points sees the light or the camera near or below the shading plane
/// (there the kernel's rule for disagreeing normals applies, tested elsewhere).
fn exact(scene: &SceneFile, n: DVec3) -> Vec<Option<f64>> {
    pixel_quadrature(&scene.scene, 16, |eye, d| {
        if d.y >= 0.0 {
            return None;
        }
        let x = (eye + d * (-eye.y / d.y)).as_dvec3();
        let to = LIGHT - x;
        let dist = to.length();
        let (cos_l, cos_v) = (n.dot(to) / dist, n.dot((eye.as_dvec3() - x).normalize()));
        if cos_l < 0.02 || cos_v < 0.02 {
            return None;
        }
        Some(KD / std::f64::consts::PI * INTENSITY * cos_l / (dist * dist))
    })
}

#[test]
fn a_normal_mapped_plane_under_a_point_light_matches_its_closed_form_on_both_backends() {
    let dir = temp_dir("plane");
    let scene = mapped_plane(&dir);
    assert_eq!(
        scene.scene.shading.len(),
        4,
        "a record and a tangent frame per triangle"
    );
    let features = scene.features();
    // A mapped normal is a shading normal: the bit that lets the vertex read one comes with it
    // (without it the GPU's specialized path shaded this plane flat).
    let both = kernel::features::NORMAL_MAPS | kernel::features::SHADING_NORMALS;
    assert_eq!(features & both, both);
    let (t, b, n) = (DVec3::X, -DVec3::Z, DVec3::Y);
    let mapped = reference(n, t, 1.0, TEXEL, SCALE);
    let want = exact(&scene, mapped);
    let tested = want.iter().filter(|e| e.is_some()).count();
    assert!(
        tested > want.len() / 2,
        "{tested} of {} pixels tested",
        want.len()
    );
    let wrong = [
        ("the unmapped normal", n),
        ("a flipped bitangent", reference(n, t, -1.0, TEXEL, SCALE)),
        ("scale ignored", reference(n, t, 1.0, TEXEL, 1.0)),
    ];
    assert!((mapped - n).length() > 0.3 && mapped.dot(b).abs() > 0.3);
    for backend in [Backend::Cpu, Backend::Gpu] {
        let film = render_film(&scene, backend, 256);
        assert_film_matches(&film, &want, &format!("normal-mapped plane, {backend:?}"));
        let (mean, var) = (film.mean(), film.variance_of_mean());
        for (label, normal) in wrong {
            let worst = max_abs_z(&mean, &var, &exact(&scene, normal));
            assert!(
                worst > 20.0,
                "{backend:?}: {label} not rejected (max |z| {worst})"
            );
        }
    }
    assert_validation_clean();
}

#[test]
fn normal_map_errors_name_the_field() {
    let dir = temp_dir("errors");
    let map = constant_png(&dir, [128, 128, 255]);
    let error = |material: &str| {
        let text = format!(
            "[camera]\neye = [0, 1, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 8\nheight = 8\n\
             [materials]\nm = {material}\n[[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n"
        );
        let path = dir.join("bad.toml");
        std::fs::write(&path, text).unwrap();
        SceneFile::load(&path).unwrap_err().to_string()
    };
    let m = map.display();
    for (material, field, says) in [
        (
            "{ kd = [0.5, 0.5, 0.5], normal_scale = 2 }".to_string(),
            "materials.m.normal_scale",
            "belongs to normal_map",
        ),
        (
            format!("{{ kd = [0.5, 0.5, 0.5], normal_map = \"{m}\", normal_scale = nan }}"),
            "materials.m.normal_scale",
            "not finite",
        ),
        (
            format!("{{ emission = [1, 1, 1], normal_map = \"{m}\" }}"),
            "materials.m.normal_map",
            "a light has no shading normal",
        ),
        (
            "{ kd = [0.5, 0.5, 0.5], normal_map = \"missing.png\" }".to_string(),
            "materials.m.normal_map",
            "does not exist",
        ),
    ] {
        let e = error(&material);
        assert!(e.contains(field) && e.contains(says), "{material}: {e}");
    }
    // A scene without normal maps keeps the feature bit off (its paths skip the code).
    let plain = scene_from_toml(
        "[camera]\neye = [0, 1, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 8\nheight = 8\n[materials]\nm = { kd = [0.5, 0.5, 0.5] }\n[[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n",
    );
    assert_eq!(plain.features() & kernel::features::NORMAL_MAPS, 0);
}

/// A glTF material whose normal map is flat (every texel the unperturbed normal): its index.
fn flat_normal_map_material(g: &mut twinpath_tests::gltf_writer::GltfWriter) -> usize {
    let img = image::RgbImage::from_pixel(2, 2, image::Rgb([128, 128, 255]));
    let mut png = std::io::Cursor::new(Vec::new());
    img.write_to(&mut png, image::ImageFormat::Png).unwrap();
    let tex = g.png_texture(&png.into_inner());
    g.push(
        "materials",
        serde_json::json!({ "normalTexture": { "index": tex } }),
    )
}

/// The tangent frame a glTF file's own `TANGENT` gives, under no transform, a mirroring one and
/// a rotation; and the per-triangle frame where the file has none or a degenerate one.
#[test]
fn gltf_tangents_are_read_and_transformed() {
    use serde_json::json;
    use twinpath_tests::gltf_writer::GltfWriter;
    let dir = temp_dir("tangents");
    // One triangle in the plane y = 0 (front +y), u along +x, v (ours) along -z: the frame
    // from the coordinates is T = +x, sign +1. The file says T = (0, 0, 2), w = -1 instead.
    let load = |tangent: Option<[f32; 4]>, node: serde_json::Value, name: &str| {
        let mut g = GltfWriter::new();
        let material = flat_normal_map_material(&mut g);
        let mesh = g.mesh(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
            Some(&[[0.0, 1.0, 0.0]; 3]),
            Some(&[[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]]),
            &[0, 1, 2],
            Some(material),
        );
        if let Some(t) = tangent {
            let a = g.floats(&[t, t, t].concat(), "VEC4");
            g.json["meshes"][mesh]["primitives"][0]["attributes"]["TANGENT"] = json!(a);
        }
        let mut node = node;
        node["mesh"] = json!(mesh);
        g.push("nodes", node);
        g.push("scenes", json!({ "nodes": [0] }));
        let path = dir.join(name);
        std::fs::write(&path, g.glb()).unwrap();
        SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}"))
    };
    let frame = |s: &SceneFile| {
        assert_eq!(s.scene.shading.len(), 2, "a record and its tangent frame");
        (
            Vec3::from(s.scene.shading[1].normal0),
            s.scene.shading[1].uv0[0],
        )
    };
    let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-6;
    // No TANGENT: the coordinates' frame.
    let (t, sign) = frame(&load(None, json!({}), "none.glb"));
    assert!(close(t, Vec3::X) && sign == 1.0, "{t} {sign}");
    // The file's tangent as given.
    let file = Some([0.0, 0.0, 2.0, -1.0]);
    let (t, sign) = frame(&load(file, json!({}), "given.glb"));
    assert!(
        close(t, Vec3::new(0.0, 0.0, 2.0)) && sign == -1.0,
        "{t} {sign}"
    );
    // A mirroring node (x -> -x): T' = M T = T here, and the sign flips.
    let (t, sign) = frame(&load(
        file,
        json!({ "scale": [-1.0, 1.0, 1.0] }),
        "mirrored.glb",
    ));
    assert!(
        close(t, Vec3::new(0.0, 0.0, 2.0)) && sign == 1.0,
        "{t} {sign}"
    );
    // A rotation of 90 degrees about +y (z -> x): T' = (2, 0, 0), the sign kept.
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let (t, sign) = frame(&load(
        file,
        json!({ "rotation": [0.0, h, 0.0, h] }),
        "rotated.glb",
    ));
    assert!(
        close(t, Vec3::new(2.0, 0.0, 0.0)) && sign == -1.0,
        "{t} {sign}"
    );
    // A degenerate tangent (zero xyz) falls back to the coordinates' frame.
    let (t, sign) = frame(&load(Some([0.0, 0.0, 0.0, 1.0]), json!({}), "zero.glb"));
    assert!(close(t, Vec3::X) && sign == 1.0, "{t} {sign}");
}

/// A normal-mapped glTF mesh without `TANGENT` gets MikkTSpace's vertex tangents (glTF 2.0,
/// "Meshes"), as Blender computes them: on a cylinder of 16 segments (u around it, v along its
/// axis), each corner's tangent is the direction of increasing u at that vertex, (-sin phi, 0,
/// -cos phi), not the facet's (one tangent per triangle is off by half a segment, 0.19); the
/// seam's corners, whose coordinates differ on either side, are the facet's.
#[test]
fn gltf_meshes_without_tangents_get_mikktspace_vertex_tangents() {
    use serde_json::json;
    use twinpath_tests::gltf_writer::GltfWriter;
    const SEGMENTS: u32 = 16;
    let dir = temp_dir("mikktspace");
    let mut g = GltfWriter::new();
    let material = flat_normal_map_material(&mut g);
    let (mut p, mut n, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for k in 0..=SEGMENTS {
        let phi = std::f32::consts::TAU * k as f32 / SEGMENTS as f32;
        for y in [0.0, 1.0] {
            p.push([phi.cos(), y, -phi.sin()]);
            n.push([phi.cos(), 0.0, -phi.sin()]);
            // glTF's v grows down the image: the image's up is +y.
            uv.push([k as f32 / SEGMENTS as f32, 1.0 - y]);
        }
    }
    for k in 0..SEGMENTS {
        let (a, c, b, d) = (2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 3);
        idx.extend([a, b, d, a, d, c]);
    }
    let mesh = g.mesh(&p, Some(&n), Some(&uv), &idx, Some(material));
    g.push("nodes", json!({ "mesh": mesh }));
    g.push("scenes", json!({ "nodes": [0] }));
    let path = dir.join("cylinder.glb");
    std::fs::write(&path, g.glb()).unwrap();
    let s = SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.scene.triangles.len(), 2 * SEGMENTS as usize);
    let (mut checked, mut seam) = (0, 0);
    for t in &s.scene.triangles {
        let frame = &s.scene.shading[t.shading as usize + 1];
        assert_eq!(
            frame.uv0[0], 1.0,
            "the bitangent's sign: v grows along +y = N x T"
        );
        let p0 = Vec3::from(t.p0);
        let corners = [p0, p0 + Vec3::from(t.edge1), p0 + Vec3::from(t.edge2)];
        let tangents = [frame.normal0, frame.normal1, frame.normal2].map(Vec3::from);
        for (c, tangent) in corners.iter().zip(tangents) {
            let phi = (-c.z).atan2(c.x);
            let want = Vec3::new(-phi.sin(), 0.0, -phi.cos());
            if (c.z.abs() < 1e-6) && c.x > 0.0 {
                // The seam: the coordinates differ on its two sides, so MikkTSpace welds
                // nothing there and the corner keeps its facet's tangent.
                seam += 1;
                assert!((tangent - want).length() < 0.25, "{c}: {tangent} vs {want}");
                continue;
            }
            assert!(
                (tangent - want).length() < 1e-4,
                "corner {c}: tangent {tangent}, the vertex's direction of u {want}"
            );
            checked += 1;
        }
    }
    assert_eq!(seam, 6, "three corners on each side of the seam");
    assert_eq!(checked, 6 * SEGMENTS as usize - 6);
}
