//! Where every output vertex of one group goes, by index arithmetic on the input triangles
//! alone, before anything is evaluated.
//!
//! Source triangles are taken in order; each one owns the corners and input edges it is the
//! first to use, and its interior. Its vertices come as one contiguous block: owned corners,
//! owned edges (`n − 1` samples each, walked from the lower input vertex index), interior (in
//! the plan's first-use order). So every block of consecutive source triangles owns a
//! contiguous vertex range and `n²` triangles per source triangle: blocks are written in
//! parallel into disjoint slices of the final buffers, and the numbering never depends on how
//! the work was split. It deliberately evaluates nothing.

use std::ops::Range;

use rayon::slice::ParallelSliceMut as _;

use crate::mesh::TriMesh;
use crate::topology::Topology;

use super::is_crease;

/// Output vertex numbering of one group of source triangles.
#[derive(Debug, Clone)]
pub(crate) struct GroupLayout {
    /// Per source triangle of the group, its first owned vertex; one more entry holds the
    /// group's vertex count.
    pub base: Vec<u32>,
    /// Per corner (`3·offset + c`): its output vertex.
    pub corner_slot: Vec<u32>,
    /// Per half-edge (`3·offset + k`, the edge opposite corner `k`): the output vertex of its
    /// first sample, walked from the lower input vertex index.
    pub edge_slot: Vec<u32>,
    /// Per source triangle: bit `c` set if it writes corner `c`, bit `3 + k` if it writes the
    /// samples of edge `k`.
    pub owns: Vec<u8>,
}

impl GroupLayout {
    /// Numbers the output vertices of triangles `range` of `mesh` at level `n`, `interior`
    /// points per triangle. `h` decides which interior edges are creases: their two sides get
    /// their own samples.
    pub fn new(
        mesh: &TriMesh,
        topo: &Topology,
        h: &[f64],
        n: u32,
        interior: usize,
        range: Range<usize>,
    ) -> GroupLayout {
        let per_edge = n.saturating_sub(1);
        Self::with_counts(mesh, topo, h, range, |_, _| per_edge, |_| interior as u32)
    }

    /// As [`GroupLayout::new`], with `per_edge(tri, k)` samples on the edge opposite corner `k`
    /// of source triangle `tri` (the same for every triangle on that input edge) and
    /// `interior(tri)` interior points.
    pub fn with_counts(
        mesh: &TriMesh,
        topo: &Topology,
        h: &[f64],
        range: Range<usize>,
        per_edge: impl Fn(usize, usize) -> u32,
        interior: impl Fn(usize) -> u32,
    ) -> GroupLayout {
        let count = range.len();
        let first_half = first_use_of_each_input_edge(mesh, topo, h, range.clone());
        let mut corner_of_vertex = vec![u32::MAX; mesh.positions.len()];
        let mut layout = GroupLayout {
            base: Vec::with_capacity(count + 1),
            corner_slot: vec![0; 3 * count],
            edge_slot: vec![0; 3 * count],
            owns: vec![0; count],
        };
        let mut next = 0u32;
        for (offset, tri) in range.enumerate() {
            layout.base.push(next);
            let mut owns = 0u8;
            for (c, &v) in mesh.triangles[tri].iter().enumerate() {
                let slot = &mut corner_of_vertex[v as usize];
                if *slot == u32::MAX {
                    *slot = next;
                    next += 1;
                    owns |= 1 << c;
                }
                layout.corner_slot[3 * offset + c] = *slot;
            }
            for k in 0..3 {
                let half = 3 * offset + k;
                let first = first_half[half] as usize;
                layout.edge_slot[half] = if first == half {
                    owns |= 8 << k;
                    let samples = per_edge(tri, k);
                    next += samples;
                    next - samples
                } else {
                    layout.edge_slot[first]
                };
            }
            layout.owns[offset] = owns;
            next += interior(tri);
        }
        layout.base.push(next);
        layout
    }

    /// Number of output vertices.
    pub fn vertex_count(&self) -> usize {
        *self.base.last().unwrap_or(&0) as usize
    }
}

/// For each half-edge of the group, the first half-edge (in group order) of the same input
/// edge: the unordered pair of input vertex indices, kept apart per side on creases. A sort
/// over the input's half-edges, not the output's vertices.
fn first_use_of_each_input_edge(
    mesh: &TriMesh,
    topo: &Topology,
    h: &[f64],
    range: Range<usize>,
) -> Vec<u32> {
    let mut keys: Vec<(u32, u32, u32, u32)> = Vec::with_capacity(3 * range.len());
    for (offset, tri) in range.enumerate() {
        let t = mesh.triangles[tri];
        for k in 0..3 {
            let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
            let (lo, hi) = (a.min(b), a.max(b));
            let half = (3 * offset + k) as u32;
            let side = if is_crease(topo, h, topo.tri_edges[tri][k]) {
                half
            } else {
                u32::MAX
            };
            keys.push((lo, hi, side, half));
        }
    }
    // Keys are distinct (each holds its half-edge), so the parallel sort's order is the order.
    keys.par_sort_unstable();
    let mut first = vec![0u32; keys.len()];
    let mut run_start = 0;
    for i in 0..keys.len() {
        let (a, b) = (keys[run_start], keys[i]);
        if (a.0, a.1, a.2) != (b.0, b.1, b.2) {
            run_start = i;
        }
        // Sorted by half-edge within a run, so the run's first entry is its first use.
        first[keys[i].3 as usize] = keys[run_start].3;
    }
    first
}
