//! The pipeline's error: every message names the file it is about (the asset, its sidecar, or
//! the output) and then where inside it and what was expected.

use std::path::{Path, PathBuf};

use crate::gltf_io;
use crate::sharpness::SharpnessError;

/// Why one file could not be processed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Reading or writing the glTF failed, or the asset is invalid or unsupported.
    #[error("{}: {source}", file.display())]
    Gltf {
        /// The file the error is about.
        file: PathBuf,
        /// What went wrong, located by JSON path.
        source: gltf_io::Error,
    },
    /// A per-edge h source (extras, sidecar, options) has a mistake; it names its own file.
    #[error(transparent)]
    Sharpness(#[from] SharpnessError),
    /// The request does not fit the asset (a mesh named on the command line that it lacks).
    #[error("{}: {what}", file.display())]
    Request {
        /// The asset.
        file: PathBuf,
        /// What was asked and what the asset has.
        what: String,
    },
    /// A bug: processing panicked. Caught by [`super::guarded`].
    #[error("{}: internal error: {what} (this is a bug in g2tess, not in the file; please report it with the file)", file.display())]
    Internal {
        /// The asset being processed.
        file: PathBuf,
        /// The panic's message.
        what: String,
    },
    /// The caller asked to stop ([`crate::options::Options::cancel`]) before the file was done;
    /// nothing was written.
    #[error("{}: cancelled", file.display())]
    Cancelled {
        /// The asset.
        file: PathBuf,
    },
    /// The work would exceed a resource bound.
    #[error("{}: {what}", file.display())]
    Limit {
        /// The asset.
        file: PathBuf,
        /// What would be exceeded and what to do instead.
        what: String,
    },
}

impl Error {
    /// A glTF-layer error about `file`.
    pub fn gltf(file: &Path, source: gltf_io::Error) -> Self {
        Error::Gltf {
            file: file.to_path_buf(),
            source,
        }
    }

    /// A resource bound about `file`.
    pub fn limit(file: &Path, what: impl Into<String>) -> Self {
        Error::Limit {
            file: file.to_path_buf(),
            what: what.into(),
        }
    }

    /// A caught panic while processing `file`; `payload` is what the panic carried.
    pub fn internal(file: &Path, payload: &(dyn std::any::Any + Send)) -> Self {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".into());
        Error::Internal {
            file: file.to_path_buf(),
            what,
        }
    }

    /// Whether the environment failed (a disk, a permission) rather than the input.
    pub fn is_io(&self) -> bool {
        matches!(self, Error::Gltf { source, .. } if source.kind == gltf_io::ErrorKind::Io)
    }
}
