//! The bytes of one in-memory buffer, and the pieces an output file is made of.
//!
//! A dense mesh's arrays are most of the memory a run holds (tens to hundreds of megabytes).
//! They are stored in the element type the pipeline produced them in, shared by reference
//! counting, and written to disk from where they lie: no stage copies them into a byte buffer,
//! and the writer never concatenates them into one file image first.

use std::ops::Range;
use std::sync::Arc;

/// One buffer's contents.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum BufferData {
    /// Bytes as read from a file, or assembled byte by byte.
    Bytes(Vec<u8>),
    /// 32-bit floats (vertex attributes), stored as the machine holds them. Only made on
    /// little-endian machines, where that already is glTF's byte order.
    Floats(Vec<f32>),
    /// 32-bit unsigned integers (indices), under the same condition as `Floats`.
    Words(Vec<u32>),
    /// A range of a file read whole: a GLB's BIN chunk, left where the read put it rather than
    /// copied out of the file's bytes (tens of megabytes for a large scan).
    FileRange {
        file: Arc<Vec<u8>>,
        range: Range<usize>,
    },
}

impl BufferData {
    /// Floats in glTF's byte order, uncopied where the machine's order is the same.
    pub fn floats(values: Vec<f32>) -> BufferData {
        if cfg!(target_endian = "little") {
            BufferData::Floats(values)
        } else {
            BufferData::Bytes(values.iter().flat_map(|x| x.to_le_bytes()).collect())
        }
    }

    /// Integers in glTF's byte order, uncopied where the machine's order is the same.
    pub fn words(values: Vec<u32>) -> BufferData {
        if cfg!(target_endian = "little") {
            BufferData::Words(values)
        } else {
            BufferData::Bytes(values.iter().flat_map(|x| x.to_le_bytes()).collect())
        }
    }

    /// The contents as glTF bytes.
    pub fn as_bytes(&self) -> &[u8] {
        match self {
            BufferData::Bytes(b) => b,
            BufferData::Floats(v) => meshopt::typed_to_bytes(v),
            BufferData::Words(v) => meshopt::typed_to_bytes(v),
            BufferData::FileRange { file, range } => &file[range.clone()],
        }
    }

    /// Length in bytes.
    pub fn len(&self) -> usize {
        self.as_bytes().len()
    }

    /// The byte vector of a buffer that is appended to byte by byte (the scratch buffer), turned
    /// into one first if it held numbers.
    pub fn bytes_mut(&mut self) -> &mut Vec<u8> {
        if !matches!(self, BufferData::Bytes(_)) {
            *self = BufferData::Bytes(self.as_bytes().to_vec());
        }
        match self {
            BufferData::Bytes(b) => b,
            _ => unreachable!("converted above"),
        }
    }
}

impl Default for BufferData {
    fn default() -> Self {
        BufferData::Bytes(Vec::new())
    }
}

/// Part of an output file: bytes made for it, or a range of a document buffer shared with the
/// document.
#[derive(Debug, Clone)]
pub(crate) enum Piece {
    Owned(Vec<u8>),
    Shared {
        data: Arc<BufferData>,
        range: Range<usize>,
    },
}

impl Piece {
    pub fn as_bytes(&self) -> &[u8] {
        match self {
            Piece::Owned(b) => b,
            Piece::Shared { data, range } => &data.as_bytes()[range.clone()],
        }
    }
}

/// A sequence of pieces with their total length. When an output is written as it is produced,
/// its first bytes are already in the file: `on_disk` counts them, and only what follows them
/// is held here.
#[derive(Debug, Clone, Default)]
pub(crate) struct Pieces {
    pieces: Vec<Piece>,
    len: usize,
    on_disk: usize,
}

impl Pieces {
    /// Marks everything up to byte `end` as already written, ending at `end`: only valid while
    /// nothing is held in memory yet.
    pub fn extend_on_disk(&mut self, end: usize) {
        assert!(
            self.pieces.is_empty() && end >= self.len,
            "bytes already on disk come before any held in memory"
        );
        self.len = end;
        self.on_disk = end;
    }

    /// How many of the first bytes are already on disk (not held here).
    pub fn on_disk(&self) -> usize {
        self.on_disk
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub fn push(&mut self, piece: Piece) {
        self.len += piece.as_bytes().len();
        if !piece.as_bytes().is_empty() {
            self.pieces.push(piece);
        }
    }

    pub fn push_bytes(&mut self, bytes: Vec<u8>) {
        self.push(Piece::Owned(bytes));
    }

    /// Zero bytes up to the next multiple of 4.
    pub fn align4(&mut self) {
        let pad = (4 - self.len % 4) % 4;
        if pad != 0 {
            self.push_bytes(vec![0; pad]);
        }
    }

    /// Appends all of `other` (which must be held in memory whole).
    pub fn extend(&mut self, other: Pieces) {
        assert_eq!(other.on_disk, 0, "appended bytes are held in memory");
        self.len += other.len;
        self.pieces.extend(other.pieces);
    }

    /// The pieces held in memory, in order (after the bytes on disk).
    pub fn iter(&self) -> impl Iterator<Item = &[u8]> {
        self.pieces.iter().map(Piece::as_bytes)
    }

    /// The pieces held in memory, in order, given up one by one: a writer frees each (and
    /// the array it shares, once the document has let go of it) as soon as it is written.
    pub fn into_pieces(self) -> impl Iterator<Item = Piece> {
        self.pieces.into_iter()
    }

    /// All pieces in one vector (all of them held in memory).
    pub fn concat(&self) -> Vec<u8> {
        assert_eq!(self.on_disk, 0, "concatenated bytes are held in memory");
        let mut out = Vec::with_capacity(self.len);
        for p in self.iter() {
            out.extend_from_slice(p);
        }
        out
    }
}

impl From<Vec<u8>> for Pieces {
    fn from(bytes: Vec<u8>) -> Self {
        let mut p = Pieces::default();
        p.push_bytes(bytes);
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_stored_little_endian() {
        let f = BufferData::floats(vec![1.0, -2.5]);
        let expected: Vec<u8> = [1.0f32, -2.5]
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        assert_eq!(f.as_bytes(), &expected[..]);
        let w = BufferData::words(vec![7, 0x0102_0304]);
        assert_eq!(w.as_bytes(), &[7, 0, 0, 0, 4, 3, 2, 1]);
        assert_eq!(w.len(), 8);
    }

    #[test]
    fn appending_to_a_number_buffer_keeps_its_bytes() {
        let mut w = BufferData::words(vec![1]);
        w.bytes_mut().push(9);
        assert_eq!(w.as_bytes(), &[1, 0, 0, 0, 9]);
    }

    #[test]
    fn pieces_concatenate_in_order_with_alignment() {
        let data = Arc::new(BufferData::Bytes(vec![10, 11, 12, 13, 14]));
        let mut p = Pieces::default();
        p.push_bytes(vec![1, 2, 3]);
        p.align4();
        p.push(Piece::Shared { data, range: 1..4 });
        assert_eq!(p.len(), 7);
        assert_eq!(p.concat(), vec![1, 2, 3, 0, 11, 12, 13]);
    }
}
