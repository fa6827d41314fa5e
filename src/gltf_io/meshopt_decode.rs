//! Decodes `EXT_meshopt_compression` / `KHR_meshopt_compression` buffer views (including their
//! octahedral, quaternion, exponential and color filters) with the `meshopt` crate.
//!
//! Decoding happens once at read time; afterwards the document holds plain buffer views and the
//! rest of the reader never sees compression. It deliberately does not encode: re-compressing the
//! output is the writer's option, not the reader's.

use serde_json::{Map, Value};

use super::document::Document;
use super::error::{Error, Result};

/// The two extension names that share one format.
pub const EXTENSIONS: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// Is `buffer` a meshopt fallback buffer (no data of its own; its views are all compressed)?
pub fn is_fallback(buffer: &gltf_json::Buffer) -> bool {
    buffer.extensions.as_ref().is_some_and(|e| {
        EXTENSIONS.iter().any(|n| {
            e.others
                .get(*n)
                .and_then(|x| x.get("fallback"))
                .and_then(Value::as_bool)
                == Some(true)
        })
    })
}

/// Is every buffer view that uses buffer `buffer` compressed (so the buffer needs no data)?
pub fn only_compressed_views(root: &gltf_json::Root, buffer: usize) -> bool {
    let mut views = root
        .buffer_views
        .iter()
        .filter(|v| v.buffer.value() == buffer)
        .peekable();
    views.peek().is_some()
        && views.all(|v| {
            v.extensions
                .as_ref()
                .is_some_and(|e| EXTENSIONS.iter().any(|n| e.others.contains_key(*n)))
        })
}

/// Decodes every compressed buffer view in place; their uncompressed bytes move to the scratch
/// buffer, and the views lose the extension. Each view decodes to at most `max_bytes`, all of
/// them together to at most `budget` (checked before each view is allocated).
pub fn decode_views(doc: &mut Document, max_bytes: u64, budget: u64) -> Result<()> {
    let mut decoded = 0u64;
    for view in 0..doc.root.buffer_views.len() {
        let Some(others) = doc.root.buffer_views[view]
            .extensions
            .as_ref()
            .map(|e| e.others.clone())
        else {
            continue;
        };
        let Some((name, ext)) = EXTENSIONS
            .iter()
            .find_map(|n| others.get(*n).map(|e| (*n, e)))
        else {
            continue;
        };
        let at = format!("bufferViews[{view}].extensions.{name}");
        let ext = ext
            .as_object()
            .ok_or_else(|| Error::invalid(&at, "is not an object"))?;
        let size = field_u64(ext, "count", &at)?.saturating_mul(field_u64(ext, "byteStride", &at)?);
        decoded = decoded.saturating_add(size);
        if decoded > budget {
            return Err(Error::invalid(
                &at,
                format!("compressed views would decode to {decoded} bytes, over the budget of {budget} for this file's data (expected counts that match the data)"),
            ));
        }
        let bytes = decode_one(doc, ext, &at, max_bytes)?;
        doc.relocate_view(view, &bytes);
        let v = &mut doc.root.buffer_views[view];
        if let Some(e) = v.extensions.as_mut() {
            e.others.remove(name);
            if e.others.is_empty() {
                v.extensions = None;
            }
        }
    }
    Ok(())
}

fn field_u64(ext: &Map<String, Value>, key: &str, at: &str) -> Result<u64> {
    ext.get(key).and_then(Value::as_u64).ok_or_else(|| {
        Error::invalid(
            format!("{at}.{key}"),
            "missing or not a non-negative integer",
        )
    })
}

fn decode_one(
    doc: &Document,
    ext: &Map<String, Value>,
    at: &str,
    max_bytes: u64,
) -> Result<Vec<u8>> {
    let buffer = field_u64(ext, "buffer", at)? as usize;
    let offset = ext.get("byteOffset").and_then(Value::as_u64).unwrap_or(0);
    let length = field_u64(ext, "byteLength", at)?;
    let stride = field_u64(ext, "byteStride", at)?;
    let count = field_u64(ext, "count", at)?;
    let mode = ext.get("mode").and_then(Value::as_str).unwrap_or("");
    let filter = ext.get("filter").and_then(Value::as_str).unwrap_or("NONE");
    let data = doc
        .buffers
        .get(buffer)
        .ok_or_else(|| {
            Error::invalid(
                format!("{at}.buffer"),
                format!("buffer {buffer} does not exist"),
            )
        })?
        .as_bytes();
    let src = offset
        .checked_add(length)
        .and_then(|end| data.get(offset as usize..end as usize))
        .ok_or_else(|| {
            Error::invalid(
                at,
                format!(
                    "bytes {offset}+{length} are not in buffer {buffer} of {} bytes",
                    data.len()
                ),
            )
        })?;
    let size = count
        .checked_mul(stride)
        .filter(|s| *s <= max_bytes)
        .ok_or_else(|| {
            Error::invalid(
                at,
                format!(
                    "count {count} × byteStride {stride} exceeds the limit of {max_bytes} bytes"
                ),
            )
        })? as usize;
    // u32 backing keeps the 16-bit filters' in-place writes aligned.
    let mut out = vec![0u32; size.div_ceil(4)];
    let dst = out.as_mut_ptr().cast::<std::ffi::c_void>();
    let (count, stride) = (count as usize, stride as usize);
    let rc = match mode {
        "ATTRIBUTES" => {
            if stride % 4 != 0 || stride == 0 || stride > 256 {
                return Err(Error::invalid(
                    format!("{at}.byteStride"),
                    format!("{stride} (expected a multiple of 4 up to 256)"),
                ));
            }
            // SAFETY: `dst` holds `count * stride` bytes; `src` is a live slice of `src.len()` bytes.
            unsafe {
                meshopt::ffi::meshopt_decodeVertexBuffer(
                    dst,
                    count,
                    stride,
                    src.as_ptr(),
                    src.len(),
                )
            }
        }
        "TRIANGLES" | "INDICES" => {
            if stride != 2 && stride != 4 {
                return Err(Error::invalid(
                    format!("{at}.byteStride"),
                    format!("{stride} (expected 2 or 4 for indices)"),
                ));
            }
            if mode == "TRIANGLES" && count % 3 != 0 {
                return Err(Error::invalid(
                    format!("{at}.count"),
                    format!("{count} (expected a multiple of 3)"),
                ));
            }
            // SAFETY: as above; the index decoders write exactly `count * stride` bytes.
            unsafe {
                if mode == "TRIANGLES" {
                    meshopt::ffi::meshopt_decodeIndexBuffer(
                        dst,
                        count,
                        stride,
                        src.as_ptr(),
                        src.len(),
                    )
                } else {
                    meshopt::ffi::meshopt_decodeIndexSequence(
                        dst,
                        count,
                        stride,
                        src.as_ptr(),
                        src.len(),
                    )
                }
            }
        }
        other => {
            return Err(Error::invalid(
                format!("{at}.mode"),
                format!("{other:?} (expected ATTRIBUTES, TRIANGLES or INDICES)"),
            ))
        }
    };
    if rc != 0 {
        return Err(Error::invalid(
            at,
            format!("compressed data does not decode (meshopt error {rc})"),
        ));
    }
    let filter_ok = match (filter, mode) {
        ("NONE", _) => true,
        (_, m) if m != "ATTRIBUTES" => false,
        ("OCTAHEDRAL" | "COLOR", _) => stride == 4 || stride == 8,
        ("QUATERNION", _) => stride == 8,
        ("EXPONENTIAL", _) => stride % 4 == 0,
        _ => false,
    };
    if !filter_ok {
        return Err(Error::invalid(
            format!("{at}.filter"),
            format!("{filter:?} with mode {mode} and byteStride {stride} (expected a filter the format defines for them)"),
        ));
    }
    // SAFETY: `dst` holds `count * stride` decoded bytes, 4-byte aligned; strides were checked above.
    unsafe {
        match filter {
            "OCTAHEDRAL" => meshopt::ffi::meshopt_decodeFilterOct(dst, count, stride),
            "QUATERNION" => meshopt::ffi::meshopt_decodeFilterQuat(dst, count, stride),
            "EXPONENTIAL" => meshopt::ffi::meshopt_decodeFilterExp(dst, count, stride),
            "COLOR" => meshopt::ffi::meshopt_decodeFilterColor(dst, count, stride),
            _ => {}
        }
    }
    let mut bytes: Vec<u8> = out.iter().flat_map(|w| w.to_ne_bytes()).collect();
    bytes.truncate(size);
    Ok(bytes)
}
