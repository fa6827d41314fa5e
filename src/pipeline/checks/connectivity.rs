//! How a mesh's triangles hang together, for the geometry checks: bow-tie vertices (a welded
//! vertex whose triangles form more than one fan) and the number of disconnected pieces.
//!
//! Both read the topology's neighbours across interior edges instead of joining classes of
//! corners or triangles: around a vertex whose edges are all interior or boundary the fans are
//! walked triangle to triangle, and the pieces are found by one search through the neighbours.
//! The union-finds these replace wrote an array over every corner (12 bytes per triangle) and
//! one over every triangle, with a compare-and-swap per join; the walks write one small
//! per-vertex record and a bit per triangle. Only vertices on a non-manifold or degenerate
//! edge, where a fan is not a path or a cycle, are decided from their triangles' corners, and
//! only those vertices' triangles are gathered.

use rayon::prelude::*;

use super::Tally;
use crate::topology::{EdgeKind, Topology, TriId, VertId};

/// Vertices decided per parallel task.
const BLOCK: usize = 4096;

/// What the fan walk needs of one welded vertex: how many distinct triangles hold it (a
/// triangle with two corners at it counted once) and the last corner (`3 × triangle + slot`)
/// that does.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Around {
    triangles: u32,
    corner: u32,
}

/// Welded vertices whose triangles form more than one fan (connected through edges that contain
/// the vertex), counted with the smallest as examples.
///
/// A vertex all of whose edges are interior (exactly two distinct non-degenerate triangles) or
/// boundary (one) has fans that are paths or cycles of triangles: each of its triangles holds
/// two of its edges, and each such edge at most one other triangle. Walking from one of its
/// triangles across its edges, both ways until a boundary edge or once round back to the start,
/// visits that triangle's whole fan, so the vertex is a bow-tie exactly when the walk visits
/// fewer triangles than hold the vertex. The walk reads only the packed neighbours: the slots
/// the topology gives for the triangle across an edge say where the vertex and the way on lie
/// (see [`walk_fan`]). Linear in the corners, whatever the valence; the vertices are decided in
/// parallel, in blocks tallied in vertex order. A walk that meets a non-manifold or degenerate
/// edge leaves its vertex to [`bow_ties_by_corners`].
/// `around` is [`around_vertices`] of `topo`, taken by the caller (beside other work).
pub(super) fn bow_tie_vertices(topo: &Topology, around: Vec<Around>) -> Tally {
    let blocks = around.len().div_ceil(BLOCK);
    let (mut found, undecided) = (0..blocks)
        .into_par_iter()
        .map(|b| {
            let mut tally = Tally::default();
            let mut undecided = Vec::new();
            let start = b * BLOCK;
            for (i, &a) in around[start..(start + BLOCK).min(around.len())]
                .iter()
                .enumerate()
            {
                let v = start + i;
                // No triangle, or one: one fan at most.
                if a.triangles < 2 {
                    continue;
                }
                match walk_fan(topo, a) {
                    Some(true) => tally.add(v),
                    Some(false) => {}
                    None => undecided.push(v as u32),
                }
            }
            (tally, undecided)
        })
        .reduce(
            || (Tally::default(), Vec::new()),
            |(mut a, mut left), (b, mut right)| {
                a.merge(&b);
                left.append(&mut right);
                (a, left)
            },
        );
    drop(around);
    if !undecided.is_empty() {
        for v in bow_ties_by_corners(topo, &undecided) {
            found.insert(v);
        }
    }
    found
}

/// Per welded vertex, its triangle count and one of its corners: one pass over the corners.
pub(super) fn around_vertices(topo: &Topology) -> Vec<Around> {
    let mut around = vec![Around::default(); topo.welded_positions.len()];
    for (t, v) in topo.tri_verts.iter().enumerate() {
        let firsts = [true, v[1] != v[0], v[2] != v[0] && v[2] != v[1]];
        for c in 0..3 {
            if firsts[c] {
                let a = &mut around[v[c].0 as usize];
                a.triangles += 1;
                a.corner = (3 * t + c) as u32;
            }
        }
    }
    around
}

/// Whether the fan walked from `a.corner` misses some of the vertex's `a.triangles` triangles:
/// `Some(true)` for a bow-tie, `Some(false)` for one fan, `None` where the walk meets an edge
/// that is neither interior nor boundary (the vertex's fans are then not paths or cycles).
///
/// At triangle f, holding the vertex in slot c, the walk leaves through edge k (k ≠ c: edge k
/// joins slots k + 1 and k + 2). The neighbour g holds f's slot k + 1 in `slots[0]` and
/// k + 2 in `slots[1]`, so the vertex sits in g's slot `s` (whichever of the two is c's), the
/// shared edge is opposite `slots[2]`, and the way on is g's third edge, opposite slot
/// `3 − s − slots[2]`. No corner is read.
fn walk_fan(topo: &Topology, a: Around) -> Option<bool> {
    let (t0, c0) = (a.corner / 3, (a.corner % 3) as usize);
    let mut visited = 1u32;
    for first in [(c0 + 1) % 3, (c0 + 2) % 3] {
        let (mut t, mut c, mut k) = (t0, c0, first);
        loop {
            let Some(n) = topo.neighbour(TriId(t), k) else {
                if topo.edge_kind(topo.tri_edges[t as usize][k]) != EdgeKind::Boundary {
                    return None;
                }
                break;
            };
            if n.tri.0 == t0 {
                // Once round: a closed fan, every triangle of it visited.
                return Some(visited < a.triangles);
            }
            visited += 1;
            // More than the vertex holds: not a path or cycle after all (never on a
            // consistent topology); decided the slow way rather than looping.
            if visited > a.triangles {
                return None;
            }
            let s = if c == (k + 1) % 3 {
                n.slots[0]
            } else {
                n.slots[1]
            };
            (t, c, k) = (n.tri.0, s as usize, (3 - s - n.slots[2]) as usize);
        }
    }
    // Both ways ended on boundary edges: an open fan.
    Some(visited < a.triangles)
}

/// The bow-ties among `vertices` (sorted), from their triangles' corners alone: each vertex's
/// triangles (every triangle once) are joined where they share an edge through the vertex,
/// that is another corner, or the vertex twice (an edge from it to itself), with a small
/// union-find per vertex. For the few vertices on non-manifold or degenerate edges; the sort of
/// their triangles keeps a book of many pages near-linear.
fn bow_ties_by_corners(topo: &Topology, vertices: &[u32]) -> Vec<usize> {
    let mut slot = vec![u32::MAX; topo.welded_positions.len()];
    for (i, &v) in vertices.iter().enumerate() {
        slot[v as usize] = i as u32;
    }
    // (the vertex's place in `vertices`, triangle), for every triangle holding one of them.
    let mut held: Vec<(u32, u32)> = topo
        .tri_verts
        .par_iter()
        .enumerate()
        .flat_map_iter(|(t, v)| {
            let firsts = [true, v[1] != v[0], v[2] != v[0] && v[2] != v[1]];
            let slot = &slot;
            (0..3)
                .filter(move |&c| firsts[c] && slot[v[c].0 as usize] != u32::MAX)
                .map(move |c| (slot[v[c].0 as usize], t as u32))
        })
        .collect();
    held.par_sort_unstable();
    let mut bow_ties = Vec::new();
    let mut keys: Vec<(u32, u32)> = Vec::new();
    let mut parent: Vec<u32> = Vec::new();
    for group in held.chunk_by(|a, b| a.0 == b.0) {
        let x = VertId(vertices[group[0].0 as usize]);
        // (edge key, triangle's place in the group): the other end of each edge through x.
        keys.clear();
        for (j, &(_, t)) in group.iter().enumerate() {
            let v = topo.tri_verts[t as usize];
            // At most two other corners (x is one of the three), each edge once.
            let mut others = 0;
            for y in v.iter().filter(|&&y| y != x) {
                if others == 0 || keys[keys.len() - 1].0 != y.0 {
                    keys.push((y.0, j as u32));
                    others += 1;
                }
            }
            if v.iter().filter(|&&y| y == x).count() > 1 {
                keys.push((x.0, j as u32));
            }
        }
        keys.sort_unstable();
        parent.clear();
        parent.extend(0..group.len() as u32);
        let mut classes = group.len();
        for w in keys.windows(2).filter(|w| w[0].0 == w[1].0) {
            let (ra, rb) = (root(&mut parent, w[0].1), root(&mut parent, w[1].1));
            if ra != rb {
                parent[ra.max(rb) as usize] = ra.min(rb);
                classes -= 1;
            }
        }
        if classes > 1 {
            bow_ties.push(x.0 as usize);
        }
    }
    bow_ties
}

/// The root of `i` in a plain union-find, halving the path on the way.
fn root(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let grand = parent[parent[i as usize] as usize];
        parent[i as usize] = grand;
        i = grand;
    }
    i
}

/// Connected pieces of triangles (through welded edges): one search from each triangle not yet
/// reached, through the neighbour across each interior edge and every use of the other edges
/// (each non-boundary edge's uses read once, so a book of many pages stays linear). A bit per
/// triangle and per edge marks what was reached.
pub(super) fn pieces(topo: &Topology) -> usize {
    let n = topo.tri_verts.len();
    let mut reached = Bits::new(n);
    let mut spread = Bits::new(topo.edge_count());
    let mut stack: Vec<u32> = Vec::new();
    let mut pieces = 0;
    for s in 0..n {
        if !reached.set(s) {
            continue;
        }
        pieces += 1;
        stack.push(s as u32);
        while let Some(t) = stack.pop() {
            for k in 0..3 {
                if let Some(g) = topo.neighbour(TriId(t), k) {
                    if reached.set(g.tri.0 as usize) {
                        stack.push(g.tri.0);
                    }
                    continue;
                }
                let e = topo.tri_edges[t as usize][k];
                if topo.edge_kind(e) == EdgeKind::Boundary || !spread.set(e.0 as usize) {
                    continue;
                }
                for u in topo.edge_uses(e) {
                    if reached.set(u.tri().0 as usize) {
                        stack.push(u.tri().0);
                    }
                }
            }
        }
    }
    pieces
}

/// A fixed set of indices, a bit each.
struct Bits(Vec<u64>);

impl Bits {
    fn new(n: usize) -> Bits {
        Bits(vec![0; n.div_ceil(64)])
    }

    /// Adds `i`; whether it was new.
    fn set(&mut self, i: usize) -> bool {
        let (word, bit) = (&mut self.0[i / 64], 1u64 << (i % 64));
        let new = *word & bit == 0;
        *word |= bit;
        new
    }
}

/// The vertices with two or more triangles that [`walk_fan`] leaves undecided, for the tests
/// that check the walk decides every vertex of a mesh whose edges are interior or boundary.
#[cfg(test)]
pub(super) fn undecided(topo: &Topology) -> Vec<usize> {
    around_vertices(topo)
        .into_iter()
        .enumerate()
        .filter(|(_, a)| a.triangles >= 2 && walk_fan(topo, *a).is_none())
        .map(|(v, _)| v)
        .collect()
}
