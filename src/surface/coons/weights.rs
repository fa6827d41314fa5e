//! The Coons patch of [`super::patch`] as weights on its 30 control points: `f(x)` of seed 002
//! Eq. 11 (as corrected) is linear in the three constituent nets, with coefficients that depend
//! only on the domain point `x`, the shape parameters `λ` and the reading of Definition 2.
//!
//! It deliberately holds no geometry: the weights of a whole lattice are computed once per
//! (level, λ, definition) and shared by every triangle with those parameters, which then costs
//! 90 multiply-adds per coordinate and point instead of a pass of nested dual numbers through
//! the whole patch.
//!
//! Each term of [`super::patch::point`] is linear in the nets:
//! - `A_k = μ_k r_k + (1−μ_k) r_{k+2}` (0-based, cyclic), so `ΣA` puts `μ_j + 1 − μ_{j+1}` on
//!   `r_j(x)`, that is on each Bernstein value of net j at x;
//! - `g_k = (1−μ) r_{k+1}(π_k) + μ r_{k+2}(π_k)` with `μ` the blend at the projection `π_k`;
//! - `E_k = D_k[(1−μ) r_{k+1} + μ r_{k+2}]` at `π_k`: the directional derivative of those
//!   weights, `μ D r + (D μ) r` (corrected Eq. 9), or `μ D r` alone for the printed reading.
//!
//! Derivatives come from running the same code on dual numbers seeded with the two canonical
//! edge directions `∂_0 = ∂/∂x_0 − ∂/∂x_2` and `∂_1 = ∂/∂x_1 − ∂/∂x_2`; a triangle whose
//! canonical order differs from its input order maps them to its own `∂_u`, `∂_v` afterwards
//! (each is `±∂_0`, `±∂_1` or a sum of the two).

use glam::DVec3;

use super::dual::{Dual, Num};
use super::patch::{bernstein, mu, Definition2, V3};
use crate::surface::pn::Net;

/// Control points of the three constituents: net k's slot m is term `10k + m`.
pub const TERMS: usize = 30;

/// The patch at one domain point as coefficients on the [`TERMS`] control points: `f = Σ
/// value[n] p[n]`, `∂_0 f = Σ d0[n] p[n]`, `∂_1 f = Σ d1[n] p[n]` along the canonical edge
/// directions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    pub value: [f64; TERMS],
    pub d0: [f64; TERMS],
    pub d1: [f64; TERMS],
}

impl Weights {
    /// The weights at canonical barycentrics `x` (not a corner) for parameters `lambda`.
    pub fn at(lambda: [f64; 3], x: [f64; 3], def: Definition2) -> Weights {
        const SEED: [[f64; 2]; 3] = [[1.0, 0.0], [0.0, 1.0], [-1.0, -1.0]];
        let x: V3<Dual<f64, 2>> = std::array::from_fn(|c| Dual::new(x[c], SEED[c]));
        let w = coefficients(lambda, x, def);
        Weights {
            value: w.map(|c| c.v),
            d0: w.map(|c| c.d[0]),
            d1: w.map(|c| c.d[1]),
        }
    }

    /// Position and its `∂_0`, `∂_1` derivatives of the patch with constituents `nets`.
    #[inline]
    pub fn combine(&self, nets: &[Net; 3]) -> [DVec3; 3] {
        let mut out = [DVec3::ZERO; 3];
        for (n, p) in nets.as_flattened().iter().enumerate() {
            out[0] += self.value[n] * *p;
            out[1] += self.d0[n] * *p;
            out[2] += self.d1[n] * *p;
        }
        out
    }
}

/// The patch's position alone at canonical barycentrics `x`: the same value, bit for bit, as
/// the position [`Weights::combine`] gives (the value parts of dual numbers are computed by the
/// same operations, and the sum runs in the same order).
pub fn position(lambda: [f64; 3], x: [f64; 3], def: Definition2, nets: &[Net; 3]) -> DVec3 {
    let w = coefficients(lambda, x, def);
    let mut out = DVec3::ZERO;
    for (n, p) in nets.as_flattened().iter().enumerate() {
        out += w[n] * *p;
    }
    out
}

/// The coefficient of each control point in `f(x)` (seed 002 Eq. 11 as corrected, or a printed
/// reading), in the arithmetic `T` (`f64` for values, [`Dual`] for derivatives too).
pub fn coefficients<T: Num>(lambda: [f64; 3], x: V3<T>, def: Definition2) -> [T; TERMS] {
    let one = T::cst(1.0);
    let bx = bernstein(x);
    let mu_x: [T; 3] = std::array::from_fn(|k| mu(lambda[k], x[k], x[(k + 2) % 3]));
    let sq = x.map(|c| c * c);
    let sigma: [T; 3] = std::array::from_fn(|k| sq[(k + 1) % 3] * sq[(k + 2) % 3]);
    let total = sigma[0] + sigma[1] + sigma[2];
    // f = ½(ΣA − q) − ½ s; as printed, ½ΣA − q − ½ s.
    let q_factor = match def {
        Definition2::PrintedQOutside => 1.0,
        _ => 0.5,
    };

    let mut w = [T::cst(0.0); TERMS];
    for j in 0..3 {
        // r_j is the first constituent of A_j and the second of A_{j+1}.
        let alpha = (mu_x[j] + (one - mu_x[(j + 1) % 3])).scale(0.5);
        for m in 0..10 {
            w[10 * j + m] = alpha * bx[m];
        }
    }
    for k in 0..3 {
        let cq = (sigma[k] / total).scale(q_factor);
        let cs = (x[k] * sigma[k] / total).scale(0.5);
        // π_k: x_k = 0, keeps x_{k+1}; D_k has +1 at k and −1 at k+2 (see `patch::auxiliary`).
        let key = x[(k + 1) % 3];
        let mut pi = [T::cst(0.0); 3];
        pi[(k + 1) % 3] = key;
        pi[(k + 2) % 3] = one - key;
        let mut dir = [0.0; 3];
        dir[k] = 1.0;
        dir[(k + 2) % 3] = -1.0;
        let y: V3<Dual<T, 1>> = std::array::from_fn(|c| Dual::new(pi[c], [T::cst(dir[c])]));
        // g_{k+1} blends r_a (weight μ) with r_b, a = k + 2, b = k + 1.
        let (a, b) = ((k + 2) % 3, (k + 1) % 3);
        let m = mu(lambda[a], y[a], y[b]);
        let not_m = Dual::cst(1.0) - m;
        let by = bernstein(y);
        for s in 0..10 {
            let (wa, wb) = (m * by[s], not_m * by[s]);
            let (ea, eb) = match def {
                Definition2::PrintedCorrection => (m.v * by[s].d[0], not_m.v * by[s].d[0]),
                _ => (wa.d[0], wb.d[0]),
            };
            w[10 * a + s] = w[10 * a + s] - cq * wa.v - cs * ea;
            w[10 * b + s] = w[10 * b + s] - cq * wb.v - cs * eb;
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::coons::patch::point;
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
    fn weights_reproduce_the_patch_and_its_tangents_for_every_reading() {
        let r = nets();
        let lam = [0.3, 0.5, 0.7];
        for def in [
            Definition2::Corrected,
            Definition2::PrintedQOutside,
            Definition2::PrintedCorrection,
        ] {
            for l in [[0.2, 0.3, 0.5], [0.0, 0.35, 0.65], [0.9, 0.05, 0.05]] {
                let x = [
                    Dual::new(l[0], [1.0, 0.0]),
                    Dual::new(l[1], [0.0, 1.0]),
                    Dual::new(l[2], [-1.0, -1.0]),
                ];
                let want = point(&r, lam, x, def);
                let [p, d0, d1] = Weights::at(lam, l, def).combine(&r);
                let got = [p, d0, d1].map(|v| v.to_array());
                for c in 0..3 {
                    let w = [want[c].v, want[c].d[0], want[c].d[1]];
                    for (g, w) in [got[0][c], got[1][c], got[2][c]].iter().zip(w) {
                        assert!((g - w).abs() < 1e-13, "{def:?} {l:?}: {g} against {w}");
                    }
                }
            }
        }
    }

    #[test]
    fn weights_of_every_constituent_sum_to_an_affine_combination() {
        // f reproduces constants: the weights sum to 1 and their derivatives to 0.
        let w = Weights::at([0.4, 0.5, 0.6], [0.25, 0.35, 0.4], Definition2::Corrected);
        let sum = |a: &[f64; TERMS]| a.iter().sum::<f64>();
        assert!((sum(&w.value) - 1.0).abs() < 1e-14);
        assert!(sum(&w.d0).abs() < 1e-13 && sum(&w.d1).abs() < 1e-13);
    }
}
