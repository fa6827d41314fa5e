//! Mesh adjacency: welds vertices by position and classifies every edge (interior, boundary,
//! non-manifold, degenerate, split normals), with each triangle edge's neighbour and its slots.
//!
//! It deliberately knows nothing of blend widths or surfaces: it only describes the mesh, and
//! reports bad geometry as [`Warning`]s instead of failing.
//!
//! The weld itself (which input vertices are one welded vertex, numbered by first use) is the
//! submodule `weld`, parallel throughout.
//!
//! Conventions: corner `k` of a triangle is opposite its edge `k`; edge `k` runs from corner
//! `(k + 1) % 3` (called `i`) to corner `(k + 2) % 3` (called `j`).

use std::fmt;
use std::ops::Range;

use rayon::prelude::*;

use glam::DVec3;

use crate::mesh::TriMesh;

mod weld;
use weld::weld;

/// A welded vertex (one per distinct position).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct VertId(pub u32);

/// A triangle of the input mesh, in input order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TriId(pub u32);

/// A welded edge, an index into [`Topology::edges`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct EdgeId(pub u32);

/// How an edge joins its triangles; only [`EdgeKind::Interior`] edges are blended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EdgeKind {
    /// Exactly two distinct non-degenerate triangles.
    Interior,
    /// One triangle.
    Boundary,
    /// Three or more triangles.
    NonManifold,
    /// Zero length, or used by a degenerate triangle.
    Degenerate,
}

/// One use of a welded edge: a triangle and its local corner opposite the edge, packed as
/// `3 × triangle + corner` in one `u32`, so that the uses of every edge fit one flat array and
/// sort in (triangle, corner) order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct EdgeUse(u32);

impl EdgeUse {
    /// The use of edge `corner` (the edge opposite that corner) of triangle `tri`.
    pub const fn new(tri: TriId, corner: u8) -> Self {
        EdgeUse(tri.0 * 3 + corner as u32)
    }

    /// The triangle.
    pub const fn tri(self) -> TriId {
        TriId(self.0 / 3)
    }

    /// The triangle's local corner opposite the edge (0, 1 or 2).
    pub const fn corner(self) -> u8 {
        (self.0 % 3) as u8
    }

    /// `(triangle, corner)` as indices.
    pub const fn at(self) -> (usize, usize) {
        ((self.0 / 3) as usize, (self.0 % 3) as usize)
    }
}

/// One welded edge, read from [`Topology`]'s arrays: a small copy, not stored anywhere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edge<'a> {
    /// End points, smaller id first.
    pub verts: [VertId; 2],
    /// Classification; non-interior edges act as h = 0.
    pub kind: EdgeKind,
    /// Every use of the edge in (triangle, corner) order, so the first use is the
    /// lowest-numbered triangle.
    pub tris: &'a [EdgeUse],
    /// The triangles using the edge carry different input normals at one of its end points
    /// (exact comparison: a hard edge, or a UV seam with slightly different normals).
    pub split_normals: bool,
}

/// The triangle across an interior edge, with the local slots that locate it (notes item 3).
///
/// For edge `k` of triangle f, with `i = (k + 1) % 3` and `j = (k + 2) % 3`: the neighbour g holds
/// f's corner `i` in slot `slots[0]` (`p`), f's corner `j` in slot `slots[1]` (`q`), and its own
/// third corner in slot `slots[2]` (`r`). This holds whatever g's corner order or winding.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Neighbour {
    /// The neighbour triangle g.
    pub tri: TriId,
    /// `[p, q, r]`, local corner slots of g.
    pub slots: [u8; 3],
}

impl Neighbour {
    /// Whether g runs along the shared edge in the same direction as f (one of the two is wound
    /// the other way): f's edge runs from its corner i to j, g's from its slot `r + 1` to
    /// `r + 2`, so both run the same way exactly when g holds i in slot `r + 1`. Read from the
    /// slots alone, without either triangle's corners.
    pub fn runs_same_way(&self) -> bool {
        self.slots[0] == (self.slots[2] + 1) % 3
    }
}

/// A [`Neighbour`] in one `u32`: `2 × (3g + r) + swapped`, where `r` is g's corner opposite the
/// shared edge and `swapped` says f's corner `i` sits in g's slot `r + 2` rather than `r + 1`;
/// [`NO_NEIGHBOUR`] for edges that are not interior. A third of the `Option<Neighbour>` it
/// replaces, which padded every entry to 12 bytes.
type PackedNeighbour = u32;
const NO_NEIGHBOUR: PackedNeighbour = u32::MAX;

/// The most triangles one [`Topology`] holds: a packed neighbour spends `6 × triangles` of a
/// `u32` (over 700 million triangles, beyond what fits the memory of any machine this runs on).
pub const MAX_TRIANGLES: usize = (u32::MAX / 6) as usize;

/// Something odd in the geometry, with the fallback that was applied.
#[derive(Debug, Clone, PartialEq)]
pub enum Warning {
    /// Two welded corners, or zero area: its edges act as h = 0 and its normals fall back to
    /// the interpolated input normals.
    DegenerateTriangle { tri: TriId },
    /// An edge used by three or more triangles: it acts as h = 0.
    NonManifoldEdge { edge: EdgeId, triangles: usize },
    /// A blend width h > 0 was asked for on `edges` edges of this kind; they act as h = 0.
    BlendIgnored {
        kind: EdgeKind,
        edges: usize,
        first: EdgeId,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::DegenerateTriangle { tri } => write!(
                f,
                "triangle {} is degenerate; its edges are not blended",
                tri.0
            ),
            Warning::NonManifoldEdge { edge, triangles } => write!(
                f,
                "edge {} is shared by {triangles} triangles; it is not blended",
                edge.0
            ),
            Warning::BlendIgnored { kind, edges, first } => {
                let what = match kind {
                    EdgeKind::Interior => "interior",
                    EdgeKind::Boundary => "boundary",
                    EdgeKind::NonManifold => "non-manifold",
                    EdgeKind::Degenerate => "degenerate",
                };
                write!(
                    f,
                    "h > 0 asked for on {edges} {what} edge(s) (first: edge {}); they use h = 0",
                    first.0
                )
            }
        }
    }
}

/// Welded adjacency of a [`TriMesh`], held as flat arrays indexed by `u32` ids.
///
/// Every per-edge fact is its own array (structure of arrays) and the uses of all edges share
/// one array cut by offsets (compressed rows), so a mesh of any shape costs a fixed number of
/// allocations and about 90 bytes per triangle; [`Topology::edge`] assembles a small [`Edge`]
/// view on demand.
#[derive(Debug, Clone, PartialEq)]
pub struct Topology {
    /// Input vertex index to welded vertex (bit-equal positions; -0.0 equals +0.0).
    pub welded_of_vertex: Vec<VertId>,
    /// One position per welded vertex (the first input vertex seen).
    pub welded_positions: Vec<DVec3>,
    /// Welded corners per triangle, in input corner order.
    pub tri_verts: Vec<[VertId; 3]>,
    /// `tri_edges[t][k]` is the edge opposite corner `k` of triangle `t`.
    pub tri_edges: Vec<[EdgeId; 3]>,
    /// Degenerate triangles (two welded corners or zero area).
    pub degenerate: Vec<bool>,
    /// Per edge: end points, smaller id first; edges are sorted by them.
    edge_verts: Vec<[VertId; 2]>,
    /// Per edge: its classification.
    edge_kinds: Vec<EdgeKind>,
    /// Per edge: whether its triangles disagree on an input normal at an end point.
    split_normals: Vec<bool>,
    /// The uses of edge `e` are `uses[use_start[e]..use_start[e + 1]]`.
    use_start: Vec<u32>,
    /// Every edge's uses, edge after edge, each edge's in (triangle, corner) order.
    uses: Vec<EdgeUse>,
    /// Per triangle and edge: the triangle across it ([`PackedNeighbour`]).
    neighbours: Vec<[PackedNeighbour; 3]>,
}

/// A triangle counts as zero-area when |cross| <= this × (longest edge)²: a few ulps of the
/// squared length, so only exactly flat (collinear up to rounding) triangles qualify.
const ZERO_AREA_RELATIVE: f64 = 1e-14;

impl Topology {
    /// Welds `mesh` and builds its edges. Never fails on odd geometry: it is classified, not
    /// rejected.
    ///
    /// Every pass is linear in the corners (a counting sort groups the uses of each edge, and
    /// only the uses that share a smaller end point are sorted among themselves), and the
    /// per-edge and per-triangle passes run in parallel; the result does not depend on the
    /// thread count.
    ///
    /// # Panics
    /// With more than [`MAX_TRIANGLES`] triangles (the caller checks the input first).
    pub fn build(mesh: &TriMesh) -> Topology {
        assert!(
            mesh.triangles.len() <= MAX_TRIANGLES,
            "a topology holds at most {MAX_TRIANGLES} triangles"
        );
        let (welded_of_vertex, welded_positions) = weld(&mesh.positions);
        // One pass over the triangles for their welded corners and whether they are degenerate.
        let (tri_verts, degenerate): (Vec<[VertId; 3]>, Vec<bool>) = mesh
            .triangles
            .par_iter()
            .map(|t| {
                let welded = |k: usize| welded_of_vertex[t[k] as usize];
                let v = [welded(0), welded(1), welded(2)];
                (v, is_degenerate(&v, &welded_positions))
            })
            .unzip();
        let Grouped {
            uses,
            edge_verts,
            use_start,
            tri_edges,
        } = group_uses(&tri_verts, welded_positions.len());

        let uses_of = |e: usize| &uses[use_start[e] as usize..use_start[e + 1] as usize];
        // Where the weld joined no two input vertices, every welded vertex is one input vertex
        // with one normal (finite: the normals were checked and repaired before), so no edge's
        // triangles can disagree on one: nothing to compare.
        let one_normal_each = welded_positions.len() == mesh.positions.len();
        let (edge_kinds, split_normals): (Vec<EdgeKind>, Vec<bool>) = (0..edge_verts.len())
            .into_par_iter()
            .map(|e| {
                let (verts, tris) = (edge_verts[e], uses_of(e));
                let uses_degenerate = tris.iter().any(|u| degenerate[u.tri().0 as usize]);
                let kind = if verts[0] == verts[1] || uses_degenerate {
                    EdgeKind::Degenerate
                } else {
                    match tris.len() {
                        1 => EdgeKind::Boundary,
                        2 => EdgeKind::Interior,
                        _ => EdgeKind::NonManifold,
                    }
                };
                let split = !one_normal_each && has_split_normals(verts, tris, mesh, &tri_verts);
                (kind, split)
            })
            .unzip();

        // A plain loop over the three sides: the closure of `array::from_fn` is not always
        // inlined, and then costs a call per side.
        let neighbours: Vec<[PackedNeighbour; 3]> = (0..tri_verts.len())
            .into_par_iter()
            .map(|f| {
                let mut codes = [NO_NEIGHBOUR; 3];
                for (kf, code) in codes.iter_mut().enumerate() {
                    let e = tri_edges[f][kf].0 as usize;
                    if edge_kinds[e] != EdgeKind::Interior {
                        continue;
                    }
                    let here = EdgeUse::new(TriId(f as u32), kf as u8);
                    let pair = uses_of(e);
                    let other = if pair[0] == here { pair[1] } else { pair[0] };
                    let (g, kg) = other.at();
                    // f's corner i sits in g's slot r + 1 or r + 2 (r = kg, opposite the edge).
                    let i = tri_verts[f][(kf + 1) % 3];
                    let swapped = tri_verts[g][(kg + 1) % 3] != i;
                    *code = (other.0 << 1) | u32::from(swapped);
                }
                codes
            })
            .collect();

        Topology {
            welded_of_vertex,
            welded_positions,
            tri_verts,
            tri_edges,
            degenerate,
            edge_verts,
            edge_kinds,
            split_normals,
            use_start,
            uses,
            neighbours,
        }
    }

    /// The number of welded edges; [`EdgeId`]s run from 0 to this.
    pub fn edge_count(&self) -> usize {
        self.edge_verts.len()
    }

    /// The edge with this id.
    pub fn edge(&self, id: EdgeId) -> Edge<'_> {
        let e = id.0 as usize;
        Edge {
            verts: self.edge_verts[e],
            kind: self.edge_kinds[e],
            tris: self.edge_uses(id),
            split_normals: self.split_normals[e],
        }
    }

    /// Every edge in id order.
    pub fn edges(&self) -> impl ExactSizeIterator<Item = Edge<'_>> + Clone + '_ {
        (0..self.edge_count()).map(|e| self.edge(EdgeId(e as u32)))
    }

    /// Every edge in id order, in parallel.
    pub fn par_edges(&self) -> impl IndexedParallelIterator<Item = Edge<'_>> + '_ {
        (0..self.edge_count())
            .into_par_iter()
            .map(|e| self.edge(EdgeId(e as u32)))
    }

    /// The classification of edge `id` alone (no view assembled).
    pub fn edge_kind(&self, id: EdgeId) -> EdgeKind {
        self.edge_kinds[id.0 as usize]
    }

    /// Whether the triangles of edge `id` carry different input normals at one of its ends
    /// ([`Edge::split_normals`]), alone (no view assembled).
    pub fn split_normals(&self, id: EdgeId) -> bool {
        self.split_normals[id.0 as usize]
    }

    /// The end points of edge `id`, smaller id first.
    pub fn edge_verts(&self, id: EdgeId) -> [VertId; 2] {
        self.edge_verts[id.0 as usize]
    }

    /// The uses of edge `id`, in (triangle, corner) order.
    pub fn edge_uses(&self, id: EdgeId) -> &[EdgeUse] {
        let e = id.0 as usize;
        &self.uses[self.use_start[e] as usize..self.use_start[e + 1] as usize]
    }

    /// The welded edge between two welded vertices, if there is one.
    pub fn edge_between(&self, a: VertId, b: VertId) -> Option<EdgeId> {
        let key = [a.min(b), a.max(b)];
        self.edge_verts
            .binary_search(&key)
            .ok()
            .map(|i| EdgeId(i as u32))
    }

    /// The triangle across edge `k` of `tri`, if that edge is interior.
    pub fn neighbour(&self, tri: TriId, k: usize) -> Option<Neighbour> {
        let code = self.neighbours[tri.0 as usize][k];
        if code == NO_NEIGHBOUR {
            return None;
        }
        let (g, r) = EdgeUse(code >> 1).at();
        let (p, q) = ((r + 1) % 3, (r + 2) % 3);
        let (p, q) = if code & 1 == 0 { (p, q) } else { (q, p) };
        Some(Neighbour {
            tri: TriId(g as u32),
            slots: [p as u8, q as u8, r as u8],
        })
    }

    /// Bytes this topology holds on the heap (capacities, not lengths).
    pub fn heap_bytes(&self) -> usize {
        fn held<T>(v: &Vec<T>) -> usize {
            v.capacity() * std::mem::size_of::<T>()
        }
        held(&self.welded_of_vertex)
            + held(&self.welded_positions)
            + held(&self.tri_verts)
            + held(&self.tri_edges)
            + held(&self.degenerate)
            + held(&self.edge_verts)
            + held(&self.edge_kinds)
            + held(&self.split_normals)
            + held(&self.use_start)
            + held(&self.uses)
            + held(&self.neighbours)
    }

    /// Degenerate triangles and non-manifold edges, in index order.
    pub fn warnings(&self) -> Vec<Warning> {
        let tris = self
            .degenerate
            .iter()
            .enumerate()
            .filter(|&(_, &d)| d)
            .map(|(t, _)| Warning::DegenerateTriangle {
                tri: TriId(t as u32),
            });
        let edges = self
            .edges()
            .enumerate()
            .filter(|(_, e)| e.kind == EdgeKind::NonManifold)
            .map(|(i, e)| Warning::NonManifoldEdge {
                edge: EdgeId(i as u32),
                triangles: e.tris.len(),
            });
        tris.chain(edges).collect()
    }
}

/// The uses of all edges grouped edge by edge, and what indexes them.
struct Grouped {
    uses: Vec<EdgeUse>,
    edge_verts: Vec<[VertId; 2]>,
    use_start: Vec<u32>,
    tri_edges: Vec<[EdgeId; 3]>,
}

/// Groups every triangle side into welded edges, in canonical (smaller vertex, larger vertex)
/// order and each edge's uses in (triangle, corner) order.
///
/// The smaller end points are cut into ranges, one task each, and every task scans all sides
/// for its own. A counting sort puts a range's sides into one bucket per vertex, straight into
/// the final array of uses (with each side's larger end point beside it in a second array), and
/// each bucket is then sorted by (larger end point, use) as plain `u64`s, with no lookup of the
/// triangles per comparison. The edges are counted first, so the edge arrays too are written in
/// place, each range into its own piece: no array is built twice and copied. Linear in the
/// corners plus the sort of each vertex's own sides, parallel without a shared write, and the
/// result does not depend on how the vertices were cut. Each triangle side then finds its edge
/// among those of its smaller end point (a binary search, so a vertex on 100 000 edges costs a
/// logarithm, not a scan).
fn group_uses(tri_verts: &[[VertId; 3]], vertex_count: usize) -> Grouped {
    let sides = 3 * tri_verts.len();
    // A few ranges per thread at most: each range reads every side once per pass.
    let ranges = if sides < PARALLEL_SIDES {
        1
    } else {
        rayon::current_num_threads().clamp(1, 8)
    };
    let cut = |i: usize| i * vertex_count / ranges;
    let vertex_ranges: Vec<Range<usize>> = (0..ranges).map(|i| cut(i)..cut(i + 1)).collect();
    let buckets: Vec<Vec<u32>> = vertex_ranges
        .par_iter()
        .map(|r| bucket_starts(tri_verts, r.clone()))
        .collect();
    let side_counts: Vec<usize> = buckets.iter().map(|b| b[b.len() - 1] as usize).collect();

    // Every range's sides, bucket by bucket, and the larger end point of each.
    let mut uses = filled(EdgeUse(0), sides);
    let mut ends = vec![0u32; sides];
    let edge_counts: Vec<usize> = pieces_of(&mut uses, &side_counts)
        .into_par_iter()
        .zip(pieces_of(&mut ends, &side_counts))
        .enumerate()
        .map(|(i, (uses, ends))| {
            fill_buckets(tri_verts, vertex_ranges[i].clone(), &buckets[i], uses, ends)
        })
        .collect();

    // The edges of each range, in place.
    let edge_count: usize = edge_counts.iter().sum();
    let mut edge_verts = filled([VertId(0); 2], edge_count);
    let mut use_start = vec![0u32; edge_count + 1];
    let mut first_edge = vec![0u32; vertex_count + 1];
    use_start[edge_count] = sides as u32;
    first_edge[vertex_count] = edge_count as u32;
    let vertex_counts: Vec<usize> = vertex_ranges.iter().map(Range::len).collect();
    let before = |counts: &[usize], i: usize| counts[..i].iter().sum::<usize>();
    pieces_of(&mut edge_verts, &edge_counts)
        .into_par_iter()
        .zip(pieces_of(&mut use_start[..edge_count], &edge_counts))
        .zip(pieces_of(&mut first_edge[..vertex_count], &vertex_counts))
        .enumerate()
        .for_each(|(i, ((edge_verts, use_start), first_edge))| {
            let (from, to) = (before(&side_counts, i), before(&side_counts, i + 1));
            let range = RangeEdges {
                vertices: vertex_ranges[i].clone(),
                buckets: &buckets[i],
                ends: &ends[from..to],
                first_use: from as u32,
                first_edge: before(&edge_counts, i) as u32,
            };
            range.write(edge_verts, use_start, first_edge);
        });
    drop(ends);

    // A plain loop over the three sides, as for the neighbours.
    let tri_edges = tri_verts
        .par_iter()
        .map(|v| {
            let mut edges = [EdgeId(0); 3];
            for (k, edge) in edges.iter_mut().enumerate() {
                let (a, b) = ordered(v[(k + 1) % 3], v[(k + 2) % 3]);
                let from = first_edge[a.0 as usize] as usize;
                let of_a = &edge_verts[from..first_edge[a.0 as usize + 1] as usize];
                *edge = EdgeId((from + of_a.partition_point(|e| e[1] < b)) as u32);
            }
            edges
        })
        .collect();
    Grouped {
        uses,
        edge_verts,
        use_start,
        tri_edges,
    }
}

/// Fewer triangle sides than this are grouped by one task: splitting them costs more than it
/// saves.
const PARALLEL_SIDES: usize = 1 << 16;

/// `n` copies of `value`, written by every thread in parallel blocks. `vec![value; n]` fills a
/// type without a zero shortcut (not a bare integer or float) on one thread, so that thread
/// takes the first-touch fault of every page of a fresh mapping (2,942 for 12 MiB) while the
/// others wait; written in parallel, each thread takes the faults of its own blocks.
fn filled<T: Copy + Send + Sync>(value: T, n: usize) -> Vec<T> {
    (0..n).into_par_iter().map(|_| value).collect()
}

/// `whole` cut into consecutive pieces of the given lengths (which sum to at most its length).
fn pieces_of<'a, T>(whole: &'a mut [T], lengths: &[usize]) -> Vec<&'a mut [T]> {
    let mut rest = whole;
    lengths
        .iter()
        .map(|&len| {
            let (piece, after) = std::mem::take(&mut rest).split_at_mut(len);
            rest = after;
            piece
        })
        .collect()
}

/// The end points of a side, smaller first.
fn ordered(a: VertId, b: VertId) -> (VertId, VertId) {
    (a.min(b), a.max(b))
}

/// Side `k` of triangle `t` when its smaller end point lies in `range`: (that end point's place
/// in the range, the larger end point).
fn side_in(
    tri_verts: &[[VertId; 3]],
    range: &Range<usize>,
    t: usize,
    k: usize,
) -> Option<(usize, VertId)> {
    let v = tri_verts[t];
    let (a, b) = ordered(v[(k + 1) % 3], v[(k + 2) % 3]);
    let i = (a.0 as usize).wrapping_sub(range.start);
    (i < range.len()).then_some((i, b))
}

/// Where each vertex's bucket starts among the sides whose smaller end point lies in `range`:
/// entry `i` for the range's vertex `i`, and a last entry with the range's side count.
fn bucket_starts(tri_verts: &[[VertId; 3]], range: Range<usize>) -> Vec<u32> {
    let n = range.len();
    let mut start = vec![0u32; n + 1];
    for t in 0..tri_verts.len() {
        for k in 0..3 {
            if let Some((i, _)) = side_in(tri_verts, &range, t, k) {
                start[i + 1] += 1;
            }
        }
    }
    let mut sum = 0;
    for x in &mut start[1..] {
        sum += *x;
        *x = sum;
    }
    start
}

/// Puts the sides of `range` into their buckets (`start` from [`bucket_starts`]): each side's use
/// into `uses` and its larger end point into `ends`, every bucket sorted by (larger end point,
/// use). Returns how many edges the range has.
fn fill_buckets(
    tri_verts: &[[VertId; 3]],
    range: Range<usize>,
    start: &[u32],
    uses: &mut [EdgeUse],
    ends: &mut [u32],
) -> usize {
    let mut next = start[..range.len()].to_vec();
    for t in 0..tri_verts.len() {
        for k in 0..3 {
            if let Some((i, b)) = side_in(tri_verts, &range, t, k) {
                let at = next[i] as usize;
                next[i] += 1;
                uses[at] = EdgeUse((3 * t + k) as u32);
                ends[at] = b.0;
            }
        }
    }
    drop(next);
    // Each bucket as `(larger end << 32) | use`, sorted as plain integers.
    let mut bucket = Vec::new();
    let mut edges = 0;
    for w in start.windows(2) {
        let (from, to) = (w[0] as usize, w[1] as usize);
        bucket.clear();
        bucket.extend((from..to).map(|p| (u64::from(ends[p]) << 32) | u64::from(uses[p].0)));
        bucket.sort_unstable();
        for (j, &x) in bucket.iter().enumerate() {
            if j == 0 || x >> 32 != bucket[j - 1] >> 32 {
                edges += 1;
            }
            ends[from + j] = (x >> 32) as u32;
            uses[from + j] = EdgeUse(x as u32);
        }
    }
    edges
}

/// One range's sorted buckets, and where its uses and edges sit in the whole arrays.
struct RangeEdges<'a> {
    vertices: Range<usize>,
    /// From [`bucket_starts`].
    buckets: &'a [u32],
    /// The range's larger end points, sorted within each bucket by [`fill_buckets`].
    ends: &'a [u32],
    /// The range's first use and first edge in the whole arrays.
    first_use: u32,
    first_edge: u32,
}

impl RangeEdges<'_> {
    /// Writes the range's pieces of the edge arrays: each edge's end points and first use, and
    /// each vertex's first edge. An edge starts wherever the larger end point changes within a
    /// bucket.
    fn write(&self, edge_verts: &mut [[VertId; 2]], use_start: &mut [u32], first_edge: &mut [u32]) {
        let mut e = 0;
        for (i, w) in self.buckets.windows(2).enumerate() {
            first_edge[i] = self.first_edge + e as u32;
            let a = VertId((self.vertices.start + i) as u32);
            for p in w[0] as usize..w[1] as usize {
                if p == w[0] as usize || self.ends[p] != self.ends[p - 1] {
                    edge_verts[e] = [a, VertId(self.ends[p])];
                    use_start[e] = self.first_use + p as u32;
                    e += 1;
                }
            }
        }
    }
}

fn is_degenerate(v: &[VertId; 3], positions: &[DVec3]) -> bool {
    if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] {
        return true;
    }
    let [a, b, c] = v.map(|x| positions[x.0 as usize]);
    let longest = (b - a)
        .length_squared()
        .max((c - b).length_squared())
        .max((a - c).length_squared());
    let cross = (b - a).cross(c - a).length();
    // Written so that NaN coordinates also count as degenerate.
    cross.partial_cmp(&(ZERO_AREA_RELATIVE * longest)) != Some(std::cmp::Ordering::Greater)
}

/// Whether the triangles using an edge (`verts`, `tris`) disagree on the input normal at
/// either end point; each use's triangle is read once for both end points.
///
/// Corners that are the same input vertex carry the same normal: their normals are compared
/// only where the input vertices differ (a seam), so an edge of an indexed mesh reads no normal.
fn has_split_normals(
    verts: [VertId; 2],
    tris: &[EdgeUse],
    mesh: &TriMesh,
    tri_verts: &[[VertId; 3]],
) -> bool {
    // The first input vertex seen at each end point.
    let mut first: [Option<u32>; 2] = [None; 2];
    for u in tris {
        let t = u.tri().0 as usize;
        let (welded, input) = (tri_verts[t], mesh.triangles[t]);
        for (seen, v) in first.iter_mut().zip(verts) {
            let Some(corner) = welded.iter().position(|&c| c == v) else {
                continue;
            };
            let i = input[corner];
            match *seen {
                None => *seen = Some(i),
                Some(f) if f != i && mesh.normals[f as usize] != mesh.normals[i as usize] => {
                    return true
                }
                Some(_) => {}
            }
        }
    }
    false
}

#[cfg(test)]
pub(crate) mod tests {
    use super::weld::weld_by;
    use super::*;

    #[test]
    fn edge_uses_pack_triangle_and_corner_in_order() {
        let all: Vec<EdgeUse> = [
            (0, 2),
            (1, 0),
            (1, 1),
            (7, 2),
            (MAX_TRIANGLES as u32 - 1, 2),
        ]
        .iter()
        .map(|&(t, k)| EdgeUse::new(TriId(t), k))
        .collect();
        assert!(all.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(all[3].tri(), TriId(7));
        assert_eq!(all[3].corner(), 2);
        assert_eq!(all[4].at(), (MAX_TRIANGLES - 1, 2));
    }

    fn quad() -> TriMesh {
        // Two triangles over the diagonal 0-2, the second with its own copy of vertex 2 and a
        // different normal there; -0.0 must weld with +0.0.
        TriMesh {
            positions: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(-0.0, 1.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
            ],
            normals: vec![DVec3::Z, DVec3::Z, DVec3::Z, DVec3::Z, DVec3::X],
            triangles: vec![[0, 1, 2], [4, 3, 0]],
        }
    }

    #[test]
    fn welds_bit_equal_positions_and_signed_zero() {
        let topo = Topology::build(&quad());
        assert_eq!(topo.welded_positions.len(), 4);
        assert_eq!(topo.welded_of_vertex[4], topo.welded_of_vertex[2]);
    }

    #[test]
    fn finds_the_shared_diagonal_with_its_slots() {
        let topo = Topology::build(&quad());
        assert_eq!(topo.edge_count(), 5);
        // Edge 1 of triangle 0 runs from its corner 2 to corner 0 (the diagonal).
        let n = topo.neighbour(TriId(0), 1).expect("diagonal is interior");
        assert_eq!(n.tri, TriId(1));
        // f's corner i = 2 is g's slot 0 (vertex 4), f's corner j = 0 is g's slot 2.
        assert_eq!(n.slots, [0, 2, 1]);
        let diag = topo.edge(topo.tri_edges[0][1]);
        assert_eq!(diag.kind, EdgeKind::Interior);
        assert!(diag.split_normals);
        let boundary = topo.edges().filter(|e| e.kind == EdgeKind::Boundary);
        assert_eq!(boundary.count(), 4);
    }

    #[test]
    fn flags_non_manifold() {
        let mut mesh = quad();
        mesh.positions.push(DVec3::new(0.5, 0.5, 1.0));
        mesh.normals.push(DVec3::Z);
        mesh.triangles.push([0, 2, 5]);
        let topo = Topology::build(&mesh);
        let diag = topo.edge_between(VertId(0), VertId(2)).expect("diagonal");
        assert_eq!(topo.edge(diag).kind, EdgeKind::NonManifold);
        assert_eq!(topo.neighbour(TriId(0), 1), None);
        let w = topo.warnings();
        assert_eq!(
            w,
            vec![Warning::NonManifoldEdge {
                edge: diag,
                triangles: 3
            }]
        );
    }

    #[test]
    fn flags_degenerate_and_its_edges() {
        let mut mesh = quad();
        mesh.positions.push(DVec3::new(0.5, 0.5, 1.0));
        mesh.positions.push(DVec3::new(2.0, 2.0, 0.0));
        mesh.normals.extend([DVec3::Z, DVec3::Z]);
        mesh.triangles.push([0, 2, 5]); // third triangle on the diagonal
        mesh.triangles.push([0, 2, 6]); // collinear: zero area
        let topo = Topology::build(&mesh);
        let diag = topo.edge_between(VertId(0), VertId(2)).expect("diagonal");
        assert_eq!(topo.edge(diag).kind, EdgeKind::Degenerate);
        let w = topo.warnings();
        assert_eq!(w, vec![Warning::DegenerateTriangle { tri: TriId(3) }]);
    }

    /// Each edge's end points and uses, one vector per edge.
    type EdgeList = Vec<([VertId; 2], Vec<EdgeUse>)>;

    /// The adjacency rebuilt the obvious way (ordered maps, one vector per edge), to check the
    /// flat arrays against.
    fn reference(mesh: &TriMesh) -> (Vec<VertId>, EdgeList) {
        let mut ids = std::collections::BTreeMap::new();
        let welded: Vec<VertId> = mesh
            .positions
            .iter()
            .map(|p| {
                let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
                let next = VertId(ids.len() as u32);
                *ids.entry(key).or_insert(next)
            })
            .collect();
        let mut edges = std::collections::BTreeMap::<[VertId; 2], Vec<EdgeUse>>::new();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (
                    welded[tri[(k + 1) % 3] as usize],
                    welded[tri[(k + 2) % 3] as usize],
                );
                edges
                    .entry([a.min(b), a.max(b)])
                    .or_default()
                    .push(EdgeUse::new(TriId(t as u32), k as u8));
            }
        }
        (welded, edges.into_iter().collect())
    }

    /// Odd shapes on few positions: books (many triangles on one edge), fans, duplicates in
    /// every corner order, degenerate and open triangles, signed zeros. The geometry checks'
    /// tests use them too.
    pub(crate) fn odd_mesh(seed: u64, tris: usize) -> TriMesh {
        let mut state = seed;
        let mut next = move |n: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) % n
        };
        let positions: Vec<DVec3> = (0..24)
            .map(|_| {
                let c = |x: u64| if x == 0 { -0.0 } else { x as f64 - 1.0 };
                DVec3::new(c(next(3)), c(next(3)), c(next(2)))
            })
            .collect();
        let normals = (0..positions.len())
            .map(|i| if i % 5 == 0 { DVec3::X } else { DVec3::Z })
            .collect();
        let mut triangles = Vec::new();
        while triangles.len() < tris {
            let t = [next(24), next(24), next(24)].map(|v| v as u32);
            match next(4) {
                0 => triangles.push([0, 1, t[2]]),
                1 => triangles.push([3, t[1], t[2]]),
                _ => triangles.push(t),
            }
            if next(5) == 0 {
                triangles.push([t[1], t[0], t[2]]);
            }
        }
        TriMesh {
            positions,
            normals,
            triangles,
        }
    }

    /// An edge's normals split exactly where two of its uses put different normals at one end
    /// point (every pair compared), on odd shapes whose repeated positions carry the same or
    /// different normals; and never where the weld joins nothing, whatever the normals.
    #[test]
    fn split_normals_match_every_pair_of_corners() {
        for seed in 0..40 {
            let mut mesh = odd_mesh(seed, 10 + 7 * seed as usize);
            // Every vertex its own normal half the time: seams with equal and unequal normals.
            if seed % 2 == 1 {
                let n = mesh.positions.len();
                mesh.normals = (0..n).map(|i| DVec3::new(i as f64, 1.0, 0.0)).collect();
            }
            let topo = Topology::build(&mesh);
            for edge in topo.edges() {
                let normal_at = |u: &EdgeUse, v: VertId| {
                    let (t, welded) = (u.at().0, topo.tri_verts[u.at().0]);
                    let c = welded.iter().position(|&w| w == v)?;
                    Some(mesh.normals[mesh.triangles[t][c] as usize])
                };
                let split = edge.verts.iter().any(|&v| {
                    edge.tris.iter().any(|a| {
                        edge.tris
                            .iter()
                            .any(|b| match (normal_at(a, v), normal_at(b, v)) {
                                (Some(x), Some(y)) => x != y,
                                _ => false,
                            })
                    })
                });
                assert_eq!(
                    edge.split_normals, split,
                    "seed {seed} edge {:?}",
                    edge.verts
                );
            }
        }
        // Distinct positions, a different normal at every vertex: nothing is split.
        let mesh = TriMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::ONE],
            normals: vec![DVec3::X, DVec3::Y, DVec3::Z, DVec3::NEG_X],
            triangles: vec![[0, 1, 2], [2, 1, 3]],
        };
        let topo = Topology::build(&mesh);
        assert_eq!(topo.edge_count(), 5);
        assert!(topo.edges().all(|e| !e.split_normals));
    }

    #[test]
    fn flat_arrays_match_the_obvious_adjacency_on_odd_shapes() {
        for seed in 0..40 {
            let mesh = odd_mesh(seed, 10 + 7 * seed as usize);
            let topo = Topology::build(&mesh);
            let (welded, edges) = reference(&mesh);
            assert_eq!(topo.welded_of_vertex, welded);
            assert_eq!(topo.edge_count(), edges.len());
            for (e, (verts, uses)) in edges.iter().enumerate() {
                let edge = topo.edge(EdgeId(e as u32));
                assert_eq!((edge.verts, edge.tris), (*verts, uses.as_slice()));
                assert_eq!(
                    topo.edge_between(verts[1], verts[0]),
                    Some(EdgeId(e as u32))
                );
                for u in uses {
                    assert_eq!(topo.tri_edges[u.at().0][u.at().1], EdgeId(e as u32));
                }
                let degenerate =
                    verts[0] == verts[1] || uses.iter().any(|u| topo.degenerate[u.at().0]);
                let kind = match uses.len() {
                    _ if degenerate => EdgeKind::Degenerate,
                    1 => EdgeKind::Boundary,
                    2 => EdgeKind::Interior,
                    _ => EdgeKind::NonManifold,
                };
                assert_eq!(edge.kind, kind, "seed {seed} edge {e}");
                // The neighbour across an interior edge holds the same two welded corners in the
                // slots it names, and its third corner in the last.
                for u in uses {
                    let (f, k) = u.at();
                    let n = topo.neighbour(u.tri(), k);
                    assert_eq!(n.is_some(), kind == EdgeKind::Interior);
                    let Some(n) = n else { continue };
                    let other = uses.iter().find(|x| *x != u).expect("two uses");
                    assert_eq!(n.tri, other.tri());
                    let (vf, vg) = (topo.tri_verts[f], topo.tri_verts[n.tri.0 as usize]);
                    assert_eq!(vg[n.slots[0] as usize], vf[(k + 1) % 3]);
                    assert_eq!(vg[n.slots[1] as usize], vf[(k + 2) % 3]);
                    assert_eq!(n.slots[2], other.corner());
                }
            }
        }
    }

    #[test]
    fn the_weld_does_not_depend_on_the_hash_of_the_positions() {
        // Hashes that collide for every position, or for half of them, give the weld that the
        // position bits alone give (the reference numbers positions by first use).
        for seed in 0..20 {
            let mut mesh = odd_mesh(seed, 40);
            mesh.positions
                .extend((0..200).map(|i| DVec3::new(f64::from(i % 7), -0.0, f64::from(i % 5))));
            let (welded, _) = reference(&mesh);
            let want = weld(&mesh.positions);
            assert_eq!(want.0, welded, "seed {seed}");
            let first = |w: &[VertId]| -> Vec<DVec3> {
                let mut at = vec![None; w.iter().map(|v| v.0 as usize + 1).max().unwrap_or(0)];
                for (i, v) in w.iter().enumerate() {
                    at[v.0 as usize].get_or_insert(mesh.positions[i]);
                }
                at.into_iter().map(Option::unwrap).collect()
            };
            assert_eq!(want.1, first(&want.0));
            assert_eq!(weld_by(&mesh.positions, |_| 7), want, "seed {seed}");
            assert_eq!(weld_by(&mesh.positions, |b| b[0] & 1), want, "seed {seed}");
        }
    }

    #[test]
    fn the_edges_do_not_depend_on_how_the_vertices_are_cut_for_threads() {
        // Enough sides to be cut into ranges, on few vertices (crowded edges in every range)
        // and on many (a subdivided sphere).
        let odd = odd_mesh(3, PARALLEL_SIDES / 2);
        let (welded, edges) = reference(&odd);
        let mut sphere = TriMesh::default();
        let n = 120u32;
        for i in 0..=n {
            for j in 0..n {
                let (u, v) = (
                    f64::from(i) * std::f64::consts::PI / f64::from(n),
                    f64::from(j) * std::f64::consts::TAU / f64::from(n),
                );
                sphere
                    .positions
                    .push(DVec3::new(u.sin() * v.cos(), u.sin() * v.sin(), u.cos()));
                if i < n {
                    let at = |a: u32, b: u32| a * n + b % n;
                    sphere
                        .triangles
                        .push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                    sphere
                        .triangles
                        .push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
        sphere.normals = vec![DVec3::Z; sphere.positions.len()];
        assert!(3 * sphere.triangles.len() > PARALLEL_SIDES);
        let in_pool = |threads: usize, mesh: &TriMesh| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| Topology::build(mesh))
        };
        let one = in_pool(1, &odd);
        assert_eq!(one.welded_of_vertex, welded);
        assert_eq!(one.edge_count(), edges.len());
        for (e, (verts, uses)) in edges.iter().enumerate() {
            let edge = one.edge(EdgeId(e as u32));
            assert_eq!((edge.verts, edge.tris), (*verts, uses.as_slice()));
            for u in uses {
                assert_eq!(one.tri_edges[u.at().0][u.at().1], EdgeId(e as u32));
            }
        }
        for threads in [2, 3, 8] {
            assert_eq!(in_pool(threads, &odd), one, "{threads} threads");
        }
        let one = in_pool(1, &sphere);
        for threads in [2, 3, 5] {
            assert_eq!(in_pool(threads, &sphere), one, "{threads} threads");
        }
    }

    #[test]
    fn a_book_of_many_pages_is_one_non_manifold_edge() {
        let mut mesh = TriMesh {
            positions: vec![DVec3::ZERO, DVec3::X],
            ..TriMesh::default()
        };
        for p in 0..500 {
            let a = f64::from(p) * 0.01;
            mesh.positions.push(DVec3::new(0.5, a.cos(), a.sin()));
            mesh.triangles.push([0, 1, p + 2]);
        }
        mesh.normals = vec![DVec3::Z; mesh.positions.len()];
        let topo = Topology::build(&mesh);
        let spine = topo.edge_between(VertId(0), VertId(1)).expect("spine");
        assert_eq!(topo.edge(spine).kind, EdgeKind::NonManifold);
        assert_eq!(topo.edge_uses(spine).len(), 500);
        assert_eq!(topo.edge_count(), 1 + 2 * 500);
        assert!((0..500).all(|t| topo.neighbour(TriId(t), 2).is_none()));
    }

    #[test]
    fn an_empty_mesh_has_no_edges() {
        let topo = Topology::build(&TriMesh::default());
        assert_eq!((topo.edge_count(), topo.edges().count()), (0, 0));
        assert!(topo.warnings().is_empty());
    }

    #[test]
    fn every_array_is_sized_exactly_84_bytes_a_triangle_on_a_closed_mesh() {
        // A torus of m × n quads: V = mn vertices, T = 2mn triangles, E = 3mn edges.
        let (m, n) = (40u32, 25u32);
        let at = |i: u32, j: u32| (i % m) * n + (j % n);
        let mut mesh = TriMesh::default();
        for i in 0..m {
            for j in 0..n {
                let (u, v) = (
                    f64::from(i) * std::f64::consts::TAU / f64::from(m),
                    f64::from(j) * std::f64::consts::TAU / f64::from(n),
                );
                let r = 2.0 + v.cos();
                mesh.positions
                    .push(DVec3::new(r * u.cos(), r * u.sin(), v.sin()));
                mesh.triangles
                    .push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                mesh.triangles
                    .push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        mesh.normals = vec![DVec3::Z; mesh.positions.len()];
        let topo = Topology::build(&mesh);
        let (v, t, e) = ((m * n) as usize, (2 * m * n) as usize, (3 * m * n) as usize);
        assert_eq!(topo.edge_count(), e);
        assert!(topo.edges().all(|e| e.kind == EdgeKind::Interior));
        // Per vertex: its welded id and position (4 + 24); per triangle: corners, edges,
        // neighbours, uses (12 each) and the degenerate flag; per edge: end points, kind, split
        // flag and use offset (8 + 1 + 1 + 4), plus the closing offset.
        assert_eq!(topo.heap_bytes(), 28 * v + 49 * t + 14 * e + 4);
        assert_eq!(topo.heap_bytes() / t, 84);
    }
}
