//! The GLB container: splits a `.glb` into its JSON text and BIN chunk, and assembles one.
//!
//! Every length in the header is checked against the bytes actually present before slicing. It
//! deliberately knows nothing about the JSON inside.

use super::error::{Error, Result};

const MAGIC: &[u8; 4] = b"glTF";
/// The chunk type of the JSON chunk.
pub(crate) const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// The two chunks of a GLB file.
#[derive(Debug)]
pub struct Chunks<'a> {
    /// The JSON chunk (trailing space padding included).
    pub json: &'a [u8],
    /// The BIN chunk, if any (zero padding included).
    pub bin: Option<&'a [u8]>,
}

/// Does `bytes` start like a GLB file (as opposed to JSON text)?
pub fn is_glb(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// Splits a GLB file into its chunks, checking every declared length.
pub fn split(bytes: &[u8]) -> Result<Chunks<'_>> {
    if bytes.len() < 12 {
        return Err(Error::invalid(
            "glb header",
            format!("file is {} bytes (expected a 12-byte header)", bytes.len()),
        ));
    }
    if !is_glb(bytes) {
        return Err(Error::invalid("glb header", "magic is not 'glTF'"));
    }
    let version = u32_at(bytes, 4);
    if version == 1 {
        return Err(Error::unsupported(
            "glb header",
            "this is a glTF 1.0 binary file, which is not supported (expected glTF 2.0)",
        ));
    }
    if version != 2 {
        return Err(Error::invalid(
            "glb header",
            format!("version is {version} (expected 2)"),
        ));
    }
    let length = u32_at(bytes, 8) as usize;
    if length != bytes.len() {
        return Err(Error::invalid(
            "glb header",
            format!(
                "declared length {length} differs from the file size {} (expected equal)",
                bytes.len()
            ),
        ));
    }
    let mut json = None;
    let mut bin = None;
    let mut at = 12;
    let mut index = 0;
    while at < bytes.len() {
        let name = format!("glb chunk {index}");
        if bytes.len() - at < 8 {
            return Err(Error::invalid(name, "file ends inside a chunk header"));
        }
        let len = u32_at(bytes, at) as usize;
        let kind = u32_at(bytes, at + 4);
        let start = at + 8;
        if len > bytes.len() - start {
            return Err(Error::invalid(
                name,
                format!(
                    "chunk length {len} runs past the end of the file ({} bytes left)",
                    bytes.len() - start
                ),
            ));
        }
        if len % 4 != 0 {
            return Err(Error::invalid(
                name,
                format!("chunk length {len} is not a multiple of 4"),
            ));
        }
        let data = &bytes[start..start + len];
        match (index, kind) {
            (0, CHUNK_JSON) => json = Some(data),
            (0, _) => {
                return Err(Error::invalid(
                    name,
                    "the first chunk is not JSON (expected a JSON chunk first)",
                ))
            }
            (1, CHUNK_BIN) => bin = Some(data),
            (_, CHUNK_JSON) => {
                return Err(Error::invalid(
                    name,
                    "a second JSON chunk (expected exactly one)",
                ))
            }
            (_, CHUNK_BIN) => return Err(Error::invalid(
                name,
                "a BIN chunk after the second position (expected at most one, right after JSON)",
            )),
            _ => {} // unknown chunk types must be ignored
        }
        at = start + len;
        index += 1;
    }
    let json = json.ok_or_else(|| Error::invalid("glb", "no JSON chunk"))?;
    Ok(Chunks { json, bin })
}

/// Assembles a GLB file from JSON text and BIN bytes, padding both to 4 bytes as the spec asks.
pub fn assemble(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let (head, tail) = frame(json, bin.len());
    let mut out = Vec::with_capacity(head.len() + bin.len() + tail.len());
    out.extend_from_slice(&head);
    out.extend_from_slice(bin);
    out.extend_from_slice(tail);
    out
}

/// What surrounds a binary chunk of `bin_len` bytes in a `.glb`: the header, the JSON chunk and
/// the binary chunk's header; then the binary chunk's padding. Lets a writer stream the binary
/// data from where it lies instead of copying it into one buffer first.
pub fn frame(json: &[u8], bin_len: usize) -> (Vec<u8>, &'static [u8]) {
    let pad = |n: usize| (4 - n % 4) % 4;
    let json_len = json.len() + pad(json.len());
    let bin_padded = bin_len + pad(bin_len);
    let total = 12 + 8 + json_len + if bin_len == 0 { 0 } else { 8 + bin_padded };
    let mut out = Vec::with_capacity(12 + 8 + json_len + 8);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_len as u32).to_le_bytes());
    out.extend_from_slice(&CHUNK_JSON.to_le_bytes());
    out.extend_from_slice(json);
    out.resize(out.len() + pad(json.len()), b' ');
    if bin_len == 0 {
        return (out, &[]);
    }
    out.extend_from_slice(&(bin_padded as u32).to_le_bytes());
    out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
    (out, &[0u8; 3][..pad(bin_len)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn assembled_files_split_back() {
        let glb = assemble(b"{\"a\":1}", &[1, 2, 3]);
        assert_eq!(glb.len() % 4, 0);
        let chunks = split(&glb).unwrap();
        assert_eq!(chunks.json, b"{\"a\":1} ");
        assert_eq!(chunks.bin.unwrap(), &[1, 2, 3, 0]);
    }

    #[test]
    fn truncated_header_is_an_error_not_a_panic() {
        for n in 0..12 {
            assert!(split(&b"glTF\x02\0\0\0\x0c\0\0\0"[..n]).is_err());
        }
    }
}
