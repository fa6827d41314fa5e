//! Everything about a domain point that does not depend on geometry: the Bernstein basis, the
//! subdomain and the blend weight, folded into one weight per control point of the two nets a
//! point combines. Computed per point for [`Surface::evaluate`](super::Surface), and once per
//! (level, lattice part, edge widths, profile) for a whole lattice, then reused by every triangle
//! with the same widths.
//!
//! It deliberately holds no positions or normals; combining weights with control nets is
//! `g2.rs`'s job.
//!
//! # Why the weights are pre-blended and stored lane by lane
//!
//! `S = b_f + β(b_g − b_f)` (Eq. 5, weights swapped back) and its derivatives
//! `∂S = ∂b_f + β(∂b_g − ∂b_f) + ∂β·(b_g − b_f)` are linear in the two control nets, so with
//! the Bernstein basis `B_m` of Eq. 1:
//!
//! ```text
//! S   = Σ (1−β)·B_m · f_m            + Σ β·B_m · g_m
//! ∂S  = Σ ((1−β)·∂B_m − ∂β·B_m) · f_m + Σ (β·∂B_m + ∂β·B_m) · g_m
//! ```
//!
//! Those per-point weights depend on the domain point only, so a pattern stores them instead
//! of `B`, `β` and `∂β`: a point then costs 9 dot products of length 10 (outside the blending
//! regions, where the neighbour's weights are all zero) or 20, and no branching. Points are
//! grouped by the net they blend with and packed [`LANES`] to a [`Lanes`] block, weights
//! indexed `[quantity][control point][lane]`, so that the sums run over several points at once
//! in SIMD registers while each point's sum keeps the order of the one-point evaluation: the
//! lattice and [`Surface::evaluate`](super::Surface) agree bit for bit.

use std::sync::Arc;

use super::blend::BlendWeight;
use super::lattice_cache::{Entry, LatticeCache};
use super::pn::{Bernstein, IJK};
use super::profile::Profile;
use super::{lattice_bary, LatticePart};

/// Points evaluated together: two f64 lanes fill an SSE2 register, the baseline of x86-64.
pub const LANES: usize = 2;

/// Weights of one net for `L` points: `[quantity][control point][lane]`, quantity 0 the
/// position, 1 and 2 the derivatives `∂_u` and `∂_v` (`∂_u = ∂/∂u − ∂/∂w`, `∂_v = ∂/∂v − ∂/∂w`).
pub type NetWeights<const L: usize> = [[[f64; L]; 10]; 3];

/// Up to `L` points with their weights on the triangle's own net and, when they blend, on the
/// neighbour's net across one edge.
#[derive(Debug, Clone, PartialEq)]
pub struct Lanes<const L: usize> {
    /// Weights on the own net `b_f`.
    pub own: NetWeights<L>,
    /// Weights on the neighbour's net `b_g ∘ M` across the edge opposite corner `k` of the
    /// group; unused (and zero) outside the blending regions.
    pub across: NetWeights<L>,
    /// Barycentrics of each point, for the orientation of its normal.
    pub bary: [[f64; 3]; L],
    /// The neighbour net's share `β` of each point's blend (Eq. 5), 0 for a point that blends
    /// with nobody: how far the side its normal is turned to leans on the neighbour's input
    /// normals (see `G2Surface::combine`).
    pub beta: [f64; L],
    /// Where each point goes in the output; [`Lanes::PADDING`] for unused lanes.
    pub target: [u32; L],
}

impl<const L: usize> Lanes<L> {
    /// Target of an unused lane (its weights are zero).
    pub const PADDING: u32 = u32::MAX;

    fn empty() -> Self {
        Lanes {
            own: [[[0.0; L]; 10]; 3],
            across: [[[0.0; L]; 10]; 3],
            bary: [[0.0; 3]; L],
            beta: [0.0; L],
            target: [Self::PADDING; L],
        }
    }

    /// Writes point `w` into lane `lane`, to go to output `target`.
    fn set(&mut self, lane: usize, w: &PointWeights, target: u32) {
        for q in 0..3 {
            for m in 0..10 {
                self.own[q][m][lane] = w.own[q][m];
                self.across[q][m][lane] = w.across[q][m];
            }
        }
        self.bary[lane] = w.bary;
        self.beta[lane] = w.beta;
        self.target[lane] = target;
    }

    /// A single point in lane 0: how [`Surface::evaluate`](super::Surface) runs the lattice's
    /// code.
    pub fn single(w: &PointWeights) -> Self {
        let mut lanes = Self::empty();
        lanes.set(0, w, 0);
        lanes
    }
}

impl Lanes<1> {
    /// Lane 0 of `lanes`, alone: the same weights, barycentrics and target.
    fn first_of<const L: usize>(lanes: &Lanes<L>) -> Self {
        let lane = |w: &NetWeights<L>| w.map(|quantity| quantity.map(|point| [point[0]]));
        Lanes {
            own: lane(&lanes.own),
            across: lane(&lanes.across),
            bary: [lanes.bary[0]],
            beta: [lanes.beta[0]],
            target: [lanes.target[0]],
        }
    }
}

/// The geometry-free data of one domain point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointWeights {
    /// The point's barycentrics.
    pub bary: [f64; 3],
    /// `Some(c)` when the point is exactly corner `c`.
    pub corner: Option<u8>,
    /// Subdomain: the point blends with the neighbour across the edge opposite corner `k`.
    pub k: u8,
    /// Whether it blends at all (`β` or one of its derivatives is not 0).
    pub blended: bool,
    /// The neighbour net's share `β` of the blend (Eq. 5 with its weights swapped back): 0
    /// outside the blending regions, exactly ½ on the edge itself (`t = ½` there, and
    /// `β(½) = ½`), the same from both sides.
    pub beta: f64,
    /// Weights on the own net, `[quantity][control point]` (see the module documentation).
    pub own: [[f64; 10]; 3],
    /// Weights on the neighbour's net; all zero unless `blended`.
    pub across: [[f64; 10]; 3],
}

impl PointWeights {
    /// Weights at barycentrics `bary` for widths `h` (by opposite corner) and `profile`.
    pub fn at(bary: [f64; 3], h: [f64; 3], profile: Profile) -> PointWeights {
        let corner = (0..3)
            .find(|&c| bary[c] == 1.0 && bary[(c + 1) % 3] == 0.0 && bary[(c + 2) % 3] == 0.0);
        let basis = Bernstein::at(bary);
        let b = BlendWeight::at(bary, h, profile);
        let blended = b.beta != 0.0 || b.beta_u != 0.0 || b.beta_v != 0.0;
        let mut own = [basis.value, basis.du, basis.dv];
        let mut across = [[0.0; 10]; 3];
        if blended {
            // The two sums of the module documentation (Eq. 5 with ∂β from Eq. 4).
            let keep = 1.0 - b.beta;
            for m in 0..10 {
                let (v, du, dv) = (basis.value[m], basis.du[m], basis.dv[m]);
                own[0][m] = keep * v;
                own[1][m] = keep * du - b.beta_u * v;
                own[2][m] = keep * dv - b.beta_v * v;
                across[0][m] = b.beta * v;
                across[1][m] = b.beta * du + b.beta_u * v;
                across[2][m] = b.beta * dv + b.beta_v * v;
            }
        }
        PointWeights {
            bary,
            corner: corner.map(|c| c as u8),
            k: b.k,
            blended,
            beta: b.beta,
            own,
            across,
        }
    }
}

/// The weights of the points of one part of a level-`n` lattice, grouped by the net they
/// blend with.
#[derive(Debug, Clone, PartialEq)]
pub struct Pattern {
    /// Number of points; targets run over `0..len`, in the part's order.
    pub len: usize,
    /// Corners in the part: (corner, target). Their point is the input vertex's own.
    pub corners: Vec<(u8, u32)>,
    /// Points that blend with no neighbour.
    pub plain: Vec<Lanes<LANES>>,
    /// `blended[k]`: points that blend with the neighbour across the edge opposite corner `k`.
    pub blended: [Vec<Lanes<LANES>>; 3],
    /// The last point of a group when it would fill only one lane of its block: `single[k]`
    /// belongs with `blended[k]`, `single[3]` with `plain`. Summed one lane wide, it reads the
    /// nets as they are, with no copy of them lane by lane, and with the same bits (each lane's
    /// sums are its own); at level 2 every edge part is such a point, so no net is copied.
    pub single: [Option<Lanes<1>>; 4],
    /// Which control points the sums need ([`EdgeRows`]): found by looking at the weights,
    /// never assumed, and [`EdgeRows::All`] wherever a weight left out would not be zero.
    pub edge_rows: EdgeRows,
}

/// The control points whose weights a [`Pattern`]'s sums need, by what the pattern's weights
/// are found to be exactly zero (`±0`) on, in every block and on both nets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeRows {
    /// All ten, for every quantity.
    All,
    /// The seven of [`EDGE_ROWS`]`[k]`: every weight is zero on the three control points whose
    /// exponent of `λ_k` is 2 or 3. So it is for every part on edge `k` (`λ_k = 0`: those
    /// points' Bernstein values and derivatives all have a factor `λ_k`).
    Edge(u8),
    /// As [`EdgeRows::Edge`], and the position's weights are also zero on the three points whose
    /// exponent of `λ_k` is 1, so the position sums only the four of [`EDGE_VALUE_ROWS`]`[k]`,
    /// edge `k`'s boundary curve (its Bernstein values, though not its derivatives, all have a
    /// factor `λ_k` there too: Eq. 1 at `λ_k = 0`, and the blend of Eq. 5 keeps the factor).
    EdgeValues(u8),
}

/// `EDGE_ROWS[k]`: the control points whose exponent of `λ_k` is 0 or 1, in slot order: all
/// that a point on edge `k` weighs (see [`EdgeRows::Edge`]).
pub const EDGE_ROWS: [[usize; 7]; 3] = rows_up_to::<7>(1);

/// `EDGE_VALUE_ROWS[k]`: the control points whose exponent of `λ_k` is 0, in slot order: edge
/// `k`'s boundary curve, all that the position of a point on edge `k` weighs (see
/// [`EdgeRows::EdgeValues`]).
pub const EDGE_VALUE_ROWS: [[usize; 4]; 3] = rows_up_to::<4>(0);

/// For each `k`, the `N` control points whose exponent of `λ_k` is at most `most`, in slot order.
const fn rows_up_to<const N: usize>(most: usize) -> [[usize; N]; 3] {
    let mut rows = [[0; N]; 3];
    let mut k = 0;
    while k < 3 {
        let (mut m, mut n) = (0, 0);
        while m < 10 {
            if IJK[m][k] <= most {
                rows[k][n] = m;
                n += 1;
            }
            m += 1;
        }
        assert!(n == N);
        k += 1;
    }
    rows
}

impl Pattern {
    /// Computes the pattern of `part` of the level-`n` lattice (`n ≥ 1`).
    pub fn new(n: u32, part: LatticePart, h: [f64; 3], profile: Profile) -> Pattern {
        let points = part.points(n);
        let barys = points.iter().map(|&(i, j)| lattice_bary(n, i, j));
        Pattern::build(barys, points.len(), part, h, profile)
    }

    /// The pattern of the points at barycentrics `barys`, in their order (targets `0..len`),
    /// for a set of scattered points asked for on many triangles: the same weights as at a
    /// lattice's points, so its sums equal [`PointWeights::at`]'s evaluated one by one.
    pub fn at_points(barys: &[[f64; 3]], h: [f64; 3], profile: Profile) -> Pattern {
        Pattern::at_part_points(barys, LatticePart::All, h, profile)
    }

    /// [`Pattern::at_points`] for points that all lie on `part` of a lattice: on an edge part,
    /// the sums then leave out the control points whose weights are all zero there
    /// ([`EdgeRows`]), as the part's own pattern does.
    pub fn at_part_points(
        barys: &[[f64; 3]],
        part: LatticePart,
        h: [f64; 3],
        profile: Profile,
    ) -> Pattern {
        Pattern::build(barys.iter().copied(), barys.len(), part, h, profile)
    }

    /// The pattern of the `len` points `barys`, which are `part`'s (for the edge rows).
    fn build(
        barys: impl Iterator<Item = [f64; 3]>,
        len: usize,
        part: LatticePart,
        h: [f64; 3],
        profile: Profile,
    ) -> Pattern {
        let mut pattern = Pattern {
            len: 0,
            corners: Vec::new(),
            plain: Vec::new(),
            blended: [Vec::new(), Vec::new(), Vec::new()],
            single: [None, None, None, None],
            edge_rows: EdgeRows::All,
        };
        // Lanes filled so far in the last block of each group.
        let mut filled = [LANES; 4];
        for (target, bary) in barys.enumerate() {
            let target = target as u32;
            let w = PointWeights::at(bary, h, profile);
            if let Some(c) = w.corner {
                pattern.corners.push((c, target));
                continue;
            }
            let (group, blocks) = if w.blended {
                (w.k as usize, &mut pattern.blended[w.k as usize])
            } else {
                (3, &mut pattern.plain)
            };
            if filled[group] == LANES {
                blocks.push(Lanes::empty());
                filled[group] = 0;
            }
            let last = blocks.last_mut().expect("a block was just pushed");
            last.set(filled[group], &w, target);
            filled[group] += 1;
        }
        pattern.len = len;
        if let LatticePart::Edge(k) = part {
            // Whether every weight of quantities `quantities` is zero on the control points
            // whose exponent of `λ_k` is at least `from`, in every block, on both nets.
            let zero_from = |from: usize, quantities: std::ops::Range<usize>| {
                let zero = |w: &NetWeights<LANES>| {
                    w[quantities.clone()].iter().all(|quantity| {
                        (0..10)
                            .filter(|&m| IJK[m][k as usize] >= from)
                            .all(|m| quantity[m].iter().all(|&x| x == 0.0))
                    })
                };
                let mut blocks = pattern.plain.iter().chain(pattern.blended.iter().flatten());
                blocks.all(|lanes| zero(&lanes.own) && zero(&lanes.across))
            };
            if zero_from(2, 0..3) {
                pattern.edge_rows = if zero_from(1, 0..1) {
                    EdgeRows::EdgeValues(k)
                } else {
                    EdgeRows::Edge(k)
                };
            }
        }
        for (group, &filled) in filled.iter().enumerate() {
            let blocks = match group {
                3 => &mut pattern.plain,
                k => &mut pattern.blended[k],
            };
            if filled == 1 {
                let last = blocks.pop().expect("a block holds the point");
                pattern.single[group] = Some(Lanes::first_of(&last));
            }
        }
        pattern
    }

    /// The blocks of group `group` (`k` < 3: blended across edge `k`, 3: plain) and its single
    /// point, if any.
    pub fn group(&self, group: usize) -> (&[Lanes<LANES>], Option<&Lanes<1>>) {
        let blocks = match group {
            3 => &self.plain,
            k => &self.blended[k],
        };
        (blocks, self.single[group].as_ref())
    }
}

/// Patterns keyed by level, lattice part, the bit patterns of the three widths, and the profile.
type Key = (u32, LatticePart, [u64; 3], Profile);

/// A shared, thread-safe store of patterns (a [`LatticeCache`]). Meshes with many distinct width
/// triples would make it grow without reuse, so past [`PatternCache::MAX_ENTRIES`] new patterns
/// are built but not kept.
#[derive(Debug)]
pub struct PatternCache(LatticeCache<Key, Pattern>);

impl Default for PatternCache {
    fn default() -> Self {
        PatternCache(LatticeCache::new(Self::MAX_ENTRIES))
    }
}

impl PatternCache {
    /// Most patterns kept (a whole level-16 lattice is about 80 kB).
    pub const MAX_ENTRIES: usize = 1024;

    /// Runs `f` on the pattern for this key, built on first use.
    ///
    /// The G² surface evaluates its lattice inside `f` rather than holding the entry: measured
    /// with callgrind, that form compiled the lattice loop to about a fifth fewer instructions
    /// (1k input, level 16: 119.6 M against 152.5 M for the whole run).
    pub fn with<R>(
        &self,
        n: u32,
        part: LatticePart,
        h: [f64; 3],
        profile: Profile,
        f: impl FnOnce(&Pattern) -> R,
    ) -> R {
        f(&self.get(n, part, h, profile))
    }

    /// The pattern for this key, built on first use.
    pub fn get(
        &self,
        n: u32,
        part: LatticePart,
        h: [f64; 3],
        profile: Profile,
    ) -> Entry<'_, Pattern> {
        let key = (n, part, h.map(f64::to_bits), profile);
        let build = || Pattern::new(n, part, h, profile);
        self.0
            .get_or_build(key, build)
            .unwrap_or_else(|| Entry::Shared(Arc::new(build())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What the edge parts' shortcut rests on, found in the weights themselves: every edge part
    /// of every level, width and profile drops exactly the three control points off its rows,
    /// and for the position the three next to them as well (so the fast sums are the ones taken
    /// at level 2, where every evaluated point is an edge's), and no part with interior points
    /// drops any.
    #[test]
    fn edge_parts_and_only_edge_parts_leave_out_the_points_off_their_rows() {
        for profile in [Profile::Paper, Profile::C2] {
            for h in [[0.212; 3], [0.05, 0.3, 0.35], [0.35, 0.0, 0.1], [0.0; 3]] {
                for n in 2..=12 {
                    for k in 0..3u8 {
                        let edge = Pattern::new(n, LatticePart::Edge(k), h, profile);
                        assert_eq!(edge.edge_rows, EdgeRows::EdgeValues(k), "{n} {k} {h:?}");
                    }
                    for part in [LatticePart::All, LatticePart::Interior] {
                        let rows = Pattern::new(n, part, h, profile).edge_rows;
                        assert_eq!(rows, EdgeRows::All);
                    }
                }
            }
        }
        for (k, rows) in EDGE_ROWS.iter().enumerate() {
            assert!(rows.windows(2).all(|w| w[0] < w[1]), "slot order");
            assert!(rows.iter().all(|&m| IJK[m][k] <= 1));
        }
    }
}
