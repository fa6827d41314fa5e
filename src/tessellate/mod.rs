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

mod lattice_edges;

use crate::mesh::TriMesh;
use crate::surface::{lattice_bary, lattice_index, lattice_len, Surface, SurfacePoint};
use crate::topology::{EdgeId, Topology};
use glam::DVec3;
use lattice_edges::{edge_sample_coords, SampleKind};
use std::ops::Range;

/// Where an output vertex was sampled: a source triangle (index into the whole mesh) and the
/// barycentric coordinates inside it. Attributes are interpolated from these.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexSource {
    /// Source triangle in the whole mesh.
    pub tri: u32,
    /// Barycentric coordinates in that triangle's corner order.
    pub bary: [f32; 3],
}

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

/// Tessellates `groups` (contiguous triangle ranges of `mesh`, one per output primitive) at
/// level `level` (≥ 1). `h` is the blend width per welded edge, used only to decide which
/// interior edges are creases (h = 0) and get split output vertices.
pub fn tessellate(
    mesh: &TriMesh,
    topo: &Topology,
    h: &[f64],
    surface: &dyn Surface,
    level: u32,
    groups: &[Range<usize>],
) -> Vec<DenseMesh> {
    let n = level.max(1);
    let edge_positions = shared_edge_positions(mesh, topo, surface, n);
    groups
        .iter()
        .map(|range| tessellate_group(mesh, topo, h, surface, n, range.clone(), &edge_positions))
        .collect()
}

/// Samples of every welded edge, `n - 1` per edge in the edge's canonical direction
/// (`verts[0]` to `verts[1]`), evaluated by the edge's lowest-numbered triangle.
fn shared_edge_positions(
    mesh: &TriMesh,
    topo: &Topology,
    surface: &dyn Surface,
    n: u32,
) -> Vec<DVec3> {
    let per_edge = (n - 1) as usize;
    let mut out = vec![DVec3::ZERO; topo.edges.len() * per_edge];
    let mut done = vec![false; topo.edges.len()];
    for tri in 0..mesh.triangles.len() {
        for k in 0..3 {
            let e = topo.tri_edges[tri][k];
            if done[e.0 as usize] {
                continue;
            }
            done[e.0 as usize] = true;
            let forward = canonical_forward(topo, tri, k);
            for m in 1..n {
                let (i, j) = edge_sample_coords(n, k, m);
                let bary = lattice_bary(n, i, j);
                let slot = if forward { m } else { n - m };
                out[e.0 as usize * per_edge + (slot - 1) as usize] =
                    surface.evaluate(tri, bary).position;
            }
        }
    }
    out
}

/// Whether the edge opposite corner `k` of `tri`, walked from corner `k+1` to corner `k+2`,
/// runs in its welded edge's canonical direction.
fn canonical_forward(topo: &Topology, tri: usize, k: usize) -> bool {
    let edge = &topo.edges[topo.tri_edges[tri][k].0 as usize];
    let from = topo.tri_verts[tri][(k + 1) % 3];
    from == edge.verts[0]
}

/// Lower and higher input vertex index, then the triangle and corner for a crease side (or
/// `u32::MAX` and 0 where both sides share).
type InputEdgeKey = (u32, u32, u32, u8);

/// An input edge: the unordered pair of input vertex indices, plus (for creases) the triangle
/// side it belongs to. Half-edges with the same key share output vertices.
fn input_edge_key(mesh: &TriMesh, crease: bool, tri: usize, k: usize) -> InputEdgeKey {
    let t = mesh.triangles[tri];
    let a = t[(k + 1) % 3];
    let b = t[(k + 2) % 3];
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    if crease {
        (lo, hi, tri as u32, k as u8)
    } else {
        (lo, hi, u32::MAX, 0)
    }
}

fn is_crease(topo: &Topology, h: &[f64], e: EdgeId) -> bool {
    h.get(e.0 as usize).is_some_and(|&v| v == 0.0) && topo.edges[e.0 as usize].tris.len() >= 2
}

const UNSET: u32 = u32::MAX;

fn tessellate_group(
    mesh: &TriMesh,
    topo: &Topology,
    h: &[f64],
    surface: &dyn Surface,
    n: u32,
    range: Range<usize>,
    edge_positions: &[DVec3],
) -> DenseMesh {
    let per_edge = (n - 1) as usize;
    let tri_count = range.len();

    // Input edges of this group, numbered in first-seen order so numbering is deterministic.
    let mut keys: Vec<InputEdgeKey> = Vec::with_capacity(tri_count * 3);
    for tri in range.clone() {
        for k in 0..3 {
            let crease = is_crease(topo, h, topo.tri_edges[tri][k]);
            keys.push(input_edge_key(mesh, crease, tri, k));
        }
    }
    let mut order: Vec<usize> = (0..keys.len()).collect();
    order.sort_by_key(|&i| (keys[i], i));
    // input_edge_of[half-edge] = dense id of its input edge, ids in order of first appearance.
    let mut input_edge_of = vec![0u32; keys.len()];
    let mut first_of_id: Vec<usize> = Vec::new();
    let mut run_start = 0;
    while run_start < order.len() {
        let mut run_end = run_start + 1;
        while run_end < order.len() && keys[order[run_end]] == keys[order[run_start]] {
            run_end += 1;
        }
        let id = first_of_id.len() as u32;
        first_of_id.push(order[run_start]);
        for &half in &order[run_start..run_end] {
            input_edge_of[half] = id;
        }
        run_start = run_end;
    }
    // Renumber ids by first appearance so the output does not depend on the sort.
    let mut renumber = vec![UNSET; first_of_id.len()];
    let mut next = 0u32;
    for id in input_edge_of.iter_mut() {
        let old = *id as usize;
        if renumber[old] == UNSET {
            renumber[old] = next;
            next += 1;
        }
        *id = renumber[old];
    }
    let input_edge_count = next as usize;

    // Output vertex layout: corners first (numbered as first referenced), then edge samples,
    // then interior samples per triangle.
    let mut corner_out = vec![UNSET; mesh.positions.len()];
    let mut corner_count = 0u32;
    for tri in range.clone() {
        for &v in &mesh.triangles[tri] {
            if corner_out[v as usize] == UNSET {
                corner_out[v as usize] = corner_count;
                corner_count += 1;
            }
        }
    }
    let edge_base = corner_count as usize;
    let interior_per_tri = if n >= 3 {
        ((n - 1) * (n - 2) / 2) as usize
    } else {
        0
    };
    let interior_base = edge_base + input_edge_count * per_edge;
    let vertex_count = interior_base + tri_count * interior_per_tri;

    let mut out = DenseMesh {
        positions: vec![[0.0; 3]; vertex_count],
        normals: vec![[0.0; 3]; vertex_count],
        sources: vec![
            VertexSource {
                tri: 0,
                bary: [0.0; 3]
            };
            vertex_count
        ],
        indices: Vec::with_capacity(tri_count * (n * n) as usize * 3),
    };
    let mut written = vec![false; vertex_count];
    let mut lattice: Vec<SurfacePoint> = Vec::with_capacity(lattice_len(n));
    let mut local = vec![0u32; lattice_len(n)];

    for (offset, tri) in range.clone().enumerate() {
        lattice.clear();
        surface.evaluate_lattice(tri, n, &mut lattice);
        for j in 0..=n {
            for i in 0..=(n - j) {
                let li = lattice_index(n, i, j);
                let (slot, position) = match SampleKind::of(n, i, j) {
                    SampleKind::Corner(c) => {
                        // The vertex's own position, not its welded representative: welding
                        // equates -0.0 and +0.0, and the input's bits are kept.
                        let v = mesh.triangles[tri][c];
                        (corner_out[v as usize] as usize, mesh.positions[v as usize])
                    }
                    SampleKind::Edge { k, m } => {
                        let half = offset * 3 + k;
                        let e = topo.tri_edges[tri][k].0 as usize;
                        let (a_in, b_in) = {
                            let t = mesh.triangles[tri];
                            (t[(k + 1) % 3], t[(k + 2) % 3])
                        };
                        // Output slot along the input edge, walked from its lower input index.
                        let slot_m = if a_in <= b_in { m } else { n - m };
                        let slot = edge_base
                            + input_edge_of[half] as usize * per_edge
                            + (slot_m - 1) as usize;
                        let welded_m = if canonical_forward(topo, tri, k) {
                            m
                        } else {
                            n - m
                        };
                        (slot, edge_positions[e * per_edge + (welded_m - 1) as usize])
                    }
                    SampleKind::Interior { index } => (
                        interior_base + offset * interior_per_tri + index,
                        lattice[li].position,
                    ),
                };
                local[li] = slot as u32;
                if !written[slot] {
                    written[slot] = true;
                    let bary = lattice_bary(n, i, j);
                    out.positions[slot] = position.as_vec3().to_array();
                    out.normals[slot] = lattice[li].normal.as_vec3().to_array();
                    out.sources[slot] = VertexSource {
                        tri: tri as u32,
                        bary: [bary[0] as f32, bary[1] as f32, bary[2] as f32],
                    };
                }
            }
        }
        emit_triangles(n, &local, &mut out.indices);
    }
    out
}

/// Appends the `n²` sub-triangles of one lattice, wound like the source triangle.
fn emit_triangles(n: u32, local: &[u32], indices: &mut Vec<u32>) {
    for j in 0..n {
        for i in 0..(n - j) {
            let a = local[lattice_index(n, i, j)];
            let b = local[lattice_index(n, i + 1, j)];
            let c = local[lattice_index(n, i, j + 1)];
            indices.extend_from_slice(&[a, b, c]);
            if i + j + 1 < n {
                let d = local[lattice_index(n, i + 1, j + 1)];
                indices.extend_from_slice(&[b, d, c]);
            }
        }
    }
}
