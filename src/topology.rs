//! Mesh adjacency: welds vertices by position and classifies every edge (interior, boundary,
//! non-manifold, degenerate, split normals), with each triangle edge's neighbour and its slots.
//!
//! It deliberately knows nothing of blend widths or surfaces: it only describes the mesh, and
//! reports bad geometry as [`Warning`]s instead of failing.
//!
//! Conventions: corner `k` of a triangle is opposite its edge `k`; edge `k` runs from corner
//! `(k + 1) % 3` (called `i`) to corner `(k + 2) % 3` (called `j`).

use rayon::slice::ParallelSliceMut as _;
use std::collections::HashMap;
use std::fmt;

use glam::DVec3;

use crate::mesh::TriMesh;

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

/// One welded edge.
#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    /// End points, smaller id first.
    pub verts: [VertId; 2],
    /// Classification; non-interior edges act as h = 0.
    pub kind: EdgeKind,
    /// Every use of the edge: the triangle and its local corner opposite the edge, in
    /// (triangle, corner) order, so the first use is the lowest-numbered triangle.
    pub tris: EdgeUses,
    /// The triangles using the edge carry different input normals at one of its end points
    /// (exact comparison: a hard edge, or a UV seam with slightly different normals).
    pub split_normals: bool,
}

/// The uses of one welded edge, `(triangle, local corner opposite the edge)`, read as a slice.
///
/// Up to two are held inline, as nearly every edge has one or two; more (a non-manifold edge)
/// go to the heap. With a vector per edge, the allocations were a third of the time spent
/// building the adjacency of a 100k-triangle mesh.
#[derive(Debug, Clone)]
pub struct EdgeUses(UsesRepr);

#[derive(Debug, Clone)]
enum UsesRepr {
    Inline { len: u8, uses: [(TriId, u8); 2] },
    Heap(Vec<(TriId, u8)>),
}

impl EdgeUses {
    /// No uses yet.
    pub const fn new() -> Self {
        EdgeUses(UsesRepr::Inline {
            len: 0,
            uses: [(TriId(0), 0); 2],
        })
    }

    /// Adds a use.
    pub fn push(&mut self, item: (TriId, u8)) {
        match &mut self.0 {
            UsesRepr::Inline { len, uses } if (*len as usize) < uses.len() => {
                uses[*len as usize] = item;
                *len += 1;
            }
            UsesRepr::Inline { uses, .. } => {
                let mut spilled = uses.to_vec();
                spilled.push(item);
                self.0 = UsesRepr::Heap(spilled);
            }
            UsesRepr::Heap(v) => v.push(item),
        }
    }

    /// The uses in the order they were added.
    pub fn as_slice(&self) -> &[(TriId, u8)] {
        match &self.0 {
            UsesRepr::Inline { len, uses } => &uses[..*len as usize],
            UsesRepr::Heap(v) => v,
        }
    }
}

impl Default for EdgeUses {
    fn default() -> Self {
        EdgeUses::new()
    }
}

impl std::ops::Deref for EdgeUses {
    type Target = [(TriId, u8)];
    fn deref(&self) -> &Self::Target {
        self.as_slice()
    }
}

impl<'a> IntoIterator for &'a EdgeUses {
    type Item = &'a (TriId, u8);
    type IntoIter = std::slice::Iter<'a, (TriId, u8)>;
    fn into_iter(self) -> Self::IntoIter {
        self.as_slice().iter()
    }
}

impl PartialEq for EdgeUses {
    fn eq(&self, other: &Self) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl Eq for EdgeUses {}

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

/// Welded adjacency of a [`TriMesh`].
#[derive(Debug, Clone, PartialEq)]
pub struct Topology {
    /// Input vertex index to welded vertex (bit-equal positions; -0.0 equals +0.0).
    pub welded_of_vertex: Vec<VertId>,
    /// One position per welded vertex (the first input vertex seen).
    pub welded_positions: Vec<DVec3>,
    /// Welded corners per triangle, in input corner order.
    pub tri_verts: Vec<[VertId; 3]>,
    /// One per welded edge, sorted by `verts`.
    pub edges: Vec<Edge>,
    /// `tri_edges[t][k]` is the edge opposite corner `k` of triangle `t`.
    pub tri_edges: Vec<[EdgeId; 3]>,
    /// `neighbours[t][k]`: the triangle across edge `k` of `t`, for interior edges only.
    pub neighbours: Vec<[Option<Neighbour>; 3]>,
    /// Degenerate triangles (two welded corners or zero area).
    pub degenerate: Vec<bool>,
}

/// A triangle counts as zero-area when |cross| <= this × (longest edge)²: a few ulps of the
/// squared length, so only exactly flat (collinear up to rounding) triangles qualify.
const ZERO_AREA_RELATIVE: f64 = 1e-14;

impl Topology {
    /// Welds `mesh` and builds its edges. Never fails: odd geometry is classified, not rejected.
    pub fn build(mesh: &TriMesh) -> Topology {
        let (welded_of_vertex, welded_positions) = weld(&mesh.positions);
        let tri_verts: Vec<[VertId; 3]> = mesh
            .triangles
            .iter()
            .map(|t| t.map(|c| welded_of_vertex[c as usize]))
            .collect();
        let degenerate: Vec<bool> = tri_verts
            .iter()
            .map(|v| is_degenerate(v, &welded_positions))
            .collect();

        // Every half-edge as (canonical key, triangle, opposite corner); sorting groups the
        // uses of one edge together and puts edges in canonical order.
        let mut half: Vec<([VertId; 2], TriId, u8)> = Vec::with_capacity(3 * tri_verts.len());
        for (t, v) in tri_verts.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (v[(k + 1) % 3], v[(k + 2) % 3]);
                half.push(([a.min(b), a.max(b)], TriId(t as u32), k as u8));
            }
        }
        // Entries are distinct, so the parallel sort's result is the one order there is.
        half.par_sort_unstable();

        // A closed mesh has half as many edges as half-edges; an open one grows the vector.
        let mut edges: Vec<Edge> = Vec::with_capacity(half.len() / 2);
        let mut tri_edges = vec![[EdgeId(0); 3]; tri_verts.len()];
        for (key, t, k) in half {
            if edges.last().is_none_or(|e| e.verts != key) {
                edges.push(Edge {
                    verts: key,
                    kind: EdgeKind::Boundary,
                    tris: EdgeUses::new(),
                    split_normals: false,
                });
            }
            let id = EdgeId(edges.len() as u32 - 1);
            edges.last_mut().expect("just pushed").tris.push((t, k));
            tri_edges[t.0 as usize][k as usize] = id;
        }

        let mut neighbours = vec![[None; 3]; tri_verts.len()];
        for edge in &mut edges {
            let uses_degenerate = edge.tris.iter().any(|&(t, _)| degenerate[t.0 as usize]);
            edge.kind = if edge.verts[0] == edge.verts[1] || uses_degenerate {
                EdgeKind::Degenerate
            } else {
                match edge.tris.len() {
                    1 => EdgeKind::Boundary,
                    2 => EdgeKind::Interior,
                    _ => EdgeKind::NonManifold,
                }
            };
            edge.split_normals = has_split_normals(edge, mesh, &tri_verts);
            if edge.kind == EdgeKind::Interior {
                let [(f, kf), (g, kg)] = [edge.tris[0], edge.tris[1]];
                neighbours[f.0 as usize][kf as usize] = Some(neighbour(&tri_verts, f, kf, g, kg));
                neighbours[g.0 as usize][kg as usize] = Some(neighbour(&tri_verts, g, kg, f, kf));
            }
        }

        Topology {
            welded_of_vertex,
            welded_positions,
            tri_verts,
            edges,
            tri_edges,
            neighbours,
            degenerate,
        }
    }

    /// The welded edge between two welded vertices, if there is one.
    pub fn edge_between(&self, a: VertId, b: VertId) -> Option<EdgeId> {
        let key = [a.min(b), a.max(b)];
        self.edges
            .binary_search_by(|e| e.verts.cmp(&key))
            .ok()
            .map(|i| EdgeId(i as u32))
    }

    /// The edge with this id.
    pub fn edge(&self, id: EdgeId) -> &Edge {
        &self.edges[id.0 as usize]
    }

    /// The triangle across edge `k` of `tri`, if that edge is interior.
    pub fn neighbour(&self, tri: TriId, k: usize) -> Option<Neighbour> {
        self.neighbours[tri.0 as usize][k]
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
            .edges
            .iter()
            .enumerate()
            .filter(|(_, e)| e.kind == EdgeKind::NonManifold)
            .map(|(i, e)| Warning::NonManifoldEdge {
                edge: EdgeId(i as u32),
                triangles: e.tris.len(),
            });
        tris.chain(edges).collect()
    }
}

/// Welds bit-equal positions (after mapping -0.0 to +0.0), numbering them by first use.
fn weld(positions: &[DVec3]) -> (Vec<VertId>, Vec<DVec3>) {
    let mut index: HashMap<[u64; 3], VertId> = HashMap::with_capacity(positions.len());
    let mut welded = Vec::new();
    let of_vertex = positions
        .iter()
        .map(|p| {
            // x + 0.0 is +0.0 for x = -0.0 and x itself otherwise.
            let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
            *index.entry(key).or_insert_with(|| {
                welded.push(*p);
                VertId(welded.len() as u32 - 1)
            })
        })
        .collect();
    (of_vertex, welded)
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

/// Whether the triangles using `edge` disagree on the input normal at either end point.
fn has_split_normals(edge: &Edge, mesh: &TriMesh, tri_verts: &[[VertId; 3]]) -> bool {
    edge.verts.iter().any(|&v| {
        let mut normals = edge.tris.iter().filter_map(|&(t, _)| {
            let corner = tri_verts[t.0 as usize].iter().position(|&c| c == v)?;
            Some(mesh.normals[mesh.triangles[t.0 as usize][corner] as usize])
        });
        match normals.next() {
            Some(first) => normals.any(|n| n != first),
            None => false,
        }
    })
}

/// Slots of g (whose edge `kg` is f's edge `kf`) holding f's corners i, j and g's third corner.
fn neighbour(tri_verts: &[[VertId; 3]], f: TriId, kf: u8, g: TriId, kg: u8) -> Neighbour {
    let vf = tri_verts[f.0 as usize];
    let vg = tri_verts[g.0 as usize];
    let i = vf[(kf as usize + 1) % 3];
    let slot_of = |v: VertId| vg.iter().position(|&c| c == v).expect("shared corner") as u8;
    Neighbour {
        tri: g,
        slots: if slot_of(i) == (kg + 1) % 3 {
            [(kg + 1) % 3, (kg + 2) % 3, kg]
        } else {
            [(kg + 2) % 3, (kg + 1) % 3, kg]
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edge_uses_keep_their_order_inline_and_spilled() {
        let mut uses = EdgeUses::new();
        assert!(uses.is_empty());
        let all: Vec<(TriId, u8)> = (0..5).map(|t| (TriId(10 - t), (t % 3) as u8)).collect();
        for (n, &u) in all.iter().enumerate() {
            uses.push(u);
            assert_eq!(uses.as_slice(), &all[..=n]);
        }
        assert_eq!(uses.iter().count(), 5);
        assert_eq!((&uses).into_iter().copied().collect::<Vec<_>>(), all);
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
        assert_eq!(topo.edges.len(), 5);
        // Edge 1 of triangle 0 runs from its corner 2 to corner 0 (the diagonal).
        let n = topo.neighbour(TriId(0), 1).expect("diagonal is interior");
        assert_eq!(n.tri, TriId(1));
        // f's corner i = 2 is g's slot 0 (vertex 4), f's corner j = 0 is g's slot 2.
        assert_eq!(n.slots, [0, 2, 1]);
        let diag = topo.edge(topo.tri_edges[0][1]);
        assert_eq!(diag.kind, EdgeKind::Interior);
        assert!(diag.split_normals);
        let boundary = topo.edges.iter().filter(|e| e.kind == EdgeKind::Boundary);
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
}
