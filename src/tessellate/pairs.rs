//! Two source triangles cut as one polygon across the edge between them.
//!
//! Every pattern keeps its source triangle's edges: an output triangle never crosses one. Where
//! a mesh is made of quads split by a diagonal, that diagonal is a patch edge like any other
//! and gets its own samples, although the surface is as smooth across it as anywhere. On a
//! torus of 125×40 quads at 1e-3 the diagonals, which run across both curvatures at once, need
//! two segments each (1.5e-3 for one chord at the outer equator) while the ring edges need one:
//! each triangle then has 5 points (3 triangles) where a cut of the quad along its rings needs 4
//! triangles for two. Manifold's `refine_to_tolerance` gives that cut (its output has no point on
//! a diagonal and no input diagonal left; `tests/benches/adaptive/manifold.py`).
//!
//! Here an interior edge whose two triangles have no interior points is given one segment where
//! the polygon of both triangles' edge samples (the two polygons of `transition.rs` joined
//! along it) has a triangulation within the tolerance: the edge is dissolved into the polygon,
//! and each triangle writes its share of that triangulation (as many triangles as its own
//! polygon would have: `k₁ − 2` and `k₂ − 2` of the `k₁ + k₂ − 4`), so the numbering of vertices
//! and triangles (`layout.rs`) is that of the counts. Only the two triangles' own points are
//! used: the edge samples of the other edges, written once for both sides as everywhere else,
//! so the output stays watertight by construction.
//!
//! # Measuring a triangle across the edge
//!
//! A triangle of the joined polygon has corners in both source triangles, so its samples
//! (`chord.rs`'s seven weights) are placed on a chart of the two: each source triangle laid flat
//! with its edge lengths in space, the second unfolded across the shared edge. A sample's chart
//! point falls in one of the two, and the surface is evaluated there, at the barycentrics of that
//! point. The chart is affine on each triangle and continuous across the edge, and close to
//! isometric, so a sample lands on the surface point under it to first order; the distance is
//! taken along the surface's normal as everywhere (`chord.rs`'s module docs say why).
//!
//! # Which edges, and which triangulation
//!
//! An edge is dissolved only where nothing changes across it but the patch: an interior edge,
//! not a crease (`h > 0`), its two triangles of one output group, using the same input vertices
//! at both ends (no UV seam or split normal there) and wound the same way. The triangulation is
//! found as `fill.rs` finds a fill: over the polygon's sub-polygons, triangles positively wound
//! and keeping the angle floor on the chart, all within the tolerance, with the largest smallest
//! angle in space. Edges are tried in parallel, each reading only its own two triangles, and
//! taken in a fixed order (most triangles saved first, then edge index) where neither triangle
//! is taken yet: the same pairs at any thread count.
//!
//! # What it costs
//!
//! Only where patterns have no interior points, at coarse tolerances, is any edge tried. There
//! it is a pass of its own over the surface: on the 10k torus at 1e-3 the run goes from 1.03e9
//! to 1.72e9 instructions for 23% fewer triangles, on the 10k icosphere at 3e-4 from 1.42e9 to
//! 1.90e9 for 1.2% fewer (13,080 edges tried, 420 joined: most are passed over after the
//! test at the edge's middle, see `joined_fill`).

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::chord::{angle_in_space, normal_distance, written, WEIGHTS};
use super::counts::SegmentCounts;
use super::is_crease;
use super::kept_patterns::{self, Kept};
use super::rows::RowPoint;
#[cfg(test)]
use super::transition::min_angle;
use super::transition::{polygon, Pattern, PatternKey, ANGLE_FLOOR};
use crate::mesh::TriMesh;
use crate::surface::{Surface, SurfacePoint};
use crate::topology::{EdgeId, EdgeKind, Topology};
use std::ops::Range;

/// The joined polygon of two triangles laid on their chart.
pub(super) struct JoinedChart {
    /// The two triangles' patterns, each with one segment on the shared edge.
    pub patterns: [Kept<Pattern>; 2],
    /// The polygon's points ([`joined_polygon`]).
    pub points: Vec<JoinedPoint>,
    /// The chart of the two triangles.
    pub chart: Chart,
    /// Where each point lies on it.
    pub on_chart: Vec<DVec2>,
}

impl JoinedChart {
    /// The joined polygon of triangles `tris` cut by `keys` (one segment on their shared
    /// sides `sides`), on the chart of the two.
    pub(super) fn new(
        topo: &Topology,
        tris: [usize; 2],
        sides: [u8; 2],
        keys: [PatternKey; 2],
    ) -> JoinedChart {
        let patterns = keys.map(kept_patterns::pattern);
        let points = joined_polygon(sides, [&patterns[0], &patterns[1]]);
        let chart = Chart::new(topo, tris, sides);
        let on_chart = points
            .iter()
            .map(|&(s, p)| chart.place(s, patterns[s].bary(p)))
            .collect();
        JoinedChart {
            patterns,
            points,
            chart,
            on_chart,
        }
    }
}

/// Two source triangles whose shared edge is dissolved into one polygon.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pair {
    /// The two source triangles, the lower-numbered first.
    pub tris: [u32; 2],
    /// Each one's local edge (opposite that corner) on the dissolved edge.
    pub sides: [u8; 2],
    /// The triangulation of the joined polygon (the two triangles' polygons joined along the
    /// edge, counter-clockwise from the end of the first's side of it), as positions in it,
    /// and past its `n` points, `n + r` for interior point `r`: the first triangle writes the
    /// first `k₁ − 2 + 2·i₁` (`i₁` of the interior points are its own), the second the rest.
    pub triangles: Vec<[u8; 3]>,
    /// Points inside the joined polygon (`rows.rs`), the first triangle's first; none where
    /// the polygon is cut by its own points alone.
    pub interior: Vec<RowPoint>,
}

impl Pair {
    /// How many of the interior points are triangle `side`'s (0 or 1) own.
    pub(crate) fn interior_of(&self, side: usize) -> usize {
        self.interior
            .iter()
            .filter(|p| usize::from(p.side) == side)
            .count()
    }

    /// How many of [`Pair::triangles`] triangle `side` writes, when its pattern alone (the
    /// polygon of its edge samples) would have `own` triangles: two more per interior point.
    pub(crate) fn share_len(&self, side: usize, own: usize) -> usize {
        own + 2 * self.interior_of(side)
    }

    /// Where point `q` of [`Pair::triangles`] lies: which triangle and its barycentrics there,
    /// `joined` being the joined polygon of `patterns`.
    pub(crate) fn point_bary(
        &self,
        joined: &[JoinedPoint],
        patterns: [&Pattern; 2],
        q: u8,
    ) -> (usize, [f64; 3]) {
        let q = usize::from(q);
        match joined.get(q) {
            Some(&(s, p)) => (s, patterns[s].bary(p)),
            None => {
                let r = self.interior[q - joined.len()];
                (usize::from(r.side), r.bary())
            }
        }
    }
}

/// A point of the joined polygon: which triangle of the pair (0 or 1) and its point in that
/// triangle's pattern.
pub(crate) type JoinedPoint = (usize, u32);

/// The joined polygon of `pair` cut by `patterns` (each with one segment on the shared edge),
/// counter-clockwise in the first triangle's winding: the first triangle's polygon from the end
/// of the shared edge round to its start, then the second's points off the shared edge.
pub(crate) fn joined_polygon(sides: [u8; 2], patterns: [&Pattern; 2]) -> Vec<JoinedPoint> {
    let mut joined = Vec::new();
    for (s, pattern) in patterns.iter().enumerate() {
        let outer = polygon(pattern);
        let k = usize::from(sides[s]);
        // The shared edge runs from corner k + 1 to corner k + 2 of each triangle; both run
        // it the other way round, so the first's end is the second's start.
        let end = ((k + 2) % 3) as u32;
        let at = outer
            .iter()
            .position(|&p| p == end)
            .expect("a corner is on the polygon");
        let rotated = (0..outer.len()).map(|i| outer[(at + i) % outer.len()]);
        if s == 0 {
            joined.extend(rotated.map(|p| (0, p)));
        } else {
            // Its first point is the first triangle's last, its last the first's first.
            joined.extend(rotated.skip(1).take(outer.len() - 2).map(|p| (1, p)));
        }
    }
    joined
}

/// The two triangles of a pair laid flat side by side (see the module docs).
pub(super) struct Chart {
    /// Each triangle's corners on the chart, in its own corner order.
    corners: [[DVec2; 3]; 2],
}

impl Chart {
    /// The chart of triangles `tris`, sharing their edges `sides`, from the welded positions.
    pub(super) fn new(topo: &Topology, tris: [usize; 2], sides: [u8; 2]) -> Chart {
        let at = |t: usize, c: usize| topo.welded_positions[topo.tri_verts[t][c].0 as usize];
        let mut corners = [[DVec2::ZERO; 3]; 2];
        for (s, &t) in tris.iter().enumerate() {
            let k = usize::from(sides[s]);
            // The first triangle's edge runs from a to b along +x, its third corner above; the
            // second runs it from b to a, its third corner below.
            let (a, b) = if s == 0 {
                ((k + 1) % 3, (k + 2) % 3)
            } else {
                ((k + 2) % 3, (k + 1) % 3)
            };
            let length = at(t, a).distance(at(t, b));
            let (da, db) = (at(t, k).distance(at(t, a)), at(t, k).distance(at(t, b)));
            let x = (da * da - db * db + length * length) / (2.0 * length);
            let y = (da * da - x * x).max(0.0).sqrt();
            corners[s][a] = DVec2::ZERO;
            corners[s][b] = DVec2::new(length, 0.0);
            corners[s][k] = DVec2::new(x, if s == 0 { y } else { -y });
        }
        Chart { corners }
    }

    /// Where point `bary` of triangle `s` of the pair lies on the chart.
    pub(super) fn place(&self, s: usize, bary: [f64; 3]) -> DVec2 {
        let c = &self.corners[s];
        bary[0] * c[0] + bary[1] * c[1] + bary[2] * c[2]
    }

    /// Which triangle of the pair (0 or 1) holds chart point `q`, and its barycentrics there:
    /// the first where it holds `q` (up to rounding), else the second, clamped to it.
    pub(super) fn locate(&self, q: DVec2) -> (usize, [f64; 3]) {
        let bary_in = |c: &[DVec2; 3]| {
            let (u, v, w) = (c[1] - c[0], c[2] - c[0], q - c[0]);
            let det = u.perp_dot(v);
            let b1 = w.perp_dot(v) / det;
            let b2 = u.perp_dot(w) / det;
            [1.0 - b1 - b2, b1, b2]
        };
        let first = bary_in(&self.corners[0]);
        if first.iter().all(|&b| b >= -1e-12) {
            return (0, normalized(first));
        }
        (1, normalized(bary_in(&self.corners[1])))
    }
}

/// `b` with negative weights (rounding at an edge) set to 0 and the rest scaled to sum to 1.
fn normalized(b: [f64; 3]) -> [f64; 3] {
    let b = b.map(|x| x.max(0.0));
    let sum = b[0] + b[1] + b[2];
    b.map(|x| x / sum)
}

/// Evaluates points of either triangle of a pair: `(s, barys, out)` appends the points of
/// triangle `s` of the pair at `barys` to `out`.
pub(super) type OnBoth<'a> = dyn FnMut(usize, &[[f64; 3]], &mut Vec<SurfacePoint>) + 'a;

/// Calls `f` with an evaluator of both triangles `tris` that sets each up once for all its
/// calls ([`Surface::evaluate_points_on_demand`]), where one evaluation per sample set the
/// patch up for each (on the 10k torus at 1e-3 the pass took 844M instructions that way, 669M
/// this way).
pub(super) fn with_both<R>(
    surface: &dyn Surface,
    tris: [usize; 2],
    f: impl FnOnce(&mut OnBoth<'_>) -> R,
) -> R {
    let mut f = Some(f);
    let mut result = None;
    surface.evaluate_points_on_demand(tris[0], &mut |first| {
        surface.evaluate_points_on_demand(tris[1], &mut |second| {
            let mut both = |s: usize, barys: &[[f64; 3]], out: &mut Vec<SurfacePoint>| {
                if s == 0 {
                    first(barys, out)
                } else {
                    second(barys, out)
                }
            };
            let f = f.take().expect("the surface calls `drive` once");
            result = Some(f(&mut both));
        });
    });
    result.expect("the surface calls `drive` once")
}

/// Scratch buffers of [`joined_triangle_error`].
#[derive(Debug, Default)]
pub(super) struct JoinedSamples {
    barys: [Vec<[f64; 3]>; 2],
    points: [Vec<SurfacePoint>; 2],
}

impl JoinedSamples {
    /// The points of triangle `s` of a pair at `barys`, evaluated by `both` into this scratch.
    pub(super) fn evaluate(
        &mut self,
        both: &mut OnBoth<'_>,
        s: usize,
        barys: &[[f64; 3]],
    ) -> &[SurfacePoint] {
        self.points[s].clear();
        both(s, barys, &mut self.points[s]);
        &self.points[s]
    }
}

/// The chord error of the output triangle with corners at chart points `chart` and written
/// positions `flat`: the largest distance of its [`WEIGHTS`] samples from the surface's tangent
/// plane at the surface point under each, found through `on_chart` and evaluated by `both`,
/// each triangle's samples in one call.
pub(super) fn joined_triangle_error(
    both: &mut OnBoth<'_>,
    on_chart: &Chart,
    chart: [DVec2; 3],
    flat: [DVec3; 3],
    scratch: &mut JoinedSamples,
) -> f64 {
    let mut side = [0u8; WEIGHTS.len()];
    for s in 0..2 {
        scratch.barys[s].clear();
        scratch.points[s].clear();
    }
    for (k, w) in WEIGHTS.iter().enumerate() {
        let q = w[0] * chart[0] + w[1] * chart[1] + w[2] * chart[2];
        let (s, bary) = on_chart.locate(q);
        side[k] = s as u8;
        scratch.barys[s].push(bary);
    }
    for s in 0..2 {
        if !scratch.barys[s].is_empty() {
            both(s, &scratch.barys[s], &mut scratch.points[s]);
        }
    }
    let mut next = [0usize; 2];
    let mut worst = 0.0f64;
    for (k, w) in WEIGHTS.iter().enumerate() {
        let s = usize::from(side[k]);
        let point = &scratch.points[s][next[s]];
        next[s] += 1;
        worst = worst.max(normal_distance(
            w[0] * flat[0] + w[1] * flat[1] + w[2] * flat[2],
            point,
        ));
    }
    worst
}

/// The chord error of `pair`'s triangles cut by `patterns`, whose triangle `u` (in the order of
/// [`Pair::triangles`]) has corner `c` at `corner(u, c)`: what the report measures.
pub(crate) fn joined_error(
    topo: &Topology,
    surface: &dyn Surface,
    pair: &Pair,
    patterns: [&Pattern; 2],
    corner: impl Fn(usize, usize) -> DVec3,
) -> f64 {
    let joined = joined_polygon(pair.sides, patterns);
    let tris = pair.tris.map(|t| t as usize);
    let chart = Chart::new(topo, tris, pair.sides);
    let mut scratch = JoinedSamples::default();
    with_both(surface, tris, |both| {
        let mut worst = 0.0f64;
        for (u, t) in pair.triangles.iter().enumerate() {
            let on_chart = t.map(|q| {
                let (s, bary) = pair.point_bary(&joined, patterns, q);
                chart.place(s, bary)
            });
            let flat = [0, 1, 2].map(|c| corner(u, c));
            worst = worst.max(joined_triangle_error(
                both,
                &chart,
                on_chart,
                flat,
                &mut scratch,
            ));
        }
        worst
    })
}

/// An edge that could be dissolved: the edge, its two triangles, their sides on it, and their
/// pattern keys with one segment there.
type Candidate = (usize, [usize; 2], [u8; 2], [PatternKey; 2]);

impl SegmentCounts {
    /// Dissolves the interior edges the module docs say into the polygon of the two triangles
    /// beside them, where that saves triangles and a triangulation of it measures within
    /// `tolerance`; `groups` are the output groups (a pair stays in one), `h` the edges' widths
    /// (creases are kept).
    pub fn pair_across_edges(
        &mut self,
        mesh: &TriMesh,
        topo: &Topology,
        h: &[f64],
        surface: &dyn Surface,
        tolerance: f64,
        groups: &[Range<usize>],
    ) {
        let counts = self;
        let group_of = group_table(counts.inner.len(), groups);
        let candidates: Vec<Candidate> = (0..topo.edge_count())
            .into_par_iter()
            .filter_map(|e| {
                let (tris, sides) = dissolvable(counts, mesh, topo, h, &group_of, e)?;
                let keys = one_segment_keys(counts, topo, tris, sides);
                // Without interior points on both sides, one segment or not.
                (keys[0].inner <= 2 && keys[1].inner <= 2).then_some((e, tris, sides, keys))
            })
            .collect();
        let found: Vec<Option<Pair>> = candidates
            .par_iter()
            .map_init(
                JoinedSamples::default,
                |scratch, &(_, tris, sides, keys)| {
                    joined_fill(surface, topo, tris, sides, keys, tolerance, scratch)
                },
            )
            .collect();
        // Most triangles saved first (two per segment taken off the edge), then by edge.
        let mut order: Vec<usize> = (0..candidates.len())
            .filter(|&c| found[c].is_some())
            .collect();
        order.sort_by_key(|&c| (std::cmp::Reverse(counts.edges[candidates[c].0]), c));
        counts.pairs.clear();
        let mut taken = vec![false; counts.inner.len()];
        counts.take_pairs(
            &order,
            |c| (candidates[c].0, candidates[c].1),
            &found,
            &mut taken,
            false,
        );
    }

    /// Cuts the pairs `found[c]` of the candidates `c` in `order` (edge and triangles
    /// `candidate(c)`) whose triangles are not `taken` yet, and marks them taken: the edge
    /// takes one segment, the triangles the fill by ears, and for quads cut in rows
    /// (`in_rows`, `rows.rs`) inner level 1: their interior is the rows' points, if any.
    pub(super) fn take_pairs(
        &mut self,
        order: &[usize],
        candidate: impl Fn(usize) -> (usize, [usize; 2]),
        found: &[Option<Pair>],
        taken: &mut [bool],
        in_rows: bool,
    ) {
        for &c in order {
            let (e, tris) = candidate(c);
            if tris.iter().any(|&t| taken[t]) {
                continue;
            }
            let pair = found[c].clone().expect("only those found");
            tris.iter().for_each(|&t| taken[t] = true);
            self.edges[e] = 1;
            for &t in &tris {
                self.fill[t] = 0;
                if in_rows {
                    self.inner[t] = 1;
                }
            }
            self.pairs.push(pair);
        }
        self.pairs.sort_by_key(|p| p.tris[0]);
    }
}

/// Per source triangle, the index of its output group in `groups` (`u32::MAX`: none).
pub(super) fn group_table(triangles: usize, groups: &[Range<usize>]) -> Vec<u32> {
    let mut group_of = vec![u32::MAX; triangles];
    for (g, range) in groups.iter().enumerate() {
        group_of[range.clone()]
            .iter_mut()
            .for_each(|x| *x = g as u32);
    }
    group_of
}

/// The two triangles of edge `e` and their sides on it, the lower-numbered first, where the
/// edge could be dissolved (the module docs say when): an interior smooth edge with more than
/// one segment, within one group, with the same input vertices on both sides, wound alike.
pub(super) fn dissolvable(
    counts: &SegmentCounts,
    mesh: &TriMesh,
    topo: &Topology,
    h: &[f64],
    group_of: &[u32],
    e: usize,
) -> Option<([usize; 2], [u8; 2])> {
    let id = EdgeId(e as u32);
    if counts.edges[e] < 2 || topo.edge_kind(id) != EdgeKind::Interior || is_crease(topo, h, id) {
        return None;
    }
    // An interior edge has two distinct triangles, the lower-numbered first.
    let uses = topo.edge_uses(id);
    let [(t0, k0), (t1, k1)] = [uses[0].at(), uses[1].at()];
    if group_of[t0] != group_of[t1] || group_of[t0] == u32::MAX {
        return None;
    }
    // The same input vertices, the second triangle running the edge the other way.
    let ends = |t: usize, k: usize| {
        let v = mesh.triangles[t];
        (v[(k + 1) % 3], v[(k + 2) % 3])
    };
    let ((a0, b0), (a1, b1)) = (ends(t0, k0), ends(t1, k1));
    ((a0, b0) == (b1, a1)).then_some(([t0, t1], [k0 as u8, k1 as u8]))
}

/// The pattern keys of triangles `tris` with one segment on their sides `sides`, filled by
/// ears (what [`joined_polygon`] reads their edge samples from).
pub(super) fn one_segment_keys(
    counts: &SegmentCounts,
    topo: &Topology,
    tris: [usize; 2],
    sides: [u8; 2],
) -> [PatternKey; 2] {
    [0, 1].map(|s| {
        let mut key = counts.key(topo, tris[s]);
        key.edges[usize::from(sides[s])] = 1;
        key.fill = 0;
        key
    })
}

/// Whether the chart triangle `t` is wound counter-clockwise with every angle at least
/// [`ANGLE_FLOOR`]: an angle `θ` between sides `u` and `v` is at least the floor where
/// `u·v ≤ 0` or `|u × v| ≥ tan(floor)·(u·v)`, without the three arctangents of `transition.rs`'s `min_angle`
/// (on the 10k icosphere at 3e-4 they were a quarter of the pass).
pub(super) fn keeps_floor(t: [DVec2; 3]) -> bool {
    let tan_floor = ANGLE_FLOOR.tan();
    (t[1] - t[0]).perp_dot(t[2] - t[0]) > 0.0
        && (0..3).all(|c| {
            let (u, v) = (t[(c + 1) % 3] - t[c], t[(c + 2) % 3] - t[c]);
            let dot = u.dot(v);
            dot <= 0.0 || u.perp_dot(v).abs() >= tan_floor * dot
        })
}

/// Writes into `position` the points of the joined polygon `joined` (of triangles cut by
/// `patterns`) that are `needed`, as the output writes them, each triangle's in one call.
pub(super) fn polygon_points(
    both: &mut OnBoth<'_>,
    scratch: &mut JoinedSamples,
    joined: &[JoinedPoint],
    patterns: &[Kept<Pattern>; 2],
    needed: &[bool],
    position: &mut [DVec3],
) {
    for (s, pattern) in patterns.iter().enumerate() {
        let wanted = |i: usize| needed[i] && joined[i].0 == s;
        scratch.barys[s].clear();
        scratch.points[s].clear();
        scratch.barys[s].extend(
            (0..joined.len())
                .filter(|&i| wanted(i))
                .map(|i| pattern.bary(joined[i].1)),
        );
        if scratch.barys[s].is_empty() {
            continue;
        }
        both(s, &scratch.barys[s], &mut scratch.points[s]);
        let mut points = scratch.points[s].iter();
        for (i, p) in position.iter_mut().enumerate() {
            if wanted(i) {
                *p = written(points.next().expect("one point per polygon point").position);
            }
        }
    }
}

/// The triangulation of the joined polygon of `tris` (cut by `keys`, one segment on the shared
/// edges `sides`) whose triangles are positively wound and keep the angle floor on the chart and
/// measure within `tolerance`, with the largest smallest angle in space; `None` if there is none.
///
/// The triangle that covers the dissolved edge's midpoint is also measured there: every
/// triangulation has one, so where no candidate triangle covering it is within the tolerance
/// there, none is, and the edge is passed over after one evaluation of the surface. Most edges
/// tried are (on the 10k icosphere at 3e-4, 12,600 of 13,080: there, where the curvature is the
/// same every way, the polygon without the edge's own samples is too coarse across it).
fn joined_fill(
    surface: &dyn Surface,
    topo: &Topology,
    tris: [usize; 2],
    sides: [u8; 2],
    keys: [PatternKey; 2],
    tolerance: f64,
    scratch: &mut JoinedSamples,
) -> Option<Pair> {
    let JoinedChart {
        patterns,
        points: joined,
        chart,
        on_chart,
    } = JoinedChart::new(topo, tris, sides, keys);
    let n = joined.len();
    if n > u8::MAX as usize {
        return None;
    }
    // The candidate triangle lo < k < hi, if wound the right way and keeping the floor.
    let keeps =
        |lo: usize, k: usize, hi: usize| keeps_floor([on_chart[lo], on_chart[k], on_chart[hi]]);
    // The dissolved edge's midpoint, and its weights in a candidate triangle that covers it.
    let k0 = usize::from(sides[0]);
    let mut middle_bary = [0.5; 3];
    middle_bary[k0] = 0.0;
    let middle = chart.place(0, middle_bary);
    let covering = |lo: usize, k: usize, hi: usize| {
        let [a, b, c] = [on_chart[lo], on_chart[k], on_chart[hi]];
        let area = (b - a).perp_dot(c - a);
        if area <= 0.0 {
            return None;
        }
        let w = [
            (b - middle).perp_dot(c - middle) / area,
            (c - middle).perp_dot(a - middle) / area,
            (a - middle).perp_dot(b - middle) / area,
        ];
        w.iter().all(|&x| x >= -1e-12).then_some(w)
    };
    // The candidate triangles that cover the middle, with their weights there: the only ones
    // the first test reads (found by three cross products each, before any angle).
    let mut covers = Vec::new();
    for lo in 0..n {
        for k in lo + 1..n {
            for hi in k + 1..n {
                if let Some(w) = covering(lo, k, hi) {
                    if keeps(lo, k, hi) {
                        covers.push(([lo, k, hi], w));
                    }
                }
            }
        }
    }
    if covers.is_empty() {
        return None;
    }
    with_both(surface, tris, |both| {
        // The polygon's points as written, each side's in one call: first those of the
        // triangles covering the middle, with the surface at the middle, then the others.
        let mut position = vec![DVec3::NAN; n];
        let mut needed = vec![false; n];
        covers
            .iter()
            .flat_map(|(t, _)| t)
            .for_each(|&v| needed[v] = true);
        polygon_points(both, scratch, &joined, &patterns, &needed, &mut position);
        scratch.points[0].clear();
        both(0, &[middle_bary], &mut scratch.points[0]);
        let at_middle = scratch.points[0][0];
        let middle_error = |position: &[DVec3], t: [usize; 3], w: [f64; 3]| {
            let flat = w[0] * position[t[0]] + w[1] * position[t[1]] + w[2] * position[t[2]];
            normal_distance(flat, &at_middle)
        };
        if !covers
            .iter()
            .any(|&(t, w)| middle_error(&position, t, w) <= tolerance)
        {
            return None;
        }
        let rest: Vec<bool> = needed.iter().map(|&x| !x).collect();
        polygon_points(both, scratch, &joined, &patterns, &rest, &mut position);
        if position.iter().any(|p| !p.is_finite()) {
            return None;
        }
        let position = position;
        let middle_error = |lo: usize, k: usize, hi: usize| {
            covering(lo, k, hi).map(|w| middle_error(&position, [lo, k, hi], w))
        };
        let angle = |lo: usize, k: usize, hi: usize| {
            angle_in_space([position[lo], position[k], position[hi]])
        };
        // best[lo·n + hi]: the largest smallest angle in space of sub-polygon lo..=hi's
        // triangulations within the tolerance, and the apex of its triangle on (lo, hi). A
        // candidate is measured only where it could change that, as in `fill.rs`.
        let mut best: Vec<Option<(f64, usize)>> = vec![None; n * n];
        for lo in 0..n - 1 {
            best[lo * n + lo + 1] = Some((f64::MAX, usize::MAX));
        }
        for span in 2..n {
            for lo in 0..n - span {
                let hi = lo + span;
                let mut found: Option<(f64, usize)> = None;
                for k in lo + 1..hi {
                    let (Some((left, _)), Some((right, _))) = (best[lo * n + k], best[k * n + hi])
                    else {
                        continue;
                    };
                    if !keeps(lo, k, hi) {
                        continue;
                    }
                    let a = angle(lo, k, hi).min(left).min(right);
                    if found.is_none_or(|(b, _)| a > b)
                        && middle_error(lo, k, hi).is_none_or(|e| e <= tolerance)
                        && joined_triangle_error(
                            both,
                            &chart,
                            [on_chart[lo], on_chart[k], on_chart[hi]],
                            [position[lo], position[k], position[hi]],
                            scratch,
                        ) <= tolerance
                    {
                        found = Some((a, k));
                    }
                }
                best[lo * n + hi] = found;
            }
        }
        best[n - 1]?;
        let mut triangles = Vec::with_capacity(n - 2);
        let mut pending = vec![(0usize, n - 1)];
        while let Some((lo, hi)) = pending.pop() {
            if hi - lo < 2 {
                continue;
            }
            let (_, k) = best[lo * n + hi].expect("a sub-polygon of the best has a best");
            triangles.push([lo as u8, k as u8, hi as u8]);
            pending.push((k, hi));
            pending.push((lo, k));
        }
        Some(Pair {
            tris: tris.map(|t| t as u32),
            sides,
            triangles,
            interior: Vec::new(),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles of a bent quad, the second's corners listed from each of its three
    /// rotations, so that the shared edge is every local edge of it.
    fn bent_quads() -> Vec<(TriMesh, [u8; 2])> {
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.1),
            DVec3::new(1.2, 0.9, 0.3),
            DVec3::new(-0.1, 1.1, 0.0),
        ];
        let second = [[0u32, 2, 3], [2, 3, 0], [3, 0, 2]];
        second
            .iter()
            .enumerate()
            .map(|(r, &t)| {
                let mesh = TriMesh {
                    normals: vec![DVec3::Z; 4],
                    positions: positions.clone(),
                    triangles: vec![[0, 1, 2], t],
                };
                // Edge 1 of the first (corner 2 to corner 0); the second's edge opposite
                // vertex 3, which rotation r puts at corner (2 + 2r) % 3.
                (mesh, [1, ((2 + 2 * r) % 3) as u8])
            })
            .collect()
    }

    #[test]
    fn the_joined_polygon_goes_round_both_triangles_once() {
        for (mesh, sides) in bent_quads() {
            let topo = Topology::build(&mesh);
            let e = topo.tri_edges[0][usize::from(sides[0])];
            assert_eq!(e, topo.tri_edges[1][usize::from(sides[1])], "{sides:?}");
            let chart = Chart::new(&topo, [0, 1], sides);
            for edges in [[2, 1, 3], [1, 3, 2], [3, 2, 1]] {
                let keys = [0, 1].map(|s| {
                    let mut edges = edges;
                    edges[usize::from(sides[s])] = 1;
                    PatternKey {
                        edges,
                        inner: 2,
                        fill: 0,
                    }
                });
                let patterns = keys.map(Pattern::new);
                let joined = joined_polygon(sides, [&patterns[0], &patterns[1]]);
                let k = patterns.each_ref().map(|p| p.triangles.len() + 2);
                assert_eq!(joined.len(), k[0] + k[1] - 2, "{edges:?} {sides:?}");
                // Counter-clockwise and simple on the chart: its signed area is the two
                // triangles' areas, each point a distinct point of the chart.
                let at: Vec<DVec2> = joined
                    .iter()
                    .map(|&(s, p)| chart.place(s, patterns[s].bary(p)))
                    .collect();
                let area: f64 = (0..at.len())
                    .map(|i| at[i].perp_dot(at[(i + 1) % at.len()]))
                    .sum::<f64>()
                    / 2.0;
                let triangle = |s: usize| {
                    let c = chart.corners[s];
                    (c[1] - c[0]).perp_dot(c[2] - c[0]) / 2.0
                };
                assert!(triangle(0) > 0.0 && triangle(1) > 0.0, "{sides:?}");
                assert!(
                    (area - triangle(0) - triangle(1)).abs() < 1e-12,
                    "{edges:?} {sides:?}: area {area}"
                );
                for i in 0..at.len() {
                    for j in i + 1..at.len() {
                        assert!(at[i].distance(at[j]) > 1e-9, "{edges:?} {sides:?}: {i} {j}");
                    }
                }
            }
        }
    }

    #[test]
    fn the_floor_test_agrees_with_the_smallest_angle() {
        // Triangles on a grid of corners, both windings, away from the floor by more than
        // rounding: the test without arctangents answers as the angles do.
        let mut checked = 0;
        for i in 0..12 {
            for j in 0..12 {
                let t = [
                    DVec2::ZERO,
                    DVec2::new(1.0, 0.0),
                    DVec2::new(i as f64 / 5.0 - 0.7, j as f64 / 6.0 - 1.0),
                ];
                let angle = min_angle(t[0].to_array(), t[1].to_array(), t[2].to_array());
                if (angle - ANGLE_FLOOR).abs() < 1e-9 {
                    continue;
                }
                let ccw = (t[1] - t[0]).perp_dot(t[2] - t[0]) > 0.0;
                assert_eq!(keeps_floor(t), ccw && angle >= ANGLE_FLOOR, "{t:?}");
                checked += 1;
            }
        }
        assert!(checked > 100);
    }

    #[test]
    fn a_point_placed_on_the_chart_is_located_where_it_came_from() {
        for (mesh, sides) in bent_quads() {
            let topo = Topology::build(&mesh);
            let chart = Chart::new(&topo, [0, 1], sides);
            // The chart keeps each triangle's edge lengths.
            for s in 0..2 {
                for c in 0..3 {
                    let (a, b) = (c, (c + 1) % 3);
                    let t = mesh.triangles[s];
                    let space =
                        mesh.positions[t[a] as usize].distance(mesh.positions[t[b] as usize]);
                    let flat = chart.corners[s][a].distance(chart.corners[s][b]);
                    assert!((space - flat).abs() < 1e-12, "{sides:?} {s} {c}");
                }
            }
            for s in 0..2 {
                for bary in [[0.2, 0.3, 0.5], [0.6, 0.3, 0.1], [0.05, 0.05, 0.9]] {
                    let (tri, back) = chart.locate(chart.place(s, bary));
                    assert_eq!(tri, s, "{sides:?} {bary:?}");
                    for i in 0..3 {
                        assert!(
                            (back[i] - bary[i]).abs() < 1e-12,
                            "{sides:?} {bary:?} {back:?}"
                        );
                    }
                }
            }
        }
    }
}
