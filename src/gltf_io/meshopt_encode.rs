//! EXT_meshopt_compression on write: every buffer view that holds only accessor data is
//! compressed (attribute codec, version 0 as the extension requires; triangle codec for triangle
//! list indices; index-sequence codec for other indices; the OCTAHEDRAL filter where
//! [`mod@super::quantize`] left octahedral normals), its compressed bytes go to buffer 0, and the view
//! itself moves to a fallback buffer that holds the uncompressed layout.
//!
//! It deliberately compresses nothing it cannot reproduce exactly: views of images, of sparse
//! accessors and of data only extensions refer to stay as they are. It does not quantize (that is
//! [`mod@super::quantize`]) and it writes no files (the writer does).

use std::collections::{BTreeMap, BTreeSet};

use serde_json::{json, Map, Value};

use super::error::{Error, Result};
use super::quantize::Filtered;

/// The extension this module writes (the reader also accepts its KHR twin).
pub const EXTENSION: &str = "EXT_meshopt_compression";

/// The vertex codec version EXT_meshopt_compression defines (version 1 is KHR-only).
const VERTEX_CODEC_VERSION: i32 = 0;

/// How to compress.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct Compression {
    /// Also write the uncompressed data (a `<name>.fallback.bin` beside the output) so that
    /// loaders without the extension can read the asset; the extension is then optional.
    /// Default: `false` (the fallback buffer is a placeholder with only a `byteLength`).
    pub fallback: bool,
}

impl Compression {
    /// Compression with or without an uncompressed fallback file.
    pub fn new(fallback: bool) -> Self {
        Self { fallback }
    }
}

/// The result of [`compress`]: the fallback buffer's size, and its bytes when they are written.
pub(crate) struct Fallback {
    pub byte_length: usize,
    pub bytes: Option<Vec<u8>>,
}

/// How one view is compressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Attributes,
    Triangles,
    Indices,
}

impl Mode {
    fn name(self) -> &'static str {
        match self {
            Mode::Attributes => "ATTRIBUTES",
            Mode::Triangles => "TRIANGLES",
            Mode::Indices => "INDICES",
        }
    }
}

/// Compresses the views of `root` (whose `views` all lie in `bin`, buffer 0) in place: `bin`
/// becomes buffer 0 with the compressed streams and every view left uncompressed; compressed
/// views point into buffer 1, the fallback. `filtered` is keyed by view index. Returns `None`
/// when no view qualified (then nothing changed).
pub(crate) fn compress(
    root: &Map<String, Value>,
    views: &mut [Value],
    bin: &mut Vec<u8>,
    filtered: &BTreeMap<usize, Filtered>,
    keep_fallback: bool,
) -> Result<Option<Fallback>> {
    let plans = plan(root, views);
    if plans.iter().all(Option::is_none) {
        return Ok(None);
    }
    let mut out = Vec::with_capacity(bin.len() / 2);
    let mut fallback = Vec::new();
    let mut fallback_len = 0usize;
    for (i, view) in views.iter_mut().enumerate() {
        let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        let len = view["byteLength"].as_u64().unwrap_or(0) as usize;
        let bytes = bin.get(offset..offset + len).ok_or_else(|| {
            Error::invalid(
                format!("bufferViews[{i}]"),
                "lies outside the buffer (please report)",
            )
        })?;
        align4(&mut out);
        let Some((mode, stride)) = plans[i] else {
            view["byteOffset"] = json!(out.len());
            out.extend_from_slice(bytes);
            continue;
        };
        let filter = filtered
            .get(&i)
            .filter(|f| mode == Mode::Attributes && f.encoded.len() == len);
        let (encoded, plain) = match mode {
            Mode::Attributes => {
                let source = filter.map_or(bytes, |f| &f.encoded[..]);
                (encode_attributes(source, stride, i)?, bytes.to_vec())
            }
            Mode::Triangles | Mode::Indices => encode_indices(bytes, stride, mode, i)?,
        };
        let count = len / stride;
        let mut ext = json!({
            "buffer": 0,
            "byteOffset": out.len(),
            "byteLength": encoded.len(),
            "byteStride": stride,
            "count": count,
            "mode": mode.name(),
        });
        if let Some(f) = filter {
            ext["filter"] = json!(f.filter.name());
        }
        out.extend_from_slice(&encoded);
        fallback_len = fallback_len.div_ceil(4) * 4;
        view["buffer"] = json!(1);
        view["byteOffset"] = json!(fallback_len);
        fallback_len += len;
        if keep_fallback {
            fallback.resize(view["byteOffset"].as_u64().unwrap_or(0) as usize, 0);
            fallback.extend_from_slice(&plain);
        }
        let obj = view.as_object_mut().expect("views are objects");
        let exts = obj
            .entry("extensions")
            .or_insert_with(|| json!({}))
            .as_object_mut()
            .ok_or_else(|| {
                Error::invalid(format!("bufferViews[{i}].extensions"), "is not an object")
            })?;
        exts.insert(EXTENSION.into(), ext);
    }
    align4(&mut out);
    *bin = out;
    Ok(Some(Fallback {
        byte_length: fallback_len.div_ceil(4) * 4,
        bytes: keep_fallback.then(|| {
            align4(&mut fallback);
            fallback
        }),
    }))
}

fn align4(bytes: &mut Vec<u8>) {
    bytes.resize(bytes.len().div_ceil(4) * 4, 0);
}

/// Per view: the mode and byte stride it is compressed with, or `None` to leave it.
fn plan(root: &Map<String, Value>, views: &[Value]) -> Vec<Option<(Mode, usize)>> {
    let list = |key: &str| {
        root.get(key)
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default()
    };
    let accessors = list("accessors");
    // Index accessors, and whether every primitive using each is a triangle list.
    let mut index_use: BTreeMap<u64, bool> = BTreeMap::new();
    for prim in list("meshes")
        .iter()
        .filter_map(|m| m["primitives"].as_array())
        .flatten()
    {
        if let Some(i) = prim["indices"].as_u64() {
            let triangles = prim["mode"].as_u64().unwrap_or(4) == 4;
            *index_use.entry(i).or_insert(true) &= triangles;
        }
    }
    let mut users: Vec<Vec<usize>> = vec![Vec::new(); views.len()];
    let mut blocked = BTreeSet::new();
    for (a, acc) in accessors.iter().enumerate() {
        if let Some(s) = acc.get("sparse") {
            for p in ["/indices/bufferView", "/values/bufferView"] {
                blocked.extend(s.pointer(p).and_then(Value::as_u64));
            }
            blocked.extend(acc["bufferView"].as_u64());
        }
        if let Some(v) = acc["bufferView"]
            .as_u64()
            .filter(|v| (*v as usize) < views.len())
        {
            users[v as usize].push(a);
        }
    }
    views
        .iter()
        .enumerate()
        .map(|(v, view)| {
            let len = view["byteLength"].as_u64()? as usize;
            if blocked.contains(&(v as u64)) || users[v].is_empty() || len == 0 {
                return None;
            }
            let parent_stride = view["byteStride"].as_u64().map(|s| s as usize);
            let is_index = |a: &usize| index_use.contains_key(&(*a as u64));
            if users[v].iter().all(is_index) {
                let sizes: BTreeSet<usize> = users[v]
                    .iter()
                    .map(|a| component_size(&accessors[*a]))
                    .collect();
                let stride = *sizes.iter().next()?;
                if sizes.len() != 1 || !(stride == 2 || stride == 4) || parent_stride.is_some() {
                    return None;
                }
                if len % stride != 0 {
                    return None;
                }
                let acc = &accessors[users[v][0]];
                let whole = users[v].len() == 1
                    && acc["byteOffset"].as_u64().unwrap_or(0) == 0
                    && acc["count"].as_u64() == Some((len / stride) as u64);
                let triangles =
                    whole && index_use[&(users[v][0] as u64)] && (len / stride) % 3 == 0;
                let mode = if triangles {
                    Mode::Triangles
                } else {
                    Mode::Indices
                };
                return Some((mode, stride));
            }
            if users[v].iter().any(is_index) {
                return None;
            }
            let elems: BTreeSet<usize> = users[v]
                .iter()
                .map(|a| element_size(&accessors[*a]))
                .collect();
            let stride = match (parent_stride, elems.iter().next()) {
                (Some(s), _) => s,
                (None, Some(e)) if elems.len() == 1 && e % 4 == 0 && len % e == 0 => *e,
                (None, _) => 4,
            };
            (stride % 4 == 0 && stride <= 256 && len % stride == 0)
                .then_some((Mode::Attributes, stride))
        })
        .collect()
}

fn component_size(acc: &Value) -> usize {
    match acc["componentType"].as_u64() {
        Some(5120 | 5121) => 1,
        Some(5122 | 5123) => 2,
        _ => 4,
    }
}

/// Bytes of one element of `acc` (0 for matrices, whose columns may be padded).
fn element_size(acc: &Value) -> usize {
    let n = match acc["type"].as_str() {
        Some("SCALAR") => 1,
        Some("VEC2") => 2,
        Some("VEC3") => 3,
        Some("VEC4") => 4,
        Some("MAT4") if component_size(acc) == 4 => 16,
        _ => return 0,
    };
    n * component_size(acc)
}

/// The attribute codec over `bytes` as elements of `stride` bytes.
fn encode_attributes(bytes: &[u8], stride: usize, view: usize) -> Result<Vec<u8>> {
    let count = bytes.len() / stride;
    // SAFETY: pure size computation.
    let bound = unsafe { meshopt::ffi::meshopt_encodeVertexBufferBound(count, stride) };
    let mut out = vec![0u8; bound];
    // SAFETY: `out` holds `bound` bytes, the encoder's worst case for `count` elements of
    // `stride` bytes; `bytes` holds exactly `count * stride` bytes; stride is a multiple of 4
    // up to 256 (checked by `plan`).
    let size = unsafe {
        meshopt::ffi::meshopt_encodeVertexBufferLevel(
            out.as_mut_ptr(),
            out.len(),
            bytes.as_ptr().cast(),
            count,
            stride,
            2,
            VERTEX_CODEC_VERSION,
        )
    };
    if size == 0 {
        return Err(Error::invalid(
            format!("bufferViews[{view}]"),
            "the attribute codec failed (please report)",
        ));
    }
    out.truncate(size);
    Ok(out)
}

/// The triangle or index-sequence codec over `bytes` (indices of `stride` bytes). Returns the
/// encoded stream and the indices as the decoder reproduces them (the triangle codec may rotate
/// a triangle's corners, keeping its winding), so that the fallback matches the decoded data.
fn encode_indices(
    bytes: &[u8],
    stride: usize,
    mode: Mode,
    view: usize,
) -> Result<(Vec<u8>, Vec<u8>)> {
    let indices: Vec<u32> = if stride == 2 {
        bytes
            .chunks_exact(2)
            .map(|b| u32::from(u16::from_le_bytes([b[0], b[1]])))
            .collect()
    } else {
        bytes
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect()
    };
    let vertices = indices.iter().max().map_or(0, |m| *m as usize + 1);
    let fail = |e: meshopt::Error| {
        Error::invalid(
            format!("bufferViews[{view}]"),
            format!("the index codec failed: {e} (please report)"),
        )
    };
    let (encoded, decoded) = if mode == Mode::Triangles {
        let enc = meshopt::encode_index_buffer(&indices, vertices).map_err(fail)?;
        let dec: Vec<u32> = meshopt::decode_index_buffer(&enc, indices.len()).map_err(fail)?;
        (enc, dec)
    } else {
        let enc = meshopt::encode_index_sequence(&indices, vertices).map_err(fail)?;
        let dec: Vec<u32> = meshopt::decode_index_sequence(&enc, indices.len()).map_err(fail)?;
        (enc, dec)
    };
    let plain = if stride == 2 {
        decoded
            .iter()
            .flat_map(|i| (*i as u16).to_le_bytes())
            .collect()
    } else {
        decoded.iter().flat_map(|i| i.to_le_bytes()).collect()
    };
    Ok((encoded, plain))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attributes_use_vertex_codec_version_0() {
        let bytes: Vec<u8> = (0..64u32).flat_map(|i| (i * 3).to_le_bytes()).collect();
        let enc = encode_attributes(&bytes, 8, 0).unwrap();
        // SAFETY: `enc` is a live slice.
        let version = unsafe { meshopt::ffi::meshopt_decodeVertexVersion(enc.as_ptr(), enc.len()) };
        assert_eq!(version, 0);
        assert_eq!(enc[0], 0xa0);
    }

    #[test]
    fn triangle_indices_round_trip_up_to_rotation() {
        let indices: Vec<u8> = [0u16, 1, 2, 2, 1, 3, 3, 1, 4]
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let (_, plain) = encode_indices(&indices, 2, Mode::Triangles, 0).unwrap();
        let tri = |b: &[u8]| {
            let t: Vec<u16> = b
                .chunks(2)
                .map(|c| u16::from_le_bytes([c[0], c[1]]))
                .collect();
            let m = (0..3).min_by_key(|k| t[*k]).unwrap();
            [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
        };
        for (a, b) in indices.chunks(6).zip(plain.chunks(6)) {
            assert_eq!(tri(a), tri(b));
        }
    }
}
