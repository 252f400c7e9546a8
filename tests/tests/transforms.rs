//! Transforms of spheres, quads and meshes in the scene file (`twinpath::scene::transform`):
//!
//! 1. A quad under scale, rotate and translate is the quad whose corners are transformed (an
//!    f64 reference), and a 4 x 4 matrix gives what the same scale, rotation and translation give.
//! 2. A mirroring transform keeps front faces (a one-sided light still emits to the side its
//!    transformed front faces) and closed meshes outward; vertex normals follow the inverse
//!    transpose (a sphere scaled into an ellipsoid gets the ellipsoid's normals).
//! 3. Spheres take a uniform scale and rotations only; bad transforms are errors naming the
//!    field.

use glam::{DMat3, DVec3, Vec3};
use twinpath::scene::{parse_scene, SceneFile};
use twinpath_tests::{repo_root, scene_from_toml};

const CAMERA: &str = "[camera]\neye = [0, 1, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 8\nheight = 8\n";

fn scene(body: &str) -> SceneFile {
    scene_from_toml(&format!(
        "{CAMERA}[materials]\nwhite = {{ kd = [0.5, 0.5, 0.5] }}\nlamp = {{ emission = [1, 1, 1] }}\nglass = {{ dielectric = {{ ior = 1.5 }} }}\n{body}"
    ))
}

fn error(body: &str) -> String {
    let text = format!("{CAMERA}[materials]\nwhite = {{ kd = [0.5, 0.5, 0.5] }}\n{body}");
    match parse_scene(&text, &repo_root().join("scenes/test.toml")) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    }
}

/// The triangles' vertices, in world space.
fn vertices(s: &SceneFile) -> Vec<[Vec3; 3]> {
    s.scene
        .triangles
        .iter()
        .map(|t| {
            let p0 = Vec3::from(t.p0);
            [p0, p0 + Vec3::from(t.edge1), p0 + Vec3::from(t.edge2)]
        })
        .collect()
}

fn assert_close(a: &[[Vec3; 3]], b: &[[Vec3; 3]], tol: f32, label: &str) {
    assert_eq!(a.len(), b.len(), "{label}: triangle counts");
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        for c in 0..3 {
            let d = (x[c] - y[c]).abs().max_element();
            assert!(
                d <= tol * (1.0 + y[c].abs().max_element()),
                "{label}: triangle {k} corner {c}: {} vs {}",
                x[c],
                y[c]
            );
        }
    }
}

#[test]
fn quads_and_meshes_transform_by_scale_rotate_translate_or_matrix() {
    let (scale, degrees, axis, translate) = (
        DVec3::new(2.0, 0.5, 1.5),
        37.0f64,
        DVec3::new(1.0, 2.0, -0.5),
        DVec3::new(0.3, -1.2, 4.0),
    );
    let r = DMat3::from_axis_angle(axis.normalize(), degrees.to_radians());
    let m = r * DMat3::from_diagonal(scale);
    let map = |p: DVec3| m * p + translate;
    let (corner, e1, e2) = (
        DVec3::new(-1.0, 0.0, 1.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -2.0),
    );
    let trs = format!(
        "scale = [{}, {}, {}]\nrotate = [{degrees}, {}, {}, {}]\ntranslate = [{}, {}, {}]",
        scale.x, scale.y, scale.z, axis.x, axis.y, axis.z, translate.x, translate.y, translate.z
    );
    let quad = scene(&format!(
        "[[quad]]\ncorner = [-1, 0, 1]\nedge1 = [2, 0, 0]\nedge2 = [0, 0, -2]\nmaterial = \"white\"\n{trs}\n"
    ));
    let c = map(corner).as_vec3();
    let (a, b) = ((m * e1).as_vec3(), (m * e2).as_vec3());
    let want = [[c, c + a, c + a + b], [c, c + a + b, c + b]];
    assert_close(&vertices(&quad), &want, 1e-6, "quad");

    // The same transform as a matrix, row-major, on a mesh.
    let rows: Vec<String> = (0..3)
        .map(|i| {
            let row = m.row(i);
            let t = translate[i];
            format!("[{}, {}, {}, {t}]", row.x, row.y, row.z)
        })
        .collect();
    let mesh = |transform: &str| {
        scene(&format!(
            "[[mesh]]\nfile = \"meshes/icosphere.obj\"\nmaterial = \"white\"\n{transform}\n"
        ))
    };
    let by_trs = mesh(&trs);
    let by_matrix = mesh(&format!("matrix = [{}, [0, 0, 0, 1]]", rows.join(", ")));
    let plain = mesh("");
    let want: Vec<[Vec3; 3]> = vertices(&plain)
        .iter()
        .map(|t| t.map(|p| map(p.as_dvec3()).as_vec3()))
        .collect();
    assert_close(
        &vertices(&by_trs),
        &want,
        1e-6,
        "mesh, scale/rotate/translate",
    );
    assert_close(&vertices(&by_matrix), &want, 1e-6, "mesh, matrix");

    // Without a rotation the arithmetic is the plain p * scale + translate, as before.
    let st = mesh("scale = 0.4\ntranslate = [-0.45, 0.4, -0.3]");
    let want: Vec<[Vec3; 3]> = vertices(&plain)
        .iter()
        .map(|t| t.map(|p| p * 0.4 + Vec3::new(-0.45, 0.4, -0.3)))
        .collect();
    for (x, y) in vertices(&st).iter().zip(&want) {
        // p0 exactly; the others through the stored edges.
        assert_eq!(x[0], y[0]);
    }
}

#[test]
fn mirroring_keeps_front_faces_and_normals_follow_the_inverse_transpose() {
    // A one-sided panel facing down (edge1 x edge2 = -y), mirrored in x: still facing down.
    for transform in [
        "",
        "scale = [-1, 1, 1]",
        "matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]]",
    ] {
        let s = scene(&format!(
            "[[quad]]\ncorner = [-0.5, 1, -0.5]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, 1]\nmaterial = \"lamp\"\n{transform}\n"
        ));
        for t in &s.scene.triangles {
            let n = Vec3::from(t.edge1).cross(Vec3::from(t.edge2));
            assert!(
                n.y < 0.0 && n.x.abs() < 1e-6 && n.z.abs() < 1e-6,
                "{transform}: front {n}"
            );
        }
    }
    // A closed glass mesh mirrored stays closed and outward (signed volume > 0).
    for transform in [
        "scale = [1, -1, 1]",
        "scale = [-2, 1, 1]\nrotate = [30, 0, 1, 0]",
    ] {
        let s = scene(&format!(
            "[[mesh]]\nfile = \"meshes/icosphere.obj\"\nmaterial = \"glass\"\n{transform}\n"
        ));
        let volume: f64 = vertices(&s)
            .iter()
            .map(|t| t[0].as_dvec3().dot(t[1].as_dvec3().cross(t[2].as_dvec3())) / 6.0)
            .sum();
        assert!(volume > 0.0, "{transform}: volume {volume}");
    }
    // The unit UV sphere scaled into an ellipsoid (2, 1, 0.5): at a surface point q, its normal
    // is along (q.x / 4, q.y, q.z / 0.25).
    let s = scene(
        "[[mesh]]\nfile = \"meshes/uv_sphere.obj\"\nmaterial = \"white\"\nscale = [2, 1, 0.5]\n",
    );
    let mut checked = 0;
    for (t, p) in s.scene.triangles.iter().zip(vertices(&s)) {
        let r = &s.scene.shading[t.shading as usize];
        for (q, n) in p.iter().zip([r.normal0, r.normal1, r.normal2]) {
            let want = Vec3::new(q.x / 4.0, q.y, q.z / 0.25).normalize();
            let got = Vec3::from(n).normalize();
            assert!(
                (got - want).length() < 1e-5,
                "normal {got} at {q}, want {want}"
            );
            checked += 1;
        }
    }
    assert!(checked > 10_000);
}

#[test]
fn spheres_take_uniform_scales_and_bad_transforms_are_errors() {
    let s = scene(
        "[[sphere]]\ncenter = [1, 0, 0]\nradius = 0.5\nmaterial = \"white\"\nscale = 2\nrotate = [90, 0, 0, 1]\ntranslate = [0, 1, 0]\n",
    );
    let c = Vec3::from(s.scene.spheres[0].center);
    assert!((c - Vec3::new(0.0, 3.0, 0.0)).length() < 1e-6, "centre {c}");
    assert!((s.scene.spheres[0].radius - 1.0).abs() < 1e-6);

    let sphere = "[[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"white\"\n";
    let quad = "[[quad]]\ncorner = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, -1]\nmaterial = \"white\"\n";
    let cases = [
        (format!("{sphere}scale = [1, 2, 1]"), "sphere[0]", "uniform scale"),
        (format!("{quad}scale = [1, 0, 1]"), "quad[0].scale", "non-zero"),
        (format!("{quad}scale = \"big\""), "quad[0].scale", "a number or [x, y, z]"),
        (format!("{quad}rotate = [30, 0, 0, 0]"), "quad[0].rotate", "non-zero axis"),
        (
            format!("{quad}matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\ntranslate = [1, 0, 0]"),
            "quad[0].matrix",
            "not both",
        ),
        (
            format!("{quad}matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1]]"),
            "quad[0].matrix",
            "singular",
        ),
        (
            format!("{quad}matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]"),
            "quad[0].matrix",
            "affine",
        ),
        (format!("{quad}translate = [1e16, 0, 0]"), "quad[0]", "beyond"),
    ];
    for (body, field, want) in cases {
        let got = error(&body);
        println!("{got}");
        assert!(
            got.contains(field) && got.contains(want),
            "'{got}' lacks {field} / {want}"
        );
    }
}
