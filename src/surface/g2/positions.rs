//! Surface points whose normal nobody reads, computed as positions alone: the chord error
//! checks read a lattice's boundary points and the vertices of the triangles they measure only
//! as positions (`tessellate/estimate.rs` takes second differences along the normal of the
//! centre point, `tessellate/chord.rs` measures along the normal of the sample point).
//!
//! A position is quantity 0 of the sums of [`G2Surface::combine`] (Eq. 5 with the weights of
//! the pattern module), summed here alone, over the same control points in the same order, so
//! it has the bits `combine` gives; the two tangent sums and the normal, two thirds of the
//! multiplications and the square root, are left out. On an edge part the position weighs
//! only the edge's boundary curve ([`EdgeRows::EdgeValues`]: four control points of each net
//! instead of ten), which `combine` already uses for one lane and which leaves its bits as
//! they are for two (the left-out terms are `±0`, see `combine`).

use glam::DVec3;

use super::{
    corner, G2Surface, LaneNet, PartEvaluation, PointEvaluation, PointSink, Split, ALL_ROWS,
};
use crate::surface::pattern::{
    EdgeRows, Lanes, NetWeights, PointWeights, EDGE_ROWS, EDGE_VALUE_ROWS,
};
use crate::surface::{lattice_index, lattice_len, LatticePart, SurfacePoint};

/// The positions of the `L` points of `w` for a pattern whose sums need `edge_rows`: [`values`]
/// over the control points a position sums, in slot order. Each case passes its rows as an
/// array of fixed length, so the sums unroll as [`G2Surface::combine`]'s do (through a slice
/// of rows the compiler kept a loop over them: about 49 instructions a row for two points, five
/// times the unrolled sums, and as much as a whole point for the chord measurement's vertices).
#[inline(always)]
fn values_for<const L: usize, N: LaneNet<L>>(
    w: &Lanes<L>,
    own: &N,
    across: Option<&N>,
    edge_rows: EdgeRows,
) -> [DVec3; L] {
    match edge_rows {
        EdgeRows::All => values(w, own, across, &ALL_ROWS),
        EdgeRows::Edge(k) => values(w, own, across, &EDGE_ROWS[k as usize]),
        EdgeRows::EdgeValues(k) => values(w, own, across, &EDGE_VALUE_ROWS[k as usize]),
    }
}

/// Adds the position sums of one net over `rows` to `acc[coordinate][lane]`, term by term as
/// `accumulate` adds quantity 0.
#[inline(always)]
#[allow(clippy::needless_range_loop)] // As in `accumulate`: the form that unrolls into SIMD.
fn add_values<const L: usize, const R: usize, N: LaneNet<L>>(
    w: &NetWeights<L>,
    net: &N,
    acc: &mut [[f64; L]; 3],
    rows: &[usize; R],
) {
    for &m in rows {
        for c in 0..3 {
            let x = net.lanes(m, c);
            for l in 0..L {
                acc[c][l] += w[0][m][l] * x[l];
            }
        }
    }
}

/// The positions of the `L` points of `w`, on `own` and, when they blend, `across`: the
/// position [`G2Surface::combine`] gives, bit for bit, for the rows `rows` of
/// [`values_for`].
#[inline(always)]
fn values<const L: usize, const R: usize, N: LaneNet<L>>(
    w: &Lanes<L>,
    own: &N,
    across: Option<&N>,
    rows: &[usize; R],
) -> [DVec3; L] {
    let mut acc = [[0.0; L]; 3];
    add_values(&w.own, own, &mut acc, rows);
    if let Some(across) = across {
        add_values(&w.across, across, &mut acc, rows);
    }
    std::array::from_fn(|l| DVec3::new(acc[0][l], acc[1][l], acc[2][l]))
}

/// The positions of a part's `len` points, written into `out` at `slot(target)` (their
/// normals left as they are).
pub(super) struct Positions<'o, F> {
    pub out: &'o mut [SurfacePoint],
    pub len: usize,
    pub slot: F,
}

/// The lattice index of edge `k`'s point `target` of the level-`n` lattice (step
/// `target + 1`, see [`LatticePart::Edge`]).
#[inline]
fn edge_slot(n: u32, k: u8, target: u32) -> usize {
    let m = target + 1;
    let (i, j) = match k {
        0 => (n - m, m),
        1 => (0, n - m),
        _ => (m, 0),
    };
    lattice_index(n, i, j)
}

impl<F: Fn(u32) -> usize> PointSink for Positions<'_, F> {
    fn len(&self) -> usize {
        self.len
    }

    #[inline(always)]
    fn put(&mut self, target: u32, point: SurfacePoint) {
        self.out[(self.slot)(target)].position = point.position;
    }

    #[inline(always)]
    fn block<const L: usize, N: LaneNet<L>>(
        &mut self,
        _normal: &[DVec3; 3],
        lanes: &Lanes<L>,
        own: &N,
        across: Option<&N>,
        _split: Option<&Split>,
        edge_rows: EdgeRows,
    ) {
        let positions = values_for(lanes, own, across, edge_rows);
        for (&target, p) in lanes.target.iter().zip(positions) {
            if target != Lanes::<1>::PADDING {
                self.out[(self.slot)(target)].position = p;
            }
        }
    }
}

impl PartEvaluation<'_, '_> {
    /// The whole level-`level` lattice in lattice order, appended to `out`: the interior points
    /// and the corners as [`crate::surface::Surface::evaluate_lattice`] gives them, the edge
    /// points' positions as it gives them and their normals zero.
    pub(super) fn lattice_with_edge_positions(&mut self, level: u32, out: &mut Vec<SurfacePoint>) {
        let zero = SurfacePoint {
            position: DVec3::ZERO,
            normal: DVec3::ZERO,
        };
        let base = out.len();
        let interior = LatticePart::Interior.len(level);
        let len = lattice_len(level);
        out.resize(base + len + interior, zero);
        let (lattice, inside) = out[base..].split_at_mut(len);
        // The interior evaluated whole after the lattice, then moved into its rows.
        self.part_into(level, LatticePart::Interior, &mut super::Points(inside));
        let mut next = inside.iter();
        for j in 1..level {
            let start = lattice_index(level, 1, j);
            for (slot, p) in lattice[start..start + (level - 1 - j) as usize]
                .iter_mut()
                .zip(&mut next)
            {
                *slot = *p;
            }
        }
        for (c, (i, j)) in [(0, 0), (level, 0), (0, level)].into_iter().enumerate() {
            lattice[lattice_index(level, i, j)] = SurfacePoint {
                position: corner(&self.local.net, c),
                normal: self.local.normal[c],
            };
        }
        for k in (0..3).filter(|_| level >= 2) {
            self.part_into(
                level,
                LatticePart::Edge(k),
                &mut Positions {
                    out: &mut *lattice,
                    len: LatticePart::Edge(k).len(level),
                    slot: |target| edge_slot(level, k, target),
                },
            );
        }
        out.truncate(base + len);
    }
}

impl PointEvaluation {
    /// The position [`PointEvaluation::at`] gives at `bary`, bit for bit, without its normal.
    pub(super) fn position_at(&mut self, surface: &G2Surface, bary: [f64; 3]) -> DVec3 {
        let w = PointWeights::at(bary, self.widths, surface.profile);
        if let Some(c) = w.corner {
            return corner(&self.local.net, c as usize);
        }
        let (local, across) = self.nets(surface, &w);
        let net = across.map(|(net, _)| net);
        let [p] = values(&Lanes::<1>::single(&w), &local.net, net, &ALL_ROWS);
        p
    }
}
