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
use super::transition::{Pattern, PatternKey};
use super::DenseMesh;
use crate::surface::Surface;
use crate::topology::Topology;

/// Sample weights inside each output triangle.
const WEIGHTS: [[f64; 3]; 7] = [
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
        .map(|offset| {
            let pattern = &patterns[&keys[offset]];
            let indices = &dense.indices[first_index[offset]..];
            pattern_error(surface, group.start + offset, pattern, |t, c| {
                position(indices[3 * t + c])
            })
        })
        .reduce(|| 0.0, f64::max)
}

/// The chord error of one source triangle cut by `pattern`, whose output triangle `t` has
/// corner `c` at `corner(t, c)`.
pub(crate) fn pattern_error(
    surface: &dyn Surface,
    tri: usize,
    pattern: &Pattern,
    corner: impl Fn(usize, usize) -> DVec3,
) -> f64 {
    let mut worst = 0.0f64;
    for (t, points) in pattern.triangles.iter().enumerate() {
        let bary = points.map(|p| pattern.bary(p));
        let flat = [0, 1, 2].map(|c| corner(t, c));
        for w in WEIGHTS {
            let mut domain = [0.0; 3];
            for (c, b) in bary.iter().enumerate() {
                for (d, x) in domain.iter_mut().zip(b) {
                    *d += w[c] * x;
                }
            }
            let on_surface = surface.evaluate(tri, domain).position;
            let on_flat = w[0] * flat[0] + w[1] * flat[1] + w[2] * flat[2];
            worst = worst.max(on_surface.distance(on_flat));
        }
    }
    worst
}

/// The chord error of source triangle `tri` cut by `pattern`, its vertices evaluated on its
/// own side (equal to the written ones up to rounding): measured without tessellating.
pub(crate) fn predicted_error(surface: &dyn Surface, tri: usize, pattern: &Pattern) -> f64 {
    let vertices: Vec<DVec3> = (0..pattern.lattice.len() as u32)
        .map(|p| surface.evaluate(tri, pattern.bary(p)).position)
        .collect();
    pattern_error(surface, tri, pattern, |t, c| {
        vertices[pattern.triangles[t][c] as usize]
    })
}
