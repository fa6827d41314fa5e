//! The two geometric rules that make an edge sharp (h = 0) without naming it: the crease angle
//! and hard edges (split normals) in the input. It deliberately does not decide precedence.

use glam::DVec3;

use crate::topology::{Edge, EdgeKind, Topology};

/// The dihedral angle must exceed the crease angle by more than this to count as a crease, so an
/// edge built at exactly the threshold (60° from `cos`/`sin` coordinates) is not flipped by
/// rounding.
pub const CREASE_SLACK_DEGREES: f64 = 1e-6;

/// The angle in degrees between the face normals of an interior edge's two triangles: 0 for a
/// flat edge, 180 for a fold back onto itself. `None` for boundary, non-manifold and degenerate
/// edges, which the surface never blends anyway.
///
/// The normals are oriented consistently before comparing: if both triangles run the edge in
/// the same direction, their windings disagree and one normal is flipped, so a mesh with mixed
/// winding gets the same creases as a clean one.
pub fn dihedral_degrees(edge: &Edge<'_>, topo: &Topology) -> Option<f64> {
    if edge.kind != EdgeKind::Interior {
        return None;
    }
    let [(t0, k0), (t1, k1)] = [edge.tris.first()?.at(), edge.tris.last()?.at()];
    let face = |t: usize| {
        let [a, b, c] = topo.tri_verts[t].map(|v| topo.welded_positions[v.0 as usize]);
        (b - a).cross(c - a)
    };
    // Edge k of a triangle runs from corner k + 1 to corner k + 2.
    let start = |t: usize, k: usize| topo.tri_verts[t][(k + 1) % 3];
    let n0 = face(t0);
    let mut n1 = face(t1);
    if start(t0, k0) == start(t1, k1) {
        n1 = -n1;
    }
    Some(angle_degrees(n0, n1))
}

/// Whether an edge of this dihedral angle is a crease under `crease_angle`.
pub fn is_crease(dihedral: f64, crease_angle: f64) -> bool {
    dihedral > crease_angle + CREASE_SLACK_DEGREES
}

/// Whether the input marks the edge hard: the triangles on its two sides carry different
/// normals at one of its ends.
pub fn is_hard_edge(edge: &Edge<'_>) -> bool {
    edge.split_normals
}

/// `atan2(|a × b|, a · b)`: accurate near 0° and 180°, where `acos` loses half its digits.
fn angle_degrees(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}
