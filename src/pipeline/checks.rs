//! What is odd about a mesh's geometry, summed up as one warning per kind for the report:
//! degenerate and sliver triangles, duplicate triangles, unused vertices, normals facing away
//! from their faces, open, non-manifold and inconsistently wound edges, bow-tie vertices, many
//! disconnected pieces.
//!
//! It only counts: the fallbacks live where the data is used (degenerate and non-manifold edges
//! act as h = 0 in [`crate::topology`], normals orient the surface, unused vertices are not
//! written). It deliberately reports one line per kind, with the first few triangles or vertices
//! as examples, so that a scan of a million bad triangles gives a readable report.

use glam::DVec3;
use rayon::prelude::*;

use super::warning::Warning;
use crate::mesh::TriMesh;
use crate::topology::{EdgeKind, Topology};

/// Triangles whose smallest angle is below this (in radians, about 0.06°) are slivers: valid,
/// but their normals and parameterization are numerically fragile.
const SLIVER_ANGLE: f64 = 1e-3;
/// Disconnected pieces above this count are worth a warning (debris, or a mesh exported
/// without welding).
const MANY_PIECES: usize = 1000;
/// Examples listed per warning.
const EXAMPLES: usize = 3;

/// One warning per odd kind of geometry found in `mesh` (the joined triangle primitives of mesh
/// `index`), each naming the fallback applied.
pub fn mesh_warnings(index: usize, mesh: &TriMesh, topo: &Topology) -> Vec<Warning> {
    let mut out = Vec::new();
    let degenerate: Vec<usize> = (0..topo.degenerate.len())
        .filter(|&t| topo.degenerate[t])
        .collect();
    if !degenerate.is_empty() {
        out.push(Warning::DegenerateTriangles {
            mesh: index,
            count: degenerate.len(),
            triangles: first(&degenerate),
        });
    }

    let sliver_cos = SLIVER_ANGLE.cos();
    let slivers: Vec<usize> = (0..mesh.triangles.len())
        .into_par_iter()
        .filter(|&t| !topo.degenerate[t] && largest_angle_cosine(mesh, t) > sliver_cos)
        .collect();
    if !slivers.is_empty() {
        out.push(Warning::SliverTriangles {
            mesh: index,
            count: slivers.len(),
            triangles: first(&slivers),
        });
    }

    let duplicates = duplicate_triangles(topo);
    if !duplicates.is_empty() {
        out.push(Warning::DuplicateTriangles {
            mesh: index,
            count: duplicates.len(),
            triangles: first(&duplicates),
        });
    }

    let mut used = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        for &c in t {
            used[c as usize] = true;
        }
    }
    let unused: Vec<usize> = (0..used.len()).filter(|&v| !used[v]).collect();
    if !unused.is_empty() {
        out.push(Warning::UnusedVertices {
            mesh: index,
            count: unused.len(),
            vertices: first(&unused),
        });
    }

    let facing_away: Vec<usize> = (0..mesh.triangles.len())
        .into_par_iter()
        .filter(|&t| {
            let tri = mesh.triangles[t];
            let [a, b, c] = tri.map(|v| mesh.positions[v as usize]);
            let face = (b - a).cross(c - a);
            !topo.degenerate[t]
                && tri
                    .iter()
                    .all(|&v| mesh.normals[v as usize].dot(face) < 0.0)
        })
        .collect();
    if !facing_away.is_empty() {
        out.push(Warning::NormalsFacingAway {
            mesh: index,
            count: facing_away.len(),
            triangles: first(&facing_away),
        });
    }

    let count = |kind: EdgeKind| topo.edges.iter().filter(|e| e.kind == kind).count();
    let boundary = count(EdgeKind::Boundary);
    if boundary > 0 {
        out.push(Warning::BoundaryEdges {
            mesh: index,
            count: boundary,
        });
    }
    let non_manifold: Vec<usize> = (0..topo.edges.len())
        .filter(|&e| topo.edges[e].kind == EdgeKind::NonManifold)
        .collect();
    if !non_manifold.is_empty() {
        out.push(Warning::NonManifoldEdges {
            mesh: index,
            count: non_manifold.len(),
            edges: first(&non_manifold),
        });
    }

    let flipped: Vec<usize> = (0..topo.edges.len())
        .filter(|&e| topo.edges[e].kind == EdgeKind::Interior && same_direction(topo, e))
        .collect();
    if !flipped.is_empty() {
        out.push(Warning::OppositeWindingEdges {
            mesh: index,
            count: flipped.len(),
            edges: first(&flipped),
        });
    }

    let bow_ties = bow_tie_vertices(topo);
    if !bow_ties.is_empty() {
        out.push(Warning::BowTieVertices {
            mesh: index,
            count: bow_ties.len(),
            vertices: first(&bow_ties),
        });
    }

    let pieces = pieces(topo);
    if pieces > MANY_PIECES {
        out.push(Warning::ManyPieces {
            mesh: index,
            pieces,
        });
    }
    out
}

/// The first few of `v`, as examples.
fn first(v: &[usize]) -> Vec<usize> {
    v[..v.len().min(EXAMPLES)].to_vec()
}

/// The cosine of the smallest angle of triangle `t`: comparing cosines instead of angles spares
/// three arc cosines per triangle, and the order is the same (the cosine falls as the angle
/// grows).
fn largest_angle_cosine(mesh: &TriMesh, t: usize) -> f64 {
    let p: [DVec3; 3] = mesh.triangles[t].map(|v| mesh.positions[v as usize]);
    (0..3)
        .map(|k| {
            let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            (a.dot(b) / (a.length_squared() * b.length_squared()).sqrt()).clamp(-1.0, 1.0)
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Triangles with the same three welded corners as an earlier triangle (in any order), in index
/// order. Sorting the corner triples groups the copies: no hash map over every triangle.
fn duplicate_triangles(topo: &Topology) -> Vec<usize> {
    let mut keyed: Vec<([u32; 3], u32)> = topo
        .tri_verts
        .par_iter()
        .enumerate()
        .filter_map(|(t, v)| {
            let mut key = v.map(|x| x.0);
            key.sort_unstable();
            (key[0] != key[1] && key[1] != key[2]).then_some((key, t as u32))
        })
        .collect();
    // Entries are distinct (the triangle index differs), so the order is the one there is.
    keyed.par_sort_unstable();
    let mut out: Vec<usize> = keyed
        .windows(2)
        .filter(|w| w[0].0 == w[1].0)
        .map(|w| w[1].1 as usize)
        .collect();
    out.sort_unstable();
    out
}

/// Do both triangles of interior edge `e` run along it in the same direction (one of them is
/// wound the other way)?
fn same_direction(topo: &Topology, e: usize) -> bool {
    let edge = &topo.edges[e];
    let dir = |(t, k): (crate::topology::TriId, u8)| {
        let v = topo.tri_verts[t.0 as usize];
        v[(k as usize + 1) % 3] == edge.verts[0]
    };
    dir(edge.tris[0]) == dir(edge.tris[1])
}

/// Welded vertices whose triangles form more than one fan (connected through edges that contain
/// the vertex).
///
/// One union-find over every (vertex, triangle) corner: each edge joins the corners of all its
/// triangles at each of its end points, once. Walking edges rather than triangles keeps this
/// linear in the corners whatever the valence (a book of 100 000 triangles on one edge, or
/// 100 000 copies of one triangle), where joining per triangle and edge use was cubic in it.
fn bow_tie_vertices(topo: &Topology) -> Vec<usize> {
    // The triangles around each welded vertex, in triangle order, as one array cut by offsets
    // (one allocation instead of one per vertex).
    let n = topo.welded_positions.len();
    let corners = |v: &[crate::topology::VertId; 3]| {
        let [a, b, c] = v.map(|x| x.0 as usize);
        [
            Some(a),
            (b != a).then_some(b),
            (c != a && c != b).then_some(c),
        ]
    };
    let mut start = vec![0usize; n + 1];
    for v in &topo.tri_verts {
        for x in corners(v).into_iter().flatten() {
            start[x + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut around = vec![0u32; start[n]];
    for (t, v) in topo.tri_verts.iter().enumerate() {
        for x in corners(v).into_iter().flatten() {
            around[fill[x]] = t as u32;
            fill[x] += 1;
        }
    }
    // The slot of triangle `t` in vertex `x`'s run of `around` (sorted by triangle).
    let slot = |x: usize, t: u32| {
        let run = &around[start[x]..start[x + 1]];
        start[x] + run.binary_search(&t).expect("the triangle uses the vertex")
    };
    let mut parent: Vec<usize> = (0..around.len()).collect();
    for e in &topo.edges {
        let [a, b] = e.verts.map(|v| v.0 as usize);
        let ends: &[usize] = if a == b { &[a] } else { &[a, b] };
        let Some(&(first, _)) = e.tris.first() else {
            continue;
        };
        for &x in ends {
            let s0 = slot(x, first.0);
            for &(t, _) in &e.tris[1..] {
                let (r0, r1) = (root(&mut parent, s0), root(&mut parent, slot(x, t.0)));
                parent[r1] = r0;
            }
        }
    }
    (0..n)
        .filter(|&v| {
            (start[v]..start[v + 1])
                .filter(|&s| root(&mut parent, s) == s)
                .nth(1)
                .is_some()
        })
        .collect()
}

/// Connected pieces of triangles (through welded edges).
fn pieces(topo: &Topology) -> usize {
    let n = topo.tri_verts.len();
    let mut parent: Vec<usize> = (0..n).collect();
    for e in &topo.edges {
        for w in e.tris.windows(2) {
            let (a, b) = (
                root(&mut parent, w[0].0 .0 as usize),
                root(&mut parent, w[1].0 .0 as usize),
            );
            parent[a] = b;
        }
    }
    (0..n).filter(|&i| root(&mut parent, i) == i).count()
}

/// The root of `i` in the union-find forest `p`, halving the path on the way.
fn root(p: &mut [usize], mut i: usize) -> usize {
    while p[i] != i {
        p[i] = p[p[i]];
        i = p[i];
    }
    i
}
