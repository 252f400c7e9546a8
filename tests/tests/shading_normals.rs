//! Vertex normals and texture coordinates of meshes, and shading with them (`kernel::surface`):
//!
//! 1. OBJ `vn`/`vt` and PLY `nx ny nz` / `u v` are read per triangle corner (the shipped UV
//!    sphere's normals are its positions, the smooth torus's point away from its ring).
//! 2. A mesh sphere with vertex normals (64 x 32 segments) gives the analytic sphere's image
//!    (same scene, same lights): away from the silhouette and the terminator, every pixel within
//!    the tessellation's error (3e-3 relative, from the facets' distance to the sphere) plus
//!    noise (z, Sidak), on both backends. The same mesh without its normals fails the same test
//!    (its facets show: 10% of the pixels at 1024 spp), which is the test's power.

use glam::Vec3;
use twinpath::render::Backend;
use twinpath::scene::mesh::{load_mesh, parse_obj};
use twinpath::scene::SceneFile;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{render_film, repo_root, scene_from_toml, with_independent_samples};

#[test]
fn obj_and_ply_vertex_normals_and_texture_coordinates_are_read() {
    let sphere = load_mesh(&repo_root().join("scenes/meshes/uv_sphere.obj")).unwrap();
    assert_eq!(sphere.normals.len(), sphere.triangles.len());
    assert_eq!(sphere.uvs.len(), sphere.triangles.len());
    for (t, n) in sphere.triangles.iter().zip(&sphere.normals) {
        for k in 0..3 {
            let (p, n) = (Vec3::from(t[k]), Vec3::from(n[k]));
            assert!((p - n).length() < 1e-6, "normal {n} at {p}");
        }
    }
    assert!(sphere
        .uvs
        .iter()
        .flatten()
        .flatten()
        .all(|c| (0.0..=1.0).contains(c)));

    let torus = load_mesh(&repo_root().join("scenes/meshes/torus_smooth.ply")).unwrap();
    assert_eq!(torus.normals.len(), torus.triangles.len());
    assert_eq!(torus.uvs.len(), torus.triangles.len());
    for (t, n) in torus.triangles.iter().zip(&torus.normals) {
        for k in 0..3 {
            let (p, n) = (Vec3::from(t[k]), Vec3::from(n[k]));
            // Ring radius 1, tube radius 0.35: the normal is (p - ring point) / 0.35.
            let ring = Vec3::new(p.x, 0.0, p.z).normalize();
            assert!(((p - ring) / 0.35 - n).length() < 1e-5, "normal {n} at {p}");
        }
    }

    // The flat meshes have neither; a file giving normals to some faces only is shaded flat.
    let flat = load_mesh(&repo_root().join("scenes/meshes/torus.ply")).unwrap();
    assert!(flat.normals.is_empty() && flat.uvs.is_empty());
    let partial = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 2 4 3\n";
    let soup = parse_obj(std::path::Path::new("partial.obj"), partial.as_bytes()).unwrap();
    assert_eq!(soup.triangles.len(), 2);
    assert!(soup.normals.is_empty());

    // A file the fuzzer made: a relative vt index reaching before the first vt (which tobj's
    // usize arithmetic would wrap and then overflow on) is an error naming its line.
    let crash = std::fs::read(repo_root().join("tests/fixtures/fuzz_obj_attributes.obj")).unwrap();
    let e = parse_obj(std::path::Path::new("fuzz.obj"), &crash).unwrap_err();
    assert_eq!(e.line, Some(3), "{e}");
    assert!(e.message.contains("texture index -2"), "{e}");
}

/// The scene: a unit sphere (`shape`) of albedo 0.6 at the origin under a sphere light and a
/// dim sky, seen from the front.
fn sphere_scene(shape: &str) -> SceneFile {
    let text = format!(
        r#"
        [camera]
        eye = [0.0, 0.4, 4.0]
        look_at = [0.0, 0.0, 0.0]
        up = [0.0, 1.0, 0.0]
        vfov = 34.0
        width = 40
        height = 40
        [render]
        seed = 31
        [materials]
        ball = {{ kd = [0.6, 0.6, 0.6] }}
        lamp = {{ emission = [30.0, 30.0, 30.0] }}
        [[sphere]]
        center = [1.5, 2.5, 4.0]
        radius = 0.4
        material = "lamp"
        [background]
        radiance = [0.2, 0.2, 0.2]
        {shape}
        "#
    );
    with_independent_samples(scene_from_toml(&text))
}

const ANALYTIC: &str = "[[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"ball\"";

fn mesh(path: &std::path::Path) -> String {
    format!(
        "[[mesh]]\nfile = \"{}\"\nmaterial = \"ball\"",
        path.display()
    )
}

/// Pixels whose 4 x 4 quadrature rays all meet the analytic sphere facing the camera
/// (|n . d| > 0.3) at points the lamp lights at more than 0.3 cosine: away from the silhouette
/// (where polygon and circle differ) and the terminator (where shadow rays graze the facets).
fn interior_pixels(scene: &SceneFile) -> Vec<bool> {
    let lamp = Vec3::new(1.5, 2.5, 4.0);
    twinpath_tests::pixel_quadrature(&scene.scene, 4, |eye, d| {
        let t = kernel::geometry::intersect_sphere(eye, d, Vec3::ZERO, 1.0, 0.0, f32::INFINITY);
        if t < 0.0 {
            return None;
        }
        let n = (eye + t * d).normalize();
        (-n.dot(d) > 0.3 && n.dot((lamp - n).normalize()) > 0.3).then_some(0.0)
    })
    .iter()
    .map(Option::is_some)
    .collect()
}

/// Relative difference allowed between a pixel of the mesh and of the analytic sphere beyond
/// noise: the mesh's facets lie up to r (1 - cos(pi / 64)) = 1.2e-3 inside the sphere (its
/// longitudes and latitudes are pi / 32 apart), and their interpolated normals are the sphere's
/// only at the vertices; the measured mean difference is 9e-4 (CPU, 1024 spp).
const TESSELLATION: f64 = 3e-3;

/// How two films differ over `mask`: the fraction of pixels whose difference exceeds
/// [`TESSELLATION`] relative plus z (Sidak over the pixels, 1e-3) standard errors, and the
/// mean relative difference.
fn compare(a: &twinpath::film::Film, b: &twinpath::film::Film, mask: &[bool]) -> (f64, f64) {
    let (ma, mb) = (a.mean(), b.mean());
    let (va, vb) = (a.variance_of_mean(), b.variance_of_mean());
    let pixels: Vec<usize> = (0..mask.len()).filter(|&i| mask[i]).collect();
    let z = twinpath_tests::z_critical(1e-3, pixels.len());
    let (mut outside, mut rel) = (0usize, 0.0);
    for &i in &pixels {
        let (x, y) = (ma[i][0] as f64, mb[i][0] as f64);
        let sigma = (va[i][0] as f64 + vb[i][0] as f64).sqrt();
        if (x - y).abs() > TESSELLATION * x.max(y) + z * sigma {
            outside += 1;
        }
        rel += (y - x) / x;
    }
    (
        outside as f64 / pixels.len() as f64,
        rel / pixels.len() as f64,
    )
}

#[test]
fn smooth_mesh_sphere_converges_to_the_analytic_sphere_on_both_backends() {
    let dir = std::env::temp_dir().join(format!("twinpath-smooth-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // The shipped UV sphere without its normals (faces v/vt/vn become v/vt).
    let smooth_path = repo_root().join("scenes/meshes/uv_sphere.obj");
    let flat_text: String = std::fs::read_to_string(&smooth_path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with("vn "))
        .map(|l| {
            if let Some(face) = l.strip_prefix("f ") {
                let corners: Vec<String> = face
                    .split_whitespace()
                    .map(|c| c.rsplit_once('/').unwrap().0.to_string())
                    .collect();
                format!("f {}\n", corners.join(" "))
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let flat_path = dir.join("uv_sphere_flat.obj");
    std::fs::write(&flat_path, flat_text).unwrap();

    let analytic = sphere_scene(ANALYTIC);
    let mask = interior_pixels(&analytic);
    let tested = mask.iter().filter(|&&m| m).count();
    assert!(tested > 200, "only {tested} interior pixels");
    for (backend, spp) in [(Backend::Cpu, 1024), (Backend::Gpu, 256)] {
        let reference = render_film(&analytic, backend, spp);
        let mut smooth = sphere_scene(&mesh(&smooth_path));
        smooth.settings.seed += 1;
        let smooth = render_film(&smooth, backend, spp);
        let mut flat = sphere_scene(&mesh(&flat_path));
        flat.settings.seed += 2;
        let flat = render_film(&flat, backend, spp);
        let (smooth_out, smooth_rel) = compare(&reference, &smooth, &mask);
        let (flat_out, flat_rel) = compare(&reference, &flat, &mask);
        println!(
            "{backend:?}, {spp} spp, {tested} pixels: smooth mesh vs analytic sphere: \
             {:.1}% of pixels beyond {TESSELLATION:e} + noise, mean relative difference \
             {smooth_rel:+.2e}; the mesh without normals: {:.1}% beyond, mean {flat_rel:+.2e}",
            100.0 * smooth_out,
            100.0 * flat_out
        );
        assert_eq!(smooth_out, 0.0, "{backend:?}: smooth mesh differs");
        assert!(smooth_rel.abs() < TESSELLATION, "{backend:?}: mean differs");
        // The same test rejects the flat mesh.
        assert!(flat_out > 0.0, "{backend:?}: facets not seen");
    }
    assert_validation_clean();
}
