//! The one error type of the glTF layer: every message says where (a JSON path such as
//! `meshes[2].primitives[0].attributes.POSITION`, or a part of the file) and what was expected.
//!
//! It deliberately does not name the input file: the caller knows it and prefixes it, so that
//! [`super::read_bytes`] (which has no file) reports the same way as [`super::read`].

use std::fmt;

/// What kind of failure an [`Error`] is, so callers can tell bad input from a bad environment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// The input breaks the glTF specification or one of the reader's bounds.
    Invalid,
    /// The input is valid glTF but uses something this tool cannot process (Draco, glTF 1.0).
    Unsupported,
    /// Reading or writing a file failed.
    Io,
}

/// A located, human-readable error: `<where>: <what is wrong> (expected …)`.
#[derive(Debug, thiserror::Error)]
#[error("{at}: {what}")]
pub struct Error {
    /// Which kind of failure this is.
    pub kind: ErrorKind,
    /// Where: a JSON path, a GLB chunk, or a file path.
    pub at: String,
    /// What is wrong, lowercase, without a final period; often ends with `(expected …)`.
    pub what: String,
    #[source]
    source: Option<std::io::Error>,
}

impl Error {
    /// The input breaks the specification or a reader bound.
    pub fn invalid(at: impl fmt::Display, what: impl fmt::Display) -> Self {
        Self::new(ErrorKind::Invalid, at, what, None)
    }

    /// The input is valid but uses a feature this tool cannot process.
    pub fn unsupported(at: impl fmt::Display, what: impl fmt::Display) -> Self {
        Self::new(ErrorKind::Unsupported, at, what, None)
    }

    /// A file could not be read or written.
    pub fn io(at: impl fmt::Display, source: std::io::Error) -> Self {
        let what = source.to_string().to_lowercase();
        Self::new(ErrorKind::Io, at, what, Some(source))
    }

    fn new(
        kind: ErrorKind,
        at: impl fmt::Display,
        what: impl fmt::Display,
        source: Option<std::io::Error>,
    ) -> Self {
        Self {
            kind,
            at: at.to_string(),
            what: what.to_string(),
            source,
        }
    }
}

/// Shorthand for results of this layer.
pub type Result<T, E = Error> = std::result::Result<T, E>;
