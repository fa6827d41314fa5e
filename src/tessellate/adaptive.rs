//! Tessellation with a segment count per welded edge and an inner level per triangle
//! ([`SegmentCounts`]), each source triangle cut by the transition pattern of its counts.
//!
//! Everything the uniform tessellator guarantees holds here, by the same means: a welded
//! edge's samples are evaluated once, by its evaluator, and written to both sides, so the
//! output is watertight bit for bit; corners are the input vertices; vertices are numbered by
//! [`GroupLayout`] (owned corners, owned edges, interior, per source triangle in order), so
//! blocks write disjoint slices and the bytes do not depend on the thread count; output
//! vertices are split where the input is and across creases. Every output vertex is a lattice
//! point of its own level ([`VertexSource`]), so attributes, split normals, morph targets and
//! skins are carried by the unchanged code of the uniform path.
//!
//! Patterns depend on the counts alone: each distinct `(edge counts, inner level)` is built
//! once and shared (`transition.rs`).

use std::ops::Range;

use rayon::prelude::*;

use super::blocks::{self, Block};
use super::counts::SegmentCounts;
use super::emit;
use super::held::{self, HeldInteriors};
use super::kept_patterns::{self, Kept};
use super::layout::GroupLayout;
use super::pairs::{joined_polygon, Pair};
use super::rows::ROW_LEVEL;
use super::transition::{Pattern, PatternKey};
use super::{DenseMesh, VertexSource, BLOCK_TRIANGLES};
use crate::mesh::TriMesh;
use crate::surface::{LatticePart, Surface, SurfacePoint};
use crate::topology::Topology;

/// Tessellates `groups` of `mesh` with `counts`; `h` as for [`super::tessellate`].
///
/// # Panics
/// If a count is 0 or above 255 (a caller bug: the options cap them).
pub fn tessellate_with_counts(
    mesh: &TriMesh,
    topo: &Topology,
    h: &[f64],
    surface: &dyn Surface,
    counts: &SegmentCounts,
    groups: &[Range<usize>],
) -> Vec<DenseMesh> {
    tessellate_with_held(
        mesh,
        topo,
        h,
        surface,
        counts,
        &HeldInteriors::default(),
        groups,
    )
}

/// [`tessellate_with_counts`], writing the interior points `held` holds for a triangle's inner
/// level (those its checks evaluated, [`super::ChordErrors::refine_to_tolerance_holding`])
/// instead of evaluating them again: the same bytes.
///
/// # Panics
/// As [`tessellate_with_counts`].
pub fn tessellate_with_held(
    mesh: &TriMesh,
    topo: &Topology,
    h: &[f64],
    surface: &dyn Surface,
    counts: &SegmentCounts,
    held: &HeldInteriors,
    groups: &[Range<usize>],
) -> Vec<DenseMesh> {
    let keys: Vec<PatternKey> = (0..mesh.triangles.len())
        .into_par_iter()
        .map(|t| counts.key(topo, t))
        .collect();
    let mut distinct = keys.clone();
    distinct.par_sort_unstable();
    distinct.dedup();
    let patterns: Vec<Kept<Pattern>> = distinct
        .par_iter()
        .map(|&k| kept_patterns::pattern(k))
        .collect();
    let pattern_of: Vec<u32> = keys
        .par_iter()
        .map(|k| distinct.binary_search(k).expect("every key was built") as u32)
        .collect();
    let pair_table = counts.pair_table();
    let shared = Shared {
        mesh,
        topo,
        surface,
        counts,
        held,
        patterns: &patterns,
        pattern_of: &pattern_of,
        pair_table: &pair_table,
    };
    groups
        .par_iter()
        .map(|range| tessellate_group(&shared, h, range.clone()))
        .collect()
}

/// What every block reads.
struct Shared<'a> {
    mesh: &'a TriMesh,
    topo: &'a Topology,
    surface: &'a dyn Surface,
    counts: &'a SegmentCounts,
    held: &'a HeldInteriors,
    patterns: &'a [Kept<Pattern>],
    pattern_of: &'a [u32],
    /// Per source triangle, its pair in `counts.pairs` ([`SegmentCounts::pair_table`]).
    pair_table: &'a [u32],
}

impl Shared<'_> {
    fn pattern(&self, tri: usize) -> &Pattern {
        &self.patterns[self.pattern_of[tri] as usize]
    }

    /// How many triangles source triangle `tri` writes: its pattern's, or its share of its pair.
    fn triangles_of(&self, tri: usize) -> usize {
        let own = self.pattern(tri).triangles.len();
        match self.counts.pair_of(self.pair_table, tri) {
            Some((pair, side)) => pair.share_len(side, own),
            None => own,
        }
    }
}

fn tessellate_group(shared: &Shared<'_>, h: &[f64], range: Range<usize>) -> DenseMesh {
    let (mesh, topo, counts) = (shared.mesh, shared.topo, shared.counts);
    let layout = GroupLayout::with_counts(
        mesh,
        topo,
        h,
        range.clone(),
        |tri, k| counts.edges[topo.tri_edges[tri][k].0 as usize] - 1,
        |tri| {
            let m = counts.inner[tri];
            let rows = counts.row_points_of(shared.pair_table, tri) as u32;
            m.saturating_sub(1) * m.saturating_sub(2) / 2 + rows
        },
    );
    // First index of each source triangle's triangles.
    let mut index_base = Vec::with_capacity(range.len() + 1);
    let mut total = 0usize;
    for tri in range.clone() {
        index_base.push(total);
        total += 3 * shared.triangles_of(tri);
    }
    index_base.push(total);

    let vertex_count = layout.vertex_count();
    let mut out = DenseMesh {
        positions: vec![[0.0; 3]; vertex_count],
        normals: vec![[0.0; 3]; vertex_count],
        sources: vec![VertexSource::lattice(0, 1, 0, 0); vertex_count],
        indices: vec![0; total],
    };
    // Blocks of whole source triangles up to about BLOCK_TRIANGLES output triangles.
    let mut ranges = Vec::new();
    let mut start = 0;
    while start < range.len() {
        let mut end = start + 1;
        while end < range.len() && index_base[end + 1] - index_base[start] <= 3 * BLOCK_TRIANGLES {
            end += 1;
        }
        ranges.push(start..end);
        start = end;
    }
    let blocks = blocks::split(
        &mut out,
        ranges,
        |t| layout.base[t] as usize,
        |t| index_base[t],
    );
    blocks
        .into_par_iter()
        .for_each(|block| tessellate_block(shared, &layout, &index_base, range.start, block));
    out
}

/// Writes the vertices a block owns and all its triangles, each vertex evaluated once (see
/// the uniform path's `tessellate_block`, which this follows point for point).
fn tessellate_block(
    shared: &Shared<'_>,
    layout: &GroupLayout,
    index_base: &[usize],
    first_tri: usize,
    mut block: Block<'_>,
) {
    let (mesh, topo, surface) = (shared.mesh, shared.topo, shared.surface);
    let mut writer = emit::TriangleWriter::new(mesh, topo, surface);
    let mut local: Vec<u32> = Vec::new();
    let mut parts = Vec::with_capacity(4);
    let mut scratch = (Vec::new(), Vec::new());
    for offset in block.tris.clone() {
        let tri = first_tri + offset;
        let pattern = shared.pattern(tri);
        let corners = mesh.triangles[tri];
        let owns = layout.owns[offset];
        let held = shared.held.get(tri, pattern.key.inner);
        // Evaluated here, the interior and the owned edges share one set-up of the triangle
        // (its net and the neighbours' composed nets) instead of one per call; a held
        // interior needs no evaluation, and its edges alone gain nothing from a batch.
        if held.is_none() && !pattern.interior_by_rank.is_empty() {
            parts.clear();
            parts.extend(
                (0..3u8)
                    .filter(|&k| pattern.key.edges[k as usize] > 1 && owns & (8 << k) != 0)
                    .map(|k| (pattern.key.edges[k as usize], LatticePart::Edge(k))),
            );
            parts.push((pattern.key.inner, LatticePart::Interior));
            writer.evaluate_parts(tri, &parts);
        }
        let source = |p: usize| {
            let [level, i, j] = pattern.lattice[p];
            VertexSource {
                tri: tri as u32,
                level,
                i,
                j,
            }
        };
        local.clear();
        local.resize(pattern.lattice.len(), 0);
        for c in 0..3 {
            let slot = layout.corner_slot[3 * offset + c] as usize;
            let owned = owns & (1 << c) != 0;
            writer.corner(&mut block, &mut local, tri, c, c, slot, owned, source(c));
        }
        for k in 0..3 {
            writer.edge(
                &mut block,
                &mut local,
                tri,
                k,
                pattern.key.edges[k],
                layout.edge_slot[3 * offset + k] as usize,
                corners[(k + 1) % 3] <= corners[(k + 2) % 3],
                owns & (8 << k) != 0,
                |m| (pattern.edge_start[k] + m - 1) as usize,
                source,
            );
        }
        if !pattern.interior_by_rank.is_empty() {
            let start = pattern.interior_start as usize;
            let first_slot = layout.base[offset + 1] as usize - pattern.interior_by_rank.len();
            let by_rank = pattern
                .interior_by_rank
                .iter()
                .map(|&index| (start + index as usize, index as usize));
            match held {
                Some(points) => held::write_interior(
                    &mut block, &mut local, points, first_slot, by_rank, source,
                ),
                None => writer.interior(
                    &mut block,
                    &mut local,
                    tri,
                    pattern.key.inner,
                    first_slot,
                    by_rank,
                    source,
                ),
            }
        }
        let (start, end) = (
            index_base[offset] - block.index_base,
            index_base[offset + 1] - block.index_base,
        );
        match shared.counts.pair_of(shared.pair_table, tri) {
            Some((pair, side)) => {
                let first_slot = layout.base[offset + 1] as usize - pair.interior_of(side);
                write_row_points(
                    surface,
                    tri,
                    pair,
                    side,
                    first_slot,
                    &mut block,
                    &mut scratch,
                );
                let out = &mut block.indices[start..end];
                write_share(shared, layout, first_tri, pair, side, out)
            }
            None => emit::triangles(&mut block.indices[start..end], &pattern.triangles, &local),
        }
    }
}

/// Writes the points inside `pair` (a quad cut in rows, `rows.rs`) that are its triangle
/// `side`'s (source triangle `tri`) into the interior slots from `first_slot` on (its pattern
/// has none): lattice points of their own level, evaluated in one call.
fn write_row_points(
    surface: &dyn Surface,
    tri: usize,
    pair: &Pair,
    side: usize,
    first_slot: usize,
    block: &mut Block<'_>,
    (barys, evaluated): &mut (Vec<[f64; 3]>, Vec<SurfacePoint>),
) {
    let own = pair.interior.iter().filter(|p| usize::from(p.side) == side);
    barys.clear();
    barys.extend(own.clone().map(|p| p.bary()));
    if barys.is_empty() {
        return;
    }
    evaluated.clear();
    surface.evaluate_points(tri, barys, evaluated);
    for (rank, (p, at)) in own.zip(evaluated.iter()).enumerate() {
        let source = VertexSource::lattice(tri as u32, ROW_LEVEL, u32::from(p.i), u32::from(p.j));
        block.put(
            first_slot + rank,
            at.position.as_vec3().to_array(),
            at.normal.as_vec3().to_array(),
            source,
        );
    }
}

/// Writes side `side`'s share of `pair`'s triangles (`pairs.rs`) into `out`, its index range:
/// the joined polygon's points are the two triangles' corners and edge samples, numbered by
/// `layout` whichever triangle writes them.
fn write_share(
    shared: &Shared<'_>,
    layout: &GroupLayout,
    first_tri: usize,
    pair: &Pair,
    side: usize,
    out: &mut [u32],
) {
    let tris = pair.tris.map(|t| t as usize);
    let patterns = tris.map(|t| shared.pattern(t));
    let joined = joined_polygon(pair.sides, patterns);
    let first_share = pair.share_len(0, patterns[0].triangles.len());
    let share = if side == 0 {
        &pair.triangles[..first_share]
    } else {
        &pair.triangles[first_share..]
    };
    let n = joined.len();
    // A point inside (`rows.rs`) is the first triangle's or the second's, the first's listed
    // first, and its triangle's interior slots are its points, in that order.
    let own = [pair.interior_of(0), pair.interior_of(1)];
    let slot = |q: u8| {
        let Some(&(s, p)) = joined.get(usize::from(q)) else {
            let r = usize::from(q) - n;
            let s = usize::from(pair.interior[r].side);
            let rank = r - if s == 1 { own[0] } else { 0 };
            let offset = tris[s] - first_tri;
            return layout.base[offset + 1] - (own[s] - rank) as u32;
        };
        point_slot(
            layout,
            shared.mesh,
            tris[s] - first_tri,
            tris[s],
            patterns[s],
            p,
        )
    };
    for (dst, t) in out.chunks_exact_mut(3).zip(share) {
        dst[0] = slot(t[0]);
        dst[1] = slot(t[1]);
        dst[2] = slot(t[2]);
    }
}

/// The output vertex of point `p` (a corner or an edge sample) of source triangle `tri`, at
/// `offset` in its group, cut by `pattern`: the slot the writer gives it.
fn point_slot(
    layout: &GroupLayout,
    mesh: &TriMesh,
    offset: usize,
    tri: usize,
    pattern: &Pattern,
    p: u32,
) -> u32 {
    if p < 3 {
        return layout.corner_slot[3 * offset + p as usize];
    }
    let k = (0..3)
        .rev()
        .find(|&k| p >= pattern.edge_start[k])
        .expect("an edge sample");
    let n = pattern.key.edges[k];
    debug_assert!(p < pattern.edge_start[k] + n - 1, "{p} is an edge sample");
    let corners = mesh.triangles[tri];
    let ascending = corners[(k + 1) % 3] <= corners[(k + 2) % 3];
    let m = p - pattern.edge_start[k] + 1;
    emit::edge_slot(layout.edge_slot[3 * offset + k] as usize, ascending, n, m) as u32
}
