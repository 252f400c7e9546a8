//! The shipped kernel modules' manifest: what `kernel/shipped/kernel.spv` (the renderer's
//! module) and `kernel/shipped/probe.spv` (the same sources with the kernel's feature `probe`:
//! the equivalence tests' compute probes, which the renderer does not ship) were compiled from,
//! and the check that the repository still holds exactly those inputs.
//!
//! twinpath ships the SPIR-V module rust-gpu compiles from `kernel/`, so that a build needs
//! neither rust-gpu's compiler backend nor its toolchain components. The module is only as good
//! as its inputs, so beside it lies a manifest naming every input that decides its bytes: each
//! kernel source file (by BLAKE3 hash), the locked version of every package the kernel and
//! rust-gpu are built from, the pinned toolchain, the workspace's release profile (rust-gpu
//! compiles the kernel with it) and the builder's options. Every build of the host compares the
//! manifest with the repository ([`check_shipped`], called by `host/build.rs`) and fails, naming
//! what differs and [`REGENERATE`], when they disagree; the module itself must hash to what the
//! manifest says. The invariant: a build that succeeds runs the module the kernel's sources
//! compile to, or was told to compile it from source.
//!
//! The manifest is a small TOML file written by [`Manifest::to_text`]; [`Manifest::parse`]
//! reads back exactly that shape (top-level keys, then `[sources]` and `[packages]`, every value
//! a quoted string) so that `host/build.rs` needs no TOML parser.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::{Path, PathBuf};

/// The shipped module, relative to the repository root.
pub const MODULE_PATH: &str = "kernel/shipped/kernel.spv";
/// The tests' module: the kernel compiled with [`PROBE_FEATURES`] (the compute entry point
/// `shaders::probe`), relative to the repository root.
pub const PROBE_MODULE_PATH: &str = "kernel/shipped/probe.spv";
/// The kernel's cargo features the tests' module is compiled with.
pub const PROBE_FEATURES: &[&str] = &["probe"];
/// The manifest of both modules, relative to the repository root.
pub const MANIFEST_PATH: &str = "kernel/shipped/manifest.toml";
/// The script that compiles the module from source and rewrites both files.
pub const REGENERATE: &str = "scripts/build_kernel.sh";
/// rust-gpu's target for the module: Vulkan 1.2 SPIR-V.
pub const TARGET: &str = "spirv-unknown-vulkan1.2";
/// SPIR-V capabilities the builder declares. Ray-tracing pipelines only: declaring RayQueryKHR
/// would make the module unusable on devices without `VK_KHR_ray_query`.
pub const CAPABILITIES: &[&str] = &["RayTracingKHR"];
/// SPIR-V extensions the builder declares (capabilities and extensions are both required).
pub const EXTENSIONS: &[&str] = &["SPV_KHR_ray_tracing"];
/// The packages whose dependency closures (in `Cargo.lock`) the module is built from: the kernel
/// itself and rust-gpu's builder (which carries its compiler backend).
const ROOT_PACKAGES: &[&str] = &["kernel", "spirv-builder"];
/// Paths, relative to the repository root, whose change can change the manifest: a build script
/// reruns when one of them changes.
pub const INPUTS: &[&str] = &["kernel", "Cargo.lock", "Cargo.toml", "rust-toolchain.toml"];

/// What a module was compiled from. Three tables, each a sorted map from a name to a string:
/// `build` (the module's own hash and size, the toolchain, the builder's options, the release
/// profile's hash), `sources` (every kernel source file's hash) and `packages` (locked versions).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Manifest {
    pub build: BTreeMap<String, String>,
    pub sources: BTreeMap<String, String>,
    pub packages: BTreeMap<String, String>,
}

/// Why a manifest could not be made, read or matched.
#[derive(Debug)]
pub enum Error {
    /// A file could not be read.
    Io { path: PathBuf, message: String },
    /// A file is not in the shape this crate reads (`Cargo.lock`, `rust-toolchain.toml` or the
    /// manifest), at a 1-based line.
    Malformed {
        path: PathBuf,
        line: usize,
        message: String,
    },
    /// The shipped module was not compiled from what the repository holds now: one line per
    /// difference, each naming the input.
    Stale { differences: Vec<String> },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io { path, message } => write!(f, "{}: {message}", path.display()),
            Error::Malformed {
                path,
                line,
                message,
            } => write!(f, "{}:{line}: {message}", path.display()),
            Error::Stale { differences } => {
                writeln!(
                    f,
                    "the shipped kernel module ({MODULE_PATH}) was not compiled from the kernel \
                     this repository holds now ({MANIFEST_PATH} differs):"
                )?;
                for d in differences {
                    writeln!(f, "  - {d}")?;
                }
                write!(
                    f,
                    "Regenerate the module and its manifest with `{REGENERATE}` (its first run \
                     builds rust-gpu's compiler backend, about 12 minutes on two cores; later \
                     runs take seconds), or build the module from source at build time with \
                     `--features twinpath/kernel-from-source`."
                )
            }
        }
    }
}

impl std::error::Error for Error {}

fn read(path: &Path) -> Result<Vec<u8>, Error> {
    std::fs::read(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn read_text(path: &Path) -> Result<String, Error> {
    String::from_utf8(read(path)?).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn hash_hex(bytes: &[u8]) -> String {
    blake3::hash(bytes).to_hex().to_string()
}

impl Manifest {
    /// The manifest modules compiled now, from the repository at `root`, would carry; `module`
    /// is the renderer's module's bytes, `probe_module` the tests' module's.
    pub fn describe(root: &Path, module: &[u8], probe_module: &[u8]) -> Result<Manifest, Error> {
        let mut build = BTreeMap::new();
        build.insert("module_blake3".into(), hash_hex(module));
        build.insert("module_bytes".into(), module.len().to_string());
        build.insert("probe_module_blake3".into(), hash_hex(probe_module));
        build.insert("probe_module_bytes".into(), probe_module.len().to_string());
        build.insert("probe_features".into(), PROBE_FEATURES.join(" "));
        build.insert("toolchain".into(), toolchain(root)?);
        build.insert("target".into(), TARGET.into());
        build.insert("capabilities".into(), CAPABILITIES.join(" "));
        build.insert("extensions".into(), EXTENSIONS.join(" "));
        build.insert(
            "release_profile_blake3".into(),
            hash_hex(release_profile(&read_text(&root.join("Cargo.toml"))?).as_bytes()),
        );
        Ok(Manifest {
            build,
            sources: kernel_sources(root)?,
            packages: locked_packages(root)?,
        })
    }

    /// The manifest's text, in the shape [`Manifest::parse`] reads.
    pub fn to_text(&self) -> String {
        let mut out = String::from(
            "# What kernel.spv and probe.spv, beside this file, were compiled from. Written by \
             scripts/build_kernel.sh;\n# every build of the host checks it against the \
             repository (kernel-manifest/src/lib.rs). Do not edit.\n",
        );
        let table = |out: &mut String, map: &BTreeMap<String, String>| {
            for (k, v) in map {
                out.push_str(&format!("{} = \"{v}\"\n", quote_key(k)));
            }
        };
        table(&mut out, &self.build);
        out.push_str("\n[sources]\n");
        table(&mut out, &self.sources);
        out.push_str("\n[packages]\n");
        table(&mut out, &self.packages);
        out
    }

    /// Reads the text [`Manifest::to_text`] writes; `path` names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Manifest, Error> {
        let mut m = Manifest::default();
        let mut section = "";
        for (i, raw) in text.lines().enumerate() {
            let malformed = |message: &str| Error::Malformed {
                path: path.to_path_buf(),
                line: i + 1,
                message: message.to_string(),
            };
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
                section = match name {
                    "sources" => "sources",
                    "packages" => "packages",
                    _ => {
                        return Err(malformed(
                            "unknown table (expected [sources] or [packages])",
                        ))
                    }
                };
                continue;
            }
            let (key, value) = line
                .split_once(" = ")
                .ok_or_else(|| malformed("expected key = \"value\""))?;
            let key = key.trim_matches('"').to_string();
            let value = value
                .strip_prefix('"')
                .and_then(|v| v.strip_suffix('"'))
                .ok_or_else(|| malformed("the value must be a quoted string"))?
                .to_string();
            let map = match section {
                "sources" => &mut m.sources,
                "packages" => &mut m.packages,
                _ => &mut m.build,
            };
            if map.insert(key, value).is_some() {
                return Err(malformed("key given twice"));
            }
        }
        Ok(m)
    }

    /// What differs from `shipped` (this manifest being what the repository says now), one line
    /// per difference, naming the input; empty when they agree.
    pub fn differences(&self, shipped: &Manifest) -> Vec<String> {
        let mut out = Vec::new();
        // Sources are named by their paths alone; other entries by their table's word.
        let mut compare = |what: &str, now: &BTreeMap<String, String>, then: &BTreeMap<_, _>| {
            let keys: BTreeSet<&String> = now.keys().chain(then.keys()).collect();
            for k in keys {
                let name = if what.is_empty() {
                    k.to_string()
                } else {
                    format!("{what} {k}")
                };
                match (now.get(k), then.get(k)) {
                    (Some(a), Some(b)) if a == b => {}
                    (Some(_), Some(_)) if what.is_empty() => out.push(format!("{name} changed")),
                    (Some(a), Some(b)) => {
                        out.push(format!("{name}: {b} when the module was built, {a} now"))
                    }
                    (Some(_), None) => out.push(format!("{name} is new")),
                    (None, Some(_)) => out.push(format!("{name} is gone")),
                    (None, None) => unreachable!("a key comes from one of the maps"),
                }
            }
        };
        compare("", &self.sources, &shipped.sources);
        compare("package", &self.packages, &shipped.packages);
        compare("build", &self.build, &shipped.build);
        out
    }
}

/// Compares the shipped module and its manifest with the repository at `root`: Ok with the
/// manifest when the module is the one the kernel's current inputs compile to (as far as the
/// manifest can tell: the CI recompiles it and compares bytes), else [`Error::Stale`].
pub fn check_shipped(root: &Path) -> Result<Manifest, Error> {
    let module = read(&root.join(MODULE_PATH))?;
    let probe_module = read(&root.join(PROBE_MODULE_PATH))?;
    let manifest_path = root.join(MANIFEST_PATH);
    let shipped = Manifest::parse(&read_text(&manifest_path)?, &manifest_path)?;
    let now = Manifest::describe(root, &module, &probe_module)?;
    let mut differences = Vec::new();
    for (path, key) in [
        (MODULE_PATH, "module_blake3"),
        (PROBE_MODULE_PATH, "probe_module_blake3"),
    ] {
        if now.build.get(key) != shipped.build.get(key) {
            differences.push(format!(
                "{path} is not the module the manifest describes (its BLAKE3 hash differs)"
            ));
        }
    }
    // The modules' own hashes and sizes are compared above; what remains are their inputs.
    let inputs = |m: &Manifest| {
        let mut m = m.clone();
        for key in [
            "module_blake3",
            "module_bytes",
            "probe_module_blake3",
            "probe_module_bytes",
        ] {
            m.build.remove(key);
        }
        m
    };
    differences.extend(inputs(&now).differences(&inputs(&shipped)));
    if differences.is_empty() {
        Ok(shipped)
    } else {
        Err(Error::Stale { differences })
    }
}

fn quote_key(k: &str) -> String {
    if k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        k.to_string()
    } else {
        format!("\"{k}\"")
    }
}

/// The pinned channel of `rust-toolchain.toml` (`channel = "..."`).
fn toolchain(root: &Path) -> Result<String, Error> {
    let path = root.join("rust-toolchain.toml");
    let text = read_text(&path)?;
    text.lines()
        .filter_map(|l| l.trim().strip_prefix("channel"))
        .filter_map(|rest| rest.trim().strip_prefix('='))
        .map(|v| v.trim().trim_matches('"').to_string())
        .next()
        .ok_or(Error::Malformed {
            path,
            line: 1,
            message: "no `channel = \"...\"` line".into(),
        })
}

/// The lines of every `[profile.release...]` table of the workspace's Cargo.toml, trimmed and
/// without comments: rust-gpu compiles the kernel in the release profile.
fn release_profile(cargo_toml: &str) -> String {
    let mut inside = false;
    let mut out = String::new();
    for line in cargo_toml.lines() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.starts_with('[') {
            inside = line.starts_with("[profile.release");
        }
        if inside && !line.is_empty() {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// Every file under `kernel/` but the shipped module's folder, by its path from the repository
/// root ('/'-separated) and its BLAKE3 hash. Hidden files, editor backups (`~`) and a `target`
/// folder are not sources.
fn kernel_sources(root: &Path) -> Result<BTreeMap<String, String>, Error> {
    fn walk(dir: &Path, rel: &str, out: &mut BTreeMap<String, String>) -> Result<(), Error> {
        let entries = std::fs::read_dir(dir).map_err(|e| Error::Io {
            path: dir.to_path_buf(),
            message: e.to_string(),
        })?;
        for entry in entries {
            let entry = entry.map_err(|e| Error::Io {
                path: dir.to_path_buf(),
                message: e.to_string(),
            })?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let rel = format!("{rel}/{name}");
            if name.starts_with('.')
                || name.ends_with('~')
                || rel == "kernel/shipped"
                || rel == "kernel/target"
            {
                continue;
            }
            let path = entry.path();
            if path.is_dir() {
                walk(&path, &rel, out)?;
            } else {
                out.insert(rel, hash_hex(&read(&path)?));
            }
        }
        Ok(())
    }
    let mut out = BTreeMap::new();
    walk(&root.join("kernel"), "kernel", &mut out)?;
    Ok(out)
}

/// The locked version of every package in the dependency closures of [`ROOT_PACKAGES`], read
/// from `Cargo.lock` (several versions of one name joined by spaces; a source other than
/// crates.io appended in parentheses).
fn locked_packages(root: &Path) -> Result<BTreeMap<String, String>, Error> {
    let path = root.join("Cargo.lock");
    let text = read_text(&path)?;
    // (name, version) -> (source, dependencies as written)
    let mut packages: BTreeMap<(String, String), (String, Vec<String>)> = BTreeMap::new();
    let mut current: Option<(String, String, String, Vec<String>)> = None;
    let mut in_deps = false;
    let flush = |current: &mut Option<(String, String, String, Vec<String>)>,
                 packages: &mut BTreeMap<_, _>| {
        if let Some((name, version, source, deps)) = current.take() {
            packages.insert((name, version), (source, deps));
        }
    };
    let value = |l: &str| {
        l.split_once('=')
            .map(|(_, v)| v.trim().trim_matches('"').to_string())
    };
    for line in text.lines() {
        let line = line.trim();
        if line == "[[package]]" {
            flush(&mut current, &mut packages);
            current = Some(Default::default());
            in_deps = false;
        } else if let Some(p) = current.as_mut() {
            if in_deps {
                if line == "]" {
                    in_deps = false;
                } else {
                    p.3.push(line.trim_end_matches(',').trim_matches('"').to_string());
                }
            } else if line.starts_with("name =") {
                p.0 = value(line).unwrap_or_default();
            } else if line.starts_with("version =") {
                p.1 = value(line).unwrap_or_default();
            } else if line.starts_with("source =") {
                p.2 = value(line).unwrap_or_default();
            } else if line.starts_with("dependencies = [") {
                in_deps = !line.ends_with(']');
            }
        }
    }
    flush(&mut current, &mut packages);

    // A dependency is written "name", "name version" or "name version (source)".
    let resolve = |spec: &str| -> Option<(String, String)> {
        let mut parts = spec.split(' ');
        let name = parts.next()?;
        match parts.next() {
            Some(version) => Some((name.to_string(), version.to_string())),
            None => packages
                .keys()
                .find(|(n, _)| n == name)
                .map(|k| (k.0.clone(), k.1.clone())),
        }
    };
    let mut seen: BTreeSet<(String, String)> = BTreeSet::new();
    let mut stack = Vec::new();
    for root_name in ROOT_PACKAGES {
        let key = resolve(root_name).ok_or_else(|| Error::Malformed {
            path: path.clone(),
            line: 1,
            message: format!("no package `{root_name}`"),
        })?;
        stack.push(key);
    }
    while let Some(key) = stack.pop() {
        if !seen.insert(key.clone()) {
            continue;
        }
        let (_, deps) = packages.get(&key).ok_or_else(|| Error::Malformed {
            path: path.clone(),
            line: 1,
            message: format!("package `{} {}` is not locked", key.0, key.1),
        })?;
        for d in deps {
            if let Some(k) = resolve(d) {
                stack.push(k);
            }
        }
    }
    let mut out: BTreeMap<String, String> = BTreeMap::new();
    for (name, version) in seen {
        let source = &packages[&(name.clone(), version.clone())].0;
        let mut v = version;
        if !source.is_empty()
            && !source.starts_with("registry+https://github.com/rust-lang/crates.io-index")
        {
            v = format!("{v} ({source})");
        }
        out.entry(name)
            .and_modify(|e| {
                e.push(' ');
                e.push_str(&v);
            })
            .or_insert(v);
    }
    Ok(out)
}
