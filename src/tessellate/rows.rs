//! Two source triangles cut as one quad in rows, with points of their own inside.
//!
//! `pairs.rs` dissolves an edge only where both triangles beside it have no interior points.
//! On a torus of 125×40 quads at 1e-4 every pattern has some (inner level 4), and each quad
//! takes 29 triangles: the isotropic inner lattice is as fine along the ring, where the
//! surface is nearly flat, as across the tube. Manifold's `refine_to_tolerance` cuts such a quad
//! in rows across the tube (four segments per tube edge, about 5.5 points inside each quad, no
//! point on the diagonal), 22 triangles a quad (`tests/benches/adaptive/manifold.py`).
//!
//! Here the quad of two triangles joined along their shared edge (the polygon of
//! `pairs::joined_polygon`, whose four corners are the two triangles' corners) is cut in rows:
//! two opposite sides with the same count `a` are the rows' ends, row `i` runs from sample `i`
//! of one to sample `i` of the other, and the other two sides are rows `0` and `a` as they are
//! sampled. Every row inside has `m` segments, its points evenly spaced on the chart of the two
//! triangles (`pairs.rs`), or every other row is shifted by half a segment (`m + 1` segments,
//! half ones at its ends) so that the points of consecutive rows alternate, as an equilateral
//! lattice's do: on the torus's outer equator, where both curvatures have one sign, aligned
//! rows cut each cell by a diagonal across both, and fail where shifted ones pass. Consecutive
//! rows are zipped into a strip, at each step the triangle (taking the lower row's next point
//! or the upper's) that keeps the floor on the chart and measures within the tolerance, with
//! the larger smallest angle in space. With aligned rows the quad has `b₀ + b_a + 2(a − 1)·m`
//! triangles, `(a − 1)(m − 1)` inner points.
//!
//! An inner point is a lattice point of level [`ROW_LEVEL`] of the triangle it falls in (the
//! chart point rounded to that lattice, a shift of at most half a step of it): so it is a
//! [`super::VertexSource`] like every output vertex, and attributes, morph targets and skins
//! are carried by the unchanged code. The layout gives each triangle its own inner points as
//! its interior (`layout.rs`), and each triangle writes two triangles more per inner point of
//! its own than its polygon alone would have: numbering, triangle counts and watertightness
//! are those of the counts. The report measures the quad's triangles on the chart, as the
//! choice did (`chord.rs`).
//!
//! # Which quads, and which rows
//!
//! The edges `pairs.rs` could dissolve but left, both orientations of the quad and the three
//! families of rows (aligned, odd or even rows shifted). In each family, more segments are
//! within the tolerance where fewer are, but for the rounding of the points and the zip's
//! choices: the dearest `m` that still saves triangles is tried first, and where it fails the
//! family is passed over; else a bisection finds the fewest segments that pass. Strips and rows
//! are made once for all the layouts that share them, and the strip that failed last is tried
//! first. Quads are taken in a fixed order (most triangles saved first, then edge index), each
//! triangle in at most one: the same cut at any thread count. Quads whose patterns are fine and
//! about as fine every way are not tried ([`worth_trying`]).
//!
//! # What it costs
//!
//! A pass of its own over the surface, several strips per quad tried: see the README's
//! *Quads cut in rows* for the measured instructions.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::chord::{angle_in_space, written};
use super::counts::SegmentCounts;
use super::pairs::{
    dissolvable, group_table, joined_triangle_error, keeps_floor, one_segment_keys, polygon_points,
    with_both, Chart, JoinedChart, JoinedSamples, OnBoth, Pair,
};
use super::transition::PatternKey;
use crate::mesh::TriMesh;
use crate::surface::{lattice_bary, Surface};
use crate::topology::Topology;
use std::ops::Range;

/// The lattice level of the triangle an inner point of a quad is rounded to: the largest
/// level a [`super::VertexSource`] holds with many divisors.
pub const ROW_LEVEL: u32 = 252;

/// An inner point of a quad cut in rows: lattice point `(i, j)` of level [`ROW_LEVEL`] of
/// triangle `side` (0 or 1) of its pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowPoint {
    /// Which triangle of the pair holds it.
    pub side: u8,
    /// Its lattice coordinates, as [`lattice_bary`] reads them.
    pub i: u8,
    /// See `i`.
    pub j: u8,
}

impl RowPoint {
    /// Its barycentrics in triangle `side`.
    pub(crate) fn bary(self) -> [f64; 3] {
        lattice_bary(ROW_LEVEL, u32::from(self.i), u32::from(self.j))
    }

    /// The lattice point of level [`ROW_LEVEL`] nearest to `bary` in triangle `side`.
    fn rounded(side: usize, bary: [f64; 3]) -> RowPoint {
        let n = ROW_LEVEL as f64;
        let i = (bary[1] * n).round().clamp(0.0, n);
        let j = (bary[2] * n).round().clamp(0.0, n - i);
        RowPoint {
            side: side as u8,
            i: i as u8,
            j: j as u8,
        }
    }
}

/// An edge whose quad could be cut in rows.
struct Candidate {
    edge: usize,
    /// Its two triangles and their sides on it.
    tris: [usize; 2],
    sides: [u8; 2],
    /// Their keys with one segment on it and no interior.
    keys: [PatternKey; 2],
    /// The triangles they have now.
    now: u64,
    /// Which orientations of the quad (`rows_fill`) are worth trying ([`worth_trying`]).
    orientations: [bool; 2],
}

impl SegmentCounts {
    /// Cuts in rows (see the module docs) the quads of the edges `pairs.rs` could dissolve but
    /// left, where that saves triangles and measures within `tolerance`, with at most `cap`
    /// segments a row; `groups` and `h` as for [`SegmentCounts::pair_across_edges`].
    #[allow(clippy::too_many_arguments)]
    pub fn rows_across_edges(
        &mut self,
        mesh: &TriMesh,
        topo: &Topology,
        h: &[f64],
        surface: &dyn Surface,
        tolerance: f64,
        cap: u32,
        groups: &[Range<usize>],
    ) {
        let counts = self;
        let group_of = group_table(counts.inner.len(), groups);
        let mut taken = vec![false; counts.inner.len()];
        for pair in &counts.pairs {
            pair.tris.iter().for_each(|&t| taken[t as usize] = true);
        }
        let candidates: Vec<Candidate> = (0..topo.edge_count())
            .into_par_iter()
            .filter_map(|e| {
                let (tris, sides) = dissolvable(counts, mesh, topo, h, &group_of, e)?;
                if tris.iter().any(|&t| taken[t]) {
                    return None;
                }
                let now = tris
                    .iter()
                    .map(|&t| counts.key(topo, t).triangle_count())
                    .sum();
                // The quad's sides counter-clockwise from the end of the first triangle's
                // side of the edge (as `joined_polygon` runs): the first triangle's edges
                // opposite its corners after and before its side's, then the second's.
                let count = |s: usize, c: usize| {
                    counts.edges
                        [topo.tri_edges[tris[s]][(usize::from(sides[s]) + c) % 3].0 as usize]
                        as usize
                };
                let [c0, c1, c2, c3] = [count(0, 1), count(0, 2), count(1, 1), count(1, 2)];
                let worth = |a: usize, other: usize, b: [usize; 2]| {
                    a == other && a >= 2 && worth_trying(now, a, b)
                };
                let orientations = [worth(c0, c2, [c1, c3]), worth(c1, c3, [c0, c2])];
                if orientations == [false, false] {
                    return None;
                }
                let mut keys = one_segment_keys(counts, topo, tris, sides);
                keys.iter_mut().for_each(|k| k.inner = 1);
                Some(Candidate {
                    edge: e,
                    tris,
                    sides,
                    keys,
                    now,
                    orientations,
                })
            })
            .collect();
        let found: Vec<Option<Pair>> = candidates
            .par_iter()
            .map_init(JoinedSamples::default, |scratch, candidate| {
                rows_fill(surface, topo, candidate, tolerance, cap, scratch)
            })
            .collect();
        let saved: Vec<u64> = (0..candidates.len())
            .map(|c| {
                found[c]
                    .as_ref()
                    .map_or(0, |pair| candidates[c].now - pair.triangles.len() as u64)
            })
            .collect();
        // Most triangles saved first, then by candidate; each triangle in one cut at most.
        let mut order: Vec<usize> = (0..candidates.len())
            .filter(|&c| found[c].is_some())
            .collect();
        order.sort_by_key(|&c| (std::cmp::Reverse(saved[c]), c));
        counts.take_pairs(
            &order,
            |c| (candidates[c].edge, candidates[c].tris),
            &found,
            &mut taken,
            true,
        );
    }
}

/// A strip of a quad: the row below, its kind, and the kind of the row above.
type StripKey = (usize, RowKind, RowKind);

/// The quads with at most this many triangles as they are are all tried.
const COARSE_QUAD: u64 = 64;

/// Whether a quad of `now` triangles as they are is worth trying in rows whose ends have `a`
/// segments and whose first and last rows have `b` segments: where the fewest rows possible
/// (one segment each) would save at least [`LEAST_SAVING`] triangles, and where the quad is
/// coarse ([`COARSE_QUAD`]) or the sides across the rows have at most two thirds of the
/// segments of the rows' ends, as across a torus's tube. Elsewhere rows save little for their
/// cost: on the 10k icosphere at 3e-4 (quads of 7 or 8 triangles) they found nothing for 1.6
/// times the run's instructions; at 1e-5 (fine patterns, the curvature the same every way),
/// 2% of the triangles for 1.7 times its time, at the error level 16 reaches 1.2% for 5
/// times.
fn worth_trying(now: u64, a: usize, b: [usize; 2]) -> bool {
    let fewest = (b[0] + b[1] + 2 * (a - 1)) as u64;
    now >= fewest + LEAST_SAVING && (now <= COARSE_QUAD || 3 * b[0].min(b[1]) <= 2 * a)
}

/// See [`worth_trying`].
const LEAST_SAVING: u64 = 4;

/// The quad's points: the joined polygon's first, then the inner points of every row made so
/// far; each on the chart and as written.
#[derive(Debug, Default)]
struct QuadPoints {
    chart: Vec<DVec2>,
    position: Vec<DVec3>,
    inner: Vec<RowPoint>,
}

/// How a row of the quad is sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RowKind {
    /// The first or last row: a side of the quad, sampled as its edge is.
    Side,
    /// An inner row of `m` segments, or, `shifted`, shifted by half a segment (`m + 1`
    /// segments, half ones at its ends).
    Inner { m: u32, shifted: bool },
}

/// Where the inner points of a row of `m` segments lie along it, as fractions of its length;
/// `shifted`, the row shifted by half a segment (`m + 1` segments, half ones at its ends).
fn stations(m: u32, shifted: bool) -> impl Iterator<Item = f64> {
    let count = if shifted { m } else { m - 1 };
    (1..=count).map(move |j| {
        let j = f64::from(j);
        if shifted {
            (j - 0.5) / f64::from(m)
        } else {
            j / f64::from(m)
        }
    })
}

/// One orientation of a quad being cut in rows: its rows' ends and sides, and the rows and
/// strips made so far, each made once for all the layouts that share it.
struct Quad<'a> {
    chart: &'a Chart,
    /// Points of the joined polygon.
    n: usize,
    /// The rows' ends (from row 0 to row `a`), the first row and the last (from the first
    /// end to the second), as point numbers.
    ends: [Vec<usize>; 2],
    first: Vec<usize>,
    last: Vec<usize>,
    points: QuadPoints,
    /// Rows made: `(row, kind)` and its point numbers.
    rows: Vec<((usize, RowKind), Vec<usize>)>,
    /// Strips zipped: `(row below, its kind, the kind of the row above)` and the triangles,
    /// `None` where it could not be within the tolerance.
    strips: Vec<(StripKey, Option<Vec<[usize; 3]>>)>,
    tolerance: f64,
}

impl Quad<'_> {
    /// The rows' count `a`.
    fn a(&self) -> usize {
        self.ends[0].len() - 1
    }

    /// Row `i` of `kind` as point numbers, made (its inner points rounded to [`ROW_LEVEL`]
    /// and evaluated as written, each triangle's in one call) the first time.
    fn row(
        &mut self,
        both: &mut OnBoth<'_>,
        scratch: &mut JoinedSamples,
        i: usize,
        kind: RowKind,
    ) -> usize {
        if let Some(at) = self.rows.iter().position(|(k, _)| *k == (i, kind)) {
            return at;
        }
        let row = match kind {
            RowKind::Side if i == 0 => self.first.clone(),
            RowKind::Side => self.last.clone(),
            RowKind::Inner { m, shifted } => {
                let (from, to) = (
                    self.points.chart[self.ends[0][i]],
                    self.points.chart[self.ends[1][i]],
                );
                let mut row = vec![self.ends[0][i]];
                for fraction in stations(m, shifted) {
                    let (s, bary) = self.chart.locate(from.lerp(to, fraction));
                    let point = RowPoint::rounded(s, bary);
                    row.push(self.points.chart.len());
                    self.points.inner.push(point);
                    self.points.chart.push(self.chart.place(s, point.bary()));
                    self.points.position.push(DVec3::NAN);
                }
                row.push(self.ends[1][i]);
                for s in 0..2 {
                    let own: Vec<usize> = row[1..row.len() - 1]
                        .iter()
                        .copied()
                        .filter(|&q| usize::from(self.points.inner[q - self.n].side) == s)
                        .collect();
                    if own.is_empty() {
                        continue;
                    }
                    let barys: Vec<[f64; 3]> = own
                        .iter()
                        .map(|&q| self.points.inner[q - self.n].bary())
                        .collect();
                    let evaluated = scratch.evaluate(both, s, &barys);
                    for (&q, at) in own.iter().zip(evaluated) {
                        self.points.position[q] = written(at.position);
                    }
                }
                row
            }
        };
        self.rows.push(((i, kind), row));
        self.rows.len() - 1
    }

    /// The strip between row `i` of kind `below` and row `i + 1` of kind `above`, zipped
    /// within the tolerance (the module docs say how), made the first time; `None` if it
    /// cannot be.
    fn strip(
        &mut self,
        both: &mut OnBoth<'_>,
        scratch: &mut JoinedSamples,
        i: usize,
        below: RowKind,
        above: RowKind,
    ) -> Option<&[[usize; 3]]> {
        let key = (i, below, above);
        let at = match self.strips.iter().position(|(k, _)| *k == key) {
            Some(at) => at,
            None => {
                let lower = self.row(both, scratch, i, below);
                let upper = self.row(both, scratch, i + 1, above);
                let zipped = self.zip(both, scratch, lower, upper);
                self.strips.push((key, zipped));
                self.strips.len() - 1
            }
        };
        self.strips[at].1.as_deref()
    }

    /// Zips rows `lower` and `upper` (indices into the rows made): at each step the
    /// triangle taking the lower row's next point or the upper's, of those that keep the
    /// floor on the chart the one with the larger smallest angle in space that measures
    /// within the tolerance.
    fn zip(
        &self,
        both: &mut OnBoth<'_>,
        scratch: &mut JoinedSamples,
        lower: usize,
        upper: usize,
    ) -> Option<Vec<[usize; 3]>> {
        let (lower, upper) = (&self.rows[lower].1, &self.rows[upper].1);
        let points = &self.points;
        if lower
            .iter()
            .chain(upper)
            .any(|&q| !points.position[q].is_finite())
        {
            return None;
        }
        let mut triangles = Vec::with_capacity(lower.len() + upper.len());
        let (mut p, mut q) = (0, 0);
        while p + 1 < lower.len() || q + 1 < upper.len() {
            let mut options: Vec<([usize; 3], bool, f64)> = Vec::with_capacity(2);
            let steps = [
                (p + 1 < lower.len()).then(|| ([lower[p], upper[q], lower[p + 1]], true)),
                (q + 1 < upper.len()).then(|| ([lower[p], upper[q], upper[q + 1]], false)),
            ];
            for (t, along_lower) in steps.into_iter().flatten() {
                if keeps_floor(t.map(|v| points.chart[v])) {
                    let angle = angle_in_space(t.map(|v| points.position[v]));
                    options.push((t, along_lower, angle));
                }
            }
            if options.len() == 2 && options[1].2 > options[0].2 {
                options.swap(0, 1);
            }
            let (t, along_lower, _) = options.into_iter().find(|&(t, _, _)| {
                let on_chart = t.map(|v| points.chart[v]);
                let flat = t.map(|v| points.position[v]);
                joined_triangle_error(both, self.chart, on_chart, flat, scratch) <= self.tolerance
            })?;
            triangles.push(t);
            if along_lower {
                p += 1;
            } else {
                q += 1;
            }
        }
        Some(triangles)
    }

    /// The kind of row `i` in a layout of inner rows of `m` segments, those of parity
    /// `shifted` (if any) shifted.
    fn kind(&self, i: usize, m: u32, shifted: Option<usize>) -> RowKind {
        if i == 0 || i == self.a() {
            RowKind::Side
        } else {
            RowKind::Inner {
                m,
                shifted: shifted == Some(i % 2),
            }
        }
    }

    /// The triangles of the layout of inner rows of `m` segments, those of parity `shifted`
    /// shifted, if every strip is within the tolerance. The strip that failed the last
    /// layout (`hard`) is tried first: where one fails the next layouts mostly fail there
    /// too, and a layout is then rejected after one strip.
    fn layout(
        &mut self,
        both: &mut OnBoth<'_>,
        scratch: &mut JoinedSamples,
        m: u32,
        shifted: Option<usize>,
        hard: &mut usize,
    ) -> Option<Vec<[usize; 3]>> {
        let a = self.a();
        let order = std::iter::once(*hard).chain((0..a).filter(|&i| i != *hard));
        for i in order {
            let (below, above) = (self.kind(i, m, shifted), self.kind(i + 1, m, shifted));
            if self.strip(both, scratch, i, below, above).is_none() {
                *hard = i;
                return None;
            }
        }
        let mut triangles = Vec::new();
        for i in 0..a {
            let (below, above) = (self.kind(i, m, shifted), self.kind(i + 1, m, shifted));
            triangles.extend_from_slice(self.strip(both, scratch, i, below, above)?);
        }
        Some(triangles)
    }
}

/// The quad of `candidate` cut in rows within `tolerance`, at most `cap` segments a row, with
/// fewer triangles than it has now, the fewest of the orientations worth trying (the first on
/// a tie); `None` if there is none.
fn rows_fill(
    surface: &dyn Surface,
    topo: &Topology,
    candidate: &Candidate,
    tolerance: f64,
    cap: u32,
    scratch: &mut JoinedSamples,
) -> Option<Pair> {
    let &Candidate {
        tris,
        sides,
        keys,
        now,
        orientations,
        ..
    } = candidate;
    let JoinedChart {
        patterns,
        points: joined,
        chart,
        on_chart,
    } = JoinedChart::new(topo, tris, sides, keys);
    let n = joined.len();
    let corners: Vec<usize> = (0..n).filter(|&i| joined[i].1 < 3).collect();
    if corners.len() != 4 || corners[0] != 0 {
        return None;
    }
    with_both(surface, tris, |both| {
        let mut polygon = QuadPoints {
            chart: on_chart,
            position: vec![DVec3::NAN; n],
            inner: Vec::new(),
        };
        polygon_points(
            both,
            scratch,
            &joined,
            &patterns,
            &vec![true; n],
            &mut polygon.position,
        );
        if polygon.position.iter().any(|p| !p.is_finite()) {
            return None;
        }
        // The four sides, each from its corner to the next, counter-clockwise.
        let side = |r: usize| -> Vec<usize> {
            let (from, to) = (corners[r], if r == 3 { n } else { corners[r + 1] });
            (from..=to).map(|i| i % n).collect()
        };
        let reversed = |mut v: Vec<usize>| {
            v.reverse();
            v
        };
        let mut best: Option<(Vec<[usize; 3]>, QuadPoints)> = None;
        for orientation in (0..2).filter(|&o| orientations[o]) {
            // The rows' ends (from row 0 to row a) and the first and last rows (from the
            // first end to the second).
            let (ends, first, last) = if orientation == 0 {
                ([side(0), reversed(side(2))], reversed(side(3)), side(1))
            } else {
                ([side(1), reversed(side(3))], reversed(side(0)), side(2))
            };
            let a = ends[0].len() - 1;
            debug_assert!(ends[1].len() - 1 == a && a >= 2, "rows' ends of one count");
            let fixed = (first.len() - 1 + last.len() - 1) as u64;
            let mut limit = best.as_ref().map_or(now, |b| b.0.len() as u64);
            let mut quad = Quad {
                chart: &chart,
                n,
                ends,
                first,
                last,
                points: QuadPoints {
                    chart: polygon.chart.clone(),
                    position: polygon.position.clone(),
                    inner: Vec::new(),
                },
                rows: Vec::new(),
                strips: Vec::new(),
                tolerance,
            };
            // Three families of layouts: every inner row with `m` segments, or every other
            // one shifted by half a segment, odd rows or even, so that the points of
            // consecutive rows alternate. In each, more segments are within the tolerance
            // where fewer are (but for the rounding of the points and the zip's choices):
            // the dearest `m` that still saves triangles is tried first, and where it fails
            // (on an evenly curved mesh, most quads) the family is passed over after one
            // strip; else a bisection finds the fewest segments that pass.
            let mut hard = 0;
            let mut found: Option<Vec<[usize; 3]>> = None;
            for shifted in [None, Some(1), Some(0)] {
                let shifts = shifted.map_or(0, |parity| {
                    (1..a).filter(|i| i % 2 == parity).count() as u64
                });
                let triangles = |m: u32| fixed + 2 * ((a as u64 - 1) * u64::from(m) + shifts);
                let Some(dearest) = (1..=cap).take_while(|&m| triangles(m) < limit).last() else {
                    continue;
                };
                let Some(mut passed) = quad.layout(both, scratch, dearest, shifted, &mut hard)
                else {
                    continue;
                };
                let (mut lo, mut hi) = (1, dearest);
                while lo < hi {
                    let mid = (lo + hi) / 2;
                    match quad.layout(both, scratch, mid, shifted, &mut hard) {
                        Some(triangles) => {
                            passed = triangles;
                            hi = mid;
                        }
                        None => lo = mid + 1,
                    }
                }
                limit = passed.len() as u64;
                found = Some(passed);
            }
            let Some(found) = found else {
                continue;
            };
            best = Some((found, quad.points));
        }
        let (triangles, points) = best?;
        // The inner points used, renumbered past the polygon's with the first triangle's
        // first, as the layout takes them.
        let mut used: Vec<usize> = triangles
            .iter()
            .flatten()
            .copied()
            .filter(|&q| q >= n)
            .collect();
        used.sort_unstable();
        used.dedup();
        used.sort_by_key(|&q| points.inner[q - n].side);
        if n + used.len() > usize::from(u8::MAX) + 1 {
            return None;
        }
        let mut renumber = vec![0usize; points.inner.len()];
        for (new, &q) in used.iter().enumerate() {
            renumber[q - n] = n + new;
        }
        let index = |q: usize| (if q < n { q } else { renumber[q - n] }) as u8;
        Some(Pair {
            tris: tris.map(|t| t as u32),
            sides,
            triangles: triangles.iter().map(|t| t.map(index)).collect(),
            interior: used.iter().map(|&q| points.inner[q - n]).collect(),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_sampled_evenly_or_shifted_by_half_a_segment() {
        let close = |a: Vec<f64>, b: &[f64]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-15)
        };
        assert!(close(stations(3, false).collect(), &[1.0 / 3.0, 2.0 / 3.0]));
        assert!(close(
            stations(3, true).collect(),
            &[1.0 / 6.0, 0.5, 5.0 / 6.0]
        ));
        assert_eq!(stations(1, false).count(), 0);
        assert!(close(stations(1, true).collect(), &[0.5]));
    }

    #[test]
    fn a_point_is_rounded_to_the_nearest_lattice_point_of_its_triangle() {
        let step = 1.0 / f64::from(ROW_LEVEL);
        for k in 0..2000 {
            // Points spread over the triangle, corners and edges included.
            let (u, v) = ((k % 53) as f64 / 52.0, (k / 53) as f64 / 37.0);
            let bary = [(1.0 - u) * (1.0 - v), u * (1.0 - v), v];
            let p = RowPoint::rounded(1, bary);
            assert_eq!(p.side, 1);
            assert!(u32::from(p.i) + u32::from(p.j) <= ROW_LEVEL, "{bary:?}");
            let b = p.bary();
            assert!(
                (b[1] - bary[1]).abs() <= step / 2.0 + 1e-12,
                "{bary:?} {b:?}"
            );
            assert!(
                (b[2] - bary[2]).abs() <= step / 2.0 + 1e-12,
                "{bary:?} {b:?}"
            );
            // A lattice point is its own rounding.
            assert_eq!(RowPoint::rounded(1, b), p);
        }
    }

    #[test]
    fn only_quads_rows_could_save_on_are_tried() {
        // A torus quad at 1e-4: 29 triangles, four segments across the tube, two along it.
        assert!(worth_trying(29, 4, [2, 2]));
        // A quad of 7 triangles that the fewest rows (6) would save one on.
        assert!(!worth_trying(7, 2, [2, 2]));
        // Fine and about as fine every way: an icosphere's quad at 1e-5.
        assert!(!worth_trying(118, 8, [8, 7]));
        // Fine but far coarser along the rows than across them.
        assert!(worth_trying(120, 8, [4, 5]));
    }
}
