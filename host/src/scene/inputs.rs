//! The files a scene was read from, each with the hash of its bytes: the scene file, meshes,
//! textures, environment maps, glTF buffers and images. A part file records them
//! (`crate::part_file`), so that `twinpath merge` refuses parts rendered from different data
//! and names the file that differs.
//!
//! The loaders read every file through [`read`], which records it while a load runs inside
//! [`recording`]. Invariant: a scene load runs on one thread (the loaders do not spawn work),
//! so the thread's record is the load's.

use std::cell::RefCell;
use std::path::{Path, PathBuf};

/// One file a scene read: its path as the scene named it, and the BLAKE3 hash of its bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InputFile {
    pub path: PathBuf,
    pub hash: blake3::Hash,
}

thread_local! {
    static RECORD: RefCell<Option<Vec<InputFile>>> = const { RefCell::new(None) };
}

/// Runs `load`, returning what it returned and the files it read through [`read`] or
/// [`record`], in the order first read, each once.
pub fn recording<T>(load: impl FnOnce() -> T) -> (T, Vec<InputFile>) {
    let outer = RECORD.with(|r| r.borrow_mut().replace(Vec::new()));
    let value = load();
    let files = RECORD.with(|r| std::mem::replace(&mut *r.borrow_mut(), outer));
    (value, files.unwrap_or_default())
}

/// Notes that the scene read `bytes` from `path` (when a load is being recorded).
pub fn record(path: &Path, bytes: &[u8]) {
    RECORD.with(|r| {
        if let Some(files) = r.borrow_mut().as_mut() {
            if !files.iter().any(|f| f.path == path) {
                files.push(InputFile {
                    path: path.to_path_buf(),
                    hash: blake3::hash(bytes),
                });
            }
        }
    });
}

/// Reads the file at `path` and records it.
pub fn read(path: &Path) -> std::io::Result<Vec<u8>> {
    let bytes = std::fs::read(path)?;
    record(path, &bytes);
    Ok(bytes)
}
