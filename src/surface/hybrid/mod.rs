//! The Mann–Davidchuk parametric hybrid cubic patch over a whole mesh (seed 001: S. Mann and
//! M. Davidchuk, "A Parametric Hybrid Triangular Bézier Patch"), G¹ across every smooth edge,
//! with analytic normals.
//!
//! It deliberately does no tessellation and prints nothing: folded edges become creases and are
//! reported as [`Warning`]s.
//!
//! Construction, once per smooth interior edge AB between triangles f = ABC and g = ABY:
//! 1. A projection plane with normal `m` ([`plane::projection_plane`], seed 001 §4).
//! 2. For each of f and g, a cubic net whose six non-corner boundary points are the oblique
//!    Hermite points of that plane ([`plane::oblique_point`]); the edge's own two points are
//!    computed once and shared. Apex normals too steep for the plane are tilted for this edge
//!    only ([`plane::tilt_to_plane`]).
//! 3. Their interior points by Foley–Opitz ([`foley_opitz`], seed 001 §2, corrected), so the two
//!    nets join C¹ over the plane; `p` is computed on the side with `|t| ≥ 1` and the other
//!    side's from the C¹ condition, so they are exactly consistent.
//!
//! Each triangle then blends its three nets ([`patch`], seed 001 Eq. 1–2).
//!
//! Creases (`h = 0`, boundary, non-manifold and degenerate edges, and edges with no plane):
//! the edge's net is the triangle's own PN net with the crease curve both sides share
//! ([`own_nets`]). The boundary curve is then the same cubic as in the PN and G²
//! schemes, each side keeps its own tangent planes, and the join is G0. For split normals on a
//! smooth edge both sides use the mean of their end normals for that edge, and the side each
//! normal is turned to follows those means blended with Nielson's weights of Eq. 1
//! ([`EdgeNormals`]), so that both triangles pick the same side along the edge.
//!
//! Speed: the patch is linear in the nets with coefficients that depend on the domain point only
//! (Bernstein values, Eq. 2's `h_ij` and Eq. 1's Nielson weights, and their derivatives), so a
//! lattice's coefficients are computed once per level ([`patch::Weights`]) and every triangle
//! combines them with its 18 distinct control points: 54 vector multiply-adds per point.
//! `evaluate` computes the same coefficients at its point and goes through the same combination,
//! so lattice and `evaluate` agree bit for bit (`tests/integration/schemes_lattice.rs`).
//!
//! Measured (`tests/integration/schemes_continuity.rs`, `tests/integration/schemes_shape.rs`, `benches/schemes.rs`): gap
//! ≤ 2e-15 L and normal jump ≤ 4e-13° across every smooth edge of the generated meshes; per
//! point with its normal 0.09 µs on a lattice (PN 0.07–0.09 µs) and 0.16 µs alone, as before;
//! distance to the exact sphere sampled by an icosahedron 0.0131 (PN 0.0584).

pub mod foley_opitz;
pub mod patch;
pub mod plane;

use glam::DVec3;
use rayon::prelude::*;

use super::lattice_cache::{Entry, LatticeCache};
use super::pn::{Net, B111, NEAR};
use super::scheme::creases::{edge_end_normal, own_nets, smooth_edges, Corners};
use super::scheme::side::{self, EdgeNormals, NetNormals};
use super::scheme::Warning;
use super::{lattice_bary, lattice_index, lattice_len, Surface, SurfacePoint};
use crate::mesh::TriMesh;
use crate::sharpness::EffectiveH;
use crate::topology::{EdgeId, Topology, TriId};
use foley_opitz::{apex_barycentrics, interior_point, neighbour_interior, Labelled};
use patch::{BoundaryBlend, Weights, TERMS};

/// How to read seed 001's formulas. Only [`PaperReading::Corrected`] is a valid surface; the
/// printed readings exist so that tests can show each correction is needed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PaperReading {
    #[default]
    Corrected,
    /// `(r, s, t)` with respect to `(b003, b030, b300)` as printed.
    PrintedBarycentricOrder,
    /// `q2 = r p2 + s b120 + t b210` as printed.
    PrintedQ,
    /// The boundary blend with the stray `b_{ijk,k}` ([`BoundaryBlend::PrintedStrayK`]).
    PrintedStrayK,
}

/// The three cubic nets of every triangle, one per edge, and which edges ended up smooth.
#[derive(Debug, Clone)]
pub struct EdgeNets {
    pub corners: Vec<Corners>,
    /// `nets[t][k]`: the net of triangle t for its edge opposite corner k.
    pub nets: Vec<[Net; 3]>,
    /// Per welded edge: G¹ (true) or a crease.
    pub smooth: Vec<bool>,
    pub warnings: Vec<Warning>,
}

impl EdgeNets {
    /// Builds the nets of every triangle of `mesh` for per-edge widths `h_per_edge`.
    ///
    /// # Panics
    /// If `h_per_edge`, `topo` and `mesh` do not belong together (a caller bug).
    pub fn new(
        mesh: &TriMesh,
        topo: &Topology,
        h_per_edge: &EffectiveH,
        reading: PaperReading,
    ) -> Self {
        super::assert_belong_together(mesh, topo, Some(h_per_edge));
        let corners: Vec<Corners> = (0..mesh.triangles.len())
            .map(|t| Corners::of(mesh, t))
            .collect();
        let mut smooth = smooth_edges(h_per_edge);
        let mut warnings = Vec::new();

        let mut planes = vec![DVec3::ZERO; topo.edge_count()];
        let mut failed: Option<(usize, usize)> = None;
        for e in 0..topo.edge_count() {
            if !smooth[e] {
                continue;
            }
            let edge = EdgeFrame::new(&corners, topo, e);
            match plane::projection_plane(edge.na, edge.nb, edge.nf, edge.ng) {
                Some(m) => planes[e] = m,
                None => {
                    smooth[e] = false;
                    let entry = failed.get_or_insert((0, e));
                    entry.0 += 1;
                }
            }
        }
        if let Some((edges, first)) = failed {
            warnings.push(Warning::NoProjectionPlane {
                edges,
                first: EdgeId(first as u32),
            });
        }

        let own = own_nets(&corners, topo, &smooth);
        let mut nets: Vec<[Net; 3]> = own.iter().map(|n| [*n; 3]).collect();
        for e in (0..topo.edge_count()).filter(|&e| smooth[e]) {
            let edge = EdgeFrame::new(&corners, topo, e);
            let (net_f, net_g) = edge.nets(&corners, planes[e], reading);
            nets[edge.f][edge.kf] = net_f;
            nets[edge.g][edge.slots[2]] = net_g;
        }
        EdgeNets {
            corners,
            nets,
            smooth,
            warnings,
        }
    }
}

/// One smooth edge AB seen from its first triangle f (corners i = A, j = B, kf = C) and its
/// neighbour g (slots p = A, q = B, r = Y).
struct EdgeFrame {
    f: usize,
    kf: usize,
    g: usize,
    slots: [usize; 3],
    na: DVec3,
    nb: DVec3,
    /// Face normals, oriented consistently across the edge and towards the end normals.
    nf: DVec3,
    ng: DVec3,
}

impl EdgeFrame {
    fn new(corners: &[Corners], topo: &Topology, e: usize) -> EdgeFrame {
        let (f, kf) = topo.edge_uses(EdgeId(e as u32))[0].at();
        let n = topo
            .neighbour(TriId(f as u32), kf)
            .expect("smooth edges are interior");
        let (g, slots) = (n.tri.0 as usize, n.slots.map(usize::from));
        let (i, j) = ((kf + 1) % 3, (kf + 2) % 3);
        let na = edge_end_normal(corners, f, i, g, slots[0]);
        let nb = edge_end_normal(corners, f, j, g, slots[1]);
        let [a, b, c] = [i, j, kf].map(|x| corners[f].position[x]);
        let y = corners[g].position[slots[2]];
        // f runs A→B and g is taken B→A whatever its winding, so the two are consistent.
        let mut nf = (b - a).cross(c - a).normalize_or_zero();
        let mut ng = (a - b).cross(y - b).normalize_or_zero();
        if (nf + ng).dot(na + nb) < 0.0 {
            (nf, ng) = (-nf, -ng);
        }
        EdgeFrame {
            f,
            kf,
            g,
            slots,
            na,
            nb,
            nf,
            ng,
        }
    }

    /// The nets of f and g for this edge, for projection plane `m`.
    fn nets(&self, corners: &[Corners], m: DVec3, reading: PaperReading) -> (Net, Net) {
        let (i, j, kf) = ((self.kf + 1) % 3, (self.kf + 2) % 3, self.kf);
        let [p, q, r] = self.slots;
        let (cf, cg) = (&corners[self.f], &corners[self.g]);
        let mut nf = [DVec3::ZERO; 3];
        nf[i] = self.na;
        nf[j] = self.nb;
        nf[kf] = plane::tilt_to_plane(cf.normal[kf], m);
        let mut ng = [DVec3::ZERO; 3];
        ng[p] = self.na;
        ng[q] = self.nb;
        ng[r] = plane::tilt_to_plane(cg.normal[r], m);
        let mut net_f = boundary_net(cf.position, nf, m);
        let mut net_g = boundary_net(cg.position, ng, m);
        // The shared curve: f's two points, bit for bit.
        net_g[NEAR[p][q]] = net_f[NEAR[i][j]];
        net_g[NEAR[q][p]] = net_f[NEAR[j][i]];

        let label = |net: &Net, pos: [DVec3; 3], [a, b, c]: [usize; 3]| Labelled {
            b300: pos[a],
            b030: pos[b],
            b003: pos[c],
            b210: net[NEAR[a][b]],
            b120: net[NEAR[b][a]],
            b201: net[NEAR[a][c]],
            b021: net[NEAR[b][c]],
            b102: net[NEAR[c][a]],
            b012: net[NEAR[c][b]],
        };
        let lf = label(&net_f, cf.position, [i, j, kf]);
        let lg = label(&net_g, cg.position, [p, q, r]);
        let order = |rst: [f64; 3]| match reading {
            PaperReading::PrintedBarycentricOrder => [rst[2], rst[1], rst[0]],
            _ => rst,
        };
        let other = |l: &Labelled, p2: DVec3, rst: [f64; 3]| match reading {
            PaperReading::PrintedQ => {
                let [r, s, t] = rst;
                r * p2 + s * l.b120 + t * l.b210
            }
            _ => neighbour_interior(l.b210, l.b120, p2, rst),
        };
        let rst = apex_barycentrics(m, lf.b300, lf.b030, lf.b003, lg.b003);
        // The side whose projected triangle is the smaller one has |t| ≥ 1: compute p there.
        let (pf, pg) = if rst[2].abs() >= 1.0 {
            let rst = order(rst);
            let pf = interior_point(&lf, lg.b102, lg.b012, rst);
            (pf, other(&lf, pf, rst))
        } else {
            let rst = order(apex_barycentrics(m, lg.b300, lg.b030, lg.b003, lf.b003));
            let pg = interior_point(&lg, lf.b102, lf.b012, rst);
            (other(&lg, pg, rst), pg)
        };
        net_f[B111] = pf;
        net_g[B111] = pg;
        (net_f, net_g)
    }
}

/// Corners and the six oblique boundary points of one triangle for plane `m`; `b111` unset.
fn boundary_net(position: [DVec3; 3], normal: [DVec3; 3], m: DVec3) -> Net {
    let mut net = [DVec3::ZERO; 10];
    for c in 0..3 {
        net[NEAR[c][c]] = position[c];
        for e in (0..3).filter(|&e| e != c) {
            net[NEAR[c][e]] = plane::oblique_point(position[c], position[e], normal[c], m);
        }
    }
    net
}

/// The parametric hybrid surface of seed 001 over a whole mesh.
#[derive(Debug, Clone)]
pub struct HybridSurface {
    /// Per triangle, its corners (positions and normals).
    corners: Vec<Corners>,
    /// Per welded edge: G¹ (true) or a crease.
    smooth: Vec<bool>,
    /// Fallbacks taken while building.
    warnings: Vec<Warning>,
    /// The end normals of smooth edges with split normals, for the side of the normals.
    sides: EdgeNormals,
    /// Per triangle, the control points its [`Weights`] combine ([`patch::gather`]). The three
    /// edge nets they are gathered from are not kept (720 bytes a triangle, read by nothing
    /// after this).
    terms: Vec<[DVec3; TERMS]>,
    /// Per level, the weights of every lattice point, in lattice order.
    patterns: LatticeCache<u32, Vec<LatticePoint>>,
}

/// One lattice point: its barycentrics (for the corner test and the normal's orientation) and
/// its weights.
#[derive(Debug, Clone, Copy)]
struct LatticePoint {
    bary: [f64; 3],
    weights: Weights,
}

impl HybridSurface {
    /// Most levels whose weights are kept (a level-16 lattice takes about 70 kB).
    const MAX_PATTERNS: usize = 64;

    /// Builds the surface: edges with `h > 0` are G¹, edges with `h = 0` creases (see the
    /// module docs); `h_per_edge` has one entry per welded edge of `topo`.
    ///
    /// # Panics
    /// If `h_per_edge`, `topo` and `mesh` do not belong together (a caller bug).
    pub fn new(mesh: &TriMesh, topo: &Topology, h_per_edge: &EffectiveH) -> Self {
        Self::with_reading(mesh, topo, h_per_edge, PaperReading::Corrected)
    }

    /// The surface as built from one reading of the paper's formulas (for tests).
    pub fn with_reading(
        mesh: &TriMesh,
        topo: &Topology,
        h_per_edge: &EffectiveH,
        reading: PaperReading,
    ) -> Self {
        let blend = match reading {
            PaperReading::PrintedStrayK => BoundaryBlend::PrintedStrayK,
            _ => BoundaryBlend::Corrected,
        };
        let EdgeNets {
            corners,
            nets,
            smooth,
            warnings,
        } = EdgeNets::new(mesh, topo, h_per_edge, reading);
        let terms = nets.par_iter().map(|n| patch::gather(n, blend)).collect();
        let sides = EdgeNormals::new(&corners, topo, &smooth);
        HybridSurface {
            corners,
            smooth,
            warnings,
            sides,
            terms,
            patterns: LatticeCache::new(Self::MAX_PATTERNS),
        }
    }

    /// Per welded edge: smooth (G¹) or a crease.
    pub fn smooth_edges(&self) -> &[bool] {
        &self.smooth
    }

    /// Fallbacks taken while building.
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// The weights of every point of the level-`level` lattice, built on first use.
    fn pattern(&self, level: u32) -> Option<Entry<'_, Vec<LatticePoint>>> {
        self.patterns.get_or_build(level, || {
            let mut points = Vec::with_capacity(lattice_len(level));
            for j in 0..=level {
                for i in 0..=level - j {
                    let bary = lattice_bary(level, i, j);
                    points.push(LatticePoint {
                        bary,
                        weights: patch::weights(bary),
                    });
                }
            }
            points
        })
    }

    /// The surface point of triangle `tri` at barycentrics `l` with weights `w` computed there:
    /// the one path of both [`Surface::evaluate`] and the lattice. `nets` is the triangle's
    /// `self.sides.of(tri)`, looked up once per triangle by the lattices.
    #[inline]
    fn combine(
        &self,
        tri: usize,
        l: [f64; 3],
        w: &Weights,
        nets: Option<&NetNormals>,
    ) -> SurfacePoint {
        let corners = &self.corners[tri];
        if let Some(p) = corners.at_corner(l) {
            return p;
        }
        let [position, du, dv] = patch::combine(w, &self.terms[tri]);
        SurfacePoint {
            position,
            normal: side::orient(corners, nets, l, du, dv, patch::net_shares),
        }
    }
}

impl Surface for HybridSurface {
    fn evaluate(&self, tri: usize, bary: [f64; 3]) -> SurfacePoint {
        if let Some(p) = self.corners[tri].at_corner(bary) {
            return p;
        }
        self.combine(tri, bary, &patch::weights(bary), self.sides.of(tri))
    }

    fn evaluate_lattice(&self, tri: usize, level: u32, out: &mut Vec<SurfacePoint>) {
        match self.pattern(level) {
            Some(pattern) => {
                let nets = self.sides.of(tri);
                out.extend(
                    pattern
                        .iter()
                        .map(|p| self.combine(tri, p.bary, &p.weights, nets)),
                )
            }
            None => {
                out.reserve(lattice_len(level));
                for j in 0..=level {
                    for i in 0..=level - j {
                        out.push(self.evaluate(tri, lattice_bary(level, i, j)));
                    }
                }
            }
        }
    }

    fn evaluate_lattice_points(
        &self,
        tri: usize,
        level: u32,
        points: &[(u32, u32)],
        out: &mut Vec<SurfacePoint>,
    ) {
        match self.pattern(level) {
            Some(pattern) => {
                let nets = self.sides.of(tri);
                out.extend(points.iter().map(|&(i, j)| {
                    let p = &pattern[lattice_index(level, i, j)];
                    self.combine(tri, p.bary, &p.weights, nets)
                }))
            }
            None => out.extend(
                points
                    .iter()
                    .map(|&(i, j)| self.evaluate(tri, lattice_bary(level, i, j))),
            ),
        }
    }
}
