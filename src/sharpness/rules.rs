//! The two geometric rules that make an edge sharp (h = 0) without naming it: the crease angle
//! and hard edges (split normals) in the input. It deliberately does not decide precedence.

use glam::DVec3;
use rayon::prelude::*;

use crate::topology::{Edge, EdgeKind, Topology, TriId};

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
    let (n0, n1) = oriented_normals(edge, topo)?;
    Some(angle_degrees(n0, n1))
}

/// The crease rule under one crease angle, with what its shortcut needs computed once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CreaseTest {
    crease_angle: f64,
    /// Edges whose angle's cosine is above this are certainly not creases; NaN (never above)
    /// where the shortcut does not apply.
    clear_cosine: f64,
}

impl CreaseTest {
    /// The rule for `crease_angle` (degrees).
    pub fn new(crease_angle: f64) -> Self {
        let limit = crease_angle + CREASE_SLACK_DEGREES;
        let clear_cosine = if limit > 0.0 && limit < 180.0 {
            limit.to_radians().cos() + 1e-9
        } else {
            f64::NAN
        };
        CreaseTest {
            crease_angle,
            clear_cosine,
        }
    }

    /// The crease angle, in degrees.
    pub fn crease_angle(&self) -> f64 {
        self.crease_angle
    }

    /// [`dihedral_degrees`] of an interior edge that is a crease under this angle
    /// ([`is_crease`]), `None` for every other edge.
    ///
    /// The arc tangent is the costly part of the rule and most edges of a smooth mesh are far
    /// from any crease: an edge whose angle's cosine lies clearly above the threshold's (by
    /// 1e-9, a million times the rounding of either side) is decided without it. Every other
    /// edge, including all near the threshold, takes the exact path, so the result is the same.
    ///
    /// The face normals are read from `faces` ([`face_normals`]): each triangle's is computed
    /// once rather than once per edge, and an edge reads two of them instead of two triangles'
    /// corners and six positions. They are the normals [`dihedral_degrees`] computes, bit for
    /// bit, so the result is the same.
    pub fn dihedral_if_crease(
        &self,
        edge: &Edge<'_>,
        topo: &Topology,
        faces: &[DVec3],
    ) -> Option<f64> {
        self.decide(oriented_faces(edge, topo, faces)?)
    }

    /// The rule on an interior edge's oriented face normals.
    fn decide(&self, (n0, n1): (DVec3, DVec3)) -> Option<f64> {
        // cos / radius > clear, compared in squares: no square root or division per edge,
        // and rounding far inside the 1e-9 margin.
        let (cos, clear) = (n0.dot(n1), self.clear_cosine);
        let radius2 = n0.cross(n1).length_squared() + cos * cos;
        let clear_of_it = if clear >= 0.0 {
            cos > 0.0 && cos * cos > clear * clear * radius2
        } else {
            cos >= 0.0 || cos * cos < clear * clear * radius2
        };
        // NaN, overflowing and underflowing sizes fail the test and take the exact path, as
        // does a NaN threshold.
        if radius2.is_finite() && radius2 > 1e-280 && !clear.is_nan() && clear_of_it {
            return None;
        }
        let dihedral = angle_degrees(n0, n1);
        is_crease(dihedral, self.crease_angle).then_some(dihedral)
    }
}

/// The face normals of an interior edge's two triangles, the second flipped where the two are
/// wound against each other; `None` for every other edge.
fn oriented_normals(edge: &Edge<'_>, topo: &Topology) -> Option<(DVec3, DVec3)> {
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
    Some((n0, n1))
}

/// Every triangle's face normal as [`oriented_normals`] computes it (the cross product of two
/// sides from the welded positions, not normalized), in parallel: read by the crease rule for
/// each of a triangle's three edges instead of computed three times.
pub fn face_normals(topo: &Topology) -> Vec<DVec3> {
    topo.tri_verts
        .par_iter()
        .map(|v| {
            let [a, b, c] = v.map(|v| topo.welded_positions[v.0 as usize]);
            (b - a).cross(c - a)
        })
        .collect()
}

/// [`oriented_normals`] read from `faces`: the second flipped where the neighbour across the
/// edge runs along it in the same direction
/// ([`Neighbour::runs_same_way`](crate::topology::Neighbour::runs_same_way)), which is where
/// the corners' test flips it.
fn oriented_faces(edge: &Edge<'_>, topo: &Topology, faces: &[DVec3]) -> Option<(DVec3, DVec3)> {
    if edge.kind != EdgeKind::Interior {
        return None;
    }
    let (t0, k0) = edge.tris.first()?.at();
    let n = topo.neighbour(TriId(t0 as u32), k0)?;
    let n1 = faces[n.tri.0 as usize];
    Some((faces[t0], if n.runs_same_way() { -n1 } else { n1 }))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TriMesh;
    use crate::topology::{EdgeKind, Topology};

    /// Two triangles hinged on the edge (0,0,0)–(1,0,0), folded by `fold` degrees, at `scale`.
    fn hinge(fold: f64, scale: f64) -> TriMesh {
        let f = fold.to_radians();
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.5, 1.0, 0.0),
            DVec3::new(0.5, -f.cos(), f.sin()),
        ]
        .into_iter()
        .map(|p| p * scale)
        .collect::<Vec<_>>();
        TriMesh {
            normals: vec![DVec3::Z; positions.len()],
            positions,
            triangles: vec![[0, 1, 2], [1, 0, 3]],
        }
    }

    /// The face normals read from the array are the ones computed from the corners, bit for
    /// bit, with the same flips: odd shapes with mixed winding, books, copies and signed zeros.
    #[test]
    fn normals_from_the_face_array_are_the_computed_ones() {
        // A torus with every third triangle wound the other way and signed zeros on its
        // equator (mostly interior edges), and odd shapes (mostly not).
        let (m, n) = (24u32, 16u32);
        let at = |i: u32, j: u32| (i % m) * n + (j % n);
        let mut torus = TriMesh::default();
        for i in 0..m {
            for j in 0..n {
                let (u, v) = (
                    f64::from(i) * std::f64::consts::TAU / f64::from(m),
                    f64::from(j) * std::f64::consts::TAU / f64::from(n),
                );
                let z = if j == 0 { -0.0 } else { v.sin() };
                let r = 2.0 + v.cos();
                torus
                    .positions
                    .push(DVec3::new(r * u.cos(), r * u.sin(), z));
                for t in [
                    [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                    [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
                ] {
                    let flip = torus.triangles.len() % 3 == 0;
                    torus
                        .triangles
                        .push(if flip { [t[0], t[2], t[1]] } else { t });
                }
            }
        }
        torus.normals = vec![DVec3::Z; torus.positions.len()];
        let odd =
            (0..30).map(|seed| crate::topology::tests::odd_mesh(seed, 20 + 9 * seed as usize));
        let mut interior = 0;
        for mesh in std::iter::once(torus).chain(odd) {
            let topo = Topology::build(&mesh);
            let faces = face_normals(&topo);
            for edge in topo.edges() {
                let bits = |n: Option<(DVec3, DVec3)>| {
                    n.map(|(a, b)| [a, b].map(|v| v.to_array().map(f64::to_bits)))
                };
                let want = oriented_normals(&edge, &topo);
                assert_eq!(bits(oriented_faces(&edge, &topo, &faces)), bits(want));
                interior += usize::from(want.is_some());
            }
        }
        assert!(interior > 1000, "{interior}");
    }

    /// The shortcut decides every edge as the exact rule does: folds from flat to nearly
    /// folded back, crease angles at, just below and just above each fold (down to the slack),
    /// at tiny, unit and huge scales (where the squares under- or overflow and the exact path
    /// decides).
    #[test]
    fn the_crease_shortcut_agrees_with_the_exact_rule() {
        let mut creases = 0;
        for scale in [1e-60, 1e-30, 1.0, 1e30, 1e70] {
            for i in 0..=180 {
                let fold = f64::from(i) * 0.999;
                let mesh = hinge(fold, scale);
                let topo = Topology::build(&mesh);
                let faces = face_normals(&topo);
                let edge = topo
                    .edges()
                    .find(|e| e.kind == EdgeKind::Interior)
                    .unwrap_or_else(|| panic!("no hinge at fold {fold}, scale {scale}"));
                let exact = dihedral_degrees(&edge, &topo).expect("interior");
                for angle in [
                    0.0,
                    exact - CREASE_SLACK_DEGREES,
                    exact - 2.0 * CREASE_SLACK_DEGREES,
                    exact,
                    exact - 1e-3,
                    exact + 1e-3,
                    exact - 1.0,
                    exact + 1.0,
                    30.0,
                    179.9,
                ] {
                    let expected = is_crease(exact, angle).then_some(exact);
                    assert_eq!(
                        CreaseTest::new(angle).dihedral_if_crease(&edge, &topo, &faces),
                        expected,
                        "fold {fold}, scale {scale}, crease angle {angle}"
                    );
                    creases += usize::from(expected.is_some());
                }
            }
        }
        // Both outcomes were tested, many times each.
        assert!(creases > 1000, "{creases}");
    }
}
