//! The shipped kernel modules (kernel/shipped/kernel.spv, the renderer's, and probe.spv, the
//! tests') are the ones the kernel's sources compile to, as far as their manifest can tell, and
//! the host runs exactly them: a kernel edit without
//! `scripts/build_kernel.sh` fails here (and fails every build, by host/build.rs), naming the
//! file that changed and the script. CI recompiles the module and compares bytes
//! (`scripts/build_kernel.sh --check`).

use kernel_manifest::{
    check_shipped, Error, Manifest, MANIFEST_PATH, MODULE_PATH, PROBE_MODULE_PATH, REGENERATE,
};
use std::path::{Path, PathBuf};
use twinpath_tests::repo_root;

#[test]
fn the_shipped_manifest_matches_the_kernel_sources() {
    if let Err(e) = check_shipped(&repo_root()) {
        panic!("{e}");
    }
}

#[test]
fn the_host_runs_the_module_the_manifest_describes() {
    let path = repo_root().join(MANIFEST_PATH);
    let manifest = Manifest::parse(&std::fs::read_to_string(&path).unwrap(), &path).unwrap();
    assert_eq!(
        manifest.build["module_blake3"],
        blake3::hash(twinpath::KERNEL_SPV).to_hex().to_string(),
        "twinpath::KERNEL_SPV ({}) is not the shipped module",
        twinpath::KERNEL_ORIGIN
    );
    assert_eq!(
        manifest.build["module_bytes"],
        twinpath::KERNEL_SPV.len().to_string()
    );
    assert_eq!(
        manifest.build["probe_module_blake3"],
        blake3::hash(twinpath::PROBE_SPV).to_hex().to_string(),
        "twinpath::PROBE_SPV is not the shipped tests' module"
    );
    assert_eq!(manifest.build["probe_features"], "probe");
    // The manifest names every kernel source and rust-gpu's compiler backend.
    assert!(manifest.sources.contains_key("kernel/src/path.rs"));
    assert!(manifest.sources.contains_key("kernel/Cargo.toml"));
    assert_eq!(manifest.packages["rustc_codegen_spirv"], "0.11.0");
    assert_eq!(manifest.packages["spirv-std"], "0.11.0");
}

#[test]
fn the_manifest_reads_back_what_it_writes() {
    let path = repo_root().join(MANIFEST_PATH);
    let text = std::fs::read_to_string(&path).unwrap();
    let manifest = Manifest::parse(&text, &path).unwrap();
    assert_eq!(manifest.to_text(), text);
}

/// A copy of the inputs the manifest covers, in a fresh folder, to change one at a time.
fn copy_of_inputs(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("twinpath-shipped-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    copy_dir(&repo_root().join("kernel"), &dir.join("kernel"));
    for f in ["Cargo.lock", "Cargo.toml", "rust-toolchain.toml"] {
        std::fs::copy(repo_root().join(f), dir.join(f)).unwrap();
    }
    assert!(check_shipped(&dir).is_ok(), "the copy is not faithful");
    dir
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.path().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// The stale-module error for the repository copy at `dir`, as the build prints it.
fn stale_message(dir: &Path) -> String {
    let result = check_shipped(dir);
    std::fs::remove_dir_all(dir).unwrap();
    match result {
        Err(e @ Error::Stale { .. }) => {
            let message = e.to_string();
            assert!(message.contains(REGENERATE), "{message}");
            message
        }
        other => panic!("expected a stale module, got {other:?}"),
    }
}

fn append(path: &Path, text: &str) {
    let mut s = std::fs::read_to_string(path).unwrap();
    s.push_str(text);
    std::fs::write(path, s).unwrap();
}

#[test]
fn a_changed_kernel_source_is_an_error_naming_it_and_the_script() {
    let dir = copy_of_inputs("changed");
    append(&dir.join("kernel/src/path.rs"), "\n// an edit\n");
    let message = stale_message(&dir);
    assert!(message.contains("kernel/src/path.rs changed"), "{message}");
}

#[test]
fn a_new_or_removed_kernel_source_is_an_error_naming_it() {
    let dir = copy_of_inputs("added");
    std::fs::write(dir.join("kernel/src/new_lobe.rs"), "pub fn f() {}\n").unwrap();
    std::fs::remove_file(dir.join("kernel/src/turns.rs")).unwrap();
    let message = stale_message(&dir);
    assert!(
        message.contains("kernel/src/new_lobe.rs is new"),
        "{message}"
    );
    assert!(message.contains("kernel/src/turns.rs is gone"), "{message}");
}

#[test]
fn a_changed_locked_package_toolchain_or_profile_is_an_error_naming_it() {
    let dir = copy_of_inputs("lock");
    let lock = std::fs::read_to_string(dir.join("Cargo.lock")).unwrap();
    let locked = "name = \"spirv-std\"\nversion = \"0.11.0\"";
    assert!(lock.contains(locked));
    let changed = lock.replacen(locked, "name = \"spirv-std\"\nversion = \"0.11.9\"", 1);
    std::fs::write(dir.join("Cargo.lock"), changed).unwrap();
    let toolchain = std::fs::read_to_string(dir.join("rust-toolchain.toml")).unwrap();
    std::fs::write(
        dir.join("rust-toolchain.toml"),
        toolchain.replace("nightly-2026-08-15", "nightly-2027-01-01"),
    )
    .unwrap();
    append(
        &dir.join("Cargo.toml"),
        "\n[profile.release]\nopt-level = 1\n",
    );
    let message = stale_message(&dir);
    assert!(
        message.contains("package spirv-std: 0.11.0 when the module was built, 0.11.9 now"),
        "{message}"
    );
    assert!(message.contains("build toolchain"), "{message}");
    assert!(
        message.contains("build release_profile_blake3"),
        "{message}"
    );
}

#[test]
fn a_module_that_is_not_the_manifests_is_an_error() {
    for (name, path) in [("module", MODULE_PATH), ("probe", PROBE_MODULE_PATH)] {
        let dir = copy_of_inputs(name);
        let module = dir.join(path);
        let mut bytes = std::fs::read(&module).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 1;
        std::fs::write(&module, bytes).unwrap();
        let message = stale_message(&dir);
        assert!(
            message.contains(&format!("{path} is not the module the manifest describes")),
            "{message}"
        );
    }
}

#[test]
fn changes_outside_the_inputs_leave_the_module_current() {
    // Editor files, other profiles and other packages' versions do not compile into the module.
    let dir = copy_of_inputs("unrelated");
    std::fs::write(dir.join("kernel/src/.path.rs.swp"), "x").unwrap();
    std::fs::write(dir.join("kernel/src/path.rs~"), "x").unwrap();
    append(
        &dir.join("Cargo.toml"),
        "\n[profile.dev.package.foo]\nopt-level = 1\n",
    );
    let lock = std::fs::read_to_string(dir.join("Cargo.lock")).unwrap();
    assert!(lock.contains("name = \"statrs\""));
    std::fs::write(
        dir.join("Cargo.lock"),
        lock.replace(
            "name = \"statrs\"\nversion = \"",
            "name = \"statrs\"\nversion = \"9",
        ),
    )
    .unwrap();
    let result = check_shipped(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    if let Err(e) = result {
        panic!("{e}");
    }
}
