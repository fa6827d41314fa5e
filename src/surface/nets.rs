//! Which cubic control net each triangle starts from ([`Nets`]): the published PN net of Eq. 2
//! ([`Nets::Paper`]), or the round net ([`Nets::Round`], the default) whose edge curves follow
//! circular arcs and whose centre follows the shape.
//!
//! It deliberately builds one triangle's net from its corners alone, as Eq. 2 does: the G² blend
//! (Eq. 3–5), the neighbour composition, the patterns and the normals take any cubic net, so they
//! are unchanged whichever rule made it.
//!
//! Why not PN's rule: its edge handles `c·cos α/3` (chord `c`, `α` the angle between chord and
//! tangent plane) are too short at third order, so every edge curve sags inside a circular arc of
//! angle θ by about `3θ⁴/128` of its radius; its centre `E + (E − V)/2` then flattens the
//! interior. The blend of Eq. 5 has to make up the difference of the two sides' cross-edge
//! derivatives inside its band, and bends hard there (normal curvature −0.04 to 2.67 along the
//! output edges of the icosahedron, a unit sphere).
//!
//! The round net:
//! - Edge handles of length `2c/(3(1 + cos α))` ([`circle_handle`]): the cubic that follows an
//!   arc of angle θ best has handles `(4/3)·r·tan(θ/4) = c/(3cos²(θ/4))`, radial error about
//!   θ⁶/55296, and `α = θ/2` on an arc. Each handle lies on the line where the corner's tangent
//!   plane meets the edge's plane (through the chord and the mean of the two end normals), so
//!   the edge curve is a plane curve close to the surface's section by that plane. PN's
//!   direction (the chord projected into each corner's tangent plane) is the same on a sphere
//!   but twists the curve where the normals turn across the edge, as along a torus's
//!   diagonals: there it was the largest error left (torus 50×10 at level 8: 3.9e-4 and 0.74°
//!   with it, 1.5e-4 and 0.39° with the edge plane). Both triangles of an edge compute the
//!   same two handles from the same two corners, bit for bit.
//! - Centre from a side-vertex rule ([`side_vertex_centre`]): from each corner, the circle cubic
//!   to the midpoint of the opposite edge curve (normal: the mean of that edge's end normals),
//!   read at 2/3; `b111` puts the patch centre on the mean of the three.
//!
//! Measured (`tests/benches/shape/shape.py`, level 8, against the exact shape): a 980-triangle
//! icosphere 4.8e-7 max distance and 0.008° max normal error (paper nets 5.1e-5, 0.046°); the
//! 50×10 torus 1.5e-4 and 0.39° (paper nets 1.5e-3, 1.46°). Candidates measured and dropped:
//! a centre that makes the patch's normal at each edge midpoint the mean of the end normals
//! (no better on the torus, unstable on thin triangles), and the centre rule with that normal
//! made perpendicular to the edge curve (worse on the torus: 1.8e-4, 0.55°), and the three
//! side-vertex points weighted by the inverse square or fourth power of their corner's distance
//! to the midpoint (no better anywhere, worse on the 320-triangle icosphere: 2.5e-6, 3.7e-6).

use glam::DVec3;

use super::pn::{pn_net, Net, B111, NEAR};

/// The rule for the control nets under every PN-based surface (`g2`, `pn`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Deserialize, serde::Serialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Nets {
    /// Circle-following edges and a side-vertex centre (this module's documentation).
    #[default]
    Round,
    /// PN triangles as published (Vlachos et al. 2001; paper Eq. 2).
    Paper,
}

impl Nets {
    /// The name used on the command line and in configuration files.
    pub fn name(self) -> &'static str {
        match self {
            Nets::Round => "round",
            Nets::Paper => "paper",
        }
    }

    /// The control net of a triangle with corner positions `p` and unit normals `n`.
    pub fn net(self, p: [DVec3; 3], n: [DVec3; 3]) -> Net {
        match self {
            Nets::Paper => pn_net(p, n),
            Nets::Round => round_net(p, n),
        }
    }

    /// `b111` from the nine boundary points already in `net` (used again after split-normal
    /// edges were averaged): Eq. 2's rule for [`Nets::Paper`], [`side_vertex_centre`] for
    /// [`Nets::Round`] with the corner normals `n`.
    pub fn centre(self, net: &Net, n: [DVec3; 3]) -> DVec3 {
        match self {
            Nets::Paper => super::pn::central_point(net),
            Nets::Round => side_vertex_centre(net, n),
        }
    }
}

/// Smallest `cos α` the handle length is computed with. An edge that leaves its corner's tangent
/// plane at more than 60° is no arc of a smooth surface sampled by this mesh (a cone tip, a
/// folded input); there the handle shrinks with the projected chord, as PN's does, instead of
/// growing without bound. Circular arcs up to 120° are reproduced.
const MIN_COS: f64 = 0.5;

/// The edge control point next to corner `p` (unit normal `n`) on the edge towards `q` (unit
/// normal `nq`): `p + k·t`, where `t` is the chord projected onto the edge's tangent line at `p`
/// (length `c·cos α`) and `k = 2/(3cos α(1 + cos α))`, so the handle is `2c/(3(1 + cos α))` long.
///
/// The tangent line is where `p`'s tangent plane meets the edge's plane, the plane through the
/// chord and the mean normal `n + nq`; both ends use that one plane, so the edge curve is a plane
/// curve, close to the surface's section by that plane. (PN's direction, the chord projected into
/// the tangent plane, lies in a different plane at each end: the curve then twists where the
/// normals turn across the edge, as along the diagonals of a torus, and leaves the surface; the
/// two agree wherever the normals are symmetric about the chord, as on a sphere or a surface of
/// revolution's meridian.)
///
/// A cubic with two such handles and the two end tangents of a circular arc lies on that arc to
/// about θ⁶/55296 of its radius (θ the arc's angle).
pub fn circle_handle(p: DVec3, n: DVec3, q: DVec3, nq: DVec3) -> DVec3 {
    let chord = q - p;
    let c2 = chord.length_squared();
    if c2 == 0.0 {
        return p;
    }
    handle_along(p, n, chord, c2, n + nq)
}

/// Both handles of the circle cubic between `(p, n)` and `(q, nq)`:
/// `[circle_handle(p, n, q, nq), circle_handle(q, nq, p, n)]`, bit for bit.
///
/// Every net rule asks for an edge's two handles together (the round net's three edges, the
/// side-vertex rule's three spokes), and the two calls share what does not depend on the end:
/// the squared chord length (`p − q` is `−(q − p)` but for the sign of zeros, whose squares are
/// the same `+0`, summed in the same order) and the edge plane's mean normal (`n + nq` and
/// `nq + n` are the same sum: addition commutes exactly). Computing them once leaves every
/// operation of each handle as it was.
#[inline]
pub fn circle_handles(p: DVec3, n: DVec3, q: DVec3, nq: DVec3) -> [DVec3; 2] {
    let chord = q - p;
    let c2 = chord.length_squared();
    if c2 == 0.0 {
        return [p, q];
    }
    let mean = n + nq;
    [
        handle_along(p, n, chord, c2, mean),
        handle_along(q, nq, p - q, c2, mean),
    ]
}

/// [`circle_handle`] at `p` (unit normal `n`) for the chord `chord` to the other end, its
/// squared length `c2 > 0` and the mean normal `mean` of the two ends (not normalized).
#[inline(always)]
fn handle_along(p: DVec3, n: DVec3, chord: DVec3, c2: f64, mean: DVec3) -> DVec3 {
    // The tangent line: across the edge plane's normal m; t(t·chord)/|t|² does not depend on
    // t's sign or length. Where the plane is undefined (the chord along the mean normal, or
    // the plane parallel to the tangent plane), PN's projection into the tangent plane.
    let m = chord.cross(mean);
    let t = m.cross(n);
    let t2 = t.length_squared();
    let tangent = if t2 > 1e-20 * c2 {
        t * (t.dot(chord) / t2)
    } else {
        chord - chord.dot(n) * n
    };
    let cos = (tangent.length_squared() / c2).sqrt().clamp(MIN_COS, 1.0);
    p + tangent * (2.0 / (3.0 * cos * (1.0 + cos)))
}

/// The round net of the module documentation from corner positions `p` and unit normals `n`.
pub fn round_net(p: [DVec3; 3], n: [DVec3; 3]) -> Net {
    let mut net = [DVec3::ZERO; 10];
    for c in 0..3 {
        net[NEAR[c][c]] = p[c];
        // Each edge's two handles at once (see `circle_handles`).
        let e = (c + 1) % 3;
        [net[NEAR[c][e]], net[NEAR[e][c]]] = circle_handles(p[c], n[c], p[e], n[e]);
    }
    net[B111] = side_vertex_centre(&net, n);
    net
}

/// `b111` such that the patch's centre `(⅓, ⅓, ⅓)` is `X`, the mean of three side-vertex points:
/// for corner `i`, `M` the midpoint of the opposite edge curve with normal
/// `normalize(n_j + n_k)`, and `X_i` the circle cubic from `(p_i, n_i)` to `(M, n_M)` at 2/3 (the
/// centre lies 2/3 of the way from a corner to the opposite edge's midpoint).
///
/// The centre of a cubic Bézier triangle is `(Σ corners + 3·Σ edge points + 6·b111)/27` (Eq. 1
/// at ⅓, ⅓, ⅓), hence `b111 = (27·X − Σ corners − 3·Σ edge points)/6`.
pub fn side_vertex_centre(net: &Net, n: [DVec3; 3]) -> DVec3 {
    let corners = net[0] + net[1] + net[2];
    let edges: DVec3 = net[3..9].iter().copied().sum();
    let mut x = DVec3::ZERO;
    for i in 0..3 {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let mid = (net[j] + 3.0 * net[NEAR[j][k]] + 3.0 * net[NEAR[k][j]] + net[k]) / 8.0;
        let n_mid = (n[j] + n[k]).normalize_or(n[i]);
        let [a, b] = circle_handles(net[i], n[i], mid, n_mid);
        // The cubic (p_i, a, b, M) at t = 2/3: Bernstein weights 1, 6, 12, 8 over 27.
        x += (net[i] + 6.0 * a + 12.0 * b + 8.0 * mid) / 27.0;
    }
    x /= 3.0;
    (27.0 * x - corners - 3.0 * edges) / 6.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::pn::Bernstein;

    /// Corners of a spherical triangle of the unit sphere, `a` radians across.
    fn sphere_triangle(a: f64) -> [DVec3; 3] {
        let s = a.sin() / 3f64.sqrt();
        [0.0, 2.0, 4.0].map(|k: f64| {
            let phi = k * std::f64::consts::PI / 3.0;
            DVec3::new(s * phi.cos(), s * phi.sin(), 1.0).normalize()
        })
    }

    #[test]
    fn circle_handle_has_the_best_arc_length() {
        // An arc of angle θ on the unit circle: handle (4/3)·tan(θ/4), tangent to the circle.
        for theta in [0.1f64, 0.6, 1.5, 2.0] {
            let p = DVec3::new(1.0, 0.0, 0.0);
            let q = DVec3::new(theta.cos(), theta.sin(), 0.0);
            let b = circle_handle(p, p, q, q);
            let want = 4.0 / 3.0 * (theta / 4.0).tan();
            assert!(((b - p).length() - want).abs() < 1e-14 * want.max(1.0));
            assert!((b - p).dot(p).abs() < 1e-15);
        }
    }

    #[test]
    fn round_nets_lie_on_the_sphere_far_closer_than_pn_and_converge_at_sixth_order() {
        // Triangles of about the size of an 80-, 320- and 1280-triangle icosphere's. Round edges err
        // like θ⁶, PN's like θ⁴: each halving must divide the round error by nearly 2⁶ = 64
        // (at least 40) and PN's by nearly 2⁴ (at most 20), and round must win by far.
        let err = |net: &Net| {
            let mut worst: f64 = 0.0;
            for i in 0..=12 {
                for j in 0..=12 - i {
                    let l = [(12 - i - j) as f64 / 12.0, i as f64 / 12.0, j as f64 / 12.0];
                    let r = Bernstein::at(l).eval(net)[0].length();
                    worst = worst.max((r - 1.0).abs());
                }
            }
            worst
        };
        let errors: Vec<(f64, f64)> = [0.55f64, 0.275, 0.1375]
            .iter()
            .map(|&a| {
                let p = sphere_triangle(a);
                (err(&round_net(p, p)), err(&pn_net(p, p)))
            })
            .collect();
        for w in errors.windows(2) {
            let ((r0, p0), (r1, p1)) = (w[0], w[1]);
            assert!(r0 / r1 > 40.0 && p0 / p1 < 20.0, "{errors:?}");
        }
        assert!(errors.iter().all(|&(r, p)| r * 50.0 < p), "{errors:?}");
    }

    #[test]
    fn handles_scale_with_the_mesh_and_stay_bounded_where_the_edge_plane_is_undefined() {
        let (p, q) = (DVec3::new(0.1, 0.2, 0.3), DVec3::new(0.9, -0.1, 0.5));
        let (n, nq) = (
            DVec3::new(0.2, 0.3, 1.0).normalize(),
            DVec3::new(-0.3, 0.1, 1.0).normalize(),
        );
        let unit = circle_handle(p, n, q, nq) - p;
        for s in [1e-6, 1e6] {
            let scaled = circle_handle(s * p, n, s * q, nq) - s * p;
            assert!((scaled - s * unit).length() < 1e-12 * s, "{s}");
        }
        // Chord along both normals (no tangent plane contains any of it): no handle at all.
        let up = DVec3::Z;
        assert_eq!(circle_handle(DVec3::ZERO, up, up, up), DVec3::ZERO);
        // Opposite normals (no mean normal): PN's direction, never longer than the chord.
        let b = circle_handle(DVec3::ZERO, up, DVec3::X, -up);
        assert!((b - DVec3::X / 3.0).length() < 1e-15, "{b}");
        let steep = circle_handle(DVec3::ZERO, up, DVec3::new(0.1, 0.0, 1.0), -up);
        assert!(steep.is_finite() && steep.length() < 1.01, "{steep}");
    }

    /// What lets the net rules take an edge's two handles at once: the pair is the two single
    /// handles bit for bit, on random edges and on the cases where a shared term could differ in
    /// sign or branch: chords with zero components (of either sign of the ends' coordinates),
    /// coincident ends, chords along the normals, and opposite normals.
    #[test]
    fn an_edges_two_handles_together_are_the_single_handles_bit_for_bit() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut cases = Vec::new();
        for i in 0..2000 {
            let mut p = DVec3::new(next(), next(), next());
            let mut q = p + 0.3 * DVec3::new(next(), next(), next());
            let n = DVec3::new(next(), next(), next()).normalize();
            let mut nq = (n + 0.5 * DVec3::new(next(), next(), next())).normalize();
            match i % 6 {
                // Equal coordinates, zero of either sign: chord components of +0.
                1 => {
                    p.x = if i % 12 == 1 { -0.0 } else { 0.0 };
                    q.x = p.x;
                    q.y = p.y;
                }
                2 => q = p,
                3 => q = p + 0.2 * n,
                4 => nq = -n,
                5 => {
                    p = DVec3::new(-0.0, 0.0, -0.0);
                    q.z = -0.0;
                }
                _ => {}
            }
            cases.push((p, n, q, nq));
        }
        let bits = |v: DVec3| v.to_array().map(f64::to_bits);
        for (p, n, q, nq) in cases {
            let [a, b] = circle_handles(p, n, q, nq);
            assert_eq!(
                bits(a),
                bits(circle_handle(p, n, q, nq)),
                "{p} {n} {q} {nq}"
            );
            assert_eq!(
                bits(b),
                bits(circle_handle(q, nq, p, n)),
                "{p} {n} {q} {nq}"
            );
        }
    }

    #[test]
    fn both_sides_of_an_edge_get_the_same_curve_bit_for_bit() {
        let p = sphere_triangle(0.7);
        let q = [p[1], p[0], DVec3::new(0.0, -0.3, 1.0).normalize()];
        let (f, g) = (round_net(p, p), round_net(q, q));
        // f's edge 0→1 is g's edge 1→0.
        assert_eq!(f[NEAR[0][1]], g[NEAR[1][0]]);
        assert_eq!(f[NEAR[1][0]], g[NEAR[0][1]]);
    }

    #[test]
    fn a_flat_triangle_keeps_a_flat_linear_net() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::new(0.3, 0.8, 0.0)];
        let net = round_net(p, [DVec3::Z; 3]);
        for (m, b) in net.iter().enumerate() {
            let ijk = crate::surface::pn::IJK[m];
            let want = (ijk[0] as f64 * p[0] + ijk[1] as f64 * p[1] + ijk[2] as f64 * p[2]) / 3.0;
            assert!((*b - want).length() < 1e-15, "slot {m}: {b} vs {want}");
        }
    }
}
