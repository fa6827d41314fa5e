//! [`G2Surface`]: per-triangle control nets (own PN patch and the three neighbour patches
//! re-expressed in its barycentrics) and their combination with [`PointWeights`] into positions
//! and exact normals; [`PnSurface`] is its h = 0 case.
//!
//! It deliberately computes no weights itself (see `pattern.rs`, `blend.rs`) and never fails:
//! bad edges act as h = 0 and are reported through [`G2Surface::warnings`].

use glam::DVec3;
use rayon::prelude::*;

use super::blend::neighbour_map;
use super::pattern::{PatternCache, PointWeights};
use super::pn::{central_point, compose, pn_net, Net, B111, NEAR};
use super::{lattice_index, Profile, Surface, SurfacePoint, H_MAX};
use crate::mesh::TriMesh;
use crate::topology::{EdgeKind, Topology, Warning};

/// Everything one triangle needs at evaluation time.
#[derive(Debug, Clone)]
struct Patch {
    /// Own PN net `b_f` (Eq. 2, with shared edge curves on unblended split edges).
    net: Net,
    /// `across[k]`: the neighbour's net composed with the map of Eq. 3, `b_g ∘ M`, for the
    /// edge opposite corner `k` (a copy of `net` where that edge is not blended).
    across: [Net; 3],
    /// Effective width of the edge opposite each corner.
    h: [f64; 3],
    /// Input corner positions and normalized input normals.
    position: [DVec3; 3],
    normal: [DVec3; 3],
}

/// The G² blended surface of Lee–Hwang–Yoon over a whole mesh, one width `h` per welded edge.
#[derive(Debug)]
pub struct G2Surface {
    patches: Vec<Patch>,
    profile: Profile,
    h_edge: Vec<f64>,
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
        super::assert_belong_together(mesh, topo, h_per_edge);

        let (h_edge, warnings) = effective_widths(topo, h_per_edge);
        let mut patches: Vec<Patch> = mesh
            .triangles
            .iter()
            .enumerate()
            .map(|(t, tri)| {
                let position = tri.map(|c| mesh.positions[c as usize]);
                let face = (position[1] - position[0])
                    .cross(position[2] - position[0])
                    .normalize_or(DVec3::Z);
                let normal = tri.map(|c| mesh.normals[c as usize].normalize_or(face));
                let net = pn_net(position, normal);
                Patch {
                    net,
                    across: [net; 3],
                    h: topo.tri_edges[t].map(|e| h_edge[e.0 as usize]),
                    position,
                    normal,
                }
            })
            .collect();
        share_unblended_edge_curves(topo, &h_edge, &mut patches);

        let nets: Vec<Net> = patches.iter().map(|p| p.net).collect();
        patches.par_iter_mut().enumerate().for_each(|(t, patch)| {
            for k in 0..3 {
                if patch.h[k] > 0.0 {
                    let n = topo.neighbours[t][k].expect("blended edges are interior");
                    let cols = neighbour_map(k, n.slots.map(usize::from));
                    patch.across[k] = compose(&nets[n.tri.0 as usize], cols);
                }
            }
        });

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

    /// The profile `r(s)` in use.
    pub fn profile(&self) -> Profile {
        self.profile
    }

    /// Edges asked to blend that cannot (boundary, non-manifold, degenerate).
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// The surface point of triangle `tri` for precomputed weights.
    #[inline]
    fn combine(&self, tri: usize, w: &PointWeights) -> SurfacePoint {
        let patch = &self.patches[tri];
        if let Some(c) = w.corner {
            let c = c as usize;
            return SurfacePoint {
                position: patch.position[c],
                normal: patch.normal[c],
            };
        }
        let [p, pu, pv] = w.basis.eval(&patch.net);
        let b = &w.blend;
        let (position, du, dv) = if b.beta != 0.0 || b.beta_u != 0.0 || b.beta_v != 0.0 {
            // S = b_f + β(b_g − b_f); ∂S = ∂b_f + β(∂b_g − ∂b_f) + ∂β·(b_g − b_f).
            let [q, qu, qv] = w.basis.eval(&patch.across[b.k as usize]);
            let d = q - p;
            (
                p + b.beta * d,
                pu + b.beta * (qu - pu) + b.beta_u * d,
                pv + b.beta * (qv - pv) + b.beta_v * d,
            )
        } else {
            (p, pu, pv)
        };
        let l = w.bary;
        let interpolated = l[0] * patch.normal[0] + l[1] * patch.normal[1] + l[2] * patch.normal[2];
        let n = du.cross(dv);
        let len2 = n.length_squared();
        // |N| ≤ 1e-14·|∂_u S|·|∂_v S|: the tangents are parallel to rounding (a degenerate
        // triangle); fall back to the interpolated input normal.
        let normal = if len2 > 1e-28 * du.length_squared() * dv.length_squared() && len2.is_finite()
        {
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
    }
}

impl Surface for G2Surface {
    fn evaluate(&self, tri: usize, bary: [f64; 3]) -> SurfacePoint {
        let w = PointWeights::at(bary, self.patches[tri].h, self.profile);
        self.combine(tri, &w)
    }

    fn evaluate_lattice(&self, tri: usize, level: u32, out: &mut Vec<SurfacePoint>) {
        let pattern = self.patterns.get(level, self.patches[tri].h, self.profile);
        out.extend(pattern.points.iter().map(|w| self.combine(tri, w)));
    }

    fn evaluate_lattice_points(
        &self,
        tri: usize,
        level: u32,
        points: &[(u32, u32)],
        out: &mut Vec<SurfacePoint>,
    ) {
        let pattern = self.patterns.get(level, self.patches[tri].h, self.profile);
        out.extend(
            points
                .iter()
                .map(|&(i, j)| self.combine(tri, &pattern.points[lattice_index(level, i, j)])),
        );
    }
}

/// Plain PN triangles (Vlachos et al. 2001; paper Eq. 1–2): the G² surface with h = 0 on every
/// edge, including its shared edge curves across split normals.
#[derive(Debug)]
pub struct PnSurface(G2Surface);

impl PnSurface {
    /// PN triangles over `mesh`.
    pub fn new(mesh: &TriMesh, topo: &Topology) -> Self {
        let zero = vec![0.0; topo.edges.len()];
        PnSurface(G2Surface::new(mesh, topo, &zero, Profile::default()))
    }
}

impl Surface for PnSurface {
    fn evaluate(&self, tri: usize, bary: [f64; 3]) -> SurfacePoint {
        self.0.evaluate(tri, bary)
    }

    fn evaluate_lattice(&self, tri: usize, level: u32, out: &mut Vec<SurfacePoint>) {
        self.0.evaluate_lattice(tri, level, out)
    }

    fn evaluate_lattice_points(
        &self,
        tri: usize,
        level: u32,
        points: &[(u32, u32)],
        out: &mut Vec<SurfacePoint>,
    ) {
        self.0.evaluate_lattice_points(tri, level, points, out)
    }
}

/// Clamped widths per edge (0 for edges that cannot blend) and one warning per kind of edge
/// that was asked to blend but cannot.
fn effective_widths(topo: &Topology, h: &[f64]) -> (Vec<f64>, Vec<Warning>) {
    let mut ignored: Vec<(EdgeKind, usize, usize)> = Vec::new();
    let widths = topo
        .edges
        .iter()
        .zip(h)
        .enumerate()
        .map(|(e, (edge, &h))| {
            let h = if h > 0.0 { h.min(H_MAX) } else { 0.0 };
            if edge.kind == EdgeKind::Interior {
                return h;
            }
            if h > 0.0 {
                match ignored.iter_mut().find(|(k, _, _)| *k == edge.kind) {
                    Some(entry) => entry.1 += 1,
                    None => ignored.push((edge.kind, 1, e)),
                }
            }
            0.0
        })
        .collect();
    let warnings = ignored
        .into_iter()
        .map(|(kind, edges, first)| Warning::BlendIgnored {
            kind,
            edges,
            first: crate::topology::EdgeId(first as u32),
        })
        .collect();
    (widths, warnings)
}

/// Makes every triangle along an unblended edge use one boundary curve: if their inner edge
/// control points differ (split normals), each gets the average, oriented along the edge
/// (PN-AEN); `b111` is then recomputed from the new edge points (Eq. 2).
fn share_unblended_edge_curves(topo: &Topology, h_edge: &[f64], patches: &mut [Patch]) {
    let mut touched = vec![false; patches.len()];
    for (edge, &h) in topo.edges.iter().zip(h_edge) {
        if h > 0.0 || edge.tris.len() < 2 || edge.verts[0] == edge.verts[1] {
            continue;
        }
        // Slots of the control points next to verts[0] and next to verts[1], per use.
        let slots: Vec<(usize, [usize; 2])> = edge
            .tris
            .iter()
            .map(|&(t, k)| {
                let (k, t) = (k as usize, t.0 as usize);
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                let s = if topo.tri_verts[t][i] == edge.verts[0] {
                    [NEAR[i][j], NEAR[j][i]]
                } else {
                    [NEAR[j][i], NEAR[i][j]]
                };
                (t, s)
            })
            .collect();
        let first = slots[0].1.map(|s| patches[slots[0].0].net[s]);
        let same = slots
            .iter()
            .all(|&(t, s)| s.map(|s| patches[t].net[s]) == first);
        if same {
            continue;
        }
        let mut sum = [DVec3::ZERO; 2];
        for &(t, s) in &slots {
            sum[0] += patches[t].net[s[0]];
            sum[1] += patches[t].net[s[1]];
        }
        let avg = sum.map(|x| x / slots.len() as f64);
        for &(t, s) in &slots {
            patches[t].net[s[0]] = avg[0];
            patches[t].net[s[1]] = avg[1];
            touched[t] = true;
        }
    }
    for (patch, touched) in patches.iter_mut().zip(touched) {
        if touched {
            patch.net[B111] = central_point(&patch.net);
        }
    }
}
