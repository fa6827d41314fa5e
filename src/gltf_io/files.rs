//! Which files an asset consists of and which files an output consists of, by name only: the
//! one place that knows that a `.gltf`'s buffer is `<stem>.bin`, that a compressed output's
//! fallback buffer is `<stem>.fallback.bin`, and where a document's `uri`s lead.
//!
//! Callers that plan work before doing it (skipping up-to-date outputs, watching, refusing two
//! outputs that would share a file or replace another asset's input) need these lists without
//! decoding anything, so the listing reads a `.glb`'s JSON chunk and nothing of its binary one.

use std::io::Read as _;
use std::path::{Path, PathBuf};

use serde_json::Value;

use super::meshopt_encode::Compression;
use super::{glb, uri};

/// The `.bin` written beside a `.gltf` output.
pub fn bin_path(gltf: &Path) -> PathBuf {
    gltf.with_extension("bin")
}

/// The file beside `path` that holds the uncompressed fallback of a compressed output.
pub fn fallback_path(path: &Path) -> PathBuf {
    path.with_extension("fallback.bin")
}

/// Every file writing `output` may create, in the order they are written: a compressed
/// output's fallback buffer, a `.gltf`'s `.bin`, the output itself. (A `.gltf` without binary
/// data gets no `.bin`; it is listed anyway, since a run may create it.)
pub fn output_files(output: &Path, compression: Option<Compression>) -> Vec<PathBuf> {
    let mut files = Vec::with_capacity(3);
    if compression.is_some_and(|c| c.fallback) {
        files.push(fallback_path(output));
    }
    let gltf = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf"));
    if gltf {
        files.push(bin_path(output));
    }
    files.push(output.to_path_buf());
    files
}

/// The buffer and image files the asset at `asset` refers to, in document order, resolved as
/// the reader resolves them (`uri`s leaving the asset's folder only when `allow_outside`).
///
/// Never fails: an unreadable or malformed asset refers to nothing here, and reading it
/// reports why. Only a `.glb`'s header and JSON chunk are read.
pub fn referenced_files(asset: &Path, allow_outside: bool) -> Vec<PathBuf> {
    let Some(json) = json_text(asset) else {
        return Vec::new();
    };
    let Ok(root) = serde_json::from_slice::<Value>(&json) else {
        return Vec::new();
    };
    let base = match asset.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    ["buffers", "images"]
        .iter()
        .filter_map(|k| root.get(*k).and_then(Value::as_array))
        .flatten()
        .filter_map(|o| o.get("uri").and_then(Value::as_str))
        // A `data:` URI is no file (and decoding it only to learn that would be waste).
        .filter(|u| !u.starts_with("data:"))
        .filter_map(
            |u| match uri::resolve(u, "uri", Some(base), allow_outside) {
                Ok(uri::Target::File(f)) => Some(f),
                _ => None,
            },
        )
        .collect()
}

/// The JSON text of a `.gltf`, or the JSON chunk of a `.glb` (read without its BIN chunk).
fn json_text(asset: &Path) -> Option<Vec<u8>> {
    let mut file = std::fs::File::open(asset).ok()?;
    let mut head = [0u8; 20];
    let mut got = 0;
    while got < head.len() {
        match file.read(&mut head[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(_) => return None,
        }
    }
    if !glb::is_glb(&head[..got]) {
        let mut text = head[..got].to_vec();
        file.read_to_end(&mut text).ok()?;
        return Some(text);
    }
    if got < head.len() {
        return None;
    }
    let len = u32::from_le_bytes([head[12], head[13], head[14], head[15]]);
    let mut json = Vec::new();
    file.take(u64::from(len)).read_to_end(&mut json).ok()?;
    Some(json)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_files_name_every_part() {
        let fallback = Some(Compression::new(true));
        assert_eq!(
            output_files(Path::new("o/x.gltf"), fallback),
            ["o/x.fallback.bin", "o/x.bin", "o/x.gltf"].map(PathBuf::from)
        );
        assert_eq!(
            output_files(Path::new("o/x.glb"), None),
            [PathBuf::from("o/x.glb")]
        );
    }

    #[test]
    fn a_glb_lists_its_files_from_the_json_chunk_alone() {
        let dir = tempfile::tempdir().unwrap();
        let json = br#"{"buffers":[{"uri":"a.bin","byteLength":4},{"uri":"data:,x","byteLength":1}],"images":[{"uri":"t%20x.png"}]}"#;
        let mut padded = json.to_vec();
        while padded.len() % 4 != 0 {
            padded.push(b' ');
        }
        let file = dir.path().join("m.glb");
        std::fs::write(&file, glb::assemble(&padded, &[0; 4])).unwrap();
        assert_eq!(
            referenced_files(&file, false),
            [dir.path().join("a.bin"), dir.path().join("t x.png")]
        );
        // Not glTF at all: nothing, and no error.
        std::fs::write(&file, b"glTF").unwrap();
        assert!(referenced_files(&file, false).is_empty());
    }
}
