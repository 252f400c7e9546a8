//! Renders split into parts (`render --part I/N`, `--samples A..B`) and `twinpath merge`, end
//! to end through the binary: the merge of a CPU render's parts is the single render's EXR and
//! PNG byte for byte, for any split and any merge order; parts that do not belong together are
//! errors naming the files.

use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_twinpath");

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("twinpath-parts-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path)
}

/// Runs twinpath with `args`; Ok(stderr) on success, Err(stderr) on failure.
fn twinpath(args: &[&str]) -> Result<String, String> {
    let out = Command::new(BIN).args(args).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    if out.status.success() {
        Ok(err)
    } else {
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        Err(err)
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Renders `scene` with `flags`, whole (to `single.exr` and `.png`) and as the parts of each
/// split, and checks every merge is the single render byte for byte.
fn assert_merges_are_exact(dir: &Path, scene: &Path, spp: u32, flags: &[&str]) {
    let spp_flag = spp.to_string();
    let base: Vec<&str> = [s(scene), "--backend", "cpu", "--quiet", "--spp", &spp_flag]
        .into_iter()
        .chain(flags.iter().copied())
        .collect();
    let render = |extra: &[&str]| {
        let mut args = vec!["render"];
        args.extend(&base);
        args.extend(extra);
        twinpath(&args).unwrap_or_else(|e| panic!("{args:?}: {e}"))
    };
    let (single_exr, single_png) = (dir.join("single.exr"), dir.join("single.png"));
    render(&["-o", s(&single_exr), "-o", s(&single_png)]);
    let single = (
        std::fs::read(&single_exr).unwrap(),
        std::fs::read(&single_png).unwrap(),
    );
    // Splits: one part; four equal ones; an uneven one by explicit ranges; given in a
    // shuffled order.
    let equal: Vec<String> = (0..4).map(|i| format!("--part={i}/4")).collect();
    let cut = [0, 1, spp / 3 + 1, spp - 1, spp];
    let uneven: Vec<String> = cut
        .windows(2)
        .map(|w| format!("--samples={}..{}", w[0], w[1]))
        .collect();
    let splits: Vec<(&str, Vec<String>, Vec<usize>)> = vec![
        ("one part", vec!["--part=0/1".into()], vec![0]),
        ("four equal parts", equal, vec![0, 1, 2, 3]),
        ("an uneven split, shuffled", uneven, vec![2, 0, 3, 1]),
    ];
    for (label, flags, order) in splits {
        let parts: Vec<PathBuf> = (0..flags.len())
            .map(|i| dir.join(format!("part{i}.exr")))
            .collect();
        for (flag, part) in flags.iter().zip(&parts) {
            render(&[flag.as_str(), "-o", s(part)]);
        }
        let (exr, png) = (dir.join("merged.exr"), dir.join("merged.png"));
        let mut args = vec!["merge"];
        args.extend(order.iter().map(|&i| s(&parts[i])));
        args.extend(["-o", s(&exr), "-o", s(&png)]);
        let log = twinpath(&args).unwrap_or_else(|e| panic!("{label}: {e}"));
        assert!(
            log.contains(&format!("samples 0..{spp} of each pixel")),
            "{label}: {log}"
        );
        assert!(
            std::fs::read(&exr).unwrap() == single.0,
            "{scene:?} {flags:?}, {label}: the merged EXR is not the single render's"
        );
        assert!(
            std::fs::read(&png).unwrap() == single.1,
            "{scene:?} {flags:?}, {label}: the merged PNG is not the single render's"
        );
    }
}

#[test]
fn merged_parts_are_the_single_render_byte_for_byte() {
    let dir = temp_dir("exact");
    // Cornell: sixteen-path packets; textures.toml: meshes and textures over the BVH, one path
    // at a time. Both samplers, and Cornell with split paths.
    let cornell = repo("scenes/cornell.toml");
    let textures = repo("scenes/textures.toml");
    assert_merges_are_exact(&dir, &cornell, 13, &["--width", "40"]);
    assert_merges_are_exact(
        &dir,
        &cornell,
        7,
        &["--width", "40", "--sampler", "independent"],
    );
    assert_merges_are_exact(&dir, &textures, 9, &["--width", "48"]);
    // Split paths with the learned table: every part learns the same table from the same
    // pilot, and a sample's continuations are numbered from its own index.
    assert_merges_are_exact(
        &dir,
        &cornell,
        13,
        &["--width", "40", "--set", "split=auto"],
    );
    assert_merges_are_exact(
        &dir,
        &textures,
        6,
        &["--width", "48", "--sampler", "independent", "--seed", "5"],
    );
}

/// A scene reading mesh file `quad.obj` in `dir` (a lit floor).
fn obj_scene(dir: &Path) -> PathBuf {
    std::fs::write(
        dir.join("quad.obj"),
        "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 3 2\nf 1 4 3\n",
    )
    .unwrap();
    let scene = dir.join("quad.toml");
    std::fs::write(
        &scene,
        r#"[camera]
eye = [0, 2, 3]
look_at = [0, 0, 0]
up = [0, 1, 0]
vfov = 40
width = 12
height = 8

[render]
spp = 8

[materials]
white = { kd = [0.8, 0.8, 0.8] }
light = { emission = [5.0, 5.0, 5.0] }

[[mesh]]
file = "quad.obj"
material = "white"

[[sphere]]
center = [0.0, 2.0, 0.0]
radius = 0.2
material = "light"
"#,
    )
    .unwrap();
    scene
}

#[test]
fn parts_that_do_not_belong_together_are_errors() {
    let dir = temp_dir("errors");
    let scene = obj_scene(&dir);
    let part = |name: &str, flags: &[&str]| {
        let out = dir.join(name);
        let mut args = vec!["render", s(&scene), "--backend", "cpu", "--quiet"];
        args.extend(flags);
        args.extend(["-o", s(&out)]);
        twinpath(&args).unwrap_or_else(|e| panic!("{args:?}: {e}"));
        out
    };
    let merge = |parts: &[&Path]| {
        let mut args = vec!["merge"];
        args.extend(parts.iter().map(|p| s(p)));
        let out = dir.join("out.exr");
        args.extend(["-o", s(&out)]);
        twinpath(&args)
    };
    let p0 = part("p0.exr", &["--part", "0/2"]);
    let p1 = part("p1.exr", &["--part", "1/2"]);
    merge(&[&p0, &p1]).expect("the two halves merge");

    // Another seed.
    let seed = part("seed.exr", &["--part", "1/2", "--seed", "9"]);
    let err = merge(&[&p0, &seed]).unwrap_err();
    assert!(
        err.contains("different seeds") && err.contains("seed.exr"),
        "{err}"
    );
    // Another setting (the camera counts: another image size).
    let depth = part("depth.exr", &["--part", "1/2", "--set", "max_depth=3"]);
    let err = merge(&[&p0, &depth]).unwrap_err();
    assert!(err.contains("max_depth is"), "{err}");
    let size = part("size.exr", &["--part", "1/2", "--width", "6"]);
    let err = merge(&[&p0, &size]).unwrap_err();
    assert!(err.contains("camera is"), "{err}");
    // Overlap: the same part twice, and ranges that cross.
    let err = merge(&[&p0, &p1, &p0]).unwrap_err();
    assert!(err.contains("overlap") && err.contains("p0.exr"), "{err}");
    let cross = part("cross.exr", &["--samples", "2..6"]);
    let err = merge(&[&p0, &cross]).unwrap_err();
    assert!(
        err.contains("(samples 0..4) and") && err.contains("(samples 2..6) overlap"),
        "{err}"
    );
    // A gap, and a missing part.
    let late = part("late.exr", &["--samples", "6..8"]);
    let err = merge(&[&p0, &late]).unwrap_err();
    assert!(
        err.contains("samples 4..6 are in no part") && err.contains("late.exr starts at 6"),
        "{err}"
    );
    let err = merge(&[&p1]).unwrap_err();
    assert!(err.contains("missing part 0/2 (samples 0..4)"), "{err}");
    // An image, not a part file.
    let image = dir.join("image.exr");
    twinpath(&[
        "render",
        s(&scene),
        "--backend",
        "cpu",
        "--quiet",
        "-o",
        s(&image),
    ])
    .unwrap();
    let err = merge(&[&p0, &image]).unwrap_err();
    assert!(err.contains("image.exr: not a twinpath part file"), "{err}");
    // The mesh file changed between the parts: the error names it.
    std::fs::write(
        dir.join("quad.obj"),
        "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 3 2\n",
    )
    .unwrap();
    let changed = part("changed.exr", &["--part", "1/2"]);
    let err = merge(&[&p0, &changed]).unwrap_err();
    assert!(
        err.contains("different scene data") && err.contains("quad.obj has hash"),
        "{err}"
    );
}

#[test]
fn parts_refuse_what_cannot_be_split_before_rendering() {
    let dir = temp_dir("refuse");
    let scene = obj_scene(&dir);
    let render = |flags: &[&str]| {
        let mut args = vec!["render", s(&scene), "--backend", "cpu", "--quiet"];
        args.extend(flags);
        twinpath(&args)
    };
    let err = render(&["--part", "0/2", "--target-error", "0.1"]).unwrap_err();
    assert!(err.contains("adaptive sampling"), "{err}");
    let err = render(&["--part", "0/9"]).unwrap_err();
    assert!(err.contains("9 parts of 8 samples"), "{err}");
    let err = render(&["--part", "2/2"]).unwrap_err();
    assert!(err.contains("count from 0"), "{err}");
    let err = render(&["--samples", "4..4"]).unwrap_err();
    assert!(err.contains("empty"), "{err}");
    let err = render(&["--part", "0/2", "-o", "x.png"]).unwrap_err();
    assert!(err.contains("one part file, an .exr"), "{err}");
    let missing = dir.join("no such folder").join("part.exr");
    let err = render(&["--part", "0/2", "-o", s(&missing)]).unwrap_err();
    assert!(err.contains("cannot write"), "{err}");
    let err = twinpath(&["merge", s(&dir.join("quad.toml")), "-o", s(&missing)]).unwrap_err();
    assert!(err.contains("cannot write"), "{err}");
}

/// A GPU render as one part merges back to the GPU render's own image (the part file holds
/// its mean times its count, which divides back exactly), and GPU parts merged with CPU parts
/// say that the result is statistically, not bitwise, the single render.
#[test]
fn gpu_parts_merge() {
    let dir = temp_dir("gpu");
    let scene = repo("scenes/cornell.toml");
    let run = |flags: &[&str]| {
        let mut args = vec![s(&scene), "--quiet", "--spp", "6", "--width", "32"];
        args.extend(flags);
        let mut all = vec!["render"];
        all.extend(args);
        twinpath(&all).unwrap_or_else(|e| panic!("{e}"))
    };
    let (single, part) = (dir.join("gpu.exr"), dir.join("gpu.part.exr"));
    run(&["--backend", "gpu", "-o", s(&single)]);
    run(&["--backend", "gpu", "--part", "0/1", "-o", s(&part)]);
    let merged = dir.join("merged.exr");
    twinpath(&["merge", s(&part), "-o", s(&merged)]).unwrap();
    assert!(std::fs::read(&merged).unwrap() == std::fs::read(&single).unwrap());

    let cpu = dir.join("cpu.part.exr");
    let gpu = dir.join("gpu1.part.exr");
    run(&["--backend", "cpu", "--part", "0/2", "-o", s(&cpu)]);
    run(&["--backend", "gpu", "--part", "1/2", "-o", s(&gpu)]);
    let log = twinpath(&["merge", s(&gpu), s(&cpu), "-o", s(&merged)]).unwrap();
    assert!(log.contains("statistically the same image"), "{log}");
}
