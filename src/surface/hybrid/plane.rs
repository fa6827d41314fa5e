//! The projection plane of one mesh edge (seed 001 §4) and the oblique edge control points it
//! gives: the functional cubic Hermite construction over that plane, written directly in 3D.
//!
//! It deliberately knows nothing of meshes or of the Foley–Opitz interior points: unit vectors
//! in, a plane normal and control points out.

use glam::DVec3;

/// The least `N·m` accepted for the end normals and the two face normals (seed 001 §4 gives no
/// number; below it the oblique points grow like `1/(N·m)`).
pub const DELTA: f64 = 0.2;

/// Below this best `min N·m` the edge gets no plane: the construction would move control points
/// by more than 20 edge lengths, so the edge is made a crease instead.
pub const GIVE_UP: f64 = 0.05;

/// The unit normal `m` of the projection plane of an edge with end normals `na`, `nb` and face
/// normals `nf`, `ng` (oriented consistently across the edge), or `None` when no plane has
/// `min(N·m) ≥` [`GIVE_UP`].
///
/// 1. `m ∥ na + nb`: seed 001 §4's preferred plane, "perpendicular to the average of the
///    normals at the two data points".
/// 2. `m ∥ nf + ng`: its failsafe plane, which contains the edge and is perpendicular to the
///    bisecting plane of the two triangles.
/// 3. An approximate max-min direction of the four vectors, from the best of the above.
///
/// The first that reaches [`DELTA`] for all four vectors is taken. Face normals at or above
/// [`DELTA`] keep both projected triangles' orientation, so they lie on opposite sides of the
/// projected edge and their domains do not overlap (the paper's validity condition); end
/// normals at or above it keep the shared boundary curve finite.
pub fn projection_plane(na: DVec3, nb: DVec3, nf: DVec3, ng: DVec3) -> Option<DVec3> {
    let all = [na, nb, nf, ng];
    let min_dot = |m: DVec3| all.iter().map(|n| n.dot(m)).fold(f64::INFINITY, f64::min);
    let average = (na + nb).normalize_or_zero();
    if min_dot(average) >= DELTA {
        return Some(average);
    }
    let bisector = (nf + ng).normalize_or_zero();
    if min_dot(bisector) >= DELTA {
        return Some(bisector);
    }
    // Max-min by nudging m towards the vector it is worst for, halving the step on failure.
    let mut m = [average, bisector, (average + bisector).normalize_or_zero()]
        .into_iter()
        .max_by(|a, b| min_dot(*a).total_cmp(&min_dot(*b)))
        .expect("three candidates");
    let mut best = min_dot(m);
    let mut step = 0.5;
    for _ in 0..60 {
        let worst = *all
            .iter()
            .min_by(|a, b| a.dot(m).total_cmp(&b.dot(m)))
            .expect("four vectors");
        let next = (m + step * worst).normalize_or_zero();
        let value = min_dot(next);
        if value > best {
            (m, best) = (next, value);
            if best >= DELTA {
                break;
            }
        } else {
            step *= 0.5;
        }
    }
    (best >= GIVE_UP).then_some(m)
}

/// `n` itself if `n·m ≥` [`DELTA`], otherwise the unit vector in span(m, n) with `N·m = DELTA`.
///
/// Used for the apex normals of an edge's two triangles, which the plane test leaves out (on a
/// cube with diagonal normals no plane suits both apexes): their points enter only the
/// Foley–Opitz formula for this edge, never the final blend along it.
pub fn tilt_to_plane(n: DVec3, m: DVec3) -> DVec3 {
    if n.dot(m) >= DELTA {
        return n;
    }
    let side = (n - n.dot(m) * m).normalize_or(m.any_orthonormal_vector());
    DELTA * m + (1.0 - DELTA * DELTA).sqrt() * side
}

/// The edge control point next to corner `x` (unit normal `nx`) towards corner `y`, for the
/// projection plane with unit normal `m`:
/// `b_m(X→Y) = X + (Y−X)/3 − m (N_X·(Y−X)) / (3 N_X·m)`.
///
/// This is `(2X+Y)/3` moved along `m` onto the tangent plane at X: the cubic Hermite boundary
/// of a function over the plane (seed 001 §3, "Hermite interpolation over a plane completely
/// determines the cubic boundary curves"). PN moves the same point along `N_X` instead.
pub fn oblique_point(x: DVec3, y: DVec3, nx: DVec3, m: DVec3) -> DVec3 {
    let d = y - x;
    x + d / 3.0 - m * (nx.dot(d) / (3.0 * nx.dot(m)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn average_plane_first_then_failsafe_then_none_for_a_knife_edge() {
        let z = DVec3::Z;
        assert_eq!(projection_plane(z, z, z, z), Some(z));
        // End normals along the edge's side, faces still facing up: average fails, bisector works.
        let side = DVec3::new(0.0, -1.0, 0.05).normalize();
        let m = projection_plane(side, side, z, z).expect("a plane");
        assert!(m.dot(side) >= DELTA && m.dot(z) >= DELTA, "{m}");
        // Faces back to back: no plane sees both from the front.
        assert_eq!(projection_plane(z, z, z, -z), None);
    }

    #[test]
    fn oblique_point_lies_in_the_tangent_plane_and_on_the_thirds_line() {
        let (x, y) = (DVec3::ZERO, DVec3::new(1.0, 0.2, 0.3));
        let n = DVec3::new(0.1, -0.3, 1.0).normalize();
        let m = DVec3::new(0.2, 0.1, 1.0).normalize();
        let b = oblique_point(x, y, n, m);
        assert!((b - x).dot(n).abs() < 1e-15);
        assert!((b - (2.0 * x + y) / 3.0).cross(m).length() < 1e-15);
    }

    #[test]
    fn tilted_normal_reaches_delta() {
        let m = DVec3::Z;
        let n = DVec3::new(1.0, 0.0, -0.5).normalize();
        let t = tilt_to_plane(n, m);
        assert!((t.length() - 1.0).abs() < 1e-15 && (t.dot(m) - DELTA).abs() < 1e-15);
        assert!((tilt_to_plane(-m, m).dot(m) - DELTA).abs() < 1e-15);
    }
}
