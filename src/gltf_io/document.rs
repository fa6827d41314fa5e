//! Reading a `.gltf`/`.glb` into a [`Document`]: the JSON twice (as written, and as the typed
//! `gltf-json` model), every buffer's bytes, and meshopt-compressed views decoded.
//!
//! It deliberately does not refuse unknown required extensions (they are carried through
//! verbatim); it refuses only what it cannot read correctly, and everything the spec calls an
//! error (see [`super::validate`]).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use gltf_json::validation::{USize64, Validate};
use serde_json::Value;

use super::buffer_data::{BufferData, Piece};
use super::error::{Error, Result};
use super::{glb, meshopt_decode, uri, validate};

/// Bounds and permissions for reading untrusted assets.
///
/// Every bound is checked before the memory it protects is allocated, so a file that lies about
/// its sizes costs no more than its own bytes.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct ReadOptions {
    /// Allow `uri`s that leave the asset's folder (`..`, absolute paths, `file:`, symbolic links
    /// that point out of it). Default: `false`. Network schemes are refused regardless.
    pub allow_outside_uris: bool,
    /// Largest file, buffer, or decoded accessor the reader accepts, in bytes.
    /// Default: [`ReadOptions::DEFAULT_MAX_BYTES`] (2 GiB).
    pub max_bytes: u64,
    /// Largest JSON text (the `.gltf` file or the GLB's JSON chunk), in bytes.
    /// Default: [`ReadOptions::DEFAULT_MAX_JSON_BYTES`] (64 MiB).
    pub max_json_bytes: u64,
    /// Deepest nesting of JSON arrays and objects. Default: [`ReadOptions::DEFAULT_MAX_JSON_DEPTH`].
    pub max_json_depth: usize,
    /// Largest decoded `data:` URI, in bytes. Default: [`ReadOptions::DEFAULT_MAX_DATA_URI_BYTES`]
    /// (32 MiB).
    pub max_data_uri_bytes: u64,
}

impl ReadOptions {
    /// Default for [`ReadOptions::max_bytes`]: large enough for any game asset, small enough
    /// that a lying header cannot make the reader allocate the machine's memory.
    pub const DEFAULT_MAX_BYTES: u64 = 2 << 30;
    /// Default for [`ReadOptions::max_json_bytes`]. Parsed JSON takes several times its text in
    /// memory (a number of two characters becomes a 32-byte value, and the reader keeps the
    /// text's tree and its typed model); real assets have JSON of a few MiB at most, and larger
    /// buffers belong in a `.bin` or a `.glb`.
    pub const DEFAULT_MAX_JSON_BYTES: u64 = 64 << 20;
    /// Default for [`ReadOptions::max_json_depth`]: glTF itself nests 6 levels deep; the rest is
    /// room for `extras` and extensions, and parsing stays far from the stack's end.
    pub const DEFAULT_MAX_JSON_DEPTH: usize = 64;
    /// Default for [`ReadOptions::max_data_uri_bytes`]: `data:` URIs cost a third more than
    /// binary data and are meant for small buffers and images.
    pub const DEFAULT_MAX_DATA_URI_BYTES: u64 = 32 << 20;
    /// Data decoded from a file (meshopt views, accessors) may be at most this many times the
    /// binary data the file actually holds, plus [`ReadOptions::EXPANSION_SLACK`]: counts and
    /// strides are declared in the JSON, and without a bound relative to the real data a file of
    /// a few bytes could ask for gigabytes (zero-filled accessors, accessors sharing one view,
    /// meshopt views that compress zeros).
    pub const EXPANSION_FACTOR: u64 = 16;
    /// See [`ReadOptions::EXPANSION_FACTOR`].
    pub const EXPANSION_SLACK: u64 = 64 << 20;

    /// The most bytes decoding may produce from `binary` bytes of real data.
    pub fn expansion_budget(&self, binary: u64) -> u64 {
        binary
            .saturating_mul(Self::EXPANSION_FACTOR)
            .saturating_add(Self::EXPANSION_SLACK)
            .min(self.max_bytes.max(Self::EXPANSION_SLACK))
    }
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self {
            allow_outside_uris: false,
            max_bytes: Self::DEFAULT_MAX_BYTES,
            max_json_bytes: Self::DEFAULT_MAX_JSON_BYTES,
            max_json_depth: Self::DEFAULT_MAX_JSON_DEPTH,
            max_data_uri_bytes: Self::DEFAULT_MAX_DATA_URI_BYTES,
        }
    }
}

/// A glTF asset in memory: everything needed to read its meshes and to write it back unchanged.
#[derive(Debug, Clone)]
pub struct Document {
    /// The typed JSON model. Accessors, buffer views and buffers here are authoritative;
    /// primitives are changed only through [`super::replace_primitive`].
    pub root: gltf_json::Root,
    /// The JSON exactly as read, for everything the typed model does not keep.
    pub(crate) raw: Value,
    /// `root` serialized right after reading: what "unchanged" looks like in typed form.
    pub(crate) base: Value,
    /// The bytes of each entry of `root.buffers` (a meshopt fallback buffer holds none), shared
    /// with the output being written (see [`super::buffer_data`]).
    pub(crate) buffers: Vec<Arc<BufferData>>,
    /// Primitives replaced since reading, as JSON (key: mesh, primitive).
    pub(crate) replaced: std::collections::BTreeMap<(usize, usize), Value>,
    /// The accessors the replaced primitives referenced when read.
    pub(crate) replaced_accessors: std::collections::BTreeSet<usize>,
    /// The folder relative `uri`s resolve against.
    pub base_dir: Option<PathBuf>,
    /// Whether the input was a `.glb`.
    pub is_glb: bool,
    /// Whether the reader may follow `uri`s out of `base_dir` (kept for embedding images).
    pub(crate) allow_outside_uris: bool,
    /// Meshes whose positions [`mod@super::quantize`] stored as integers, with the transform that
    /// maps them back; the writer puts it on a child node of every node using the mesh.
    pub(crate) dequantize: std::collections::BTreeMap<usize, super::quantize::Dequantize>,
    /// Buffer views whose bytes are the decoded form of a meshopt filter, with the filter's
    /// encoded bytes, so the compressor does not have to re-derive them (and lose precision).
    pub(crate) filtered: std::collections::BTreeMap<usize, super::quantize::Filtered>,
}

/// Reads the asset at `path` (`.gltf` or `.glb`, told apart by content).
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Document> {
    let shown = path.display().to_string();
    let len = std::fs::metadata(path)
        .map_err(|e| Error::io(&shown, e))?
        .len();
    if len > opts.max_bytes {
        return Err(Error::invalid(
            shown,
            format!("file is {len} bytes (expected at most {})", opts.max_bytes),
        ));
    }
    // Read once, and kept: a GLB's BIN chunk becomes the first buffer where it lies.
    let bytes = Arc::new(super::read_file::read_whole(path).map_err(|e| Error::io(&shown, e))?);
    let named_glb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if named_glb && !bytes.starts_with(b"{") {
        glb::split(&bytes)?; // a .glb that is not JSON either: report its header
    }
    let dir = path.parent().map(|p| {
        if p.as_os_str().is_empty() {
            Path::new(".")
        } else {
            p
        }
    });
    parse(&bytes, Some(&bytes), dir, opts)
}

/// Reads an asset from memory; relative `uri`s resolve against `base_dir` (none: only `data:`).
pub fn read_bytes(bytes: &[u8], base_dir: Option<&Path>, opts: &ReadOptions) -> Result<Document> {
    parse(bytes, None, base_dir, opts)
}

/// Reads an asset from `bytes`; with `file` (the same bytes, shared), a GLB's BIN chunk is
/// kept in it instead of copied.
fn parse(
    bytes: &[u8],
    file: Option<&Arc<Vec<u8>>>,
    base_dir: Option<&Path>,
    opts: &ReadOptions,
) -> Result<Document> {
    let is_glb = glb::is_glb(bytes);
    let (json, bin) = if is_glb {
        let chunks = glb::split(bytes)?;
        (chunks.json, chunks.bin)
    } else {
        (bytes, None)
    };
    check_json_size(json, opts)?;
    if json.starts_with(&[0xEF, 0xBB, 0xBF]) {
        return Err(Error::invalid(
            "json",
            "starts with a utf-8 byte order mark, which glTF forbids (expected '{')",
        ));
    }
    let raw: Value = serde_json::from_slice(json)
        .map_err(|e| Error::invalid("json", e.to_string().to_lowercase()))?;
    check_version(&raw)?;
    let root: gltf_json::Root = serde_json::from_value(typed_shim(&raw))
        .map_err(|e| Error::invalid("json", e.to_string().to_lowercase()))?;
    validate::primitive_references(&root)?;
    check_typed(&root)?;
    validate::structure(&root, &raw)?;

    let bin = bin.map(|chunk| match file {
        Some(file) => {
            let start = chunk.as_ptr() as usize - file.as_ptr() as usize;
            BufferData::FileRange {
                file: Arc::clone(file),
                range: start..start + chunk.len(),
            }
        }
        None => BufferData::Bytes(chunk.to_vec()),
    });
    let buffers = load_buffers(&root, bin, base_dir, opts)?;
    {
        let views: Vec<&[u8]> = buffers.iter().map(BufferData::as_bytes).collect();
        validate::buffer_views(&root, &views)?;
    }
    let mut doc = Document {
        base: Value::Null,
        root,
        raw,
        buffers: buffers.into_iter().map(Arc::new).collect(),
        replaced: Default::default(),
        replaced_accessors: Default::default(),
        base_dir: base_dir.map(Path::to_path_buf),
        is_glb,
        allow_outside_uris: opts.allow_outside_uris,
        dequantize: Default::default(),
        filtered: Default::default(),
    };
    let binary = doc.buffer_bytes();
    let budget = opts.expansion_budget(binary);
    meshopt_decode::decode_views(&mut doc, opts.max_bytes, budget)?;
    validate::data(&doc, opts.max_bytes, budget)?;
    doc.base = serde_json::to_value(&doc.root).map_err(|e| Error::invalid("json", e))?;
    Ok(doc)
}

/// Refuses JSON text that is too large or nested too deeply, before parsing it (the parser's
/// own recursion limit would give a message without the bound).
fn check_json_size(json: &[u8], opts: &ReadOptions) -> Result<()> {
    if json.len() as u64 > opts.max_json_bytes {
        return Err(Error::invalid(
            "json",
            format!(
                "is {} bytes (expected at most {}; store large buffers in a .bin or a .glb)",
                json.len(),
                opts.max_json_bytes
            ),
        ));
    }
    let (mut depth, mut in_string, mut escaped) = (0usize, false, false);
    for (at, &b) in json.iter().enumerate() {
        if in_string {
            match b {
                _ if escaped => escaped = false,
                b'\\' => escaped = true,
                b'"' => in_string = false,
                _ => {}
            }
            continue;
        }
        match b {
            b'"' => in_string = true,
            b'[' | b'{' => {
                depth += 1;
                if depth > opts.max_json_depth {
                    return Err(Error::invalid(
                        "json",
                        format!(
                            "arrays and objects nest deeper than {} levels at byte {at} (expected at most {})",
                            opts.max_json_depth, opts.max_json_depth
                        ),
                    ));
                }
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    Ok(())
}

/// A copy of `raw` with the properties `gltf-json` requires but the spec leaves optional filled
/// in (`scenes[].nodes`), so that valid files parse. The merge on write drops them again.
fn typed_shim(raw: &Value) -> Value {
    let mut v = raw.clone();
    for scene in v
        .get_mut("scenes")
        .and_then(Value::as_array_mut)
        .into_iter()
        .flatten()
    {
        if let Some(obj) = scene.as_object_mut() {
            obj.entry("nodes").or_insert_with(|| Value::Array(vec![]));
        }
    }
    v
}

/// Refuses anything but glTF 2.x, with a message that names glTF 1.0 when it is that.
fn check_version(raw: &Value) -> Result<()> {
    let Some(obj) = raw.as_object() else {
        return Err(Error::invalid(
            "json",
            "the top level is not an object (expected a glTF object)",
        ));
    };
    let version = obj
        .get("asset")
        .ok_or_else(|| {
            Error::invalid(
                "asset",
                "missing (expected an asset object with version \"2.0\")",
            )
        })?
        .get("version")
        .and_then(Value::as_str)
        .ok_or_else(|| Error::invalid("asset.version", "missing (expected \"2.0\")"))?;
    match version.split('.').next() {
        Some("2") => Ok(()),
        Some("1") => Err(Error::unsupported(
            "asset.version",
            format!("glTF {version} is not supported (expected 2.0)"),
        )),
        _ => Err(Error::invalid(
            "asset.version",
            format!("{version:?} is not a glTF version (expected \"2.0\")"),
        )),
    }
}

/// Runs `gltf-json`'s own checks (unresolved references, bad enum values, missing fields), except
/// its refusal of required extensions it does not know: those are carried through.
fn check_typed(root: &gltf_json::Root) -> Result<()> {
    let mut first = None;
    root.validate(
        root,
        gltf_json::Path::new,
        &mut |path: &dyn Fn() -> gltf_json::Path, err| {
            use gltf_json::validation::Error as E;
            if first.is_some() || err == E::Unsupported {
                return;
            }
            // The spec lets accessors omit bufferView (they read as zeros); gltf-json does not.
            let p = path();
            // Likewise texture.source, which extensions such as KHR_texture_basisu replace.
            let optional = [("accessors[", "].bufferView"), ("textures[", "].source")];
            if err == E::Missing
                && optional
                    .iter()
                    .any(|(a, b)| p.as_str().starts_with(a) && p.as_str().ends_with(b))
            {
                return;
            }
            let what = match err {
                E::IndexOutOfBounds => {
                    "refers to an object that does not exist (expected an index in range)"
                }
                E::Invalid => "has a value the glTF specification does not allow",
                E::Missing => "is missing (expected it by the glTF specification)",
                E::Oversize => "is larger than this system can address",
                E::Unsupported => unreachable!(),
            };
            first = Some(Error::invalid(path().as_str(), what));
        },
    );
    match first {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Loads every buffer: the GLB BIN chunk, `data:` URIs and files, checking declared lengths.
fn load_buffers(
    root: &gltf_json::Root,
    mut bin: Option<BufferData>,
    base_dir: Option<&Path>,
    opts: &ReadOptions,
) -> Result<Vec<BufferData>> {
    let has_bin = bin.is_some();
    let mut out = Vec::with_capacity(root.buffers.len());
    for (i, buffer) in root.buffers.iter().enumerate() {
        let at = format!("buffers[{i}]");
        let declared = buffer.byte_length.0;
        if declared > opts.max_bytes {
            return Err(Error::invalid(
                &at,
                format!(
                    "byteLength {declared} exceeds the limit of {} bytes",
                    opts.max_bytes
                ),
            ));
        }
        let data = match (&buffer.uri, has_bin) {
            (Some(u), _) => {
                let data = uri::load(u, &format!("{at}.uri"), base_dir, &uri::Limits::from(opts))?;
                if u.starts_with("data:") && data.len() as u64 != declared {
                    return Err(Error::invalid(
                        format!("{at}.byteLength"),
                        format!(
                            "is {declared} but the data: uri holds {} bytes (expected equal)",
                            data.len()
                        ),
                    ));
                }
                BufferData::Bytes(data)
            }
            (None, true) if i == 0 => bin.take().expect("the BIN chunk, once"),
            (None, _)
                if meshopt_decode::is_fallback(buffer)
                    || meshopt_decode::only_compressed_views(root, i) =>
            {
                BufferData::default()
            }
            (None, _) => {
                return Err(Error::invalid(
                    format!("{at}.uri"),
                    "missing, and the buffer is not the glb's BIN chunk (expected a uri)",
                ))
            }
        };
        let placeholder = buffer.uri.is_none() && (i != 0 || !has_bin);
        if !placeholder && (data.len() as u64) < declared {
            return Err(Error::invalid(
                format!("{at}.byteLength"),
                format!("is {declared} but only {} bytes are present (expected at most the data's length)", data.len()),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// The name of the in-memory buffers that each hold one array the pipeline made (see
/// [`Document::push_array_view`]).
pub(crate) const ARRAY_BUFFER_NAME: &str = "g2tess array";

impl Document {
    /// The bytes of buffer view `view`, bounds already checked at read time.
    pub(crate) fn view_bytes(&self, view: usize) -> Result<&[u8]> {
        let (data, range) = self.view_range(view)?;
        Ok(&data.as_bytes()[range])
    }

    /// Buffer view `view` as a piece of an output file, sharing the document's memory.
    pub(crate) fn view_piece(&self, view: usize) -> Result<Piece> {
        let (data, range) = self.view_range(view)?;
        Ok(Piece::Shared {
            data: Arc::clone(data),
            range,
        })
    }

    fn view_range(&self, view: usize) -> Result<(&Arc<BufferData>, std::ops::Range<usize>)> {
        let v = self
            .root
            .buffer_views
            .get(view)
            .ok_or_else(|| Error::invalid(format!("bufferViews[{view}]"), "does not exist"))?;
        let data = &self.buffers[v.buffer.value()];
        let start = v.byte_offset.map_or(0, |o| o.0) as usize;
        let end = start + v.byte_length.0 as usize;
        if end > data.len() {
            return Err(Error::invalid(
                format!("bufferViews[{view}]"),
                format!(
                    "bytes {start}..{end} are not in its buffer of {} bytes",
                    data.len()
                ),
            ));
        }
        Ok((data, start..end))
    }

    /// Frees the bytes of every buffer read with the document (the input's buffers, and the
    /// scratch buffer holding its decoded meshopt views), keeping the arrays the pipeline
    /// stored since. For a streamed output once the primitives are decoded: the input's bytes
    /// the output keeps are on disk by then and the rest are the replaced primitives', so
    /// holding them to the end (a large scan's whole file) only raises the peak. A view of a
    /// freed buffer reads as out of range afterwards (an error, never stale bytes); new views
    /// are appended to the emptied scratch buffer from its start.
    pub(crate) fn release_read_buffers(&mut self) {
        for (data, buffer) in self.buffers.iter_mut().zip(&self.root.buffers) {
            if buffer.name.as_deref() != Some(ARRAY_BUFFER_NAME) {
                *data = Arc::default();
            }
        }
    }

    /// Bytes held in all buffers.
    pub(crate) fn buffer_bytes(&self) -> u64 {
        self.buffers.iter().map(|b| b.len() as u64).sum()
    }

    /// Stores `data` (a whole array the pipeline made) as a buffer of its own, uncopied, and a
    /// buffer view over all of it; returns the view's index. The writer packs every view into
    /// one output buffer, so the number of in-memory buffers never shows in the output.
    pub(crate) fn push_array_view(
        &mut self,
        data: BufferData,
        stride: Option<usize>,
        target: Option<gltf_json::buffer::Target>,
    ) -> usize {
        let len = data.len();
        self.root.buffers.push(gltf_json::Buffer {
            byte_length: USize64(len as u64),
            name: Some(ARRAY_BUFFER_NAME.into()),
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        self.buffers.push(Arc::new(data));
        self.push_view_entry(self.buffers.len() - 1, 0, len, stride, target)
    }

    /// Appends a buffer view entry over `len` bytes of buffer `buffer` from `offset`; returns
    /// its index.
    fn push_view_entry(
        &mut self,
        buffer: usize,
        offset: usize,
        len: usize,
        stride: Option<usize>,
        target: Option<gltf_json::buffer::Target>,
    ) -> usize {
        self.root.buffer_views.push(gltf_json::buffer::View {
            buffer: gltf_json::Index::new(buffer as u32),
            byte_length: USize64(len as u64),
            byte_offset: Some(USize64(offset as u64)),
            byte_stride: stride.map(gltf_json::buffer::Stride),
            name: None,
            target: target.map(gltf_json::validation::Checked::Valid),
            extensions: None,
            extras: Default::default(),
        });
        self.root.buffer_views.len() - 1
    }

    /// Appends `bytes` as a new buffer view in the document's scratch buffer; returns its index.
    pub(crate) fn push_view(
        &mut self,
        bytes: &[u8],
        stride: Option<usize>,
        target: Option<gltf_json::buffer::Target>,
    ) -> usize {
        let (scratch, offset) = self.append_to_scratch(bytes);
        self.push_view_entry(scratch, offset, bytes.len(), stride, target)
    }

    /// Appends `bytes` to the scratch buffer at the next 4-byte boundary; returns the scratch
    /// buffer's index and where the bytes start.
    fn append_to_scratch(&mut self, bytes: &[u8]) -> (usize, usize) {
        let scratch = self.scratch_buffer();
        let data = Arc::make_mut(&mut self.buffers[scratch]).bytes_mut();
        while data.len() % 4 != 0 {
            data.push(0);
        }
        let offset = data.len();
        data.extend_from_slice(bytes);
        self.root.buffers[scratch].byte_length = USize64(data.len() as u64);
        (scratch, offset)
    }

    /// The in-memory buffer that new views go into, created on first use.
    fn scratch_buffer(&mut self) -> usize {
        const NAME: &str = "g2tess scratch";
        if let Some(i) = self
            .root
            .buffers
            .iter()
            .position(|b| b.name.as_deref() == Some(NAME) && b.uri.is_none())
        {
            return i;
        }
        self.root.buffers.push(gltf_json::Buffer {
            byte_length: USize64(0),
            name: Some(NAME.into()),
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        self.buffers.push(Arc::default());
        self.buffers.len() - 1
    }

    /// Points buffer view `view` at `bytes` (decoded meshopt data) in the scratch buffer.
    pub(crate) fn relocate_view(&mut self, view: usize, bytes: &[u8]) {
        let (scratch, offset) = self.append_to_scratch(bytes);
        let v = &mut self.root.buffer_views[view];
        v.buffer = gltf_json::Index::new(scratch as u32);
        v.byte_offset = Some(USize64(offset as u64));
        v.byte_length = USize64(bytes.len() as u64);
    }
}
