//! The part of uniform tessellation that depends on the level only: what each lattice point is
//! (corner, edge sample, interior), the order the `n²` sub-triangles are emitted in, and the
//! order interior points are numbered in. Built once per level and shared by every triangle.
//!
//! It deliberately knows no mesh and no surface: only lattice indices.

use super::lattice_edges::SampleKind;
use crate::surface::{lattice_index, lattice_len};

/// Rows of sub-triangles per band of the emission order. A band is walked column by column, so
/// the vertices in flight are two columns of `BAND + 1` points: 16, which is exactly the FIFO
/// size meshoptimizer's analyzers model and that GPUs of the last decade keep at least. Seven
/// rows measured best of 2 to 8 (ACMR 0.64 per lattice at level 16, 0.61 at level 32, against
/// 0.99 and 1.03 for plain row order; see `optimize.rs` for the whole-mesh figures).
pub(crate) const BAND: u32 = 7;

/// Everything about a level-`n` lattice that every triangle shares.
#[derive(Debug, Clone)]
pub(crate) struct LatticePlan {
    /// Segments per edge.
    pub n: u32,
    /// Number of lattice points, `(n + 1)(n + 2)/2`.
    pub len: usize,
    /// Lattice coordinates `(i, j)` of each lattice point, as stored in
    /// [`super::VertexSource`].
    pub lattice_ij: Vec<[u8; 2]>,
    /// Lattice index of each corner.
    pub corners: [u32; 3],
    /// `edges[k][m − 1]`: lattice index of step `m` along the edge opposite corner `k`, walked
    /// from corner `k + 1` (the order of [`LatticePart::Edge`](crate::surface::LatticePart)).
    pub edges: [Vec<u32>; 3],
    /// Interior points in order of first use by [`LatticePlan::triangles`] (the vertex fetch
    /// order, which is the order they are numbered in): their lattice index and their index in
    /// [`LatticePart::Interior`](crate::surface::LatticePart) order.
    pub interior_by_rank: Vec<(u32, u32)>,
    /// The `n²` sub-triangles as lattice indices, wound like the source triangle, in emission
    /// order.
    pub triangles: Vec<[u32; 3]>,
    /// Number of interior points, `(n − 1)(n − 2)/2`.
    pub interior: usize,
}

impl LatticePlan {
    /// Where local point `li` of source triangle `tri` comes from, on this plan's lattice.
    #[inline]
    pub fn source(&self, tri: usize, li: usize) -> super::VertexSource {
        let [i, j] = self.lattice_ij[li];
        super::VertexSource {
            tri: tri as u32,
            level: self.n as u8,
            i,
            j,
        }
    }

    /// The plan for level `n ≥ 1`.
    pub fn new(n: u32) -> LatticePlan {
        let len = lattice_len(n);
        let mut kinds = Vec::with_capacity(len);
        let mut lattice_ij = Vec::with_capacity(len);
        for j in 0..=n {
            for i in 0..=n - j {
                kinds.push(SampleKind::of(n, i, j));
                lattice_ij.push([i as u8, j as u8]);
            }
        }
        let triangles = banded_triangles(n);
        let mut corners = [0; 3];
        let mut edges = [0, 1, 2].map(|_| vec![0; n.saturating_sub(1) as usize]);
        for (li, kind) in kinds.iter().enumerate() {
            match *kind {
                SampleKind::Corner(c) => corners[c] = li as u32,
                SampleKind::Edge { k, m } => edges[k][(m - 1) as usize] = li as u32,
                SampleKind::Interior { .. } => {}
            }
        }
        let mut ranked = vec![false; len];
        let mut interior_by_rank = Vec::new();
        for &li in triangles.iter().flatten() {
            if let SampleKind::Interior { index } = kinds[li as usize] {
                if !ranked[li as usize] {
                    ranked[li as usize] = true;
                    interior_by_rank.push((li, index as u32));
                }
            }
        }
        LatticePlan {
            n,
            len,
            lattice_ij,
            corners,
            edges,
            interior: interior_by_rank.len(),
            interior_by_rank,
            triangles,
        }
    }
}

/// The sub-triangles of a level-`n` lattice in bands of [`BAND`] rows; each band is walked
/// column by column (fixed `i`, rows upward), alternately forward and backward, so that the
/// next band starts where the last one ended and its first column is still cached.
///
/// Up triangle `(i, j)`: points `(i, j), (i+1, j), (i, j+1)`; down triangle `(i, j)`:
/// `(i+1, j), (i+1, j+1), (i, j+1)`, both wound like the source triangle.
fn banded_triangles(n: u32) -> Vec<[u32; 3]> {
    let at = |i: u32, j: u32| lattice_index(n, i, j) as u32;
    let mut out = Vec::with_capacity((n * n) as usize);
    for (band, j0) in (0..n).step_by(BAND as usize).enumerate() {
        let j1 = (j0 + BAND).min(n);
        let columns = 0..n - j0;
        let columns: Vec<u32> = if band % 2 == 0 {
            columns.collect()
        } else {
            columns.rev().collect()
        };
        for i in columns {
            for j in j0..j1 {
                if i + j >= n {
                    break;
                }
                out.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
                if i + j + 1 < n {
                    out.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sub_triangle_is_emitted_once() {
        for n in 1..=20 {
            let plan = LatticePlan::new(n);
            assert_eq!(plan.triangles.len(), (n * n) as usize);
            let mut sorted: Vec<[u32; 3]> = plan
                .triangles
                .iter()
                .map(|t| {
                    let mut t = *t;
                    t.sort();
                    t
                })
                .collect();
            sorted.sort();
            sorted.dedup();
            assert_eq!(sorted.len(), (n * n) as usize, "level {n}");
            let interior = if n >= 3 { (n - 1) * (n - 2) / 2 } else { 0 };
            assert_eq!(plan.interior, interior as usize);
        }
    }
}
