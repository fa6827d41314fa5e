//! Uniform tessellation of a whole mesh: every source triangle becomes `n²` triangles on the
//! barycentric lattice of level `n`, with shared samples evaluated once.
//!
//! It deliberately knows nothing of glTF or attributes other than position and normal: each
//! output vertex records where it came from ([`VertexSource`]) and [`crate::attributes`] carries
//! the rest.
//!
//! # Watertightness
//!
//! Two triangles that share a welded edge take the positions of its samples from one evaluation
//! (the edge's lowest-numbered triangle, in the edge's canonical direction), and a corner's
//! position is the input vertex's own. Positions along a shared edge are therefore
//! bit-identical on both sides, whatever the surface scheme and whatever the rounding of either
//! side's own evaluation.
//!
//! # Where output vertices are split
//!
//! Output vertices are numbered per group (one group per output primitive). A corner sample is
//! one output vertex per input vertex; an edge sample is one output vertex per input edge (the
//! unordered pair of input vertex indices). So two triangles that referenced the same input
//! vertices share output vertices, and where the input split a vertex (a UV seam, a hard edge)
//! the output is split too, with identical positions. A crease (an interior edge whose `h` is 0)
//! is also split, because the surface's normal jumps there.
//!
//! # Speed
//!
//! Everything that depends on the level alone is planned once (`plan.rs`); the vertex numbering
//! of a group is index arithmetic on the input triangles (`layout.rs`), so every block of
//! consecutive source triangles owns a contiguous range of the final vertex and index buffers.
//! Each output vertex is evaluated once: a corner is the input vertex (no evaluation), the
//! samples of a welded edge are evaluated by the triangle that writes them, straight into the
//! output (no array of edge samples in between; a triangle that owns a split copy of them
//! evaluates the edge's evaluating side once more for the positions and its own side for the
//! normals), and each triangle evaluates only its interior
//! ([`LatticePart`]). A triangle asks for the edges it owns and its
//! interior in one call ([`Surface::evaluate_lattice_parts`]), so that the surface rebuilds the
//! triangle's net once and composes each neighbour's net once for all of them (on the 100k
//! icosphere, 13% fewer instructions in evaluation at level 3, 3% at level 2; on the 10k
//! icosphere at level 16, 6%). That per-triangle loop is one piece of code
//! (`emit.rs`) for this uniform path and the per-edge-count path (`adaptive.rs`).
//! Blocks run in parallel (rayon) and write straight into those ranges: no per-vertex
//! allocation, no hash map, and the same bytes at any thread count. Triangles come out in
//! cache-friendly bands and vertices in order of first use, so meshoptimizer's passes have
//! little left to do (`optimize.rs` measures it).
//!
//! # Memory
//!
//! The uniform path writes a group in two halves: the vertices while the surface is needed
//! ([`tessellate_vertices`]), then the triangles and the vertex sources from the numbering
//! alone ([`Tessellation::finish`]), so that the pipeline frees the surface in between. On the
//! 1M-triangle icosphere at level 2 that keeps the G² surface (88 MB) and the index and source
//! buffers (64 MB) from being held at once: the heap's peak fell from 401 MB to 308 MB.

mod adaptive;
mod blocks;
mod chord;
mod coarsen;
mod counts;
mod emit;
mod estimate;
mod fill;
mod held;
mod kept_patterns;
mod lattice_edges;
mod layout;
mod pairs;
mod plan;
mod rows;
mod transition;

use crate::mesh::TriMesh;
use crate::surface::{lattice_bary, LatticePart, Surface};
use crate::topology::{EdgeId, Topology};
use blocks::Block;
use layout::GroupLayout;
use plan::LatticePlan;
use rayon::prelude::*;
use std::ops::Range;

pub use adaptive::{tessellate_with_counts, tessellate_with_held};
pub use chord::chord_error;
pub use counts::{ChordErrors, SegmentCounts, PROBE_KEPT_BYTES, PROBE_LEVEL};
pub use held::{HeldInteriors, HELD_BYTES};
pub use pairs::Pair;
pub use rows::{RowPoint, ROW_LEVEL};

/// Where an output vertex was sampled: a source triangle (index into the whole mesh) and a point
/// of that triangle's level-n lattice. Attributes are interpolated from these.
///
/// Kept to eight bytes because there is one per output vertex: with the barycentrics stored as
/// three floats it was 16 bytes, a quarter of the dense mesh's memory, and on a 6.45 M-triangle
/// output every MiB of fresh memory is time spent in page faults.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct VertexSource {
    /// Source triangle in the whole mesh.
    pub tri: u32,
    level: u8,
    i: u8,
    j: u8,
}

impl VertexSource {
    /// Lattice point `(i, j)` of triangle `tri` at level `level`: barycentrics
    /// `((n − i − j)/n, i/n, j/n)` in the triangle's corner order, as
    /// [`lattice_bary`] numbers them.
    ///
    /// # Panics
    /// If `level` is 0 or above [`MAX_TESSELLATION_LEVEL`], or `i + j > level`.
    pub fn lattice(tri: u32, level: u32, i: u32, j: u32) -> Self {
        assert!(
            (1..=MAX_TESSELLATION_LEVEL).contains(&level) && i + j <= level,
            "lattice point ({i}, {j}) of level {level}"
        );
        VertexSource {
            tri,
            level: level as u8,
            i: i as u8,
            j: j as u8,
        }
    }

    /// Barycentric coordinates in the source triangle's corner order. Exact at corners (one
    /// coordinate is 1.0, the others 0.0) and along edges (one is 0.0).
    #[inline]
    pub fn bary(self) -> [f32; 3] {
        let n = u32::from(self.level);
        lattice_bary(n, u32::from(self.i), u32::from(self.j)).map(|x| x as f32)
    }

    /// The lattice coordinates `(n − i − j, i, j)`, one per corner.
    #[inline]
    fn steps(self) -> [u8; 3] {
        [self.level - self.i - self.j, self.i, self.j]
    }

    /// The corner this vertex sits on, if it is one.
    #[inline]
    pub fn corner(self) -> Option<usize> {
        self.steps().iter().position(|&s| s == self.level)
    }

    /// The corner with the largest barycentric coordinate, ties to the lowest corner: read from
    /// the integer lattice coordinates, which order exactly as the barycentrics do.
    #[inline]
    pub fn nearest_corner(self) -> usize {
        let steps = self.steps();
        (1..3).fold(0, |best, c| if steps[c] > steps[best] { c } else { best })
    }
}

/// The finest level the tessellator takes (a lattice coordinate is stored in a byte; the
/// command line allows up to [`crate::options::MAX_LEVEL`]).
pub const MAX_TESSELLATION_LEVEL: u32 = u8::MAX as u32;
const _: () = assert!(crate::options::MAX_LEVEL <= MAX_TESSELLATION_LEVEL);

/// The dense output of one group of source triangles.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DenseMesh {
    /// Output positions.
    pub positions: Vec<[f32; 3]>,
    /// Output unit normals, from the surface.
    pub normals: Vec<[f32; 3]>,
    /// For each output vertex, where it was sampled.
    pub sources: Vec<VertexSource>,
    /// Triangle list, three indices per triangle, wound like the source triangle.
    pub indices: Vec<u32>,
}

/// Number of output triangles and an upper bound on output vertices for `tris` source triangles
/// at level `level` (used to refuse work that would not fit in memory).
pub fn output_size(tris: usize, level: u32) -> (u64, u64) {
    let n = u64::from(level);
    let t = tris as u64;
    (t * n * n, t * ((n + 1) * (n + 2) / 2))
}

/// Output triangles per parallel block: large enough that a block's setup is noise, small
/// enough that two threads stay balanced on a few thousand input triangles.
const BLOCK_TRIANGLES: usize = 16 * 1024;

/// Blocks per thread at least, so that threads stay balanced when a group has few output
/// triangles (see [`block_ranges`]).
const BLOCKS_PER_THREAD: usize = 4;

/// Source triangles per block at least: below, a block's setup is no longer noise.
const MIN_BLOCK_TRIS: usize = 64;

/// Tessellates `groups` (contiguous triangle ranges of `mesh`, one per output primitive) at
/// level `level` (≥ 1). `h` is the blend width per welded edge, used only to decide which
/// interior edges are creases (h = 0) and get split output vertices.
///
/// # Panics
/// If `level` is above [`MAX_TESSELLATION_LEVEL`] (a caller bug: the options refuse it).
pub fn tessellate(
    mesh: &TriMesh,
    topo: &Topology,
    h: &[f64],
    surface: &dyn Surface,
    level: u32,
    groups: &[Range<usize>],
) -> Vec<DenseMesh> {
    tessellate_vertices(mesh, topo, h, surface, level, groups).finish()
}

/// The first half of [`tessellate`]: every output vertex evaluated and written, the triangles
/// and the vertex sources still to come ([`Tessellation::finish`]). Those depend on the
/// numbering alone, not on the surface, so a caller that is done with the surface frees it
/// in between: on a million-triangle input at level 2 the G² surface (88 bytes per input
/// triangle) and the indices and sources (64 bytes per input triangle) are then never held at
/// once.
///
/// # Panics
/// As [`tessellate`].
pub fn tessellate_vertices<'a>(
    mesh: &'a TriMesh,
    topo: &Topology,
    h: &[f64],
    surface: &dyn Surface,
    level: u32,
    groups: &[Range<usize>],
) -> Tessellation<'a> {
    assert!(
        level <= MAX_TESSELLATION_LEVEL,
        "level {level} is above {MAX_TESSELLATION_LEVEL}"
    );
    let plan = LatticePlan::new(level.max(1));
    let groups = groups
        .par_iter()
        .map(|range| tessellate_group(mesh, topo, h, surface, &plan, range.clone()))
        .collect();
    Tessellation {
        meshes: Vec::new(),
        numbering: Some(Numbering { mesh, plan, groups }),
    }
}

/// A tessellation, possibly with only its vertices written (see [`tessellate_vertices`]).
pub struct Tessellation<'a> {
    /// The finished meshes, when nothing is left to write.
    meshes: Vec<DenseMesh>,
    /// What writes the rest of each group: its vertices written, its numbering kept.
    numbering: Option<Numbering<'a>>,
}

/// The uniform path's groups between their two halves.
struct Numbering<'a> {
    mesh: &'a TriMesh,
    plan: LatticePlan,
    /// Per group: its first source triangle, its vertex numbering, its vertices.
    groups: Vec<(usize, GroupLayout, DenseMesh)>,
}

impl Tessellation<'_> {
    /// Meshes that are complete already (the per-edge-count path writes everything in one pass).
    pub fn done(meshes: Vec<DenseMesh>) -> Self {
        Tessellation {
            meshes,
            numbering: None,
        }
    }

    /// The meshes, with their triangles and vertex sources written: no surface is read.
    pub fn finish(self) -> Vec<DenseMesh> {
        let Some(Numbering { mesh, plan, groups }) = self.numbering else {
            return self.meshes;
        };
        groups
            .into_par_iter()
            .map(|(first_tri, layout, mut dense)| {
                number_group(mesh, &plan, first_tri, &layout, &mut dense);
                dense
            })
            .collect()
    }
}

/// The triangle that evaluates the samples of welded edge `e` for everyone, and the corner its
/// side of the edge is opposite: the edge's lowest-numbered triangle, its first use (the uses
/// are kept in (triangle, corner) order, see [`crate::topology::Topology::edge_uses`]). Reading the first
/// use instead of searching them all keeps this constant time: it is asked once per triangle
/// side, so a search made a book of many triangles on one edge quadratic.
fn evaluator(topo: &Topology, e: usize) -> Option<(usize, usize)> {
    Some(topo.edge_uses(EdgeId(e as u32)).first()?.at())
}

/// Whether the edge opposite corner `k` of `tri`, walked from corner `k+1` to corner `k+2`,
/// runs in its welded edge's canonical direction.
fn canonical_forward(topo: &Topology, tri: usize, k: usize) -> bool {
    let from = topo.tri_verts[tri][(k + 1) % 3];
    from == topo.edge_verts(topo.tri_edges[tri][k])[0]
}

fn is_crease(topo: &Topology, h: &[f64], e: EdgeId) -> bool {
    h.get(e.0 as usize).is_some_and(|&v| v == 0.0) && topo.edge_uses(e).len() >= 2
}

/// Position and normal of corner `c` of `tri` as written: the vertex's own position, not its
/// welded representative (welding equates -0.0 and +0.0, and the input's bits are kept), and
/// its normalized input normal (the contract of `Surface::evaluate` at a corner); only a
/// degenerate input normal needs the surface's fallback.
fn corner_vertex(
    mesh: &TriMesh,
    surface: &dyn Surface,
    tri: usize,
    c: usize,
) -> ([f32; 3], [f32; 3]) {
    let v = mesh.triangles[tri][c] as usize;
    let normal = match mesh.normals[v].try_normalize() {
        Some(normal) => normal,
        None => {
            let mut bary = [0.0; 3];
            bary[c] = 1.0;
            surface.evaluate(tri, bary).normal
        }
    };
    (
        mesh.positions[v].as_vec3().to_array(),
        normal.as_vec3().to_array(),
    )
}

/// What every block reads.
struct Shared<'a> {
    mesh: &'a TriMesh,
    topo: &'a Topology,
    surface: &'a dyn Surface,
    plan: &'a LatticePlan,
    layout: &'a GroupLayout,
    first_tri: usize,
}

/// The vertices of one group, evaluated and written, with the numbering that places them.
fn tessellate_group(
    mesh: &TriMesh,
    topo: &Topology,
    h: &[f64],
    surface: &dyn Surface,
    plan: &LatticePlan,
    range: Range<usize>,
) -> (usize, GroupLayout, DenseMesh) {
    let n = plan.n;
    let layout = GroupLayout::new(mesh, topo, h, n, plan.interior, range.clone());
    let vertex_count = layout.vertex_count();
    // The pages are zeroed by the kernel as they are first written, in parallel below.
    let mut out = DenseMesh {
        positions: vec![[0.0; 3]; vertex_count],
        normals: vec![[0.0; 3]; vertex_count],
        sources: Vec::new(),
        indices: Vec::new(),
    };
    let blocks = blocks::split(
        &mut out,
        block_ranges(n, range.len()),
        |t| layout.base[t] as usize,
        |_| 0,
    );
    let shared = Shared {
        mesh,
        topo,
        surface,
        plan,
        layout: &layout,
        first_tri: range.start,
    };
    blocks
        .into_par_iter()
        .for_each(|block| tessellate_block(&shared, block));
    (range.start, layout, out)
}

/// The blocks of a group of `len` source triangles at level `n`: consecutive triangle ranges
/// of about [`BLOCK_TRIANGLES`] output triangles, and at least [`BLOCKS_PER_THREAD`] per
/// thread where the group is too small for that (but no fewer than [`MIN_BLOCK_TRIS`] source
/// triangles each). Without the second bound a 10k-triangle mesh at level 2 made three blocks
/// (4,096, 4,096 and 1,488 triangles), so one thread did two thirds of the work, and at level
/// 1 one block, which one thread did alone. Blocks only cut the output buffers: how many
/// there are changes no output bit.
fn block_ranges(n: u32, len: usize) -> impl Iterator<Item = Range<usize>> {
    let by_output = (BLOCK_TRIANGLES / (n * n) as usize).max(1);
    let by_threads = len
        .div_ceil(BLOCKS_PER_THREAD * rayon::current_num_threads())
        .max(MIN_BLOCK_TRIS);
    let tris_per_block = by_output.min(by_threads);
    (0..len)
        .step_by(tris_per_block)
        .map(move |start| start..(start + tris_per_block).min(len))
}

/// The second half of a group: its triangles and the source of every vertex, from the
/// numbering alone (the same slots [`tessellate_block`] gave the writer).
fn number_group(
    mesh: &TriMesh,
    plan: &LatticePlan,
    first_tri: usize,
    layout: &GroupLayout,
    out: &mut DenseMesh,
) {
    let n = plan.n;
    let vertex_count = layout.vertex_count();
    let tris = layout.owns.len();
    let per_tri_indices = 3 * (n * n) as usize;
    // Every slot is overwritten below; filling in parallel spreads the first touch of the
    // pages (the indices are zeroed by the kernel as they are first written).
    out.sources = Vec::with_capacity(vertex_count);
    out.sources.par_extend(rayon::iter::repeat_n(
        VertexSource::lattice(0, 1, 0, 0),
        vertex_count,
    ));
    out.indices = vec![0; tris * per_tri_indices];
    let blocks = blocks::split(
        out,
        block_ranges(n, tris),
        |t| layout.base[t] as usize,
        |t| t * per_tri_indices,
    );
    blocks.into_par_iter().for_each(|mut block| {
        let mut local = vec![0u32; plan.len];
        for offset in block.tris.clone() {
            number_triangle(
                mesh, plan, layout, first_tri, offset, &mut block, &mut local,
            );
        }
    });
}

/// Writes the sources of the vertices triangle `offset` of the group owns and its triangles,
/// numbering its lattice as [`tessellate_block`] does through [`emit::TriangleWriter`].
fn number_triangle(
    mesh: &TriMesh,
    plan: &LatticePlan,
    layout: &GroupLayout,
    first_tri: usize,
    offset: usize,
    block: &mut Block<'_>,
    local: &mut [u32],
) {
    let n = plan.n;
    let tri = first_tri + offset;
    let corners = mesh.triangles[tri];
    let owns = layout.owns[offset];
    let base = block.vertex_base;
    let sources = block
        .sources
        .as_deref_mut()
        .expect("numbered blocks hold sources");
    let source = |li: usize| plan.source(tri, li);
    for (c, &li) in plan.corners.iter().enumerate() {
        let slot = layout.corner_slot[3 * offset + c] as usize;
        local[li as usize] = slot as u32;
        if owns & (1 << c) != 0 {
            sources[slot - base] = source(li as usize);
        }
    }
    for (k, lis) in plan.edges.iter().enumerate() {
        let first_slot = layout.edge_slot[3 * offset + k] as usize;
        let ascending = corners[(k + 1) % 3] <= corners[(k + 2) % 3];
        let owned = owns & (8 << k) != 0;
        for m in 1..n {
            let slot = emit::edge_slot(first_slot, ascending, n, m);
            let li = lis[(m - 1) as usize] as usize;
            local[li] = slot as u32;
            if owned {
                sources[slot - base] = source(li);
            }
        }
    }
    if plan.interior > 0 {
        let first_slot = layout.base[offset + 1] as usize - plan.interior;
        for (rank, &(li, _)) in plan.interior_by_rank.iter().enumerate() {
            local[li as usize] = (first_slot + rank) as u32;
            sources[first_slot + rank - base] = source(li as usize);
        }
    }
    let per_tri_indices = 3 * (n * n) as usize;
    let start = (offset - block.tris.start) * per_tri_indices;
    emit::triangles(
        &mut block.indices[start..start + per_tri_indices],
        &plan.triangles,
        local,
    );
}

/// Evaluates and writes the vertices a block owns (their triangles and sources come after, in
/// [`number_group`]). Each output vertex is evaluated once: corners are the input vertices,
/// edge samples come from the shared pass (their normals too, unless this triangle is not the
/// edge's evaluator), and only the interior is evaluated here.
fn tessellate_block(shared: &Shared<'_>, mut block: Block<'_>) {
    let Shared {
        mesh,
        topo,
        surface,
        plan,
        layout,
        first_tri,
    } = *shared;
    let n = plan.n;
    let mut writer = emit::TriangleWriter::new(mesh, topo, surface);
    let mut local = vec![0u32; plan.len];
    let mut parts = Vec::with_capacity(4);
    for offset in block.tris.clone() {
        let tri = first_tri + offset;
        let corners = mesh.triangles[tri];
        let owns = layout.owns[offset];
        // Every part this triangle evaluates, in one call: its owned edges and its interior.
        // At level 1 an edge has no samples: nothing is asked of the surface.
        parts.clear();
        parts.extend(
            (0..3u8)
                .filter(|&k| n > 1 && owns & (8 << k) != 0)
                .map(|k| (n, LatticePart::Edge(k))),
        );
        if plan.interior > 0 {
            parts.push((n, LatticePart::Interior));
        }
        if !parts.is_empty() {
            writer.evaluate_parts(tri, &parts);
        }
        // The level was checked once in `tessellate`, the coordinates come from its plan.
        let source = |li: usize| plan.source(tri, li);
        for (c, &li) in plan.corners.iter().enumerate() {
            let slot = layout.corner_slot[3 * offset + c] as usize;
            let owned = owns & (1 << c) != 0;
            writer.corner(
                &mut block,
                &mut local,
                tri,
                c,
                li as usize,
                slot,
                owned,
                source(li as usize),
            );
        }
        for (k, lis) in plan.edges.iter().enumerate() {
            writer.edge(
                &mut block,
                &mut local,
                tri,
                k,
                n,
                layout.edge_slot[3 * offset + k] as usize,
                corners[(k + 1) % 3] <= corners[(k + 2) % 3],
                owns & (8 << k) != 0,
                |m| lis[(m - 1) as usize] as usize,
                source,
            );
        }
        if plan.interior > 0 {
            writer.interior(
                &mut block,
                &mut local,
                tri,
                n,
                layout.base[offset + 1] as usize - plan.interior,
                plan.interior_by_rank
                    .iter()
                    .map(|&(li, index)| (li as usize, index as usize)),
                source,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Consecutive ranges from 0 to `len`, none empty.
    fn assert_cover(blocks: &[Range<usize>], len: usize) {
        assert_eq!(blocks.first().map_or(0, |b| b.start), 0);
        assert_eq!(blocks.last().map_or(0, |b| b.end), len);
        assert!(blocks.windows(2).all(|w| w[0].end == w[1].start));
        assert!(blocks.iter().all(|b| !b.is_empty()));
    }

    #[test]
    fn small_groups_at_low_levels_get_blocks_for_every_thread() {
        let threads = rayon::current_num_threads();
        for (n, len) in [(1, 9_680), (2, 9_680), (4, 9_680), (2, 1_000), (16, 9_680)] {
            let blocks: Vec<_> = block_ranges(n, len).collect();
            assert_cover(&blocks, len);
            let wanted = (BLOCKS_PER_THREAD * threads).min(len / MIN_BLOCK_TRIS);
            assert!(
                blocks.len() >= wanted,
                "level {n}, {len} triangles: {blocks:?}"
            );
            let by_output = BLOCK_TRIANGLES / (n * n) as usize;
            assert!(blocks.iter().all(|b| b.len() <= by_output.max(1)));
        }
    }

    #[test]
    fn large_groups_keep_blocks_of_the_output_size() {
        // About 16k output triangles a block at level 2, unless there are so many threads
        // that the blocks per thread ask for smaller ones.
        let len = 1_003_520;
        let blocks: Vec<_> = block_ranges(2, len).collect();
        assert_cover(&blocks, len);
        let by_threads = len.div_ceil(BLOCKS_PER_THREAD * rayon::current_num_threads());
        let size = (BLOCK_TRIANGLES / 4).min(by_threads);
        assert!(blocks[..blocks.len() - 1].iter().all(|b| b.len() == size));
    }
}
