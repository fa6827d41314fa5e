//! The blend-region profile `r(s)` of paper Section 4.2: how far from an edge the blending region
//! reaches, at distance `s` along the edge.
//!
//! It deliberately computes only `r` and `dr/ds`; the blend parameter `t` is in `blend.rs`.
//!
//! Both profiles are evaluated from the nearer corner, `0 ≤ s ≤ √2/2` (r is symmetric,
//! `r(s) = r(√2 − s)`; notes item 5), and share three pieces: the line `r = s/√3` (the subdomain
//! bisector, so the region fills the wedge next to a corner) up to `s = 1.5h`, a transition up to
//! `s = 2h`, and the plateau `r = h`. They differ only in the transition:
//! - [`Profile::Paper`]: the paper's arc of radius `h` centred at `(2h, 0)`. It is tangent to the
//!   line and the plateau but its curvature jumps there, so `r` is only C¹ and the surface is only
//!   G¹ across the four lines `s = 1.5h, 2h, √2 − 2h, √2 − 1.5h` inside each region (notes item 9).
//! - [`Profile::C2`]: the quintic Hermite segment matching value, slope and zero second
//!   derivative of the line at `1.5h` and of the plateau at `2h`. `r` is C², monotone, and stays
//!   below both the line and `h` (so the region never leaves its subdomain), which makes the
//!   surface curvature-continuous everywhere but at the vertices.
//!
//! Measured (`tests/integration/surface_continuity.rs`): the normal-curvature jump × L along the edge
//! across the four switch lines of every interior edge, halfway into the region, at distance eps
//! either side of the line (max over the mesh):
//!
//! | mesh, h             | profile | eps = 1e-2 | 1e-3    | 1e-4    |
//! |---------------------|---------|------------|---------|---------|
//! | cube, 0.106         | paper   | 1.12       | 1.19    | 1.20    |
//! | cube, 0.106         | C²      | 1.09       | 0.142   | 0.0146  |
//! | cube, 0.212         | paper   | 0.669      | 0.709   | 0.713   |
//! | cube, 0.212         | C²      | 0.376      | 0.0432  | 0.00438 |
//! | bumpy sphere, 0.106 | paper   | 0.0694     | 0.0710  | 0.0714  |
//! | bumpy sphere, 0.106 | C²      | 0.0689     | 0.00905 | 0.00093 |
//! | bumpy sphere, 0.212 | paper   | 0.0628     | 0.0635  | 0.0636  |
//! | bumpy sphere, 0.212 | C²      | 0.0370     | 0.00422 | 0.00043 |
//!
//! The paper's jump does not converge (it stays at 0.06–1.2 / L); the C²
//! profile's falls 10× per decade, as a smooth surface's must. Across mesh edges the two are
//! identical (G² alike, same figures), and with a precomputed pattern they cost the same.
//! [`Profile::C2`] is therefore the default.

/// Which `r(s)` shapes the blending regions.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Deserialize, serde::Serialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// The paper's line–arc–plateau profile (C¹ at its switch points).
    Paper,
    /// Line–quintic–plateau, C² everywhere (the default; see the module docs for why).
    #[default]
    C2,
}

const INV_SQRT3: f64 = 0.577_350_269_189_625_8;

impl Profile {
    /// `(r, dr/ds)` at distance `s` (from the nearer corner, `0 ≤ s ≤ √2/2`) for blend width `h`.
    /// `h ≤ 0` gives `r ≡ 0` (no blending).
    #[inline]
    pub fn radius(self, s: f64, h: f64) -> (f64, f64) {
        if h <= 0.0 {
            return (0.0, 0.0);
        }
        if s < 1.5 * h {
            return (s * INV_SQRT3, INV_SQRT3);
        }
        if s >= 2.0 * h {
            return (h, 0.0);
        }
        match self {
            Profile::Paper => {
                let x = 2.0 * h - s;
                let r = (h * h - x * x).max(0.0).sqrt();
                (r, if r > 0.0 { x / r } else { 0.0 })
            }
            Profile::C2 => {
                // Quintic Hermite on [1.5h, 2h]: y0 = 1.5h/√3, y0' = 1/√3, y1 = h, y1' = 0,
                // y0'' = y1'' = 0. With x in [0, 1] and width w = h/2:
                // y = y0 H0(x) + y1 H1(x) + w y0' Hm0(x).
                let w = 0.5 * h;
                let x = (s - 1.5 * h) / w;
                let (x2, x3) = (x * x, x * x * x);
                let h1 = x3 * (10.0 - 15.0 * x + 6.0 * x2);
                let dh1 = 30.0 * x2 * (1.0 - x) * (1.0 - x);
                let hm0 = x - 6.0 * x3 + 8.0 * x3 * x - 3.0 * x3 * x2;
                let dhm0 = 1.0 - 18.0 * x2 + 32.0 * x3 - 15.0 * x3 * x;
                let y0 = 1.5 * h * INV_SQRT3;
                let r = y0 + (h - y0) * h1 + w * INV_SQRT3 * hm0;
                let dr = ((h - y0) * dh1 + w * INV_SQRT3 * dhm0) / w;
                (r, dr)
            }
        }
    }

    /// The four switch points `1.5h, 2h, √2 − 2h, √2 − 1.5h` along an edge (from its corner `b`).
    pub fn switch_points(h: f64) -> [f64; 4] {
        let l = std::f64::consts::SQRT_2;
        [1.5 * h, 2.0 * h, l - 2.0 * h, l - 1.5 * h]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_agree_outside_the_transition_and_meet_its_ends() {
        let h = 0.2;
        for p in [Profile::Paper, Profile::C2] {
            assert_eq!(p.radius(0.1, h), (0.1 * INV_SQRT3, INV_SQRT3));
            assert_eq!(p.radius(0.5, h), (h, 0.0));
            let (r0, d0) = p.radius(1.5 * h, h);
            assert!((r0 - 1.5 * h * INV_SQRT3).abs() < 1e-15 && (d0 - INV_SQRT3).abs() < 1e-12);
            let (r1, d1) = p.radius(2.0 * h - 1e-12, h);
            assert!((r1 - h).abs() < 1e-9 && d1.abs() < 1e-5);
        }
    }

    #[test]
    fn c2_profile_stays_under_line_and_plateau_and_rises() {
        let h = 0.3;
        let mut last = 0.0;
        for m in 0..=1000 {
            let s = 1.5 * h + 0.5 * h * m as f64 / 1000.0;
            let (r, dr) = Profile::C2.radius(s, h);
            assert!(r <= s * INV_SQRT3 + 1e-15 && r <= h + 1e-15 && r >= last && dr >= -1e-15);
            last = r;
        }
    }

    #[test]
    fn c2_derivative_matches_differences() {
        let h = 0.25;
        let s = 1.7 * h;
        let e = 1e-7;
        let fd = (Profile::C2.radius(s + e, h).0 - Profile::C2.radius(s - e, h).0) / (2.0 * e);
        assert!((fd - Profile::C2.radius(s, h).1).abs() < 1e-7);
    }
}
