//! The chord error of a transition pattern predicted from one lattice of surface points, through
//! the lattice evaluation (cached weights) instead of sampling every output triangle point by
//! point.
//!
//! For a surface that is quadratic in the domain, a flat triangle with corners at domain points
//! `λ_a` is off the surface, at weights `w`, by
//!
//! ```text
//! S(Σ w_a λ_a) − Σ w_a S(λ_a) = −½ Σ_{a<b} w_a w_b Q_ab,   Q_ab = D²S[λ_a − λ_b, λ_a − λ_b]
//! ```
//!
//! (so opposite curvatures cancel as they do on the surface). `D²S` is fixed by its values
//! along the three lattice directions, and the second differences of a level-`L` lattice give
//! those at every interior point: `S(p − u) − 2S(p) + S(p + u) = D²S[u, u] + O(|u|⁴)`. Only their
//! component along the surface normal `n(p)` is kept, as `chord.rs` measures the error along the
//! normal: the tangential part of `D²S` is the parametrization's curvature, not the surface's,
//! and near the G² blend's corners it grows as one over the distance to the corner (see
//! `chord.rs`), which would ask for counts the surface does not need.
//! So one lattice per source triangle predicts the error of every output triangle at the seven
//! sample points `chord.rs` measures, from the second differences at the lattice points nearest
//! its corners: exactly on quadratic surfaces, and at the pattern's own resolution (`L` is at
//! least its inner level), so the blend bands the coarse probe misses are seen.
//!
//! It deliberately evaluates nothing: it reads the lattice its caller evaluated.

use glam::DVec3;

use super::chord::WEIGHTS;
use super::transition::{Pattern, PatternKey};
use crate::surface::{lattice_index, LatticePart, SurfacePoint};

/// Second differences of a level-`L` lattice at its interior points (`i, j ≥ 1`, `i + j < L`),
/// along the surface normal there, in interior lattice order: along `i`, along `j`, and along
/// `(i − 1, j + 1)`.
#[derive(Debug, Default)]
pub(crate) struct Curvature {
    level: u32,
    at: Vec<[f64; 3]>,
    /// How far, at most, the second differences a check at twice this lattice's resolution
    /// reads (scaled to this lattice's step) can lie from [`Curvature::at`]: see
    /// [`Curvature::spread`].
    spread: f64,
    /// The inner lattice error last computed on this lattice and the inner level it was for
    /// ([`Curvature::inner_error`]); level 0: none; level [`EVERY_POINT`]: the largest error
    /// over every interior point, unscaled, which gives the error of every inner level at or
    /// above the lattice's (what [`Curvature::read`] leaves).
    inner: (u32, f64),
}

/// The level [`Curvature`] keeps its inner lattice error for when it holds the worst over every
/// interior point (see [`Curvature::inner_error`]).
const EVERY_POINT: u32 = u32::MAX;

/// The largest of `|½ Σ_{a<b} w_a w_b|` over the sample weights: the most a unit change of
/// every `Q_ab` changes a sample's predicted error (at the centroid, `½ · 3 · (1/3)²`).
const WEIGHT_GAIN: f64 = 1.0 / 6.0;

/// Relative allowance for the rounding of [`worst_abs`]'s sums against [`Under`], which filters
/// the points that cannot change a maximum, and against the spread's `WEIGHT_GAIN` bounds.
const BOUND_SLACK: f64 = 1.0 + 1e-12;

/// The interior point of the level-`l` lattice nearest barycentrics `b`, as an index among the
/// interior points in lattice order.
fn nearest(l: u32, b: [f64; 3]) -> usize {
    let round = |x: f64| (x * f64::from(l)).round().max(1.0) as u32;
    let i = round(b[1]).min(l - 2);
    let j = round(b[2]).min(l - 1 - i);
    interior_index(l, i, j)
}

/// Index of interior point `(i, j)` of the level-`n` lattice among the interior points, in
/// lattice order.
fn interior_index(n: u32, i: u32, j: u32) -> usize {
    let (n, i, j) = (n as usize, i as usize, j as usize);
    (j - 1) * (n - 1) - (j - 1) * j / 2 + (i - 1)
}

impl Curvature {
    /// Appends what [`Curvature::restore`] takes back: the second differences read, in
    /// interior lattice order, then the spread and the last inner lattice error with its level.
    pub fn keep(&self, into: &mut Vec<[f64; 3]>) {
        // Held per triangle until its next check: exactly as large as it needs to be, not
        // doubled by the trailer's push.
        into.reserve_exact(self.at.len() + 1);
        into.extend_from_slice(&self.at);
        into.push([self.spread, f64::from(self.inner.0), self.inner.1]);
    }

    /// Takes back what [`Curvature::keep`] appended for a level-`level` lattice read before,
    /// when `values` has that lattice's number of interior points (which differs from level to
    /// level) and the spread; whether it did. A lattice of the same triangle and level has the
    /// same values, bit for bit, so restoring them stands for reading it again.
    pub fn restore(&mut self, level: u32, values: &[[f64; 3]]) -> bool {
        let interior = LatticePart::Interior.len(level);
        if level < 3 || values.len() != interior + 1 {
            return false;
        }
        self.level = level;
        self.at.clear();
        self.at.extend_from_slice(&values[..interior]);
        let [spread, inner_level, inner_error] = values[interior];
        self.spread = spread;
        self.inner = (inner_level as u32, inner_error);
        true
    }

    /// A bound on how far the second differences of the lattice at twice this one's
    /// resolution, times 4 (the step halved), lie from this lattice's at the points a model
    /// reads, for a surface smooth at the scale of two steps; `∞` when this lattice is too
    /// coarse to tell.
    ///
    /// With step `h` along a lattice direction `u`, `δ(h) = S(p − hu) − 2S(p) + S(p + hu)`
    /// `= h² D²S[u,u] + (h⁴/12) D⁴S[u,u,u,u] + O(h⁶)`, so the finer check reads
    /// `4δ(h/2) = δ(h) − Δ/4 + O(h⁶)` with `Δ = δ(2h)/4 − δ(h)` (Richardson: the stride-2
    /// differences of this same lattice, no new evaluation). The finer lattice's model also
    /// reads its points up to half a step from this one's, where the differences differ by at
    /// most half the largest change `V` between neighbouring points. The spread is
    /// `Δ_max/2 + V_max`: both terms twice what the expansion gives, for the higher orders. A
    /// blend band narrower than a step, which the finer check exists for, breaks the expansion
    /// and shows in both `Δ` and `V` as differences of the size of the second differences
    /// themselves, so its spread is large and the finer check runs. NaN until
    /// [`Curvature::measure_spread`] measured it (no bound passes then).
    pub fn spread(&self) -> f64 {
        self.spread
    }

    /// Reads the second differences of `points`, the whole level-`level` lattice (`level ≥ 3`)
    /// in lattice order; reuses its own storage.
    ///
    /// The largest error of the inner lattice over every interior point, which
    /// [`Curvature::inner_error`] gives any inner level at or above this one from (the checks
    /// at a pattern's own resolution and the probe ask for it after every read), is taken in the
    /// same pass, while each point's differences are in registers: the same filter and maximum
    /// as [`Curvature::lattice_error`] at the lattice's own level, in the same order, so the same
    /// bits. The rows are walked as windows of the rows below, at and above, written into the
    /// storage sized once, so the loop has no bounds checks or growth of its own.
    pub fn read(&mut self, points: &[SurfacePoint], level: u32) {
        debug_assert!(level >= 3);
        self.level = level;
        self.at.clear();
        self.at.resize(LatticePart::Interior.len(level), [0.0; 3]);
        let mut out = self.at.as_mut_slice();
        let mut worst = 0.0f64;
        let mut under = Under::new(worst);
        // From row `j − 1` on: rows `j − 1`, `j` and `j + 1` have `L + 2 − j`, `L + 1 − j` and
        // `L − j` points (`row`).
        let l = level as usize;
        let mut rows = points;
        for j in 1..l {
            let (below, from_here) = rows.split_at(l + 2 - j);
            let (here, above) = from_here.split_at(l + 1 - j);
            rows = from_here;
            let (row_out, rest) = std::mem::take(&mut out).split_at_mut(l - 1 - j);
            out = rest;
            // Point `i` of the row (from 1): `here[i − 1..=i + 1]`, `below[i..=i + 1]`,
            // `above[i − 1..=i]`, the same sums as `at(i ± 1, j)`, `at(i, j ± 1)` and
            // `at(i ± 1, j ∓ 1)` in the same order.
            let windows = here
                .windows(3)
                .zip(below[1..].windows(2))
                .zip(above.windows(2));
            for (((h, b), a), q) in windows.zip(row_out) {
                *q = second_differences(&h[1], [&h[0], &h[2], &b[0], &a[1], &b[1], &a[0]]);
                if !under.holds(*q) {
                    raise(&mut worst, &mut under, worst_abs(*q), 0.0);
                }
            }
        }
        self.inner = (EVERY_POINT, worst);
        self.spread = f64::NAN;
    }

    /// Measures [`Curvature::spread`] on `points`, the lattice [`Curvature::read`] read last:
    /// apart, as only a check that may skip the finer one needs it.
    pub fn measure_spread(&mut self, points: &[SurfacePoint]) {
        self.spread = self.spread_of(points);
    }

    /// [`Curvature::spread`] of the lattice `points` whose second differences `at` holds.
    fn spread_of(&self, points: &[SurfacePoint]) -> f64 {
        let level = self.level;
        if level < 6 {
            return f64::INFINITY;
        }
        let mut richardson = 0.0f64;
        let mut change = 0.0f64;
        let mut index = 0;
        for j in 1..level {
            // Points two rows below and above, where they exist (`i + j + 2 ≤ level` below).
            let here = row(points, level, j);
            let (below, above) = if j >= 2 && j + 2 <= level {
                (row(points, level, j - 2), row(points, level, j + 2))
            } else {
                (here, here)
            };
            // Interior points of row `j` (`i` from 1): the next row's start, `(i, j + 1)`.
            let row_length = (level - 1 - j) as usize;
            for i in 1..level - j {
                let fine = self.at[index];
                if i >= 2 && j >= 2 && i + j + 2 <= level {
                    let i = i as usize;
                    let p = &here[i];
                    let centre = 2.0 * p.position;
                    let along = |d: DVec3| 0.25 * d.dot(p.normal);
                    let coarse = [
                        along(here[i - 2].position - centre + here[i + 2].position),
                        along(below[i].position - centre + above[i].position),
                        along(below[i + 2].position - centre + above[i - 2].position),
                    ];
                    for k in 0..3 {
                        richardson = larger(richardson, (coarse[k] - fine[k]).abs());
                    }
                }
                // The neighbours (i + 1, j) and (i, j + 1), when interior.
                if i + j + 1 < level {
                    for other in [self.at[index + 1], self.at[index + row_length]] {
                        for k in 0..3 {
                            change = larger(change, (other[k] - fine[k]).abs());
                        }
                    }
                }
                index += 1;
            }
        }
        if richardson.is_finite() && change.is_finite() {
            0.5 * richardson + change
        } else {
            f64::INFINITY
        }
    }

    /// [`Curvature::lattice_error`] of a level-`m` inner lattice (`m ≥ 1`), computed once per
    /// lattice and level: a triangle checked again with only its edge counts raised (most of
    /// the checks while the counts settle, restored by [`Curvature::restore`]) has the same
    /// inner lattice error, bit for bit, and the model's boundary part is all that changes.
    ///
    /// An inner level `m` at or above the lattice's own reads every interior point (each is at
    /// least one level-`m` step in from the edges), so [`Curvature::lattice_error`] is
    /// `(L/m)²` times one maximum for all of them: that maximum is what is kept, and the
    /// product is taken as `lattice_error` takes it, so a triangle whose inner level is raised
    /// on the same lattice (the probe's, while the counts settle on it) scales the kept
    /// maximum instead of reading the lattice again.
    pub fn inner_error(&mut self, m: u32) -> f64 {
        let l = self.level;
        if m >= l {
            if self.inner.0 != EVERY_POINT {
                // At its own level the scale is 1: the maximum itself, bit for bit.
                self.inner = (EVERY_POINT, self.lattice_error(l));
            }
            let scale = (f64::from(l) / f64::from(m)).powi(2);
            return scale * self.inner.1;
        }
        if self.inner.0 != m {
            self.inner = (m, self.lattice_error(m));
        }
        self.inner.1
    }

    /// The largest predicted error of the inner lattice of a level-`m` pattern (every triangle
    /// of a uniform lattice has edges along the three lattice directions, one step long): over
    /// the points at least one level-`m` step in from every edge, where its triangles are; none
    /// below level 4, where every triangle touches the boundary.
    pub fn lattice_error(&self, m: u32) -> f64 {
        if m < 4 && m != self.level {
            return 0.0;
        }
        let l = self.level;
        let inside = |i: u32, j: u32| {
            // Barycentrics i/l, j/l and (l − i − j)/l each at least 1/m (or the whole
            // interior when m is the lattice's own level).
            m == l || (i * m >= l && j * m >= l && (l - i - j) * m >= l)
        };
        let mut worst = 0.0f64;
        let mut under = Under::new(worst);
        let mut index = 0;
        for j in 1..l {
            for i in 1..l - j {
                if inside(i, j) {
                    let q = self.at[index];
                    // A point under the largest error so far cannot change it.
                    if !under.holds(q) {
                        raise(&mut worst, &mut under, worst_abs(q), 0.0);
                    }
                }
                index += 1;
            }
        }
        let scale = (f64::from(l) / f64::from(m)).powi(2);
        scale * worst
    }

    /// The predicted error of one output triangle of a model at one of the interior points
    /// nearest its corners (found when the model was built), or any value at most the maximum
    /// `under` was made for when it is at most that (`under` is then all it asks: the caller
    /// keeps a maximum that is at least that one).
    /// `l2` is the lattice's `L²`, computed once per model by the caller.
    #[inline(always)]
    fn sample_error(&self, s: &ModelSample, under: Under, l2: f64) -> f64 {
        let [d1, d2, d3] = self.at[s.point as usize];
        let mixed = d1 + d2 - d3;
        let q = s
            .edges
            .map(|[ii, jj, ij]| l2 * (ii * d1 + jj * d2 + ij * mixed));
        if under.holds(q) {
            0.0
        } else {
            worst_abs(q)
        }
    }
}

/// The larger of a running maximum `max`, never NaN, and `x`; `max` when `x` is NaN, as
/// `f64::max` gives, in one comparison (the maxima of the checks' loops, run per lattice point
/// and per model sample).
#[inline]
fn larger(max: f64, x: f64) -> f64 {
    if x > max {
        x
    } else {
        max
    }
}

/// Row `j` of a level-`level` lattice in lattice order: points `(0, j)` to `(level − j, j)`.
#[inline]
fn row(points: &[SurfacePoint], level: u32, j: u32) -> &[SurfacePoint] {
    let start = lattice_index(level, 0, j);
    &points[start..start + (level + 1 - j) as usize]
}

/// The second differences at `p` along its normal, from its neighbours `[i − 1, i + 1, below
/// i, above i, below i + 1, above i − 1]` as [`Curvature::read`] pairs them:
/// `(a − 2p) + b` per direction, then the dot product with the normal, as `DVec3` takes it.
#[inline(always)]
fn second_differences(p: &SurfacePoint, around: [&SurfacePoint; 6]) -> [f64; 3] {
    let centre = 2.0 * p.position;
    let along =
        |a: &SurfacePoint, b: &SurfacePoint| (a.position - centre + b.position).dot(p.normal);
    [
        along(around[0], around[1]),
        along(around[2], around[3]),
        along(around[4], around[5]),
    ]
}

/// What a maximum `worst` asks of a point's or a sample's differences `q` that cannot raise it:
/// `max |Q| ≤ 8·worst` and `Σ|Q| ≤ 18·worst`, each with room for the rounding. Each sample's
/// error is at most `½ Σ_{a<b} w_a w_b |Q_ab|`, which is `|Q_ab|/8` at an edge midpoint and at
/// most `Σ|Q|/18` at the centroid and at the points halfway to the corners (their products
/// `w_a w_b` are `1/9`, `1/9`, `1/36`, each at most the centroid's `1/9`), so when both hold
/// [`worst_abs`]`(q)` is at most `worst`: its sums round by a few units in the last place,
/// the thresholds keep [`BOUND_SLACK`] below the exact ones, and `Σ|Q|` as summed is at most
/// two units above the exact sum. A `q` with a NaN or an infinite term has a NaN or infinite
/// sum, over every threshold (they stop at the largest finite number), so it is never under:
/// [`worst_abs`] takes it as before.
///
/// Made once per change of the maximum instead of a bound per point compared with it (the
/// bound's products, maxima and finiteness test on every point: the checks' sample loop 73 →
/// 57 instructions a sample in isolation). It passes what the bound `BOUND_SLACK · max(max|Q|/8,
/// Σ|Q|/18) ≤ worst` passes, up to the rounding of the thresholds.
#[derive(Debug, Clone, Copy)]
struct Under {
    most: f64,
    sum: f64,
}

impl Under {
    /// The thresholds for the maximum `worst`.
    #[inline]
    fn new(worst: f64) -> Under {
        Under {
            most: (worst * (8.0 / BOUND_SLACK)).min(f64::MAX),
            sum: (worst * (18.0 / BOUND_SLACK)).min(f64::MAX),
        }
    }

    /// Whether `q`'s error is certainly at most the maximum these thresholds are for.
    #[inline]
    fn holds(self, q: [f64; 3]) -> bool {
        let [a, b, c] = q.map(f64::abs);
        larger(larger(a, b), c) <= self.most && a + b + c <= self.sum
    }
}

/// Raises the maximum `worst` (never NaN) to `e` when `e` is larger, `f64::max`'s value as
/// [`larger`] takes it, and `under` with it, made for the larger of the two and `floor`.
#[inline]
fn raise(worst: &mut f64, under: &mut Under, e: f64, floor: f64) {
    if e > *worst {
        *worst = e;
        *under = Under::new(larger(e, floor));
    }
}

/// The largest error over the sample weights for `q = [Q_01, Q_12, Q_02]` (normal components).
#[inline]
fn worst_abs(q: [f64; 3]) -> f64 {
    if !(q[0].is_finite() && q[1].is_finite() && q[2].is_finite()) {
        return worst_abs_any(q);
    }
    let sample = |w: [f64; 3]| 0.5 * (w[0] * w[1] * q[0] + w[1] * w[2] * q[1] + w[0] * w[2] * q[2]);
    // At an edge midpoint two of the three products are 0 and add a signed zero, which
    // changes neither the sum nor its absolute value for finite `q`: left out.
    let [_, m01, m12, m02, ..] = WEIGHTS;
    let midpoints = [
        0.5 * (m01[0] * m01[1] * q[0]),
        0.5 * (m12[1] * m12[2] * q[1]),
        0.5 * (m02[0] * m02[2] * q[2]),
    ];
    [WEIGHTS[0], WEIGHTS[4], WEIGHTS[5], WEIGHTS[6]]
        .map(sample)
        .into_iter()
        .chain(midpoints)
        .map(f64::abs)
        .fold(0.0, larger)
}

/// [`worst_abs`] term by term over every sample weight, for any `q` (a non-finite one makes
/// some terms NaN, which the maximum skips).
fn worst_abs_any(q: [f64; 3]) -> f64 {
    WEIGHTS
        .iter()
        .map(|w| (0.5 * (w[0] * w[1] * q[0] + w[1] * w[2] * q[1] + w[0] * w[2] * q[2])).abs())
        .fold(0.0, f64::max)
}

/// One output triangle of a pattern that touches the source triangle's boundary, at one of the
/// interior points of the model's lattice nearest its corners (where its error is read). The
/// triangles of a pattern's rings repeat a few shapes, and neighbours share nearest points: a
/// model holds each (point, shape) once, touching the union of the edges its triangles touch,
/// which leaves the largest error per edge as it is and reads about a third as many.
#[derive(Debug, Clone)]
struct ModelSample {
    /// Index of the point among the lattice's interior points.
    point: u32,
    /// For the triangle's edges (corners 0–1, 1–2, 0–2) with domain vector `(d_i, d_j)`:
    /// `(d_i², d_j², d_i d_j)`.
    edges: [[f64; 3]; 3],
    /// The source triangle's edges its triangles touch (bit `k`: edge `k`).
    touches: u8,
}

/// What the error of one pattern is predicted from: its boundary triangles one by one (they
/// differ in shape), its inner lattice as a whole.
#[derive(Debug, Clone)]
pub(crate) struct PatternModel {
    key: PatternKey,
    level: u32,
    /// Ordered by the edges they touch (bit mask), those touching one edge first.
    boundary: Vec<ModelSample>,
    /// The runs of [`PatternModel::boundary`] with the same edges touched: the mask, the start
    /// and the end of its run. A run touching one edge keeps that edge's maximum in a register and
    /// needs no per-sample test of the mask, which was about half of what a check cost. In the
    /// order [`PatternModel::error_deciding`] reads them: the runs touching one edge whose count
    /// differs from the inner level first (the transition rings, where a check that fails mostly
    /// fails, so that what decides it is known early), then the other single-edge runs, then
    /// those touching two edges.
    runs: Vec<(u8, u32, u32)>,
    /// Per edge, how much the predicted error of its triangles can grow per unit of
    /// [`Curvature::spread`]: each second difference `δ_k` off by at most `s` moves
    /// `Q_e = L²(ii δ₁ + jj δ₂ + ij (δ₁ + δ₂ − δ₃))` by at most
    /// `s L² (|ii + ij| + |jj + ij| + |ij|)`, and the error by at most `WEIGHT_GAIN` times the
    /// largest of those; the largest over the triangles touching the edge.
    edge_gains: [f64; 3],
}

/// The predicted errors of one source triangle's pattern.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PatternError {
    /// Of its inner lattice.
    pub inner: f64,
    /// Of its triangles along each edge.
    pub edges: [f64; 3],
}

impl PatternError {
    /// Whether every part is at or below `tolerance`.
    pub fn within(&self, tolerance: f64) -> bool {
        self.inner <= tolerance && self.edges.iter().all(|&e| e <= tolerance)
    }
}

impl PatternModel {
    /// About the memory the model takes, in bytes (its vectors' contents and itself).
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<PatternModel>()
            + std::mem::size_of_val(&self.boundary[..])
            + std::mem::size_of_val(&self.runs[..])
    }

    /// The model of `pattern` over the second differences of a level-`level` lattice (`level`
    /// at least 3). A lattice coarser than the pattern's inner level, as the probe's, serves
    /// too: its second differences, scaled by `L²`, are the same `D²S` (exactly on a quadratic
    /// surface), read at fewer points, each the nearest to more of the pattern's corners.
    pub fn new(pattern: &Pattern, level: u32) -> PatternModel {
        let l2 = f64::from(level).powi(2);
        let mut edge_gains = [0.0f64; 3];
        let mut boundary = Vec::new();
        for t in 0..pattern.triangles.len() {
            let touches = pattern.touches(t);
            if touches == 0 {
                continue;
            }
            let corners = pattern.triangles[t].map(|p| pattern.bary(p));
            let edge = |a: usize, b: usize| {
                let (di, dj) = (corners[a][1] - corners[b][1], corners[a][2] - corners[b][2]);
                [di * di, dj * dj, di * dj]
            };
            let edges = [edge(0, 1), edge(1, 2), edge(0, 2)];
            let gain = WEIGHT_GAIN
                * edges
                    .iter()
                    .map(|&[ii, jj, ij]| {
                        l2 * ((ii + ij).abs() + (jj + ij).abs() + ij.abs()) * BOUND_SLACK
                    })
                    .fold(0.0, f64::max);
            for (k, g) in edge_gains.iter_mut().enumerate() {
                if touches & (1 << k) != 0 {
                    *g = g.max(gain);
                }
            }
            for b in corners {
                boundary.push(ModelSample {
                    point: nearest(level, b) as u32,
                    edges,
                    touches,
                });
            }
        }
        // Samples that differ only in the edges they touch merge into one whatever their order,
        // so the sort need not be stable; the point, compared first, mostly decides it.
        let same_key = |s: &ModelSample| (s.point, s.edges.map(|e| e.map(f64::to_bits)));
        boundary.sort_unstable_by(|a, b| {
            a.point
                .cmp(&b.point)
                .then_with(|| same_key(a).cmp(&same_key(b)))
        });
        boundary.dedup_by(|later, kept| {
            let same = same_key(later) == same_key(kept);
            if same {
                kept.touches |= later.touches;
            }
            same
        });
        // The maxima do not depend on the order the samples are read in (see
        // `PatternModel::error`): single edges first, so that the floors of the samples
        // touching two edges are already those edges' largest single-edge errors.
        boundary.sort_by_key(|s| (s.touches.count_ones(), s.touches));
        let mut runs: Vec<(u8, u32, u32)> = Vec::new();
        for (i, s) in boundary.iter().enumerate() {
            let i = i as u32;
            match runs.last_mut() {
                Some((mask, _, end)) if *mask == s.touches => *end = i + 1,
                _ => runs.push((s.touches, i, i + 1)),
            }
        }
        let ring = |mask: u8| {
            mask.count_ones() == 1
                && pattern.key.edges[mask.trailing_zeros() as usize] != pattern.key.inner
        };
        // Stable: the other runs keep their order, single edges before pairs.
        runs.sort_by_key(|&(mask, _, _)| !ring(mask));
        PatternModel {
            key: pattern.key,
            level,
            boundary,
            runs,
            edge_gains,
        }
    }

    /// The inner level of its pattern.
    pub fn inner(&self) -> u32 {
        self.key.inner
    }

    /// The key of its pattern.
    pub fn key(&self) -> PatternKey {
        self.key
    }

    /// An upper bound of the errors the same model predicts from any lattice whose second
    /// differences lie within `spread` of those `error` was predicted from
    /// ([`PatternModel::error`]): each part grows by at most its gain times `spread`. The inner
    /// lattice's error is `(L/m)²` times the worst over its points, each moving by at most
    /// `WEIGHT_GAIN · spread`.
    pub fn bound(&self, error: &PatternError, spread: f64) -> PatternError {
        PatternError {
            inner: error.inner + self.inner_growth(spread),
            edges: [0, 1, 2].map(|k| error.edges[k] + self.edge_gains[k] * spread),
        }
    }

    /// How much [`PatternModel::bound`] adds to the inner lattice's error for `spread`: how
    /// rough the lattice is at the scale of two steps, in the units of the error.
    pub fn inner_growth(&self, spread: f64) -> f64 {
        let scale = (f64::from(self.level) / f64::from(self.key.inner)).powi(2);
        scale * WEIGHT_GAIN * BOUND_SLACK * spread
    }

    /// The floors per edge part ([`PatternModel::error_over_each`]) under which a part's value
    /// decides nothing for a check against `tolerance` that also asks whether
    /// [`PatternModel::bound`] with `spread` is within it, the inner part's error being
    /// `inner`: the largest `f` with `f + gain · spread` at most `tolerance` in floating point
    /// (addition rounds monotonically, so every value at or below `f` passes the bound as `f`
    /// does, and passes the tolerance); the tolerance itself where the bound cannot pass
    /// whatever the edges (its inner part over the tolerance, or the spread not finite).
    pub fn skip_floors(&self, inner: f64, tolerance: f64, spread: f64) -> [f64; 3] {
        let bound = self.bound(
            &PatternError {
                inner,
                edges: [0.0; 3],
            },
            spread,
        );
        if !(spread.is_finite() && bound.inner <= tolerance) {
            return [tolerance; 3];
        }
        [0, 1, 2].map(|k| {
            let grown = self.edge_gains[k] * spread;
            let mut f = tolerance - grown;
            while f > 0.0 && f + grown > tolerance {
                // The next float down (`f` is positive and finite here).
                f = f64::from_bits(f.to_bits() - 1);
            }
            f.min(tolerance)
        })
    }

    /// The predicted errors of this pattern over the surface whose second differences are
    /// `curvature` (the lattice the model was built for).
    #[cfg(test)]
    pub fn error(&self, curvature: &mut Curvature) -> PatternError {
        self.error_over(curvature, 0.0)
    }

    /// [`PatternModel::error`] where only the parts above `floor` need their value: each edge
    /// part above `floor` is the same bits as [`PatternModel::error`]'s, one at or below it any
    /// value at most its own (the inner part is always exact). A check that only compares
    /// passing parts with `floor` and scales failing ones by their value decides the same with
    /// either. A sample whose bound is at or below `floor` is not summed: it cannot raise a part
    /// above `floor`, as one under the part's maximum so far cannot raise that maximum.
    #[cfg(test)]
    pub fn error_over(&self, curvature: &mut Curvature, floor: f64) -> PatternError {
        self.error_over_each(curvature, [floor; 3])
    }

    /// [`PatternModel::error_over`] with a floor per edge part, `floors[k]` for edge `k`'s.
    #[cfg(test)]
    pub fn error_over_each(&self, curvature: &mut Curvature, floors: [f64; 3]) -> PatternError {
        self.error_deciding(curvature, floors, f64::INFINITY, |_| ALL_EDGES)
    }

    /// [`PatternModel::error_over_each`] for a check whose caller only needs what decides its
    /// outcome: once the edge parts in `failed` are known to be over `tolerance`,
    /// `needed(failed)` names the parts whose value can still change it (bit `k`: edge `k`),
    /// and the samples of the others are not read. A part over `tolerance` is returned over
    /// it, at most its exact value; a part no longer needed at most its exact value; every
    /// other part as [`PatternModel::error_over_each`] gives it. With `needed` always all
    /// three parts, the two are the same.
    ///
    /// The runs are read in the order [`PatternModel::runs`] keeps them, the transition rings
    /// first, so that what decides a failing check is known early.
    pub fn error_deciding(
        &self,
        curvature: &mut Curvature,
        floors: [f64; 3],
        tolerance: f64,
        needed: impl Fn(u8) -> u8,
    ) -> PatternError {
        let mut out = PatternError {
            inner: curvature.inner_error(self.key.inner),
            edges: [0.0; 3],
        };
        debug_assert_eq!(
            curvature.level, self.level,
            "the model was built for this lattice"
        );
        // Each edge's error is the largest over the samples touching it, whatever their order
        // (`larger` skips NaN as a maximum does), and a sample skipped as `Under` the smallest
        // maximum it could raise (or the floor, where that is above it) is at most that: so
        // reading the samples run by run gives the plain maximum bit for bit above the floors.
        let l2 = f64::from(self.level).powi(2);
        let (mut failed, mut wanted) = (0u8, needed(0));
        for &(mask, start, end) in &self.runs {
            if wanted == 0 {
                break;
            }
            if mask & wanted == 0 {
                continue;
            }
            let run = &self.boundary[start as usize..end as usize];
            if mask.count_ones() == 1 {
                let k = mask.trailing_zeros() as usize;
                let mut worst = out.edges[k];
                let mut under = Under::new(larger(worst, floors[k]));
                for t in run {
                    let e = curvature.sample_error(t, under, l2);
                    raise(&mut worst, &mut under, e, floors[k]);
                    if e > tolerance && failed & mask == 0 {
                        failed |= mask;
                        wanted = needed(failed);
                        if wanted & mask == 0 {
                            break;
                        }
                    }
                }
                out.edges[k] = worst;
                continue;
            }
            for t in run {
                // The smallest maximum this sample could raise, or the floor of its part
                // where that is above it.
                let touched = |k: usize| {
                    if mask & (1 << k) != 0 {
                        larger(out.edges[k], floors[k])
                    } else {
                        f64::INFINITY
                    }
                };
                let below = touched(0).min(touched(1)).min(touched(2));
                let e = curvature.sample_error(t, Under::new(below), l2);
                for (k, edge) in out.edges.iter_mut().enumerate() {
                    if mask & (1 << k) != 0 {
                        *edge = larger(*edge, e);
                    }
                }
                if e > tolerance && failed & mask != mask {
                    failed |= mask;
                    wanted = needed(failed);
                    if wanted & mask == 0 {
                        break;
                    }
                }
            }
        }
        out
    }
}

/// Every edge part of a pattern (bit `k`: edge `k`).
#[cfg(test)]
const ALL_EDGES: u8 = 0b111;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{lattice_bary, lattice_len};

    /// The level-`n` lattice of the height field `z = f(x, y)` over the equilateral triangle
    /// of side `side`, with exact unit normals.
    fn height_lattice(
        n: u32,
        side: f64,
        f: impl Fn(f64, f64) -> (f64, f64, f64),
    ) -> Vec<SurfacePoint> {
        let mut points = vec![
            SurfacePoint {
                position: DVec3::ZERO,
                normal: DVec3::Z,
            };
            lattice_len(n)
        ];
        for j in 0..=n {
            for i in 0..=n - j {
                let b = lattice_bary(n, i, j);
                let (x, y) = (side * (b[1] + 0.5 * b[2]), side * 0.75f64.sqrt() * b[2]);
                let (z, fx, fy) = f(x, y);
                points[lattice_index(n, i, j)] = SurfacePoint {
                    position: DVec3::new(x, y, z),
                    normal: DVec3::new(-fx, -fy, 1.0).normalize(),
                };
            }
        }
        points
    }

    fn curvature(points: &[SurfacePoint], level: u32) -> Curvature {
        let mut c = Curvature::default();
        c.read(points, level);
        c.measure_spread(points);
        c
    }

    /// A height field: `(x, y) ↦ (z, ∂z/∂x, ∂z/∂y)`.
    type Field = Box<dyn Fn(f64, f64) -> (f64, f64, f64)>;

    /// Smooth height fields (quadratic plus quartic and oscillating terms, wavelengths from
    /// 3 to 12 triangle sides), so that the finer lattice's prediction differs from the
    /// coarser one's by the higher orders the spread allows for.
    fn smooth_fields() -> Vec<Field> {
        vec![
            Box::new(|x, y| {
                let z = 0.4 * (x * x + y * y) + 0.3 * x.powi(4);
                (z, 0.8 * x + 1.2 * x.powi(3), 0.8 * y)
            }),
            Box::new(|x, y| {
                let (kx, ky) = (2.0, 1.3);
                let z = 0.2 * (kx * x).sin() * (ky * y).cos();
                (
                    z,
                    0.2 * kx * (kx * x).cos() * (ky * y).cos(),
                    -0.2 * ky * (kx * x).sin() * (ky * y).sin(),
                )
            }),
            Box::new(|x, y| {
                let z = 0.05 * (x * x - 0.5 * y * y) + 0.02 * (x * y).powi(2);
                (z, 0.1 * x + 0.04 * x * y * y, -0.05 * y + 0.04 * x * x * y)
            }),
        ]
    }

    fn keys() -> Vec<PatternKey> {
        [
            ([8, 8, 8], 8),
            ([5, 8, 7], 8),
            ([12, 9, 10], 12),
            ([6, 6, 6], 6),
            ([9, 8, 5], 9),
        ]
        .map(|(edges, inner)| PatternKey::new(edges, inner))
        .to_vec()
    }

    /// Calls `visit` with every smooth field's lattice at each of `levels(key)` and the model
    /// of every test key's pattern over it.
    fn each_model(
        levels: impl Fn(PatternKey) -> Vec<u32>,
        mut visit: impl FnMut(PatternKey, u32, &PatternModel, &[SurfacePoint]),
    ) {
        for f in smooth_fields() {
            for key in keys() {
                let pattern = Pattern::new(key);
                for level in levels(key) {
                    let model = PatternModel::new(&pattern, level);
                    visit(key, level, &model, &height_lattice(level, 1.0, &f));
                }
            }
        }
    }

    /// What the stage-2 skip rests on: the errors a model predicts from the lattice at twice
    /// the resolution are at most [`PatternModel::bound`] of those predicted from the pattern's
    /// own lattice with its spread, on smooth surfaces; and without the spread they are not
    /// (the finer lattice does see more), so the bound is not vacuous.
    #[test]
    fn the_spread_bounds_the_check_at_twice_the_resolution() {
        let mut exceeded_without_spread = 0;
        for f in smooth_fields() {
            for key in keys() {
                let pattern = Pattern::new(key);
                let (coarse_level, fine_level) = (key.inner.max(6), 2 * key.inner);
                let mut coarse = curvature(&height_lattice(coarse_level, 1.0, &f), coarse_level);
                let mut fine = curvature(&height_lattice(fine_level, 1.0, &f), fine_level);
                let coarse_model = PatternModel::new(&pattern, coarse_level);
                let fine_model = PatternModel::new(&pattern, fine_level);
                let predicted = coarse_model.error(&mut coarse);
                let bound = coarse_model.bound(&predicted, coarse.spread());
                let finer = fine_model.error(&mut fine);
                assert!(coarse.spread().is_finite());
                assert!(
                    finer.inner <= bound.inner,
                    "{key:?}: {finer:?} over {bound:?}"
                );
                for k in 0..3 {
                    assert!(
                        finer.edges[k] <= bound.edges[k],
                        "{key:?}: {finer:?} over {bound:?}"
                    );
                    exceeded_without_spread += usize::from(finer.edges[k] > predicted.edges[k]);
                }
                exceeded_without_spread += usize::from(finer.inner > predicted.inner);
            }
        }
        assert!(exceeded_without_spread > 0, "the spread never mattered");
    }

    /// A blend band about a lattice step wide (a `tanh` ridge of width a fifth of the
    /// triangle, on a level-8 lattice) is what the check at twice the resolution exists for:
    /// its spread must be of the size of the second differences, not of the higher orders.
    #[test]
    fn a_band_about_a_step_wide_has_a_spread_of_its_curvature_size() {
        let ridge = |x: f64, y: f64| {
            let w = 0.2;
            let t = ((x - 0.45) / w).tanh();
            let dz = 0.01 * (1.0 - t * t) / w;
            (0.01 * t, dz, 0.0 * y)
        };
        let level = 8;
        let c = curvature(&height_lattice(level, 1.0, ridge), level);
        let largest =
            c.at.iter()
                .flat_map(|q| q.map(f64::abs))
                .fold(0.0, f64::max);
        assert!(
            c.spread() > 0.25 * largest,
            "{} against {largest}",
            c.spread()
        );
    }

    /// The filters of [`Curvature::lattice_error`] and [`PatternModel::error`] (points whose
    /// bound cannot change a maximum, samples shared by several triangles read once) leave the
    /// result as the plain maximum over every boundary triangle and every nearest point, bit for
    /// bit.
    #[test]
    fn the_filtered_error_is_the_plain_maximum() {
        for f in smooth_fields() {
            for key in keys() {
                let pattern = Pattern::new(key);
                for level in [key.inner.max(6), 2 * key.inner] {
                    let mut c = curvature(&height_lattice(level, 1.0, &f), level);
                    let error = PatternModel::new(&pattern, level).error(&mut c);
                    let l2 = f64::from(level).powi(2);
                    let mut plain = PatternError::default();
                    let (l, m) = (level, key.inner);
                    let mut index = 0;
                    for j in 1..l {
                        for i in 1..l - j {
                            if m == l || (i * m >= l && j * m >= l && (l - i - j) * m >= l) {
                                plain.inner = plain.inner.max(worst_abs(c.at[index]));
                            }
                            index += 1;
                        }
                    }
                    plain.inner *= (f64::from(l) / f64::from(m)).powi(2);
                    for t in 0..pattern.triangles.len() {
                        let touches = pattern.touches(t);
                        let corners = pattern.triangles[t].map(|p| pattern.bary(p));
                        let edge = |a: usize, b: usize| {
                            let (di, dj) =
                                (corners[a][1] - corners[b][1], corners[a][2] - corners[b][2]);
                            [di * di, dj * dj, di * dj]
                        };
                        let edges = [edge(0, 1), edge(1, 2), edge(0, 2)];
                        for b in corners {
                            let [d1, d2, d3] = c.at[nearest(level, b)];
                            let q = edges
                                .map(|[ii, jj, ij]| l2 * (ii * d1 + jj * d2 + ij * (d1 + d2 - d3)));
                            for k in 0..3 {
                                if touches & (1 << k) != 0 {
                                    plain.edges[k] = plain.edges[k].max(worst_abs(q));
                                }
                            }
                        }
                    }
                    assert_eq!(
                        error.inner.to_bits(),
                        plain.inner.to_bits(),
                        "{key:?} at {level}"
                    );
                    for k in 0..3 {
                        assert_eq!(
                            error.edges[k].to_bits(),
                            plain.edges[k].to_bits(),
                            "{key:?} at {level}"
                        );
                    }
                }
            }
        }
    }

    /// [`PatternModel::error_over`] gives every part above its floor with the bits of
    /// [`PatternModel::error`], and every part at or below it at most the floor, at floors
    /// between, at and around the parts' values: a check comparing with the floor decides the
    /// same, and scales a failing part by the same value.
    #[test]
    fn the_error_over_a_floor_is_exact_above_it() {
        let (mut above, mut below) = (0, 0);
        each_model(
            |key| vec![6, key.inner, 2 * key.inner],
            |key, level, model, points| {
                let exact = model.error(&mut curvature(points, level));
                let parts = exact.edges;
                let mut floors: Vec<f64> = parts.to_vec();
                for p in parts {
                    floors.extend([0.5 * p, 0.99 * p, 1.01 * p, 2.0 * p]);
                }
                for floor in floors {
                    let over = model.error_over(&mut curvature(points, level), floor);
                    assert_eq!(over.inner.to_bits(), exact.inner.to_bits());
                    for k in 0..3 {
                        if exact.edges[k] > floor {
                            above += 1;
                            assert_eq!(
                                over.edges[k].to_bits(),
                                exact.edges[k].to_bits(),
                                "{key:?} at {level}, floor {floor}"
                            );
                        } else {
                            below += 1;
                            assert!(over.edges[k] <= floor, "{key:?} at {level}");
                        }
                    }
                }
            },
        );
        assert!(above > 100 && below > 100, "{above} above, {below} below");
    }

    /// [`PatternModel::error_deciding`] keeps its contract whatever parts its caller still
    /// needs: a part known to fail comes back over the tolerance, every part at most its exact
    /// value, and a part needed to the end (always, or until it fails and never failing) with
    /// the bits of [`PatternModel::error_over_each`]; and a caller needing nothing once a part
    /// fails gets whether the check passes right.
    #[test]
    fn the_deciding_error_keeps_what_its_caller_needs() {
        let (mut failing, mut passing) = (0, 0);
        each_model(
            |key| vec![6, key.inner, 2 * key.inner],
            |key, level, model, points| {
                let exact = model.error_over_each(&mut curvature(points, level), [0.0; 3]);
                for scale in [0.5, 0.9, 1.0, 1.1, 2.0] {
                    let tolerance = scale * exact.edges.iter().fold(0.0, |a, &b| b.max(a));
                    let floors = [tolerance; 3];
                    let over = model.error_over_each(&mut curvature(points, level), floors);
                    let until_failing = model.error_deciding(
                        &mut curvature(points, level),
                        floors,
                        tolerance,
                        |failed| ALL_EDGES & !failed,
                    );
                    let until_first = model.error_deciding(
                        &mut curvature(points, level),
                        floors,
                        tolerance,
                        |failed| if failed == 0 { ALL_EDGES } else { 0 },
                    );
                    for k in 0..3 {
                        assert!(until_first.edges[k] <= exact.edges[k], "{key:?} at {level}");
                        if exact.edges[k] > tolerance {
                            failing += 1;
                            assert!(until_failing.edges[k] > tolerance, "{key:?} at {level}");
                            assert!(until_failing.edges[k] <= exact.edges[k]);
                        } else {
                            passing += 1;
                            assert_eq!(
                                until_failing.edges[k].to_bits(),
                                over.edges[k].to_bits(),
                                "{key:?} at {level}"
                            );
                        }
                    }
                    assert_eq!(
                        until_first.within(tolerance),
                        exact.within(tolerance),
                        "{key:?} at {level}, tolerance {tolerance}"
                    );
                    if exact.within(tolerance) {
                        for k in 0..3 {
                            assert_eq!(until_first.edges[k].to_bits(), over.edges[k].to_bits());
                        }
                    }
                }
            },
        );
        assert!(
            failing > 50 && passing > 50,
            "{failing} failing, {passing} passing"
        );
    }

    /// Stage 1's check decides the same with [`PatternModel::skip_floors`] as with every part
    /// exact: whether each part passes the tolerance, the value of each failing one, and
    /// whether the bound of the finer check passes; at tolerances around the parts' values,
    /// so that both outcomes of each question occur.
    #[test]
    fn the_skip_floors_decide_as_the_exact_parts() {
        let (mut skipped, mut kept) = (0, 0);
        for f in smooth_fields() {
            for key in keys() {
                let pattern = Pattern::new(key);
                let level = key.inner.max(6);
                let model = PatternModel::new(&pattern, level);
                let points = height_lattice(level, 1.0, &f);
                let mut c = curvature(&points, level);
                let exact = model.error(&mut c);
                let spread = c.spread();
                let largest = exact.edges.iter().fold(exact.inner, |a, &b| a.max(b));
                for scale in [0.5, 0.9, 1.0, 1.1, 1.5, 2.0, 4.0, 16.0] {
                    let tolerance = scale * largest;
                    let floors = model.skip_floors(exact.inner, tolerance, spread);
                    let over = model.error_over_each(&mut c, floors);
                    assert_eq!(over.within(tolerance), exact.within(tolerance));
                    for k in 0..3 {
                        if exact.edges[k] > tolerance {
                            assert_eq!(over.edges[k].to_bits(), exact.edges[k].to_bits());
                        }
                    }
                    let finer = |e: &PatternError| model.bound(e, spread).within(tolerance);
                    assert_eq!(finer(&over), finer(&exact), "{key:?} at {tolerance}");
                    if finer(&exact) {
                        skipped += 1;
                    } else {
                        kept += 1;
                    }
                }
            }
        }
        assert!(
            skipped > 10 && kept > 10,
            "{skipped} pass the bound, {kept} do not"
        );
    }

    /// The inner lattice error of an inner level at or above the lattice's, taken from the one
    /// maximum over every interior point, kept and restored, is [`Curvature::lattice_error`]'s
    /// bit for bit; below the lattice's level it is computed as before.
    #[test]
    fn the_inner_error_above_the_lattice_level_is_its_lattice_error() {
        for f in smooth_fields() {
            for level in [6, 9, 16] {
                let points = height_lattice(level, 1.0, &f);
                let plain = curvature(&points, level);
                let mut c = curvature(&points, level);
                let mut kept = Vec::new();
                for m in [level, level + 1, 17, 2 * level + 3, 4, level - 1, level + 2] {
                    let mut restored = Curvature::default();
                    if !kept.is_empty() {
                        assert!(restored.restore(level, &kept));
                        c = restored;
                    }
                    assert_eq!(
                        c.inner_error(m).to_bits(),
                        plain.lattice_error(m).to_bits(),
                        "level {level}, inner {m}"
                    );
                    kept.clear();
                    c.keep(&mut kept);
                }
            }
        }
    }

    /// The second differences [`Curvature::read`] takes row by row through windows are the
    /// plain formula's at each interior point `(i, j)`, bit for bit, and the inner error it
    /// takes in the same pass is the largest sample error over all of them.
    #[test]
    fn the_second_differences_read_are_the_plain_formula_at_every_point() {
        for f in smooth_fields() {
            for level in [3, 4, 7, 16] {
                let points = height_lattice(level, 1.0, &f);
                let mut c = Curvature::default();
                c.read(&points, level);
                let at = |i: u32, j: u32| &points[lattice_index(level, i, j)];
                let mut plain = Vec::new();
                for j in 1..level {
                    for i in 1..level - j {
                        let p = at(i, j);
                        let centre = 2.0 * p.position;
                        let along = |a: &SurfacePoint, b: &SurfacePoint| {
                            (a.position - centre + b.position).dot(p.normal)
                        };
                        plain.push([
                            along(at(i - 1, j), at(i + 1, j)),
                            along(at(i, j - 1), at(i, j + 1)),
                            along(at(i + 1, j - 1), at(i - 1, j + 1)),
                        ]);
                    }
                }
                let bits =
                    |q: &[[f64; 3]]| q.iter().map(|d| d.map(f64::to_bits)).collect::<Vec<_>>();
                assert_eq!(bits(&c.at), bits(&plain), "level {level}");
                let worst = plain.iter().map(|&q| worst_abs(q)).fold(0.0, f64::max);
                assert!(worst > 0.0, "level {level}: a curved field");
                assert_eq!(
                    c.inner_error(level).to_bits(),
                    worst.to_bits(),
                    "level {level}"
                );
            }
        }
    }

    /// `q` spread over magnitudes and signs, from a fixed-seed generator, with the cases
    /// where two or all three are equal or zero.
    fn sample_qs() -> Vec<[f64; 3]> {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let unit = (state >> 11) as f64 / (1u64 << 53) as f64;
            (2.0 * unit - 1.0) * 10f64.powi((state % 13) as i32 - 9)
        };
        let mut qs: Vec<[f64; 3]> = (0..20_000).map(|_| [next(), next(), next()]).collect();
        qs.extend([
            [1.0, 1.0, 1.0],
            [-1.0, 1.0, -1.0],
            [1.0, 0.0, 0.0],
            [0.0, -2.5e-6, 0.0],
            [0.0, 0.0, 0.0],
            [-0.0, 0.0, -0.0],
            [3e-7, 3e-7, -1e-7],
        ]);
        qs
    }

    /// The sample-by-sample maximum without its zero terms is the term-by-term one, bit for
    /// bit, so the predictions (and the counts) are those of the plain formula.
    #[test]
    fn the_worst_sample_is_the_term_by_term_maximum() {
        for q in sample_qs() {
            assert_eq!(worst_abs(q).to_bits(), worst_abs_any(q).to_bits(), "{q:?}");
        }
        for q in [
            [f64::INFINITY, 1.0, 0.0],
            [f64::NAN, 1.0, 2.0],
            [1.0, f64::NEG_INFINITY, 1.0],
        ] {
            let (a, b) = (worst_abs(q), worst_abs_any(q));
            assert!(a.to_bits() == b.to_bits(), "{q:?}: {a} against {b}");
        }
    }

    /// A point or sample [`Under`] a maximum has its error at most that maximum (else a
    /// maximum could be missed), for maxima at and around the error and at the thresholds'
    /// edge; one with a NaN or an infinite term is never under.
    #[test]
    fn what_is_under_a_maximum_cannot_raise_it() {
        let mut held = 0;
        for q in sample_qs() {
            let e = worst_abs(q);
            let [a, b, c] = q.map(f64::abs);
            let edge = (a.max(b).max(c) / 8.0).max((a + b + c) / 18.0);
            let maxima = [
                e,
                f64::from_bits(e.to_bits().saturating_sub(1)),
                e * (1.0 - 1e-13),
                e * (1.0 + 1e-13),
                edge,
                edge * BOUND_SLACK,
                edge * BOUND_SLACK * (1.0 + 1e-15),
                0.0,
            ];
            for worst in maxima {
                if Under::new(worst).holds(q) {
                    held += 1;
                    assert!(e <= worst, "{q:?}: {e} over {worst}");
                }
            }
        }
        assert!(held > 20_000, "{held} held");
        let odd = [
            [f64::INFINITY, 1.0, 0.0],
            [f64::NAN, 1.0, 2.0],
            [1.0, f64::NEG_INFINITY, f64::NAN],
            [f64::MAX, f64::MAX, 1.0],
        ];
        for q in odd {
            for worst in [0.0, 1.0, f64::MAX, f64::INFINITY] {
                assert!(!Under::new(worst).holds(q), "{q:?} under {worst}");
            }
        }
    }

    /// [`Under`] passes what the bound `max(max|Q|/8, Σ|Q|/18)` with its rounding allowance
    /// passes, which is tighter than the plain `max|Q|/6` where the three differ (else it
    /// would filter nothing more).
    #[test]
    fn what_is_under_is_what_the_bound_passes() {
        let mut tighter = 0;
        for q in sample_qs() {
            let [a, b, c] = q.map(f64::abs);
            let bound = BOUND_SLACK * (a.max(b).max(c) / 8.0).max((a + b + c) / 18.0);
            assert!(Under::new(bound * (1.0 + 1e-9)).holds(q), "{q:?}");
            assert!(
                !Under::new(bound * (1.0 - 1e-9)).holds(q) || bound == 0.0,
                "{q:?}"
            );
            if bound < 0.9 * WEIGHT_GAIN * a.max(b).max(c) {
                tighter += 1;
            }
        }
        assert!(tighter > 10_000, "tighter on {tighter} of 20,007");
    }

    /// A restored lattice gives back the inner lattice error it kept for the same inner level
    /// and computes it afresh for another level or another lattice, each bit for bit
    /// [`Curvature::lattice_error`].
    #[test]
    fn the_kept_inner_error_is_the_lattice_error_of_its_level_only() {
        let fields = smooth_fields();
        let level = 12;
        let mut c = curvature(&height_lattice(level, 1.0, &fields[0]), level);
        let first = c.inner_error(9);
        assert_eq!(first.to_bits(), c.lattice_error(9).to_bits());
        let mut kept = Vec::new();
        c.keep(&mut kept);
        let mut restored = Curvature::default();
        assert!(restored.restore(level, &kept));
        assert_eq!(restored.inner_error(9).to_bits(), first.to_bits());
        let other = restored.inner_error(6);
        assert_eq!(other.to_bits(), c.lattice_error(6).to_bits());
        assert_ne!(other.to_bits(), first.to_bits(), "levels 6 and 9 differ");
        // Another lattice read into the same storage forgets the kept value.
        let points = height_lattice(level, 1.0, &fields[1]);
        restored.read(&points, level);
        let fresh = curvature(&points, level).lattice_error(9);
        assert_ne!(fresh.to_bits(), first.to_bits(), "the fields differ");
        assert_eq!(restored.inner_error(9).to_bits(), fresh.to_bits());
    }
}
