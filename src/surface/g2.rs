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
use crate::topology::{Edge, EdgeId, Topology, TriId, Warning};

/// A control net by coordinate, `[x, y, z][control point]`: the layout the per-point sums of
/// [`accumulate`] read, one coordinate of one control point at a time.
type SoaNet = [[f64; 10]; 3];

/// Everything one triangle needs at evaluation time that no other triangle holds too: 216
/// bytes, one allocation for the whole mesh.
///
/// The corners' positions and normals live once per input vertex ([`CornerVertex`]), not
/// once per use of it: every rule of [`Nets`] copies a corner's position into its net bit for
/// bit and the shared edge curves leave corners alone, so the net is whole again when a
/// lattice part asks for it ([`G2Surface::local`]). The widths are read from the surface's
/// per-edge table through `edges`. Copies of both cost 160 bytes a triangle, and at a million
/// input triangles every such byte is a page fault at set-up.
#[derive(Debug, Clone)]
struct Patch {
    /// Control points 3 to 9 of the own net `b_f` (Eq. 2 or the round net, with shared edge
    /// curves on unblended split edges), by coordinate: the six edge points and `b111`.
    inner: [[f64; INNER]; 3],
    /// Input vertex of each corner, an index into [`G2Surface::vertices`].
    verts: [u32; 3],
    /// `across[k]`: for a blended edge opposite corner `k` (its width above 0), the neighbour
    /// and its slots, from which [`G2Surface::across_net`] composes `b_g ∘ M` (Eq. 3) when a
    /// point needs it; meaningless on other edges.
    ///
    /// The composed nets are not stored: three of them per triangle were two thirds of the
    /// surface's memory (720 of 1128 bytes), more than the dense output of a level-8 triangle,
    /// and composing costs less than the page faults of holding them. Each is composed once per
    /// lattice part, with the same arithmetic on every path, so point and lattice evaluation
    /// still agree bit for bit.
    across: [Across; 3],
    /// The welded edge opposite each corner, an index into [`G2Surface::effective_h`].
    edges: [u32; 3],
}

/// Control points of a net that are not corners (the corners are slots 0, 1, 2).
const INNER: usize = 7;

/// An input vertex as every triangle on it reads it.
#[derive(Debug, Clone, Copy)]
struct CornerVertex {
    position: DVec3,
    /// The normalized input normal, or zero where it has no direction (each triangle then
    /// uses its own face normal, see [`face_fallback`]).
    normal: DVec3,
}

/// One triangle's whole net and corner normals, put together for a lattice part or a point.
struct Local {
    net: SoaNet,
    normal: [DVec3; 3],
}

/// The triangle across a blended edge and the slots `[p, q, r]` of [`neighbour_map`].
#[derive(Debug, Clone, Copy, Default)]
struct Across {
    tri: u32,
    slots: [u8; 3],
}

/// The G² blended surface of Lee–Hwang–Yoon over a whole mesh, one width `h` per welded edge.
#[derive(Debug)]
pub struct G2Surface {
    patches: Vec<Patch>,
    vertices: Vec<CornerVertex>,
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
        let vertices: Vec<CornerVertex> = mesh
            .positions
            .par_iter()
            .zip(&mesh.normals)
            .map(|(&position, normal)| CornerVertex {
                position,
                normal: normal.normalize_or(DVec3::ZERO),
            })
            .collect();
        // Built in place, in the final array: no per-triangle corner or net arrays beside it.
        let mut patches: Vec<Patch> = (0..mesh.triangles.len())
            .into_par_iter()
            .map(|t| {
                let verts = mesh.triangles[t];
                let (position, normal) = corners(&vertices, verts);
                let edges = topo.tri_edges[t].map(|e| e.0);
                let across = std::array::from_fn(|k| {
                    if h_edge[edges[k] as usize] > 0.0 {
                        let n = topo
                            .neighbour(TriId(t as u32), k)
                            .expect("blended edges are interior");
                        Across {
                            tri: n.tri.0,
                            slots: n.slots,
                        }
                    } else {
                        Across::default()
                    }
                });
                let net = soa(&nets_rule.net(position, normal));
                Patch {
                    inner: net.map(|c| std::array::from_fn(|m| c[3 + m])),
                    verts,
                    across,
                    edges,
                }
            })
            .collect();
        share_unblended_edge_curves(topo, &h_edge, &vertices, &mut patches, nets_rule);

        G2Surface {
            patches,
            vertices,
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
        debug_assert!(
            self.h_edge[patch.edges[k] as usize] > 0.0,
            "only blended edges"
        );
        let across = patch.across[k];
        let g = aos(&self.local(across.tri as usize).net);
        soa(&compose(
            &g,
            neighbour_map(k, across.slots.map(usize::from)),
        ))
    }

    /// Triangle `tri`'s whole net and corner normals, exactly as they were when its net was
    /// made.
    #[inline]
    fn local(&self, tri: usize) -> Local {
        local(&self.vertices, &self.patches[tri])
    }

    /// The effective widths of `patch`'s edges, opposite corners 0, 1, 2.
    #[inline]
    fn widths(&self, patch: &Patch) -> [f64; 3] {
        patch.edges.map(|e| self.h_edge[e as usize])
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
        normal: &[DVec3; 3],
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
            let interpolated = b[0] * normal[0] + b[1] * normal[1] + b[2] * normal[2];
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
                    interpolated.normalize_or(normal[0])
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

/// Corner `c`'s position in a net.
#[inline]
fn corner(net: &SoaNet, c: usize) -> DVec3 {
    DVec3::new(net[0][c], net[1][c], net[2][c])
}

/// Positions and unit normals of the corners `verts` as the net rules take them: the
/// normalized input normals, and the face normal where one has no direction.
#[inline]
fn corners(vertices: &[CornerVertex], verts: [u32; 3]) -> ([DVec3; 3], [DVec3; 3]) {
    let v = verts.map(|v| vertices[v as usize]);
    let position = v.map(|v| v.position);
    let face = face_fallback(position);
    (
        position,
        v.map(|v| {
            if v.normal == DVec3::ZERO {
                face
            } else {
                v.normal
            }
        }),
    )
}

/// The unit face normal of a triangle (+z if it has none): the corner normal of an input
/// vertex whose normal has no direction.
#[inline]
fn face_fallback(p: [DVec3; 3]) -> DVec3 {
    (p[1] - p[0]).cross(p[2] - p[0]).normalize_or(DVec3::Z)
}

/// A patch's whole net and corner normals (see [`G2Surface::local`]).
#[inline]
fn local(vertices: &[CornerVertex], patch: &Patch) -> Local {
    let (position, normal) = corners(vertices, patch.verts);
    let net = std::array::from_fn(|x| {
        let mut coord = [0.0; 10];
        for c in 0..3 {
            coord[c] = position[c][x];
        }
        coord[3..].copy_from_slice(&patch.inner[x]);
        coord
    });
    Local { net, normal }
}

/// One patch set up for single points: its net broadcast once, and each neighbour's net
/// composed (Eq. 3) the first time a point blends across that edge, then kept. A single point
/// and a batch of them run the same arithmetic, so they agree bit for bit.
struct PointEvaluation<'a> {
    patch: &'a Patch,
    widths: [f64; 3],
    local: Local,
    own: Broadcast<1>,
    across: [Option<Broadcast<1>>; 3],
}

impl<'a> PointEvaluation<'a> {
    fn new(surface: &'a G2Surface, tri: usize) -> Self {
        let patch = &surface.patches[tri];
        let local = surface.local(tri);
        PointEvaluation {
            patch,
            widths: surface.widths(patch),
            own: broadcast(&local.net),
            local,
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
        let patch = self.patch;
        let net = w.blended.then(|| {
            let k = w.k as usize;
            &*self.across[k].get_or_insert_with(|| broadcast(&surface.across_net(patch, k)))
        });
        let [p] = G2Surface::combine(&self.local.normal, &Lanes::<1>::single(&w), &self.own, net);
        p
    }
}

impl Surface for G2Surface {
    fn evaluate(&self, tri: usize, bary: [f64; 3]) -> SurfacePoint {
        let mut out = PointEvaluation::new(self, tri);
        out.at(self, bary)
    }

    /// [`Surface::evaluate`] point by point, with the own net broadcast and each neighbour's
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
        let patch = &self.patches[tri];
        let local = self.local(tri);
        self.patterns
            .with(level, part, self.widths(patch), self.profile, |pattern| {
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
                        position: corner(&local.net, c as usize),
                        normal: local.normal[c as usize],
                    };
                }
                let own = broadcast(&local.net);
                let groups = std::iter::once((None, &pattern.plain))
                    .chain((0..3).map(|k| (Some(k), &pattern.blended[k])));
                for (k, blocks) in groups {
                    if blocks.is_empty() {
                        continue;
                    }
                    let across = k.map(|k| broadcast(&self.across_net(patch, k)));
                    for lanes in blocks {
                        let points = Self::combine(&local.normal, lanes, &own, across.as_ref());
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

    fn evaluate_points(&self, tri: usize, barys: &[[f64; 3]], out: &mut Vec<SurfacePoint>) {
        self.0.evaluate_points(tri, barys, out)
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
    topo: &Topology,
    h_edge: &[f64],
    vertices: &[CornerVertex],
    patches: &mut [Patch],
    rule: Nets,
) {
    // Edge points only: never a corner.
    let point = |t: usize, s: usize| {
        let inner = &patches[t].inner;
        DVec3::new(inner[0][s - 3], inner[1][s - 3], inner[2][s - 3])
    };
    let uses = |edge| edge_uses(topo, edge);
    let averaged: Vec<(usize, [DVec3; 2])> = topo
        .par_edges()
        .zip(h_edge.par_iter())
        .enumerate()
        .filter_map(|(e, (edge, &h))| {
            if h > 0.0 || edge.tris.len() < 2 || edge.verts[0] == edge.verts[1] {
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
                let inner = &mut patches[t].inner;
                [inner[0][slot - 3], inner[1][slot - 3], inner[2][slot - 3]] = value.to_array();
            }
            touched.push(t as u32);
        }
    }
    touched.sort_unstable();
    touched.dedup();
    for t in touched {
        let patch = &mut patches[t as usize];
        let Local { net, normal } = local(vertices, patch);
        let centre = rule.centre(&aos(&net), normal);
        let b = B111 - 3;
        [patch.inner[0][b], patch.inner[1][b], patch.inner[2][b]] = centre.to_array();
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
