//! Where and how strongly a domain point blends with a neighbour: the subdomain (paper §4.1),
//! `d`, `s`, the blend parameter `t` (Eq. 4) and the weight `β(t) = 1 − α(t)` of Eq. 5, with
//! their derivatives; and the neighbour map of Eq. 3 in its general form.
//!
//! It deliberately depends only on the domain point, the three edge widths `h` and the profile,
//! never on geometry, so that a tessellation pattern can compute it once for every triangle.

use super::profile::Profile;

const SQRT_3_2: f64 = 1.224_744_871_391_589;
const INV_SQRT2: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// The blend at one domain point: `S = b_f + β·(b_g − b_f)`, `b_g` from the neighbour across
/// edge `k`. `β = 0` (and both derivatives 0) outside every blending region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlendWeight {
    /// Subdomain: the edge opposite corner `k` is the one blended across.
    pub k: u8,
    /// `β(t) = 1 − α(t) = 10t³ − 15t⁴ + 6t⁵`.
    pub beta: f64,
    /// `∂_u β` and `∂_v β` (`∂_u = ∂/∂u − ∂/∂w`, `∂_v = ∂/∂v − ∂/∂w`).
    pub beta_u: f64,
    pub beta_v: f64,
}

impl BlendWeight {
    /// The blend weight at barycentrics `l` with widths `h[k]` for the edge opposite corner `k`.
    ///
    /// Corrections to the paper (notes items 1 and 4):
    /// - Eq. 5 has its weights swapped; with `α(0) = 1` the surface must be
    ///   `α(t)·b_f + (1 − α(t))·b_g`, i.e. `b_f + β(t)(b_g − b_f)`.
    /// - `d = √(3/2)·λ_k` replaces Eq. 4's `√(‖a‖² − s²)`: equal, but without the cancellation that
    ///   loses half the digits near the edge, and differentiable.
    /// - `s` is measured from the nearer corner straight from the barycentrics,
    ///   `s_n = min(2λ_a + λ_k, 2λ_b + λ_k)/√2`: computed the long way `s` rounds to just below √2
    ///   at a corner, which gives `t = ½` and a derivative of 1e15.
    /// - `t = 0` wherever `r = 0` (h = 0, and the corners, where Eq. 4 is 0/0).
    pub fn at(l: [f64; 3], h: [f64; 3], profile: Profile) -> BlendWeight {
        let k = subdomain(l);
        let none = BlendWeight {
            k: k as u8,
            beta: 0.0,
            beta_u: 0.0,
            beta_v: 0.0,
        };
        let (a, b) = ((k + 2) % 3, (k + 1) % 3);
        // `far` is the corner whose coordinate measures s from the nearer one.
        let (sa, sb) = (2.0 * l[a] + l[k], 2.0 * l[b] + l[k]);
        let (s2, far) = if sa <= sb { (sa, a) } else { (sb, b) };
        let s = s2 * INV_SQRT2;
        let (r, dr) = profile.radius(s, h[k]);
        let d = SQRT_3_2 * l[k];
        if r <= 0.0 || d >= r {
            return none;
        }
        let t = 0.5 * (1.0 - d / r);
        // ∂t = −½(∂d/r − d·r'(s)·∂s/r²), ∂d = √(3/2)·e_k, ∂s = (2e_far + e_k)/√2.
        let mut grad = [0.0; 3];
        grad[k] += -0.5 * SQRT_3_2 / r;
        let ds = 0.5 * d * dr / (r * r) * INV_SQRT2;
        grad[far] += 2.0 * ds;
        grad[k] += ds;
        let (beta, dbeta) = smoothstep5(t);
        BlendWeight {
            k: k as u8,
            beta,
            beta_u: dbeta * (grad[0] - grad[2]),
            beta_v: dbeta * (grad[1] - grad[2]),
        }
    }
}

/// `β(t) = 1 − α(t)` with the paper's quintic `α(t) = 1 − 10t³ + 15t⁴ − 6t⁵`, and `β'(t)`.
#[inline]
pub fn smoothstep5(t: f64) -> (f64, f64) {
    let t2 = t * t;
    let u = 1.0 - t;
    (t2 * t * (10.0 - 15.0 * t + 6.0 * t2), 30.0 * t2 * u * u)
}

/// Subdomain of a point (paper §4.1): the index of its smallest coordinate, ties to the lowest.
#[inline]
pub fn subdomain(l: [f64; 3]) -> usize {
    let mut k = 0;
    if l[1] < l[k] {
        k = 1;
    }
    if l[2] < l[k] {
        k = 2;
    }
    k
}

/// Columns of the neighbour map `μ = Mλ` (Eq. 3 in the general form of notes item 3) for edge
/// `k` of f, whose neighbour holds f's corners `i = k+1`, `j = k+2` in slots `p, q` and its own
/// third corner in slot `r`: `μ_p = λ_i + λ_k`, `μ_q = λ_j + λ_k`, `μ_r = −λ_k`.
///
/// Eq. 3 as printed assumes the layout of the paper's Fig. 4 and is right for one half-edge in
/// three; this form needs only vertex identity, whatever g's corner order or winding.
pub fn neighbour_map(k: usize, [p, q, r]: [usize; 3]) -> [[f64; 3]; 3] {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let mut cols = [[0.0; 3]; 3];
    cols[i][p] = 1.0;
    cols[j][q] = 1.0;
    cols[k][p] = 1.0;
    cols[k][q] = 1.0;
    cols[k][r] = -1.0;
    cols
}

/// `μ = Mλ` for the map of [`neighbour_map`].
pub fn map_point(k: usize, slots: [usize; 3], l: [f64; 3]) -> [f64; 3] {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let [p, q, r] = slots;
    let mut mu = [0.0; 3];
    mu[p] = l[i] + l[k];
    mu[q] = l[j] + l[k];
    mu[r] = -l[k];
    mu
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_outside_regions_at_corners_and_for_h_zero() {
        for p in [Profile::Paper, Profile::C2] {
            assert_eq!(BlendWeight::at([0.4, 0.3, 0.3], [0.35; 3], p).beta, 0.0);
            assert_eq!(BlendWeight::at([0.0, 1.0, 0.0], [0.35; 3], p).beta, 0.0);
            assert_eq!(BlendWeight::at([0.0, 0.5, 0.5], [0.0; 3], p).beta, 0.0);
        }
    }

    #[test]
    fn half_on_the_edge_and_gradient_matches_differences() {
        let h = [0.1, 0.2, 0.3];
        let w = BlendWeight::at([0.0, 0.5, 0.5], h, Profile::C2);
        assert_eq!((w.k, w.beta), (0, 0.5));
        for l in [[0.05, 0.6, 0.35], [0.03, 0.1, 0.87], [0.5, 0.46, 0.04]] {
            for profile in [Profile::Paper, Profile::C2] {
                let e = 1e-7;
                let b = |l: [f64; 3]| BlendWeight::at(l, h, profile).beta;
                let fu =
                    (b([l[0] + e, l[1], l[2] - e]) - b([l[0] - e, l[1], l[2] + e])) / (2.0 * e);
                let fv =
                    (b([l[0], l[1] + e, l[2] - e]) - b([l[0], l[1] - e, l[2] + e])) / (2.0 * e);
                let w = BlendWeight::at(l, h, profile);
                assert!(w.beta > 0.0, "{l:?} is inside a region");
                assert!(
                    (w.beta_u - fu).abs() < 1e-6 && (w.beta_v - fv).abs() < 1e-6,
                    "{l:?}"
                );
            }
        }
    }

    #[test]
    fn neighbour_map_is_its_own_inverse_from_the_other_side() {
        // f's edge 1 (corners 2, 0) is g's edge 2 with g = (f0, f2, x): p = 1 holds f's corner
        // i = 2, q = 0 holds j = 0, r = 2.
        let l = [0.2, 0.1, 0.7];
        let mu = map_point(1, [1, 0, 2], l);
        // From g's side: its edge 2, corners i = 0 (f's 0, f slot 0) and j = 1 (f's 2, slot 2).
        let back = map_point(2, [0, 2, 1], mu);
        for c in 0..3 {
            assert!((back[c] - l[c]).abs() < 1e-15);
        }
    }
}
