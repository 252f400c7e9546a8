//! Hands the kernel's SPIR-V module to the host as the env var `kernel.spv` (a path, included by
//! `twinpath::KERNEL_SPV`) and says where it came from in `TWINPATH_KERNEL_ORIGIN`; the tests'
//! module (the kernel with its feature `probe`) as `probe.spv` (`twinpath::PROBE_SPV`, feature
//! `test-support`).
//!
//! By default the module is the shipped one, `kernel/shipped/kernel.spv`, and the build fails at
//! once, naming what changed and `scripts/build_kernel.sh`, when its manifest no longer matches
//! the kernel's sources (`kernel_manifest::check_shipped`): a stale module is never used
//! silently. With the feature `kernel-from-source` rust-gpu compiles `kernel/` now, and the module
//! and the manifest it would ship with are written to OUT_DIR, where `scripts/build_kernel.sh`
//! takes them from.
fn main() {
    #[cfg(feature = "gpu")]
    if let Err(e) = kernel_module() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

#[cfg(feature = "gpu")]
fn kernel_module() -> Result<(), Box<dyn std::error::Error>> {
    let host = std::path::PathBuf::from(std::env::var("CARGO_MANIFEST_DIR")?);
    let root = host.parent().ok_or("host/ has no parent folder")?;
    for input in kernel_manifest::INPUTS {
        println!("cargo:rerun-if-changed={}", root.join(input).display());
    }
    #[cfg(not(feature = "kernel-from-source"))]
    {
        kernel_manifest::check_shipped(root)?;
        let module = root.join(kernel_manifest::MODULE_PATH);
        println!("cargo:rustc-env=kernel.spv={}", module.display());
        let probe = root.join(kernel_manifest::PROBE_MODULE_PATH);
        println!("cargo:rustc-env=probe.spv={}", probe.display());
        println!(
            "cargo:rustc-env=TWINPATH_KERNEL_ORIGIN=shipped ({}, its manifest checked against the kernel's sources)",
            kernel_manifest::MODULE_PATH
        );
    }
    #[cfg(feature = "kernel-from-source")]
    {
        let out_dir = std::path::PathBuf::from(std::env::var("OUT_DIR")?);
        let bytes = std::fs::read(compile(root, &[])?)?;
        let probe_bytes = std::fs::read(compile(root, kernel_manifest::PROBE_FEATURES)?)?;
        let module = out_dir.join("kernel.spv");
        std::fs::write(&module, &bytes)?;
        let probe = out_dir.join("probe.spv");
        std::fs::write(&probe, &probe_bytes)?;
        let manifest = kernel_manifest::Manifest::describe(root, &bytes, &probe_bytes)?;
        std::fs::write(out_dir.join("manifest.toml"), manifest.to_text())?;
        println!("cargo:rustc-env=kernel.spv={}", module.display());
        println!("cargo:rustc-env=probe.spv={}", probe.display());
        println!("cargo:rustc-env=TWINPATH_KERNEL_ORIGIN=compiled from kernel/ by rust-gpu at build time (feature kernel-from-source)");
    }
    Ok(())
}

/// Compiles `kernel/` with its cargo features `features` by rust-gpu under the options the
/// manifest records, and returns the module's path.
#[cfg(feature = "kernel-from-source")]
fn compile(
    root: &std::path::Path,
    features: &[&str],
) -> Result<std::path::PathBuf, Box<dyn std::error::Error>> {
    use spirv_builder::{Capability, ModuleResult, SpirvBuilder};
    let mut builder = SpirvBuilder::new(root.join("kernel"), kernel_manifest::TARGET)
        .shader_crate_features(features.iter().map(|f| f.to_string()));
    for name in kernel_manifest::CAPABILITIES {
        builder = builder.capability(match *name {
            "RayTracingKHR" => Capability::RayTracingKHR,
            other => return Err(format!("build.rs does not know the capability {other}").into()),
        });
    }
    for name in kernel_manifest::EXTENSIONS {
        builder = builder.extension(*name);
    }
    builder.build_script.defaults = true;
    builder.build_script.env_shader_spv_path = Some(false);
    match builder.build()?.module {
        ModuleResult::SingleModule(path) => Ok(path),
        ModuleResult::MultiModule(_) => {
            Err("rust-gpu wrote several modules; the host binds one".into())
        }
    }
}
