//! One parametric hybrid patch (seed 001 §3): three cubic nets, one per edge, blended into the
//! ten control points `c_ijk(u)` of a cubic Bézier triangle that is then evaluated at `u`,
//! `F(u) = Σ B_ijk(u) c_ijk(u)`, with its exact first derivatives.
//!
//! It deliberately knows nothing of how the nets were built or of the mesh.
//!
//! Net `i` belongs to the edge opposite corner `i` (`u_i = 0`). Corners are constants; every
//! other boundary control point with a 0 at position `i`, a 1 at position `j` and a 2 at `k` is
//! `c = h_ij(u) b_{·,i} + h_ji(u) b_{·,j}` with seed 001 Eq. 2,
//! `h_ij = (1−u_i)u_j² / ((1−u_i)u_j² + (1−u_j)u_i²)`; the interior point is Nielson's blend of
//! Eq. 1, `c111 = Σ a_i b_{111,i}`, `a_i = u_j u_k / (u_i u_j + u_i u_k + u_j u_k)`.
//!
//! Correction: the paper prints `c_ijk = h_ij b_{ijk,i} + h_ji b_{ijk,k} b_{ijk,j}`; its own
//! worked examples (`c012`, `c021`) and G¹ need the stray `b_{ijk,k}` dropped. Why this is G¹: on
//! `u_i = 0` every control point whose Bernstein function is O(1) or O(u_i) equals net i's
//! (`h = 1`, `a_i = 1`), and `h_ij = 1 − O(u_i²)` there, so `F` agrees with net i to first order
//! along edge i.

use glam::DVec3;

use crate::surface::pn::{Bernstein, Net, B111, NEAR};

/// How to read the boundary blend of seed 001 §3 (only the first is correct; the other is kept
/// so that a test can show it wrong).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BoundaryBlend {
    /// `c = h_ij b_{·,i} + h_ji b_{·,j}`, as in the paper's worked examples.
    #[default]
    Corrected,
    /// The printed `h_ji b_{·,k} b_{·,j}` read as `h_ji b_{·,k}`.
    PrintedStrayK,
}

/// How many control points one patch combines: the three corners, both candidates for each of
/// the six edge points (`b_{·,i}` and `b_{·,j}` of the boundary blend), and the three nets'
/// `b111`.
pub const TERMS: usize = 18;

/// The edge points in term order, as `(k, j)`: exponent 2 at corner k, 1 at j, 0 at `i = 3−j−k`.
const EDGE_SLOTS: [(usize, usize); 6] = [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)];

/// The patch at one domain point as coefficients on the [`TERMS`] control points [`gather`]
/// lists: `F = Σ value[n] p[n]`, `∂_u F = Σ du[n] p[n]`, `∂_v F = Σ dv[n] p[n]`.
///
/// `F(u) = Σ B_ijk(u) c_ijk(u)` with every `c_ijk` an affine combination of control points whose
/// weights depend on `u` only (Eq. 1–2), so `F` is linear in the nets with geometry-free
/// coefficients. They are computed once per lattice point and level and shared by every
/// triangle; a single point computes the same ones, so both paths agree bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    pub value: [f64; TERMS],
    pub du: [f64; TERMS],
    pub dv: [f64; TERMS],
}

/// The coefficients of [`Weights`] at barycentrics `l`. At a corner they are finite but
/// meaningless (the blends are 0/0 there); callers return the corner itself instead.
pub fn weights(l: [f64; 3]) -> Weights {
    let basis = Bernstein::at(l);
    let grad_to_uv = |g: [f64; 3]| (g[0] - g[2], g[1] - g[2]);
    let mut w = Weights {
        value: [0.0; TERMS],
        du: [0.0; TERMS],
        dv: [0.0; TERMS],
    };
    // Corners are constants: only their Bernstein factor varies.
    for (k, near) in NEAR.iter().enumerate() {
        let slot = near[k];
        w.value[k] = basis.value[slot];
        w.du[k] = basis.du[slot];
        w.dv[k] = basis.dv[slot];
    }
    // h[i][j] = h_ij with its gradient (in the three barycentrics); h_ji = 1 − h_ij.
    let mut h = [[(0.0, [0.0; 3]); 3]; 3];
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let (v, g) = edge_weight(l, i, j);
        h[i][j] = (v, g);
        h[j][i] = (1.0 - v, g.map(|x| -x));
    }
    // c = h_ij b_{·,i} + h_ji b_{·,j} (Eq. 2, corrected):
    // ∂(B c) = (∂B) c + B (∂h_ij)(b_{·,i} − b_{·,j}).
    for (e, &(k, j)) in EDGE_SLOTS.iter().enumerate() {
        let i = 3 - j - k;
        let slot = NEAR[k][j];
        let (hij, g) = h[i][j];
        let hji = h[j][i].0;
        let (gu, gv) = grad_to_uv(g);
        let (b, bu, bv) = (basis.value[slot], basis.du[slot], basis.dv[slot]);
        let (own, other) = (3 + 2 * e, 4 + 2 * e);
        w.value[own] = b * hij;
        w.value[other] = b * hji;
        w.du[own] = bu * hij + b * gu;
        w.du[other] = bu * hji - b * gu;
        w.dv[own] = bv * hij + b * gv;
        w.dv[other] = bv * hji - b * gv;
    }
    // c111 = Σ a_i b_{111,i} (Eq. 1).
    let (a, ga) = nielson(l);
    let (b, bu, bv) = (basis.value[B111], basis.du[B111], basis.dv[B111]);
    for i in 0..3 {
        let (gu, gv) = grad_to_uv(ga[i]);
        w.value[15 + i] = b * a[i];
        w.du[15 + i] = bu * a[i] + b * gu;
        w.dv[15 + i] = bv * a[i] + b * gv;
    }
    w
}

/// The [`TERMS`] control points of one triangle's three nets that [`Weights`] combine, in term
/// order: corners (from net 0; all three nets share them), then per edge point of
/// `EDGE_SLOTS` the one of net i and the one `blend` pairs it with, then the three `b111`.
pub fn gather(nets: &[Net; 3], blend: BoundaryBlend) -> [DVec3; TERMS] {
    let mut p = [DVec3::ZERO; TERMS];
    for k in 0..3 {
        p[k] = nets[0][NEAR[k][k]];
    }
    for (e, &(k, j)) in EDGE_SLOTS.iter().enumerate() {
        let i = 3 - j - k;
        let slot = NEAR[k][j];
        p[3 + 2 * e] = nets[i][slot];
        p[4 + 2 * e] = match blend {
            BoundaryBlend::Corrected => nets[j][slot],
            BoundaryBlend::PrintedStrayK => nets[k][slot],
        };
    }
    for i in 0..3 {
        p[15 + i] = nets[i][B111];
    }
    p
}

/// Position and its `∂_u`, `∂_v` derivatives from weights and gathered control points.
#[inline]
pub fn combine(w: &Weights, p: &[DVec3; TERMS]) -> [DVec3; 3] {
    let mut out = [DVec3::ZERO; 3];
    for (n, p) in p.iter().enumerate() {
        out[0] += w.value[n] * *p;
        out[1] += w.du[n] * *p;
        out[2] += w.dv[n] * *p;
    }
    out
}

/// Position and its derivatives along `∂_u = ∂/∂u − ∂/∂w` and `∂_v = ∂/∂v − ∂/∂w` (the
/// convention of [`Bernstein`]) at barycentrics `l`, which must not be a corner.
pub fn evaluate(nets: &[Net; 3], l: [f64; 3], blend: BoundaryBlend) -> [DVec3; 3] {
    combine(&weights(l), &gather(nets, blend))
}

/// Seed 001 Eq. 2, `h_ij(u)`, and its gradient. It is 0/0 only at corner k, where every point
/// it blends has a zero Bernstein factor; there it returns ½.
fn edge_weight(l: [f64; 3], i: usize, j: usize) -> (f64, [f64; 3]) {
    let (ui, uj) = (l[i], l[j]);
    let p = (1.0 - ui) * uj * uj;
    let q = (1.0 - uj) * ui * ui;
    let den = p + q;
    if den.abs() < 1e-300 {
        return (0.5, [0.0; 3]);
    }
    // ∂P/∂u_i = −u_j², ∂P/∂u_j = 2(1−u_i)u_j; ∂Q/∂u_i = 2(1−u_j)u_i, ∂Q/∂u_j = −u_i².
    let mut g = [0.0; 3];
    let d2 = den * den;
    g[i] = (-uj * uj * q - p * 2.0 * (1.0 - uj) * ui) / d2;
    g[j] = (2.0 * (1.0 - ui) * uj * q + p * ui * ui) / d2;
    (p / den, g)
}

/// Nielson's weights of seed 001 Eq. 1 alone, `a_i = u_j u_k / (u_i u_j + u_i u_k + u_j u_k)`:
/// net i's share of the interior point, exactly 1 on its edge `u_i = 0` and exactly 0 on the
/// other two edges (the products that vanish there are exact zeros). Not finite at a corner.
pub fn net_shares(l: [f64; 3]) -> [f64; 3] {
    let [u0, u1, u2] = l;
    let s = u0 * u1 + u0 * u2 + u1 * u2;
    [u1 * u2 / s, u0 * u2 / s, u0 * u1 / s]
}

/// Nielson's weights of seed 001 Eq. 1 with their gradients; 0/0 only at the corners, where
/// `b111`'s Bernstein factor vanishes (equal weights there).
fn nielson(l: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let [u0, u1, u2] = l;
    let s = u0 * u1 + u0 * u2 + u1 * u2;
    if s.abs() < 1e-300 {
        return ([1.0 / 3.0; 3], [[0.0; 3]; 3]);
    }
    let gs = [u1 + u2, u0 + u2, u0 + u1];
    let a = net_shares(l);
    let mut g = [[0.0; 3]; 3];
    for (i, gi) in g.iter_mut().enumerate() {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let n = l[j] * l[k];
        let mut gn = [0.0; 3];
        gn[j] = l[k];
        gn[k] = l[j];
        for c in 0..3 {
            gi[c] = (gn[c] * s - n * gs[c]) / (s * s);
        }
    }
    (a, g)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::pn::pn_net;

    fn nets() -> [Net; 3] {
        let p = [DVec3::ZERO, DVec3::X, DVec3::new(0.3, 1.0, 0.1)];
        let n = |x: f64, y: f64| DVec3::new(x, y, 1.0).normalize();
        [
            pn_net(p, [n(0.1, 0.0), n(0.0, 0.2), n(-0.1, 0.1)]),
            pn_net(p, [n(0.2, 0.1), n(0.0, -0.1), n(0.1, 0.3)]),
            pn_net(p, [n(-0.2, 0.0), n(0.1, 0.1), n(0.0, -0.2)]),
        ]
    }

    #[test]
    fn derivatives_match_central_differences() {
        let nets = nets();
        let e = 1e-6;
        for l in [[0.2, 0.3, 0.5], [0.01, 0.5, 0.49], [0.7, 0.05, 0.25]] {
            let [_, du, dv] = evaluate(&nets, l, BoundaryBlend::Corrected);
            let p = |l: [f64; 3]| evaluate(&nets, l, BoundaryBlend::Corrected)[0];
            let fu = (p([l[0] + e, l[1], l[2] - e]) - p([l[0] - e, l[1], l[2] + e])) / (2.0 * e);
            let fv = (p([l[0], l[1] + e, l[2] - e]) - p([l[0], l[1] - e, l[2] + e])) / (2.0 * e);
            assert!(
                (du - fu).length() < 1e-7 && (dv - fv).length() < 1e-7,
                "{l:?}"
            );
        }
    }

    #[test]
    fn edge_i_is_net_i() {
        let nets = nets();
        for i in 0..3 {
            let mut l = [0.3; 3];
            l[i] = 0.0;
            l[(i + 1) % 3] = 0.7;
            let got = evaluate(&nets, l, BoundaryBlend::Corrected)[0];
            let want = Bernstein::at(l).eval(&nets[i])[0];
            assert!((got - want).length() < 1e-15, "edge {i}");
        }
    }
}
