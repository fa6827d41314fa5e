//! Decodes accessors: every component type, `normalized`, `byteStride` and interleaving, matrix
//! column padding, sparse substitution (also without a base buffer view) and zero-filled
//! accessors.
//!
//! Every declared count and offset is checked against the bytes present before anything is
//! allocated. An accessor whose elements lie tightly packed in its buffer view (the common case:
//! no stride, no matrix padding, no sparse substitution) is read in place, borrowing the
//! buffer's bytes: decoding a large primitive then copies each array once, from the file's
//! bytes into the final typed array. It deliberately does not interpret semantics (that is
//! [`super::primitive`]'s job).

use std::borrow::Cow;

use gltf_json::accessor::{ComponentType, Type};
use gltf_json::validation::Checked;
use rayon::prelude::*;

use super::document::Document;
use super::error::{Error, Result};

/// An accessor's elements, tightly packed (no stride, no matrix padding), little-endian:
/// borrowed from the document where they already lie that way, else decoded into a copy.
#[derive(Debug, Clone, PartialEq)]
pub struct Accessor<'a> {
    /// The stored component type.
    pub component_type: ComponentType,
    /// Components per element (1 for SCALAR … 16 for MAT4).
    pub components: usize,
    /// Whether integer components map to [0, 1] or [-1, 1].
    pub normalized: bool,
    /// Number of elements.
    pub count: usize,
    bytes: Cow<'a, [u8]>,
}

/// Components per task of a parallel scan ([`Accessor::find_first`]).
pub(crate) const SCAN_BLOCK: usize = 1 << 14;

/// The first index of `items` that passes `hit`, searched in parallel blocks of
/// [`SCAN_BLOCK`] scanned one after another (a parallel search per item costs more than the
/// test): the same first hit whatever the thread count.
pub(crate) fn first_in_blocks<T: Sync>(
    items: &[T],
    hit: impl Fn(&T) -> bool + Sync,
) -> Option<usize> {
    items
        .par_chunks(SCAN_BLOCK)
        .enumerate()
        .find_map_first(|(b, block)| Some(b * SCAN_BLOCK + block.iter().position(&hit)?))
}

/// Bytes per component.
pub fn component_size(t: ComponentType) -> usize {
    match t {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

/// Components per element.
pub fn type_components(t: Type) -> usize {
    match t {
        Type::Scalar => 1,
        Type::Vec2 => 2,
        Type::Vec3 => 3,
        Type::Vec4 | Type::Mat2 => 4,
        Type::Mat3 => 9,
        Type::Mat4 => 16,
    }
}

/// The accessor type holding `n` components of a vertex attribute.
pub fn vector_type(n: usize) -> Type {
    match n {
        1 => Type::Scalar,
        2 => Type::Vec2,
        3 => Type::Vec3,
        _ => Type::Vec4,
    }
}

/// (rows, bytes per column incl. padding, columns) of one element as stored in a buffer.
fn stored_layout(t: Type, csize: usize) -> (usize, usize, usize) {
    let (rows, cols) = match t {
        Type::Mat2 => (2, 2),
        Type::Mat3 => (3, 3),
        Type::Mat4 => (4, 4),
        other => (type_components(other), 1),
    };
    let col = rows * csize;
    let col_padded = if cols > 1 { col.div_ceil(4) * 4 } else { col };
    (rows, col_padded, cols)
}

/// The bytes [`read`] allocates for accessor `a` (tightly packed), from its declaration alone;
/// saturates instead of overflowing, and is 0 for an accessor whose type is invalid.
pub fn decoded_size(a: &gltf_json::Accessor) -> u64 {
    match (&a.component_type, &a.type_) {
        (Checked::Valid(ct), Checked::Valid(ty)) => a
            .count
            .0
            .saturating_mul((component_size(ct.0) * type_components(*ty)) as u64),
        _ => 0,
    }
}

/// Reads accessor `index` of `doc`, applying sparse substitution; borrows the document's bytes
/// where they are already tightly packed.
pub fn read(doc: &Document, index: usize, max_bytes: u64) -> Result<Accessor<'_>> {
    let at = format!("accessors[{index}]");
    let a = doc
        .root
        .accessors
        .get(index)
        .ok_or_else(|| Error::invalid(&at, "does not exist"))?;
    let (Checked::Valid(ct), Checked::Valid(ty)) = (&a.component_type, &a.type_) else {
        return Err(Error::invalid(&at, "has an invalid componentType or type"));
    };
    let ct = ct.0;
    let csize = component_size(ct);
    let components = type_components(*ty);
    let (rows, col_bytes, cols) = stored_layout(*ty, csize);
    let elem_stored = col_bytes * cols;
    let elem_packed = components * csize;
    let count = a.count.0;
    let total = count
        .checked_mul(elem_packed as u64)
        .filter(|t| *t <= max_bytes)
        .ok_or_else(|| {
            Error::invalid(
                format!("{at}.count"),
                format!("{count} elements exceed the limit of {max_bytes} bytes"),
            )
        })?;
    let count = count as usize;
    let mut bytes: Cow<'_, [u8]> = Cow::Borrowed(&[]);
    match a.buffer_view {
        Some(view) => {
            let v = &doc.root.buffer_views[view.value()];
            let data = doc.view_bytes(view.value())?;
            let stride = v.byte_stride.map_or(elem_stored, |s| s.0);
            let offset = a.byte_offset.map_or(0, |o| o.0) as usize;
            if count > 0 {
                let need = (count as u64 - 1) * stride as u64 + offset as u64 + elem_stored as u64;
                if need > data.len() as u64 {
                    return Err(Error::invalid(
                        &at,
                        format!(
                            "{count} elements of {elem_stored} bytes at offset {offset} with stride {stride} need {need} bytes, but bufferViews[{}] has {} (expected the data to fit)",
                            view.value(),
                            data.len()
                        ),
                    ));
                }
            }
            if count == 0 {
                // Nothing to read (and the offset need not lie inside the view).
            } else if stride == elem_packed && elem_stored == elem_packed {
                // Already tightly packed: read in place (a sparse accessor copies below).
                bytes = Cow::Borrowed(&data[offset..offset + total as usize]);
            } else {
                let mut packed = Vec::with_capacity(total as usize);
                for i in 0..count {
                    let e = offset + i * stride;
                    for c in 0..cols {
                        let s = e + c * col_bytes;
                        packed.extend_from_slice(&data[s..s + rows * csize]);
                    }
                }
                bytes = Cow::Owned(packed);
            }
        }
        None => bytes = Cow::Owned(vec![0; total as usize]),
    }
    if let Some(sparse) = &a.sparse {
        let sat = format!("{at}.sparse");
        let n = sparse.count.0 as usize;
        if n as u64 > count as u64 {
            return Err(Error::invalid(
                format!("{sat}.count"),
                format!("{n} exceeds the accessor's count {count}"),
            ));
        }
        let Checked::Valid(ict) = &sparse.indices.component_type else {
            return Err(Error::invalid(
                format!("{sat}.indices.componentType"),
                "invalid (expected 5121, 5123 or 5125)",
            ));
        };
        let isize = component_size(ict.0);
        let idata = sparse_slice(
            doc,
            sparse.indices.buffer_view.value(),
            sparse.indices.byte_offset.0,
            n * isize,
            &format!("{sat}.indices"),
        )?;
        let vdata = sparse_slice(
            doc,
            sparse.values.buffer_view.value(),
            sparse.values.byte_offset.0,
            n * elem_stored,
            &format!("{sat}.values"),
        )?;
        let bytes = bytes.to_mut();
        let mut previous = None;
        for k in 0..n {
            let target = read_uint(&idata[k * isize..], ict.0) as usize;
            if target >= count || previous.is_some_and(|p| target <= p) {
                return Err(Error::invalid(
                    format!("{sat}.indices"),
                    format!("index {target} at position {k} is out of range or not increasing (expected strictly increasing values below {count})"),
                ));
            }
            previous = Some(target);
            let mut w = target * elem_packed;
            for c in 0..cols {
                let s = k * elem_stored + c * col_bytes;
                bytes[w..w + rows * csize].copy_from_slice(&vdata[s..s + rows * csize]);
                w += rows * csize;
            }
        }
    }
    Ok(Accessor {
        component_type: ct,
        components,
        normalized: a.normalized,
        count,
        bytes,
    })
}

fn sparse_slice<'a>(
    doc: &'a Document,
    view: usize,
    offset: u64,
    len: usize,
    at: &str,
) -> Result<&'a [u8]> {
    let data = doc.view_bytes(view)?;
    let start = offset as usize;
    data.get(start..start.saturating_add(len)).ok_or_else(|| {
        Error::invalid(
            at,
            format!(
                "{len} bytes at offset {offset} do not fit in bufferViews[{view}] of {} bytes",
                data.len()
            ),
        )
    })
}

fn read_uint(b: &[u8], t: ComponentType) -> u32 {
    match t {
        ComponentType::U8 | ComponentType::I8 => b[0] as u32,
        ComponentType::U16 | ComponentType::I16 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

impl Accessor<'_> {
    /// Component `i` (flat index) as stored, widened without scaling.
    pub fn raw(&self, i: usize) -> f64 {
        let s = component_size(self.component_type);
        let b = &self.bytes[i * s..];
        match self.component_type {
            ComponentType::I8 => b[0] as i8 as f64,
            ComponentType::U8 => b[0] as f64,
            ComponentType::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            ComponentType::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            ComponentType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            ComponentType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        }
    }

    /// Number of components in total (`count × components`).
    pub fn len(&self) -> usize {
        self.count * self.components
    }

    /// Whether the accessor holds no elements.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The first component (flat index and value, widened without scaling as [`Accessor::raw`]
    /// gives it) for which `hit` holds. One tight loop per component type, where calling
    /// [`Accessor::raw`] per component dispatched on the type every time.
    pub fn find(&self, mut hit: impl FnMut(f64) -> bool) -> Option<(usize, f64)> {
        fn scan<const N: usize>(
            bytes: &[u8],
            widen: impl Fn([u8; N]) -> f64,
            hit: &mut impl FnMut(f64) -> bool,
        ) -> Option<(usize, f64)> {
            bytes
                .chunks_exact(N)
                .map(|b| widen(b.try_into().expect("chunks of N bytes")))
                .enumerate()
                .find(|&(_, x)| hit(x))
        }
        let b = &self.bytes[..];
        match self.component_type {
            ComponentType::I8 => scan(b, |x: [u8; 1]| f64::from(x[0] as i8), &mut hit),
            ComponentType::U8 => scan(b, |x: [u8; 1]| f64::from(x[0]), &mut hit),
            ComponentType::I16 => scan(b, |x| f64::from(i16::from_le_bytes(x)), &mut hit),
            ComponentType::U16 => scan(b, |x| f64::from(u16::from_le_bytes(x)), &mut hit),
            ComponentType::U32 => scan(b, |x| f64::from(u32::from_le_bytes(x)), &mut hit),
            ComponentType::F32 => scan(b, |x| f64::from(f32::from_le_bytes(x)), &mut hit),
        }
    }

    /// [`Accessor::find`] for a test that needs no state, run in parallel over the components:
    /// the same first hit whatever the thread count. The reader's data checks (non-finite
    /// floats, indices out of range) are each one such scan over every array of the file, which
    /// for a large mesh cost as much as decoding it.
    pub fn find_first(&self, hit: impl Fn(f64) -> bool + Sync) -> Option<(usize, f64)> {
        fn scan<const N: usize>(
            bytes: &[u8],
            widen: impl Fn([u8; N]) -> f64 + Sync,
            hit: &(impl Fn(f64) -> bool + Sync),
        ) -> Option<(usize, f64)> {
            let at = |b: &[u8]| widen(b.try_into().expect("chunks of N bytes"));
            // Blocks of components scanned one after another: a parallel search per component
            // costs more than the test.
            let k = bytes
                .par_chunks(SCAN_BLOCK * N)
                .enumerate()
                .find_map_first(|(i, block)| {
                    let k = block.chunks_exact(N).position(|b| hit(at(b)))?;
                    Some(i * SCAN_BLOCK + k)
                })?;
            Some((k, at(&bytes[k * N..(k + 1) * N])))
        }
        let b = &self.bytes[..];
        match self.component_type {
            ComponentType::I8 => scan(b, |x: [u8; 1]| f64::from(x[0] as i8), &hit),
            ComponentType::U8 => scan(b, |x: [u8; 1]| f64::from(x[0]), &hit),
            ComponentType::I16 => scan(b, |x| f64::from(i16::from_le_bytes(x)), &hit),
            ComponentType::U16 => scan(b, |x| f64::from(u16::from_le_bytes(x)), &hit),
            ComponentType::U32 => scan(b, |x| f64::from(u32::from_le_bytes(x)), &hit),
            ComponentType::F32 => scan(b, |x| f64::from(f32::from_le_bytes(x)), &hit),
        }
    }

    /// Calls `visit` with every component in order (widened as [`Accessor::find`] does).
    pub fn for_each(&self, mut visit: impl FnMut(f64)) {
        self.find(|x| {
            visit(x);
            false
        });
    }

    /// Every component as `f32`, normalized integers mapped as the spec says
    /// (e.g. `max(c / 127, -1)` for signed bytes); floats are bit-exact.
    pub fn to_f32(&self) -> Vec<f32> {
        if self.component_type == ComponentType::F32 {
            return convert_in_blocks(&self.bytes, f32::from_le_bytes);
        }
        let scale = match (self.normalized, self.component_type) {
            (false, _) => 1.0,
            (true, ComponentType::I8) => 127.0,
            (true, ComponentType::U8) => 255.0,
            (true, ComponentType::I16) => 32767.0,
            (true, ComponentType::U16) => 65535.0,
            (true, _) => 4294967295.0,
        };
        let mut out = Vec::with_capacity(self.len());
        self.for_each(|x| out.push(((x / scale).max(-1.0)) as f32));
        out
    }

    /// Every component as `u32` (for indices, joints and integer IDs).
    pub fn to_u32(&self) -> Vec<u32> {
        let b = &self.bytes[..];
        match self.component_type {
            ComponentType::U8 => b.iter().map(|&x| u32::from(x)).collect(),
            ComponentType::U16 => b
                .chunks_exact(2)
                .map(|x| u32::from(u16::from_le_bytes([x[0], x[1]])))
                .collect(),
            ComponentType::U32 => convert_in_blocks(b, u32::from_le_bytes),
            _ => {
                let mut out = Vec::with_capacity(self.len());
                self.for_each(|x| out.push(x as u32));
                out
            }
        }
    }
}

/// Elements one task of [`convert_in_blocks`] converts: enough that the tasks cost nothing
/// beside the copying.
const CONVERT_BLOCK: usize = 1 << 16;

/// `bytes` read as little-endian elements of `W` bytes each, by `from` (whole elements only).
///
/// In parallel blocks, each a plain loop that compiles to vector moves (a parallel collect of
/// one element at a time cost twenty times the instructions of the serial loop): the output is
/// allocated zeroed, which costs no write, and each block faults in and fills its own pages, so
/// the copy and its page faults, most of the time of a large accessor's decode, are shared out.
fn convert_in_blocks<T, const W: usize>(bytes: &[u8], from: impl Fn([u8; W]) -> T + Sync) -> Vec<T>
where
    T: Copy + Default + Send,
{
    let mut out = vec![T::default(); bytes.len() / W];
    out.par_chunks_mut(CONVERT_BLOCK)
        .zip(bytes.par_chunks(CONVERT_BLOCK * W))
        .for_each(|(out, bytes)| {
            for (o, b) in out.iter_mut().zip(bytes.chunks_exact(W)) {
                *o = from(b.try_into().expect("chunks of W bytes"));
            }
        });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// More than one block and a part of one: every element converted in place, in order,
    /// as one little-endian read of its bytes.
    #[test]
    fn blocks_convert_every_element_in_order() {
        let n = 2 * CONVERT_BLOCK + 12_345;
        let bytes: Vec<u8> = (0..4 * n).map(|i| (i * 7 + i / 5) as u8).collect();
        let floats = convert_in_blocks(&bytes, f32::from_le_bytes);
        let words = convert_in_blocks(&bytes, u32::from_le_bytes);
        assert_eq!(floats.len(), n);
        for (i, b) in bytes.chunks_exact(4).enumerate() {
            let want = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            assert_eq!((floats[i].to_bits(), words[i]), (want, want), "element {i}");
        }
    }
}
