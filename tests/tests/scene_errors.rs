//! Bad input of every class is an error naming the file, the line and the field; never a panic.

use std::path::{Path, PathBuf};
use twinpath::scene::{mesh::parse_ply, parse_scene, SceneError, SceneFile};
use twinpath::settings::{LightSampling, LightSelection, Mis, Roulette, Sampler};

const GOOD: &str = r#"
[camera]
eye = [0, 1, 4]
look_at = [0, 1, 0]
up = [0, 1, 0]
vfov = 40
width = 32
height = 24

[materials]
white = { kd = [0.5, 0.5, 0.5] }
lamp = { emission = [4, 4, 4] }

[[sphere]]
center = [0, 1, 0]
radius = 0.5
material = "white"

[[quad]]
corner = [-1, 0, 1]
edge1 = [2, 0, 0]
edge2 = [0, 0, -2]
material = "white"
"#;

fn scene_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/bad.toml")
}

fn error_of(text: &str) -> SceneError {
    match parse_scene(text, &scene_path()) {
        Ok(_) => panic!("accepted bad scene:\n{text}"),
        Err(e) => {
            println!("{e}");
            e
        }
    }
}

/// Replaces the first occurrence of `from` in the good scene.
fn with(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "{from}");
    GOOD.replacen(from, to, 1)
}

fn line_containing(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

fn assert_error(text: &str, line_needle: &str, field: &str, message_part: &str) {
    let e = error_of(text);
    assert_eq!(e.file, scene_path());
    assert_eq!(e.line, Some(line_containing(text, line_needle)), "{e}");
    assert!(
        e.field.contains(field),
        "field {:?} should name {field:?}: {e}",
        e.field
    );
    assert!(
        e.message
            .to_lowercase()
            .contains(&message_part.to_lowercase()),
        "message {:?} should say {message_part:?}",
        e.message
    );
    let shown = e.to_string();
    assert!(shown.starts_with(&format!("{}:{}: ", scene_path().display(), e.line.unwrap())));
}

#[test]
fn good_scene_parses() {
    let s = parse_scene(GOOD, &scene_path()).unwrap();
    assert_eq!(s.scene.spheres.len(), 1);
    assert_eq!(s.scene.triangles.len(), 2);
    assert!(s.scene.lights.is_empty());
}

#[test]
fn builtin_scene_is_the_shipped_cornell_file() {
    let builtin = SceneFile::builtin_default();
    let file =
        SceneFile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/cornell.toml"))
            .unwrap();
    assert_eq!(builtin.scene.spheres, file.scene.spheres);
    assert_eq!(builtin.scene.triangles, file.scene.triangles);
    assert_eq!(builtin.scene.lights.len(), 1);
    assert_eq!(builtin.scene.triangles.len(), 10);
}

#[test]
fn syntax_error() {
    assert_error(
        &with("vfov = 40", "vfov = = 40"),
        "vfov = = 40",
        "syntax",
        "",
    );
}

#[test]
fn unknown_key() {
    assert_error(
        &with("vfov = 40", "vfov = 40\nfocal = 3"),
        "focal",
        "syntax",
        "unknown field",
    );
}

#[test]
fn unknown_material() {
    assert_error(
        &with("material = \"white\"", "material = \"chalk\""),
        "chalk",
        "sphere[0].material",
        "unknown material 'chalk'",
    );
}

#[test]
fn negative_radius() {
    assert_error(
        &with("radius = 0.5", "radius = -0.5"),
        "radius",
        "sphere[0].radius",
        "positive",
    );
}

#[test]
fn zero_radius_light() {
    let t = with(
        "radius = 0.5\nmaterial = \"white\"",
        "radius = 0.0\nmaterial = \"lamp\"",
    );
    assert_error(&t, "radius", "sphere[0].radius", "positive");
}

#[test]
fn zero_area_quad() {
    assert_error(
        &with("edge2 = [0, 0, -2]", "edge2 = [4, 0, 0]"),
        "edge2",
        "quad[0].edge2",
        "zero area",
    );
}

#[test]
fn nan_value() {
    assert_error(
        &with("center = [0, 1, 0]", "center = [0, nan, 0]"),
        "center",
        "sphere[0].center",
        "not finite",
    );
    assert_error(&with("vfov = 40", "vfov = nan"), "vfov", "camera.vfov", "");
    assert_error(
        &with("kd = [0.5, 0.5, 0.5]", "kd = [0.5, inf, 0.5]"),
        "white",
        "materials.white.kd",
        "not finite",
    );
}

#[test]
fn coordinates_and_radii_outside_the_supported_range() {
    assert_error(
        &with("center = [0, 1, 0]", "center = [0, 1e20, 0]"),
        "center",
        "sphere[0].center",
        "beyond",
    );
    assert_error(
        &with("radius = 0.5", "radius = 1e-20"),
        "radius",
        "sphere[0].radius",
        "outside",
    );
    assert_error(
        &with("eye = [0, 1, 4]", "eye = [0, 1, 4e16]"),
        "eye",
        "camera.eye",
        "beyond",
    );
}

#[test]
fn zero_width() {
    assert_error(
        &with("width = 32", "width = 0"),
        "width",
        "camera.width",
        "outside",
    );
}

/// An emissive quad is two triangle lights, one-sided unless its material says `two_sided`;
/// `two_sided` belongs to emitters, and a sphere emits from its outside only.
#[test]
fn emissive_quads_and_two_sided_emitters() {
    let t = with(
        "edge2 = [0, 0, -2]\nmaterial = \"white\"",
        "edge2 = [0, 0, -2]\nmaterial = \"lamp\"",
    );
    let s = parse_scene(&t, &scene_path()).unwrap();
    assert_eq!(s.scene.lights.len(), 2);
    assert!(s
        .scene
        .lights
        .iter()
        .all(|l| l.kind == kernel::scene::light_kind::TRIANGLE
            && l.two_sided == 0
            && (l.area - 2.0).abs() < 1e-6));
    assert_eq!(
        s.scene
            .triangles
            .iter()
            .map(|t| t.light)
            .collect::<Vec<_>>(),
        vec![0, 1]
    );
    let two = t.replace(
        "lamp = { emission = [4, 4, 4] }",
        "lamp = { emission = [4, 4, 4], two_sided = true }",
    );
    let s = parse_scene(&two, &scene_path()).unwrap();
    assert!(s.scene.lights.iter().all(|l| l.two_sided == 1));
    assert_error(
        &with(
            "white = { kd = [0.5, 0.5, 0.5] }",
            "white = { kd = [0.5, 0.5, 0.5], two_sided = true }",
        ),
        "two_sided",
        "materials.white.two_sided",
        "belongs to emitters",
    );
    let sphere_lamp = with(
        "lamp = { emission = [4, 4, 4] }",
        "lamp = { emission = [4, 4, 4], two_sided = true }",
    )
    .replacen("material = \"white\"", "material = \"lamp\"", 1);
    assert_error(
        &sphere_lamp,
        "\"lamp\"",
        "sphere[0].material",
        "outside only",
    );
}

#[test]
fn albedo_above_one_and_negative_emission() {
    assert_error(
        &with("kd = [0.5, 0.5, 0.5]", "kd = [1.5, 0.5, 0.5]"),
        "white",
        "materials.white.kd",
        "above 1",
    );
    assert_error(
        &with("emission = [4, 4, 4]", "emission = [4, -4, 4]"),
        "lamp",
        "materials.lamp.emission",
        "negative",
    );
}

#[test]
fn camera_degenerate() {
    assert_error(
        &with("look_at = [0, 1, 0]", "look_at = [0, 1, 4]"),
        "look_at",
        "camera.look_at",
        "equals camera.eye",
    );
    assert_error(
        &with("up = [0, 1, 0]", "up = [0, 0, 2]"),
        "up =",
        "camera.up",
        "parallel",
    );
}

#[test]
fn missing_mesh_file() {
    let t = format!("{GOOD}\n[[mesh]]\nfile = \"no_such_mesh.obj\"\nmaterial = \"white\"\n");
    assert_error(&t, "no_such_mesh", "mesh[0].file", "does not exist");
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("twinpath-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn malformed_obj_names_the_mesh_file() {
    let dir = temp_dir("obj");
    std::fs::write(
        dir.join("broken.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
    )
    .unwrap();
    let scene = format!("{GOOD}\n[[mesh]]\nfile = \"broken.obj\"\nmaterial = \"white\"\n");
    let e = parse_scene(&scene, &dir.join("s.toml")).unwrap_err();
    println!("{e}");
    assert_eq!(e.file, dir.join("broken.obj"));
    std::fs::write(
        dir.join("nan.obj"),
        "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let scene = format!("{GOOD}\n[[mesh]]\nfile = \"nan.obj\"\nmaterial = \"white\"\n");
    let e = parse_scene(&scene, &dir.join("s.toml")).unwrap_err();
    println!("{e}");
    assert_eq!(e.file, dir.join("nan.obj"));
    assert!(
        e.message.contains("finite") || e.message.contains("malformed"),
        "{e}"
    );
}

#[test]
fn good_meshes_load() {
    let dir = temp_dir("mesh");
    std::fs::write(
        dir.join("tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("tri.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    )
    .unwrap();
    let scene = format!(
        "{GOOD}\n[[mesh]]\nfile = \"tri.obj\"\nmaterial = \"white\"\n[[mesh]]\nfile = \"tri.ply\"\nmaterial = \"white\"\n"
    );
    let s = parse_scene(&scene, &dir.join("s.toml")).unwrap();
    assert_eq!(s.scene.triangles.len(), 2 + 2 + 1);
    assert_eq!(s.scene.triangle_groups.len(), 3);
}

#[test]
fn malformed_ply() {
    let p = Path::new("m.ply");
    let header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    // index out of range, on line 14
    let e = parse_ply(
        p,
        format!("{header}0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").as_bytes(),
    )
    .unwrap_err();
    println!("{e}");
    assert_eq!((e.line, e.field.as_str()), (Some(13), "face 0"));
    assert!(e.message.contains("out of range"));
    // NaN vertex on line 11
    let e = parse_ply(
        p,
        format!("{header}0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n").as_bytes(),
    )
    .unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (Some(11), "vertex 1"));
    // truncated body
    let e = parse_ply(p, format!("{header}0 0 0\n1 0 0\n").as_bytes()).unwrap_err();
    println!("{e}");
    // huge declared count: rejected before allocating
    let huge = header.replace("element vertex 3", "element vertex 4000000000");
    let e = parse_ply(p, format!("{huge}0 0 0\n").as_bytes()).unwrap_err();
    println!("{e}");
    assert!(e.message.contains("exceeds") || e.message.contains("too short"));
    let big = header.replace("element vertex 3", "element vertex 100000000");
    let e = parse_ply(p, format!("{big}0 0 0\n").as_bytes()).unwrap_err();
    assert!(e.message.contains("too short"), "{e}");
    // an element with no properties and a huge count has nothing to read (found by the fuzzer
    // as its slowest input: it used to loop over the whole declared count)
    let empty = header.replace("element face 1", "element blob 268435455\nelement face 1");
    let s = parse_ply(
        p,
        format!("{empty}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").as_bytes(),
    )
    .unwrap();
    assert_eq!(s.triangles.len(), 1);
    // not a ply, binary garbage
    assert!(parse_ply(p, b"\xff\xfe\x00garbage").is_err());
    assert!(parse_ply(p, b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nend_header\n\x00").is_err());
}

#[test]
fn not_utf8_scene_file() {
    let dir = temp_dir("utf8");
    let path = dir.join("bin.toml");
    std::fs::write(&path, b"[camera]\neye = [0, 1, 4]\n\xff\xfe\n").unwrap();
    let e = SceneFile::load(&path).unwrap_err();
    println!("{e}");
    assert_eq!(e.line, Some(3));
    let e = SceneFile::load(&dir.join("missing.toml")).unwrap_err();
    assert!(e.message.contains("cannot read"));
}

#[test]
fn render_keywords_name_their_choices() {
    for (key, choices) in [
        ("roulette", "\"constant\" or \"throughput\""),
        ("mis", "\"power\", \"half\", \"light\" or \"bsdf\""),
        ("light_sampling", "\"solid_angle\" or \"area\""),
        ("light_selection", "\"power\" or \"uniform\""),
        ("sampler", "\"independent\" or \"sobol\""),
    ] {
        let text = format!("{GOOD}\n[render]\n{key} = \"bogus\"\n");
        assert_error(
            &text,
            &format!("{key} = "),
            &format!("render.{key}"),
            &format!("'bogus' is not {choices}"),
        );
    }
    // Throughput roulette starts at depth 5 unless the scene says otherwise.
    let parse =
        |extra: &str| parse_scene(&format!("{GOOD}\n[render]\n{extra}"), &scene_path()).unwrap();
    let s = parse("");
    assert_eq!(
        (s.settings.roulette, s.settings.roulette_start_depth()),
        (Roulette::Throughput, 5)
    );
    let s = parse("roulette = \"constant\"\n");
    assert_eq!(
        (s.settings.roulette, s.settings.roulette_start_depth()),
        (Roulette::Constant, 1)
    );
    let s = parse("rr_start_depth = 2\nroulette = \"constant\"\n");
    assert_eq!(s.settings.roulette_start_depth(), 2);
    let s = parse("mis = \"half\"\nlight_sampling = \"area\"\nlight_selection = \"uniform\"\n");
    assert_eq!(
        (
            s.settings.mis,
            s.settings.light_sampling,
            s.settings.light_selection
        ),
        (Mis::Half, LightSampling::Area, LightSelection::Uniform)
    );
    // Sobol points unless the scene asks for independent numbers.
    assert_eq!(parse("").settings.sampler, Sampler::Sobol);
    let s = parse("sampler = \"independent\"\n");
    assert_eq!(s.settings.sampler, Sampler::Independent);
}

/// The good scene with material `white` replaced by `white_def`.
fn with_white(white_def: &str) -> String {
    with(
        "white = { kd = [0.5, 0.5, 0.5] }",
        &format!("white = {white_def}"),
    )
}

#[test]
fn every_material_kind_parses() {
    use kernel::scene::material_kind;
    for (def, kind) in [
        ("{ kd = [0.5, 0.5, 0.5] }", material_kind::DIFFUSE),
        (
            "{ kd = [0.5, 0.4, 0.3], ks = [0.5, 0.6, 0.7], alpha = 0.1 }",
            material_kind::GLOSSY,
        ),
        ("{ ks = [0.9, 0.9, 0.9], alpha = 0 }", material_kind::GLOSSY),
        (
            "{ conductor = \"gold\", alpha = 0.2 }",
            material_kind::CONDUCTOR,
        ),
        ("{ conductor = \"aluminium\" }", material_kind::CONDUCTOR),
        (
            "{ conductor = { eta = [0.2, 0.9, 1.1], k = [3.9, 2.4, 2.1] }, alpha = 1 }",
            material_kind::CONDUCTOR,
        ),
        (
            "{ conductor = { reflectance = [1, 1, 1] } }",
            material_kind::CONDUCTOR,
        ),
        (
            "{ dielectric = { ior = 1.5 }, alpha = 0.3 }",
            material_kind::DIELECTRIC,
        ),
    ] {
        // The sphere is white; the quad gets a diffuse material (a dielectric quad is an error).
        let text = with_white(def).replace(
            "edge2 = [0, 0, -2]\nmaterial = \"white\"",
            "edge2 = [0, 0, -2]\nmaterial = \"floor\"",
        ) + "";
        let text = text.replace(
            "[materials]\n",
            "[materials]\nfloor = { kd = [0.5, 0.5, 0.5] }\n",
        );
        let s = parse_scene(&text, &scene_path()).unwrap_or_else(|e| panic!("{def}: {e}"));
        let m = s.scene.materials[s
            .scene
            .material_names
            .iter()
            .position(|n| n == "white")
            .unwrap()];
        assert_eq!(m.kind, kind, "{def}");
    }
}

#[test]
fn bad_materials_name_their_field() {
    let line = "white = {";
    for (def, field, message) in [
        (
            "{ kd = [0.6, 0.5, 0.5], ks = [0.5, 0.1, 0.1], alpha = 0.1 }",
            "materials.white.ks",
            "exceeds 1",
        ),
        (
            "{ kd = [0.5, 0.5, 0.5], ks = [0.1, 0.1, 0.1] }",
            "materials.white",
            "no alpha",
        ),
        (
            "{ kd = [0.5, 0.5, 0.5], alpha = 0.1 }",
            "materials.white",
            "no ks",
        ),
        (
            "{ ks = [0.1, 0.1, 0.1], alpha = 1.5 }",
            "materials.white.alpha",
            "outside",
        ),
        (
            "{ ks = [0.1, 0.1, 0.1], alpha = -0.1 }",
            "materials.white.alpha",
            "outside",
        ),
        (
            "{ conductor = \"unobtainium\" }",
            "materials.white.conductor",
            "unknown metal",
        ),
        (
            "{ conductor = { eta = [1, 1, 1] } }",
            "materials.white.conductor",
            "together",
        ),
        (
            "{ conductor = { eta = [0, 1, 1], k = [1, 1, 1] } }",
            "materials.white.conductor",
            "> 0",
        ),
        (
            "{ conductor = { reflectance = [1.2, 1, 1] } }",
            "materials.white.conductor",
            "above 1",
        ),
        (
            "{ conductor = { reflectance = [1, 1] } }",
            "materials.white.conductor",
            "[r, g, b]",
        ),
        (
            "{ conductor = { colour = [1, 1, 1] } }",
            "materials.white.conductor",
            "unknown field",
        ),
        (
            "{ conductor = 3 }",
            "materials.white.conductor",
            "metal's name",
        ),
        (
            "{ conductor = \"gold\", kd = [0.5, 0.5, 0.5] }",
            "materials.white",
            "kd belongs",
        ),
        (
            "{ conductor = \"gold\", dielectric = { ior = 1.5 } }",
            "materials.white",
            "more than one",
        ),
        (
            "{ dielectric = { ior = 0 } }",
            "materials.white.dielectric.ior",
            "outside",
        ),
        (
            "{ dielectric = { ior = 1.5, abbe = 30 } }",
            "syntax",
            "unknown field",
        ),
        (
            "{ kd = [0.5, 0.5, 0.5], ks = [0.1, 0.1, 0.1], alpha = 0.2, emission = [1, 1, 1] }",
            "materials.white",
            "more than one of",
        ),
        (
            "{ kd = [0.5, 0.5, 0.5], alpha = 0.2, emission = [1, 1, 1] }",
            "materials.white",
            "emission and a glossy lobe",
        ),
        ("{ }", "materials.white", "needs kd"),
    ] {
        assert_error(&with_white(def), line, field, message);
    }
}

#[test]
fn dielectric_needs_a_closed_outward_surface() {
    // On a quad: rejected at the quad's material.
    let glass = with_white("{ dielectric = { ior = 1.5 } }");
    let e = error_of(&glass);
    assert_eq!(e.field, "quad[0].material");
    assert!(e.message.contains("closed surface"), "{e}");
    // A tetrahedron: closed and outward is accepted; open, or wound inward, names the mesh.
    let dir = temp_dir("dielectric");
    let tetra = |faces: &str| format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n{faces}");
    let outward = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    let inward = "f 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n";
    let open = "f 1 3 2\nf 1 2 4\nf 1 4 3\n";
    let mismatched = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 4 3\n";
    for (name, faces) in [
        ("out", outward),
        ("in", inward),
        ("open", open),
        ("mixed", mismatched),
    ] {
        std::fs::write(dir.join(format!("{name}.obj")), tetra(faces)).unwrap();
    }
    let scene = |file: &str| {
        GOOD.replace(
            "white = { kd",
            "glass = { dielectric = { ior = 1.5 } }\nwhite = { kd",
        ) + &format!("\n[[mesh]]\nfile = \"{file}\"\nmaterial = \"glass\"\n")
    };
    let s = parse_scene(&scene("out.obj"), &dir.join("s.toml")).unwrap();
    assert_eq!(s.scene.triangles.len(), 2 + 4);
    for (file, message) in [
        ("in.obj", "signed volume"),
        ("open.obj", "not a closed"),
        ("mixed.obj", "not a closed"),
    ] {
        let e = parse_scene(&scene(file), &dir.join("s.toml")).unwrap_err();
        println!("{e}");
        assert_eq!(e.file, dir.join(file));
        assert!(e.field.contains("mesh[0]"), "{e}");
        assert!(e.message.contains(message), "{e}");
    }
    // The shipped icosphere is closed and outward: it can be glass.
    let icosphere = GOOD.replace(
        "white = { kd",
        "glass = { dielectric = { ior = 1.5 } }\nwhite = { kd",
    ) + "\n[[mesh]]\nfile = \"meshes/icosphere.obj\"\nmaterial = \"glass\"\n";
    parse_scene(
        &icosphere,
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/s.toml"),
    )
    .unwrap();
}

#[test]
fn thin_lens_settings() {
    let s = parse_scene(
        &with(
            "height = 24",
            "height = 24\naperture = 0.1\nfocus_distance = 2.5",
        ),
        &scene_path(),
    )
    .unwrap();
    assert_eq!(
        (s.scene.camera.aperture, s.scene.camera.focus_distance),
        (0.1, 2.5)
    );
    // The default focus is the look-at point's distance; the default aperture a pinhole.
    let s = parse_scene(GOOD, &scene_path()).unwrap();
    assert_eq!(
        (s.scene.camera.aperture, s.scene.camera.focus_distance),
        (0.0, 4.0)
    );
    assert_error(
        &with("height = 24", "height = 24\naperture = -0.1"),
        "aperture",
        "camera.aperture",
        "not a lens diameter",
    );
    assert_error(
        &with("height = 24", "height = 24\nfocus_distance = 0"),
        "focus_distance",
        "camera.focus_distance",
        "not a distance",
    );
}

#[test]
fn environment_map_settings() {
    let bg = |body: &str| format!("{GOOD}\n[background]\n{body}\n");
    let sky = twinpath_tests::repo_root().join("scenes/sky.hdr");
    let s = parse_scene(
        &bg(&format!(
            "map = \"{}\"\nscale = 0.5\nrotation = 90",
            sky.display()
        )),
        &scene_path(),
    )
    .unwrap();
    let map = s.scene.environment.as_ref().unwrap();
    assert_eq!(
        (map.width, map.height, map.scale, map.rotation_degrees),
        (512, 256, 0.5, 90.0)
    );
    // The map is a light: the last entry of the light table.
    assert_eq!(
        s.scene.lights.last().unwrap().kind,
        kernel::scene::light_kind::ENVIRONMENT
    );
    assert_error(
        &bg("map = \"nowhere.exr\""),
        "nowhere",
        "background.map",
        "does not exist",
    );
    assert_error(
        &bg(&format!(
            "radiance = [1, 1, 1]\nmap = \"{}\"",
            sky.display()
        )),
        "map =",
        "background",
        "choose one",
    );
    assert_error(
        &bg("radiance = [1, 1, 1]\nscale = 2"),
        "scale",
        "background",
        "belong to a map",
    );
    assert_error(
        &bg(&format!("map = \"{}\"\nscale = -1", sky.display())),
        "scale",
        "background.scale",
        "non-negative",
    );
    // A file that is not an image: named, with the reason.
    let e = error_of(&bg("map = \"../scenes/cornell.toml\""));
    assert!(
        e.file.ends_with("cornell.toml") && e.field == "background.map",
        "{e}"
    );
}

/// Meshes with triangles that rays may leave higher than the grazing offset is derived for
/// (`scene::grazing_domain`) load with a note naming the mesh, and meshes without load without:
/// a needle 10^-6 as wide as it is long, 1 mm triangles 3 km from the origin in a plane tilted
/// against the axes (world-space, and instanced by two translations of 3 km), beside a needle 10^-3 wide and a 1 mm triangle at
/// the origin, which are within. No shipped scene has such a triangle.
#[test]
fn triangles_beyond_the_grazing_domain_are_noted() {
    let dir = temp_dir("grazing");
    let write = |name: &str, triangles: &[[[f64; 3]; 3]]| {
        let mut obj = String::new();
        for (k, t) in triangles.iter().enumerate() {
            for v in t {
                obj += &format!("v {} {} {}\n", v[0], v[1], v[2]);
            }
            obj += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
        }
        std::fs::write(dir.join(name), obj).unwrap();
    };
    let fine = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let needle = |w: f64| [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, w, 0.0]];
    let mm = |x: f64, k: usize| {
        let z = k as f64 * 0.01;
        [[x, 0.0, z], [x + 1e-3, 1e-3, z], [x, 0.0, z + 1e-3]]
    };
    write("needle.obj", &[needle(1e-6), fine]);
    write("thin.obj", &[needle(1e-3), fine]);
    write("far.obj", &[mm(3000.0, 0), fine]);
    write("near.obj", &[mm(0.0, 0), fine]);
    let mm_mesh: Vec<_> = (0..16).map(|k| mm(0.0, k)).collect();
    write("mm16.obj", &mm_mesh);
    let mut scene = GOOD.to_string();
    for file in ["needle.obj", "thin.obj", "far.obj", "near.obj"] {
        scene += &format!("[[mesh]]\nfile = \"{file}\"\nmaterial = \"white\"\n");
    }
    for x in [3000, -3000] {
        scene += &format!(
            "[[mesh]]\nfile = \"mm16.obj\"\nmaterial = \"white\"\ntranslate = [{x}, 0, 0]\n"
        );
    }
    // A well-shaped mesh placed twice under a map of condition 2000, beyond
    // `kernel::instance::DEVICE_INVERSE_CONDITION_LIMIT`, and twice under one of 500, within;
    // and placed twice by a stretch of 29.5 along (1, 1, 1) (condition 39, determinant
    // condition 194, beyond `instancing::DETERMINANT_CONDITION_LIMIT`) and once more unmoved.
    // The placements beyond a limit are flattened, with a note, and none is beyond the domain.
    let stack: Vec<_> = (0..16)
        .map(|k| fine.map(|[x, y, z]| [x + k as f64, y, z]))
        .collect();
    write("squashed.obj", &stack);
    write("squeezed.obj", &stack);
    write("turned.obj", &stack);
    for (file, z) in [("squashed.obj", 2000), ("squeezed.obj", 500)] {
        for x in [0, 10] {
            scene += &format!(
                "[[mesh]]\nfile = \"{file}\"\nmaterial = \"white\"\nscale = [1, 1, {z}]\ntranslate = [{x}, 0, 0]\n"
            );
        }
    }
    for x in [0, 100] {
        scene += &format!(
            "[[mesh]]\nfile = \"turned.obj\"\nmaterial = \"white\"\nmatrix = [[10.5, 9.5, 9.5, {x}], [9.5, 10.5, 9.5, 0], [9.5, 9.5, 10.5, 0], [0, 0, 0, 1]]\n"
        );
    }
    scene += "[[mesh]]\nfile = \"turned.obj\"\nmaterial = \"white\"\ntranslate = [0, 0, 300]\n";
    std::fs::write(dir.join("s.toml"), &scene).unwrap();
    let loaded = SceneFile::load(&dir.join("s.toml")).unwrap();
    assert_eq!(
        loaded.scene.instances.len(),
        5,
        "mm16.obj, squeezed.obj and the unmoved turned.obj are instanced, squashed.obj and \
         the stretched turned.obj flattened"
    );
    let notes = &loaded.scene.notes;
    for n in notes {
        println!("note: {n}");
    }
    let about = |file: &str| {
        notes
            .iter()
            .filter(|n| n.contains(file))
            .collect::<Vec<_>>()
    };
    let needle_notes = about("needle.obj");
    assert_eq!(needle_notes.len(), 1, "{notes:?}");
    assert!(needle_notes[0].contains("1 of 2 triangles") && needle_notes[0].contains("a needle"));
    // What marks these notes, in the shipped scenes below.
    let marker = "beyond the domain";
    let flattened = "flattened into world space";
    assert!(
        notes
            .iter()
            .all(|n| n.contains(marker) || n.contains(flattened)),
        "{notes:?}"
    );
    let far_notes = about("far.obj");
    assert_eq!(far_notes.len(), 1, "{notes:?}");
    assert!(far_notes[0].contains("1 of 2 triangles") && far_notes[0].contains("(3000, 0, 0)"));
    assert!(far_notes[0].contains("small against the rounding"));
    let instanced = about("mm16.obj");
    assert_eq!(instanced.len(), 1, "{notes:?}");
    assert!(instanced[0].contains("16 of 16 triangles (object space, under 2 instances)"));
    let squashed = about("squashed.obj");
    assert_eq!(squashed.len(), 1, "{notes:?}");
    assert!(
        squashed[0].contains("2 placements flattened")
            && squashed[0].contains("condition number ||M|| ||M^-1|| is 2000, above 1000"),
        "{squashed:?}"
    );
    let turned = about("turned.obj");
    assert_eq!(turned.len(), 1, "{notes:?}");
    assert!(
        turned[0].contains("2 placements flattened")
            && turned[0].contains("determinant condition perm(|A|) / |det A| is 194, above 125"),
        "{turned:?}"
    );
    assert!(about("thin.obj").is_empty() && about("near.obj").is_empty());
    assert!(about("squeezed.obj").is_empty(), "{notes:?}");
    assert_eq!(notes.len(), 5, "{notes:?}");
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let gltf = std::fs::read_dir(scenes.join("gltf")).unwrap();
    for entry in std::fs::read_dir(&scenes).unwrap().chain(gltf) {
        let path = entry.unwrap().path();
        if path
            .extension()
            .is_some_and(|e| e == "toml" || e == "glb" || e == "gltf")
        {
            let s = SceneFile::load(&path).unwrap();
            let beyond: Vec<_> = s
                .scene
                .notes
                .iter()
                .filter(|n| n.contains(marker) || n.contains(flattened))
                .collect();
            assert!(beyond.is_empty(), "{}: {beyond:?}", path.display());
        }
    }
}
