//! The Foley–Opitz C¹ cross-boundary construction of seed 001 §2: the interior control points
//! `p` and `q` of two cubic patches over a plane, from their boundary control points.
//!
//! It deliberately knows nothing of meshes, planes or blending: labelled points in, two points
//! out. Corrected as follows (each shown wrong by `tests/integration/schemes_typos.rs`):
//! - `(r, s, t)` are the barycentrics of the neighbour's apex `Y` (the paper's `c003`) with
//!   respect to `(b300, b030, b003)`, not `(b003, b030, b300)` as printed: the blossom derivation
//!   of the printed `p2` formula ties `r` to `b300`, `s` to `b030` and `t` to the apex `b003`.
//! - `q2 = r·b210 + s·b120 + t·p2`, not `r·p2 + s·b120 + t·b210`: this is the C¹ condition
//!   `c111 = r b210 + s b120 + t b111` (subdivision of one cubic); the printed form swaps r and t.

use glam::DVec3;

/// The control points of the patch over triangle `(A, B, C)` = `(b300, b030, b003)` that the
/// construction reads, in the paper's notation (`b210` next to A towards B, and so on).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Labelled {
    pub b300: DVec3,
    pub b030: DVec3,
    pub b003: DVec3,
    pub b210: DVec3,
    pub b120: DVec3,
    pub b201: DVec3,
    pub b021: DVec3,
    pub b102: DVec3,
    pub b012: DVec3,
}

/// `(r, s, t)`: the barycentrics of `y` with respect to `(a, b, c)` after orthogonal projection
/// onto a plane with unit normal `m`. For a valid plane the two triangles lie on opposite sides
/// of the projected edge, so `t < 0`.
pub fn apex_barycentrics(m: DVec3, a: DVec3, b: DVec3, c: DVec3, y: DVec3) -> [f64; 3] {
    // det(u, v, m) is the signed area of the projections of u and v: adding multiples of m
    // to either does not change it, so no explicit projection is needed.
    let area = |u: DVec3, v: DVec3| u.cross(v).dot(m);
    let (e1, e2, w) = (b - a, c - a, y - a);
    let whole = area(e1, e2);
    let s = area(w, e2) / whole;
    let t = area(e1, w) / whole;
    [1.0 - s - t, s, t]
}

/// Foley–Opitz `p2`, the interior point of the patch over `(A, B, C)` for which it joins the
/// neighbour over `(A, B, Y)` C¹ (seed 001 §2, first displayed equation):
///
/// `p2 = [c102 + c012 − r²(b300+b210) − 2rs(b210+b120) − 2rt b201 − 2st b021 − s²(b120+b030)
///        − t²(b102+b012)] / (2(r+s)t)`
///
/// with `c102`, `c012` the neighbour's points next to `Y` towards A and B. The coefficients sum
/// to 1, so this is an affine combination of points. Its denominator is at least 4 in magnitude
/// when `|t| ≥ 1`, which is why callers evaluate it on that side.
pub fn interior_point(n: &Labelled, c102: DVec3, c012: DVec3, [r, s, t]: [f64; 3]) -> DVec3 {
    let num = c102 + c012
        - r * r * (n.b300 + n.b210)
        - 2.0 * r * s * (n.b210 + n.b120)
        - 2.0 * r * t * n.b201
        - 2.0 * s * t * n.b021
        - s * s * (n.b120 + n.b030)
        - t * t * (n.b102 + n.b012);
    num / (2.0 * (r + s) * t)
}

/// The neighbour's interior point forced by C¹ continuity, corrected from seed 001 §2's
/// `q2 = r p2 + s b120 + t b210` to `q2 = r b210 + s b120 + t p2`.
pub fn neighbour_interior(b210: DVec3, b120: DVec3, p2: DVec3, [r, s, t]: [f64; 3]) -> DVec3 {
    r * b210 + s * b120 + t * p2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentrics_reproduce_the_point_in_the_plane() {
        let m = DVec3::new(0.1, 0.2, 1.0).normalize();
        let (a, b, c) = (
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.1),
            DVec3::new(0.4, 1.0, -0.2),
        );
        let y = DVec3::new(0.6, -0.8, 0.3);
        let [r, s, t] = apex_barycentrics(m, a, b, c, y);
        assert!(t < 0.0);
        let back = r * a + s * b + t * c;
        assert!((back - y).cross(m).length() < 1e-14);
    }
}
