//! Transition patterns: how one source triangle is cut when its three edges carry their own
//! segment counts and its interior a lattice level of its own.
//!
//! The pattern is the one the Direct3D 11 tessellator and OpenSubdiv's Bfr use, a regular
//! inner lattice with a stitched ring, with two changes that keep it equal to the uniform
//! lattice when all counts agree and keep its triangles well shaped when they do not:
//!
//! - the inner lattice is the interior of the level-`M` lattice (its points off the boundary),
//!   so the ring is one lattice step wide and interior points have exact lattice coordinates;
//! - a corner whose two edges both have room is cut off as an ear (the uniform lattice's corner
//!   triangle) before the ring is stitched, and the stitch picks, at every step, the candidate
//!   triangle with the larger minimum angle among those that stay outside the inner lattice.
//!
//! The edges may also be finer than the inner level (up to 1.5 times it, `counts.rs`), where
//! the interior needs less than the edges do: the same stitch joins the finer edge samples to
//! the coarser inner ring (an annulus of `P` outer and `Q` inner points takes `P + Q`
//! triangles whichever is larger, so [`PatternKey::triangle_count`] holds), around one inner
//! point at `M = 3`; at `M ≤ 2` there is no interior and the polygon of the edge samples is cut
//! by ears of largest minimum angle, which on a triangle curved along two edges and flat along
//! the third gives triangles running along the flat direction, or, where the key's `fill` names
//! one, by a triangulation chosen per source triangle by measured chord error (`fill.rs`).
//!
//! Points are numbered per pattern: the three corners, then the samples of edge 0, 1 and 2
//! (`counts[k] − 1` each, step `m` walked from corner `k + 1`), then the level-`M` interior in
//! [`LatticePart::Interior`](crate::surface::LatticePart) order. Each point also has lattice
//! coordinates `(level, i, j)`: a corner at level 1, an edge sample at its edge's count, an
//! interior point at `M`, so every output vertex is a lattice point of its own level and
//! attributes are carried exactly as for uniform levels.
//!
//! It deliberately knows no mesh and no surface: patterns depend on the counts alone and are
//! built once per distinct `(counts, M)` and shared.

use std::sync::OnceLock;

use super::lattice_edges::SampleKind;
use super::plan::LatticePlan;

/// Segment counts of the three edges (edge `k` opposite corner `k`) and the interior level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) struct PatternKey {
    /// Segments along edge `k`, at least 1.
    pub edges: [u32; 3],
    /// Level of the inner lattice. Any level from 1 to 255 gives a valid pattern; `counts.rs`
    /// keeps it at least two thirds of the largest edge count and every edge at least half of
    /// it, where the patterns' triangles are well shaped (see the tests).
    pub inner: u32,
    /// How a pattern without interior (`inner ≤ 2`) fills the polygon of its edge samples: 0,
    /// by ears of largest minimum angle in the domain; `f ≥ 1`, by triangulation `f − 1` of
    /// that polygon in the order of [`triangulation`], chosen per source triangle by measured
    /// chord error (`fill.rs`). Always 0 with an inner lattice.
    pub fill: u16,
}

impl PatternKey {
    /// The key of `edges` around `inner` with the default fill.
    #[cfg(test)]
    pub fn new(edges: [u32; 3], inner: u32) -> PatternKey {
        PatternKey {
            edges,
            inner,
            fill: 0,
        }
    }

    /// Number of triangles of the pattern, without building it: `Σe + M(M − 3)` with an inner
    /// lattice (`M ≥ 3`; `M²` when all counts equal `M`), else the `Σe − 2` triangles of a
    /// polygon with `Σe` vertices.
    pub fn triangle_count(self) -> u64 {
        let sum: u64 = self.edges.iter().map(|&e| u64::from(e)).sum();
        let m = u64::from(self.inner);
        if m >= 3 {
            sum + m * (m - 3)
        } else {
            sum - 2
        }
    }
}

/// The triangles of one source triangle for one [`PatternKey`].
#[derive(Debug, Clone)]
pub(crate) struct Pattern {
    pub key: PatternKey,
    /// Per point: lattice coordinates `(level, i, j)` (see the module docs).
    pub lattice: Vec<[u8; 3]>,
    /// First point of each edge's samples.
    pub edge_start: [u32; 3],
    /// First interior point.
    pub interior_start: u32,
    /// Interior indices in order of first use by [`Pattern::triangles`] (the order they are
    /// numbered in).
    pub interior_by_rank: Vec<u32>,
    /// Triangles as point indices, wound like the source triangle.
    pub triangles: Vec<[u32; 3]>,
    /// [`Pattern::sides`], found on first use: only the checks that measure every output
    /// triangle ask for it, on patterns of a few hundred triangles, while sorting the sides of
    /// every pattern built took more than building it.
    sides: OnceLock<Sides>,
}

/// How the output triangles of a [`Pattern`] share their sides: per triangle, bit `k` for its
/// side from corner `k` to corner `k + 1` (mod 3).
#[derive(Debug, Clone, Default)]
pub(crate) struct Sides {
    /// The side is also a side of an earlier triangle: a check measuring the triangles in
    /// order has measured its midpoint sample already (`chord.rs`).
    pub earlier: Vec<u8>,
    /// Per side `3t + k` marked in [`Sides::earlier`], the first triangle's side `3t' + k'` it
    /// is; `u32::MAX` for the others.
    pub first: Vec<u32>,
    /// Per edge of the source triangle, the sides along it (no other triangle's), as
    /// (triangle, side).
    pub along: [Vec<(u32, u8)>; 3],
}

impl Pattern {
    /// About the memory the pattern takes, in bytes (its vectors' contents and itself).
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<Pattern>()
            + std::mem::size_of_val(&self.lattice[..])
            + std::mem::size_of_val(&self.interior_by_rank[..])
            + std::mem::size_of_val(&self.triangles[..])
            // Its sides' uses (`Sides`: 13 bytes a triangle, and the sides along the edges),
            // counted before they are found, so that a store weighs the pattern once for all.
            + 14 * self.triangles.len()
    }

    /// How the output triangles share their sides.
    pub fn sides(&self) -> &Sides {
        self.sides.get_or_init(|| Sides::of(self))
    }

    /// Builds the pattern of `key`.
    ///
    /// # Panics
    /// If a count is 0 or above 255.
    pub fn new(key: PatternKey) -> Pattern {
        let PatternKey {
            edges, inner: m, ..
        } = key;
        assert!(
            edges.iter().chain([&m]).all(|&c| (1..=255).contains(&c)),
            "counts {key:?}"
        );
        let mut lattice = vec![[1, 0, 0], [1, 1, 0], [1, 0, 1]];
        let mut edge_start = [0; 3];
        for k in 0..3 {
            edge_start[k] = lattice.len() as u32;
            let e = edges[k];
            for mstep in 1..e {
                let (i, j) = edge_point(e, k, mstep);
                lattice.push([e as u8, i as u8, j as u8]);
            }
        }
        let interior_start = lattice.len() as u32;
        for j in 1..m {
            for i in 1..m.saturating_sub(j) {
                lattice.push([m as u8, i as u8, j as u8]);
            }
        }
        let mut pattern = Pattern {
            key,
            lattice,
            edge_start,
            interior_start,
            interior_by_rank: Vec::new(),
            triangles: Vec::new(),
            sides: OnceLock::new(),
        };
        if edges == [m; 3] && key.fill == 0 {
            pattern.triangles = uniform_triangles(&pattern, m);
        } else {
            pattern.triangles = stitched_triangles(&pattern);
        }
        let interior_points = pattern.lattice.len() - interior_start as usize;
        let mut ranked = vec![false; interior_points];
        for &p in pattern.triangles.iter().flatten() {
            if let Some(index) = p.checked_sub(interior_start) {
                if !std::mem::replace(&mut ranked[index as usize], true) {
                    pattern.interior_by_rank.push(index);
                }
            }
        }
        debug_assert_eq!(pattern.interior_by_rank.len(), interior_points);
        debug_assert_eq!(pattern.triangles.len() as u64, key.triangle_count());
        pattern
    }

    /// Barycentrics of point `p`.
    pub fn bary(&self, p: u32) -> [f64; 3] {
        let [n, i, j] = self.lattice[p as usize].map(f64::from);
        [(n - i - j) / n, i / n, j / n]
    }

    /// Position of point `p` in the equilateral reference triangle, where angles are judged.
    pub fn domain(&self, p: u32) -> [f64; 2] {
        domain(self.bary(p))
    }

    /// The source triangle's edges output triangle `t` touches (bit `k` for edge `k`; a corner
    /// touches both its edges): 0 for a triangle of the inner lattice.
    pub fn touches(&self, t: usize) -> u8 {
        let mut edges = 0u8;
        for &p in &self.triangles[t] {
            if p < 3 {
                edges |= (1 << ((p + 1) % 3)) | (1 << ((p + 2) % 3));
            } else if p < self.interior_start {
                // The last edge whose samples start at or before p (empty edges start where
                // the next one does).
                let k = (0..3).rev().find(|&k| p >= self.edge_start[k]).unwrap_or(0);
                edges |= 1 << k;
            }
        }
        edges
    }

    /// Point index of step `mstep` along edge `k` (walked from corner `k + 1`).
    fn edge(&self, k: usize, mstep: u32) -> u32 {
        if mstep == 0 {
            return ((k + 1) % 3) as u32;
        }
        if mstep == self.key.edges[k] {
            return ((k + 2) % 3) as u32;
        }
        self.edge_start[k] + mstep - 1
    }

    /// Point index of interior lattice point `(i, j)` of level `M`.
    fn interior(&self, i: u32, j: u32) -> u32 {
        match SampleKind::of(self.key.inner, i, j) {
            SampleKind::Interior { index } => self.interior_start + index as u32,
            other => unreachable!("({i}, {j}) is {other:?}"),
        }
    }
}

impl Sides {
    /// The sides of `pattern`'s triangles: every side once with the triangle and corner it
    /// starts at, sorted, so that equal sides are neighbours, the earliest triangle's first.
    fn of(pattern: &Pattern) -> Sides {
        let triangles = &pattern.triangles;
        let mut sides: Vec<([u32; 2], u32)> = (0..triangles.len() * 3)
            .map(|tk| {
                let corners = triangles[tk / 3];
                let (a, b) = (corners[tk % 3], corners[(tk + 1) % 3]);
                ([a.min(b), a.max(b)], tk as u32)
            })
            .collect();
        sides.sort_unstable();
        let mut uses = Sides {
            earlier: vec![0; triangles.len()],
            first: vec![u32::MAX; 3 * triangles.len()],
            along: Default::default(),
        };
        let mut run_start = 0;
        for (i, &(side, tk)) in sides.iter().enumerate() {
            let (t, k) = (tk / 3, (tk % 3) as u8);
            let before = i > 0 && sides[i - 1].0 == side;
            let after = sides.get(i + 1).is_some_and(|next| next.0 == side);
            if !before {
                run_start = i;
            }
            if before {
                uses.earlier[t as usize] |= 1 << k;
                uses.first[tk as usize] = sides[run_start].1;
            } else if !after {
                // On the edge where both ends have no weight on its opposite corner.
                let [a, b] = side.map(|p| pattern.bary(p));
                if let Some(edge) = (0..3).find(|&e| a[e] == 0.0 && b[e] == 0.0) {
                    uses.along[edge].push((t, k));
                }
            }
        }
        for along in &mut uses.along {
            along.sort_unstable();
        }
        uses
    }
}

/// Lattice coordinates of step `m` along edge `k` at level `n` (the order of
/// [`LatticePart::Edge`](crate::surface::LatticePart)).
fn edge_point(n: u32, k: usize, m: u32) -> (u32, u32) {
    match k {
        0 => (n - m, m),
        1 => (0, n - m),
        _ => (m, 0),
    }
}

/// The uniform level-`m` lattice in the plan's cache-friendly order.
fn uniform_triangles(pattern: &Pattern, m: u32) -> Vec<[u32; 3]> {
    let plan = LatticePlan::new(m);
    let point = |li: u32| {
        let [i, j] = plan.lattice_ij[li as usize].map(u32::from);
        match SampleKind::of(m, i, j) {
            SampleKind::Corner(c) => c as u32,
            SampleKind::Edge { k, m } => pattern.edge(k, m),
            SampleKind::Interior { index } => pattern.interior_start + index as u32,
        }
    };
    plan.triangles.iter().map(|t| t.map(point)).collect()
}

/// The worst minimum angle in the domain over the default patterns the balance allows,
/// `atan(√3/5)` = 19.1° (see the tests), less a rounding allowance: the floor a fill chosen by
/// measured error (`fill.rs`) keeps.
pub(crate) const ANGLE_FLOOR: f64 = 0.333_473_172_251_832_1 - 1e-9;

/// Position of barycentrics `b` in the equilateral reference triangle of side 1, where angles
/// are judged.
fn domain(b: [f64; 3]) -> [f64; 2] {
    [b[1] + 0.5 * b[2], b[2] * (0.75f64).sqrt()]
}

fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Smallest angle of triangle `abc`, in radians (0 for a degenerate one).
pub(crate) fn min_angle(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let angle = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        let u = [q[0] - p[0], q[1] - p[1]];
        let v = [r[0] - p[0], r[1] - p[1]];
        let cross = u[0] * v[1] - u[1] * v[0];
        let dot = u[0] * v[0] + u[1] * v[1];
        cross.abs().atan2(dot)
    };
    angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b))
}

/// Whether `p` lies inside or on triangle `abc` (counter-clockwise).
fn inside(p: [f64; 2], a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> bool {
    const EPS: f64 = 1e-12;
    orient(a, b, p) >= -EPS && orient(b, c, p) >= -EPS && orient(c, a, p) >= -EPS
}

/// Ears, stitched ring and inner lattice (see the module docs).
fn stitched_triangles(pattern: &Pattern) -> Vec<[u32; 3]> {
    let PatternKey {
        edges,
        inner: m,
        fill,
    } = pattern.key;
    let at = |p: u32| domain(pattern.bary(p));
    let mut triangles = Vec::with_capacity(pattern.key.triangle_count() as usize);

    // The outer ring, counter-clockwise from corner 0: edge 2 runs from corner 0 to corner 1,
    // edge 0 from 1 to 2, edge 1 from 2 to 0.
    let mut outer = Vec::new();
    for (c, k) in [(0usize, 2usize), (1, 0), (2, 1)] {
        // Corner c sits between edge (c + 1) % 3 (arriving) and edge (c + 2) % 3 (leaving).
        let (arriving, leaving) = (edges[(c + 1) % 3], edges[(c + 2) % 3]);
        let ear = m >= 3 && arriving >= 2 && leaving >= 2 && 2 * (arriving + leaving) >= 3 * m;
        if ear {
            triangles.push([
                pattern.edge((c + 1) % 3, arriving - 1),
                c as u32,
                pattern.edge((c + 2) % 3, 1),
            ]);
        } else {
            outer.push(c as u32);
        }
        outer.extend((1..edges[k]).map(|s| pattern.edge(k, s)));
    }

    if m < 3 {
        if fill == 0 {
            clip_ears(&mut outer, &at, &mut triangles);
        } else {
            let index = u32::from(fill - 1);
            assert!(
                index < triangulations(outer.len()),
                "fill {fill} of a polygon of {} points",
                outer.len()
            );
            triangles.extend(triangulation(outer.len(), index).map(|t| t.map(|v| outer[v])));
        }
        return triangles;
    }
    assert_eq!(
        fill, 0,
        "a fill needs a pattern without interior: {:?}",
        pattern.key
    );

    // The inner ring, counter-clockwise from the inner corner next to corner 0.
    let inner: Vec<u32> = if m == 3 {
        vec![pattern.interior(1, 1)]
    } else {
        let side = m - 2;
        (1..=side)
            .map(|i| (i, 1))
            .chain((2..=side).map(|j| (m - 1 - j, j)))
            .chain((2..side).rev().map(|j| (1, j)))
            .map(|(i, j)| pattern.interior(i, j))
            .collect()
    };
    stitch(&outer, &inner, &at, &mut triangles);

    if m >= 4 {
        // The inner lattice: level M − 3, shifted one step in from every edge.
        let plan = LatticePlan::new(m - 3);
        triangles.extend(plan.triangles.iter().map(|t| {
            t.map(|li| {
                let [i, j] = plan.lattice_ij[li as usize].map(u32::from);
                pattern.interior(i + 1, j + 1)
            })
        }));
    }
    triangles
}

/// Stitches the ring between two closed counter-clockwise polygons, `outer` starting at the
/// point facing `inner[0]`. At each step one of the two candidate triangles (advance along the
/// outer ring, or along the inner one) is taken: of those positively oriented, containing no
/// other ring point and whose new diagonal stays outside the inner polygon, the one with the
/// larger minimum angle.
fn stitch(outer: &[u32], inner: &[u32], at: &dyn Fn(u32) -> [f64; 2], out: &mut Vec<[u32; 3]>) {
    let (p, q) = (outer.len(), inner.len());
    let o = |i: usize| outer[i % p];
    let inn = |j: usize| inner[j % q];
    // Whether the diagonal from inner point j to `x` leaves j outside the inner polygon (for a
    // convex polygon: x is not strictly inside the cone of its two edges at j).
    let visible = |j: usize, x: [f64; 2]| {
        if q < 3 {
            return true;
        }
        let (prev, here, next) = (at(inn(j + q - 1)), at(inn(j)), at(inn(j + 1)));
        !(orient(prev, here, x) > 1e-12 && orient(here, next, x) > 1e-12)
    };
    let (mut i, mut j) = (0usize, 0usize);
    while i < p || (q > 1 && j < q) {
        let outer_step = (i < p).then(|| [o(i), o(i + 1), inn(j)]);
        let inner_step = (q > 1 && j < q).then(|| [o(i), inn(j + 1), inn(j)]);
        let score = |t: [u32; 3], other: u32, diagonal: (usize, u32)| {
            let [a, b, c] = t.map(at);
            let valid = orient(a, b, c) > 1e-12
                && !inside(at(other), a, b, c)
                && visible(diagonal.0, at(diagonal.1));
            valid.then(|| min_angle(a, b, c))
        };
        let outer_score = outer_step
            .and_then(|t| score(t, if q > 1 { inn(j + 1) } else { o(i + 2) }, (j, o(i + 1))));
        let inner_score = inner_step.and_then(|t| score(t, o(i + 1), (j + 1, o(i))));
        let take_outer = match (outer_score, inner_score) {
            (Some(a), Some(b)) => a >= b,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (None, None) => outer_step.is_some(),
        };
        if take_outer {
            out.push(outer_step.expect("an outer step remains"));
            i += 1;
        } else {
            out.push(inner_step.expect("an inner step remains"));
            j += 1;
        }
    }
}

/// Triangulates a convex polygon (points on the reference triangle's boundary, some collinear)
/// by cutting, each time, the ear with the largest minimum angle among those positively
/// oriented and holding no other vertex, not even on their new diagonal.
fn clip_ears(polygon: &mut Vec<u32>, at: &dyn Fn(u32) -> [f64; 2], out: &mut Vec<[u32; 3]>) {
    while polygon.len() >= 3 {
        let n = polygon.len();
        let best = (0..n)
            .filter_map(|v| {
                let t = [polygon[(v + n - 1) % n], polygon[v], polygon[(v + 1) % n]];
                let [a, b, c] = t.map(at);
                let empty = polygon
                    .iter()
                    .all(|&x| t.contains(&x) || !inside(at(x), a, b, c));
                (orient(a, b, c) > 1e-12 && empty).then(|| (min_angle(a, b, c), v, t))
            })
            .max_by(|x, y| x.0.total_cmp(&y.0).then(y.1.cmp(&x.1)));
        let Some((_, v, t)) = best else { break };
        out.push(t);
        polygon.remove(v);
    }
}

/// The points of the polygon a pattern without interior (`inner ≤ 2`) fills: its corners
/// and edge samples counter-clockwise from corner 0 (edge 2, edge 0, edge 1), the order
/// [`PatternKey::fill`] numbers its triangulations in.
pub(crate) fn polygon(pattern: &Pattern) -> Vec<u32> {
    assert!(pattern.key.inner < 3, "{:?} has an interior", pattern.key);
    let mut outer = Vec::new();
    for (c, k) in [(0usize, 2usize), (1, 0), (2, 1)] {
        outer.push(c as u32);
        outer.extend((1..pattern.key.edges[k]).map(|s| pattern.edge(k, s)));
    }
    outer
}

/// The Catalan numbers `C(0)` to `C(19)`, the last that fits a `u32`: `C(k + 1) = Σ C(i)·C(k − i)`.
const CATALAN: [u32; 20] = {
    let mut c = [1u32; 20];
    let mut k = 0;
    while k + 1 < c.len() {
        let mut sum = 0;
        let mut i = 0;
        while i <= k {
            sum += c[i] * c[k - i];
            i += 1;
        }
        c[k + 1] = sum;
        k += 1;
    }
    c
};

/// Number of triangulations of a convex polygon of `n` points: the Catalan number
/// `C(n − 2)` (1 for a triangle, 429 for the 9 points of edges 3, 3, 3 around no interior).
/// A table, as the fill search (`fill.rs`) asks for it twice per candidate apex.
///
/// # Panics
/// Above 21 points, whose count does not fit a `u32` (a fill has at most 9).
pub(crate) fn triangulations(n: usize) -> u32 {
    CATALAN[n.saturating_sub(2)]
}

/// Triangulation `index` of the convex polygon of points `0..n`, counter-clockwise, as
/// triangles of polygon positions: the triangle on the side `(0, n − 1)` has its apex at the
/// first `k` whose block (the triangulations of `0..=k` times those of `k..n`) holds the
/// index, the sub-polygons numbered the same way, the right one's index running fastest.
/// `fill.rs` finds a triangulation and its index by the same recursion.
pub(crate) fn triangulation(n: usize, index: u32) -> impl Iterator<Item = [usize; 3]> {
    let mut out = Vec::with_capacity(n.saturating_sub(2));
    let mut pending = vec![(0usize, n - 1, index)];
    while let Some((lo, hi, mut index)) = pending.pop() {
        if hi - lo < 2 {
            continue;
        }
        for k in lo + 1..hi {
            let right = triangulations(hi - k + 1);
            let block = triangulations(k - lo + 1) * right;
            if index < block {
                out.push([lo, k, hi]);
                pending.push((k, hi, index % right));
                pending.push((lo, k, index / right));
                break;
            }
            index -= block;
        }
    }
    out.into_iter()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Every pattern tiles the reference triangle: triangles positively oriented, their areas
    /// summing to the whole, every inner edge shared by exactly two triangles in opposite
    /// directions and every boundary segment used once; and the worst minimum angle is kept.
    fn check(key: PatternKey) -> f64 {
        let pattern = Pattern::new(key);
        let at = |p: u32| domain(pattern.bary(p));
        assert_eq!(
            pattern.triangles.len() as u64,
            key.triangle_count(),
            "{key:?}"
        );
        let mut area = 0.0;
        let mut worst = f64::MAX;
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &pattern.triangles {
            let [a, b, c] = t.map(at);
            let o = orient(a, b, c);
            assert!(o > 0.0, "{key:?}: {t:?} not positive");
            area += o / 2.0;
            worst = worst.min(min_angle(a, b, c));
            for s in 0..3 {
                *directed.entry((t[s], t[(s + 1) % 3])).or_default() += 1;
            }
        }
        let whole = (0.75f64).sqrt() / 2.0;
        assert!(
            (area - whole).abs() < 1e-12 * whole.max(1.0),
            "{key:?}: area {area}"
        );
        let boundary: usize = key.edges.iter().map(|&e| e as usize).sum();
        let mut unpaired = 0;
        for (&(a, b), &count) in &directed {
            assert_eq!(count, 1, "{key:?}: edge {a}-{b} used {count} times");
            if !directed.contains_key(&(b, a)) {
                unpaired += 1;
            }
        }
        assert_eq!(unpaired, boundary, "{key:?}: boundary segments");
        let used: std::collections::HashSet<u32> =
            pattern.triangles.iter().flatten().copied().collect();
        assert_eq!(
            used.len(),
            pattern.lattice.len(),
            "{key:?}: every point used"
        );
        worst
    }

    /// A pattern's sides: each inside side marked on every triangle after the first that has
    /// it, each side along an edge listed under that edge and nowhere marked, and an edge of
    /// `e` segments listing `e` of them, whatever the counts and fill.
    #[test]
    fn the_sides_are_found_shared_or_along_their_edge() {
        for (edges, inner, fill) in [
            ([4, 4, 4], 4, 0),
            ([5, 3, 7], 6, 0),
            ([1, 2, 3], 2, 0),
            ([3, 3, 3], 2, 17),
            ([2, 1, 1], 1, 0),
        ] {
            let pattern = Pattern::new(PatternKey { edges, inner, fill });
            let sides = pattern.sides();
            let side = |t: usize, k: usize| {
                let c = pattern.triangles[t];
                let (a, b) = (c[k], c[(k + 1) % 3]);
                [a.min(b), a.max(b)]
            };
            let what = format!("{edges:?} {inner} {fill}");
            for t in 0..pattern.triangles.len() {
                for k in 0..3 {
                    let before = (0..t).any(|u| (0..3).any(|l| side(u, l) == side(t, k)));
                    let shared = sides.earlier[t] & (1 << k) != 0;
                    assert_eq!(shared, before, "{what}: triangle {t} side {k}");
                    let first = (0..3 * t).find(|&uk| side(uk / 3, uk % 3) == side(t, k));
                    let named = sides.first[3 * t + k];
                    assert_eq!(
                        first.map(|f| f as u32),
                        (named != u32::MAX).then_some(named)
                    );
                }
            }
            for (e, along) in sides.along.iter().enumerate() {
                assert_eq!(along.len(), edges[e] as usize, "{what}: edge {e}");
                for &(t, k) in along {
                    let (t, k) = (t as usize, k as usize);
                    let on_edge = side(t, k).iter().all(|&p| pattern.bary(p)[e] == 0.0);
                    let others = (0..pattern.triangles.len())
                        .filter(|&u| (0..3).any(|l| side(u, l) == side(t, k)))
                        .count();
                    assert!(on_edge && others == 1, "{what}: edge {e} side {t}/{k}");
                }
            }
        }
    }

    #[test]
    fn uniform_counts_give_the_uniform_lattice() {
        for m in 1..=12 {
            let key = PatternKey::new([m; 3], m);
            let worst = check(key);
            assert!((worst - std::f64::consts::FRAC_PI_3).abs() < 1e-9, "{m}");
        }
    }

    #[test]
    fn every_balanced_combination_tiles_the_triangle_with_well_shaped_triangles() {
        // The combinations with M at least every edge, every edge at least ⌈M/2⌉.
        let mut worst = f64::MAX;
        for m in 1..=24u32 {
            let low = m.div_ceil(2);
            for a in low..=m {
                for b in low..=m {
                    for c in low..=m {
                        let angle = check(PatternKey::new([a, b, c], m));
                        worst = worst.min(angle);
                    }
                }
            }
        }
        // Measured: 30.00° (the uniform lattice has 60°; a sliver would be a few degrees).
        let degrees = worst.to_degrees();
        println!("worst minimum angle over balanced patterns: {degrees:.2}°");
        assert!(degrees > 29.99, "worst minimum angle {degrees}°");
    }

    #[test]
    fn edges_finer_than_the_inner_level_tile_the_triangle_with_well_shaped_triangles() {
        // The combinations `counts.rs` also produces: an inner level below the largest edge
        // count, down to two thirds of it, every edge at least half the inner level.
        let mut worst = f64::MAX;
        let mut worst_key = None;
        let mut count = 0;
        for m in 1..=12u32 {
            let low = m.div_ceil(2);
            let high = 3 * m / 2;
            for a in low..=high {
                for b in low..=high {
                    for c in low..=high {
                        let key = PatternKey::new([a, b, c], m);
                        if a.max(b).max(c) <= m
                            || crate::tessellate::counts::inner_floor(a.max(b).max(c)) > m
                        {
                            continue;
                        }
                        count += 1;
                        let angle = check(key);
                        if angle < worst {
                            (worst, worst_key) = (angle, Some(key));
                        }
                    }
                }
            }
        }
        // Measured: 19.11° = atan(√3/5), at edges 3, 3, 2 around inner level 2 (no interior:
        // the polygon of the edge samples) and wherever an edge has 1.5 times the inner
        // level's segments, the same up to inner level 20 (41,680 patterns); with edges up to
        // twice the inner level the rings hold slivers (0.2° at 32 against 16).
        let degrees = worst.to_degrees();
        println!("worst minimum angle over {count} patterns: {degrees:.2}° at {worst_key:?}");
        assert_eq!(count, 6084);
        assert!(
            degrees > (3f64.sqrt() / 5.0).atan().to_degrees() - 1e-9,
            "worst minimum angle {degrees}° at {worst_key:?}"
        );
    }

    #[test]
    fn every_fill_index_is_a_distinct_triangulation_of_the_polygon() {
        // Catalan numbers C(n − 2), and each index decodes to n − 2 triangles of the polygon's
        // points counter-clockwise, every inner diagonal shared by two of them, no two indices
        // alike.
        let counts: Vec<u32> = (3..=9).map(triangulations).collect();
        assert_eq!(counts, [1, 2, 5, 14, 42, 132, 429]);
        for n in 3..=9usize {
            let mut seen = std::collections::HashSet::new();
            for index in 0..triangulations(n) {
                let mut t: Vec<[usize; 3]> = triangulation(n, index).collect();
                assert_eq!(t.len(), n - 2, "{n} {index}");
                let mut sides: HashMap<(usize, usize), u32> = HashMap::new();
                for &[a, b, c] in &t {
                    assert!(a < b && b < c && c < n, "{n} {index}: {t:?}");
                    for side in [(a, b), (b, c), (a, c)] {
                        *sides.entry(side).or_default() += 1;
                    }
                }
                for (&(a, b), &uses) in &sides {
                    let boundary = b == a + 1 || (a == 0 && b == n - 1);
                    assert_eq!(uses, if boundary { 1 } else { 2 }, "{n} {index}: {t:?}");
                }
                t.sort_unstable();
                assert!(seen.insert(t), "{n} {index} repeats a triangulation");
            }
        }
    }

    #[test]
    fn a_fill_that_keeps_the_floor_tiles_the_triangle() {
        // Every fill of edges 3, 3, 2 around no interior whose triangles keep the floor is a
        // pattern like the default one: same points, same count, tiling the triangle.
        let key = PatternKey::new([3, 3, 2], 2);
        let base = Pattern::new(key);
        let outer = polygon(&base);
        let mut kept = 0;
        for index in 0..triangulations(outer.len()) {
            let keeps = triangulation(outer.len(), index).all(|t| {
                let [a, b, c] = t.map(|v| base.domain(outer[v]));
                min_angle(a, b, c) >= ANGLE_FLOOR
            });
            if keeps {
                kept += 1;
                let fill = u16::try_from(index + 1).unwrap();
                let worst = check(PatternKey { fill, ..key });
                assert!(worst >= ANGLE_FLOOR, "{index}");
            }
        }
        assert!(kept > 1, "{kept}");
    }

    #[test]
    fn a_triangle_flat_along_one_edge_is_filled_from_its_edge_samples() {
        // Three segments on two edges, one on the third, no interior: five triangles, none
        // with a vertex inside, each joining the two fine edges or one of them to the coarse
        // one (the polygon of 3 + 3 + 1 boundary points, not the nine of level 3).
        let key = PatternKey::new([1, 3, 3], 2);
        check(key);
        let pattern = Pattern::new(key);
        assert_eq!(pattern.triangles.len(), 5);
        assert_eq!(pattern.interior_start as usize, pattern.lattice.len());
    }
}
