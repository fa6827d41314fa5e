//! The cubic Bézier triangle of one mesh triangle: its PN control net (paper Eq. 1–2), the
//! Bernstein basis with its derivatives, and the blossom that re-expresses a neighbour's patch in
//! this triangle's barycentrics.
//!
//! It deliberately knows nothing of blending or of the mesh: nets in, points out.
//!
//! Control net (paper Fig. 2, corners `p1, p2, p3` at `(u, v, w)` = (1,0,0), (0,1,0), (0,0,1)):
//!
//! ```text
//!                 b003
//!             b102     b012
//!         b201     b111     b021
//!     b300     b210     b120     b030
//! ```
//!
//! Stored in the order `[b300, b030, b003, b210, b120, b021, b012, b102, b201, b111]` ([`IJK`]).

use glam::DVec3;

/// Exponents `(i, j, k)` of `u^i v^j w^k` for each slot of a [`Net`].
pub const IJK: [[usize; 3]; 10] = [
    [3, 0, 0],
    [0, 3, 0],
    [0, 0, 3],
    [2, 1, 0],
    [1, 2, 0],
    [0, 2, 1],
    [0, 1, 2],
    [1, 0, 2],
    [2, 0, 1],
    [1, 1, 1],
];

/// `NEAR[c][e]`: slot of the edge control point next to corner `c` on the edge towards `e`.
pub const NEAR: [[usize; 3]; 3] = [[0, 3, 8], [4, 1, 5], [7, 6, 2]];

/// Slot of the central control point `b111`.
pub const B111: usize = 9;

/// The ten control points of a cubic Bézier triangle, in [`IJK`] order.
pub type Net = [DVec3; 10];

/// PN control net of paper Eq. 2 (Vlachos et al. 2001) from corner positions and unit normals.
///
/// `E` is the mean of all six edge control points: the paper's Eq. 2 lists five (it drops
/// `b021`) but divides by 6 (notes item 2).
pub fn pn_net(p: [DVec3; 3], n: [DVec3; 3]) -> Net {
    let mut net = [DVec3::ZERO; 10];
    for c in 0..3 {
        net[NEAR[c][c]] = p[c];
        for e in (0..3).filter(|&e| e != c) {
            // b_ce = (2 p_c + p_e - w_ce n_c) / 3, w_ce = (p_e - p_c) · n_c.
            let w = (p[e] - p[c]).dot(n[c]);
            net[NEAR[c][e]] = (2.0 * p[c] + p[e] - w * n[c]) / 3.0;
        }
    }
    net[B111] = central_point(&net);
    net
}

/// `b111 = E + (E - V)/2` (Eq. 2) from the six edge control points already in `net`.
pub fn central_point(net: &Net) -> DVec3 {
    let e = net[3..9].iter().copied().sum::<DVec3>() / 6.0;
    let v = (net[0] + net[1] + net[2]) / 3.0;
    e + (e - v) / 2.0
}

/// Bernstein values `B_ijk(u, v, w) = 3!/(i! j! k!) u^i v^j w^k` (Eq. 1) and their derivatives
/// along `∂_u = ∂/∂u − ∂/∂w` and `∂_v = ∂/∂v − ∂/∂w`, the two edge directions of the domain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bernstein {
    pub value: [f64; 10],
    pub du: [f64; 10],
    pub dv: [f64; 10],
}

impl Bernstein {
    /// The basis at barycentrics `(u, v, w)` (extended homogeneously off the plane u+v+w = 1).
    pub fn at(l: [f64; 3]) -> Bernstein {
        // pow[c][e] = l[c]^e; dpow[c][e] = d/dl[c] of l[c]^e.
        let pow = l.map(|x| [1.0, x, x * x, x * x * x]);
        let dpow = l.map(|x| [0.0, 1.0, 2.0 * x, 3.0 * x * x]);
        let mut b = Bernstein {
            value: [0.0; 10],
            du: [0.0; 10],
            dv: [0.0; 10],
        };
        for (m, &[i, j, k]) in IJK.iter().enumerate() {
            let c = 6.0 / (FACT[i] * FACT[j] * FACT[k]);
            let (pu, pv, pw) = (pow[0][i], pow[1][j], pow[2][k]);
            let gw = c * pu * pv * dpow[2][k];
            b.value[m] = c * pu * pv * pw;
            b.du[m] = c * dpow[0][i] * pv * pw - gw;
            b.dv[m] = c * pu * dpow[1][j] * pw - gw;
        }
        b
    }

    /// Position and its `∂_u`, `∂_v` derivatives of the patch with control net `net`.
    #[inline]
    pub fn eval(&self, net: &Net) -> [DVec3; 3] {
        let mut out = [DVec3::ZERO; 3];
        for (m, p) in net.iter().enumerate() {
            out[0] += self.value[m] * *p;
            out[1] += self.du[m] * *p;
            out[2] += self.dv[m] * *p;
        }
        out
    }
}

const FACT: [f64; 4] = [1.0, 1.0, 2.0, 6.0];

/// The control net, in this triangle's barycentrics λ, of `b_g(Mλ)`, where `M` is linear and
/// `cols[c] = M e_c` (g's barycentrics of this triangle's corner `c`).
///
/// `b_g ∘ M` is again a cubic in λ; its control points are blossom values of `b_g` at the
/// columns of `M`, `c_ijk = 𝔟_g(M e_0 ×i, M e_1 ×j, M e_2 ×k)`. The neighbour map of Eq. 3 (as
/// corrected in the notes, item 3) has small-integer columns, so this is exact up to rounding,
/// and it is done per lattice part that blends across the edge (or per blended point): afterwards
/// both patches share one set of Bernstein values.
///
/// The ten blossom values share their first steps: one de Casteljau step per column gives three
/// quadratic nets, four more steps the linear nets the ten values are read from (120 vector
/// multiply-adds, no branches; evaluating each blossom on its own took 270 branchy terms and
/// was the largest cost of building a surface).
pub fn compose(net_g: &Net, cols: [[f64; 3]; 3]) -> Net {
    let [c0, c1, c2] = cols;
    let (q0, q1, q2) = (
        lower_to_quadratic(net_g, c0),
        lower_to_quadratic(net_g, c1),
        lower_to_quadratic(net_g, c2),
    );
    let (l00, l11, l22, l01) = (
        lower_to_linear(&q0, c0),
        lower_to_linear(&q1, c1),
        lower_to_linear(&q2, c2),
        lower_to_linear(&q0, c1),
    );
    let point = |l: [DVec3; 3], x: [f64; 3]| x[0] * l[0] + x[1] * l[1] + x[2] * l[2];
    // In IJK order: b300, b030, b003, b210, b120, b021, b012, b102, b201, b111.
    [
        point(l00, c0),
        point(l11, c1),
        point(l22, c2),
        point(l00, c1),
        point(l11, c0),
        point(l11, c2),
        point(l22, c1),
        point(l22, c0),
        point(l00, c2),
        point(l01, c2),
    ]
}

/// One de Casteljau step with argument `x` (the blossom with one argument fixed): the quadratic
/// net `q_e = Σ_c x_c b_{e + e_c}`, indexed `[i][j]` with `k = 2 − i − j`.
fn lower_to_quadratic(net: &Net, x: [f64; 3]) -> [[DVec3; 3]; 3] {
    let mut q = [[DVec3::ZERO; 3]; 3];
    for i in 0..3 {
        for j in 0..3 - i {
            let k = 2 - i - j;
            q[i][j] = x[0] * net[slot([i + 1, j, k])]
                + x[1] * net[slot([i, j + 1, k])]
                + x[2] * net[slot([i, j, k + 1])];
        }
    }
    q
}

/// The next step: the linear net `[l_100, l_010, l_001]` from a quadratic one.
fn lower_to_linear(q: &[[DVec3; 3]; 3], x: [f64; 3]) -> [DVec3; 3] {
    [
        x[0] * q[2][0] + x[1] * q[1][1] + x[2] * q[1][0],
        x[0] * q[1][1] + x[1] * q[0][2] + x[2] * q[0][1],
        x[0] * q[1][0] + x[1] * q[0][1] + x[2] * q[0][0],
    ]
}

/// Slot in [`IJK`] order of the control point with exponents `e`.
fn slot(e: [usize; 3]) -> usize {
    SLOT[e[0]][e[1]] as usize
}

/// The inverse of [`IJK`], indexed by the first two exponents (the third is 3 minus both).
const SLOT: [[u8; 4]; 4] = {
    let mut table = [[u8::MAX; 4]; 4];
    let mut m = 0;
    while m < IJK.len() {
        table[IJK[m][0]][IJK[m][1]] = m as u8;
        m += 1;
    }
    table
};

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_net() -> Net {
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.1, 0.2),
            DVec3::new(0.2, 1.0, -0.1),
        ];
        let n = [
            DVec3::new(0.1, -0.2, 1.0),
            DVec3::new(-0.3, 0.1, 1.0),
            DVec3::new(0.2, 0.3, 1.0),
        ]
        .map(DVec3::normalize);
        pn_net(p, n)
    }

    #[test]
    fn partition_of_unity_and_zero_sum_derivatives() {
        let b = Bernstein::at([0.2, 0.3, 0.5]);
        assert!((b.value.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!(b.du.iter().sum::<f64>().abs() < 1e-14);
        assert!(b.dv.iter().sum::<f64>().abs() < 1e-14);
    }

    #[test]
    fn derivatives_match_central_differences() {
        let net = sample_net();
        let l = [0.2, 0.3, 0.5];
        let [_, du, dv] = Bernstein::at(l).eval(&net);
        let h = 1e-6;
        let p = |l: [f64; 3]| Bernstein::at(l).eval(&net)[0];
        let fu = (p([l[0] + h, l[1], l[2] - h]) - p([l[0] - h, l[1], l[2] + h])) / (2.0 * h);
        let fv = (p([l[0], l[1] + h, l[2] - h]) - p([l[0], l[1] - h, l[2] + h])) / (2.0 * h);
        assert!((du - fu).length() < 1e-8 && (dv - fv).length() < 1e-8);
    }

    /// The blossom summed term by term from its definition.
    fn blossom(net: &Net, [x, y, z]: [[f64; 3]; 3]) -> DVec3 {
        let mut sum = DVec3::ZERO;
        for (a, &xa) in x.iter().enumerate() {
            for (b, &yb) in y.iter().enumerate() {
                for (c, &zc) in z.iter().enumerate() {
                    let mut e = [0usize; 3];
                    e[a] += 1;
                    e[b] += 1;
                    e[c] += 1;
                    sum += xa * yb * zc * net[slot(e)];
                }
            }
        }
        sum
    }

    #[test]
    fn composition_equals_the_blossom_definition_for_any_map() {
        let net = sample_net();
        // A neighbour map of Eq. 3 (small integers) and a generic one.
        for cols in [
            [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, -1.0]],
            [[0.3, -0.2, 0.9], [0.5, 0.25, 0.25], [-0.1, 0.7, 0.4]],
        ] {
            let c = compose(&net, cols);
            for (m, &[i, j, k]) in IJK.iter().enumerate() {
                let mut args = Vec::new();
                for (col, times) in cols.iter().zip([i, j, k]) {
                    args.extend(std::iter::repeat_n(*col, times));
                }
                let direct = blossom(&net, [args[0], args[1], args[2]]);
                assert!(
                    (c[m] - direct).length() < 1e-14,
                    "slot {m}: {} vs {direct}",
                    c[m]
                );
            }
        }
    }

    #[test]
    fn composing_with_a_permutation_relabels_the_patch() {
        // M maps corner c to g's corner perm[c]: b_g(Mλ) at λ must equal b_g at permuted λ.
        let net = sample_net();
        let perm = [2, 0, 1];
        let cols = perm.map(|p| {
            let mut e = [0.0; 3];
            e[p] = 1.0;
            e
        });
        let c = compose(&net, cols);
        let l = [0.2, 0.3, 0.5];
        let mut mu = [0.0; 3];
        for k in 0..3 {
            mu[perm[k]] = l[k];
        }
        let a = Bernstein::at(l).eval(&c)[0];
        let b = Bernstein::at(mu).eval(&net)[0];
        assert!((a - b).length() < 1e-15);
    }
}
