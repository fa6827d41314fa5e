//! A document's output written while the document is still being made: each buffer view goes
//! to disk as soon as it is added (and its array is freed), the JSON last. With `--check`, the
//! same bytes are compared with the files on disk as they come instead of being written.
//!
//! The bytes are those [`super::write()`] gives: the binary data starts with the input's views
//! that the output keeps (known before any primitive is replaced, from what the replaced
//! primitives referred to), then every view added since, in the order it was added; the writer
//! ([`mod@super::write`]) builds the JSON over that layout and checks that every written view
//! lies where it would have put it.
//!
//! The layout of the files:
//! - `.gltf`: the `.bin` is written in place as it is produced; the `.gltf` when done.
//! - `.glb`: the JSON chunk comes first, and its length is known only at the end (accessor
//!   bounds, counts). The binary chunk is written to a second temporary file beside the output
//!   and, once the JSON is known, copied behind it by the kernel (`copy_file_range`, no pass
//!   through this process's memory; a reflink on file systems that share blocks), in 16 MiB
//!   steps whose blocks are freed from the staging file as each is copied (a punched hole), so
//!   the binary chunk is never on disk twice (where holes cannot be punched, it briefly is). The last
//!   mesh's arrays, in memory anyway until the end, are not staged but written behind the copy
//!   from where they lie: a one-mesh file is written once, as before. The file is byte for byte
//!   what [`super::write()`] writes; reserving space for the JSON instead would have changed
//!   every `.glb` (padding).
//!
//! Compressed outputs (`EXT_meshopt_compression`) are not streamed: the compressor plans every
//! view from the whole document. Neither are quantized ones, since quantization rewrites the
//! document's primitives after they are all made.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::buffer_data::{BufferData, Pieces};
use super::compare::Comparison;
use super::document::Document;
use super::error::{Error, Result};
use super::files::bin_path;
use super::glb;
use super::write::{self, persist, Staging, WriteOptions};

/// Whether a streamed output is written or compared with what is on disk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StreamMode {
    /// Write temporary files and rename them into place at the end, all or none.
    Write,
    /// Compare with the files on disk; write nothing.
    Check,
}

/// What a finished streamed output did.
#[derive(Debug, Clone, Default)]
pub struct Streamed {
    /// Every file of the output with its length in bytes, in the order they are written.
    pub files: Vec<(PathBuf, u64)>,
    /// [`StreamMode::Check`]: the first file (in that order) that differs from what is on disk,
    /// or is missing.
    pub stale: Option<PathBuf>,
}

/// Where the binary data goes as it is produced.
enum Sink {
    Write(Staging),
    Compare(Comparison),
}

/// An output being written (or compared) while its document is made: see the module
/// documentation.
pub struct StreamedOutput {
    path: PathBuf,
    as_glb: bool,
    embed_images: bool,
    sink: Sink,
    /// Bytes of binary data produced so far.
    len: usize,
    /// The views written so far, with the offset of each in the binary data.
    written: BTreeMap<usize, usize>,
    /// The first view and the first buffer not yet looked at.
    next_view: usize,
    next_buffer: usize,
}

impl std::fmt::Debug for StreamedOutput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StreamedOutput")
            .field("path", &self.path)
            .field("len", &self.len)
            .field("views", &self.written.len())
            .finish_non_exhaustive()
    }
}

impl StreamedOutput {
    /// Starts the output of `doc` at `path` (`.glb`, or `.gltf` + `<stem>.bin`), where the
    /// triangle primitives `replacing` are about to be replaced: refuses to overwrite the
    /// input as [`super::write()`] does, and writes (or compares) the input's views the
    /// output keeps.
    pub fn begin(
        doc: &Document,
        path: &Path,
        opts: &WriteOptions,
        replacing: &[(usize, usize)],
        mode: StreamMode,
    ) -> Result<StreamedOutput> {
        if opts.compression.is_some() {
            return Err(Error::invalid(
                "output",
                "a compressed output is not streamed (expected the whole document at once)",
            ));
        }
        let as_glb = write::is_glb_name(path)?;
        let bin = (!as_glb).then(|| bin_path(path));
        write::refuse_overwriting_input(doc, path, bin.as_deref(), opts)?;
        let sink = match (mode, &bin) {
            (StreamMode::Write, Some(bin)) => Sink::Write(Staging::new(bin)?),
            (StreamMode::Write, None) => Sink::Write(Staging::aside(path)?),
            (StreamMode::Check, Some(bin)) => Sink::Compare(Comparison::open(bin)),
            (StreamMode::Check, None) => Sink::Compare(Comparison::at(path, glb_bin_start(path))),
        };
        let mut out = StreamedOutput {
            path: path.to_path_buf(),
            as_glb,
            embed_images: !write::same_dir(doc.base_dir.as_deref(), write::parent_dir(path)),
            sink,
            len: 0,
            written: BTreeMap::new(),
            next_view: doc.root.buffer_views.len(),
            next_buffer: doc.buffers.len(),
        };
        for view in write::views_kept_after_replacing(doc, replacing)? {
            out.put_view(doc, view)?;
        }
        Ok(out)
    }

    /// Frees the buffers `doc` was read with, once its triangle primitives are decoded: every
    /// input view the output keeps was written (or compared) by [`StreamedOutput::begin`], and
    /// what remains of them belonged to the primitives being replaced. On a million-triangle
    /// scan that is the whole input file, held otherwise until the end.
    pub fn release_input(&self, doc: &mut Document) {
        doc.release_read_buffers();
    }

    /// Writes every buffer view added to `doc` since the last call, in order, and frees the
    /// arrays that held them. `last`: no view will be added after these; a `.glb` then keeps
    /// them in memory and writes them behind the staged binary data at the end, since staging
    /// them would only copy them once more (for a one-mesh file, all of its arrays).
    pub fn flush(&mut self, doc: &mut Document, last: bool) -> Result<()> {
        let keep = last && self.as_glb && matches!(self.sink, Sink::Write(_));
        if keep {
            self.next_view = doc.root.buffer_views.len();
            self.next_buffer = doc.buffers.len();
            return Ok(());
        }
        for view in self.next_view..doc.root.buffer_views.len() {
            self.put_view(doc, view)?;
        }
        self.next_view = doc.root.buffer_views.len();
        for b in self.next_buffer..doc.buffers.len() {
            // A new array buffer holds exactly one view, written above.
            if doc.root.buffers[b].name.as_deref() == Some(super::document::ARRAY_BUFFER_NAME) {
                doc.buffers[b] = Arc::new(BufferData::default());
            }
        }
        self.next_buffer = doc.buffers.len();
        Ok(())
    }

    fn put_view(&mut self, doc: &Document, view: usize) -> Result<()> {
        let bytes = doc.view_bytes(view)?;
        let at = self.len.next_multiple_of(4);
        self.put(&[0; 3][..at - self.len])?;
        self.put(bytes)?;
        self.written.insert(view, at);
        Ok(())
    }

    fn put(&mut self, bytes: &[u8]) -> Result<()> {
        match &mut self.sink {
            Sink::Write(s) => s.write(bytes)?,
            Sink::Compare(c) => c.feed(bytes),
        }
        self.len += bytes.len();
        Ok(())
    }

    /// Writes the rest (images to embed, the JSON) and renames every file into place, all or
    /// none ([`StreamMode::Write`]); or compares the rest and says which file differs
    /// ([`StreamMode::Check`]). On an error nothing is renamed and the temporary files are
    /// removed.
    ///
    /// The document lets go of its new arrays (its JSON model stays): each is freed as soon as
    /// its bytes are written, not when the document is dropped after the file is on disk.
    pub fn finish(mut self, doc: &mut Document) -> Result<Streamed> {
        self.flush_nothing_new(doc)?;
        let bin_path = (!self.as_glb).then(|| bin_path(&self.path));
        let (json, bin) = write::assemble_after_stream(
            doc,
            self.embed_images,
            bin_path.as_deref(),
            &self.written,
        )?;
        release_arrays(doc);
        if bin.on_disk() != self.len {
            return Err(Error::invalid(
                "output",
                "the binary data written differs from its layout (please report)",
            ));
        }
        let staged = self.len;
        let shown = self.path.display().to_string();
        if self.as_glb && matches!(self.sink, Sink::Write(_)) {
            // The staged bytes are copied behind the JSON, then what is still in memory.
            let text = serde_json::to_vec(&json).map_err(|e| Error::invalid(&shown, e))?;
            let (head, tail) = glb::frame(&text, bin.len());
            let total = (head.len() + bin.len() + tail.len()) as u64;
            let Sink::Write(spool) = self.sink else {
                unreachable!("matched above")
            };
            let spool = spool.written_out()?;
            let mut glb = Staging::new(&self.path)?;
            glb.write(&head)?;
            glb.copy_from(spool, staged as u64)?;
            put_and_free(bin, |bytes| glb.write(bytes))?;
            glb.write(tail)?;
            persist(glb.finish()?, &self.path)?;
            return Ok(Streamed {
                files: vec![(self.path.clone(), total)],
                stale: None,
            });
        }
        put_and_free(bin, |bytes| self.put(bytes))?;
        if self.as_glb {
            let text = serde_json::to_vec(&json).map_err(|e| Error::invalid(&shown, e))?;
            let (head, tail) = glb::frame(&text, self.len);
            let total = (head.len() + self.len + tail.len()) as u64;
            let files = vec![(self.path.clone(), total)];
            match self.sink {
                Sink::Write(_) => unreachable!("written above"),
                Sink::Compare(mut body) => {
                    let mut start = Comparison::open(&self.path);
                    start.feed(&head);
                    // Without binary data there is no binary chunk: the head is the file.
                    let same = if self.len == 0 {
                        start.finish()
                    } else {
                        body.feed(tail);
                        body.finish() && start.matches_so_far()
                    };
                    let stale = (!same).then(|| self.path.clone());
                    Ok(Streamed { files, stale })
                }
            }
        } else {
            let mut text =
                serde_json::to_vec_pretty(&json).map_err(|e| Error::invalid(&shown, e))?;
            text.push(b'\n');
            let bin_path = bin_path.expect("a .gltf has a .bin path");
            let has_bin = self.len > 0;
            let mut files = Vec::with_capacity(2);
            if has_bin {
                files.push((bin_path.clone(), self.len as u64));
            }
            files.push((self.path.clone(), text.len() as u64));
            match self.sink {
                Sink::Write(bin) => {
                    // Both files are complete on disk before either is renamed.
                    let bin = has_bin.then(|| bin.finish()).transpose()?;
                    let gltf = write::stage_bytes(&self.path, &text)?;
                    if let Some(bin) = bin {
                        persist(bin, &bin_path)?;
                    }
                    persist(gltf, &self.path)?;
                    Ok(Streamed { files, stale: None })
                }
                Sink::Compare(bin) => {
                    let mut json = Comparison::open(&self.path);
                    json.feed(&text);
                    let stale = if has_bin && !bin.finish() {
                        Some(bin_path)
                    } else if !json.finish() {
                        Some(self.path.clone())
                    } else {
                        None
                    };
                    Ok(Streamed { files, stale })
                }
            }
        }
    }

    /// Refuses to finish with views added since the last [`StreamedOutput::flush`]: they would
    /// have to be written after bytes that are already on disk.
    fn flush_nothing_new(&self, doc: &Document) -> Result<()> {
        if doc.root.buffer_views.len() != self.next_view {
            return Err(Error::invalid(
                "output",
                "views were added after the last flush (please report)",
            ));
        }
        Ok(())
    }
}

/// Empties every buffer of `doc` that holds one array the pipeline made (its bytes are shared
/// with the pieces being written, which then hold the last reference).
fn release_arrays(doc: &mut Document) {
    for (data, buffer) in doc.buffers.iter_mut().zip(&doc.root.buffers) {
        if buffer.name.as_deref() == Some(super::document::ARRAY_BUFFER_NAME) {
            *data = Arc::new(BufferData::default());
        }
    }
}

/// Hands each piece of `bin` to `put`, in order, and frees it as soon as it is written, on a
/// pool thread: unmapping a large array's pages (about 30 ms for a 112 MB output, measured)
/// then runs beside the next write and the flush to disk instead of after the rename.
///
/// The pieces are written by one thread, unlike the parallel read of an input: a buffered
/// write holds its file's inode lock exclusively while it copies into the page cache (ext4,
/// XFS and tmpfs alike), so blocks written at their offsets by several threads are copied one
/// after another, the other threads asleep on the lock. Copying in parallel through a shared
/// mapping would turn a full disk into a signal instead of an error naming the file.
fn put_and_free(bin: Pieces, mut put: impl FnMut(&[u8]) -> Result<()>) -> Result<()> {
    for piece in bin.into_pieces() {
        put(piece.as_bytes())?;
        rayon::spawn(move || drop(piece));
    }
    Ok(())
}

/// Where the binary chunk's data starts in the `.glb` at `path`, from its header (`None`: no
/// file, or not a GLB with a JSON chunk first, so that no streamed comparison can match).
fn glb_bin_start(path: &Path) -> Option<u64> {
    use std::io::Read as _;
    let mut head = [0u8; 20];
    std::fs::File::open(path).ok()?.read_exact(&mut head).ok()?;
    let word = |at: usize| u32::from_le_bytes([head[at], head[at + 1], head[at + 2], head[at + 3]]);
    (glb::is_glb(&head) && word(16) == glb::CHUNK_JSON).then(|| 20 + u64::from(word(12)) + 8)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gltf_io::{read_bytes, replace_primitive_owned, Attribute, PrimitiveData};

    /// One triangle, its positions in a `data:` buffer.
    fn triangle() -> Document {
        triangle_and(&[])
    }

    /// [`triangle`] with the primitives `more` after it in its mesh.
    fn triangle_and(more: &[serde_json::Value]) -> Document {
        let floats: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::Engine::encode(&base64::engine::general_purpose::STANDARD, &floats)
        );
        let json = serde_json::json!({
            "asset": { "version": "2.0" },
            "buffers": [{ "byteLength": 36, "uri": uri }],
            "bufferViews": [{ "buffer": 0, "byteLength": 36 }],
            "accessors": [{ "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                            "min": [0, 0, 0], "max": [1, 1, 0] }],
            "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 } }] }],
        });
        let mut json = json;
        json["meshes"][0]["primitives"]
            .as_array_mut()
            .unwrap()
            .extend_from_slice(more);
        read_bytes(
            &serde_json::to_vec(&json).unwrap(),
            None,
            &Default::default(),
        )
        .unwrap()
    }

    /// A strip of `n` triangles.
    fn strip(n: u32) -> PrimitiveData {
        let positions = (0..n + 2)
            .flat_map(|i| [i as f32, (i % 2) as f32, 0.0])
            .collect();
        PrimitiveData {
            attributes: vec![Attribute::float("POSITION", 3, positions)],
            indices: (0..n).flat_map(|i| [i, i + 1, i + 2]).collect(),
            targets: Vec::new(),
        }
    }

    #[test]
    fn flushed_arrays_are_freed_and_the_file_is_what_the_writer_gives() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.glb");
        let opts = WriteOptions::default();
        let mut in_memory = triangle();
        replace_primitive_owned(&mut in_memory, 0, 0, strip(100_000)).unwrap();
        let expected = write::encode(&in_memory, &path, &opts).unwrap();

        let mut doc = triangle();
        let mut out =
            StreamedOutput::begin(&doc, &path, &opts, &[(0, 0)], StreamMode::Write).unwrap();
        replace_primitive_owned(&mut doc, 0, 0, strip(100_000)).unwrap();
        let held = doc.buffer_bytes();
        assert!(held > 100_000 * 12, "{held}");
        out.flush(&mut doc, false).unwrap();
        // Only the input's buffer (36 bytes) is left.
        assert!(
            doc.buffer_bytes() < 1000,
            "{} still held",
            doc.buffer_bytes()
        );
        let done = out.finish(&mut doc).unwrap();
        assert_eq!(done.files, vec![(path.clone(), expected[0].len())]);
        assert_eq!(std::fs::read(&path).unwrap(), expected[0].to_bytes());

        // Checked against that file: the same; against one byte more: not.
        let check = |doc: &mut Document| {
            let mut out =
                StreamedOutput::begin(doc, &path, &opts, &[(0, 0)], StreamMode::Check).unwrap();
            replace_primitive_owned(doc, 0, 0, strip(100_000)).unwrap();
            out.flush(doc, true).unwrap();
            out.finish(doc).unwrap().stale
        };
        assert_eq!(check(&mut triangle()), None);
        let mut longer = std::fs::read(&path).unwrap();
        longer.push(0);
        std::fs::write(&path, longer).unwrap();
        assert_eq!(check(&mut triangle()), Some(path.clone()));
    }

    /// A `.glb`'s staged binary data is freed step by step as it is copied behind the JSON, so
    /// the output never needs it twice on disk; the copy is byte for byte.
    #[cfg(target_os = "linux")]
    #[test]
    fn staged_bytes_are_freed_as_they_are_copied() {
        use std::os::unix::fs::MetadataExt as _;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.glb");
        // Two steps and a part of a third.
        let data: Vec<u8> = (0..(40u32 << 20)).map(|i| (i % 251) as u8).collect();
        let mut spool = Staging::aside(&path).unwrap();
        spool.write(&data).unwrap();
        let spool = spool.written_out().unwrap();
        spool.as_file().sync_all().unwrap();
        let probe = spool.reopen().unwrap();
        let allocated = || probe.metadata().unwrap().blocks() * 512;
        let before = allocated();
        assert!(before >= data.len() as u64, "{before}");

        let mut out = Staging::new(&path).unwrap();
        out.copy_from(spool, data.len() as u64).unwrap();
        let after = allocated();
        let copied = out.finish().unwrap();
        assert!(
            std::fs::read(copied.path()).unwrap() == data,
            "copy differs"
        );
        if after == before {
            // A file system that cannot punch holes (the blocks are freed when it is removed).
            // SAFETY: a valid descriptor; the call reads no memory of ours.
            let punched = unsafe {
                use std::os::fd::AsRawFd as _;
                libc::fallocate(
                    probe.as_raw_fd(),
                    libc::FALLOC_FL_PUNCH_HOLE | libc::FALLOC_FL_KEEP_SIZE,
                    0,
                    4096,
                )
            };
            if punched != 0 {
                eprintln!(
                    "skipped: the file system of {} punches no holes",
                    dir.path().display()
                );
                return;
            }
        }
        assert!(
            after < 1 << 20,
            "{after} bytes of the staged data still allocated"
        );
    }

    /// Once the primitives are decoded the input's bytes are freed, and the output still holds
    /// every input view it keeps (here the positions, which a line primitive also draws):
    /// they were written when the output began.
    #[test]
    fn released_input_bytes_are_freed_and_the_views_kept_are_still_written() {
        let lines = serde_json::json!({ "attributes": { "POSITION": 0 }, "mode": 1 });
        let with_lines = || triangle_and(std::slice::from_ref(&lines));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.glb");
        let opts = WriteOptions::default();
        let mut in_memory = with_lines();
        replace_primitive_owned(&mut in_memory, 0, 0, strip(1000)).unwrap();
        let expected = write::encode(&in_memory, &path, &opts).unwrap();

        let mut doc = with_lines();
        let mut out =
            StreamedOutput::begin(&doc, &path, &opts, &[(0, 0)], StreamMode::Write).unwrap();
        assert_eq!(doc.buffer_bytes(), 36);
        out.release_input(&mut doc);
        assert_eq!(doc.buffer_bytes(), 0);
        replace_primitive_owned(&mut doc, 0, 0, strip(1000)).unwrap();
        out.flush(&mut doc, true).unwrap();
        out.finish(&mut doc).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), expected[0].to_bytes());
    }

    /// The last mesh's arrays, kept in memory for a `.glb` until its JSON is known, are let go
    /// by the document as they are written: after `finish` it holds none of them (they were
    /// freed with the pieces written), and the file is byte for byte what the writer gives.
    #[test]
    fn finishing_lets_go_of_the_arrays_it_writes() {
        let dir = tempfile::tempdir().unwrap();
        let opts = WriteOptions::default();
        for name in ["out.glb", "out.gltf"] {
            let path = dir.path().join(name);
            let mut in_memory = triangle();
            replace_primitive_owned(&mut in_memory, 0, 0, strip(100_000)).unwrap();
            let expected = write::encode(&in_memory, &path, &opts).unwrap();

            let mut doc = triangle();
            let mut out =
                StreamedOutput::begin(&doc, &path, &opts, &[(0, 0)], StreamMode::Write).unwrap();
            replace_primitive_owned(&mut doc, 0, 0, strip(100_000)).unwrap();
            out.flush(&mut doc, true).unwrap();
            if name == "out.glb" {
                // Kept for the end: the binary chunk follows the JSON.
                assert!(doc.buffer_bytes() > 100_000 * 12, "{name}");
            }
            out.finish(&mut doc).unwrap();
            // Only the input's buffer (36 bytes) is left.
            assert!(
                doc.buffer_bytes() < 1000,
                "{name}: {} held",
                doc.buffer_bytes()
            );
            for file in &expected {
                assert!(
                    std::fs::read(&file.path).unwrap() == file.to_bytes(),
                    "{} differs",
                    file.path.display()
                );
            }
        }
    }

    #[test]
    fn views_added_after_the_last_flush_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.gltf");
        let mut doc = triangle();
        let out = StreamedOutput::begin(
            &doc,
            &path,
            &WriteOptions::default(),
            &[(0, 0)],
            StreamMode::Write,
        )
        .unwrap();
        replace_primitive_owned(&mut doc, 0, 0, strip(10)).unwrap();
        assert!(out.finish(&mut doc).is_err());
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "temporary files left: {left:?}");
    }
}
