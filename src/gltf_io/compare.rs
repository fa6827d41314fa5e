//! Compares bytes, as they are produced, with a file on disk (`--check`): the file is read in
//! chunks beside the bytes being fed, never whole, and once one byte differs nothing more is
//! read.
//!
//! It deliberately has one verdict, "the same or not": a file that is missing, unreadable,
//! shorter or longer than the bytes fed is not the same, exactly as a whole-file comparison
//! would say.

use std::fs::File;
use std::io::{Read as _, Seek as _, SeekFrom};
use std::path::Path;

/// How much of the file is read at a time.
const CHUNK: usize = 1 << 20;

/// A running comparison of fed bytes with a file, from some offset of it on.
#[derive(Debug)]
pub(crate) struct Comparison {
    /// The file, while it still matches.
    file: Option<File>,
    /// The byte of the file that the next fed byte is compared with.
    pos: u64,
    buf: Vec<u8>,
}

impl Comparison {
    /// Compares fed bytes with `path` from its first byte.
    pub fn open(path: &Path) -> Comparison {
        Comparison::at(path, Some(0))
    }

    /// Compares fed bytes with `path` from byte `offset` on (`None`: the bytes cannot be in it,
    /// e.g. a file that is not a GLB where one is expected).
    pub fn at(path: &Path, offset: Option<u64>) -> Comparison {
        let file = offset.and_then(|at| {
            let mut f = File::open(path).ok()?;
            f.seek(SeekFrom::Start(at)).ok()?;
            Some(f)
        });
        Comparison {
            file,
            pos: offset.unwrap_or(0),
            buf: Vec::new(),
        }
    }

    /// Compares `bytes` with the file's next bytes.
    pub fn feed(&mut self, bytes: &[u8]) {
        let Some(file) = &mut self.file else {
            return;
        };
        if self.buf.is_empty() {
            self.buf = vec![0; CHUNK];
        }
        for step in bytes.chunks(CHUNK) {
            let on_disk = &mut self.buf[..step.len()];
            if file.read_exact(on_disk).is_err() || on_disk != step {
                self.file = None;
                return;
            }
            self.pos += step.len() as u64;
        }
    }

    /// Whether every byte fed so far matched.
    pub fn matches_so_far(&self) -> bool {
        self.file.is_some()
    }

    /// Whether every byte fed matched and the file ends right after them.
    pub fn finish(self) -> bool {
        self.file
            .and_then(|f| f.metadata().ok())
            .is_some_and(|m| m.len() == self.pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn compare(on_disk: Option<&[u8]>, fed: &[&[u8]]) -> bool {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f");
        if let Some(b) = on_disk {
            std::fs::write(&path, b).unwrap();
        }
        let mut c = Comparison::open(&path);
        for piece in fed {
            c.feed(piece);
        }
        c.finish()
    }

    #[test]
    fn equal_bytes_in_any_pieces_are_the_same() {
        let bytes: Vec<u8> = (0..3 * CHUNK + 5).map(|i| (i * 7 % 251) as u8).collect();
        assert!(compare(Some(&bytes), &[&bytes]));
        let (a, b) = bytes.split_at(CHUNK + 3);
        assert!(compare(Some(&bytes), &[a, &[], b]));
        assert!(compare(Some(b""), &[]));
    }

    #[test]
    fn one_byte_changed_truncated_extended_or_missing_is_not_the_same() {
        let bytes: Vec<u8> = (0..2 * CHUNK + 9).map(|i| (i % 13) as u8).collect();
        for at in [0, CHUNK - 1, CHUNK, bytes.len() - 1] {
            let mut changed = bytes.clone();
            changed[at] ^= 0x10;
            assert!(!compare(Some(&changed), &[&bytes]), "byte {at}");
        }
        assert!(!compare(Some(&bytes[..bytes.len() - 1]), &[&bytes]));
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(!compare(Some(&longer), &[&bytes]));
        assert!(!compare(None, &[&bytes]));
        assert!(!compare(None, &[]));
    }

    #[test]
    fn a_comparison_can_start_inside_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f");
        std::fs::write(&path, b"headBODY").unwrap();
        let mut c = Comparison::at(&path, Some(4));
        c.feed(b"BODY");
        assert!(c.finish());
        let mut c = Comparison::at(&path, None);
        c.feed(b"");
        assert!(!c.matches_so_far());
    }
}
