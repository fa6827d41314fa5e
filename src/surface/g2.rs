//! [`G2Surface`]: per-triangle control nets (own PN patch, and the neighbour patches re-expressed
//! in its barycentrics when they are needed) and their combination with [`PointWeights`] into
//! positions and exact normals; [`PnSurface`] is its h = 0 case.
//!
//! It deliberately computes no weights itself (see `pattern.rs`, `blend.rs`) and never fails:
//! bad edges act as h = 0 and are reported through [`G2Surface::warnings`].

use glam::DVec3;
use rayon::prelude::*;

use super::neighbour_net::{compose_across, Reach, SoaNet};
use super::net_memo::{self, Local};
use super::nets::Nets;
use super::pattern::{
    EdgeRows, Lanes, NetWeights, Pattern, PatternCache, PointWeights, EDGE_ROWS, EDGE_VALUE_ROWS,
    LANES,
};
use super::pn::{Net, B111, NEAR};
use super::{lattice_len, LatticePart, Profile, Surface, SurfacePoint};
use crate::mesh::TriMesh;
use crate::sharpness::EffectiveH;
use crate::topology::{Edge, EdgeId, Topology, TriId};

mod point_sets;
mod positions;
mod refine;

/// Everything one triangle needs at evaluation time that the mesh and its topology do not
/// already hold: 88 bytes, one allocation for the whole mesh.
///
/// The corners' positions and normals are read from the mesh the surface borrows, the
/// neighbours and edge widths through its topology, not copied: every rule of [`Nets`] copies a corner's position
/// into its net bit for bit and the shared edge curves leave corners alone, so the net is whole
/// again when a lattice part asks for it ([`G2Surface::local`]). Both outlive the surface in
/// the pipeline anyway (the tessellation reads them), so a copy here would only add to the
/// run's peak, which is reached while the surface is alive: at a million input triangles every
/// byte held per triangle is a megabyte.
#[derive(Debug, Clone)]
struct Patch {
    /// Control points 3 to 9 of the own net `b_f` (Eq. 2 or the round net, with shared edge
    /// curves on unblended split edges), by coordinate: the six edge points and `b111`, each as
    /// its offset from the flat net's point ([`flat_point`]), in `f32`.
    ///
    /// The offset is the part of a control point that curvature makes, `O(κ·L²)` for edges of
    /// length `L`, so `f32` keeps it to about `6e-8` of that (1e-13 of the radius on a
    /// million-triangle unit sphere) in half the bytes of the point. Both triangles of an edge
    /// compute the same flat point from the same two corners, so a curve they share is still
    /// shared bit for bit, and the surface stays watertight exactly as with `f64` points.
    inner: [[f32; INNER]; 3],
    /// Bit `m − 3` set: edge point `m` is an average of split-normal curves (PN-AEN), used as
    /// stored. Every other edge point lies in its corner's tangent plane (both net rules put it
    /// there), and is put back into it exactly when the net is rebuilt ([`local`]): the `f32`
    /// offset would otherwise tilt each patch's tangent plane at a corner by up to `6e-8` rad,
    /// differently in each triangle around a vertex, and the surface would no longer be G1 at
    /// the vertex to rounding.
    as_stored: u8,
}

/// The bytes a [`Patch`] takes: pinned, since the surface's memory per triangle is a figure the
/// pipeline is planned around (the run's peak at a million triangles).
const _: () = assert!(std::mem::size_of::<Patch>() == 88);

/// Control points of a net that are not corners (the corners are slots 0, 1, 2).
const INNER: usize = 7;

/// Where the surface takes each triangle's [`Patch`] from when its net is rebuilt.
#[derive(Debug)]
enum Patches {
    /// Made for every triangle when the surface is built (88 bytes each), and rewritten where
    /// an unblended edge's triangles share one curve.
    Stored(Vec<Patch>),
    /// Made again from the triangle's corners by this rule each time its net is rebuilt: the
    /// patch [`Patches::Stored`] would hold, since no edge curve is shared
    /// ([`on_demand_pays`]).
    ///
    /// Why: at level 2 every net is read in the one pass of the tessellator, in triangle order,
    /// and the memo of rebuilt nets (`net_memo`) keeps it from its first use to its last, so
    /// it is made about once either way. Storing it first cost a pass of its own over the
    /// corners and 88 MB (each page a fault) on a million triangles, and it was then rebuilt
    /// from what was stored.
    OnDemand(Nets),
}

/// The point of the flat net (the triangle itself as a cubic) in slot `m`:
/// `(i·p0 + j·p1 + k·p2)/3` for the exponents `(i, j, k)` of [`IJK`](super::pn::IJK).
///
/// Written per kind of slot so that an edge point depends on its edge's two corners only and
/// in the same way from both triangles of the edge (`(2·p_c + p_e)/3`, the corner it is next
/// to first), whatever the triangles' corner order: the offsets of a shared edge curve are then
/// equal on both sides, and so are the points rebuilt from them.
#[inline]
fn flat_point(p: [f64; 3], m: usize) -> f64 {
    match m {
        B111 => (p[0] + p[1] + p[2]) / 3.0,
        _ => {
            let [c, e] = NEAR_OF[m - 3];
            (2.0 * p[c] + p[e]) / 3.0
        }
    }
}

/// `NEAR_OF[m − 3] = [c, e]` for the edge slot `m = NEAR[c][e]` (the inverse of [`NEAR`]).
const NEAR_OF: [[usize; 2]; 6] = {
    let mut table = [[0; 2]; 6];
    let mut c = 0;
    while c < 3 {
        let mut e = 0;
        while e < 3 {
            if c != e {
                table[NEAR[c][e] - 3] = [c, e];
            }
            e += 1;
        }
        c += 1;
    }
    table
};

/// Coordinate `x` of the corners `p`, by corner.
#[inline]
fn coordinate(p: &[DVec3; 3], x: usize) -> [f64; 3] {
    [p[0][x], p[1][x], p[2][x]]
}

/// `net`'s control points 3 to 9 as the offsets [`Patch::inner`] stores.
fn offsets(net: &Net) -> [[f32; INNER]; 3] {
    let mut out = [[0.0; INNER]; 3];
    for (x, coord) in out.iter_mut().enumerate() {
        let p = [net[0][x], net[1][x], net[2][x]];
        for (m, offset) in coord.iter_mut().enumerate() {
            *offset = (net[3 + m][x] - flat_point(p, 3 + m)) as f32;
        }
    }
    out
}

/// The G² blended surface of Lee–Hwang–Yoon over a whole mesh, one width `h` per welded edge.
///
/// It borrows the mesh (corner positions and normals), its topology (each triangle's edges, and
/// the neighbour across each blended edge) and the widths instead of copying them; see
/// `Patch`.
#[derive(Debug)]
pub struct G2Surface<'a> {
    mesh: &'a TriMesh,
    topo: &'a Topology,
    /// One width per welded edge; `None`: 0 on every edge (PN triangles).
    h: Option<&'a [f64]>,
    patches: Patches,
    profile: Profile,
    patterns: PatternCache,
    /// The weights of the scattered point sets asked for again and again ([`point_sets`]), a
    /// store per size of set ([`point_sets::TIERS`]).
    point_sets: point_sets::PointSetStores,
    /// The weights of the points a lattice adds to the one of half its level ([`refine`]).
    odd_points: refine::OddPointsCache,
    /// This surface's tag in the per-thread memo of rebuilt nets ([`net_memo`]).
    memo_owner: u64,
}

impl<'a> G2Surface<'a> {
    /// Builds the surface with the widths `h` the pipeline decided (one per edge of `topo`;
    /// boundary, non-manifold and degenerate edges are 0 there, so they are PN creases). Where
    /// an edge is not blended but its triangles disagree on its boundary curve (split normals),
    /// all of them use the average of their edge control points (PN-AEN), so the surface stays
    /// watertight.
    ///
    /// # Panics
    /// If `h`, `topo` and `mesh` do not belong together (a caller bug).
    pub fn new(mesh: &'a TriMesh, topo: &'a Topology, h: &'a EffectiveH, profile: Profile) -> Self {
        Self::with_nets(mesh, topo, h, profile, Nets::default())
    }

    /// [`G2Surface::new`] over control nets made by the rule `nets` instead of the default.
    ///
    /// # Panics
    /// If `h`, `topo` and `mesh` do not belong together (a caller bug).
    pub fn with_nets(
        mesh: &'a TriMesh,
        topo: &'a Topology,
        h: &'a EffectiveH,
        profile: Profile,
        nets_rule: Nets,
    ) -> Self {
        super::assert_belong_together(mesh, topo, Some(h));
        Self::build(mesh, topo, Some(h), profile, nets_rule)
    }

    /// [`G2Surface::with_nets`] for a caller that reads the surface in one pass over the
    /// triangles in order, as the uniform tessellator does: where that lets each net be made
    /// about once without storing it, no patch is stored (made on demand). Every point
    /// has the same bits as on the surface [`G2Surface::with_nets`] builds; only the cost
    /// differs, and a caller that reads triangles in another order or more than once (a
    /// tolerance's probes, a report's figures, a chain of levels) should take that one.
    ///
    /// # Panics
    /// If `h`, `topo` and `mesh` do not belong together (a caller bug).
    pub fn with_nets_for_one_pass(
        mesh: &'a TriMesh,
        topo: &'a Topology,
        h: &'a EffectiveH,
        profile: Profile,
        nets_rule: Nets,
    ) -> Self {
        super::assert_belong_together(mesh, topo, Some(h));
        let on_demand = on_demand_pays(topo, h);
        Self::assemble(mesh, topo, Some(h), profile, nets_rule, on_demand)
    }

    /// [`G2Surface::with_nets`] with the widths checked; `h`: `None` for 0 on every edge.
    fn build(
        mesh: &'a TriMesh,
        topo: &'a Topology,
        h: Option<&'a [f64]>,
        profile: Profile,
        nets_rule: Nets,
    ) -> Self {
        Self::assemble(mesh, topo, h, profile, nets_rule, false)
    }

    /// The surface with its patches stored, or made on demand when `on_demand` (which the
    /// caller has found to pay, and which requires every edge curve to be its own triangle's:
    /// see [`on_demand_pays`]).
    fn assemble(
        mesh: &'a TriMesh,
        topo: &'a Topology,
        h: Option<&'a [f64]>,
        profile: Profile,
        nets_rule: Nets,
        on_demand: bool,
    ) -> Self {
        let patches = if on_demand {
            Patches::OnDemand(nets_rule)
        } else {
            // Built in place, in the final array, in one pass: no per-triangle corner or net
            // arrays beside it.
            Patches::Stored(
                (0..mesh.triangles.len())
                    .into_par_iter()
                    .map(|t| {
                        let (position, normal) = corners(mesh, mesh.triangles[t]);
                        Patch {
                            inner: offsets(&nets_rule.net(position, normal)),
                            as_stored: 0,
                        }
                    })
                    .collect(),
            )
        };
        let mut surface = G2Surface {
            mesh,
            topo,
            h,
            patches,
            profile,
            patterns: PatternCache::default(),
            point_sets: point_sets::PointSetStores::default(),
            odd_points: refine::OddPointsCache::new(refine::MAX_LEVELS),
            memo_owner: net_memo::new_owner(),
        };
        debug_assert!((0..mesh.triangles.len()).all(|t| (0..3)
            .all(|k| surface.widths(t)[k] == 0.0 || topo.neighbour(TriId(t as u32), k).is_some())));
        match &mut surface.patches {
            Patches::Stored(patches) => {
                share_unblended_edge_curves(mesh, topo, h, patches, nets_rule)
            }
            Patches::OnDemand(_) => {
                debug_assert!(h.is_some_and(|h| !has_unblended_shared_edge(topo, h)))
            }
        }
        surface
    }

    /// The effective widths of the edges opposite triangle `tri`'s corners.
    #[inline]
    fn widths(&self, tri: usize) -> [f64; 3] {
        match self.h {
            Some(h) => self.topo.tri_edges[tri].map(|e| h[e.0 as usize]),
            None => [0.0; 3],
        }
    }

    /// Bytes this surface holds on the heap for its triangles (capacities, not lengths; the
    /// pattern cache, shared by all triangles, and the borrowed mesh and topology are not
    /// counted).
    pub fn heap_bytes(&self) -> usize {
        match &self.patches {
            Patches::Stored(patches) => patches.capacity() * std::mem::size_of::<Patch>(),
            Patches::OnDemand(_) => 0,
        }
    }

    /// The neighbour's net across edge `k` of triangle `tri` in `tri`'s barycentrics,
    /// `b_g ∘ M` (Eq. 3 in the form of [`neighbour_map`](super::blend::neighbour_map)); `k`
    /// must be a blended edge. With `reach` [`Reach::Edge`] only the seven control points a
    /// point on edge `k` itself weighs are composed (see [`compose_across`]).
    ///
    /// The composed nets are not stored: three of them per triangle were two thirds of the
    /// surface's memory (720 of 1128 bytes), more than the dense output of a level-8 triangle,
    /// and composing costs less than the page faults of holding them. Each is composed once per
    /// lattice part, with the same arithmetic on every path, so point and lattice evaluation
    /// still agree bit for bit.
    ///
    /// Written into `out` (see [`compose_across`]): a part composes straight into the net it
    /// keeps.
    fn across_net(&self, tri: usize, k: usize, reach: Reach, out: &mut SoaNet) {
        debug_assert!(self.widths(tri)[k] > 0.0, "only blended edges");
        let n = self
            .topo
            .neighbour(TriId(tri as u32), k)
            .expect("blended edges are interior");
        let [p, q, r] = n.slots.map(usize::from);
        // The neighbour's whole net, as its own lattice parts read it: usually kept from its
        // first rebuild (`net_memo`). An edge's composition never reads the two points next to
        // the neighbour's third corner `r` (exponent 2 of `μ_r`, see `compose_across`), and
        // every other point is rebuilt by the same arithmetic whether those two are put back
        // into their tangent plane or not (each point's projection reads only itself, its
        // corner and that corner's normal), so the composed net has the same bits either way.
        self.with_local(n.tri.0 as usize, |g| {
            compose_across(&g.net, k, [p, q, r], reach, out)
        })
    }

    /// The [`Split`] of blended edge `k` of triangle `tri`, whose own corner normals are
    /// `normal`. Most edges have no split normals, and the topology's flag says so without
    /// reading the neighbour (it compares the input normals themselves: where they are equal,
    /// so are the unit normals made from them); only flagged edges compare the unit normals.
    #[inline]
    fn split_across(&self, tri: usize, k: usize, normal: &[DVec3; 3]) -> Option<Split> {
        if !self.topo.split_normals(self.topo.tri_edges[tri][k]) {
            return None;
        }
        self.split_of_flagged(tri, k, normal)
    }

    /// [`G2Surface::split_across`] past the flag: the neighbour's corner normals read.
    #[cold]
    #[inline(never)]
    fn split_of_flagged(&self, tri: usize, k: usize, normal: &[DVec3; 3]) -> Option<Split> {
        let n = self
            .topo
            .neighbour(TriId(tri as u32), k)
            .expect("blended edges are interior");
        let [p, q, _] = n.slots.map(usize::from);
        self.with_local(n.tri.0 as usize, |g| split(normal, &g.normal, k, [p, q]))
    }

    /// `read` of triangle `tri`'s whole net and corner normals, exactly as they were when its
    /// net was stored: kept in this thread's memo from an earlier rebuild when there is one,
    /// which has the same bits (`net_memo`).
    #[inline]
    fn with_local<R>(&self, tri: usize, read: impl FnOnce(&Local) -> R) -> R {
        let rebuild = |out: &mut Local| match &self.patches {
            Patches::Stored(patches) => local_into(self.mesh, tri, &patches[tri], out),
            Patches::OnDemand(rule) => made_local_into(self.mesh, tri, *rule, out),
        };
        net_memo::with_local(self.memo_owner, tri, rebuild, read)
    }

    /// The profile `r(s)` in use.
    pub fn profile(&self) -> Profile {
        self.profile
    }

    /// The surface points of `L` domain points of `patch` from their weights, on its own net
    /// `own` and, when they blend, the neighbour's net `across` (the points of one [`Lanes`]
    /// block all blend with the same neighbour, or with none).
    ///
    /// Position and tangents are the sums of the pattern module's documentation (Eq. 5 and its
    /// derivatives); the normal is `∂_u S × ∂_v S`, turned to the side of the input normals
    /// blended as the surface is ([`Split`]): the own corner normals interpolated,
    /// `Σ b_c n_c`, where the point blends with nobody or the edge it blends across has no
    /// split normals (`split` is `None`), and otherwise `(1 − β)·Σ b_c n_c + β·Σ b_c n′_c`,
    /// `n′` the own corner normals with the shared edge's two corners taking the neighbour's.
    /// Each lane's sums run in the same order whatever `L`, so a lattice block and a single
    /// point agree bit for bit.
    ///
    /// Only the control points `edge_rows` names are summed (in slot order): all ten, or, where
    /// the pattern found every other weight exactly zero, [`EDGE_ROWS`]`[k]`, and for the
    /// position of a one-lane block [`EDGE_VALUE_ROWS`]`[k]`. Leaving such a term out leaves
    /// every bit as it was: the sums start at `+0` and so are never `−0` (in round-to-nearest
    /// `a + b = −0` only when both are `−0`), the nets are finite (finite `f32` positions, unit
    /// normals, bounded handles), so each left-out term `±0·x` is `±0`, and adding `±0` to a
    /// sum that is not `−0` does not change it.
    #[inline(always)]
    fn combine<const L: usize, N: LaneNet<L>>(
        normal: &[DVec3; 3],
        w: &Lanes<L>,
        own: &N,
        across: Option<&N>,
        split: Option<&Split>,
        edge_rows: EdgeRows,
    ) -> [SurfacePoint; L] {
        let sums = |rows: &[usize; 7], value_rows: &[usize; 4]| {
            // Two lanes share each net's load between the three quantities; one lane has no
            // such load to share, and skips the three position terms that are zero.
            if L == 1 {
                let acc = accumulate_split(&w.own, own, [[[0.0; L]; 3]; 3], value_rows, rows);
                match across {
                    Some(across) => accumulate_split(&w.across, across, acc, value_rows, rows),
                    None => acc,
                }
            } else {
                let acc = accumulate(&w.own, own, [[[0.0; L]; 3]; 3], rows);
                match across {
                    Some(across) => accumulate(&w.across, across, acc, rows),
                    None => acc,
                }
            }
        };
        let acc = match edge_rows {
            EdgeRows::All => {
                let acc = accumulate(&w.own, own, [[[0.0; L]; 3]; 3], &ALL_ROWS);
                match across {
                    Some(across) => accumulate(&w.across, across, acc, &ALL_ROWS),
                    None => acc,
                }
            }
            EdgeRows::Edge(k) => {
                let rows = &EDGE_ROWS[k as usize];
                let acc = accumulate(&w.own, own, [[[0.0; L]; 3]; 3], rows);
                match across {
                    Some(across) => accumulate(&w.across, across, acc, rows),
                    None => acc,
                }
            }
            EdgeRows::EdgeValues(k) => sums(&EDGE_ROWS[k as usize], &EDGE_VALUE_ROWS[k as usize]),
        };
        let normals = lane_normals(normal, w, split, &acc[1], &acc[2]);
        std::array::from_fn(|l| SurfacePoint {
            position: DVec3::new(acc[0][0][l], acc[0][1][l], acc[0][2][l]),
            normal: normals[l],
        })
    }
}

/// The unit normals of `L` points from their tangent sums `du` and `dv`
/// (`[coordinate][lane]`), as [`G2Surface::combine`] describes them: `∂_u S × ∂_v S`
/// normalized and turned to the side of the input normals blended as the surface is (the own
/// corner normals `normal` interpolated at each lane's barycentrics, and the neighbour's
/// share `β` of the [`Split`] difference where there is one).
///
/// Lane by lane the operations of `DVec3::cross`, `dot`, `/` and `-` in their order, so each
/// normal has the bits of the one-point evaluation; the cross product, the division and the
/// side's dot product are taken over whole lanes, as the sums are, instead of in a closure per
/// point, which the compiler did not inline (the `--level 16` run of the 10k icosphere: 1.0817e9
/// → 1.0514e9 instructions).
#[inline(always)]
#[allow(clippy::needless_range_loop)] // As in `accumulate`: the form that unrolls into SIMD.
fn lane_normals<const L: usize>(
    normal: &[DVec3; 3],
    w: &Lanes<L>,
    split: Option<&Split>,
    du: &[[f64; L]; 3],
    dv: &[[f64; L]; 3],
) -> [DVec3; L] {
    let dot = |a: &[[f64; L]; 3], b: &[[f64; L]; 3], l: usize| {
        a[0][l] * b[0][l] + a[1][l] * b[1][l] + a[2][l] * b[2][l]
    };
    // `du.cross(dv)`.
    let mut n = [[0.0; L]; 3];
    for l in 0..L {
        n[0][l] = du[1][l] * dv[2][l] - dv[1][l] * du[2][l];
        n[1][l] = du[2][l] * dv[0][l] - dv[2][l] * du[0][l];
        n[2][l] = du[0][l] * dv[1][l] - dv[0][l] * du[1][l];
    }
    // `b[0] * normal[0] + b[1] * normal[1] + b[2] * normal[2]`, then, with split normals,
    // `(1 − β)·Σ b_c n_c + β·Σ b_c n′_c` written as the own side plus the share of the
    // difference: only the two corners of the edge differ.
    let own = normal.map(|n| n.to_array());
    let mut interpolated = [[0.0; L]; 3];
    for c in 0..3 {
        for l in 0..L {
            let b = w.bary[l];
            interpolated[c][l] = b[0] * own[0][c] + b[1] * own[1][c] + b[2] * own[2][c];
        }
    }
    if let Some(d) = split {
        let d = d.map(|d| d.to_array());
        for c in 0..3 {
            for l in 0..L {
                let b = w.bary[l];
                interpolated[c][l] +=
                    w.beta[l] * (b[0] * d[0][c] + b[1] * d[1][c] + b[2] * d[2][c]);
            }
        }
    }
    // `n / len2.sqrt()` and its side in every lane: a lane that falls back below discards
    // them.
    let mut len2 = [0.0; L];
    let mut unit = [[0.0; L]; 3];
    let mut side = [0.0; L];
    for l in 0..L {
        len2[l] = dot(&n, &n, l);
        let length = len2[l].sqrt();
        for c in 0..3 {
            unit[c][l] = n[c][l] / length;
        }
        side[l] = dot(&unit, &interpolated, l);
    }
    std::array::from_fn(|l| {
        // |N| ≤ 1e-14·|∂_u S|·|∂_v S|: the tangents are parallel to rounding (a degenerate
        // triangle); fall back to the (blended) interpolated input normal.
        let parallel = 1e-28 * dot(du, du, l) * dot(dv, dv, l);
        if len2[l] > parallel && len2[l].is_finite() {
            let n = DVec3::new(unit[0][l], unit[1][l], unit[2][l]);
            if side[l] < 0.0 {
                -n
            } else {
                n
            }
        } else {
            DVec3::new(interpolated[0][l], interpolated[1][l], interpolated[2][l])
                .normalize_or(normal[0])
        }
    })
}

/// Where the two triangles of a blended edge carry different input normals at its ends (split
/// normals): `n′_c − n_c` for each own corner `c`, the neighbour's unit input normal at that
/// vertex minus the own, 0 at the corner off the edge.
///
/// Why the side of a normal needs it: `∂_u S × ∂_v S` fixes the normal's line, and both
/// triangles of a blended edge find the same line on it (the blend is G¹ there). Each side was
/// chosen by the own corner normals interpolated; with split normals the two triangles
/// interpolate different normals along the edge, and where the surface stands near a right
/// angle to them the two sides fell on opposite sides of it: a 180° turn along the edge.
/// The side is now chosen by the input normals blended as the surface is (Eq. 5):
/// `(1 − β)·Σ b_c n_c + β·Σ b_c n′_c`. On the edge `β = ½` from both sides (`t = ½` there, and
/// `β(½) = ½`) and `b` is the same point, so both sides' references are
/// `½ Σ b_c (n_c + n′_c)` (to rounding) and choose the same side wherever the surface is not
/// tangent to it; away from the edge the reference fades into the own interpolation with the
/// blend, so it is continuous over the triangle and the blended edge, and inside a patch that
/// folds it still follows the own normals point by point (one sign per piece of triangles
/// instead removed the turns at edges but broke the normals of folds). Where a triangle's own
/// normals lie on the other side of the surface than its neighbour's, the side must still
/// change somewhere between their interiors: it now changes inside the blending region, where
/// the surface is tangent to the blended normals, instead of along the edge.
type Split = [DVec3; 3];

/// The [`Split`] across edge `k` whose neighbour holds the own corners `k + 1` and `k + 2` in
/// its slots `p` and `q`, from the own corner normals `own` and the neighbour's `theirs`;
/// `None` when they are equal bit for bit, where the reference is the own interpolation and
/// no arithmetic is added (the output is then that of the own rule, bit for bit).
#[inline]
fn split(own: &[DVec3; 3], theirs: &[DVec3; 3], k: usize, [p, q]: [usize; 2]) -> Option<Split> {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    if theirs[p] == own[i] && theirs[q] == own[j] {
        return None;
    }
    let mut d = [DVec3::ZERO; 3];
    d[i] = theirs[p] - own[i];
    d[j] = theirs[q] - own[j];
    Some(d)
}

/// Every control point, in slot order: the rows [`G2Surface::combine`] sums by default.
const ALL_ROWS: [usize; 10] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9];

/// A control net with every coordinate repeated in `L` lanes, `[control point][x, y, z][lane]`:
/// the sums of [`accumulate`] are then the same operation on whole lanes, which compilers turn
/// into SIMD arithmetic without being told. Made only for blocks of two or more lanes: a
/// one-lane block reads the [`SoaNet`] itself (a level-2 run then makes no copy at all).
type Broadcast<const L: usize> = [[[f64; L]; 3]; 10];

fn broadcast<const L: usize>(net: &SoaNet) -> Broadcast<L> {
    // Plain loops: nested `array::map` closures were not inlined, and cost more than the sums.
    let mut out = [[[0.0; L]; 3]; 10];
    for (m, point) in out.iter_mut().enumerate() {
        for (lanes, coord) in point.iter_mut().zip(net) {
            *lanes = [coord[m]; L];
        }
    }
    out
}

/// A net as the sums of `L` lanes read it: coordinate `c` of control point `m` in every lane.
/// The same value whichever layout it comes from, so the sums have the same bits.
trait LaneNet<const L: usize> {
    fn lanes(&self, m: usize, c: usize) -> [f64; L];
}

impl<const L: usize> LaneNet<L> for Broadcast<L> {
    #[inline(always)]
    fn lanes(&self, m: usize, c: usize) -> [f64; L] {
        self[m][c]
    }
}

impl LaneNet<1> for SoaNet {
    #[inline(always)]
    fn lanes(&self, m: usize, c: usize) -> [f64; 1] {
        [self[c][m]]
    }
}

/// Adds the weighted sums of one net to `acc[quantity][coordinate][lane]`: for each lane, the
/// control points in order, so that the result does not depend on how many lanes run together.
///
/// The sums are taken and returned by value, and written as plain indexed loops: kept out of
/// memory that way, the compiler unrolls them and runs the lanes in SIMD registers.
#[inline(always)]
#[allow(clippy::needless_range_loop)] // Indexed loops are the form that unrolls into SIMD.
fn accumulate<const L: usize, const R: usize, N: LaneNet<L>>(
    w: &NetWeights<L>,
    net: &N,
    mut acc: [[[f64; L]; 3]; 3],
    rows: &[usize; R],
) -> [[[f64; L]; 3]; 3] {
    for &m in rows {
        for q in 0..3 {
            for c in 0..3 {
                let x = net.lanes(m, c);
                for l in 0..L {
                    acc[q][c][l] += w[q][m][l] * x[l];
                }
            }
        }
    }
    acc
}

/// [`accumulate`] with the position summed over `value_rows` only and the tangents over `rows`
/// (each in slot order; the sums are independent, so the split changes no bit).
#[inline(always)]
#[allow(clippy::needless_range_loop)] // As in `accumulate`.
fn accumulate_split<const L: usize, const V: usize, const R: usize, N: LaneNet<L>>(
    w: &NetWeights<L>,
    net: &N,
    mut acc: [[[f64; L]; 3]; 3],
    value_rows: &[usize; V],
    rows: &[usize; R],
) -> [[[f64; L]; 3]; 3] {
    for &m in value_rows {
        for c in 0..3 {
            let x = net.lanes(m, c);
            for l in 0..L {
                acc[0][c][l] += w[0][m][l] * x[l];
            }
        }
    }
    for &m in rows {
        for q in 1..3 {
            for c in 0..3 {
                let x = net.lanes(m, c);
                for l in 0..L {
                    acc[q][c][l] += w[q][m][l] * x[l];
                }
            }
        }
    }
    acc
}

/// A net by control point (the inverse of [`soa`], bit for bit).
fn aos(net: &SoaNet) -> Net {
    std::array::from_fn(|m| DVec3::new(net[0][m], net[1][m], net[2][m]))
}

/// Corner `c`'s position in a net.
#[inline]
fn corner(net: &SoaNet, c: usize) -> DVec3 {
    DVec3::new(net[0][c], net[1][c], net[2][c])
}

/// Positions and unit normals of the corners `verts` as the net rules take them: the
/// normalized input normals, and the face normal where one has no direction.
///
/// Normalized here, each time, rather than once per vertex into an array of their own: the
/// division costs less than the memory, and it is the same arithmetic on every path, so a
/// net is rebuilt bit for bit.
///
/// Written as plain loops rather than `array::map`: every patch set-up and every lattice part
/// comes through here, and the closures `map` takes were not inlined.
#[inline]
fn corners(mesh: &TriMesh, verts: [u32; 3]) -> ([DVec3; 3], [DVec3; 3]) {
    let mut position = [DVec3::ZERO; 3];
    let mut normal = [DVec3::ZERO; 3];
    for c in 0..3 {
        let v = verts[c] as usize;
        position[c] = mesh.positions[v];
        normal[c] = mesh.normals[v].normalize_or(DVec3::ZERO);
    }
    // Only for the rare vertex without a normal.
    if normal.contains(&DVec3::ZERO) {
        let face = face_fallback(position);
        for n in &mut normal {
            if *n == DVec3::ZERO {
                *n = face;
            }
        }
    }
    (position, normal)
}

/// The unit face normal of a triangle (+z if it has none): the corner normal of an input
/// vertex whose normal has no direction.
#[inline]
fn face_fallback(p: [DVec3; 3]) -> DVec3 {
    (p[1] - p[0]).cross(p[2] - p[0]).normalize_or(DVec3::Z)
}

/// Triangle `tri`'s whole net and corner normals from its `patch` (see
/// [`G2Surface::with_local`]).
fn local(mesh: &TriMesh, tri: usize, patch: &Patch) -> Local {
    let mut out = Local {
        net: [[0.0; 10]; 3],
        normal: [DVec3::ZERO; 3],
    };
    local_into(mesh, tri, patch, &mut out);
    out
}

/// [`local`], written into `out` (a slot of the memo of rebuilt nets, without a copy).
#[inline]
fn local_into(mesh: &TriMesh, tri: usize, patch: &Patch, out: &mut Local) {
    let (position, normal) = corners(mesh, mesh.triangles[tri]);
    // Plain loops, not `array::from_fn`, whose closure was not inlined (see `corners`).
    let net = &mut out.net;
    for (x, coord) in net.iter_mut().enumerate() {
        let p = coordinate(&position, x);
        coord[..3].copy_from_slice(&p);
        for (m, (point, &offset)) in coord[3..].iter_mut().zip(&patch.inner[x]).enumerate() {
            *point = flat_point(p, 3 + m) + f64::from(offset);
        }
    }
    onto_tangent_planes(net, &normal, patch.as_stored);
    out.normal = normal;
}

/// [`local_into`] of the patch [`Patches::Stored`] holds for `tri` where no edge curve is
/// shared: its net made by `rule` from its corners, each point off the corners rounded to its
/// `f32` offset and rebuilt from it, with the same operations in the same order as
/// [`offsets`] then [`local_into`], so with the same bits. The corners are read and each flat
/// point is computed once for both halves.
#[inline]
fn made_local_into(mesh: &TriMesh, tri: usize, rule: Nets, out: &mut Local) {
    let (position, normal) = corners(mesh, mesh.triangles[tri]);
    let made = rule.net(position, normal);
    for (x, coord) in out.net.iter_mut().enumerate() {
        let p = coordinate(&position, x);
        coord[..3].copy_from_slice(&p);
        for (m, point) in coord[3..].iter_mut().enumerate() {
            let flat = flat_point(p, 3 + m);
            let offset = (made[3 + m][x] - flat) as f32;
            *point = flat + f64::from(offset);
        }
    }
    onto_tangent_planes(&mut out.net, &normal, 0);
    out.normal = normal;
}

/// Whether some edge with two or more triangles and two distinct ends is not blended: there
/// [`share_unblended_edge_curves`] may make its triangles share one curve, which a patch made
/// on demand would not.
fn has_unblended_shared_edge(topo: &Topology, h: &[f64]) -> bool {
    h.par_iter().enumerate().any(|(e, &h)| {
        h == 0.0 && {
            let edge = topo.edge(EdgeId(e as u32));
            edge.tris.len() >= 2 && edge.verts[0] != edge.verts[1]
        }
    })
}

/// Whether the patches of a surface read in one pass in triangle order are better made on
/// demand ([`Patches::OnDemand`]) than stored: every edge curve is its own triangle's, and the
/// neighbours across blended edges lie close enough in triangle order that the memo of
/// rebuilt nets keeps each net from its first use to its last.
///
/// A net the memo has lost is made again whole (about four times the cost of a rebuild from
/// a stored patch), so the neighbours must be near: at most one blended edge in
/// [`FAR_SHARE`] may join triangles half the memo's size apart or more. The bench icospheres
/// have 0.4% (1M) and 1.4% (100k) of neighbours farther than the whole memo's size, the 10k
/// one 3.3% (across the faces of its icosahedron).
fn on_demand_pays(topo: &Topology, h: &[f64]) -> bool {
    if has_unblended_shared_edge(topo, h) {
        return false;
    }
    // A sample of the triangles tells as well as all of them, at a seventh of the cost.
    let (far, blended) = (0..topo.tri_edges.len())
        .into_par_iter()
        .step_by(SAMPLE_STRIDE)
        .map(|t| {
            let mut counts = (0usize, 0usize);
            for (k, e) in topo.tri_edges[t].iter().enumerate() {
                if h[e.0 as usize] > 0.0 {
                    counts.1 += 1;
                    let n = topo
                        .neighbour(TriId(t as u32), k)
                        .expect("blended edges are interior");
                    if (n.tri.0 as usize).abs_diff(t) >= net_memo::SLOTS / 2 {
                        counts.0 += 1;
                    }
                }
            }
            counts
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    far * FAR_SHARE <= blended
}

/// See [`on_demand_pays`]. Measured on the 10k icosphere at level 2 with pairs of triangles
/// swapped (callgrind, one thread, whole process), stored against on demand: 3.3% of far
/// neighbours 108.5 M against 104.3 M instructions, 6.8% 108.8 M / 104.9 M, 11.9% 109.0 M /
/// 105.7 M, 19.4% 109.3 M / 107.1 M: on demand costs less up to about a third, so one in
/// eight leaves a wide margin (one in 32 kept the 10k icosphere's patches stored).
const FAR_SHARE: usize = 8;

/// [`on_demand_pays`] counts the neighbours of every this many triangles.
const SAMPLE_STRIDE: usize = 7;

/// Edge control point `slot` of triangle `tri`'s `patch`, as [`local`] rebuilds it.
fn edge_point(mesh: &TriMesh, tri: usize, patch: &Patch, slot: usize) -> DVec3 {
    let net = local(mesh, tri, patch).net;
    DVec3::new(net[0][slot], net[1][slot], net[2][slot])
}

/// Moves the edge points of `net` that lie in their corner's tangent plane (all but those in
/// `as_stored`) back into it: `b ← b − ((b − p_c)·n_c) n_c`. Both triangles of an edge do the
/// same arithmetic on the same corner and offsets, so shared curves stay shared bit for bit.
#[inline]
fn onto_tangent_planes(net: &mut SoaNet, normal: &[DVec3; 3], as_stored: u8) {
    for (m, &[c, _]) in NEAR_OF.iter().enumerate() {
        if as_stored & (1 << m) != 0 {
            continue;
        }
        let slot = m + 3;
        let v = DVec3::new(
            net[0][slot] - net[0][c],
            net[1][slot] - net[1][c],
            net[2][slot] - net[2][c],
        );
        let d = v.dot(normal[c]);
        for (x, coord) in net.iter_mut().enumerate() {
            coord[slot] = coord[c] + (v[x] - d * normal[c][x]);
        }
    }
}

/// Stores `value` as control point `slot` (3 to 9) of triangle `tri`'s `patch`.
fn set_point(mesh: &TriMesh, tri: usize, patch: &mut Patch, slot: usize, value: DVec3) {
    let position = mesh.triangles[tri].map(|v| mesh.positions[v as usize]);
    for x in 0..3 {
        let flat = flat_point(coordinate(&position, x), slot);
        patch.inner[x][slot - 3] = (value[x] - flat) as f32;
    }
}

/// One patch set up for single points: its net rebuilt once, and each neighbour's net
/// composed (Eq. 3) the first time a point blends across that edge, then kept. A single point
/// and a batch of them run the same arithmetic, so they agree bit for bit.
struct PointEvaluation {
    tri: usize,
    widths: [f64; 3],
    local: Local,
    across: [Option<(SoaNet, Option<Split>)>; 3],
}

impl PointEvaluation {
    fn new(surface: &G2Surface, tri: usize) -> Self {
        PointEvaluation {
            tri,
            widths: surface.widths(tri),
            local: surface.with_local(tri, |local| *local),
            across: [None; 3],
        }
    }

    fn at(&mut self, surface: &G2Surface, bary: [f64; 3]) -> SurfacePoint {
        let w = PointWeights::at(bary, self.widths, surface.profile);
        if let Some(c) = w.corner {
            let c = c as usize;
            return SurfacePoint {
                position: corner(&self.local.net, c),
                normal: self.local.normal[c],
            };
        }
        let (local, across) = self.nets(surface, &w);
        let [p] = G2Surface::combine(
            &local.normal,
            &Lanes::<1>::single(&w),
            &local.net,
            across.map(|(net, _)| net),
            across.and_then(|(_, split)| split.as_ref()),
            EdgeRows::All,
        );
        p
    }

    /// The set-up's own net and corner normals, and the neighbour's net a point with weights
    /// `w` blends with, composed on first use.
    #[inline]
    fn nets(
        &mut self,
        surface: &G2Surface,
        w: &PointWeights,
    ) -> (&Local, Option<&(SoaNet, Option<Split>)>) {
        let tri = self.tri;
        let normal = &self.local.normal;
        let across = &mut self.across;
        let net = w.blended.then(|| {
            let k = w.k as usize;
            &*across[k].get_or_insert_with(|| {
                let mut net = [[0.0; 10]; 3];
                surface.across_net(tri, k, Reach::Whole, &mut net);
                (net, surface.split_across(tri, k, normal))
            })
        });
        (&self.local, net)
    }
}

impl Surface for G2Surface<'_> {
    fn evaluate(&self, tri: usize, bary: [f64; 3]) -> SurfacePoint {
        let mut out = PointEvaluation::new(self, tri);
        out.at(self, bary)
    }

    /// [`Surface::evaluate`] point by point, with the own net rebuilt and each neighbour's
    /// net composed once for all of them instead of once per point.
    fn evaluate_points(&self, tri: usize, barys: &[[f64; 3]], out: &mut Vec<SurfacePoint>) {
        let mut points = PointEvaluation::new(self, tri);
        out.extend(barys.iter().map(|&bary| points.at(self, bary)));
    }

    fn evaluate_lattice_part(
        &self,
        tri: usize,
        level: u32,
        part: LatticePart,
        out: &mut Vec<SurfacePoint>,
    ) {
        PartEvaluation::run(self, tri, &[(level, part)], out);
    }

    /// One set-up for every call.
    fn evaluate_points_on_demand(
        &self,
        tri: usize,
        drive: &mut dyn FnMut(&mut crate::surface::PointsOnDemand<'_>),
    ) {
        let mut points = PointEvaluation::new(self, tri);
        drive(&mut |barys, out| out.extend(barys.iter().map(|&bary| points.at(self, bary))));
    }

    /// The interior through its lattice part's pattern, each edge's positions alone through
    /// its edge part's (`g2::positions`).
    fn evaluate_lattice_positions_on_edges(
        &self,
        tri: usize,
        level: u32,
        out: &mut Vec<SurfacePoint>,
    ) {
        PartEvaluation::set_up(self, tri, false, |evaluation| {
            evaluation.lattice_with_edge_positions(level, out);
        });
    }

    /// The even points copied from `coarse`, the others through the patterns of the points a
    /// lattice adds to the one of half its level (`g2::refine`).
    fn evaluate_lattice_positions_on_edges_refining(
        &self,
        tri: usize,
        level: u32,
        coarse: &[SurfacePoint],
        out: &mut Vec<SurfacePoint>,
    ) {
        if level % 2 != 0 || coarse.len() != lattice_len(level / 2) {
            return self.evaluate_lattice_positions_on_edges(tri, level, out);
        }
        PartEvaluation::set_up(self, tri, false, |evaluation| {
            evaluation.refined_lattice_with_edge_positions(level, coarse, out);
        });
    }

    fn evaluate_points_positions_first(
        &self,
        tri: usize,
        barys: &[[f64; 3]],
        positions_only: usize,
        out: &mut Vec<SurfacePoint>,
    ) {
        let positions_only = positions_only.min(barys.len());
        if self.point_set(tri, barys, positions_only, out) {
            return;
        }
        let mut points = PointEvaluation::new(self, tri);
        let (first, rest) = barys.split_at(positions_only);
        out.extend(first.iter().map(|&bary| SurfacePoint {
            position: points.position_at(self, bary),
            normal: DVec3::ZERO,
        }));
        out.extend(rest.iter().map(|&bary| points.at(self, bary)));
    }

    /// [`Surface::evaluate_lattice_part`] part after part, with the triangle's own net rebuilt
    /// once, and each neighbour's net composed (Eq. 3) once for every part that
    /// blends across its edge (an edge and the interior both do), instead of once per part;
    /// only its edge row when the parts are all edges.
    fn evaluate_lattice_parts(
        &self,
        tri: usize,
        parts: &[(u32, LatticePart)],
        out: &mut Vec<SurfacePoint>,
    ) {
        PartEvaluation::run(self, tri, parts, out);
    }
}

/// One patch set up for lattice parts: its net rebuilt once, and each
/// neighbour's net composed (Eq. 3) the first time a part blends across that edge, then kept.
/// The values are those a part evaluated alone computes, so parts evaluated together or apart
/// agree bit for bit.
struct PartEvaluation<'s, 'a> {
    surface: &'s G2Surface<'a>,
    tri: usize,
    widths: [f64; 3],
    local: Local,
    /// The own net lane by lane, made when a block of two or more lanes first needs it.
    own_lanes: Option<Broadcast<LANES>>,
    /// Each neighbour's composed net, and how much of it was composed.
    across: [Option<Across>; 3],
    /// Whether every part asked for is an edge: then a neighbour's net is only ever weighed on
    /// its own edge, and its edge row is all that is composed ([`Reach::Edge`]).
    edges_only: bool,
}

/// A neighbour's net composed across one edge, for [`PartEvaluation`].
struct Across {
    /// How much of it was composed.
    reach: Reach,
    net: SoaNet,
    /// The edge's split normals, if any.
    split: Option<Split>,
    /// `net` lane by lane, made when a block of two or more lanes first needs it.
    lanes: Option<Broadcast<LANES>>,
}

/// Where [`PartEvaluation::part_into`] puts a part's points: each block of lanes is given its
/// weights and nets, and computes what it keeps.
trait PointSink {
    /// Number of points of the part.
    fn len(&self) -> usize;

    /// Point `target` of the part, whole.
    fn put(&mut self, target: u32, point: SurfacePoint);

    /// The points of `lanes` (targets [`Lanes::PADDING`] unused), from `own` and `across` as
    /// [`G2Surface::combine`] takes them: by default each whole, given to
    /// [`PointSink::put`].
    #[inline(always)]
    fn block<const L: usize, N: LaneNet<L>>(
        &mut self,
        normal: &[DVec3; 3],
        lanes: &Lanes<L>,
        own: &N,
        across: Option<&N>,
        split: Option<&Split>,
        edge_rows: EdgeRows,
    ) {
        let points = G2Surface::combine(normal, lanes, own, across, split, edge_rows);
        for (&target, p) in lanes.target.iter().zip(points) {
            if target != Lanes::<1>::PADDING {
                self.put(target, p);
            }
        }
    }
}

/// Every point whole, in the part's order.
struct Points<'o>(&'o mut [SurfacePoint]);

impl PointSink for Points<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }

    #[inline(always)]
    fn put(&mut self, target: u32, point: SurfacePoint) {
        self.0[target as usize] = point;
    }
}

/// Makes sure `cached` holds the neighbour's net across edge `k` of `tri` as far as `part`
/// weighs it: points of edge `k` blend only across edge `k`, and when every part asked for is
/// an edge only its edge row is composed; any other part may weigh the whole net.
#[inline]
#[allow(clippy::too_many_arguments)]
fn compose_for(
    surface: &G2Surface,
    tri: usize,
    normal: &[DVec3; 3],
    cached: &mut Option<Across>,
    k: usize,
    part: LatticePart,
    edges_only: bool,
) {
    let reach = if edges_only && part == LatticePart::Edge(k as u8) {
        Reach::Edge
    } else {
        Reach::Whole
    };
    if !matches!(cached, Some(had) if had.reach == Reach::Whole || had.reach == reach) {
        let kept = cached.insert(Across {
            reach,
            net: [[0.0; 10]; 3],
            split: None,
            lanes: None,
        });
        surface.across_net(tri, k, reach, &mut kept.net);
        kept.split = surface.split_across(tri, k, normal);
    }
}

impl<'s, 'a> PartEvaluation<'s, 'a> {
    /// The points of the lattice parts `parts` of triangle `tri`, in order, appended to `out`.
    ///
    /// The set-up is made here and used where it is made: returned from a constructor, it was
    /// moved twice on the way (about 3 kB with the room for its lane copies and neighbour nets,
    /// twice per triangle), and its own net was copied out of the memo through a return value
    /// as well; it is now copied once, straight into place.
    #[inline]
    fn run(
        surface: &'s G2Surface<'a>,
        tri: usize,
        parts: &[(u32, LatticePart)],
        out: &mut Vec<SurfacePoint>,
    ) {
        let edges_only = parts
            .iter()
            .all(|&(_, part)| matches!(part, LatticePart::Edge(_)));
        Self::set_up(surface, tri, edges_only, |evaluation| {
            for &(level, part) in parts {
                evaluation.part(level, part, out);
            }
        });
    }

    /// Runs `body` on triangle `tri` set up, made where it is used (see [`PartEvaluation::run`]).
    #[inline(always)]
    fn set_up<R>(
        surface: &'s G2Surface<'a>,
        tri: usize,
        edges_only: bool,
        body: impl FnOnce(&mut Self) -> R,
    ) -> R {
        let mut evaluation = PartEvaluation {
            surface,
            tri,
            widths: surface.widths(tri),
            local: Local {
                net: [[0.0; 10]; 3],
                normal: [DVec3::ZERO; 3],
            },
            own_lanes: None,
            across: [None, None, None],
            edges_only,
        };
        surface.with_local(tri, |local| evaluation.local = *local);
        body(&mut evaluation)
    }

    /// The points of `part` of the level-`level` lattice, appended to `out`.
    #[inline]
    fn part(&mut self, level: u32, part: LatticePart, out: &mut Vec<SurfacePoint>) {
        let base = out.len();
        out.resize(
            base + part.len(level),
            SurfacePoint {
                position: DVec3::ZERO,
                normal: DVec3::ZERO,
            },
        );
        self.part_into(level, part, &mut Points(&mut out[base..]));
    }

    /// The points of `part` of the level-`level` lattice, given to `out` block by block.
    #[inline]
    fn part_into<S: PointSink>(&mut self, level: u32, part: LatticePart, out: &mut S) {
        let surface = self.surface;
        surface
            .patterns
            .with(level, part, self.widths, surface.profile, |pattern| {
                self.pattern_into(pattern, part, out)
            });
    }

    /// The points of `pattern`, the pattern of `part`, given to `out` block by block.
    #[inline(always)]
    fn pattern_into<S: PointSink>(&mut self, pattern: &Pattern, part: LatticePart, out: &mut S) {
        let PartEvaluation {
            surface,
            tri,
            widths: _,
            local,
            own_lanes,
            across,
            edges_only,
        } = self;
        debug_assert_eq!(out.len(), pattern.len);
        for &(c, target) in &pattern.corners {
            out.put(
                target,
                SurfacePoint {
                    position: corner(&local.net, c as usize),
                    normal: local.normal[c as usize],
                },
            );
        }
        // The plain points first, then those blended across each edge.
        for group in [3, 0, 1, 2] {
            let (blocks, single) = pattern.group(group);
            if blocks.is_empty() && single.is_none() {
                continue;
            }
            let k = (group < 3).then_some(group);
            if let Some(k) = k {
                compose_for(
                    surface,
                    *tri,
                    &local.normal,
                    &mut across[k],
                    k,
                    part,
                    *edges_only,
                );
            }
            if !blocks.is_empty() {
                let own = &*own_lanes.get_or_insert_with(|| broadcast(&local.net));
                let (across, split) = match k {
                    Some(k) => {
                        let a = across[k].as_mut().expect("composed just above");
                        let lanes = &*a.lanes.get_or_insert_with(|| broadcast(&a.net));
                        (Some(lanes), a.split.as_ref())
                    }
                    None => (None, None),
                };
                for lanes in blocks {
                    out.block(&local.normal, lanes, own, across, split, pattern.edge_rows);
                }
            }
            if let Some(lane) = single {
                let across = k.map(|k| across[k].as_ref().expect("composed just above"));
                out.block(
                    &local.normal,
                    lane,
                    &local.net,
                    across.map(|a| &a.net),
                    across.and_then(|a| a.split.as_ref()),
                    pattern.edge_rows,
                );
            }
        }
    }
}

/// Plain PN triangles (Vlachos et al. 2001; paper Eq. 1–2): the G² surface with h = 0 on every
/// edge, including its shared edge curves across split normals.
#[derive(Debug)]
pub struct PnSurface<'a>(G2Surface<'a>);

impl<'a> PnSurface<'a> {
    /// PN triangles over `mesh`, on the default nets.
    pub fn new(mesh: &'a TriMesh, topo: &'a Topology) -> Self {
        Self::with_nets(mesh, topo, Nets::default())
    }

    /// PN triangles over `mesh` on nets made by the rule `nets` ([`Nets::Paper`]: Vlachos et
    /// al. as published).
    pub fn with_nets(mesh: &'a TriMesh, topo: &'a Topology, nets: Nets) -> Self {
        // No width table: every edge is at 0.
        super::assert_belong_together(mesh, topo, None);
        PnSurface(G2Surface::build(mesh, topo, None, Profile::default(), nets))
    }
}

impl Surface for PnSurface<'_> {
    fn evaluate(&self, tri: usize, bary: [f64; 3]) -> SurfacePoint {
        self.0.evaluate(tri, bary)
    }

    fn evaluate_lattice_part(
        &self,
        tri: usize,
        level: u32,
        part: LatticePart,
        out: &mut Vec<SurfacePoint>,
    ) {
        self.0.evaluate_lattice_part(tri, level, part, out)
    }

    fn evaluate_lattice_parts(
        &self,
        tri: usize,
        parts: &[(u32, LatticePart)],
        out: &mut Vec<SurfacePoint>,
    ) {
        self.0.evaluate_lattice_parts(tri, parts, out)
    }

    fn evaluate_points(&self, tri: usize, barys: &[[f64; 3]], out: &mut Vec<SurfacePoint>) {
        self.0.evaluate_points(tri, barys, out)
    }

    fn evaluate_points_on_demand(
        &self,
        tri: usize,
        drive: &mut dyn FnMut(&mut crate::surface::PointsOnDemand<'_>),
    ) {
        self.0.evaluate_points_on_demand(tri, drive)
    }

    fn evaluate_lattice_positions_on_edges(
        &self,
        tri: usize,
        level: u32,
        out: &mut Vec<SurfacePoint>,
    ) {
        self.0.evaluate_lattice_positions_on_edges(tri, level, out)
    }

    fn evaluate_lattice_positions_on_edges_refining(
        &self,
        tri: usize,
        level: u32,
        coarse: &[SurfacePoint],
        out: &mut Vec<SurfacePoint>,
    ) {
        self.0
            .evaluate_lattice_positions_on_edges_refining(tri, level, coarse, out)
    }

    fn evaluate_points_positions_first(
        &self,
        tri: usize,
        barys: &[[f64; 3]],
        positions_only: usize,
        out: &mut Vec<SurfacePoint>,
    ) {
        self.0
            .evaluate_points_positions_first(tri, barys, positions_only, out)
    }
}

/// Makes every triangle along an unblended edge use one boundary curve: if their inner edge
/// control points differ (split normals), each gets the average, oriented along the edge
/// (PN-AEN); `b111` is then recomputed from the new edge points by the centre rule of `rule`
/// (Eq. 2 for the paper's nets), with each triangle's own corner normals.
///
/// Each use of an edge owns its two inner control points alone, so the edges are independent:
/// they are compared in parallel, and only the few that differ are written afterwards, in edge
/// order. The result does not depend on the order either way.
fn share_unblended_edge_curves(
    mesh: &TriMesh,
    topo: &Topology,
    h_edge: Option<&[f64]>,
    patches: &mut [Patch],
    rule: Nets,
) {
    // Edge points only: never a corner.
    let point = |t: usize, s: usize| edge_point(mesh, t, &patches[t], s);
    let uses = |edge| edge_uses(topo, edge);
    let averaged: Vec<(usize, [DVec3; 2])> = topo
        .par_edges()
        .enumerate()
        .filter_map(|(e, edge)| {
            let blended = h_edge.is_some_and(|h| h[e] > 0.0);
            if blended || edge.tris.len() < 2 || edge.verts[0] == edge.verts[1] {
                return None;
            }
            let mut all = uses(edge);
            let (t0, s0) = all.next()?;
            let first = s0.map(|s| point(t0, s));
            if all.all(|(t, s)| s.map(|s| point(t, s)) == first) {
                return None;
            }
            let mut sum = [DVec3::ZERO; 2];
            for (t, s) in uses(edge) {
                sum[0] += point(t, s[0]);
                sum[1] += point(t, s[1]);
            }
            Some((e, sum.map(|x| x / edge.tris.len() as f64)))
        })
        .collect();
    if averaged.is_empty() {
        return;
    }
    let mut touched = Vec::new();
    for (e, avg) in averaged {
        for (t, s) in uses(topo.edge(EdgeId(e as u32))) {
            for (slot, value) in s.into_iter().zip(avg) {
                set_point(mesh, t, &mut patches[t], slot, value);
                patches[t].as_stored |= 1 << (slot - 3);
            }
            touched.push(t as u32);
        }
    }
    touched.sort_unstable();
    touched.dedup();
    for t in touched {
        let t = t as usize;
        let Local { net, normal } = local(mesh, t, &patches[t]);
        let centre = rule.centre(&aos(&net), normal);
        set_point(mesh, t, &mut patches[t], B111, centre);
    }
}

/// The uses `(triangle, [slot next to verts[0], slot next to verts[1]])` of `edge`'s inner
/// control points, in the edge's use order.
fn edge_uses<'a>(
    topo: &'a Topology,
    edge: Edge<'a>,
) -> impl Iterator<Item = (usize, [usize; 2])> + 'a {
    edge.tris.iter().map(move |u| {
        let (t, k) = u.at();
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let s = if topo.tri_verts[t][i] == edge.verts[0] {
            [NEAR[i][j], NEAR[j][i]]
        } else {
            [NEAR[j][i], NEAR[i][j]]
        };
        (t, s)
    })
}
