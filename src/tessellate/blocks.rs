//! Cuts a group's output buffers into disjoint per-block slices, so that threads fill the
//! final arrays in place (no per-block buffers to concatenate afterwards). Both the uniform and
//! the per-edge-count tessellator use it; it knows nothing of patterns or surfaces.

use std::ops::Range;

use super::{DenseMesh, VertexSource};

/// One block of consecutive source triangles and the slices of the final buffers it owns.
pub(super) struct Block<'a> {
    /// Triangle offsets within the group.
    pub tris: Range<usize>,
    /// First output vertex of the block, numbered in the whole group.
    pub vertex_base: usize,
    /// First index of the block, counted in the whole group.
    pub index_base: usize,
    pub positions: &'a mut [[f32; 3]],
    pub normals: &'a mut [[f32; 3]],
    /// `None` while the vertices are evaluated on the uniform path: its sources are written
    /// afterwards, from the numbering alone (see [`super::Tessellation::finish`]).
    pub sources: Option<&'a mut [VertexSource]>,
    pub indices: &'a mut [u32],
}

impl Block<'_> {
    /// Writes output vertex `slot` (numbered in the whole group).
    #[inline]
    pub fn put(&mut self, slot: usize, position: [f32; 3], normal: [f32; 3], source: VertexSource) {
        let at = slot - self.vertex_base;
        self.positions[at] = position;
        self.normals[at] = normal;
        if let Some(sources) = self.sources.as_deref_mut() {
            sources[at] = source;
        }
    }
}

/// The blocks of `out` for the triangle ranges `blocks` (consecutive, covering the group from
/// offset 0); `vertex_at(t)` and `index_at(t)` are the first output vertex and the first index
/// of triangle offset `t` (`t` up to the group's end). Blocks get sources only where `out`
/// holds one per vertex, and as many indices as `index_at` gives (none while the uniform path
/// evaluates vertices: `index_at` is 0 throughout then).
pub(super) fn split<'a>(
    out: &'a mut DenseMesh,
    blocks: impl IntoIterator<Item = Range<usize>>,
    vertex_at: impl Fn(usize) -> usize,
    index_at: impl Fn(usize) -> usize,
) -> Vec<Block<'a>> {
    let with_sources = out.sources.len() == out.positions.len();
    let (mut positions, mut normals, mut sources, mut indices) = (
        &mut out.positions[..],
        &mut out.normals[..],
        &mut out.sources[..],
        &mut out.indices[..],
    );
    let mut cut = Vec::new();
    for tris in blocks {
        let (vertex_base, index_base) = (vertex_at(tris.start), index_at(tris.start));
        let vertices = vertex_at(tris.end) - vertex_base;
        let (p, rest_p) = std::mem::take(&mut positions).split_at_mut(vertices);
        let (n, rest_n) = std::mem::take(&mut normals).split_at_mut(vertices);
        let (s, rest_s) = if with_sources {
            let (s, rest) = std::mem::take(&mut sources).split_at_mut(vertices);
            (Some(s), rest)
        } else {
            (None, &mut [][..])
        };
        let (i, rest_i) =
            std::mem::take(&mut indices).split_at_mut(index_at(tris.end) - index_base);
        (positions, normals, sources, indices) = (rest_p, rest_n, rest_s, rest_i);
        cut.push(Block {
            tris,
            vertex_base,
            index_base,
            positions: p,
            normals: n,
            sources: s,
            indices: i,
        });
    }
    cut
}
