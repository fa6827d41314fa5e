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
use super::transition::{Pattern, PatternKey};
use super::DenseMesh;
use crate::surface::{LatticePart, Surface, SurfacePoint};
use crate::topology::Topology;

/// Sample weights inside each output triangle.
pub(super) const WEIGHTS: [[f64; 3]; 7] = [
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [0.5, 0.5, 0.0],
    [0.0, 0.5, 0.5],
    [0.5, 0.0, 0.5],
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
];

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
    let mut patterns: HashMap<PatternKey, Pattern> = HashMap::new();
    let mut first_index = Vec::with_capacity(keys.len());
    let mut total = 0usize;
    for &key in &keys {
        first_index.push(total);
        total += 3 * patterns
            .entry(key)
            .or_insert_with(|| Pattern::new(key))
            .triangles
            .len();
    }
    assert_eq!(total, dense.indices.len(), "output of these counts");
    let position = |v: u32| DVec3::from(dense.positions[v as usize].map(f64::from));
    (0..keys.len())
        .into_par_iter()
        .map_init(Samples::default, |samples, offset| {
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
        let bary = pattern.triangles[t].map(|p| pattern.bary(p));
        for w in WEIGHTS {
            let mut domain = [0.0; 3];
            for (c, b) in bary.iter().enumerate() {
                for (d, x) in domain.iter_mut().zip(b) {
                    *d += w[c] * x;
                }
            }
            samples.barys.push(domain);
        }
    }
    samples.points.clear();
    surface.evaluate_points(tri, &samples.barys, &mut samples.points);
    for (t, on_surface) in chosen.zip(samples.points.chunks_exact(WEIGHTS.len())) {
        let flat = [0, 1, 2].map(|c| corner(t, c));
        let mut worst = 0.0f64;
        for (w, s) in WEIGHTS.iter().zip(on_surface) {
            let on_flat = w[0] * flat[0] + w[1] * flat[1] + w[2] * flat[2];
            worst = worst.max(normal_distance(on_flat, s));
        }
        each(t, worst);
    }
}

/// Where an output vertex at `p` is written: its `f32` rounding, as the tessellators write it
/// (`emit.rs`). The checks measure the triangles as written, so the rounding is part of what they
/// measure, as it is of what the report measures, and no allowance for it is kept under the
/// tolerance.
#[inline]
fn written(p: DVec3) -> DVec3 {
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

/// The chord error of source triangle `tri` cut by `pattern`, its vertices evaluated on its
/// own side (equal to the written ones up to rounding), by part: measured without
/// tessellating.
pub(crate) fn measured_error(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    samples: &mut Samples,
) -> PatternError {
    // The pattern's points in its numbering: corners, each edge's samples, the interior, each
    // as the lattice parts list them.
    samples.points.clear();
    surface.evaluate_points(
        tri,
        &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        &mut samples.points,
    );
    for k in 0..3 {
        let n = pattern.key.edges[k];
        if n > 1 {
            surface.evaluate_lattice_part(tri, n, LatticePart::Edge(k as u8), &mut samples.points);
        }
    }
    if pattern.key.inner >= 3 {
        surface.evaluate_lattice_part(
            tri,
            pattern.key.inner,
            LatticePart::Interior,
            &mut samples.points,
        );
    }
    debug_assert_eq!(samples.points.len(), pattern.lattice.len());
    let mut vertices = std::mem::take(&mut samples.vertices);
    vertices.clear();
    vertices.extend(samples.points.iter().map(|p| written(p.position)));
    let error = errors_by_part(surface, tri, pattern, |_| true, &vertices, samples);
    samples.vertices = vertices;
    error
}

/// [`measured_error`] of the output triangles at the source triangle's corners only (those
/// with a corner among their vertices), their vertices evaluated point by point: the part of a
/// pattern the lattice estimate (`estimate.rs`) cannot see, because the G² blend's curvature
/// near a vertex varies on the scale of the distance to it (the corner wedge, where `β` depends
/// on the direction only), so the second differences one lattice step in miss it. About 21
/// surface points per source triangle, whatever its counts.
pub(crate) fn corner_error(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    samples: &mut Samples,
) -> PatternError {
    let at_corner = |t: usize| pattern.triangles[t].iter().any(|&p| p < 3);
    let mut used: Vec<u32> = (0..pattern.triangles.len())
        .filter(|&t| at_corner(t))
        .flat_map(|t| pattern.triangles[t])
        .collect();
    used.sort_unstable();
    used.dedup();
    samples.barys.clear();
    samples.barys.extend(used.iter().map(|&p| pattern.bary(p)));
    samples.points.clear();
    surface.evaluate_points(tri, &samples.barys, &mut samples.points);
    let mut vertices = std::mem::take(&mut samples.vertices);
    vertices.clear();
    vertices.resize(pattern.lattice.len(), DVec3::ZERO);
    for (&p, s) in used.iter().zip(&samples.points) {
        vertices[p as usize] = written(s.position);
    }
    let error = errors_by_part(surface, tri, pattern, at_corner, &vertices, samples);
    samples.vertices = vertices;
    error
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
        |t, e| {
            let touches = pattern.touches(t);
            if touches == 0 {
                error.inner = error.inner.max(e);
            }
            for (k, edge) in error.edges.iter_mut().enumerate() {
                if touches & (1 << k) != 0 {
                    *edge = edge.max(e);
                }
            }
        },
    );
    error
}
