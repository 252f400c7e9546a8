//! Scene errors: every one names the file, the line when there is one, and the field.

use std::fmt;
use std::path::{Path, PathBuf};

/// A problem with a scene file or a file it refers to.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The file at fault (the scene, or a mesh it names).
    pub file: PathBuf,
    /// 1-based line in `file`, when the problem has one.
    pub line: Option<usize>,
    /// The field at fault, e.g. `sphere[2].radius`, or `syntax` for a parse error.
    pub field: String,
    pub message: String,
}

impl SceneError {
    pub fn new(
        file: &Path,
        line: Option<usize>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            file: file.to_path_buf(),
            line,
            field: field.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        write!(f, ": {}: {}", self.field, self.message)
    }
}

impl std::error::Error for SceneError {}

/// 1-based line of byte offset `offset` in `text`.
pub fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}
