//! Smooth surfaces over a whole triangle mesh, evaluated with exact unit normals at any domain
//! point: PN triangles, and the G² blend of Lee, Hwang and Yoon, "Bézier Triangles with G²
//! Continuity across Boundaries", Symmetry 8(3), 2016 (with the corrections listed below).
//!
//! It deliberately does no tessellation, sharing of edge samples or I/O: it maps (triangle,
//! barycentrics) to a [`SurfacePoint`]. Per-edge widths come in already resolved.
//!
//! The surface of triangle f at barycentrics λ = (u, v, w):
//! 1. `b_f`: a cubic Bézier triangle (Eq. 1) from the corners' positions and normals: by
//!    default the round net of [`nets`] (edge curves that follow circular arcs, centre by a
//!    side-vertex rule), or the PN net of Eq. 2 ([`pn`], all six edge points in `E`) with
//!    [`Nets::Paper`]. Everything below takes any cubic net.
//! 2. Subdomain `k` = the smallest coordinate; the neighbour g across the edge opposite `k`
//!    is reached by the general neighbour map `μ = Mλ` ([`blend::neighbour_map`]; Eq. 3 is
//!    right for one labelling only).
//! 3. `t` from Eq. 4 with `d = √(3/2)·λ_k`, `s` from the nearer corner, `r(s)` from [`Profile`].
//! 4. `S = α(t)·b_f(λ) + (1 − α(t))·b_g(μ)`: Eq. 5 with its weights swapped back, so that S is
//!    `b_f` outside the blending regions.
//! 5. Normals: the analytic `∂_u S × ∂_v S`, through β(t), d, r(s) and s, oriented by the
//!    interpolated input normals.
//!
//! Speed: everything that depends only on the domain point, the three widths and the profile
//! (Bernstein values and derivatives, subdomain, t, β and ∂β) is folded into one weight per
//! control point of the own and the neighbour's net and kept in a [`pattern::Pattern`], built
//! once per (level, lattice part, widths, profile) and shared by every triangle; the neighbour's
//! patch is re-expressed in the triangle's own barycentrics once per edge ([`pn::compose`]), so
//! a point costs 9 dot products of length 10 outside the blending regions and of length 20
//! inside, run for two points at a time, and no allocation. `benches/surface.rs` measures it.
//!
//! Module map: [`nets`] (which rule makes the control nets), [`pn`] (the paper's control net,
//! Bernstein basis, composition), [`profile`] (r(s)), [`blend`] (subdomain,
//! t, β, neighbour map), [`pattern`] (geometry-free per-point weights, cached per lattice in a
//! [`lattice_cache`], as the other schemes' lattice weights are), and
//! `g2.rs` ([`G2Surface`], [`PnSurface`]: nets per triangle, combination, normals), with
//! `neighbour_net.rs` (the neighbour's net in the triangle's own barycentrics, Eq. 3, computed
//! as `pn::compose` computes it but with only the arithmetic that can change a bit) and
//! `net_memo.rs` (each thread's last rebuilt nets, so that a triangle's net is rebuilt about
//! once for its own parts and its neighbours' edges together).

pub mod blend;
pub mod coons;
pub mod flat;
mod g2;
pub mod hybrid;
pub mod lattice_cache;
mod neighbour_net;
mod net_memo;
pub mod nets;
pub mod pattern;
pub mod pn;
pub mod profile;
pub mod scheme;

use glam::DVec3;

use crate::mesh::TriMesh;
use crate::topology::Topology;

pub use flat::FlatSurface;
pub use g2::{G2Surface, PnSurface};
pub use nets::Nets;
pub use profile::Profile;
pub use scheme::{build_surface, Scheme, SchemeParams};

/// Largest blend width: at `h = √2/4` the two arcs of `r(s)` fuse into one and the three regions
/// of a triangle just touch (notes item 4). `h` is a length in the paper's reference triangle
/// (equilateral, side √2), not in world units.
pub const H_MAX: f64 = std::f64::consts::SQRT_2 / 4.0;

/// Checks that a mesh, its topology and its per-edge widths belong together; every surface's
/// constructor calls it, since a mismatch is a caller bug that would otherwise index out of
/// bounds far from its cause.
///
/// # Panics
/// If `topo` was not built from `mesh`, or `h_per_edge` (when given) is not one value per
/// welded edge.
pub(crate) fn assert_belong_together(mesh: &TriMesh, topo: &Topology, h_per_edge: Option<&[f64]>) {
    if let Some(h) = h_per_edge {
        assert_eq!(h.len(), topo.edge_count(), "one h per welded edge");
    }
    assert_eq!(
        topo.tri_verts.len(),
        mesh.triangles.len(),
        "topology of this mesh"
    );
    assert_eq!(
        mesh.normals.len(),
        mesh.positions.len(),
        "one normal per vertex"
    );
}

/// A point of a surface with its unit normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub position: DVec3,
    /// Unit length, on the side of the interpolated input normals.
    pub normal: DVec3,
}

/// The function [`Surface::evaluate_points_on_demand`] hands its caller: appends the points at
/// the barycentrics it is given to the buffer.
pub type PointsOnDemand<'a> = dyn FnMut(&[[f64; 3]], &mut Vec<SurfacePoint>) + 'a;

/// A smooth surface over every triangle of a mesh.
pub trait Surface: Sync {
    /// Position and exact unit normal at barycentrics `bary` (sum 1) of triangle `tri`, corners
    /// in input order. At a corner (`bary` a unit vector) the position is the input vertex's and
    /// the normal its normalized input normal.
    fn evaluate(&self, tri: usize, bary: [f64; 3]) -> SurfacePoint;

    /// All points of the level-`level` lattice (`level ≥ 1`) of triangle `tri`, in lattice order
    /// (see [`lattice_index`]), appended to `out`. Fast implementations reuse a precomputed
    /// pattern; results equal [`Surface::evaluate`] at [`lattice_bary`] bit for bit.
    fn evaluate_lattice(&self, tri: usize, level: u32, out: &mut Vec<SurfacePoint>) {
        self.evaluate_lattice_part(tri, level, LatticePart::All, out);
    }

    /// The points of one part of the level-`level` lattice (`level ≥ 1`) of triangle `tri`, in
    /// the order of [`LatticePart::points`], appended to `out`; equal to [`Surface::evaluate`] at
    /// [`lattice_bary`] bit for bit. The tessellator evaluates each shared edge once, from one
    /// side, and each triangle's interior: every output vertex once, corners not at all.
    fn evaluate_lattice_part(
        &self,
        tri: usize,
        level: u32,
        part: LatticePart,
        out: &mut Vec<SurfacePoint>,
    ) {
        // Through the surface's own scattered-point path, which may have cached weights.
        self.evaluate_lattice_points(tri, level, &part.points(level), out);
    }

    /// The points of several parts `(level, part)` of triangle `tri`'s lattices, appended to
    /// `out` part after part, each as [`Surface::evaluate_lattice_part`] gives it, bit for bit.
    /// The tessellator asks for all the parts a triangle writes at once, so that a surface can
    /// set the triangle up once for all of them.
    fn evaluate_lattice_parts(
        &self,
        tri: usize,
        parts: &[(u32, LatticePart)],
        out: &mut Vec<SurfacePoint>,
    ) {
        for &(level, part) in parts {
            self.evaluate_lattice_part(tri, level, part, out);
        }
    }

    /// The points at barycentrics `barys` of triangle `tri`, appended to `out` in order; equal to
    /// [`Surface::evaluate`] bit for bit. Many points of one triangle at once let a surface do
    /// its per-triangle work once (the chord error measurement asks for thousands).
    fn evaluate_points(&self, tri: usize, barys: &[[f64; 3]], out: &mut Vec<SurfacePoint>) {
        out.extend(barys.iter().map(|&b| self.evaluate(tri, b)));
    }

    /// Calls `drive` once with a function that appends the points of triangle `tri` at any
    /// barycentrics to a buffer, each equal to [`Surface::evaluate_points`]'s bit for bit, for a
    /// caller that decides which points it needs next from those it has: the early-exit check
    /// of `tessellate::chord` stops at the first output triangle over the tolerance, and the
    /// fill choice of `tessellate::fill` measures a candidate triangle only where it could
    /// change the choice.
    /// Here each call is one [`Surface::evaluate_points`] call; a surface that sets a triangle
    /// up per call should set it up once for all of them, as G2Surface does.
    fn evaluate_points_on_demand(
        &self,
        tri: usize,
        drive: &mut dyn FnMut(&mut PointsOnDemand<'_>),
    ) {
        drive(&mut |barys, out| self.evaluate_points(tri, barys, out));
    }

    /// [`Surface::evaluate_lattice`] for a caller that reads the normals of the interior points
    /// only: every position, and the corners' and interior points' normals, are those
    /// [`Surface::evaluate_lattice`] gives, bit for bit; the normals of the other edge points
    /// are unspecified (a surface may leave them out: a third of the work of such a point).
    /// The chord error checks take second differences of positions along the centre point's
    /// normal, and centres are interior.
    fn evaluate_lattice_positions_on_edges(
        &self,
        tri: usize,
        level: u32,
        out: &mut Vec<SurfacePoint>,
    ) {
        self.evaluate_lattice(tri, level, out);
    }

    /// [`Surface::evaluate_lattice_positions_on_edges`] of the level-`level` lattice, given
    /// `coarse`, what that call gave for the level-`level / 2` lattice of the same triangle:
    /// the same points, bit for bit, where it gives them (positions everywhere, the normals of
    /// the corners and interior points). The coarse lattice is the fine one's even points
    /// `(2i, 2j)`, at the same barycentrics bit for bit (`2i/2n` and `i/n` are one quotient,
    /// rounded once), so a surface may copy them and evaluate the other three quarters alone.
    /// A `coarse` that is not such a lattice (`level` odd, or the wrong length) is not read.
    fn evaluate_lattice_positions_on_edges_refining(
        &self,
        tri: usize,
        level: u32,
        coarse: &[SurfacePoint],
        out: &mut Vec<SurfacePoint>,
    ) {
        let _ = coarse;
        self.evaluate_lattice_positions_on_edges(tri, level, out);
    }

    /// [`Surface::evaluate_points`] for a caller that reads only the positions of the first
    /// `positions_only` points: every position, and the normals from point `positions_only`
    /// on, are those [`Surface::evaluate_points`] gives, bit for bit; the first points'
    /// normals are unspecified. The chord error measurement reads its triangles' vertices as
    /// positions and its samples whole, and asks for both in one call so that a surface sets
    /// the triangle up once.
    fn evaluate_points_positions_first(
        &self,
        tri: usize,
        barys: &[[f64; 3]],
        positions_only: usize,
        out: &mut Vec<SurfacePoint>,
    ) {
        let _ = positions_only;
        self.evaluate_points(tri, barys, out);
    }

    /// Some points `(i, j)` of the level-`level` lattice of triangle `tri`, appended to `out` in
    /// the order given; equal to [`Surface::evaluate`] at [`lattice_bary`] bit for bit.
    fn evaluate_lattice_points(
        &self,
        tri: usize,
        level: u32,
        points: &[(u32, u32)],
        out: &mut Vec<SurfacePoint>,
    ) {
        out.extend(
            points
                .iter()
                .map(|&(i, j)| self.evaluate(tri, lattice_bary(level, i, j))),
        );
    }
}

/// A part of a lattice, for [`Surface::evaluate_lattice_part`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LatticePart {
    /// Every point, in lattice order.
    All,
    /// The points off the triangle's boundary, in lattice order.
    Interior,
    /// The `n − 1` points strictly inside the edge opposite corner `k`, walked from corner
    /// `k + 1` towards corner `k + 2`.
    Edge(u8),
}

impl LatticePart {
    /// Lattice coordinates `(i, j)` of the part's points of the level-`n` lattice, in order.
    pub fn points(self, n: u32) -> Vec<(u32, u32)> {
        match self {
            LatticePart::All => (0..=n)
                .flat_map(|j| (0..=n - j).map(move |i| (i, j)))
                .collect(),
            LatticePart::Interior => (1..n)
                .flat_map(|j| (1..n - j).map(move |i| (i, j)))
                .collect(),
            LatticePart::Edge(k) => (1..n)
                .map(|m| match k {
                    0 => (n - m, m),
                    1 => (0, n - m),
                    _ => (m, 0),
                })
                .collect(),
        }
    }

    /// Number of the part's points of the level-`n` lattice: `(n + 1)(n + 2)/2` in all,
    /// `(n − 1)(n − 2)/2` inside, `n − 1` on an edge (corners excluded); `points(n).len()`
    /// without listing them.
    #[inline]
    pub fn len(self, n: u32) -> usize {
        let m = n as usize;
        match self {
            LatticePart::All => lattice_len(n),
            LatticePart::Interior => m.saturating_sub(1) * m.saturating_sub(2) / 2,
            LatticePart::Edge(_) => m.saturating_sub(1),
        }
    }
}

/// Index of lattice point `(i, j)` of level `n`. Lattice order, used by every module: for `j` in
/// `0..=n`, for `i` in `0..=n-j`; point `(i, j)` has barycentrics [`lattice_bary`]`(n, i, j)`.
#[inline]
pub fn lattice_index(n: u32, i: u32, j: u32) -> usize {
    let (n, i, j) = (n as usize, i as usize, j as usize);
    j * (2 * n + 3 - j) / 2 + i
}

/// Number of points in the level-`n` lattice, `(n + 1)(n + 2)/2`.
#[inline]
pub fn lattice_len(n: u32) -> usize {
    let n = n as usize;
    (n + 1) * (n + 2) / 2
}

/// Barycentrics `((n−i−j)/n, i/n, j/n)` of lattice point `(i, j)`, each an exact integer
/// division in f64, so corners are exact unit vectors and edge points have an exact 0.
#[inline]
pub fn lattice_bary(n: u32, i: u32, j: u32) -> [f64; 3] {
    let nf = n as f64;
    [(n - i - j) as f64 / nf, i as f64 / nf, j as f64 / nf]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lattice_index_counts_rows() {
        let n = 5;
        let mut idx = 0;
        for j in 0..=n {
            for i in 0..=n - j {
                assert_eq!(lattice_index(n, i, j), idx);
                idx += 1;
            }
        }
        assert_eq!(idx, lattice_len(n));
    }

    #[test]
    fn lattice_parts_cover_the_lattice_once() {
        for n in 1..=7 {
            let mut seen = vec![0; lattice_len(n)];
            for part in [
                LatticePart::Interior,
                LatticePart::Edge(0),
                LatticePart::Edge(1),
                LatticePart::Edge(2),
            ] {
                for (i, j) in part.points(n) {
                    seen[lattice_index(n, i, j)] += 1;
                    let l = lattice_bary(n, i, j);
                    match part {
                        LatticePart::Edge(k) => assert_eq!(l[k as usize], 0.0),
                        _ => assert!(l.iter().all(|&x| x > 0.0)),
                    }
                }
            }
            // Everything but the three corners, once.
            assert_eq!(seen.iter().filter(|&&c| c == 0).count(), 3);
            assert!(seen.iter().all(|&c| c <= 1));
            let all = LatticePart::All.points(n);
            assert!((0..all.len()).all(|x| lattice_index(n, all[x].0, all[x].1) == x));
        }
    }
}
