//! The check of a lent GPU machine (`scripts/gpu_machine_prepare.sh` builds the test binaries,
//! `scripts/gpu_machine_check.sh` runs them there; docs/gpu.md) runs every test binary that
//! has a GPU part: a test file that names `Backend::Gpu`, `twinpath::vulkan` or
//! `twinpath_tests::gpu` must be in the prepared list and in one of the check's queues, and
//! every prepared name must be a test file. Such machines are lent rarely and briefly, so a GPU
//! test added without them would go unrun on a real GPU for as long as nobody noticed. The same
//! holds for the GPU peer's scenes (`scripts/gpu_peer_scenes.txt`): each row's scene,
//! reference and Mitsuba builder must exist, or the peer table of that one run has a hole.

use std::collections::BTreeSet;
use twinpath_tests::repo_root;

/// What marks a test file as having a GPU part.
const GPU_MARKS: [&str; 3] = ["Backend::Gpu", "twinpath::vulkan", "twinpath_tests::gpu"];

/// The test files (by name, without `.rs`) under tests/tests whose text has a [`GPU_MARKS`],
/// this file (which names them) aside.
fn gpu_test_files() -> BTreeSet<String> {
    let dir = repo_root().join("tests/tests");
    std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "rs"))
        .filter(|p| p.file_stem().unwrap() != env!("CARGO_CRATE_NAME"))
        .filter(|p| {
            let text = std::fs::read_to_string(p).unwrap();
            GPU_MARKS.iter().any(|m| text.contains(m))
        })
        .map(|p| p.file_stem().unwrap().to_str().unwrap().to_string())
        .collect()
}

/// Whether `word` is a test binary's name: lower-case letters, digits and underscores.
fn is_name(word: &str) -> bool {
    !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

/// The names in `gpu_machine_prepare.sh`'s `for t in ...; do` list (continued over lines by
/// backslashes).
fn prepared(script: &str) -> BTreeSet<String> {
    let start = script
        .find("for t in ")
        .expect("gpu_machine_prepare.sh has no `for t in` list");
    let list = &script[start + "for t in ".len()..];
    let end = list.find("; do").expect("the list ends with `; do`");
    list[..end]
        .split_whitespace()
        .filter(|w| *w != "\\")
        .map(str::to_string)
        .collect()
}

/// The binaries `gpu_machine_check.sh` runs: every `$B/<name>` and every name after a `queue`
/// call (not its definition), up to the call's end.
fn checked(script: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for line in script.lines().filter(|l| !l.trim_start().starts_with('#')) {
        for (i, _) in line.match_indices("$B/") {
            let rest = &line[i + 3..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if is_name(&name) {
                names.insert(name);
            }
        }
        let words: Vec<&str> = line
            .split(|c: char| c.is_whitespace() || c == '(' || c == ';' || c == '&')
            .filter(|w| !w.is_empty())
            .collect();
        for (i, _) in words.iter().enumerate().filter(|(_, w)| **w == "queue") {
            names.extend(
                words[i + 1..]
                    .iter()
                    .take_while(|w| is_name(w))
                    .map(|w| w.to_string()),
            );
        }
    }
    names
}

#[test]
fn the_lent_gpu_check_runs_every_test_with_a_gpu_part() {
    let read = |f: &str| std::fs::read_to_string(repo_root().join("scripts").join(f)).unwrap();
    let gpu = gpu_test_files();
    let prepared = prepared(&read("gpu_machine_prepare.sh"));
    let checked = checked(&read("gpu_machine_check.sh"));
    println!(
        "{} test files with a GPU part; {} prepared; {} binaries the check runs",
        gpu.len(),
        prepared.len(),
        checked.len()
    );
    // The detector and the parsers see what they must: the GPU suite's core files.
    for core in ["gpu_functions", "gpu_render", "spirv_module", "instances"] {
        assert!(gpu.contains(core), "{core} not seen as a GPU test");
        assert!(checked.contains(core), "{core} not seen in the check");
    }
    let unprepared: Vec<_> = gpu.difference(&prepared).collect();
    assert!(
        unprepared.is_empty(),
        "GPU tests gpu_machine_prepare.sh does not build: {unprepared:?}"
    );
    let unchecked: Vec<_> = gpu.difference(&checked).collect();
    assert!(
        unchecked.is_empty(),
        "GPU tests gpu_machine_check.sh does not run: {unchecked:?}"
    );
    let stray: Vec<_> = prepared
        .iter()
        .filter(|t| !repo_root().join(format!("tests/tests/{t}.rs")).exists())
        .collect();
    assert!(
        stray.is_empty(),
        "prepared names that are no test file: {stray:?}"
    );
}

/// The rows of `scripts/gpu_peer_scenes.txt`: (name, reference, builder), comments and blank
/// lines aside.
fn peer_scenes(list: &str) -> Vec<[String; 3]> {
    list.lines()
        .map(|l| l.split('#').next().unwrap())
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let words: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(
                words.len(),
                3,
                "gpu_peer_scenes.txt: `{l}` is not NAME REFERENCE BUILDER"
            );
            std::array::from_fn(|i| words[i].to_string())
        })
        .collect()
}

#[test]
fn the_gpu_peer_scenes_exist_in_both_renderers() {
    let root = repo_root();
    let read = |f: &str| std::fs::read_to_string(root.join("scripts").join(f)).unwrap();
    let rows = peer_scenes(&read("gpu_peer_scenes.txt"));
    let builders = read("mitsuba_scenes.py");
    assert!(!rows.is_empty(), "gpu_peer_scenes.txt lists no scene");
    for [name, reference, builder] in &rows {
        let scene = root.join(format!("scenes/{name}.toml"));
        assert!(scene.exists(), "{}: no such scene", scene.display());
        let image = root.join(format!("tests/reference/{reference}/mitsuba_ref.exr"));
        assert!(image.exists(), "{}: no such reference", image.display());
        assert!(
            builders.contains(&format!("\ndef {builder}(")),
            "scripts/mitsuba_scenes.py has no `def {builder}(`"
        );
    }
    println!(
        "{} GPU peer scenes, each with its scene, reference and builder",
        rows.len()
    );
}
