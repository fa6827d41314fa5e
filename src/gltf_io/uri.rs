//! Resolves a buffer or image `uri` to bytes: `data:` URIs decoded in memory, relative file
//! names percent-decoded and read from the asset's folder.
//!
//! It deliberately never touches the network, and by default refuses any `uri` that would leave
//! the asset's folder (`..`, absolute paths, `file:`, a symbolic link inside the folder that
//! points out of it), because a model downloaded from anywhere must not make the tool read
//! arbitrary files. Sizes are checked before anything is read or decoded.

use std::path::{Component, Path, PathBuf};

use base64::Engine as _;

use super::document::ReadOptions;
use super::error::{Error, Result};

/// What [`load`] may read.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Follow `uri`s out of the asset's folder.
    pub allow_outside: bool,
    /// Largest file read, in bytes.
    pub max_file_bytes: u64,
    /// Largest decoded `data:` URI, in bytes.
    pub max_data_bytes: u64,
}

impl From<&ReadOptions> for Limits {
    fn from(o: &ReadOptions) -> Self {
        Self {
            allow_outside: o.allow_outside_uris,
            max_file_bytes: o.max_bytes,
            max_data_bytes: o.max_data_uri_bytes,
        }
    }
}

/// Where a `uri` points, before any bytes are read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// A `data:` URI: its decoded bytes.
    Data(Vec<u8>),
    /// A file on disk.
    File(PathBuf),
}

/// Classifies and checks `uri` (found at JSON path `at`) relative to `base_dir`.
///
/// Percent-decoding happens here because exporters write both `%20` and literal spaces.
pub fn resolve(
    uri: &str,
    at: &str,
    base_dir: Option<&Path>,
    allow_outside: bool,
) -> Result<Target> {
    if let Some(rest) = uri.strip_prefix("data:") {
        return decode_data_uri(rest, at).map(Target::Data);
    }
    let scheme = uri.split_once(':').map(|(s, _)| s).filter(|s| {
        s.len() > 1
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    });
    let local = match scheme {
        Some(s) if s.eq_ignore_ascii_case("file") && allow_outside => {
            uri[5..].trim_start_matches("//").to_string()
        }
        Some(s) => {
            return Err(Error::invalid(
                at,
                format!("uri {uri:?} uses the {s}: scheme, which is never fetched (expected a relative file name or a data: uri)"),
            ))
        }
        None => uri.to_string(),
    };
    let decoded = percent_encoding::percent_decode_str(&local)
        .decode_utf8()
        .map_err(|_| {
            Error::invalid(
                at,
                format!("uri {uri:?} is not valid utf-8 after percent-decoding"),
            )
        })?;
    let rel = Path::new(decoded.as_ref());
    let escapes = rel.is_absolute()
        || rel.components().any(|c| {
            matches!(
                c,
                Component::ParentDir | Component::RootDir | Component::Prefix(_)
            )
        });
    if escapes && !allow_outside {
        return Err(Error::invalid(
            at,
            format!("uri {uri:?} leaves the asset's folder (expected a file beside the asset; pass --allow-outside-uris to permit it)"),
        ));
    }
    let Some(base) = base_dir else {
        return Err(Error::invalid(
            at,
            format!("uri {uri:?} refers to a file, but the input has no folder to resolve it in"),
        ));
    };
    Ok(Target::File(base.join(rel)))
}

/// Reads the bytes `uri` points at, refusing files and `data:` payloads larger than `limits`
/// before reading or decoding them, and files that resolve (through symbolic links) outside
/// `base_dir` unless allowed.
pub fn load(uri: &str, at: &str, base_dir: Option<&Path>, limits: &Limits) -> Result<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        // Base64 holds 3 bytes in 4 characters: bound the payload before decoding it.
        let estimate = (rest.len() as u64).saturating_mul(3) / 4;
        if estimate > limits.max_data_bytes {
            return Err(Error::invalid(
                at,
                format!(
                    "data: uri holds about {estimate} bytes (expected at most {}; store large buffers in a .bin or a .glb)",
                    limits.max_data_bytes
                ),
            ));
        }
    }
    match resolve(uri, at, base_dir, limits.allow_outside)? {
        Target::Data(bytes) => Ok(bytes),
        Target::File(path) => {
            let shown = format!("{at} ({})", path.display());
            if !limits.allow_outside {
                if let Some(base) = base_dir {
                    stays_inside(&path, base, uri, &shown)?;
                }
            }
            let len = std::fs::metadata(&path)
                .map_err(|e| Error::io(&shown, e))?
                .len();
            if len > limits.max_file_bytes {
                return Err(Error::invalid(
                    shown,
                    format!(
                        "file is {len} bytes (expected at most {})",
                        limits.max_file_bytes
                    ),
                ));
            }
            std::fs::read(&path).map_err(|e| Error::io(shown, e))
        }
    }
}

/// Refuses `path` when, with every symbolic link followed, it is not inside `base`: a link in the
/// asset's folder must not make the tool read a file the asset could not name directly.
fn stays_inside(path: &Path, base: &Path, uri: &str, shown: &str) -> Result<()> {
    let real = std::fs::canonicalize(path).map_err(|e| Error::io(shown, e))?;
    let real_base = std::fs::canonicalize(base).map_err(|e| Error::io(shown, e))?;
    if real.starts_with(&real_base) {
        return Ok(());
    }
    Err(Error::invalid(
        shown,
        format!(
            "uri {uri:?} is a link to {}, outside the asset's folder (expected a file inside it; pass --allow-outside-uris to permit it)",
            real.display()
        ),
    ))
}

/// Decodes the part of a `data:` URI after the scheme: base64 or percent-encoded payloads.
fn decode_data_uri(rest: &str, at: &str) -> Result<Vec<u8>> {
    let (meta, payload) = rest
        .split_once(',')
        .ok_or_else(|| Error::invalid(at, "data: uri has no ',' before its payload"))?;
    if meta.ends_with(";base64") {
        base64::engine::general_purpose::STANDARD
            .decode(payload.trim_end())
            .map_err(|e| Error::invalid(at, format!("data: uri is not valid base64: {e}")))
    } else {
        Ok(percent_encoding::percent_decode_str(payload).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parent_dir_is_refused_unless_allowed() {
        let base = Path::new("/assets");
        assert!(resolve("../secret.bin", "buffers[0].uri", Some(base), false).is_err());
        assert!(resolve("/etc/passwd", "buffers[0].uri", Some(base), false).is_err());
        assert_eq!(
            resolve("../x.bin", "b", Some(base), true).unwrap(),
            Target::File(base.join("../x.bin"))
        );
    }

    #[test]
    fn network_schemes_are_never_fetched() {
        let err = resolve(
            "http://example.com/b.bin",
            "buffers[0].uri",
            Some(Path::new(".")),
            true,
        )
        .unwrap_err();
        assert!(err.to_string().contains("http: scheme"), "{err}");
        assert!(resolve("file:///etc/passwd", "b", Some(Path::new(".")), false).is_err());
    }

    #[test]
    fn percent_encoded_names_are_decoded() {
        let t = resolve(
            "Unicode%20%E2%9D%A4 Binary.bin",
            "b",
            Some(Path::new("d")),
            false,
        )
        .unwrap();
        assert_eq!(t, Target::File(Path::new("d").join("Unicode ❤ Binary.bin")));
    }

    #[test]
    fn data_uris_decode_base64() {
        let t = resolve(
            "data:application/octet-stream;base64,AAEC",
            "b",
            None,
            false,
        )
        .unwrap();
        assert_eq!(t, Target::Data(vec![0, 1, 2]));
    }
}
