//! [`G2Surface`]: per-triangle control nets (own PN patch, and the neighbour patches re-expressed
//! in its barycentrics when they are needed) and their combination with [`PointWeights`] into
//! positions and exact normals; [`PnSurface`] is its h = 0 case.
//!
//! It deliberately computes no weights itself (see `pattern.rs`, `blend.rs`) and never fails:
//! bad edges act as h = 0 and are reported through [`G2Surface::warnings`].

use glam::DVec3;
use rayon::prelude::*;

use super::blend::neighbour_map;
use super::nets::Nets;
use super::pattern::{Lanes, NetWeights, PatternCache, PointWeights};
use super::pn::{compose, Net, B111, NEAR};
use super::{LatticePart, Profile, Surface, SurfacePoint};
use crate::mesh::TriMesh;
use crate::sharpness::EffectiveH;
use crate::topology::{Topology, TriId, Warning};

/// A control net by coordinate, `[x, y, z][control point]`: the layout the per-point sums of
/// [`accumulate`] read, one coordinate of one control point at a time.
type SoaNet = [[f64; 10]; 3];

/// Everything one triangle needs at evaluation time.
#[derive(Debug, Clone)]
struct Patch {
    /// Own PN net `b_f` (Eq. 2, with shared edge curves on unblended split edges).
    net: SoaNet,
    /// `across[k]`: for a blended edge opposite corner `k`, the neighbour and its slots, from
    /// which [`G2Surface::across_net`] composes `b_g ∘ M` (Eq. 3) when a point needs it.
    ///
    /// The composed nets are not stored: three of them per triangle were two thirds of the
    /// surface's memory (720 of 1128 bytes), more than the dense output of a level-8 triangle,
    /// and composing costs less than the page faults of holding them. Each is composed once per
    /// lattice part, with the same arithmetic on every path, so point and lattice evaluation
    /// still agree bit for bit.
    across: [Option<Across>; 3],
    /// Effective width of the edge opposite each corner.
    h: [f64; 3],
    /// Input corner positions and normalized input normals.
    position: [DVec3; 3],
    normal: [DVec3; 3],
}

/// The triangle across a blended edge and the slots `[p, q, r]` of [`neighbour_map`].
#[derive(Debug, Clone, Copy)]
struct Across {
    tri: u32,
    slots: [u8; 3],
}

/// The G² blended surface of Lee–Hwang–Yoon over a whole mesh, one width `h` per welded edge.
#[derive(Debug)]
pub struct G2Surface {
    patches: Vec<Patch>,
    profile: Profile,
    h_edge: EffectiveH,
    warnings: Vec<Warning>,
    patterns: PatternCache,
}

impl G2Surface {
    /// Builds the surface. `h_per_edge` is indexed by [`EdgeId`](crate::topology::EdgeId) and
    /// must have one entry per edge of `topo`; values are clamped to `[0, H_MAX]` (NaN to 0).
    /// Boundary, non-manifold and degenerate edges act as h = 0 (with a warning if h > 0 was
    /// asked for). Where an edge is not blended but its triangles disagree on its boundary
    /// curve (split normals), all of them use the average of their edge control points
    /// (PN-AEN), so the surface stays watertight.
    ///
    /// # Panics
    /// If `h_per_edge`, `topo` and `mesh` do not belong together (a caller bug).
    pub fn new(mesh: &TriMesh, topo: &Topology, h_per_edge: &[f64], profile: Profile) -> Self {
        Self::with_nets(mesh, topo, h_per_edge, profile, Nets::default())
    }

    /// [`G2Surface::new`] over control nets made by the rule `nets` instead of the default.
    ///
    /// # Panics
    /// If `h_per_edge`, `topo` and `mesh` do not belong together (a caller bug).
    pub fn with_nets(
        mesh: &TriMesh,
        topo: &Topology,
        h_per_edge: &[f64],
        profile: Profile,
        nets_rule: Nets,
    ) -> Self {
        super::assert_belong_together(mesh, topo, h_per_edge);

        // The one rule for which edges blend and how wide (widths the pipeline resolved pass
        // through it unchanged, and without warnings).
        let (h_edge, warnings) = EffectiveH::from_requested(topo, h_per_edge);
        let corners: Vec<([DVec3; 3], [DVec3; 3])> = mesh
            .triangles
            .par_iter()
            .map(|tri| {
                let position = tri.map(|c| mesh.positions[c as usize]);
                let face = (position[1] - position[0])
                    .cross(position[2] - position[0])
                    .normalize_or(DVec3::Z);
                (
                    position,
                    tri.map(|c| mesh.normals[c as usize].normalize_or(face)),
                )
            })
            .collect();
        let mut nets: Vec<Net> = corners
            .par_iter()
            .map(|&(p, n)| nets_rule.net(p, n))
            .collect();
        share_unblended_edge_curves(topo, &h_edge, &mut nets, nets_rule, &corners);

        let patches: Vec<Patch> = corners
            .par_iter()
            .enumerate()
            .map(|(t, &(position, normal))| {
                let h = topo.tri_edges[t].map(|e| h_edge[e.0 as usize]);
                let across = std::array::from_fn(|k| {
                    (h[k] > 0.0).then(|| {
                        let n = topo
                            .neighbour(TriId(t as u32), k)
                            .expect("blended edges are interior");
                        Across {
                            tri: n.tri.0,
                            slots: n.slots,
                        }
                    })
                });
                Patch {
                    net: soa(&nets[t]),
                    across,
                    h,
                    position,
                    normal,
                }
            })
            .collect();

        G2Surface {
            patches,
            profile,
            h_edge,
            warnings,
            patterns: PatternCache::default(),
        }
    }

    /// The width each edge is actually blended with (0 for edges that are not).
    pub fn effective_h(&self) -> &[f64] {
        &self.h_edge
    }

    /// The neighbour's net across edge `k` of `patch` in `patch`'s barycentrics, `b_g ∘ M`
    /// (Eq. 3 in the form of [`neighbour_map`]); `k` must be a blended edge.
    fn across_net(&self, patch: &Patch, k: usize) -> SoaNet {
        let across = patch.across[k].expect("only blended edges are composed");
        let g = aos(&self.patches[across.tri as usize].net);
        soa(&compose(
            &g,
            neighbour_map(k, across.slots.map(usize::from)),
        ))
    }

    /// The profile `r(s)` in use.
    pub fn profile(&self) -> Profile {
        self.profile
    }

    /// Edges asked to blend that cannot (boundary, non-manifold, degenerate).
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// The surface points of `L` domain points of `patch` from their weights, on its own net
    /// `own` and, when they blend, the neighbour's net `across` (the points of one [`Lanes`]
    /// block all blend with the same neighbour, or with none).
    ///
    /// Position and tangents are the sums of the pattern module's documentation (Eq. 5 and its
    /// derivatives); the normal is `∂_u S × ∂_v S`, oriented by the interpolated input normals.
    /// Each lane's sums run in the same order whatever `L`, so a lattice block and a single
    /// point agree bit for bit.
    #[inline(always)]
    fn combine<const L: usize>(
        patch: &Patch,
        w: &Lanes<L>,
        own: &Broadcast<L>,
        across: Option<&Broadcast<L>>,
    ) -> [SurfacePoint; L] {
        let mut acc = accumulate(&w.own, own, [[[0.0; L]; 3]; 3]);
        if let Some(across) = across {
            acc = accumulate(&w.across, across, acc);
        }
        std::array::from_fn(|l| {
            let v = |q: usize| DVec3::new(acc[q][0][l], acc[q][1][l], acc[q][2][l]);
            let (position, du, dv) = (v(0), v(1), v(2));
            let b = w.bary[l];
            let interpolated =
                b[0] * patch.normal[0] + b[1] * patch.normal[1] + b[2] * patch.normal[2];
            let n = du.cross(dv);
            let len2 = n.length_squared();
            // |N| ≤ 1e-14·|∂_u S|·|∂_v S|: the tangents are parallel to rounding (a degenerate
            // triangle); fall back to the interpolated input normal.
            let normal =
                if len2 > 1e-28 * du.length_squared() * dv.length_squared() && len2.is_finite() {
                    let n = n / len2.sqrt();
                    if n.dot(interpolated) < 0.0 {
                        -n
                    } else {
                        n
                    }
                } else {
                    interpolated.normalize_or(patch.normal[0])
                };
            SurfacePoint { position, normal }
        })
    }
}

/// A control net with every coordinate repeated in `L` lanes, `[control point][x, y, z][lane]`:
/// the sums of [`accumulate`] are then the same operation on whole lanes, which compilers turn
/// into SIMD arithmetic without being told.
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

/// Adds the weighted sums of one net to `acc[quantity][coordinate][lane]`: for each lane, the
/// control points in order, so that the result does not depend on how many lanes run together.
///
/// The sums are taken and returned by value, and written as plain indexed loops: kept out of
/// memory that way, the compiler unrolls them and runs the lanes in SIMD registers.
#[inline(always)]
fn accumulate<const L: usize>(
    w: &NetWeights<L>,
    net: &Broadcast<L>,
    mut acc: [[[f64; L]; 3]; 3],
) -> [[[f64; L]; 3]; 3] {
    #[allow(clippy::needless_range_loop)]
    for m in 0..10 {
        for q in 0..3 {
            for c in 0..3 {
                for l in 0..L {
                    acc[q][c][l] += w[q][m][l] * net[m][c][l];
                }
            }
        }
    }
    acc
}

/// A net by coordinate.
fn soa(net: &Net) -> SoaNet {
    [0, 1, 2].map(|c| net.map(|p| p[c]))
}

/// A net by control point (the inverse of [`soa`], bit for bit).
fn aos(net: &SoaNet) -> Net {
    std::array::from_fn(|m| DVec3::new(net[0][m], net[1][m], net[2][m]))
}

impl Surface for G2Surface {
    fn evaluate(&self, tri: usize, bary: [f64; 3]) -> SurfacePoint {
        let patch = &self.patches[tri];
        let w = PointWeights::at(bary, patch.h, self.profile);
        if let Some(c) = w.corner {
            let c = c as usize;
            return SurfacePoint {
                position: patch.position[c],
                normal: patch.normal[c],
            };
        }
        let own = broadcast(&patch.net);
        let across = w
            .blended
            .then(|| broadcast(&self.across_net(patch, w.k as usize)));
        let [p] = Self::combine(patch, &Lanes::<1>::single(&w), &own, across.as_ref());
        p
    }

    fn evaluate_lattice_part(
        &self,
        tri: usize,
        level: u32,
        part: LatticePart,
        out: &mut Vec<SurfacePoint>,
    ) {
        let patch = &self.patches[tri];
        self.patterns
            .with(level, part, patch.h, self.profile, |pattern| {
                let base = out.len();
                out.resize(
                    base + pattern.len,
                    SurfacePoint {
                        position: DVec3::ZERO,
                        normal: DVec3::ZERO,
                    },
                );
                let out = &mut out[base..];
                for &(c, target) in &pattern.corners {
                    out[target as usize] = SurfacePoint {
                        position: patch.position[c as usize],
                        normal: patch.normal[c as usize],
                    };
                }
                let own = broadcast(&patch.net);
                let groups = std::iter::once((None, &pattern.plain))
                    .chain((0..3).map(|k| (Some(k), &pattern.blended[k])));
                for (k, blocks) in groups {
                    if blocks.is_empty() {
                        continue;
                    }
                    let across = k.map(|k| broadcast(&self.across_net(patch, k)));
                    for lanes in blocks {
                        let points = Self::combine(patch, lanes, &own, across.as_ref());
                        for (&target, p) in lanes.target.iter().zip(points) {
                            if target != Lanes::<1>::PADDING {
                                out[target as usize] = p;
                            }
                        }
                    }
                }
            });
    }
}

/// Plain PN triangles (Vlachos et al. 2001; paper Eq. 1–2): the G² surface with h = 0 on every
/// edge, including its shared edge curves across split normals.
#[derive(Debug)]
pub struct PnSurface(G2Surface);

impl PnSurface {
    /// PN triangles over `mesh`, on the default nets.
    pub fn new(mesh: &TriMesh, topo: &Topology) -> Self {
        Self::with_nets(mesh, topo, Nets::default())
    }

    /// PN triangles over `mesh` on nets made by the rule `nets` ([`Nets::Paper`]: Vlachos et
    /// al. as published).
    pub fn with_nets(mesh: &TriMesh, topo: &Topology, nets: Nets) -> Self {
        let zero = vec![0.0; topo.edge_count()];
        PnSurface(G2Surface::with_nets(
            mesh,
            topo,
            &zero,
            Profile::default(),
            nets,
        ))
    }
}

impl Surface for PnSurface {
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
}

/// Makes every triangle along an unblended edge use one boundary curve: if their inner edge
/// control points differ (split normals), each gets the average, oriented along the edge
/// (PN-AEN); `b111` is then recomputed from the new edge points by the centre rule of `rule`
/// (Eq. 2 for the paper's nets), with each triangle's own corner normals from `corners`.
fn share_unblended_edge_curves(
    topo: &Topology,
    h_edge: &[f64],
    nets: &mut [Net],
    rule: Nets,
    corners: &[([DVec3; 3], [DVec3; 3])],
) {
    let mut touched = vec![false; nets.len()];
    for (edge, &h) in topo.edges().zip(h_edge) {
        if h > 0.0 || edge.tris.len() < 2 || edge.verts[0] == edge.verts[1] {
            continue;
        }
        // Slots of the control points next to verts[0] and next to verts[1], per use.
        let slots: Vec<(usize, [usize; 2])> = edge
            .tris
            .iter()
            .map(|u| {
                let (t, k) = u.at();
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                let s = if topo.tri_verts[t][i] == edge.verts[0] {
                    [NEAR[i][j], NEAR[j][i]]
                } else {
                    [NEAR[j][i], NEAR[i][j]]
                };
                (t, s)
            })
            .collect();
        let first = slots[0].1.map(|s| nets[slots[0].0][s]);
        let same = slots.iter().all(|&(t, s)| s.map(|s| nets[t][s]) == first);
        if same {
            continue;
        }
        let mut sum = [DVec3::ZERO; 2];
        for &(t, s) in &slots {
            sum[0] += nets[t][s[0]];
            sum[1] += nets[t][s[1]];
        }
        let avg = sum.map(|x| x / slots.len() as f64);
        for &(t, s) in &slots {
            nets[t][s[0]] = avg[0];
            nets[t][s[1]] = avg[1];
            touched[t] = true;
        }
    }
    for ((net, touched), (_, normal)) in nets.iter_mut().zip(touched).zip(corners) {
        if touched {
            net[B111] = rule.centre(net, *normal);
        }
    }
}
