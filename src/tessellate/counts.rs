//! How many segments each welded edge and each triangle's interior need for the output to stay
//! within a chord error of the smooth surface, or within a triangle budget.
//!
//! The chord error of linear interpolation over a triangle with edge vectors `d_ab` is, for a
//! surface that is locally quadratic, `S(λ) − L(λ) = ½ Σ_{a<b} λ_a λ_b d_abᵀ H d_ab`, at most
//! `K/6` (at the centroid) where `K` is the largest second difference along an edge; along a
//! single edge curve it is `K/8` (at the midpoint). Both fall as `1/n²` with the segment count.
//! So one probe per triangle, the level-[`PROBE_LEVEL`] lattice and its second differences in
//! the three lattice directions, gives each triangle and each edge an error constant `c` with
//! error ≈ `c/n²`; the counts for any tolerance, and the tolerance that meets a budget, follow
//! without evaluating the surface again.
//!
//! Two balance rules keep the transition patterns well shaped (`transition.rs`): a triangle's
//! inner level is at least each of its edge counts, and each edge count is at least half the
//! inner level of each triangle beside it. Raising one value raises its neighbours to half of
//! it, so the propagation dies out within `log₂(cap)` steps: a few sweeps over the mesh.
//!
//! It deliberately builds no pattern and writes no vertex.

use rayon::prelude::*;

use super::chord::predicted_error;
use super::evaluator;
use super::transition::{Pattern, PatternKey};
use crate::mesh::TriMesh;
use crate::surface::{lattice_index, Surface, SurfacePoint};
use crate::topology::Topology;

/// Lattice level of the probe: 28 surface points per triangle, a fifth of what level 16
/// writes, and enough second differences to see a blending region's curvature.
pub const PROBE_LEVEL: u32 = 6;

/// Margin on the predicted error: the probe sees the curvature at its own points only, and
/// the transition rings hold triangles up to twice as long as the inner lattice's. Measured
/// on the icosphere, torus, bumpy sphere, height field and domed plate (`tests/integration/tessellate_adaptive.rs`),
/// the error reached without it is up to 4% over the target.
pub const MARGIN: f64 = 1.25;

/// The chord error constants of a mesh's surface: error ≈ `c / n²` at `n` segments.
#[derive(Debug, Clone)]
pub struct ChordErrors {
    /// Per source triangle, for its interior.
    pub triangles: Vec<f64>,
    /// Per welded edge, for its curve.
    pub edges: Vec<f64>,
}

/// Segment counts of one mesh: per welded edge and per source triangle's interior.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SegmentCounts {
    /// Segments along each welded edge (both sides use them: watertight by construction).
    pub edges: Vec<u32>,
    /// Inner lattice level of each source triangle.
    pub inner: Vec<u32>,
}

impl ChordErrors {
    /// Probes `surface` once per triangle.
    pub fn probe(mesh: &TriMesh, topo: &Topology, surface: &dyn Surface) -> ChordErrors {
        let p = PROBE_LEVEL;
        let scale = f64::from(p * p);
        let per_tri: Vec<(f64, [f64; 3])> = (0..mesh.triangles.len())
            .into_par_iter()
            .map_init(Vec::new, |points: &mut Vec<SurfacePoint>, tri| {
                points.clear();
                surface.evaluate_lattice(tri, p, points);
                let (inner, edges) = second_differences(points, p);
                (
                    finite(inner * scale / 6.0),
                    edges.map(|d| finite(d * scale / 8.0)),
                )
            })
            .collect();
        let mut edges = vec![0.0f64; topo.edge_count()];
        for (e, c) in edges.iter_mut().enumerate() {
            // The evaluator's side: the one whose samples are written.
            if let Some((tri, k)) = evaluator(topo, e) {
                *c = per_tri[tri].1[k];
            }
        }
        ChordErrors {
            triangles: per_tri.iter().map(|t| t.0).collect(),
            edges,
        }
    }

    /// The counts that keep the chord error at or below `tolerance`, each at most `cap`.
    pub fn counts(&self, topo: &Topology, tolerance: f64, cap: u32) -> SegmentCounts {
        let need = |c: f64| -> u32 {
            let n = (MARGIN * c / tolerance).sqrt().ceil();
            if n.is_nan() || n < 1.0 {
                1
            } else {
                n.min(f64::from(cap)) as u32
            }
        };
        let mut counts = SegmentCounts {
            edges: self.edges.iter().map(|&c| need(c)).collect(),
            inner: self.triangles.iter().map(|&c| need(c)).collect(),
        };
        counts.balance(topo);
        counts
    }

    /// The counts that keep the measured chord error at or below `tolerance`: the prediction
    /// of [`ChordErrors::counts`], then, while some triangle's pattern measures over the
    /// tolerance (the chord module's samples, on the surface, without tessellating), its
    /// counts scaled up by `√(error/tolerance)` and rebalanced; only triangles whose counts
    /// changed are measured again. The probe cannot see curvature narrower than its spacing
    /// (the G² blend bands along edges, where the error first falls as `1/n`), which the
    /// measurement does.
    ///
    /// Stops when every triangle meets the tolerance or is at `cap`.
    pub fn refine_to_tolerance(
        &self,
        topo: &Topology,
        surface: &dyn Surface,
        tolerance: f64,
        cap: u32,
    ) -> SegmentCounts {
        let mut counts = self.counts(topo, tolerance, cap);
        let mut measured: Vec<Option<PatternKey>> = vec![None; counts.inner.len()];
        loop {
            let keys: Vec<PatternKey> = (0..counts.inner.len())
                .map(|t| counts.key(topo, t))
                .collect();
            let mut distinct: Vec<PatternKey> = keys
                .iter()
                .zip(&measured)
                .filter(|(k, m)| m.as_ref() != Some(k))
                .map(|(k, _)| *k)
                .collect();
            distinct.sort_unstable();
            distinct.dedup();
            let patterns: Vec<Pattern> = distinct.par_iter().map(|&k| Pattern::new(k)).collect();
            let over: Vec<(usize, f64)> = (0..keys.len())
                .into_par_iter()
                .filter(|&t| measured[t].as_ref() != Some(&keys[t]))
                .filter_map(|t| {
                    let pattern = &patterns[distinct.binary_search(&keys[t]).ok()?];
                    let error = predicted_error(surface, t, pattern);
                    (error > tolerance).then_some((t, error))
                })
                .collect();
            measured.clone_from_slice(&keys.into_iter().map(Some).collect::<Vec<_>>());
            // Each failing triangle scales its interior and edges from this round's counts; an
            // edge between two failing triangles takes the larger, not both in turn.
            let mut raised = false;
            let edges_before = counts.edges.clone();
            for (t, error) in over {
                let factor = (error / tolerance).sqrt() * 1.05;
                let scale = |c: u32| ((f64::from(c) * factor).ceil() as u32).max(c + 1).min(cap);
                let inner = scale(counts.inner[t]);
                raised |= inner > counts.inner[t];
                counts.inner[t] = inner;
                for e in topo.tri_edges[t] {
                    let e = e.0 as usize;
                    let next = scale(edges_before[e]);
                    raised |= next > counts.edges[e];
                    counts.edges[e] = counts.edges[e].max(next);
                }
            }
            if !raised {
                return counts;
            }
            counts.balance(topo);
        }
    }

    /// The largest tolerance (and its counts) whose output has at most `budget` triangles, by
    /// bisection on the tolerance with the counts alone; when even one segment everywhere is
    /// over the budget, those counts.
    pub fn for_budget(&self, topo: &Topology, budget: u64, cap: u32) -> (f64, SegmentCounts) {
        let largest = self
            .triangles
            .iter()
            .chain(&self.edges)
            .fold(0.0f64, |a, &b| a.max(b));
        if largest <= 0.0 {
            return (0.0, self.counts(topo, 1.0, cap));
        }
        // At `hi` every count is 1; at `lo` every count is `cap`.
        let (mut lo, mut hi) = (largest / (4.0 * f64::from(cap * cap)), largest * 1.01);
        let mut best = (hi, self.counts(topo, hi, cap));
        if best.1.triangle_count(topo) > budget {
            return best;
        }
        for _ in 0..48 {
            let mid = (lo * hi).sqrt();
            let counts = self.counts(topo, mid, cap);
            if counts.triangle_count(topo) <= budget {
                best = (mid, counts);
                hi = mid;
            } else {
                lo = mid;
            }
            if hi / lo < 1.0 + 1e-6 {
                break;
            }
        }
        best
    }
}

fn finite(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// Largest second difference of a level-`p` lattice of surface points in any of the three
/// lattice directions, and along each of the triangle's three edges (edge `k` opposite corner
/// `k`).
fn second_differences(points: &[SurfacePoint], p: u32) -> (f64, [f64; 3]) {
    let at = |i: u32, j: u32| points[lattice_index(p, i, j)].position;
    let d2 = |a: (u32, u32), b: (u32, u32), c: (u32, u32)| {
        (at(a.0, a.1) - 2.0 * at(b.0, b.1) + at(c.0, c.1)).length()
    };
    let mut inner = 0.0f64;
    let mut edges = [0.0f64; 3];
    for j in 0..=p {
        for i in 0..=p - j {
            // Along i (j fixed): edge 2 when j = 0.
            if i >= 1 && i < p - j {
                let d = d2((i - 1, j), (i, j), (i + 1, j));
                inner = inner.max(d);
                if j == 0 {
                    edges[2] = edges[2].max(d);
                }
            }
            // Along j (i fixed): edge 1 when i = 0.
            if j >= 1 && i + j < p {
                let d = d2((i, j - 1), (i, j), (i, j + 1));
                inner = inner.max(d);
                if i == 0 {
                    edges[1] = edges[1].max(d);
                }
            }
            // Along i + j fixed: edge 0 when i + j = p.
            if i >= 1 && j >= 1 {
                let d = d2((i + 1, j - 1), (i, j), (i - 1, j + 1));
                inner = inner.max(d);
                if i + j == p {
                    edges[0] = edges[0].max(d);
                }
            }
        }
    }
    (inner, edges)
}

impl SegmentCounts {
    /// Every edge and every interior at `level`: the uniform tessellation.
    pub fn uniform(topo: &Topology, level: u32) -> SegmentCounts {
        SegmentCounts {
            edges: vec![level; topo.edge_count()],
            inner: vec![level; topo.tri_edges.len()],
        }
    }

    /// The pattern key of source triangle `tri`.
    #[inline]
    pub(crate) fn key(&self, topo: &Topology, tri: usize) -> PatternKey {
        PatternKey {
            edges: topo.tri_edges[tri].map(|e| self.edges[e.0 as usize]),
            inner: self.inner[tri],
        }
    }

    /// Output triangles, from the counts alone.
    pub fn triangle_count(&self, topo: &Topology) -> u64 {
        (0..self.inner.len())
            .map(|t| self.key(topo, t).triangle_count())
            .sum()
    }

    /// Largest count anywhere.
    pub fn max(&self) -> u32 {
        self.edges
            .iter()
            .chain(&self.inner)
            .copied()
            .max()
            .unwrap_or(1)
    }

    /// Applies the two balance rules of the module docs until neither raises anything.
    fn balance(&mut self, topo: &Topology) {
        loop {
            let mut changed = false;
            for (inner, edges) in self.inner.iter_mut().zip(&topo.tri_edges) {
                let need = edges
                    .iter()
                    .map(|e| self.edges[e.0 as usize])
                    .max()
                    .unwrap_or(1);
                if *inner < need {
                    *inner = need;
                    changed = true;
                }
            }
            for (&inner, edges) in self.inner.iter().zip(&topo.tri_edges) {
                let need = inner.div_ceil(2);
                for e in edges {
                    let count = &mut self.edges[e.0 as usize];
                    if *count < need {
                        *count = need;
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
    }
}
