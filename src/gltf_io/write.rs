//! Writing a [`Document`]: `.glb`, or `.gltf` with a `.bin` beside it, chosen by the output's
//! extension; buffers repacked into one 4-byte-aligned buffer; accessors and views orphaned by
//! replaced primitives dropped; everything else carried verbatim.
//!
//! Files are written to a temporary file beside the target and renamed into place, so an
//! interrupted run never leaves a half-written output. It deliberately never overwrites the
//! input (or a file the input refers to) unless asked to.

use std::collections::{BTreeMap, BTreeSet};
use std::io::Write as _;
use std::path::{Path, PathBuf};

use serde_json::{json, Map, Value};

use super::buffer_data::Pieces;
use super::compare::Comparison;
use super::document::Document;
use super::error::{Error, Result};
use super::files::{bin_path, fallback_path};
use super::meshopt_encode::{self, Compression};
use super::{dequantize_nodes, draco_decode, glb, json_merge, meshopt_decode, uri};

/// How to write.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct WriteOptions {
    /// Allow the output to replace the input file or one of its companion files.
    /// Default: `false`.
    pub overwrite_input: bool,
    /// The file the document was read from, to refuse overwriting it. Default: none.
    pub input: Option<PathBuf>,
    /// Compress buffer views with EXT_meshopt_compression. Default: none (uncompressed).
    pub compression: Option<Compression>,
}

impl WriteOptions {
    /// Options that refuse to overwrite `input` unless `overwrite_input` is set.
    pub fn new(input: Option<PathBuf>, overwrite_input: bool) -> Self {
        Self {
            input,
            overwrite_input,
            compression: None,
        }
    }

    /// These options with `compression` (none: uncompressed).
    pub fn with_compression(mut self, compression: Option<Compression>) -> Self {
        self.compression = compression;
        self
    }
}

/// One file of an output: its path and its bytes, held as the pieces they are made of (most of
/// them shared with the document's buffers, so encoding a dense mesh copies none of its arrays).
#[derive(Debug, Clone)]
pub struct OutputFile {
    /// Where it goes.
    pub path: PathBuf,
    bytes: Pieces,
}

impl OutputFile {
    fn new(path: PathBuf, bytes: Pieces) -> Self {
        OutputFile { path, bytes }
    }

    /// Its length in bytes.
    pub fn len(&self) -> u64 {
        self.bytes.len() as u64
    }

    /// Whether it has no bytes.
    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// Its bytes in one vector.
    pub fn to_bytes(&self) -> Vec<u8> {
        self.bytes.concat()
    }

    /// Whether the file at its path holds exactly its bytes, read in chunks beside them (never
    /// whole) and only up to the first difference.
    pub fn matches_disk(&self) -> bool {
        let mut on_disk = Comparison::open(&self.path);
        for piece in self.bytes.iter() {
            on_disk.feed(piece);
        }
        on_disk.finish()
    }

    /// Writes it to a temporary file beside its path, then renames it into place.
    pub fn write_atomically(&self) -> Result<()> {
        write_pieces_atomically(&self.path, self.bytes.iter())
    }
}

/// Writes every file of one output as a set: each to a temporary file beside its path first,
/// and only when all of them are on disk, renames them into place in order (a file before the
/// file that refers to it). On an error while writing (a full disk), the temporary files are
/// removed and the previous files are all kept, so that a `.gltf` never ends up beside a `.bin`
/// of another run.
///
/// The renames themselves are not one step: should one fail (it replaces a name in the same
/// folder, so only a concurrent change of the folder could make it), the files renamed before
/// it are already new.
pub fn write_files_atomically(files: &[OutputFile]) -> Result<()> {
    let staged = files
        .iter()
        .map(|f| stage(&f.path, f.bytes.iter()))
        .collect::<Result<Vec<_>>>()?;
    for (tmp, file) in staged.into_iter().zip(files) {
        persist(tmp, &file.path)?;
    }
    Ok(())
}

/// The files of one output, in the order they are to be written (a file before the file that
/// refers to it).
pub type Files = Vec<OutputFile>;

/// Writes `doc` to `path` (`.glb`, or `.gltf` + `<stem>.bin`).
pub fn write(doc: &Document, path: &Path, opts: &WriteOptions) -> Result<()> {
    write_files_atomically(&encode(doc, path, opts)?)
}

/// The files [`write()`] would create for `path`, with their bytes, in the order it writes them
/// (a `.gltf`'s `.bin` before the `.gltf` that refers to it), without touching the disk.
///
/// It exists so that a caller can compare a fresh result with what is on disk (`--check`).
pub fn encode(doc: &Document, path: &Path, opts: &WriteOptions) -> Result<Files> {
    let shown = path.display().to_string();
    let as_glb = is_glb_name(path)?;
    let bin_path = (!as_glb).then(|| bin_path(path));
    let fallback = opts
        .compression
        .filter(|c| c.fallback)
        .map(|_| fallback_path(path));
    refuse_overwriting_input(doc, path, bin_path.as_deref(), opts)?;
    if let Some(f) = &fallback {
        refuse_overwriting_input(doc, f, None, opts)?;
    }
    let out_dir = parent_dir(path);
    let embed_images = !same_dir(doc.base_dir.as_deref(), out_dir);
    let (json, bin, fallback_bytes) = assemble(
        doc,
        embed_images,
        bin_path.as_deref(),
        opts.compression,
        fallback.as_deref(),
        None,
    )?;
    let mut files = Vec::with_capacity(3);
    if let (Some(f), Some(bytes)) = (fallback, fallback_bytes) {
        files.push(OutputFile::new(f, bytes.into()));
    }
    if as_glb {
        let text = serde_json::to_vec(&json).map_err(|e| Error::invalid(&shown, e))?;
        let (head, tail) = glb::frame(&text, bin.len());
        let mut glb = Pieces::from(head);
        glb.extend(bin);
        glb.push_bytes(tail.to_vec());
        files.push(OutputFile::new(path.to_path_buf(), glb));
    } else {
        let mut text = serde_json::to_vec_pretty(&json).map_err(|e| Error::invalid(&shown, e))?;
        text.push(b'\n');
        if let Some(bin_path) = bin_path.filter(|_| !bin.is_empty()) {
            files.push(OutputFile::new(bin_path, bin));
        }
        files.push(OutputFile::new(path.to_path_buf(), text.into()));
    }
    Ok(files)
}

/// The `.glb` bytes of `doc`, without touching any file: for callers that keep the result in
/// memory (and for fuzzing the whole per-file job). Images stored as separate files stay
/// referenced by their `uri`.
pub fn to_glb_bytes(doc: &Document, compression: Option<Compression>) -> Result<Vec<u8>> {
    if compression.is_some_and(|c| c.fallback) {
        return Err(Error::invalid(
            "output",
            "a compressed output with a fallback buffer needs a file beside it (expected a path)",
        ));
    }
    let (json, bin, _) = assemble(doc, false, None, compression, None, None)?;
    let text = serde_json::to_vec(&json).map_err(|e| Error::invalid("json", e))?;
    Ok(glb::assemble(&text, &bin.concat()))
}

/// Whether `path` names a `.glb` (`false`: a `.gltf`); any other name is an error.
pub(crate) fn is_glb_name(path: &Path) -> Result<bool> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("glb") => Ok(true),
        Some("gltf") => Ok(false),
        _ => Err(Error::invalid(
            "output name",
            "has no .glb or .gltf extension (expected one of them)",
        )),
    }
}

pub(crate) fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

pub(crate) fn same_dir(a: Option<&Path>, b: &Path) -> bool {
    let canon = |p: &Path| std::fs::canonicalize(p).ok();
    a.is_some_and(|a| canon(a).is_some() && canon(a) == canon(b))
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Refuses to replace the input, or a buffer or image file it refers to, unless forced.
pub(crate) fn refuse_overwriting_input(
    doc: &Document,
    path: &Path,
    bin: Option<&Path>,
    opts: &WriteOptions,
) -> Result<()> {
    if opts.overwrite_input {
        return Ok(());
    }
    let mut inputs: Vec<PathBuf> = opts.input.iter().cloned().collect();
    let uris = ["buffers", "images"]
        .iter()
        .flat_map(|k| {
            doc.raw
                .get(*k)
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
        })
        .filter_map(|o| o.get("uri").and_then(Value::as_str));
    for u in uris {
        if let Ok(uri::Target::File(f)) = uri::resolve(u, "uri", doc.base_dir.as_deref(), true) {
            inputs.push(f);
        }
    }
    for out in std::iter::once(path).chain(bin) {
        if let Some(input) = inputs.iter().find(|i| same_file(i, out)) {
            return Err(Error::invalid(
                out.display(),
                format!(
                    "would overwrite the input {} (pass --overwrite-input to allow it)",
                    input.display()
                ),
            ));
        }
    }
    Ok(())
}

/// Writes `bytes` to a temporary file in `path`'s folder, then renames it over `path`.
pub fn atomic_write(path: &Path, bytes: &[u8]) -> Result<()> {
    write_pieces_atomically(path, std::iter::once(bytes))
}

/// Writes the concatenation of `pieces` to a temporary file in `path`'s folder, flushes it to
/// disk, then renames it over `path`: a reader sees the old file or the whole new one.
fn write_pieces_atomically<'a>(path: &Path, pieces: impl Iterator<Item = &'a [u8]>) -> Result<()> {
    let tmp = stage(path, pieces)?;
    persist(tmp, path)
}

/// Renames the finished temporary file `tmp` over `path`.
///
/// The file it replaces (a previous run's output) is held across the rename and let go on a
/// pool thread. Freeing a large file's blocks is slow (45–58 ms for a 112 MB output on an ext4
/// disk that discards freed blocks, measured in 5 renames): held, the rename only swaps the
/// names, and the freeing runs beside whatever the process does next instead of inside the
/// write.
pub(crate) fn persist(tmp: tempfile::NamedTempFile, path: &Path) -> Result<()> {
    let replaced = hold_replaced(path);
    tmp.persist(path)
        .map_err(|e| Error::io(path.display(), e.error))?;
    if let Some(old) = replaced {
        rayon::spawn(move || drop(old));
    }
    Ok(())
}

/// A handle on the file at `path`, if there is one, that keeps it from being freed when a
/// rename replaces it. Opened with `O_PATH`: it needs no permission to read the file, never
/// blocks (a FIFO at the output's name would block an open for reading), and with
/// `O_NOFOLLOW` holds a symbolic link itself, which is what the rename replaces.
#[cfg(target_os = "linux")]
fn hold_replaced(path: &Path) -> Option<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt as _;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_PATH | libc::O_NOFOLLOW)
        .open(path)
        .ok()
}

#[cfg(not(target_os = "linux"))]
fn hold_replaced(_path: &Path) -> Option<std::fs::File> {
    None
}

/// Writes `bytes` to a new temporary file in `path`'s folder and flushes it to disk; dropping
/// the result removes it.
pub(crate) fn stage_bytes(path: &Path, bytes: &[u8]) -> Result<tempfile::NamedTempFile> {
    stage(path, std::iter::once(bytes))
}

/// Writes the concatenation of `pieces` to a new temporary file in `path`'s folder and flushes
/// it to disk; dropping the result removes it.
fn stage<'a>(
    path: &Path,
    pieces: impl Iterator<Item = &'a [u8]>,
) -> Result<tempfile::NamedTempFile> {
    let mut staging = Staging::new(path)?;
    for piece in pieces {
        staging.write(piece)?;
    }
    staging.finish()
}

/// A new temporary file in a target's folder, written front to back: the target's contents
/// before they are renamed into place, or bytes kept aside until they are (the binary chunk of
/// a `.glb` whose JSON chunk, which comes first, is not known yet). Dropped unfinished, the
/// file is removed.
pub(crate) struct Staging {
    out: std::io::BufWriter<tempfile::NamedTempFile>,
    shown: String,
    written: u64,
    handed: u64,
    /// Whether written bytes are handed to the disk as they come (not for bytes set aside,
    /// which are copied and removed before they would ever need to be on disk).
    writeback: bool,
}

impl Staging {
    /// Creates the temporary file beside `path` for bytes set aside, to be copied into another
    /// file and removed: nothing is asked of the disk for them.
    pub fn aside(path: &Path) -> Result<Staging> {
        let mut staging = Staging::new(path)?;
        staging.writeback = false;
        Ok(staging)
    }

    /// Creates the temporary file beside `path`.
    pub fn new(path: &Path) -> Result<Staging> {
        let shown = path.display().to_string();
        let mut builder = tempfile::Builder::new();
        builder.prefix(".g2tess-").suffix(".tmp");
        // Temporary files are private (0600); the finished output gets the usual permissions.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt as _;
            builder.permissions(std::fs::Permissions::from_mode(0o644));
        }
        let tmp = builder
            .tempfile_in(parent_dir(path))
            .map_err(|e| Error::io(&shown, e))?;
        Ok(Staging {
            // Small pieces (headers, padding) are gathered; large ones go to the file directly.
            out: std::io::BufWriter::with_capacity(1 << 16, tmp),
            shown,
            written: 0,
            handed: 0,
            writeback: true,
        })
    }

    /// Appends `bytes`, in steps, each handed to the disk as soon as it is written.
    pub fn write(&mut self, bytes: &[u8]) -> Result<()> {
        for step in bytes.chunks(WRITEBACK_STEP) {
            self.out
                .write_all(step)
                .map_err(|e| Error::io(&self.shown, e))?;
            self.written += step.len() as u64;
            self.hand_over(false)?;
        }
        Ok(())
    }

    /// Appends the first `len` bytes of the finished staging file `from`, copied by the kernel
    /// (no pass through this process's memory), in steps: each step's blocks are freed from
    /// `from` once copied, so the bytes are on disk twice by one step at most, not whole.
    pub fn copy_from(&mut self, from: tempfile::NamedTempFile, len: u64) -> Result<()> {
        use std::io::{Read as _, Seek as _};
        let shown = self.shown.clone();
        let err = |e| Error::io(&shown, e);
        self.out.flush().map_err(err)?;
        let mut src = from.reopen().map_err(err)?;
        src.rewind().map_err(err)?;
        let mut done = 0u64;
        while done < len {
            let step = (len - done).min(WRITEBACK_STEP as u64);
            let copied =
                std::io::copy(&mut (&mut src).take(step), self.out.get_mut().as_file_mut())
                    .map_err(err)?;
            if copied != step {
                return Err(Error::io(
                    &self.shown,
                    std::io::Error::new(
                        std::io::ErrorKind::UnexpectedEof,
                        format!(
                            "its staged data ended after {} of {len} bytes",
                            done + copied
                        ),
                    ),
                ));
            }
            release(from.as_file(), done, step);
            done += step;
            self.written += step;
            self.hand_over(false)?;
        }
        self.hand_over(true)
    }

    /// Starts writing back what was written since the last time, once that is a whole step
    /// (or whatever there is, when `now`).
    fn hand_over(&mut self, now: bool) -> Result<()> {
        let pending = self.written - self.handed;
        if !self.writeback {
            return Ok(());
        }
        if pending >= WRITEBACK_STEP as u64 || (now && pending > 0) {
            self.out.flush().map_err(|e| Error::io(&self.shown, e))?;
            start_writeback(self.out.get_ref().as_file(), self.handed, pending);
            self.handed = self.written;
        }
        Ok(())
    }

    /// Flushes the file to disk and returns it, still temporary.
    pub fn finish(self) -> Result<tempfile::NamedTempFile> {
        let shown = self.shown.clone();
        let tmp = self.written_out()?;
        tmp.as_file().sync_all().map_err(|e| Error::io(&shown, e))?;
        Ok(tmp)
    }

    /// The file with everything written handed to the kernel, not waited for: for bytes that
    /// are copied elsewhere and then removed.
    pub fn written_out(self) -> Result<tempfile::NamedTempFile> {
        let shown = self.shown;
        self.out
            .into_inner()
            .map_err(|e| Error::io(&shown, e.into_error()))
    }
}

/// Bytes written between two requests to start writing back to disk.
const WRITEBACK_STEP: usize = 16 << 20;

/// Asks the kernel to start writing `len` bytes at `offset` of `file` to disk now, without
/// waiting. The final flush then waits only for what is left: on a 173 MiB output the disk
/// works while the rest is still being copied, instead of after it. Advice only: an error
/// (a file system without it) changes nothing but the timing.
#[cfg(target_os = "linux")]
fn start_writeback(file: &std::fs::File, offset: u64, len: u64) {
    use std::os::fd::AsRawFd as _;
    let (Ok(offset), Ok(len)) = (i64::try_from(offset), i64::try_from(len)) else {
        return;
    };
    // SAFETY: the descriptor belongs to `file`, open for the duration of the call; the call
    // reads no memory of ours.
    unsafe {
        libc::sync_file_range(file.as_raw_fd(), offset, len, libc::SYNC_FILE_RANGE_WRITE);
    }
}

#[cfg(not(target_os = "linux"))]
fn start_writeback(_file: &std::fs::File, _offset: u64, _len: u64) {}

/// Frees the disk blocks of `len` bytes at `offset` of `file` (a staging file whose bytes were
/// copied and are read no more), keeping its length. Advice only: a file system that cannot
/// punch holes keeps the blocks until the file is removed, as before.
#[cfg(target_os = "linux")]
fn release(file: &std::fs::File, offset: u64, len: u64) {
    use std::os::fd::AsRawFd as _;
    let (Ok(offset), Ok(len)) = (i64::try_from(offset), i64::try_from(len)) else {
        return;
    };
    // SAFETY: the descriptor belongs to `file`, open for the duration of the call; the call
    // reads no memory of ours.
    unsafe {
        libc::fallocate(
            file.as_raw_fd(),
            libc::FALLOC_FL_PUNCH_HOLE | libc::FALLOC_FL_KEEP_SIZE,
            offset,
            len,
        );
    }
}

#[cfg(not(target_os = "linux"))]
fn release(_file: &std::fs::File, _offset: u64, _len: u64) {}

/// The output JSON before repacking: the document as read, with the typed model's changes,
/// the primitives in `replaced` and the dequantizing nodes; and the typed model alone.
fn output_json(
    doc: &Document,
    replaced: &BTreeMap<(usize, usize), Value>,
) -> Result<(Value, Value)> {
    let now = serde_json::to_value(&doc.root).map_err(|e| Error::invalid("json", e))?;
    let mut out = json_merge::merge(&doc.base, &now, &doc.raw);
    let root = out
        .as_object_mut()
        .ok_or_else(|| Error::invalid("json", "top level is not an object"))?;
    for ((m, p), prim) in replaced {
        root["meshes"][*m]["primitives"][*p] = prim.clone();
    }
    dequantize_nodes::apply(root, &doc.dequantize);
    Ok((now, out))
}

/// Which accessors and which buffer views of `doc` the output whose JSON is `root` keeps: what
/// it refers to, and whatever no replaced primitive left behind (`replaced_accessors`: the
/// accessors the replaced primitives referred to when read).
fn kept_items(
    doc: &Document,
    root: &mut Map<String, Value>,
    replaced_accessors: &BTreeSet<usize>,
) -> Result<(Vec<bool>, Vec<bool>)> {
    let mut referenced = BTreeSet::new();
    for_each_accessor_ref(root, &mut |i| {
        referenced.insert(*i as usize);
    });
    // References inside extensions were never validated by the typed model: check them here.
    if let Some(bad) = referenced.iter().find(|i| **i >= doc.root.accessors.len()) {
        return Err(Error::invalid(
            "json",
            format!(
                "a reference to accessor {bad}, which does not exist (expected an index below {})",
                doc.root.accessors.len()
            ),
        ));
    }
    let mut bad_view = None;
    for_each_view_ref(root, &mut |v| {
        if *v as usize >= doc.root.buffer_views.len() {
            bad_view = Some(*v);
        }
    });
    if let Some(bad) = bad_view {
        return Err(Error::invalid(
            "json",
            format!("a reference to buffer view {bad}, which does not exist (expected an index below {})", doc.root.buffer_views.len()),
        ));
    }
    let keep_accessor: Vec<bool> = (0..doc.root.accessors.len())
        .map(|i| referenced.contains(&i) || !replaced_accessors.contains(&i))
        .collect();
    let mut view_used = vec![false; doc.root.buffer_views.len()];
    let mut view_orphaned = vec![false; doc.root.buffer_views.len()];
    for (i, a) in doc.root.accessors.iter().enumerate() {
        for v in accessor_views(a) {
            if keep_accessor[i] {
                view_used[v] = true;
            } else {
                view_orphaned[v] = true;
            }
        }
    }
    for_each_view_ref(root, &mut |v| view_used[*v as usize] = true);
    let keep_view: Vec<bool> = view_used
        .iter()
        .zip(&view_orphaned)
        .map(|(u, o)| *u || !*o)
        .collect();
    Ok((keep_accessor, keep_view))
}

/// The buffer views accessor `a` reads (its own and its sparse parts').
fn accessor_views(a: &gltf_json::Accessor) -> Vec<usize> {
    let sparse = a
        .sparse
        .iter()
        .flat_map(|s| [s.indices.buffer_view.value(), s.values.buffer_view.value()]);
    a.buffer_view
        .map(|v| v.value())
        .into_iter()
        .chain(sparse)
        .collect()
}

/// The buffer views of `doc` as read that its output will still hold once the triangle
/// primitives `replacing` are replaced (whatever they are replaced with, since new primitives
/// refer only to new accessors), in the order they are written: the start of the output's
/// binary data, known before any primitive is replaced.
pub(crate) fn views_kept_after_replacing(
    doc: &Document,
    replacing: &[(usize, usize)],
) -> Result<Vec<usize>> {
    let mut replaced = doc.replaced.clone();
    let mut replaced_accessors = doc.replaced_accessors.clone();
    for &(m, p) in replacing {
        let mut json = doc.primitive_json(m, p).cloned().ok_or_else(|| {
            Error::invalid(format!("meshes[{m}].primitives[{p}]"), "does not exist")
        })?;
        super::primitive::collect_accessor_refs(&json, &mut replaced_accessors);
        // What a replacement removes: its data references, and the Draco stream's view.
        if let Some(obj) = json.as_object_mut() {
            for key in ["attributes", "indices", "targets"] {
                obj.remove(key);
            }
            if let Some(ext) = obj.get_mut("extensions").and_then(Value::as_object_mut) {
                ext.remove(draco_decode::EXTENSION);
            }
        }
        replaced.insert((m, p), json);
    }
    let (_, mut out) = output_json(doc, &replaced)?;
    let root = out
        .as_object_mut()
        .ok_or_else(|| Error::invalid("json", "top level is not an object"))?;
    let (_, keep_view) = kept_items(doc, root, &replaced_accessors)?;
    Ok((0..keep_view.len()).filter(|v| keep_view[*v]).collect())
}

/// The output JSON and binary buffer of `doc` (uncompressed) whose views in `written` are
/// already written, at the offsets given: the returned buffer holds only what follows them.
pub(crate) fn assemble_after_stream(
    doc: &Document,
    embed_images: bool,
    bin_path: Option<&Path>,
    written: &BTreeMap<usize, usize>,
) -> Result<(Value, Pieces)> {
    let (json, bin, _) = assemble(doc, embed_images, bin_path, None, None, Some(written))?;
    Ok((json, bin))
}

/// Builds the output JSON, its binary buffer, and (compressed, when asked) the uncompressed
/// fallback buffer's bytes.
///
/// `written` holds the views already written to the output as it was produced, by index, with
/// the offset each was written at: they take no memory here, and must come first, in order.
fn assemble(
    doc: &Document,
    embed_images: bool,
    bin_path: Option<&Path>,
    compression: Option<Compression>,
    fallback_path: Option<&Path>,
    written: Option<&BTreeMap<usize, usize>>,
) -> Result<(Value, Pieces, Option<Vec<u8>>)> {
    let (now, mut out) = output_json(doc, &doc.replaced)?;
    let root = out
        .as_object_mut()
        .ok_or_else(|| Error::invalid("json", "top level is not an object"))?;
    let (keep_accessor, keep_view) = kept_items(doc, root, &doc.replaced_accessors)?;

    // Repack every kept view into one buffer.
    let typed_views = now
        .get("bufferViews")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let mut bin = Pieces::default();
    let mut views = Vec::new();
    let mut view_map = vec![None; keep_view.len()];
    let mut written_kept = 0;
    for (i, keep) in keep_view.iter().enumerate() {
        if !*keep {
            continue;
        }
        let mut v = typed_views[i].clone();
        v["buffer"] = json!(0);
        match written.and_then(|w| w.get(&i)) {
            Some(&at) => {
                // Written already: it must lie where this layout puts it.
                let len = doc.root.buffer_views[i].byte_length.0 as usize;
                if bin.len() != bin.on_disk() || at != bin.len().next_multiple_of(4) {
                    return Err(Error::invalid(
                        format!("bufferViews[{i}]"),
                        "was written out of place (please report)",
                    ));
                }
                v["byteOffset"] = json!(at);
                v["byteLength"] = json!(len);
                bin.extend_on_disk(at + len);
                written_kept += 1;
            }
            None => {
                let piece = doc.view_piece(i)?;
                bin.align4();
                v["byteOffset"] = json!(bin.len());
                v["byteLength"] = json!(piece.as_bytes().len());
                bin.push(piece);
            }
        }
        view_map[i] = Some(views.len());
        views.push(v);
    }
    if written.is_some_and(|w| w.len() != written_kept) {
        return Err(Error::invalid(
            "bufferViews",
            "a view was written that the output does not keep (please report)",
        ));
    }
    let typed_accessors = now
        .get("accessors")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let mut accessors = Vec::new();
    let mut accessor_map = vec![None; keep_accessor.len()];
    for (i, keep) in keep_accessor.iter().enumerate() {
        if !*keep {
            continue;
        }
        let mut a = typed_accessors[i].clone();
        for ptr in [
            "/bufferView",
            "/sparse/indices/bufferView",
            "/sparse/values/bufferView",
        ] {
            if let Some(v) = a.pointer_mut(ptr) {
                *v = json!(view_map[v.as_u64().unwrap_or(0) as usize]);
            }
        }
        accessor_map[i] = Some(accessors.len());
        accessors.push(a);
    }
    for_each_accessor_ref(root, &mut |i| {
        *i = accessor_map[*i as usize].unwrap_or(0) as u64
    });
    for_each_view_ref(root, &mut |v| {
        *v = view_map[*v as usize].unwrap_or(0) as u64
    });

    if embed_images {
        embed_external_images(doc, root, &mut bin, &mut views)?;
    }
    set_array(root, "accessors", accessors);
    let fallback = match compression {
        Some(_) if bin.on_disk() > 0 => {
            return Err(Error::invalid(
                "output",
                "compression needs the whole buffer in memory (please report)",
            ))
        }
        Some(c) => {
            let filtered = doc
                .filtered
                .iter()
                .filter_map(|(v, f)| Some((view_map.get(*v).copied().flatten()?, f.clone())))
                .collect();
            // The compressor rewrites the buffer: it works on one contiguous copy.
            let mut flat = bin.concat();
            let fallback =
                meshopt_encode::compress(root, &mut views, &mut flat, &filtered, c.fallback)?;
            bin = flat.into();
            fallback
        }
        None => None,
    };
    set_array(root, "bufferViews", views);
    fix_extension_lists(root);
    let mut buffers = if bin.is_empty() && fallback.is_none() {
        vec![]
    } else {
        bin.align4();
        let mut b = json!({ "byteLength": bin.len() });
        if let Some(u) = file_uri(bin_path) {
            b["uri"] = json!(u);
        }
        vec![b]
    };
    if let Some(f) = &fallback {
        let mut b = json!({
            "byteLength": f.byte_length,
            "extensions": { meshopt_encode::EXTENSION: { "fallback": true } },
        });
        if let Some(u) = file_uri(fallback_path).filter(|_| f.bytes.is_some()) {
            b["uri"] = json!(u);
        }
        buffers.push(b);
    }
    set_array(root, "buffers", buffers);
    if let Some(f) = &fallback {
        add_extension(root, meshopt_encode::EXTENSION, f.bytes.is_none());
    }
    Ok((out, bin, fallback.and_then(|f| f.bytes)))
}

/// The relative `uri` of a file written beside the output.
fn file_uri(path: Option<&Path>) -> Option<String> {
    let name = path.and_then(Path::file_name).and_then(|n| n.to_str())?;
    Some(percent_encoding::utf8_percent_encode(name, URI_ESCAPES).to_string())
}

/// Lists `name` in `extensionsUsed`, and in `extensionsRequired` when `required`.
fn add_extension(root: &mut Map<String, Value>, name: &str, required: bool) {
    let keys: &[&str] = if required {
        &["extensionsUsed", "extensionsRequired"]
    } else {
        &["extensionsUsed"]
    };
    for key in keys {
        let list = root.entry(*key).or_insert_with(|| json!([]));
        if let Some(list) = list.as_array_mut() {
            if !list.iter().any(|e| e == name) {
                list.push(json!(name));
            }
        }
    }
}

/// Characters escaped in a written file name `uri` (RFC 3986 reserved and unsafe ones).
const URI_ESCAPES: &percent_encoding::AsciiSet = &percent_encoding::CONTROLS
    .add(b' ')
    .add(b'"')
    .add(b'#')
    .add(b'%')
    .add(b'<')
    .add(b'>')
    .add(b'?')
    .add(b'[')
    .add(b'\\')
    .add(b']')
    .add(b'^')
    .add(b'`')
    .add(b'{')
    .add(b'|')
    .add(b'}')
    .add(b':');

fn set_array(root: &mut Map<String, Value>, key: &str, items: Vec<Value>) {
    if items.is_empty() {
        root.remove(key);
    } else {
        root.insert(key.into(), Value::Array(items));
    }
}

fn arr<'a>(root: &'a mut Map<String, Value>, key: &str) -> impl Iterator<Item = &'a mut Value> {
    root.get_mut(key)
        .and_then(Value::as_array_mut)
        .into_iter()
        .flatten()
}

fn visit_u64(v: Option<&mut Value>, f: &mut dyn FnMut(&mut u64)) {
    if let Some(v) = v {
        if let Some(mut i) = v.as_u64() {
            f(&mut i);
            *v = json!(i);
        }
    }
}

fn visit_values(v: Option<&mut Value>, f: &mut dyn FnMut(&mut u64)) {
    for x in v
        .and_then(Value::as_object_mut)
        .into_iter()
        .flat_map(|o| o.values_mut())
    {
        visit_u64(Some(x), f);
    }
}

/// Calls `f` on every accessor index the JSON holds (in places this writer knows about).
fn for_each_accessor_ref(root: &mut Map<String, Value>, f: &mut dyn FnMut(&mut u64)) {
    for mesh in arr(root, "meshes") {
        for prim in mesh
            .get_mut("primitives")
            .and_then(Value::as_array_mut)
            .into_iter()
            .flatten()
        {
            visit_values(prim.get_mut("attributes"), f);
            visit_u64(prim.get_mut("indices"), f);
            for t in prim
                .get_mut("targets")
                .and_then(Value::as_array_mut)
                .into_iter()
                .flatten()
            {
                visit_values(Some(t), f);
            }
        }
    }
    for skin in arr(root, "skins") {
        visit_u64(skin.get_mut("inverseBindMatrices"), f);
    }
    for anim in arr(root, "animations") {
        for s in anim
            .get_mut("samplers")
            .and_then(Value::as_array_mut)
            .into_iter()
            .flatten()
        {
            visit_u64(s.get_mut("input"), f);
            visit_u64(s.get_mut("output"), f);
        }
    }
    for node in arr(root, "nodes") {
        visit_values(
            node.pointer_mut("/extensions/EXT_mesh_gpu_instancing/attributes"),
            f,
        );
    }
}

/// Calls `f` on every buffer view index outside accessors (images, Draco primitives).
fn for_each_view_ref(root: &mut Map<String, Value>, f: &mut dyn FnMut(&mut u64)) {
    for image in arr(root, "images") {
        visit_u64(image.get_mut("bufferView"), f);
    }
    for mesh in arr(root, "meshes") {
        for prim in mesh
            .get_mut("primitives")
            .and_then(Value::as_array_mut)
            .into_iter()
            .flatten()
        {
            visit_u64(
                prim.pointer_mut("/extensions/KHR_draco_mesh_compression/bufferView"),
                f,
            );
        }
    }
}

/// Moves images stored as separate files into the output's buffer, because their relative
/// `uri`s would not resolve from the output's folder. Network `uri`s are kept as they are.
fn embed_external_images(
    doc: &Document,
    root: &mut Map<String, Value>,
    bin: &mut Pieces,
    views: &mut Vec<Value>,
) -> Result<()> {
    for (i, image) in arr(root, "images").enumerate() {
        let Some(u) = image.get("uri").and_then(Value::as_str).map(str::to_owned) else {
            continue;
        };
        let at = format!("images[{i}].uri");
        let target = match uri::resolve(&u, &at, doc.base_dir.as_deref(), doc.allow_outside_uris) {
            Ok(uri::Target::File(f)) => f,
            Ok(uri::Target::Data(_)) => continue,
            Err(_) if u.contains("://") => continue,
            Err(e) => return Err(e),
        };
        // Read through the same checks as buffers: size bound, no link out of the folder.
        let limits = uri::Limits {
            allow_outside: doc.allow_outside_uris,
            ..uri::Limits::from(&super::ReadOptions::default())
        };
        let bytes = uri::load(&u, &at, doc.base_dir.as_deref(), &limits)?;
        let mime = image
            .get("mimeType")
            .and_then(Value::as_str)
            .map(str::to_owned)
            .or_else(|| mime_of(&target, &bytes))
            .ok_or_else(|| {
                Error::invalid(
                    &at,
                    "cannot tell the image's type to embed it (expected png, jpeg, webp or ktx2)",
                )
            })?;
        bin.align4();
        views.push(json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len() }));
        bin.push_bytes(bytes);
        let obj = image.as_object_mut().expect("images are objects");
        obj.remove("uri");
        obj.insert("bufferView".into(), json!(views.len() - 1));
        obj.insert("mimeType".into(), json!(mime));
    }
    Ok(())
}

fn mime_of(path: &Path, bytes: &[u8]) -> Option<String> {
    let by_magic = if bytes.starts_with(b"\x89PNG") {
        Some("image/png")
    } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        Some("image/jpeg")
    } else if bytes.len() > 12 && &bytes[8..12] == b"WEBP" {
        Some("image/webp")
    } else if bytes.starts_with(b"\xABKTX 20") {
        Some("image/ktx2")
    } else {
        None
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    by_magic
        .or(match ext.as_deref() {
            Some("png") => Some("image/png"),
            Some("jpg" | "jpeg") => Some("image/jpeg"),
            Some("webp") => Some("image/webp"),
            Some("ktx2") => Some("image/ktx2"),
            _ => None,
        })
        .map(str::to_owned)
}

/// Keeps `extensionsUsed`/`extensionsRequired` true to what is written: meshopt compression is
/// decoded on read (the compressor adds it back), and KHR_mesh_quantization is listed exactly
/// when quantized attributes are written.
fn fix_extension_lists(root: &mut Map<String, Value>) {
    let quantized = uses_quantized_attributes(root);
    if quantized {
        add_extension(root, "KHR_mesh_quantization", true);
    }
    // Primitives decoded from Draco are written uncompressed; the others keep their stream.
    let draco = root
        .get("meshes")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .filter_map(|m| m.get("primitives").and_then(Value::as_array))
        .flatten()
        .any(|p| {
            p.pointer(&format!("/extensions/{}", draco_decode::EXTENSION))
                .is_some()
        });
    for key in ["extensionsUsed", "extensionsRequired"] {
        if let Some(list) = root.get_mut(key).and_then(Value::as_array_mut) {
            list.retain(|e| {
                let name = e.as_str().unwrap_or("");
                !meshopt_decode::EXTENSIONS.contains(&name)
                    && (quantized || name != "KHR_mesh_quantization")
                    && (draco || name != draco_decode::EXTENSION)
            });
            if list.is_empty() {
                root.remove(key);
            }
        }
    }
}

/// Does any primitive attribute still use a format only KHR_mesh_quantization allows?
fn uses_quantized_attributes(root: &mut Map<String, Value>) -> bool {
    let accessors = root
        .get("accessors")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let format = |i: u64| {
        let a = &accessors[i as usize];
        (
            a["componentType"].as_u64().unwrap_or(5126),
            a["normalized"].as_bool().unwrap_or(false),
        )
    };
    let mut found = false;
    let meshes = root
        .get("meshes")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    for prim in meshes
        .iter()
        .filter_map(|m| m["primitives"].as_array())
        .flatten()
    {
        let targets = prim["targets"].as_array().cloned().unwrap_or_default();
        let sets =
            std::iter::once((&prim["attributes"], false)).chain(targets.iter().map(|t| (t, true)));
        for (set, is_target) in sets {
            for (name, i) in set.as_object().into_iter().flatten() {
                let Some(i) = i.as_u64() else { continue };
                let (ct, normalized) = format(i);
                let core = match name.as_str() {
                    "POSITION" | "NORMAL" | "TANGENT" => ct == 5126,
                    n if n.starts_with("TEXCOORD_") => {
                        ct == 5126 || (normalized && (ct == 5121 || ct == 5123))
                    }
                    _ => true,
                };
                found |= !core || (is_target && ct != 5126 && !name.starts_with('_'));
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A previous output is replaced whole, and the next write over the new one works (the
    /// handle held on the old file is let go, not left on the name).
    #[test]
    fn an_output_replaces_the_previous_one() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.glb");
        std::fs::write(&path, vec![7u8; 1 << 20]).unwrap();
        atomic_write(&path, b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        atomic_write(&path, b"third").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"third");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "{names:?}");
    }

    /// The handle held on a replaced file keeps that file, unlinked, until it is let go: the
    /// rename itself frees none of its blocks, whatever its size.
    #[cfg(target_os = "linux")]
    #[test]
    fn the_replaced_file_is_held_across_the_rename() {
        use std::os::unix::fs::MetadataExt as _;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.glb");
        std::fs::write(&path, vec![7u8; 1 << 20]).unwrap();
        let held = hold_replaced(&path).expect("a file to hold");
        stage_bytes(&path, b"new").unwrap().persist(&path).unwrap();
        let old = held.metadata().unwrap();
        assert_eq!((old.len(), old.nlink()), (1 << 20, 0));
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert!(hold_replaced(&dir.path().join("none.glb")).is_none());
    }

    /// What sits at the output's name is never opened for reading: a FIFO there (which an open
    /// for reading would wait on until a writer came) is replaced at once.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_fifo_at_the_output_name_is_replaced_without_waiting() {
        use std::os::unix::ffi::OsStrExt as _;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.glb");
        let name = std::ffi::CString::new(path.as_os_str().as_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path; the call reads nothing else of ours.
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o644) }, 0);
        let (done, wait) = std::sync::mpsc::channel();
        let target = path.clone();
        std::thread::spawn(move || done.send(atomic_write(&target, b"new").is_ok()));
        let written = wait
            .recv_timeout(std::time::Duration::from_secs(20))
            .expect("replacing a FIFO waited for a writer");
        assert!(written);
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
    }
}
