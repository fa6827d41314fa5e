//! Fairing of the Coons shape parameters (seed 002 Eq. 5): per triangle, the `(λ1, λ2, λ3)` that
//! minimise the linearised thin-plate energy `∫ |f_uu|² + 2|f_uv|² + |f_vv|²` of the patch.
//!
//! It deliberately stays local and deterministic (no global solve, no randomness): a fixed
//! quadrature and a fixed number of golden-section steps per coordinate.
//!
//! Corrections: Eq. 5 integrates over `A = [0,1]²`, but `f(u, v, 1−u−v)` is defined on the
//! triangle only, so the integral is over `u, v ≥ 0, u + v ≤ 1`. Quadrature: the 15 interior
//! points of the level-7 lattice, equal weights (the paper used 9 inner points). Second
//! derivatives by central differences of positions with step [`STEP`].
//!
//! The search is bounded to [`super::CoonsSurface::FAIR_RANGE`]: with wider bounds λ runs to the
//! ends, where μ changes sharply near the corners, which the quadrature does not see.

use super::patch::{point_at, sample, Definition2, Sample};
use crate::surface::pn::Net;

/// Central-difference step for the second derivatives (barycentric units).
pub const STEP: f64 = 1e-3;

/// Golden-section steps per coordinate and sweep.
const GOLDEN_STEPS: usize = 14;
const SWEEPS: usize = 2;

/// The thin-plate energy of the patch with constituents `r` and parameters `lambda`, up to a
/// constant factor (the quadrature's area weight).
pub fn energy(r: &[Net; 3], lambda: [f64; 3]) -> f64 {
    Quadrature::new(r).energy(lambda)
}

/// The patch's λ-free parts at every point the energy's quadrature and differences read: per
/// quadrature point, the centre and its eight neighbours at ±[`STEP`]. Built once per triangle,
/// so that each of the search's hundred energies only blends.
struct Quadrature {
    stencils: Vec<[Sample<f64>; 9]>,
}

impl Quadrature {
    fn new(r: &[Net; 3]) -> Self {
        let at = |l: [f64; 3], a: f64, b: f64| sample(r, [l[0] + a, l[1] + b, l[2] - a - b]);
        let n = 7;
        let h = STEP;
        let mut stencils = Vec::with_capacity(15);
        for j in 1..n {
            for i in 1..n - j {
                let l = [
                    (n - i - j) as f64 / n as f64,
                    i as f64 / n as f64,
                    j as f64 / n as f64,
                ];
                stencils.push([
                    at(l, 0.0, 0.0),
                    at(l, h, 0.0),
                    at(l, -h, 0.0),
                    at(l, 0.0, h),
                    at(l, 0.0, -h),
                    at(l, h, h),
                    at(l, h, -h),
                    at(l, -h, h),
                    at(l, -h, -h),
                ]);
            }
        }
        Quadrature { stencils }
    }

    fn energy(&self, lambda: [f64; 3]) -> f64 {
        let f = |s: &Sample<f64>| point_at(s, lambda, Definition2::Corrected);
        let h = STEP;
        let mut sum = 0.0;
        for stencil in &self.stencils {
            let [c, up, um, vp, vm, pp, pm, mp, mm] = stencil.each_ref().map(f);
            for d in 0..3 {
                let fuu = (up[d] - 2.0 * c[d] + um[d]) / (h * h);
                let fvv = (vp[d] - 2.0 * c[d] + vm[d]) / (h * h);
                let fuv = (pp[d] - pm[d] - mp[d] + mm[d]) / (4.0 * h * h);
                sum += fuu * fuu + 2.0 * fuv * fuv + fvv * fvv;
            }
        }
        sum
    }
}

/// The faired `(λ1, λ2, λ3)` within `[lo, hi]`, starting from `start`: coordinate descent with
/// golden-section search.
pub fn fair_lambda(r: &[Net; 3], start: f64, (lo, hi): (f64, f64)) -> [f64; 3] {
    let inv_phi = (5f64.sqrt() - 1.0) / 2.0;
    let quadrature = Quadrature::new(r);
    let mut lam = [start.clamp(lo, hi); 3];
    let mut best = quadrature.energy(lam);
    for _ in 0..SWEEPS {
        for k in 0..3 {
            let e = |x: f64| {
                let mut l = lam;
                l[k] = x;
                quadrature.energy(l)
            };
            let (mut a, mut b) = (lo, hi);
            let mut c = b - inv_phi * (b - a);
            let mut d = a + inv_phi * (b - a);
            let (mut ec, mut ed) = (e(c), e(d));
            for _ in 0..GOLDEN_STEPS {
                if ec < ed {
                    (b, d, ed) = (d, c, ec);
                    c = b - inv_phi * (b - a);
                    ec = e(c);
                } else {
                    (a, c, ec) = (c, d, ed);
                    d = a + inv_phi * (b - a);
                    ed = e(d);
                }
            }
            let (x, ex) = if ec < ed { (c, ec) } else { (d, ed) };
            // Keep the current value unless the search found a lower energy.
            if ex < best {
                lam[k] = x;
                best = ex;
            }
        }
    }
    lam
}
