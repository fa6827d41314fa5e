//! Continuity across mesh edges, measured: for every interior edge, the position gap and the
//! normal-angle jump between the two sides at the edge, and the jump in cross-edge normal
//! curvature between points at distance `eps` on either side.
//!
//! It deliberately judges nothing (no thresholds) and knows nothing of how a surface is built: it
//! samples any [`Surface`] through [`Surface::evaluate`].
//!
//! Distances are in the domain metric of the paper (barycentrics as points of R³: the reference
//! triangle is equilateral with side √2), so `eps` means the same on every triangle.
//! Lengths are reported relative to the mean edge length `L`: gaps as a fraction of `L`,
//! curvature jumps as `|κ_f − κ_g|·L` (dimensionless).

use glam::DVec3;

use crate::surface::blend::map_point;
use crate::surface::Surface;
use crate::topology::{EdgeKind, Topology, TriId};

/// Largest and 95th-percentile value of a set of samples (0 for no samples).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stat {
    pub max: f64,
    pub p95: f64,
}

impl Stat {
    /// Statistics of `v` (reordered in place). NaN counts as the largest value.
    pub fn of(v: &mut [f64]) -> Stat {
        if v.is_empty() {
            return Stat::default();
        }
        // A NaN (a broken evaluation) must show, so it sorts above every number.
        v.sort_by(|a, b| match (a.is_nan(), b.is_nan()) {
            (false, false) => a.total_cmp(b),
            (x, y) => x.cmp(&y),
        });
        let rank = ((0.95 * v.len() as f64).ceil() as usize).clamp(1, v.len());
        Stat {
            max: v[v.len() - 1],
            p95: v[rank - 1],
        }
    }
}

/// The curvature jump at one distance from the edges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvatureJump {
    /// Distance from the edge on each side, in the domain metric.
    pub eps: f64,
    /// `|κ_f − κ_g|·L` over all samples.
    pub jump: Stat,
}

/// Where to sample.
#[derive(Debug, Clone, PartialEq)]
pub struct Sampling {
    /// Distances from the edge for the curvature jump. Default `[1e-2, 1e-3, 1e-4]`.
    pub eps: Vec<f64>,
    /// Samples per edge, evenly spaced. Default 9.
    pub per_edge: usize,
    /// Fraction of the edge left out at each end (near vertices curvature varies on the scale of
    /// the distance to the vertex, so fixed-step estimates do not converge). Default 0.1.
    pub margin: f64,
}

impl Default for Sampling {
    fn default() -> Self {
        Sampling {
            eps: vec![1e-2, 1e-3, 1e-4],
            per_edge: 9,
            margin: 0.1,
        }
    }
}

/// Measured continuity over the interior edges of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuityReport {
    /// Interior edges measured.
    pub edges: usize,
    /// Samples per measure (edges × samples per edge).
    pub samples: usize,
    /// Mean length of the welded edges, `L`.
    pub mean_edge_length: f64,
    /// `|S_f − S_g| / L` at edge points evaluated from both sides.
    pub gap: Stat,
    /// Angle between the two sides' normals at edge points, in degrees.
    pub normal_jump_deg: Stat,
    /// Cross-edge normal-curvature jump, one entry per [`Sampling::eps`].
    pub curvature_jump: Vec<CurvatureJump>,
}

/// Measures `surface` across every interior edge of `topo`.
pub fn measure(surface: &dyn Surface, topo: &Topology, sampling: &Sampling) -> ContinuityReport {
    let mean_edge_length = mean_edge_length(topo);
    let (mut gaps, mut angles) = (Vec::new(), Vec::new());
    let mut curv: Vec<Vec<f64>> = vec![Vec::new(); sampling.eps.len()];
    let mut edges = 0;
    for edge in topo.edges().filter(|e| e.kind == EdgeKind::Interior) {
        edges += 1;
        let (f, k) = edge.tris[0].at();
        let n = topo
            .neighbour(TriId(f as u32), k)
            .expect("interior edges have a neighbour");
        let (g, slots) = (n.tri.0 as usize, n.slots.map(usize::from));
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        // Unit cross-edge direction into f (domain metric: |e_k − (e_i + e_j)/2| = √(3/2)).
        let mut dir = [0.0; 3];
        dir[k] = 1.0;
        dir[i] = -0.5;
        dir[j] = -0.5;
        let dir = dir.map(|x| x / 1.5f64.sqrt());
        let dir_g = map_point(k, slots, dir);
        for m in 0..sampling.per_edge {
            let x = if sampling.per_edge == 1 {
                0.5
            } else {
                let span = 1.0 - 2.0 * sampling.margin;
                sampling.margin + span * m as f64 / (sampling.per_edge - 1) as f64
            };
            let mut on_edge = [0.0; 3];
            on_edge[i] = 1.0 - x;
            on_edge[j] = x;
            let a = surface.evaluate(f, on_edge);
            let b = surface.evaluate(g, map_point(k, slots, on_edge));
            gaps.push((a.position - b.position).length() / mean_edge_length);
            angles.push(angle_deg(a.normal, b.normal));
            for (e, out) in sampling.eps.iter().zip(&mut curv) {
                let at = |s: f64| std::array::from_fn(|c| on_edge[c] + s * dir[c]);
                let step = 0.25 * e;
                let kf = normal_curvature(surface, f, at(*e), dir, step);
                let kg = normal_curvature(surface, g, map_point(k, slots, at(-e)), dir_g, step);
                out.push((kf - kg).abs() * mean_edge_length);
            }
        }
    }
    ContinuityReport {
        edges,
        samples: gaps.len(),
        mean_edge_length,
        gap: Stat::of(&mut gaps),
        normal_jump_deg: Stat::of(&mut angles),
        curvature_jump: sampling
            .eps
            .iter()
            .zip(&mut curv)
            .map(|(&eps, v)| CurvatureJump {
                eps,
                jump: Stat::of(v),
            })
            .collect(),
    }
}

/// Normal curvature of `surface` at `bary` of `tri` along the domain direction `dir` (a
/// barycentric vector, sum 0), from the surface's own unit normals by the Weingarten relation:
/// `κ = −(N₊ − N₋)·(S₊ − S₋) / |S₊ − S₋|²` with `±` at `bary ± step·dir`.
///
/// Differencing the exact normals once instead of positions twice keeps the rounding error at
/// about `ε/step` rather than `ε/step²`, so `eps = 1e-4` still resolves 1e-9 relative curvature.
/// The stencil must stay inside the triangle.
pub fn normal_curvature(
    surface: &dyn Surface,
    tri: usize,
    bary: [f64; 3],
    dir: [f64; 3],
    step: f64,
) -> f64 {
    let at = |s: f64| surface.evaluate(tri, std::array::from_fn(|c| bary[c] + s * dir[c]));
    let (minus, plus) = (at(-step), at(step));
    let ds = plus.position - minus.position;
    -(plus.normal - minus.normal).dot(ds) / ds.length_squared()
}

/// Angle between two vectors in degrees, accurate for tiny angles (atan2, not acos).
pub fn angle_deg(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

/// Mean length of the welded edges with two distinct end points.
pub fn mean_edge_length(topo: &Topology) -> f64 {
    let lengths: Vec<f64> = topo
        .edges()
        .filter(|e| e.verts[0] != e.verts[1])
        .map(|e| {
            let [a, b] = e.verts.map(|v| topo.welded_positions[v.0 as usize]);
            (a - b).length()
        })
        .collect();
    if lengths.is_empty() {
        return 1.0;
    }
    lengths.iter().sum::<f64>() / lengths.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stat_is_max_and_nearest_rank_p95_with_nan_on_top() {
        let mut v: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        assert_eq!(
            Stat::of(&mut v),
            Stat {
                max: 100.0,
                p95: 95.0
            }
        );
        let mut v = vec![1.0, -f64::NAN, 2.0];
        assert!(Stat::of(&mut v).max.is_nan());
    }

    #[test]
    fn angle_is_accurate_for_tiny_angles() {
        let a = DVec3::X;
        let b = DVec3::new(1.0, 1e-12, 0.0).normalize();
        assert!((angle_deg(a, b) - 1e-12f64.to_degrees()).abs() < 1e-24);
    }
}
