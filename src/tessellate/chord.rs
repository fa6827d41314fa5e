//! Measures the chord error of a tessellation: how far the flat output triangles lie from the
//! surface they sample.
//!
//! For every output triangle, points at fixed barycentric weights `w` (centroid, edge midpoints
//! and the points halfway from the centroid to each corner) are placed on the flat triangle,
//! `X = Σ wᵢ Pᵢ`, and on the surface at the same domain point of the source triangle,
//! `S = S(Σ wᵢ λᵢ)`, with its exact unit normal `n`. The error of that sample is the distance
//! of `X` from the surface's tangent plane there, `|(X − S)·n|`; the largest is the measured
//! tolerance, reported per mesh and checked by the tests.
//!
//! # Why along the normal, not `|X − S|`
//!
//! `X − S` has a tangential part that is no distance from the surface: it only says that the
//! flat triangle's affine parametrization and the surface's differ. The G² blend's does near
//! every corner whose neighbours do not complete a parallelogram (all of them on an icosphere,
//! most of all at its valence-5 vertices): inside the corner wedge `β` depends on the direction
//! only (`t = ½(1 − 3λ_k/(2λ_near + λ_k))`, Eq. 4 on the line piece of `r(s)`), and it blends two
//! first-order maps, `b_f`'s and the extrapolated `b_g ∘ M`'s (Eq. 3, 5), that lie in the same
//! tangent plane but differ. `S` is then homogeneous of degree one in the distance from the
//! corner, to first order, and its affine interpolant is off by `O(1/n)` in the plane, not
//! `O(1/n²)`. Measured on the 5,120-triangle icosphere (`h` 0.212): `|X − S|` is 3.1e-4, 2.9e-4,
//! 1.6e-4, 8.2e-5 at levels 4, 8, 16, 32, while `|(X − S)·n|` is 7.1e-5, 1.8e-5, 4.5e-6, 1.1e-6,
//! equal to the flat points' distance from the unit sphere (the surface is within 2.1e-7 of it)
//! and falling as `1/n²`, as a chord error of a smooth surface must.
//!
//! The distance from `X` to the surface is `|(X − S)·n|` up to `½κ|X − S|²` (`κ` the largest
//! normal curvature there), second order in a difference that is itself at most the chord.
//!
//! It deliberately tessellates nothing: it reads a [`DenseMesh`] and rebuilds the patterns of
//! its counts to know which domain points its vertices came from.

use std::collections::HashMap;
use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

use super::counts::SegmentCounts;
use super::estimate::PatternError;
use super::kept_patterns::{self, Kept};
use super::pairs::joined_error;
use super::transition::{Pattern, PatternKey};
use super::DenseMesh;
use crate::surface::{LatticePart, Surface, SurfacePoint};
use crate::topology::Topology;

/// Sample weights inside each output triangle: [`WEIGHTS`]`[1 + k]` is the midpoint of the side
/// from corner `k` to corner `k + 1` (mod 3).
pub(super) const WEIGHTS: [[f64; 3]; 7] = [
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [0.5, 0.5, 0.0],
    [0.0, 0.5, 0.5],
    [0.5, 0.0, 0.5],
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
];

/// The side `k` (from corner `k` to corner `k + 1`) whose midpoint [`WEIGHTS`]`[s]` is, if it
/// is one.
fn midpoint_side(s: usize) -> Option<usize> {
    (1..=3).contains(&s).then(|| s - 1)
}

/// The index in [`WEIGHTS`] of the midpoint of side `k`: [`midpoint_side`] the other way.
fn midpoint_sample(k: u8) -> usize {
    1 + usize::from(k)
}

/// The most points a pattern may have for [`with_candidate_errors`] to keep its sides' midpoint
/// distances (a table of `n²`): a fill's polygon has at most 9.
const SHARED_MIDPOINTS_UP_TO: usize = 64;

/// The largest distance between `dense` (the output of `group` tessellated with `counts`) and
/// `surface`, sampled as the module docs say.
///
/// # Panics
/// If `dense` is not the output of `group` with `counts`.
pub fn chord_error(
    topo: &Topology,
    surface: &dyn Surface,
    counts: &SegmentCounts,
    group: Range<usize>,
    dense: &DenseMesh,
) -> f64 {
    let keys: Vec<PatternKey> = group.clone().map(|t| counts.key(topo, t)).collect();
    let mut patterns: HashMap<PatternKey, Kept<Pattern>> = HashMap::new();
    let mut first_index = Vec::with_capacity(keys.len());
    let mut total = 0usize;
    let pair_table = counts.pair_table();
    for (offset, &key) in keys.iter().enumerate() {
        first_index.push(total);
        let own = patterns
            .entry(key)
            .or_insert_with(|| kept_patterns::pattern(key))
            .triangles
            .len();
        total += 3 * (own + 2 * counts.row_points_of(&pair_table, group.start + offset));
    }
    assert_eq!(total, dense.indices.len(), "output of these counts");
    let position = |v: u32| DVec3::from(dense.positions[v as usize].map(f64::from));
    (0..keys.len())
        .into_par_iter()
        .map_init(Samples::default, |samples, offset| {
            if let Some((pair, side)) = counts.pair_of(&pair_table, group.start + offset) {
                // The pair is measured once, as a whole, by its first triangle.
                if side == 1 {
                    return 0.0;
                }
                let offsets = pair.tris.map(|t| t as usize - group.start);
                let both = offsets.map(|o| &*patterns[&keys[o]]);
                let first_share = pair.share_len(0, both[0].triangles.len());
                return joined_error(topo, surface, pair, both, |u, c| {
                    let (o, u) = if u < first_share {
                        (offsets[0], u)
                    } else {
                        (offsets[1], u - first_share)
                    };
                    position(dense.indices[first_index[o] + 3 * u + c])
                });
            }
            let pattern = &patterns[&keys[offset]];
            let indices = &dense.indices[first_index[offset]..];
            pattern_error(
                surface,
                group.start + offset,
                pattern,
                |t, c| position(indices[3 * t + c]),
                samples,
            )
        })
        .reduce(|| 0.0, f64::max)
}

/// Scratch buffers of [`pattern_error`] and [`measured_error`], kept per thread.
#[derive(Debug, Default)]
pub(crate) struct Samples {
    barys: Vec<[f64; 3]>,
    points: Vec<SurfacePoint>,
    vertices: Vec<DVec3>,
    midpoints: Vec<f64>,
    measured: Vec<(u32, u8)>,
}

impl Samples {
    /// Takes back the buffer [`written_vertices`] returned, for the next call.
    pub fn give_back(&mut self, vertices: Vec<DVec3>) {
        self.vertices = vertices;
    }
}

/// Calls `each(t, error)` with the chord error of every output triangle `t` of source triangle
/// `tri` cut by `pattern` that `selected(t)`, whose corner `c` is at `corner(t, c)`. The sample
/// points of all of them are evaluated in one call, so the surface does its per-triangle work
/// once.
fn triangle_errors(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    selected: impl Fn(usize) -> bool,
    corner: impl Fn(usize, usize) -> DVec3,
    samples: &mut Samples,
    mut each: impl FnMut(usize, f64),
) {
    samples.barys.clear();
    let chosen = (0..pattern.triangles.len()).filter(|&t| selected(t));
    for t in chosen.clone() {
        samples.barys.extend(sample_barys(pattern, t));
    }
    samples.points.clear();
    // Every sample whole, through the surface's kept weights where it keeps them (the same
    // samples for every source triangle with this pattern).
    surface.evaluate_points_positions_first(tri, &samples.barys, 0, &mut samples.points);
    for (t, on_surface) in chosen.zip(samples.points.chunks_exact(WEIGHTS.len())) {
        each(
            t,
            sampled_error([0, 1, 2].map(|c| corner(t, c)), on_surface),
        );
    }
}

/// The chord error of the output triangle with corners `flat`: the largest distance of its
/// [`WEIGHTS`] sample points from the surface's tangent planes at `on_surface`, the surface
/// points of the same domain points.
#[inline]
fn sampled_error(flat: [DVec3; 3], on_surface: &[SurfacePoint]) -> f64 {
    sampled_error_with(&WEIGHTS, flat, on_surface)
}

/// [`sampled_error`] at the samples of `weights` only.
#[inline]
fn sampled_error_with(weights: &[[f64; 3]], flat: [DVec3; 3], on_surface: &[SurfacePoint]) -> f64 {
    let mut worst = 0.0f64;
    for (w, s) in weights.iter().zip(on_surface) {
        worst = worst.max(sample_distance(w, flat, s));
    }
    worst
}

/// The distance of the sample at weights `w` of the flat triangle `flat` from the surface's
/// tangent plane at `on_surface`, the surface point of the same domain point: the one
/// expression every check sums a sample with, so a side's midpoint has the same bits in every
/// triangle that shares the side (see [`Candidate::Side`]).
#[inline]
fn sample_distance(w: &[f64; 3], flat: [DVec3; 3], on_surface: &SurfacePoint) -> f64 {
    normal_distance(w[0] * flat[0] + w[1] * flat[1] + w[2] * flat[2], on_surface)
}

/// Where an output vertex at `p` is written: its `f32` rounding, as the tessellators write it
/// (`emit.rs`). The checks measure the triangles as written, so the rounding is part of what they
/// measure, as it is of what the report measures, and no allowance for it is kept under the
/// tolerance.
#[inline]
pub(super) fn written(p: DVec3) -> DVec3 {
    p.as_vec3().as_dvec3()
}

/// The distance of `x` from the tangent plane of the surface at `s` (see the module docs).
#[inline]
pub(super) fn normal_distance(x: DVec3, s: &SurfacePoint) -> f64 {
    (x - s.position).dot(s.normal).abs()
}

/// The chord error of one source triangle cut by `pattern`, whose output triangle `t` has
/// corner `c` at `corner(t, c)`.
pub(crate) fn pattern_error(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    corner: impl Fn(usize, usize) -> DVec3,
    samples: &mut Samples,
) -> f64 {
    let mut worst = 0.0f64;
    triangle_errors(
        surface,
        tri,
        pattern,
        |_| true,
        corner,
        samples,
        |_, e| {
            worst = worst.max(e);
        },
    );
    worst
}

/// The points of source triangle `tri`'s `pattern` in the pattern's numbering (corners, each
/// edge's samples, the interior, each as the lattice parts list them), evaluated on its own
/// side into `points` (cleared first).
fn evaluate_pattern_points(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    points: &mut Vec<SurfacePoint>,
) {
    points.clear();
    surface.evaluate_points(
        tri,
        &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        points,
    );
    for k in 0..3 {
        let n = pattern.key.edges[k];
        if n > 1 {
            surface.evaluate_lattice_part(tri, n, LatticePart::Edge(k as u8), points);
        }
    }
    if pattern.key.inner >= 3 {
        surface.evaluate_lattice_part(tri, pattern.key.inner, LatticePart::Interior, points);
    }
    debug_assert_eq!(points.len(), pattern.lattice.len());
}

/// The chord error of source triangle `tri` cut by `pattern`, its vertices evaluated on its
/// own side (equal to the written ones up to rounding), by part: measured without
/// tessellating.
pub(crate) fn measured_error(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    samples: &mut Samples,
) -> PatternError {
    let vertices = written_vertices(surface, tri, pattern, samples);
    let error = if vertices.iter().all(|v| v.is_finite()) {
        errors_by_part_once(surface, tri, pattern, &vertices, samples)
    } else {
        errors_by_part(surface, tri, pattern, |_| true, &vertices, samples)
    };
    samples.vertices = vertices;
    error
}

/// [`errors_by_part`] of every output triangle, the vertices finite: each side's midpoint
/// sample is measured at the first triangle with that side and its distance read again at the
/// others (the same bits there, see [`Candidate::Side`]), so a pattern costs about 5.5 points
/// per triangle instead of 7. Each triangle's error is the largest of its samples', in another
/// order, so the same bits.
fn errors_by_part_once(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    vertices: &[DVec3],
    samples: &mut Samples,
) -> PatternError {
    let sides = pattern.sides();
    let Samples {
        barys,
        points,
        midpoints,
        measured,
        ..
    } = samples;
    barys.clear();
    measured.clear();
    for t in 0..pattern.triangles.len() {
        for (s, bary) in sample_barys(pattern, t).enumerate() {
            if midpoint_side(s).is_none_or(|k| sides.earlier[t] & (1 << k) == 0) {
                barys.push(bary);
                measured.push((t as u32, s as u8));
            }
        }
    }
    points.clear();
    // Every sample whole, through the surface's kept weights where it keeps them (the same
    // samples for every source triangle with this pattern).
    surface.evaluate_points_positions_first(tri, barys, 0, points);
    // Per side 3t + k, its midpoint's distance where triangle t measured it.
    midpoints.clear();
    midpoints.resize(3 * pattern.triangles.len(), f64::NAN);
    let mut error = PatternError::default();
    let mut at = measured.iter().zip(points.iter()).peekable();
    for (t, corners) in pattern.triangles.iter().enumerate() {
        let flat = corners.map(|p| vertices[p as usize]);
        let mut worst = 0.0f64;
        while let Some((&(_, s), point)) = at.next_if(|((u, _), _)| *u as usize == t) {
            let d = sample_distance(&WEIGHTS[s as usize], flat, point);
            if let Some(k) = midpoint_side(s as usize) {
                midpoints[3 * t + k] = d;
            }
            worst = worst.max(d);
        }
        for k in 0..3 {
            if sides.earlier[t] & (1 << k) != 0 {
                worst = worst.max(midpoints[sides.first[3 * t + k] as usize]);
            }
        }
        add_by_part(&mut error, pattern.touches(t), worst);
    }
    error
}

/// The vertices of source triangle `tri`'s `pattern` as the output writes them, evaluated on
/// its own side ([`evaluate_pattern_points`]) and rounded to `f32`, in the buffer taken from
/// `samples` (the caller gives it back, [`Samples::give_back`]). They are those of every
/// pattern with the same counts, whatever its fill: a coarsening step's checks of one triangle
/// (its default fill, the fill search, the fill chosen) evaluate them once.
pub(crate) fn written_vertices(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    samples: &mut Samples,
) -> Vec<DVec3> {
    evaluate_pattern_points(surface, tri, pattern, &mut samples.points);
    let mut vertices = std::mem::take(&mut samples.vertices);
    vertices.clear();
    vertices.extend(samples.points.iter().map(|p| written(p.position)));
    vertices
}

/// Whether [`measured_error`] of source triangle `tri` cut by `pattern` is within
/// `tolerance`, found by measuring output triangle after output triangle and stopping at the
/// first over it: a check that fails (most of those a coarsening step makes; all 15,000 on a
/// 5,000-triangle tube at 1e-4) is decided where the first failing triangle lies, there on
/// average a tenth of the way through, instead of at the end. `vertices` are the pattern's
/// points as [`written_vertices`] gives them.
///
/// Each sample is measured once: a side's midpoint at the first triangle with that side. Where
/// a step has `lowered` an edge's count, that edge's midpoints come first, one point each: its
/// curve is where such a check mostly fails (on 2CylinderEngine at a relative tolerance of
/// 2e-4, 135,000 failing checks of 3 triangles each stopped after 1.8 triangles, 13 samples).
///
/// The same answer, bit for bit: the same vertices, samples and sums (a midpoint's distance
/// has the same bits in both triangles where the vertices are finite, and where they are not
/// every sample is measured in its own triangle), and a pattern is within exactly when none of
/// its samples is over (an error that is not a number is passed over here as the maxima of
/// [`measured_error`] pass over it).
pub(crate) fn measured_within(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    vertices: &[DVec3],
    tolerance: f64,
    lowered: Option<usize>,
    samples: &mut Samples,
) -> bool {
    let sides = pattern.sides();
    // A side's midpoint sample is the same in both triangles beside it (see `Candidate::Side`):
    // measured at the first, within the tolerance there unless the check has ended.
    let earlier: &[u8] = if vertices.iter().all(|v| v.is_finite()) {
        &sides.earlier
    } else {
        &[]
    };
    let first: &[(u32, u8)] = lowered.map_or(&[], |edge| &sides.along[edge]);
    let Samples { barys, points, .. } = samples;
    let mut within = tolerance >= 0.0;
    surface.evaluate_points_on_demand(tri, &mut |evaluate| {
        // The midpoints of the sides along the lowered edge first, each as its triangle
        // measures it: where a check fails, it is mostly on that edge's curve, decided there
        // in a few points instead of whole triangles.
        barys.clear();
        for &(t, k) in first {
            barys.extend(sample_barys(pattern, t as usize).nth(midpoint_sample(k)));
        }
        points.clear();
        evaluate(barys, points);
        for (&(t, k), point) in first.iter().zip(points.iter()) {
            let flat = pattern.triangles[t as usize].map(|p| vertices[p as usize]);
            if sample_distance(&WEIGHTS[midpoint_sample(k)], flat, point) > tolerance {
                within = false;
                return;
            }
        }
        let mut weights = [[0.0; 3]; WEIGHTS.len()];
        let mut next_first = 0;
        for (t, corners) in pattern.triangles.iter().enumerate() {
            let mut measured = earlier.get(t).copied().unwrap_or(0);
            // The lowered edge's sides of this triangle (`first` is in triangle order).
            while let Some(&(_, k)) = first.get(next_first).filter(|f| f.0 as usize == t) {
                measured |= 1 << k;
                next_first += 1;
            }
            barys.clear();
            let mut count = 0;
            for (s, bary) in sample_barys(pattern, t).enumerate() {
                if midpoint_side(s).is_some_and(|k| measured & (1 << k) != 0) {
                    continue;
                }
                weights[count] = WEIGHTS[s];
                count += 1;
                barys.push(bary);
            }
            points.clear();
            evaluate(barys, points);
            let flat = corners.map(|p| vertices[p as usize]);
            if sampled_error_with(&weights[..count], flat, points) > tolerance {
                within = false;
            }
            if !within {
                return;
            }
        }
    });
    within
}

/// What [`with_candidate_errors`] measures among the points of a pattern.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Candidate {
    /// The chord error of the triangle with these corners, as [`measured_error`] measures an
    /// output triangle's: seven samples.
    Triangle([u32; 3]),
    /// The distance at the midpoint of the side between these two points alone: the sample
    /// that every triangle with this side measures there (weights ½, ½ and 0), bit for bit
    /// where the vertices are finite (the third vertex's term is then an exact zero, and the
    /// two others are summed in the same order), so a triangle's error is at least it.
    Side(u32, u32),
}

/// Calls `choose` once with a function measuring a [`Candidate`] among the points of `pattern`
/// on source triangle `tri`, at `vertices` as [`written_vertices`] gives them (the triangles
/// need not be among the pattern's own: `fill.rs` chooses among them); a candidate's samples
/// are evaluated only when it is asked for, with one set-up of the source triangle for all of
/// them ([`Surface::evaluate_points_on_demand`]).
pub(crate) fn with_candidate_errors<R>(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    vertices: &[DVec3],
    samples: &mut Samples,
    choose: impl FnOnce(&mut dyn FnMut(Candidate) -> f64) -> R,
) -> R {
    let Samples {
        barys,
        points,
        midpoints,
        ..
    } = samples;
    // Per side `[a, b]` (`a < b`), at `a·n + b`: its midpoint sample's distance once measured,
    // NaN before. Candidates share sides (each diagonal of the polygon is one of several), and
    // a side's midpoint sample has the same bits in every triangle with that side where the
    // vertices are finite (see `Candidate::Side`); kept for the small polygons of a fill.
    let n = vertices.len();
    midpoints.clear();
    if n <= SHARED_MIDPOINTS_UP_TO && vertices.iter().all(|v| v.is_finite()) {
        midpoints.resize(n * n, f64::NAN);
    }
    let slot = |t: [u32; 3], k: usize| {
        let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
        a.min(b) * n + a.max(b)
    };
    let mut choose = Some(choose);
    let mut chosen = None;
    surface.evaluate_points_on_demand(tri, &mut |evaluate| {
        let mut error_of = |candidate: Candidate| {
            // A side as the first two corners of a triangle whose third repeats the second:
            // the middle sample's weight on it is 0.
            let (t, wanted) = match candidate {
                Candidate::Triangle(t) => (t, 0..WEIGHTS.len()),
                Candidate::Side(a, b) => ([a, b, b], 1..2),
            };
            // The largest distance over the samples, in any order: the known midpoints' first.
            let mut worst = 0.0f64;
            let mut measured = [0; WEIGHTS.len()];
            let mut count = 0;
            barys.clear();
            let bary = samples_in(t.map(|p| pattern.bary(p)));
            for (s, bary) in bary.enumerate().take(wanted.end).skip(wanted.start) {
                let known = midpoint_side(s)
                    .and_then(|k| midpoints.get(slot(t, k)))
                    .filter(|d| !d.is_nan());
                match known {
                    Some(&d) => worst = worst.max(d),
                    None => {
                        measured[count] = s;
                        count += 1;
                        barys.push(bary);
                    }
                }
            }
            points.clear();
            evaluate(barys, points);
            let flat = t.map(|p| vertices[p as usize]);
            for (&s, point) in measured[..count].iter().zip(points.iter()) {
                let d = sample_distance(&WEIGHTS[s], flat, point);
                if let Some(known) = midpoint_side(s).and_then(|k| midpoints.get_mut(slot(t, k))) {
                    *known = d;
                }
                worst = worst.max(d);
            }
            worst
        };
        if let Some(choose) = choose.take() {
            chosen = Some(choose(&mut error_of));
        }
    });
    chosen.expect("the surface calls `drive` once")
}

/// The smallest angle of the triangle with corners `p`, in radians (0 if degenerate).
pub(crate) fn angle_in_space(p: [DVec3; 3]) -> f64 {
    (0..3)
        .map(|c| {
            let u = p[(c + 1) % 3] - p[c];
            let v = p[(c + 2) % 3] - p[c];
            u.cross(v).length().atan2(u.dot(v))
        })
        .fold(f64::MAX, f64::min)
}

/// Which output triangles of a pattern finer than `MEASURED_UP_TO` (`counts.rs`) the
/// refinement measures ([`boundary_error`]); the lattice model (`estimate.rs`) answers for the
/// rest.
///
/// The model reads a boundary triangle's error at the interior points nearest its corners,
/// exactly on a quadratic surface. Near a source corner those are the points one step in from
/// both edges, where the G² blend's curvature varies on the scale of the distance to the corner
/// (the corner wedge, where `β` depends on the direction only), and at the corner triangles
/// alone the output was over the tolerance at boundary triangles one to six steps from a
/// corner: at `--relative-tolerance 2e-4` Suzanne 1.64× (241 output triangles, all within 6
/// steps, most within 3), DamagedHelmet 2.61×, Pirate 1.25×, the bundled icosahedron 1.004×.
/// Measured within four steps of the corners those were within the tolerance, but PalmTree was
/// still 1.0285×, at boundary triangles 4 to 11 steps from a corner where the model at twice the
/// resolution is 3% under; measured along the whole edges, 0.9995×.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Reach {
    /// The triangles with a source corner among their vertices, where stage 1 resolved the
    /// pattern: its prediction plus what the check at twice the resolution could change of it,
    /// given how much its second differences vary from point to point (the spread bound), is
    /// within the tolerance, and the check at twice the resolution is spared. There the model
    /// holds up to the corner triangles. On the 10k icosphere at the error level 16 reaches,
    /// 9,120 of its 9,680 triangles.
    Corners,
    /// Every triangle that touches a source edge, where stage 1 did not resolve the pattern
    /// (every fine pattern of Suzanne and DamagedHelmet at 2e-4) or found its lattice rough
    /// (`counts.rs`, `ROUGH`; there the whole pattern follows once these pass). On a uniform
    /// pattern of level 17, 93 triangles and 744 surface points instead of 3 and 30.
    Edges,
}

/// Whether [`boundary_error`] measures output triangle `t` of `pattern` with `reach`.
pub(crate) fn in_reach(pattern: &Pattern, t: usize, reach: Reach) -> bool {
    match reach {
        Reach::Corners => pattern.triangles[t].iter().any(|&p| p < 3),
        Reach::Edges => pattern.touches(t) != 0,
    }
}

/// The output triangles of a pattern within a [`Reach`] and the domain points
/// [`boundary_error`] evaluates for them: the same for every source triangle with that pattern,
/// so found once per pattern instead of once per check (a pass over the pattern's triangles, a
/// sort, and the samples' weights).
#[derive(Debug)]
pub(crate) struct BoundaryTriangles {
    /// The triangles, ascending, each with the source triangle's edges it touches
    /// ([`Pattern::touches`]) and its corners as indices into the evaluated points.
    triangles: Vec<(u8, [u32; 3])>,
    /// The triangles' vertices' barycentrics (each vertex once, by ascending point), then
    /// each triangle's [`WEIGHTS`] samples, triangle after triangle.
    barys: Vec<[f64; 3]>,
}

impl BoundaryTriangles {
    /// The triangles of `pattern` within `reach`.
    pub fn new(pattern: &Pattern, reach: Reach) -> BoundaryTriangles {
        let taken: Vec<usize> = (0..pattern.triangles.len())
            .filter(|&t| in_reach(pattern, t, reach))
            .collect();
        let mut used: Vec<u32> = taken.iter().flat_map(|&t| pattern.triangles[t]).collect();
        used.sort_unstable();
        used.dedup();
        let mut barys: Vec<[f64; 3]> = used.iter().map(|&p| pattern.bary(p)).collect();
        for &t in &taken {
            barys.extend(sample_barys(pattern, t));
        }
        let triangles = taken
            .iter()
            .map(|&t| {
                let corners = pattern.triangles[t]
                    .map(|p| used.binary_search(&p).expect("every vertex is listed") as u32);
                (pattern.touches(t), corners)
            })
            .collect();
        BoundaryTriangles { triangles, barys }
    }
}

/// The domain points of the [`WEIGHTS`] samples of output triangle `t` of `pattern`.
fn sample_barys(pattern: &Pattern, t: usize) -> impl Iterator<Item = [f64; 3]> {
    samples_in(pattern.triangles[t].map(|p| pattern.bary(p)))
}

/// The domain points of the [`WEIGHTS`] samples of the domain triangle with corners `bary`.
fn samples_in(bary: [[f64; 3]; 3]) -> impl Iterator<Item = [f64; 3]> {
    WEIGHTS.into_iter().map(move |w| {
        let mut domain = [0.0; 3];
        for (c, b) in bary.iter().enumerate() {
            for (d, x) in domain.iter_mut().zip(b) {
                *d += w[c] * x;
            }
        }
        domain
    })
}

/// [`measured_error`] of the output triangles of `pattern` within a [`Reach`] only
/// (`triangles`), their vertices evaluated point by point: the part of a fine pattern the
/// lattice estimate (`estimate.rs`) cannot be trusted with. Evaluated in one call (the surface
/// sets the triangle and its neighbours up once for the vertices and the samples). The same
/// values as measuring the selected triangles with [`errors_by_part`], bit for bit: the same
/// points, weights and sums in the same order.
pub(crate) fn boundary_error(
    surface: &dyn Surface,
    tri: usize,
    triangles: &BoundaryTriangles,
    samples: &mut Samples,
) -> PatternError {
    samples.points.clear();
    // The vertices are read as positions, the samples whole.
    let on_surface_from = triangles.barys.len() - WEIGHTS.len() * triangles.triangles.len();
    surface.evaluate_points_positions_first(
        tri,
        &triangles.barys,
        on_surface_from,
        &mut samples.points,
    );
    let (vertices, on_surface) = samples.points.split_at(on_surface_from);
    let mut error = PatternError::default();
    for (&(touches, at), on_surface) in triangles
        .triangles
        .iter()
        .zip(on_surface.chunks_exact(WEIGHTS.len()))
    {
        let flat = at.map(|v| written(vertices[v as usize].position));
        add_by_part(&mut error, touches, sampled_error(flat, on_surface));
    }
    error
}

/// Adds the error `e` of an output triangle touching the source triangle's edges `touches`
/// (none: the inner lattice) to the parts' maxima.
#[inline]
fn add_by_part(error: &mut PatternError, touches: u8, e: f64) {
    if touches == 0 {
        error.inner = error.inner.max(e);
    }
    for (k, edge) in error.edges.iter_mut().enumerate() {
        if touches & (1 << k) != 0 {
            *edge = edge.max(e);
        }
    }
}

/// The chord errors of the `selected` output triangles of `pattern`, whose vertex `p` is at
/// `vertices[p]`, by part of the pattern (its inner lattice, or each edge a triangle touches).
fn errors_by_part(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    selected: impl Fn(usize) -> bool,
    vertices: &[DVec3],
    samples: &mut Samples,
) -> PatternError {
    let mut error = PatternError::default();
    triangle_errors(
        surface,
        tri,
        pattern,
        selected,
        |t, c| vertices[pattern.triangles[t][c] as usize],
        samples,
        |t, e| add_by_part(&mut error, pattern.touches(t), e),
    );
    error
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A height field over the equilateral triangle, curved differently along each direction
    /// and fastest near corner 0, so that the corner triangles' errors differ part by part.
    struct Field;

    impl Surface for Field {
        fn evaluate(&self, _tri: usize, b: [f64; 3]) -> SurfacePoint {
            let (x, y) = (b[1] + 0.5 * b[2], 0.75f64.sqrt() * b[2]);
            let z = 0.3 * (3.0 * x).sin() * (2.0 * y).cos() + 0.2 * (x * x + 0.1).sqrt();
            let zx = 0.9 * (3.0 * x).cos() * (2.0 * y).cos() + 0.2 * x / (x * x + 0.1).sqrt();
            let zy = -0.6 * (3.0 * x).sin() * (2.0 * y).sin();
            SurfacePoint {
                position: DVec3::new(x, y, z),
                normal: DVec3::new(-zx, -zy, 1.0).normalize(),
            }
        }
    }

    /// [`Field`] counting the points it evaluates, so that a check that stops early is seen to
    /// stop (through the trait's own evaluation on demand).
    struct CountingField(std::sync::atomic::AtomicUsize);

    impl Surface for CountingField {
        fn evaluate(&self, tri: usize, b: [f64; 3]) -> SurfacePoint {
            self.0.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            Field.evaluate(tri, b)
        }
    }

    /// [`measured_within`] answers as [`measured_error`]'s `within` does at every tolerance
    /// around the output triangles' own errors (each of them exactly, halfway between
    /// neighbours, below the smallest, negative), and stops evaluating samples at the first
    /// triangle over: below the largest error it evaluates fewer points than the whole check.
    #[test]
    fn the_check_that_stops_early_agrees_with_the_whole_measurement() {
        for (edges, inner) in [([6, 6, 6], 6), ([5, 3, 7], 6), ([2, 1, 2], 2)] {
            let pattern = Pattern::new(PatternKey::new(edges, inner));
            let mut samples = Samples::default();
            let mut errors = Vec::new();
            let vertices: Vec<DVec3> = (0..pattern.lattice.len() as u32)
                .map(|p| written(Field.evaluate(0, pattern.bary(p)).position))
                .collect();
            triangle_errors(
                &Field,
                0,
                &pattern,
                |_| true,
                |t, c| vertices[pattern.triangles[t][c] as usize],
                &mut samples,
                |_, e| errors.push(e),
            );
            errors.sort_by(f64::total_cmp);
            let largest = *errors.last().expect("triangles");
            assert!(errors[0] < largest, "{edges:?} {inner}: errors differ");
            let mut tolerances = vec![-1.0, 0.0, 0.5 * errors[0], 2.0 * largest];
            tolerances.extend(errors.windows(2).map(|w| 0.5 * (w[0] + w[1])));
            tolerances.extend(&errors);
            let whole = measured_error(&Field, 0, &pattern, &mut samples);
            // Its midpoints measured once, it is every triangle measured whole, part by part.
            let each = errors_by_part(&Field, 0, &pattern, |_| true, &vertices, &mut samples);
            let bits =
                |e: PatternError| [e.inner, e.edges[0], e.edges[1], e.edges[2]].map(f64::to_bits);
            assert_eq!(bits(whole), bits(each), "{edges:?} {inner}");
            let counting = CountingField(Default::default());
            let written = written_vertices(&Field, 0, &pattern, &mut samples);
            let mut within = |tolerance, lowered| {
                measured_within(
                    &counting,
                    0,
                    &pattern,
                    &written,
                    tolerance,
                    lowered,
                    &mut samples,
                )
            };
            let all_points = {
                within(2.0 * largest, None);
                counting.0.swap(0, std::sync::atomic::Ordering::Relaxed)
            };
            // Every sample once: a side inside the pattern is two triangles', its midpoint one
            // sample (the sides along the edges are the edges' segments).
            let triangles = pattern.triangles.len();
            let inside = (3 * triangles - edges.iter().sum::<u32>() as usize) / 2;
            assert_eq!(
                all_points,
                WEIGHTS.len() * triangles - inside,
                "{edges:?} {inner}"
            );
            let mut stopped_early = false;
            for tolerance in tolerances {
                for lowered in [None, Some(0), Some(1), Some(2)] {
                    let what = format!("{edges:?} {inner} at {tolerance:e}, {lowered:?} first");
                    assert_eq!(
                        within(tolerance, lowered),
                        whole.within(tolerance),
                        "{what}"
                    );
                    let evaluated = counting.0.swap(0, std::sync::atomic::Ordering::Relaxed);
                    assert!(evaluated <= all_points, "{what}");
                    stopped_early |= evaluated < all_points;
                }
            }
            assert!(stopped_early, "{edges:?} {inner}: some check stops early");
        }
    }

    /// A candidate's error is the one measured afresh, bit for bit, whichever candidates were
    /// measured before it and shared a side with it: every triangle and side of the 9 points of
    /// edges 3, 3, 3, asked for in one call in a scrambled order, against each asked for alone.
    #[test]
    fn candidate_errors_are_those_measured_afresh_in_any_order() {
        let pattern = Pattern::new(PatternKey::new([3, 3, 3], 2));
        let mut samples = Samples::default();
        let vertices = written_vertices(&Field, 0, &pattern, &mut samples);
        let n = vertices.len() as u32;
        let mut candidates = Vec::new();
        for a in 0..n {
            for b in a + 1..n {
                candidates.push(Candidate::Side(a, b));
                candidates.extend((b + 1..n).map(|c| Candidate::Triangle([a, b, c])));
            }
        }
        let mut afresh = |candidate| {
            with_candidate_errors(&Field, 0, &pattern, &vertices, &mut samples, |error_of| {
                error_of(candidate)
            })
        };
        let alone: Vec<f64> = candidates.iter().map(|&c| afresh(c)).collect();
        // Every seventh, wrapping round: sides and triangles interleaved.
        let order: Vec<usize> = (0..candidates.len())
            .map(|i| i * 7 % candidates.len())
            .collect();
        assert_ne!(candidates.len() % 7, 0, "7 is prime to the count");
        let together: Vec<f64> =
            with_candidate_errors(&Field, 0, &pattern, &vertices, &mut samples, |error_of| {
                order.iter().map(|&i| error_of(candidates[i])).collect()
            });
        for (&i, error) in order.iter().zip(together) {
            assert_eq!(error.to_bits(), alone[i].to_bits(), "{:?}", candidates[i]);
            assert!(error > 0.0, "{:?}", candidates[i]);
        }
    }

    /// The corners' reach takes the triangles with a source corner among their vertices and
    /// nothing else; the edges' every triangle with a vertex on a source edge: on the uniform
    /// pattern of level 17, 3 and 93 (by hand: per edge 17 triangles with a side on it and 16
    /// with a vertex, 3 · 33 = 99, less the 6 that touch two edges, the corner triangle and the
    /// one beside it at each corner).
    #[test]
    fn each_reach_takes_the_triangles_it_names() {
        let pattern = Pattern::new(PatternKey::new([17; 3], 17));
        let taken = |reach| {
            (0..pattern.triangles.len())
                .filter(|&t| in_reach(&pattern, t, reach))
                .collect::<Vec<_>>()
        };
        let at_corners = taken(Reach::Corners);
        assert_eq!(at_corners.len(), 3);
        assert!(at_corners
            .iter()
            .all(|&t| pattern.triangles[t].iter().any(|&p| p < 3)));
        let along_edges = taken(Reach::Edges);
        assert_eq!(along_edges.len(), 93);
        assert!(along_edges.iter().all(|&t| pattern.touches(t) != 0));
        assert!(at_corners.iter().all(|t| along_edges.contains(t)));
    }

    /// [`boundary_error`] with its triangles found once per pattern and every point evaluated
    /// in one call gives what measuring those triangles one by one gives ([`errors_by_part`] on
    /// the vertices as evaluated), bit for bit, part by part, for either reach.
    #[test]
    fn the_boundary_error_is_that_of_its_triangles_measured_one_by_one() {
        let keys = [([20, 20, 20], 20), ([17, 16, 20], 18), ([13, 9, 18], 14)];
        for ((edges, inner), reach) in keys
            .into_iter()
            .flat_map(|key| [(key, Reach::Corners), (key, Reach::Edges)])
        {
            let pattern = Pattern::new(PatternKey::new(edges, inner));
            let selected = |t: usize| in_reach(&pattern, t, reach);
            let vertices: Vec<DVec3> = (0..pattern.lattice.len() as u32)
                .map(|p| written(Field.evaluate(0, pattern.bary(p)).position))
                .collect();
            let mut samples = Samples::default();
            let plain = errors_by_part(&Field, 0, &pattern, selected, &vertices, &mut samples);
            let triangles = BoundaryTriangles::new(&pattern, reach);
            let fast = boundary_error(&Field, 0, &triangles, &mut samples);
            let bits =
                |e: PatternError| [e.inner, e.edges[0], e.edges[1], e.edges[2]].map(f64::to_bits);
            assert_eq!(bits(fast), bits(plain), "{edges:?} {inner} {reach:?}");
            // Not vacuous: every edge's measured triangles have an error.
            assert!(plain.edges.iter().all(|&e| e > 0.0), "{plain:?}");
        }
    }
}
