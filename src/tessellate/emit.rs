//! Writing one source triangle into its block: the per-triangle loop the uniform and the
//! per-edge-count tessellators share. They differ only in how a triangle's lattice is laid out
//! (one [`super::plan::LatticePlan`] per level, or one transition pattern per set of counts);
//! each step here takes the layout's answer (which local point, which output slot) and does
//! the rest the same way on both paths:
//! - corners are the input vertices, written by the triangle that owns them;
//! - edge samples take their position from the welded edge's one evaluating triangle (so a
//!   welded edge is bit-watertight), evaluated in place by the same call, and their normal from
//!   this side's own surface (normals differ across a crease);
//! - interior points are evaluated here, as one lattice part;
//! - triangles are written by local point, through the local-to-slot map the steps fill.

use super::blocks::Block;
use super::{canonical_forward, corner_vertex, evaluator, VertexSource};
use crate::mesh::TriMesh;
use crate::surface::{LatticePart, Surface, SurfacePoint};
use crate::topology::Topology;

/// What the steps of one triangle read, and the scratch they reuse from triangle to triangle.
pub(super) struct TriangleWriter<'a> {
    pub mesh: &'a TriMesh,
    pub topo: &'a Topology,
    pub surface: &'a dyn Surface,
    own_edge: Vec<SurfacePoint>,
    evaluator_edge: Vec<SurfacePoint>,
    interior: Vec<SurfacePoint>,
    /// The parts [`TriangleWriter::evaluate_parts`] evaluated together, for triangle
    /// `batch_tri`: their points one part after another, and where each part's run starts.
    batch: Vec<SurfacePoint>,
    batch_tri: usize,
    batch_parts: Vec<(u32, LatticePart, usize)>,
}

impl<'a> TriangleWriter<'a> {
    /// A writer for triangles of `surface`. Edge samples are evaluated by the triangle that
    /// writes them, straight into the output: positions always from the welded edge's
    /// [`evaluator`] (the same call gives the same bits, so a welded edge stays bit-watertight
    /// without an array in between), normals from the writing side. Only a side that is not
    /// the evaluator (a split copy: a seam, a crease, another group) evaluates the edge twice.
    pub fn new(mesh: &'a TriMesh, topo: &'a Topology, surface: &'a dyn Surface) -> Self {
        TriangleWriter {
            mesh,
            topo,
            surface,
            own_edge: Vec::new(),
            evaluator_edge: Vec::new(),
            interior: Vec::new(),
            batch: Vec::new(),
            batch_tri: usize::MAX,
            batch_parts: Vec::new(),
        }
    }

    /// Evaluates the parts `(level, part)` of `tri` that the steps of this triangle will write,
    /// in one call ([`Surface::evaluate_lattice_parts`]): the surface sets the triangle up once
    /// for all of them instead of once per part. The steps then read them from here; a part not
    /// named is evaluated by its step, with the same bits.
    pub fn evaluate_parts(&mut self, tri: usize, parts: &[(u32, LatticePart)]) {
        self.batch.clear();
        self.batch_parts.clear();
        self.batch_tri = tri;
        self.surface
            .evaluate_lattice_parts(tri, parts, &mut self.batch);
        let mut start = 0;
        for &(level, part) in parts {
            self.batch_parts.push((level, part, start));
            start += part.len(level);
        }
        debug_assert_eq!(start, self.batch.len());
    }

    /// Where part `(level, part)` of `tri` lies in the batch, if [`TriangleWriter::evaluate_parts`]
    /// evaluated it.
    #[inline]
    fn batched(&self, tri: usize, level: u32, part: LatticePart) -> Option<usize> {
        if self.batch_tri != tri {
            return None;
        }
        self.batch_parts
            .iter()
            .find(|&&(l, p, _)| l == level && p == part)
            .map(|&(_, _, start)| start)
    }

    /// Corner `c` of `tri`, local point `point`, output slot `slot`; written if `owned`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn corner(
        &self,
        block: &mut Block<'_>,
        local: &mut [u32],
        tri: usize,
        c: usize,
        point: usize,
        slot: usize,
        owned: bool,
        source: VertexSource,
    ) {
        local[point] = slot as u32;
        if owned {
            let (position, normal) = corner_vertex(self.mesh, self.surface, tri, c);
            block.put(slot, position, normal, source);
        }
    }

    /// The `n − 1` samples of edge `k` of `tri`: sample `m` (1 to n − 1, from corner
    /// `(k + 1) % 3`) is local point `point(m)`; the edge's output slots start at `first_slot`
    /// and run from its lower input vertex (`ascending`: that is corner `(k + 1) % 3`). Written
    /// if `owned`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn edge(
        &mut self,
        block: &mut Block<'_>,
        local: &mut [u32],
        tri: usize,
        k: usize,
        n: u32,
        first_slot: usize,
        ascending: bool,
        owned: bool,
        point: impl Fn(u32) -> usize,
        source: impl Fn(usize) -> VertexSource,
    ) {
        // No samples (one segment): nothing to number, and no surface to set up for none.
        if n <= 1 {
            return;
        }
        let slot = |m: u32| edge_slot(first_slot, ascending, n, m);
        if !owned {
            for m in 1..n {
                local[point(m)] = slot(m) as u32;
            }
            return;
        }
        let e = self.topo.tri_edges[tri][k].0 as usize;
        let forward = canonical_forward(self.topo, tri, k);
        let evaluated_by = evaluator(self.topo, e);
        let evaluated_here = evaluated_by == Some((tri, k));
        let own_start = self.batched(tri, n, LatticePart::Edge(k as u8));
        if own_start.is_none() {
            self.own_edge.clear();
            self.surface.evaluate_lattice_part(
                tri,
                n,
                LatticePart::Edge(k as u8),
                &mut self.own_edge,
            );
        }
        let own_edge = match own_start {
            Some(start) => &self.batch[start..start + (n - 1) as usize],
            None => &self.own_edge[..],
        };
        // The evaluator's run, and whether it is walked the same way as this side's.
        let mut same_direction = true;
        if !evaluated_here {
            if let Some((te, ke)) = evaluated_by {
                self.evaluator_edge.clear();
                self.surface.evaluate_lattice_part(
                    te,
                    n,
                    LatticePart::Edge(ke as u8),
                    &mut self.evaluator_edge,
                );
                same_direction = canonical_forward(self.topo, te, ke) == forward;
            }
        }
        let positions = if evaluated_here || evaluated_by.is_none() {
            own_edge
        } else {
            &self.evaluator_edge
        };
        for m in 1..n {
            let (p, s) = (point(m), slot(m));
            local[p] = s as u32;
            let at = (if same_direction { m } else { n - m } - 1) as usize;
            block.put(
                s,
                positions[at].position.as_vec3().to_array(),
                own_edge[(m - 1) as usize].normal.as_vec3().to_array(),
                source(p),
            );
        }
    }

    /// The interior of `tri` on its lattice of `level`: `by_rank` gives, in output order, each
    /// interior point's local point and its index in the lattice part; their slots are
    /// consecutive from `first_slot`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn interior(
        &mut self,
        block: &mut Block<'_>,
        local: &mut [u32],
        tri: usize,
        level: u32,
        first_slot: usize,
        by_rank: impl Iterator<Item = (usize, usize)>,
        source: impl Fn(usize) -> VertexSource,
    ) {
        let interior = match self.batched(tri, level, LatticePart::Interior) {
            Some(start) => &self.batch[start..],
            None => {
                self.interior.clear();
                self.surface.evaluate_lattice_part(
                    tri,
                    level,
                    LatticePart::Interior,
                    &mut self.interior,
                );
                &self.interior[..]
            }
        };
        for (rank, (point, index)) in by_rank.enumerate() {
            let slot = first_slot + rank;
            local[point] = slot as u32;
            let p = &interior[index];
            block.put(
                slot,
                p.position.as_vec3().to_array(),
                p.normal.as_vec3().to_array(),
                source(point),
            );
        }
    }
}

/// The output slot of sample `m` (1 to n − 1, counted from corner `(k + 1) % 3`) of an edge whose
/// slots start at `first_slot` and run from its lower input vertex (`ascending`: that is corner
/// `(k + 1) % 3`). One formula for the pass that evaluates the samples and the one that numbers
/// the triangles after the surface is freed: they must agree slot for slot.
#[inline]
pub(super) fn edge_slot(first_slot: usize, ascending: bool, n: u32, m: u32) -> usize {
    first_slot + (if ascending { m } else { n - m } - 1) as usize
}

/// `triangles` by local point, written as output slots through `local`.
#[inline]
pub(super) fn triangles(out: &mut [u32], triangles: &[[u32; 3]], local: &[u32]) {
    for (dst, t) in out.chunks_exact_mut(3).zip(triangles) {
        dst[0] = local[t[0] as usize];
        dst[1] = local[t[1] as usize];
        dst[2] = local[t[2] as usize];
    }
}
