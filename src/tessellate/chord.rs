//! Measures the chord error of a tessellation: how far the flat output triangles lie from the
//! surface they sample.
//!
//! For every output triangle, points at fixed barycentric weights `w` (centroid, edge midpoints
//! and the points halfway from the centroid to each corner) are placed on the flat triangle,
//! `Σ wᵢ Pᵢ`, and on the surface at the same domain point of the source triangle,
//! `S(Σ wᵢ λᵢ)`; their distance bounds the distance from the flat point to the surface from
//! above. The largest is the measured tolerance, reported per mesh and checked by the tests.
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
/// `tri` cut by `pattern`, whose corner `c` is at `corner(t, c)`. The sample points of all of
/// them are evaluated in one call, so the surface does its per-triangle work once.
fn triangle_errors(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    corner: impl Fn(usize, usize) -> DVec3,
    samples: &mut Samples,
    mut each: impl FnMut(usize, f64),
) {
    samples.barys.clear();
    for points in &pattern.triangles {
        let bary = points.map(|p| pattern.bary(p));
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
    for (t, on_surface) in samples.points.chunks_exact(WEIGHTS.len()).enumerate() {
        let flat = [0, 1, 2].map(|c| corner(t, c));
        let mut worst = 0.0f64;
        for (w, s) in WEIGHTS.iter().zip(on_surface) {
            let on_flat = w[0] * flat[0] + w[1] * flat[1] + w[2] * flat[2];
            worst = worst.max(s.position.distance(on_flat));
        }
        each(t, worst);
    }
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
    triangle_errors(surface, tri, pattern, corner, samples, |_, e| {
        worst = worst.max(e);
    });
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
    vertices.extend(samples.points.iter().map(|p| p.position));
    let mut error = PatternError::default();
    triangle_errors(
        surface,
        tri,
        pattern,
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
    samples.vertices = vertices;
    error
}
