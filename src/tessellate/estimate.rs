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
use super::transition::Pattern;
use crate::surface::{lattice_index, SurfacePoint};

/// Second differences of a level-`L` lattice at its interior points (`i, j ≥ 1`, `i + j < L`),
/// along the surface normal there, in interior lattice order: along `i`, along `j`, and along
/// `(i − 1, j + 1)`.
#[derive(Debug, Default)]
pub(crate) struct Curvature {
    level: u32,
    at: Vec<[f64; 3]>,
}

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
    /// The second differences read, in interior lattice order: what [`Curvature::restore`]
    /// takes back.
    pub fn values(&self) -> &[[f64; 3]] {
        &self.at
    }

    /// Takes back the [`Curvature::values`] of a level-`level` lattice read before, when
    /// `values` has that lattice's number of interior points (which differs from level to level);
    /// whether it did. A lattice of the same triangle and level has the same values, bit for
    /// bit, so restoring them stands for reading it again.
    pub fn restore(&mut self, level: u32, values: &[[f64; 3]]) -> bool {
        let interior = (level.saturating_sub(1) * level.saturating_sub(2) / 2) as usize;
        if level < 3 || values.len() != interior {
            return false;
        }
        self.level = level;
        self.at.clear();
        self.at.extend_from_slice(values);
        true
    }

    /// Reads the second differences of `points`, the whole level-`level` lattice (`level ≥ 3`)
    /// in lattice order; reuses its own storage.
    pub fn read(&mut self, points: &[SurfacePoint], level: u32) {
        debug_assert!(level >= 3);
        self.level = level;
        self.at.clear();
        let at = |i: u32, j: u32| points[lattice_index(level, i, j)].position;
        for j in 1..level {
            for i in 1..level - j {
                let p = &points[lattice_index(level, i, j)];
                let centre = 2.0 * p.position;
                let along = |d: DVec3| d.dot(p.normal);
                self.at.push([
                    along(at(i - 1, j) - centre + at(i + 1, j)),
                    along(at(i, j - 1) - centre + at(i, j + 1)),
                    along(at(i + 1, j - 1) - centre + at(i - 1, j + 1)),
                ]);
            }
        }
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
        let mut index = 0;
        for j in 1..l {
            for i in 1..l - j {
                if inside(i, j) {
                    worst = worst.max(worst_abs(self.at[index]));
                }
                index += 1;
            }
        }
        let scale = (f64::from(l) / f64::from(m)).powi(2);
        scale * worst
    }

    /// The predicted error of one output triangle of a model, at the second differences of
    /// the interior points nearest its corners (found when the model was built).
    fn triangle_error(&self, t: &ModelTriangle) -> f64 {
        debug_assert_eq!(t.level, self.level, "the model was built for this lattice");
        let l2 = f64::from(self.level).powi(2);
        let mut worst = 0.0f64;
        for &p in t.nearest.iter().filter(|&&p| p != u32::MAX) {
            let [d1, d2, d3] = self.at[p as usize];
            let mixed = d1 + d2 - d3;
            let q = t
                .edges
                .map(|[ii, jj, ij]| l2 * (ii * d1 + jj * d2 + ij * mixed));
            worst = worst.max(worst_abs(q));
        }
        worst
    }
}

/// The largest error over the sample weights for `q = [Q_01, Q_12, Q_02]` (normal components).
#[inline]
fn worst_abs(q: [f64; 3]) -> f64 {
    WEIGHTS
        .iter()
        .map(|w| (0.5 * (w[0] * w[1] * q[0] + w[1] * w[2] * q[1] + w[0] * w[2] * q[2])).abs())
        .fold(0.0, f64::max)
}

/// An output triangle of a pattern that touches the source triangle's boundary.
#[derive(Debug, Clone)]
struct ModelTriangle {
    /// The lattice level the model reads.
    level: u32,
    /// The interior points of that lattice nearest its corners, each once (`u32::MAX` for a
    /// repeat): where its second differences are read.
    nearest: [u32; 3],
    /// For its edges (corners 0–1, 1–2, 0–2) with domain vector `(d_i, d_j)`: `(d_i², d_j², d_i d_j)`.
    edges: [[f64; 3]; 3],
    /// The source triangle's edges it touches (bit `k`: edge `k`).
    touches: u8,
}

/// What the error of one pattern is predicted from: its boundary triangles one by one (they
/// differ in shape), its inner lattice as a whole.
#[derive(Debug, Clone)]
pub(crate) struct PatternModel {
    inner: u32,
    boundary: Vec<ModelTriangle>,
}

/// The predicted errors of one source triangle's pattern.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PatternError {
    /// Of its inner lattice.
    pub inner: f64,
    /// Of its triangles along each edge.
    pub edges: [f64; 3],
}

impl PatternModel {
    /// The model of `pattern` over the second differences of a level-`level` lattice (`level`
    /// at least 3 and at least the pattern's inner level).
    pub fn new(pattern: &Pattern, level: u32) -> PatternModel {
        let boundary = (0..pattern.triangles.len())
            .filter_map(|t| {
                let touches = pattern.touches(t);
                if touches == 0 {
                    return None;
                }
                let corners = pattern.triangles[t].map(|p| pattern.bary(p));
                let edge = |a: usize, b: usize| {
                    let (di, dj) = (corners[a][1] - corners[b][1], corners[a][2] - corners[b][2]);
                    [di * di, dj * dj, di * dj]
                };
                let mut nearest = corners.map(|b| nearest(level, b) as u32);
                for c in 1..3 {
                    if nearest[..c].contains(&nearest[c]) {
                        nearest[c] = u32::MAX;
                    }
                }
                Some(ModelTriangle {
                    level,
                    nearest,
                    edges: [edge(0, 1), edge(1, 2), edge(0, 2)],
                    touches,
                })
            })
            .collect();
        PatternModel {
            inner: pattern.key.inner,
            boundary,
        }
    }

    /// The inner level of its pattern.
    pub fn inner(&self) -> u32 {
        self.inner
    }

    /// The predicted errors of this pattern over the surface whose second differences are
    /// `curvature` (a lattice of level at least the pattern's inner level).
    pub fn error(&self, curvature: &Curvature) -> PatternError {
        let mut out = PatternError {
            inner: curvature.lattice_error(self.inner),
            edges: [0.0; 3],
        };
        for t in &self.boundary {
            let e = curvature.triangle_error(t);
            for (k, edge) in out.edges.iter_mut().enumerate() {
                if t.touches & (1 << k) != 0 {
                    *edge = edge.max(e);
                }
            }
        }
        out
    }
}
