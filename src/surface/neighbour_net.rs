//! The neighbour's control net re-expressed in a triangle's own barycentrics, `b_g ∘ M` (Eq. 3
//! in the form of [`neighbour_map`](super::blend::neighbour_map)), as the G² blend (Eq. 5)
//! weighs it.
//!
//! It computes the values [`compose`](super::pn::compose) computes for that map, with the same
//! roundings, but does only the arithmetic that can change a bit:
//! - The map's columns are the neighbour's corners `e_p`, `e_q` for the two corners of the
//!   shared edge and `e_p + e_q − e_r` for the corner `k` opposite it: entries 0 and ±1 only.
//!   A de Casteljau step by a unit column, `Σ_c x_c·v_c` with `x = e_p`, is `1·v_p + 0·… + 0·…`,
//!   which is `v_p` exactly except perhaps for the sign of a zero (`v_p = −0` plus `+0` gives
//!   `+0`); here it is `v_p`, a selection with no arithmetic. Steps by the third column keep
//!   `compose`'s three products and its order of sums, so they round the same way.
//! - So a value here differs from `compose`'s at most in the sign of a zero, and so does every
//!   value computed from it. That never reaches the surface: a control point is only used
//!   through the weighted sums of `g2.rs`, which start at `+0`, and a sum that starts at `+0`
//!   is never `−0` (in round-to-nearest, `a + b = −0` only when both are `−0`), so adding
//!   `w·(±0) = ±0` leaves it as it is. (The nets are finite: positions are finite `f32` and
//!   normals unit, so no `0·∞` arises on either path.)
//! - [`Reach::Edge`]: a point on edge `k` itself (`λ_k = 0`) gives every control point whose
//!   exponent of `λ_k` is 2 or 3 a Bernstein value and derivatives of exactly `±0` (each has a
//!   factor `λ_k`), so their weights are `±0` and, by the argument above, the sums do not
//!   depend on those control points at all: they are left at `0` and not composed.
//!
//! Cost (callgrind, one thread): about 290 instructions for an edge's seven points (430 while
//! they were laid out with the other differences and gathered, as a whole net's are) and 460
//! for a whole net, where `compose` and the conversions to and from its layout took about 900;
//! at level 2 every composition is an edge's, one per triangle's owned edge sample.

use super::pn::IJK;

/// A control net by coordinate, `[x, y, z][control point]` (slots in [`IJK`] order).
pub(super) type SoaNet = [[f64; 10]; 3];

/// Which control points of the composed net are wanted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Reach {
    /// All ten: points anywhere in the triangle.
    Whole,
    /// The seven whose exponent of `λ_k` is 0 or 1, all that points on edge `k` itself weigh;
    /// the other three are left at 0 (see the module documentation).
    Edge,
}

/// The multi-indices of degree 2, numbered as [`FIRST`] and the first differences are.
const DEGREE2: [[usize; 3]; 6] = [
    [2, 0, 0],
    [1, 1, 0],
    [1, 0, 1],
    [0, 2, 0],
    [0, 1, 1],
    [0, 0, 2],
];

/// Slot of the control point with exponents `e` (the inverse of [`IJK`]).
const fn slot(e: [usize; 3]) -> usize {
    let mut m = 0;
    while !(IJK[m][0] == e[0] && IJK[m][1] == e[1] && IJK[m][2] == e[2]) {
        m += 1;
    }
    m
}

/// Number of the degree-2 multi-index `e` in [`DEGREE2`].
const fn degree2(e: [usize; 3]) -> usize {
    let mut n = 0;
    while !(DEGREE2[n][0] == e[0] && DEGREE2[n][1] == e[1] && DEGREE2[n][2] == e[2]) {
        n += 1;
    }
    n
}

const fn plus(mut e: [usize; 3], c: usize) -> [usize; 3] {
    e[c] += 1;
    e
}

/// `FIRST[n][c]`: the slot of `DEGREE2[n] + e_c`, the points the first difference at
/// `DEGREE2[n]` sums.
const FIRST: [[usize; 3]; 6] = {
    let mut table = [[0; 3]; 6];
    let mut n = 0;
    while n < 6 {
        let mut c = 0;
        while c < 3 {
            table[n][c] = slot(plus(DEGREE2[n], c));
            c += 1;
        }
        n += 1;
    }
    table
};

/// `SECOND[y][c]`: the number of `e_y + e_c`, the first differences the second difference at
/// `e_y` sums.
const SECOND: [[usize; 3]; 3] = {
    let mut table = [[0; 3]; 3];
    let mut y = 0;
    while y < 3 {
        let mut c = 0;
        while c < 3 {
            table[y][c] = degree2(plus(plus([0; 3], y), c));
            c += 1;
        }
        y += 1;
    }
    table
};

/// Where composed slot `m` is read from, `SOURCE[k][p][q][m]`, in the values a composition
/// lays out one after another: the neighbour's ten points (by slot), its six first differences
/// (by [`DEGREE2`] number), its three second differences (by corner) and the third difference.
/// Slot `m` with own exponents `(a_i, a_j, t)` reads the `t`-th difference at `a_i·e_p + a_j·e_q`
/// (see [`compose_across`]).
const SOURCE: [[[[u8; 10]; 3]; 3]; 3] = {
    let mut table = [[[[0; 10]; 3]; 3]; 3];
    let mut k = 0;
    while k < 3 {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let mut p = 0;
        while p < 3 {
            let mut q = 0;
            while q < 3 {
                let mut m = 0;
                while p != q && m < 10 {
                    let mut e = [0; 3];
                    e[p] += IJK[m][i];
                    e[q] += IJK[m][j];
                    table[k][p][q][m] = match IJK[m][k] {
                        0 => slot(e),
                        1 => 10 + degree2(e),
                        2 => {
                            16 + if e[0] == 1 {
                                0
                            } else if e[1] == 1 {
                                1
                            } else {
                                2
                            }
                        }
                        _ => 19,
                    } as u8;
                    m += 1;
                }
                q += 1;
            }
            p += 1;
        }
        k += 1;
    }
    table
};

/// `b_g ∘ M` for the neighbour `g` with net `net_g` across the own edge opposite corner `k`,
/// whose corners `(k + 1) % 3`, `(k + 2) % 3` are the neighbour's corners `p`, `q`, and `r` its
/// third (`slots = [p, q, r]`, as for [`neighbour_map`](super::blend::neighbour_map)); only the
/// points `reach` names, the others 0.
///
/// The composed point with own exponents `(a_i, a_j, t)` (`t` that of `λ_k`) is the blossom of
/// `b_g` at `e_p` `a_i` times, `e_q` `a_j` times and `d = e_p + e_q − e_r` `t` times.
/// [`compose`](super::pn::compose) takes the arguments in an order that depends on the slot,
/// but the steps by `e_p` and `e_q` are selections, which only shift the multi-index the
/// steps by `d` read: whatever the order, the value is the `t`-th difference by `d` at
/// `a_i·e_p + a_j·e_q`, each difference `Σ_c d_c·v(· + e_c)` summed in the order `compose` sums
/// it (`c` = 0, 1, 2). The first differences are shared by all slots, as `compose`'s quadratic
/// net by `d` is.
///
/// Written into `out`, every point of it (those `reach` leaves out set to 0), so that the
/// surface composes straight into the net it keeps rather than into one it then copies (240
/// bytes per composition, one composition per evaluated edge at level 2).
#[inline]
pub(super) fn compose_across(
    net_g: &SoaNet,
    k: usize,
    slots: [usize; 3],
    reach: Reach,
    out: &mut SoaNet,
) {
    match reach {
        Reach::Whole => compose_whole(net_g, k, slots, out),
        Reach::Edge => compose_edge(net_g, k, slots, out),
    }
}

/// An edge's composed points by where they come from: `(slot, neighbour slot)` for the four
/// selections, `(slot, first difference)` for the three differences.
type EdgeSources = ([(u8, u8); 4], [(u8, u8); 3]);

/// `EDGE_SOURCE[k][p][q]`: for [`Reach::Edge`], the four composed slots with exponent 0 of
/// `λ_k` and the neighbour slot each is (a selection), then the three with exponent 1 and the
/// [`DEGREE2`] number of the first difference each is; both in slot order.
const EDGE_SOURCE: [[[EdgeSources; 3]; 3]; 3] = {
    let mut table = [[[([(0, 0); 4], [(0, 0); 3]); 3]; 3]; 3];
    let mut k = 0;
    while k < 3 {
        let mut p = 0;
        while p < 3 {
            let mut q = 0;
            while q < 3 {
                let (mut selected, mut differences) = (0, 0);
                let mut m = 0;
                while p != q && m < 10 {
                    let from = SOURCE[k][p][q][m];
                    match IJK[m][k] {
                        0 => {
                            table[k][p][q].0[selected] = (m as u8, from);
                            selected += 1;
                        }
                        1 => {
                            table[k][p][q].1[differences] = (m as u8, from - 10);
                            differences += 1;
                        }
                        _ => {}
                    }
                    m += 1;
                }
                assert!(p == q || (selected == 4 && differences == 3));
                q += 1;
            }
            p += 1;
        }
        k += 1;
    }
    table
};

/// [`compose_across`] for [`Reach::Edge`]: the same values as [`compose`]'s for the seven
/// points an edge weighs, written straight to their slots (four selections and three first
/// differences, each summed as `compose` sums it), without laying out and gathering the
/// differences an edge never reads; the other three points are left at 0.
#[inline(always)]
fn compose_edge(net_g: &SoaNet, k: usize, slots: [usize; 3], out: &mut SoaNet) {
    let [p, q, r] = slots;
    let mut d = [1.0; 3];
    d[r] = -1.0;
    let (selected, differences) = &EDGE_SOURCE[k][p][q];
    for (g, out) in net_g.iter().zip(out) {
        for &m in &OFF_EDGE[k] {
            out[m as usize] = 0.0;
        }
        for &(m, from) in selected {
            out[m as usize] = g[from as usize];
        }
        for &(m, n) in differences {
            let sum = &FIRST[n as usize];
            out[m as usize] = d[0] * g[sum[0]] + d[1] * g[sum[1]] + d[2] * g[sum[2]];
        }
    }
}

/// `OFF_EDGE[k]`: the three slots whose exponent of `λ_k` is 2 or 3, which [`Reach::Edge`]
/// leaves at 0.
const OFF_EDGE: [[u8; 3]; 3] = {
    let mut table = [[0; 3]; 3];
    let mut k = 0;
    while k < 3 {
        let (mut m, mut n) = (0, 0);
        while m < 10 {
            if IJK[m][k] >= 2 {
                table[k][n] = m as u8;
                n += 1;
            }
            m += 1;
        }
        assert!(n == 3);
        k += 1;
    }
    table
};

/// [`compose_across`] for [`Reach::Whole`].
#[inline(always)]
fn compose_whole(net_g: &SoaNet, k: usize, slots: [usize; 3], out: &mut SoaNet) {
    let [p, q, r] = slots;
    let mut d = [1.0; 3];
    d[r] = -1.0;
    let source = &SOURCE[k][p][q];
    for (g, out) in net_g.iter().zip(out) {
        // The neighbour's points, then the differences.
        let mut values = [0.0; 20];
        values[..10].copy_from_slice(g);
        for (n, sum) in FIRST.iter().enumerate() {
            values[10 + n] = d[0] * g[sum[0]] + d[1] * g[sum[1]] + d[2] * g[sum[2]];
        }
        for (y, sum) in SECOND.iter().enumerate() {
            let first = &values[10..16];
            values[16 + y] = d[0] * first[sum[0]] + d[1] * first[sum[1]] + d[2] * first[sum[2]];
        }
        values[19] = d[0] * values[16] + d[1] * values[17] + d[2] * values[18];
        for (point, &from) in out.iter_mut().zip(source) {
            *point = values[from as usize];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::blend::neighbour_map;
    use crate::surface::pattern::{NetWeights, Pattern};
    use crate::surface::pn::{compose, Net};
    use crate::surface::{LatticePart, Profile};
    use glam::DVec3;

    /// A net with every coordinate different, some of them zeros of either sign, so that a
    /// step that added a zero would show in the bits.
    fn nets() -> Vec<Net> {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        let mut out: Vec<Net> = (0..20)
            .map(|_| std::array::from_fn(|_| DVec3::new(next(), next(), next())))
            .collect();
        let mut zeros: Net = std::array::from_fn(|_| DVec3::new(next(), next(), next()));
        for (m, point) in zeros.iter_mut().enumerate() {
            point[m % 3] = if m % 2 == 0 { 0.0 } else { -0.0 };
        }
        out.push(zeros);
        out.push([DVec3::splat(-0.0); 10]);
        out
    }

    fn by_coordinate(net: &Net) -> SoaNet {
        [0, 1, 2].map(|c| net.map(|p| p[c]))
    }

    /// [`compose_across`] into a net of NaNs: a point it did not write would show.
    fn composed(net_g: &SoaNet, k: usize, slots: [usize; 3], reach: Reach) -> SoaNet {
        let mut out = [[f64::NAN; 10]; 3];
        compose_across(net_g, k, slots, reach, &mut out);
        out
    }

    /// Same value, and the same bits wherever the value is not zero.
    fn same(a: f64, b: f64) -> bool {
        a == b && (a == 0.0 || a.to_bits() == b.to_bits())
    }

    #[test]
    fn the_composed_net_is_that_of_compose_bit_for_bit_but_for_the_sign_of_zeros() {
        let slot_orders = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        for net in nets() {
            for k in 0..3 {
                for slots in slot_orders {
                    let want = compose(&net, neighbour_map(k, slots));
                    let got = composed(&by_coordinate(&net), k, slots, Reach::Whole);
                    let edge = composed(&by_coordinate(&net), k, slots, Reach::Edge);
                    for (m, exponents) in IJK.iter().enumerate() {
                        for x in 0..3 {
                            assert!(same(got[x][m], want[m][x]), "k {k} {slots:?} slot {m}");
                            if exponents[k] < 2 {
                                assert_eq!(edge[x][m].to_bits(), got[x][m].to_bits());
                            } else {
                                assert_eq!(edge[x][m], 0.0);
                            }
                        }
                    }
                }
            }
        }
    }

    /// What lets the G² surface hand an edge's composition a net whose two points next to the
    /// neighbour's third corner were rebuilt differently (it reads one rebuilt net for every
    /// use): [`Reach::Edge`] never reads those two points, whatever they hold.
    #[test]
    fn an_edge_composition_reads_nothing_next_to_the_neighbours_third_corner() {
        use crate::surface::pn::NEAR;
        for net in nets() {
            for k in 0..3 {
                for slots in [
                    [0, 1, 2],
                    [1, 2, 0],
                    [2, 0, 1],
                    [0, 2, 1],
                    [2, 1, 0],
                    [1, 0, 2],
                ] {
                    let r = slots[2];
                    let mut moved = by_coordinate(&net);
                    for coord in &mut moved {
                        coord[NEAR[r][slots[0]]] = 1e300;
                        coord[NEAR[r][slots[1]]] = f64::NAN;
                    }
                    let want = composed(&by_coordinate(&net), k, slots, Reach::Edge);
                    let got = composed(&moved, k, slots, Reach::Edge);
                    for x in 0..3 {
                        for m in 0..10 {
                            assert_eq!(got[x][m].to_bits(), want[x][m].to_bits(), "{k} {m}");
                        }
                    }
                }
            }
        }
    }

    /// Whether the weights `across` are zero on every control point with exponent 2 or 3 of
    /// `λ_k`.
    fn off_row_zero<const L: usize>(across: &NetWeights<L>, k: usize) -> bool {
        across
            .iter()
            .all(|quantity| (0..10).all(|m| IJK[m][k] < 2 || quantity[m].iter().all(|&w| w == 0.0)))
    }

    /// What [`Reach::Edge`] rests on: on an edge part every neighbour weight of a control point
    /// with exponent 2 or 3 of the edge's `λ_k` is exactly zero.
    #[test]
    fn edge_points_weigh_nothing_of_the_points_off_their_edge_row() {
        for profile in [Profile::Paper, Profile::C2] {
            for h in [[0.212; 3], [0.05, 0.3, 0.35], [0.35, 0.0, 0.1]] {
                for n in 2..=20 {
                    for k in 0..3u8 {
                        let pattern = Pattern::new(n, LatticePart::Edge(k), h, profile);
                        for group in 0..3 {
                            let (blocks, single) = pattern.group(group);
                            let empty = blocks.is_empty() && single.is_none();
                            assert!(empty || group == k as usize);
                            for lanes in blocks {
                                assert!(off_row_zero(&lanes.across, k as usize), "{n} {k}");
                            }
                            if let Some(lane) = single {
                                assert!(off_row_zero(&lane.across, k as usize), "{n} {k}");
                            }
                        }
                    }
                }
            }
        }
    }
}
