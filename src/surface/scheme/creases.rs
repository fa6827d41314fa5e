//! What the hybrid and Coons schemes share about a mesh: which edges are smooth, each triangle's
//! corner data, and its own PN net with crease curves that both sides of an edge agree on.
//!
//! It deliberately builds no smooth surface: it only fixes the data both constructions start
//! from, so that they are watertight in the same way.

use glam::DVec3;

use crate::mesh::TriMesh;
use crate::sharpness::EffectiveH;
use crate::surface::pn::{central_point, pn_net, Net, B111, NEAR};
use crate::surface::SurfacePoint;
use crate::topology::Topology;

/// Input corner positions and normalized input normals of one triangle (a zero normal falls back
/// to the face normal, a degenerate face to +z).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corners {
    pub position: [DVec3; 3],
    pub normal: [DVec3; 3],
}

impl Corners {
    /// Corner data of triangle `t` of `mesh`.
    pub fn of(mesh: &TriMesh, t: usize) -> Corners {
        let tri = mesh.triangles[t];
        let position = tri.map(|c| mesh.positions[c as usize]);
        let face = (position[1] - position[0])
            .cross(position[2] - position[0])
            .normalize_or(DVec3::Z);
        Corners {
            position,
            normal: tri.map(|c| mesh.normals[c as usize].normalize_or(face)),
        }
    }

    /// The exact corner point when `l` is a unit vector.
    pub fn at_corner(&self, l: [f64; 3]) -> Option<SurfacePoint> {
        let c = (0..3).find(|&c| l[c] == 1.0 && l[(c + 1) % 3] == 0.0 && l[(c + 2) % 3] == 0.0)?;
        Some(SurfacePoint {
            position: self.position[c],
            normal: self.normal[c],
        })
    }

    /// The unit normal of tangents `du × dv`, on the side of the interpolated input normals;
    /// the interpolated normal itself where the tangents are parallel to rounding. (Triangles
    /// of a smooth edge with split normals choose by the normals their edge nets share
    /// instead: [`EdgeNormals`](super::side::EdgeNormals).)
    pub fn orient(&self, l: [f64; 3], du: DVec3, dv: DVec3) -> DVec3 {
        let interpolated = l[0] * self.normal[0] + l[1] * self.normal[1] + l[2] * self.normal[2];
        Self::orient_to(interpolated, self.normal[0], du, dv)
    }

    /// The unit normal of tangents `du × dv`, on the side of `reference`; `reference` itself
    /// (normalized, else `fallback`) where the tangents are parallel to rounding
    /// (`|du × dv| ≤ 1e-14·|du|·|dv|`, a degenerate triangle).
    #[inline]
    pub fn orient_to(reference: DVec3, fallback: DVec3, du: DVec3, dv: DVec3) -> DVec3 {
        let n = du.cross(dv);
        let len2 = n.length_squared();
        if len2 > 1e-28 * du.length_squared() * dv.length_squared() && len2.is_finite() {
            let n = n / len2.sqrt();
            if n.dot(reference) < 0.0 {
                -n
            } else {
                n
            }
        } else {
            reference.normalize_or(fallback)
        }
    }
}

/// Which edges are smooth: those the one rule ([`EffectiveH`]) gave a width above 0, that is
/// interior edges asked for `h > 0`; every other edge is a crease.
pub fn smooth_edges(h: &EffectiveH) -> Vec<bool> {
    h.iter().map(|&h| h > 0.0).collect()
}

/// Each triangle's PN net (seed 000 Eq. 2, all six edge points in `E`), with one boundary curve
/// per edge that is not `smooth`, so that creases are watertight.
///
/// Where the triangles of a crease disagree on an end normal (split normals), the edge control
/// point next to that end follows the crease line `d = N_f × N_g`, the intersection of both
/// tangent planes: `b(A→B) = A + d (d·(B−A)) / (3|d|²)`. It lies in both tangent planes, so each
/// side stays tangent to its own input normal at A. With more than two triangles (or parallel
/// normals) the points are averaged instead (PN-AEN). `b111` follows from the new edge points.
pub fn own_nets(corners: &[Corners], topo: &Topology, smooth: &[bool]) -> Vec<Net> {
    let mut nets: Vec<Net> = corners
        .iter()
        .map(|c| pn_net(c.position, c.normal))
        .collect();
    let mut touched = vec![false; nets.len()];
    for (edge, &smooth) in topo.edges().zip(smooth) {
        if smooth || edge.tris.len() < 2 || edge.verts[0] == edge.verts[1] {
            continue;
        }
        // Per use: triangle, local corner at verts[0] and at verts[1].
        let uses: Vec<(usize, [usize; 2])> = edge
            .tris
            .iter()
            .map(|u| {
                let (t, k) = u.at();
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                if topo.tri_verts[t][i] == edge.verts[0] {
                    (t, [i, j])
                } else {
                    (t, [j, i])
                }
            })
            .collect();
        for end in 0..2 {
            let (a, b) = (end, 1 - end);
            let point = |&(t, c): &(usize, [usize; 2])| nets[t][NEAR[c[a]][c[b]]];
            let first = point(&uses[0]);
            if uses.iter().all(|u| point(u) == first) {
                continue;
            }
            let shared = crease_point(corners, &uses, a, b)
                .unwrap_or_else(|| uses.iter().map(point).sum::<DVec3>() / uses.len() as f64);
            for &(t, c) in &uses {
                nets[t][NEAR[c[a]][c[b]]] = shared;
                touched[t] = true;
            }
        }
    }
    for (net, touched) in nets.iter_mut().zip(touched) {
        if touched {
            net[B111] = central_point(net);
        }
    }
    nets
}

/// The crease-line edge point next to end `a` (towards end `b`) for exactly two uses.
fn crease_point(
    corners: &[Corners],
    uses: &[(usize, [usize; 2])],
    a: usize,
    b: usize,
) -> Option<DVec3> {
    let [(f, cf), (g, cg)] = uses else {
        return None;
    };
    let pa = corners[*f].position[cf[a]];
    let pb = corners[*f].position[cf[b]];
    let d = corners[*f].normal[cf[a]].cross(corners[*g].normal[cg[a]]);
    // Unit normals: |d| = sin of their angle; below 1e-8 the line is not defined to rounding.
    if d.length_squared() < 1e-16 {
        return None;
    }
    Some(pa + d * (d.dot(pb - pa) / (3.0 * d.length_squared())))
}

/// The normal a smooth edge uses at its end vertex in corner `c` of `f` (whose neighbour `g`
/// holds that vertex in corner `cg`): the triangle's own normal, or, where the two sides'
/// input normals differ (split normals), their normalized mean, so that both sides build the
/// edge from the same data.
pub fn edge_end_normal(corners: &[Corners], f: usize, c: usize, g: usize, cg: usize) -> DVec3 {
    let (nf, ng) = (corners[f].normal[c], corners[g].normal[cg]);
    if nf == ng {
        nf
    } else {
        (nf + ng).normalize_or(nf)
    }
}
