//! Scene-file errors that point at the offending text.

use thiserror::Error;

/// One problem with a scene file, located in the source text.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{source_name}:{line}:{column}: field `{path}`: {message}; expected {expected}")]
pub struct SceneError {
    /// File path (or `<catalog>/name.toml` for embedded scenes).
    pub source_name: String,
    /// 1-based line and column of the offending value (or of the enclosing table when the
    /// field is missing).
    pub line: usize,
    pub column: usize,
    /// Field path, e.g. `link[1].joint.stiffness`.
    pub path: String,
    pub message: String,
    /// The form the field should take, e.g. "a finite number > 0".
    pub expected: String,
}

/// Errors from loading a scene by name or path.
#[derive(Debug, Error)]
pub enum LoadError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("cannot read scene file {path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    #[error(
        "`{0}` is neither a catalog scene nor a readable .toml file; run `flexverify scenes` for the catalog"
    )]
    NotFound(String),
}

/// 1-based (line, column) of a byte offset; columns count characters.
pub fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let mut line = 1;
    let mut line_start = 0;
    for (i, b) in text.bytes().enumerate().take(offset) {
        if b == b'\n' {
            line += 1;
            line_start = i + 1;
        }
    }
    let column = text
        .get(line_start..offset)
        .map_or(1, |s| s.chars().count() + 1);
    (line, column)
}
