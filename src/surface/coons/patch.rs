//! One C¹ Coons-type patch (seed 002, Definition 2 as corrected): three constituent cubics
//! `r1, r2, r3` blended so that the patch interpolates `r_i` along edge i and joins it C¹ there.
//!
//! It deliberately knows nothing of the mesh or of where the constituents come from; it is
//! generic over [`Num`], so the same code gives positions (`f64`) and exact tangents
//! ([`Dual`]).
//!
//! With `x = (u, v, w)`, constituents `r_k` for the edge `x_k = 0` and shape parameters `λ_k`:
//!
//! ```text
//! μ1 = (1−λ1)w² / (λ1u² + (1−λ1)w²)   A1 = μ1 r1 + (1−μ1) r3        (blends, §1)
//! μ2 = (1−λ2)u² / (λ2v² + (1−λ2)u²)   A2 = μ2 r2 + (1−μ2) r1
//! μ3 = (1−λ3)v² / (λ3w² + (1−λ3)v²)   A3 = μ3 r3 + (1−μ3) r2
//! g1 = A3(0, v, 1−v)   g2 = A1(1−w, 0, w)   g3 = A2(u, 1−u, 0)   (auxiliary curves)
//! E1 = D1·∇A3 at g1's point, D1 = (1, 0, −1); E2: D2 = (−1, 1, 0); E3: D3 = (0, −1, 1)
//! Σ = v²w² + u²w² + u²v²,  q = (v²w² g1 + u²w² g2 + u²v² g3)/Σ      (Eq. 4)
//! κ1 = u v²w²/Σ,  κ2 = v u²w²/Σ,  κ3 = w u²v²/Σ                     (Eq. 10)
//! f = ½(A1 + A2 + A3 − q) − ½(κ1 E1 + κ2 E2 + κ3 E3)                 (Eq. 11, corrected)
//! ```
//!
//! Corrections to the paper, each shown wrong by `tests/integration/schemes_typos.rs`:
//! - Eq. 11 prints `f = ½[…] − q − s`; `q` belongs inside the bracket as in Eq. 3, else the patch
//!   does not even interpolate its boundary curves.
//! - Eq. 9's coefficients `μ3 r3u + (1−μ3) r2u` omit the derivative of the blend itself: the
//!   correct one is `D1·∇A3 = μ3 D1r3 + (1−μ3) D1r2 + (D1μ3)(r3 − r2)`, and `r3 ≠ r2` on `u = 0`.
//! - Its partial derivatives "with barycentric coordinates" are only meaningful along in-plane
//!   directions that keep the auxiliary curve's parameter fixed: `D1` keeps `v`, `D2` keeps `w`,
//!   `D3` keeps `u`.
//! - `g2` is keyed by `w` (the paper's `g2(u, 0, 1−u)` is keyed by `u`), so that the patch is
//!   invariant under cyclic relabelling of its corners; both keys are C¹.
//!
//! Why it is C¹ (the paper defers it): on `u = 0` with `v, w > 0` the terms `1−μ1`, `μ2`, `κ2`,
//! `κ3` and the `g2`, `g3` weights are O(u²), the `g1` weight is `1 − O(u²)` and `κ1 = u + O(u³)`.
//! So `f = r1` there and `d f = d r1 + ½ d(A3 − q) − ½ (d u) E1`; since `A3 − q` vanishes on the
//! edge and `D1 q = 0`, `d(A3 − q) = (d u) E1` and `d f = d r1`. The other edges follow
//! cyclically. All of `μ`, `Σ`, `κ` are 0/0 only at the corners, which callers must not pass.

use super::dual::{Dual, Num};
use crate::surface::pn::Net;

/// A point or vector with coordinates in `T`.
pub type V3<T> = [T; 3];

/// How to read seed 002's Definition 2. Only [`Definition2::Corrected`] is C¹; the printed
/// readings exist so that tests can show each correction is needed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Definition2 {
    #[default]
    Corrected,
    /// Eq. 11 as printed: `f = ½[A1 + A2 + A3] − q − s`.
    PrintedQOutside,
    /// Eq. 9 as printed: `E1 = μ3 D1r3 + (1−μ3) D1r2`, without `(D1μ3)(r3 − r2)`.
    PrintedCorrection,
}

/// The patch at barycentrics `x` (not a corner) from constituent nets `r` (net k for the edge
/// opposite corner k) and shape parameters `lambda`.
pub fn point<T: Num>(r: &[Net; 3], lambda: [f64; 3], x: V3<T>, def: Definition2) -> V3<T> {
    point_at(&sample(r, x), lambda, def)
}

/// Everything [`point`] needs at one `x` that does not depend on λ: the constituents at `x` and,
/// for each auxiliary curve, its point and the two constituents there with their cross
/// derivatives. The fairing evaluates one patch at the same points for a hundred values of λ;
/// these cubics were most of that work.
#[derive(Debug, Clone, Copy)]
pub struct Sample<T: Num> {
    x: V3<T>,
    rx: [V3<T>; 3],
    aux: [Auxiliary<T>; 3],
}

/// The point `y` of auxiliary curve `g_{k+1}` (with direction `D_{k+1}` as its derivative) and
/// the constituents its blend `A_{a+1}`, `a = k + 2`, combines there.
#[derive(Debug, Clone, Copy)]
struct Auxiliary<T: Num> {
    y: V3<Dual<T, 1>>,
    first: V3<Dual<T, 1>>,
    second: V3<Dual<T, 1>>,
}

/// The λ-free part of the patch at `x` (see [`Sample`]).
pub fn sample<T: Num>(r: &[Net; 3], x: V3<T>) -> Sample<T> {
    Sample {
        x,
        rx: [cubic(&r[0], x), cubic(&r[1], x), cubic(&r[2], x)],
        aux: std::array::from_fn(|k| auxiliary_sample(k, r, x)),
    }
}

/// The patch at a [`Sample`]'s point for shape parameters `lambda`: the same arithmetic, in the
/// same order, as [`point`] there.
pub fn point_at<T: Num>(at: &Sample<T>, lambda: [f64; 3], def: Definition2) -> V3<T> {
    let (x, rx) = (at.x, &at.rx);
    let mut sum_a = [T::cst(0.0); 3];
    for k in 0..3 {
        sum_a = add(sum_a, blend(k, rx, lambda, x));
    }
    let sq = x.map(|c| c * c);
    let sigma: [T; 3] = std::array::from_fn(|k| sq[(k + 1) % 3] * sq[(k + 2) % 3]);
    let total = sigma[0] + sigma[1] + sigma[2];
    let mut q = [T::cst(0.0); 3];
    let mut s = [T::cst(0.0); 3];
    for k in 0..3 {
        let (g, e) = auxiliary(k, &at.aux[k], lambda, def);
        q = add(q, mul(sigma[k] / total, g));
        s = add(s, mul(x[k] * sigma[k] / total, e));
    }
    let half = |v: V3<T>| v.map(|c| c.scale(0.5));
    match def {
        Definition2::PrintedQOutside => sub(sub(half(sum_a), q), half(s)),
        _ => sub(half(sub(sum_a, q)), half(s)),
    }
}

/// The cubic Bézier triangle with net `net` at `x`.
#[inline]
pub fn cubic<T: Num>(net: &Net, x: V3<T>) -> V3<T> {
    let b = bernstein(x);
    let mut out = [T::cst(0.0); 3];
    for (bm, p) in b.iter().zip(net) {
        out[0] = out[0] + bm.scale(p.x);
        out[1] = out[1] + bm.scale(p.y);
        out[2] = out[2] + bm.scale(p.z);
    }
    out
}

/// The cubic Bernstein basis at `x`, in `pn::IJK` order:
/// b300 b030 b003 b210 b120 b021 b012 b102 b201 b111.
#[inline]
pub fn bernstein<T: Num>([u, v, w]: V3<T>) -> [T; 10] {
    let (u2, v2, w2) = (u * u, v * v, w * w);
    [
        u2 * u,
        v2 * v,
        w2 * w,
        (u2 * v).scale(3.0),
        (u * v2).scale(3.0),
        (v2 * w).scale(3.0),
        (v * w2).scale(3.0),
        (u * w2).scale(3.0),
        (u2 * w).scale(3.0),
        (u * v * w).scale(6.0),
    ]
}

/// `μ = (1−λ)b² / (λa² + (1−λ)b²)`, the shape of every `μ_k`.
#[inline]
pub(super) fn mu<T: Num>(lambda: f64, a: T, b: T) -> T {
    let bb = (b * b).scale(1.0 - lambda);
    bb / ((a * a).scale(lambda) + bb)
}

/// `A_{k+1} = μ r_{k+1} + (1−μ) r_k'` from the constituents' values `rx` at `x`: `μ` weighs
/// `x_k` against `x_{k+2}`, and the second constituent is `r_{k+2}` (0-based, cyclic).
#[inline]
fn blend<T: Num>(k: usize, rx: &[V3<T>; 3], lambda: [f64; 3], x: V3<T>) -> V3<T> {
    let m = mu(lambda[k], x[k], x[(k + 2) % 3]);
    let (first, second) = (rx[k], rx[(k + 2) % 3]);
    add(second, mul(m, sub(first, second)))
}

/// The λ-free part of auxiliary curve `g_{k+1}` at `x`: its point, the parallel projection of
/// `x` onto edge k (`π` has `x_k = 0` and keeps `x_{k+1}`), carrying the direction `D` (+1 at k,
/// −1 at k+2) as its derivative, and the constituents of its blend there.
fn auxiliary_sample<T: Num>(k: usize, r: &[Net; 3], x: V3<T>) -> Auxiliary<T> {
    let key = x[(k + 1) % 3];
    let mut pi = [T::cst(0.0); 3];
    pi[(k + 1) % 3] = key;
    pi[(k + 2) % 3] = T::cst(1.0) - key;
    let mut dir = [0.0; 3];
    dir[k] = 1.0;
    dir[(k + 2) % 3] = -1.0;
    let y: V3<Dual<T, 1>> = std::array::from_fn(|c| Dual::new(pi[c], [T::cst(dir[c])]));
    // g_{k+1} uses the blend A_{a+1} with a = k + 2.
    let a = (k + 2) % 3;
    Auxiliary {
        y,
        first: cubic(&r[a], y),
        second: cubic(&r[(a + 2) % 3], y),
    }
}

/// Auxiliary curve `g_{k+1}` and its cross derivative `E_{k+1}` from its λ-free part.
fn auxiliary<T: Num>(
    k: usize,
    at: &Auxiliary<T>,
    lambda: [f64; 3],
    def: Definition2,
) -> (V3<T>, V3<T>) {
    let a = (k + 2) % 3;
    let (y, first, second) = (at.y, at.first, at.second);
    let m = mu(lambda[a], y[a], y[(a + 2) % 3]);
    let value = add(second, mul(m, sub(first, second)));
    let g = value.map(|c| c.v);
    let e = match def {
        Definition2::PrintedCorrection => {
            let (mv, one) = (m.v, T::cst(1.0));
            std::array::from_fn(|c| mv * first[c].d[0] + (one - mv) * second[c].d[0])
        }
        _ => value.map(|c| c.d[0]),
    };
    (g, e)
}

#[inline]
fn add<T: Num>(a: V3<T>, b: V3<T>) -> V3<T> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
fn sub<T: Num>(a: V3<T>, b: V3<T>) -> V3<T> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
fn mul<T: Num>(s: T, a: V3<T>) -> V3<T> {
    [s * a[0], s * a[1], s * a[2]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::pn::{pn_net, Bernstein};
    use glam::DVec3;

    fn nets() -> [Net; 3] {
        let p = [DVec3::ZERO, DVec3::X, DVec3::new(0.3, 1.0, 0.1)];
        let n = |x: f64, y: f64| DVec3::new(x, y, 1.0).normalize();
        [
            pn_net(p, [n(0.1, 0.0), n(0.0, 0.2), n(-0.1, 0.1)]),
            pn_net(p, [n(0.2, 0.1), n(0.0, -0.1), n(0.1, 0.3)]),
            pn_net(p, [n(-0.2, 0.0), n(0.1, 0.1), n(0.0, -0.2)]),
        ]
    }

    fn v(a: V3<f64>) -> DVec3 {
        DVec3::from_array(a)
    }

    #[test]
    fn cubic_is_the_bernstein_patch() {
        let net = nets()[1];
        let l = [0.2, 0.3, 0.5];
        let want = Bernstein::at(l).eval(&net)[0];
        assert!((v(cubic(&net, l)) - want).length() < 1e-15);
    }

    #[test]
    fn interpolates_and_joins_each_constituent_to_first_order() {
        let r = nets();
        let lam = [0.3, 0.5, 0.7];
        let f = |l: [f64; 3]| v(point(&r, lam, l, Definition2::Corrected));
        for k in 0..3 {
            let mut l = [0.0; 3];
            l[(k + 1) % 3] = 0.35;
            l[(k + 2) % 3] = 0.65;
            let want = v(cubic(&r[k], l));
            assert!((f(l) - want).length() < 1e-14, "edge {k}");
            // Inward difference quotient: f − r_k = O(e²).
            let e = 1e-4;
            let mut inside = l;
            inside[k] += e;
            inside[(k + 1) % 3] -= e;
            let gap = (f(inside) - v(cubic(&r[k], inside))).length();
            assert!(gap < 1e-6, "edge {k}: {gap}");
        }
    }

    #[test]
    fn dual_tangents_match_central_differences() {
        let r = nets();
        let lam = [0.5; 3];
        let l = [0.2, 0.3, 0.5];
        let x = [
            Dual::new(l[0], [1.0, 0.0]),
            Dual::new(l[1], [0.0, 1.0]),
            Dual::new(l[2], [-1.0, -1.0]),
        ];
        let d = point(&r, lam, x, Definition2::Corrected);
        let e = 1e-6;
        let f = |l: [f64; 3]| v(point(&r, lam, l, Definition2::Corrected));
        let fu = (f([l[0] + e, l[1], l[2] - e]) - f([l[0] - e, l[1], l[2] + e])) / (2.0 * e);
        let du = DVec3::new(d[0].d[0], d[1].d[0], d[2].d[0]);
        assert!((du - fu).length() < 1e-8);
        assert_eq!(DVec3::new(d[0].v, d[1].v, d[2].v), f(l));
    }
}
