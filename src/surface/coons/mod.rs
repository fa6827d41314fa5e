//! The C¹ Coons-type blending of seed 002 (M. Szilvási-Nagy and I. Szabó, "C¹-Continuous
//! Coons-type Blending of Triangular Patches") made into a G¹ surface over a whole mesh.
//!
//! It deliberately does no tessellation and prints nothing; the paper's single-patch formula is
//! in [`patch`], the optional fairing of its shape parameters in [`fair`].
//!
//! The paper blends three given constituents over one triangle and builds no mesh. Here each
//! smooth edge e between triangles f and g gets **one** edge surface `S_e`, and each triangle
//! uses `S_e` restricted to itself as its constituent for that edge. By Definition 2 (as
//! corrected) f joins `S_e` C¹ along e in f's barycentrics, and g joins it C¹ in g's; the chart
//! between them is affine, so f and g join G¹. Every constituent interpolates the corners and is
//! tangent to the vertex normals there, which is the corner compatibility Theorem 1 needs.
//!
//! Edge surfaces ([`Constituents`]):
//! - [`Constituents::FoleyOpitz`] (default): the two Foley–Opitz nets of the hybrid scheme for
//!   that edge, C¹ over its projection plane, with the hybrid's plane fallbacks.
//! - [`Constituents::PnAverage`]: `S_e = ½(PN_f + PN_g)`, each PN cubic extended polynomially
//!   over the other triangle (seed 000's neighbour map, [`compose`]); needs no plane and has no
//!   singular setup.
//!
//! The default is the Foley–Opitz one because it is measurably better (`tests/integration/schemes_shape.rs`,
//! `benches/schemes.rs`): closer to the exact surface on every mesh measured (sphere sampled by
//! an icosahedron: max distance 0.0134 against 0.0597; torus 10×10: 0.0109 against 0.0239, where
//! PN gives 0.0584 and 0.0117), and cheaper to build and to evaluate. `PnAverage` is kept for
//! meshes whose folds defeat the projection planes.
//!
//! Creases (`h = 0`, boundary, non-manifold, degenerate): the constituent is the triangle's own
//! PN net with the shared crease curve ([`own_nets`]), so each side joins its own PN
//! patch C¹: G0 across, tangent to its own normals, watertight.
//!
//! Normals: exact, by forward differentiation of the patch formula ([`dual`]), including the
//! directional derivatives inside its correction term (a dual of a dual). Central differences
//! ([`NormalMethod::FiniteDifference`]) agree to 1.7e-7° but cost more, so analytic is the
//! default. Where a smooth edge has split normals, the side each normal is turned to follows
//! the mean end normals its edge surface is built from, blended with the weights of the
//! auxiliary curves in Eq. 4 ([`EdgeNormals`]), so that both triangles pick the same side along
//! the edge.
//!
//! Speed: Eq. 11 is linear in the 30 control points of the three constituents, with
//! coefficients that depend only on the domain point, λ and the reading of Definition 2
//! ([`weights`]). A lattice's coefficients, with their derivatives, are computed once per
//! (level, λ, definition) in canonical corner order and shared by every triangle with that λ;
//! a point then costs 90 vector multiply-adds. λ is one value for the whole mesh unless faired;
//! faired λ are mostly unique, and a triangle whose λ no other triangle has computes its
//! coefficients point by point. `evaluate` computes the same coefficients at its point and goes
//! through the same combination, so lattice and `evaluate` agree bit for bit
//! (`tests/integration/schemes_lattice.rs`). Per point with its normal (`benches/schemes.rs`, bumpy sphere,
//! level 16): 0.17 µs on a lattice with one λ, 0.4 µs with faired λ, 1.1 µs alone (before the
//! coefficients were shared, every point cost 1.3 µs; PN: 0.07–0.09 µs).
//!
//! Measured (`tests/integration/schemes_continuity.rs`): gap ≤ 3e-15 L and normal jump ≤ 7e-13° across
//! every smooth edge of the generated meshes (analytic normals; 2e-6° by differences).

pub mod dual;
pub mod fair;
pub mod patch;
pub mod weights;

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use super::hybrid::{EdgeNets, PaperReading};
use super::lattice_cache::{Entry, LatticeCache};
use super::pn::{compose, Net, IJK};
use super::scheme::creases::{own_nets, smooth_edges, Corners};
use super::scheme::side::{self, EdgeNormals, NetNormals};
use super::scheme::{SchemeParams, Warning};
use super::{blend, lattice_bary, lattice_index, lattice_len, Surface, SurfacePoint};
use crate::mesh::TriMesh;
use crate::sharpness::EffectiveH;
use crate::topology::{Topology, TriId};
use patch::Definition2;
use weights::Weights;

/// The edge surfaces a Coons patch blends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Constituents {
    /// `½(PN_f + PN_g)` over the two triangles of the edge.
    PnAverage,
    /// The hybrid scheme's Foley–Opitz nets of the edge.
    #[default]
    FoleyOpitz,
}

/// How [`CoonsSurface`] computes normals.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NormalMethod {
    /// Tangents by forward differentiation (dual numbers): exact to rounding.
    #[default]
    Analytic,
    /// Tangents by central differences of positions, step `1e-5` (less near corners).
    FiniteDifference,
}

/// The Coons-type surface of seed 002 over a whole mesh.
#[derive(Debug, Clone)]
pub struct CoonsSurface {
    corners: Vec<Corners>,
    /// `perm[t][c]`: the input corner of triangle t that is its canonical corner c.
    perm: Vec<[usize; 3]>,
    /// `nets[t][k]`: triangle t's constituent for its edge opposite canonical corner k, in
    /// canonical barycentrics.
    nets: Vec<[Net; 3]>,
    /// `(λ1, λ2, λ3)` per triangle, in canonical order.
    lambda: Vec<[f64; 3]>,
    smooth: Vec<bool>,
    warnings: Vec<Warning>,
    /// The end normals of smooth edges with split normals, for the side of the normals.
    sides: EdgeNormals,
    /// Whether another triangle has the same `λ`, so that lattice weights are worth keeping.
    shared_lambda: Vec<bool>,
    normals: NormalMethod,
    definition: Definition2,
    /// Lattice weights per (level, bits of λ, definition), in canonical lattice order.
    patterns: LatticeCache<PatternKey, Vec<LatticePoint>>,
}

type PatternKey = (u32, [u64; 3], Definition2);

/// One point of a lattice in canonical barycentrics `x`, with its weights.
#[derive(Debug, Clone, Copy)]
struct LatticePoint {
    x: [f64; 3],
    weights: Weights,
}

/// `∂_u` and `∂_v` of the input barycentrics `(u, v, w)`, as changes of `(u, v, w)`.
const SEED: [[f64; 2]; 3] = [[1.0, 0.0], [0.0, 1.0], [-1.0, -1.0]];

impl CoonsSurface {
    /// λ is clamped to this range: towards 0 or 1, μ becomes discontinuous at a corner.
    pub const LAMBDA_RANGE: (f64, f64) = (0.05, 0.95);
    /// The range searched by fairing (see [`fair`]).
    pub const FAIR_RANGE: (f64, f64) = (0.25, 0.75);
    /// Most lattice weight sets kept (one for the default λ; a level-16 lattice takes about
    /// 110 kB). Faired λ are mostly unique per triangle, and those are computed point by point.
    const MAX_PATTERNS: usize = 32;

    /// Builds the surface: edges with `h > 0` are G¹, edges with `h = 0` creases (see the module
    /// docs); `h_per_edge` has one entry per welded edge of `topo`. Reads `params.lambda`,
    /// `params.fair` and `params.constituents`.
    ///
    /// # Panics
    /// If `h_per_edge`, `topo` and `mesh` do not belong together (a caller bug).
    pub fn new(
        mesh: &TriMesh,
        topo: &Topology,
        h_per_edge: &EffectiveH,
        params: &SchemeParams,
    ) -> Self {
        super::assert_belong_together(mesh, topo, Some(h_per_edge));
        let (corners, nets, smooth, warnings) = match params.constituents {
            Constituents::PnAverage => pn_average(mesh, topo, h_per_edge),
            Constituents::FoleyOpitz => {
                let e = EdgeNets::new(mesh, topo, h_per_edge, PaperReading::Corrected);
                (e.corners, e.nets, e.smooth, e.warnings)
            }
        };
        let perm: Vec<[usize; 3]> = corners
            .iter()
            .map(|c| canonical_order(c.position))
            .collect();
        let nets: Vec<[Net; 3]> = nets
            .iter()
            .zip(&perm)
            .map(|(r, p)| p.map(|k| permute_net(&r[k], *p)))
            .collect();
        let (lo, hi) = Self::LAMBDA_RANGE;
        let start = if params.lambda.is_nan() {
            SchemeParams::DEFAULT_LAMBDA
        } else {
            params.lambda.clamp(lo, hi)
        };
        let lambda = if params.fair {
            // Each triangle is faired alone (a fixed search on its own nets), so the result
            // does not depend on how the work is split.
            nets.par_iter()
                .map(|r| fair::fair_lambda(r, start, Self::FAIR_RANGE))
                .collect()
        } else {
            vec![[start; 3]; nets.len()]
        };
        let mut uses: HashMap<[u64; 3], usize> = HashMap::new();
        for l in &lambda {
            *uses.entry(l.map(f64::to_bits)).or_default() += 1;
        }
        let shared_lambda = lambda
            .iter()
            .map(|l| uses[&l.map(f64::to_bits)] > 1)
            .collect();
        let sides = EdgeNormals::new(&corners, topo, &smooth);
        CoonsSurface {
            corners,
            perm,
            nets,
            lambda,
            smooth,
            warnings,
            sides,
            shared_lambda,
            normals: NormalMethod::default(),
            definition: Definition2::Corrected,
            patterns: LatticeCache::new(Self::MAX_PATTERNS),
        }
    }

    /// The same surface with normals computed by `method`.
    pub fn with_normals(mut self, method: NormalMethod) -> Self {
        self.normals = method;
        self
    }

    /// The surface as built from one reading of Definition 2 (for tests).
    pub fn with_definition(mut self, definition: Definition2) -> Self {
        self.definition = definition;
        self
    }

    /// `(λ1, λ2, λ3)` of each triangle.
    pub fn lambda(&self) -> &[[f64; 3]] {
        &self.lambda
    }

    /// Triangle `t`'s three constituent nets, in its canonical corner order.
    pub fn constituents(&self, t: usize) -> &[Net; 3] {
        &self.nets[t]
    }

    /// Per welded edge: smooth (G¹) or a crease.
    pub fn smooth_edges(&self) -> &[bool] {
        &self.smooth
    }

    /// Fallbacks taken while building.
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// The position alone, as the finite-difference normals need it; equal to the analytic
    /// path's position bit for bit ([`weights::position`]).
    fn position(&self, tri: usize, l: [f64; 3]) -> DVec3 {
        let x = self.perm[tri].map(|c| l[c]);
        weights::position(self.lambda[tri], x, self.definition, &self.nets[tri])
    }

    /// The lattice weights for triangle `tri`'s λ, when they are worth keeping and there is
    /// room; `None` means evaluate point by point (same values).
    fn pattern(&self, tri: usize, level: u32) -> Option<Entry<'_, Vec<LatticePoint>>> {
        if self.normals != NormalMethod::Analytic || !self.shared_lambda[tri] {
            return None;
        }
        let lambda = self.lambda[tri];
        let key = (level, lambda.map(f64::to_bits), self.definition);
        self.patterns.get_or_build(key, || {
            let mut points = Vec::with_capacity(lattice_len(level));
            for j in 0..=level {
                for i in 0..=level - j {
                    let x = lattice_bary(level, i, j);
                    points.push(LatticePoint {
                        x,
                        weights: Weights::at(lambda, x, self.definition),
                    });
                }
            }
            points
        })
    }

    /// Lattice point `(i, j)` of triangle `tri` from the canonical-order `pattern`: the same
    /// point and weights as [`Surface::evaluate`] computes there, since a lattice point in
    /// canonical order is another point of the same lattice with the same coordinates.
    #[inline]
    fn lattice_point(
        &self,
        tri: usize,
        level: u32,
        pattern: &[LatticePoint],
        nets: Option<&NetNormals>,
        (i, j): (u32, u32),
    ) -> SurfacePoint {
        let perm = self.perm[tri];
        let e = [level - i - j, i, j];
        let p = &pattern[lattice_index(level, e[perm[1]], e[perm[2]])];
        let mut l = [0.0; 3];
        for c in 0..3 {
            l[perm[c]] = p.x[c];
        }
        self.analytic(tri, l, &p.weights, nets)
    }

    /// The surface point of triangle `tri` at input barycentrics `l` with the weights of its
    /// canonical barycentrics: the one analytic path of both `evaluate` and the lattice. `nets`
    /// is the triangle's `self.sides.of(tri)`, looked up once per triangle by the lattices.
    #[inline]
    fn analytic(
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
        let [position, d0, d1] = w.combine(&self.nets[tri]);
        // The input directions in canonical barycentrics, as sums of ±∂_0 and ±∂_1.
        let s = self.perm[tri].map(|c| SEED[c]);
        let du = s[0][0] * d0 + s[1][0] * d1;
        let dv = s[0][1] * d0 + s[1][1] * d1;
        SurfacePoint {
            position,
            normal: side::orient(corners, nets, l, du, dv, curve_shares),
        }
    }
}

/// The weights of the three auxiliary curves in seed 002 Eq. 4, `u_j² u_k² / Σ` for the curve
/// of edge `u_i = 0` with `Σ = v²w² + u²w² + u²v²`: how the patch follows each edge's
/// constituent, exactly 1 on its edge and exactly 0 on the other two (the products that vanish
/// there are exact zeros). Symmetric in the corners, so input and canonical order agree. Not
/// finite at a corner.
fn curve_shares(l: [f64; 3]) -> [f64; 3] {
    let [a, b, c] = l.map(|x| x * x);
    let s = [b * c, a * c, a * b];
    let sum = s[0] + s[1] + s[2];
    s.map(|x| x / sum)
}

/// The corners of a triangle sorted by position (lexicographic, total order): the Coons patch
/// is invariant under cyclic relabelling but not under reflection (its auxiliary curves are
/// projected in one rotational sense), so it is always built in this order, which does not
/// depend on the input's corner order or winding.
fn canonical_order(p: [DVec3; 3]) -> [usize; 3] {
    let key = |c: usize| p[c].to_array();
    let mut order = [0, 1, 2];
    order.sort_by(|&a, &b| {
        let (ka, kb) = (key(a), key(b));
        ka[0]
            .total_cmp(&kb[0])
            .then(ka[1].total_cmp(&kb[1]))
            .then(ka[2].total_cmp(&kb[2]))
    });
    order
}

/// `net` re-expressed in barycentrics `x` with `x[c] = l[perm[c]]`: the point with exponents
/// `e'` is the old point with exponents `e[perm[c]] = e'[c]`.
fn permute_net(net: &Net, perm: [usize; 3]) -> Net {
    std::array::from_fn(|m| {
        let mut e = [0; 3];
        for c in 0..3 {
            e[perm[c]] = IJK[m][c];
        }
        net[IJK
            .iter()
            .position(|x| *x == e)
            .expect("exponents sum to 3")]
    })
}

type Built = (Vec<Corners>, Vec<[Net; 3]>, Vec<bool>, Vec<Warning>);

/// Constituents `½(PN_f + PN_g ∘ M)` on smooth edges, the own PN net elsewhere.
fn pn_average(mesh: &TriMesh, topo: &Topology, h: &EffectiveH) -> Built {
    let corners: Vec<Corners> = (0..mesh.triangles.len())
        .map(|t| Corners::of(mesh, t))
        .collect();
    let smooth = smooth_edges(h);
    let warnings = Vec::new();
    let own = own_nets(&corners, topo, &smooth);
    let nets = (0..own.len())
        .map(|t| {
            std::array::from_fn(|k| {
                if !smooth[topo.tri_edges[t][k].0 as usize] {
                    return own[t];
                }
                let n = topo
                    .neighbour(TriId(t as u32), k)
                    .expect("smooth edges are interior");
                let cols = blend::neighbour_map(k, n.slots.map(usize::from));
                let other = compose(&own[n.tri.0 as usize], cols);
                std::array::from_fn(|m| 0.5 * (own[t][m] + other[m]))
            })
        })
        .collect();
    (corners, nets, smooth, warnings)
}

impl Surface for CoonsSurface {
    fn evaluate(&self, tri: usize, l: [f64; 3]) -> SurfacePoint {
        let corners = &self.corners[tri];
        if let Some(p) = corners.at_corner(l) {
            return p;
        }
        match self.normals {
            NormalMethod::Analytic => {
                let x = self.perm[tri].map(|c| l[c]);
                let w = Weights::at(self.lambda[tri], x, self.definition);
                self.analytic(tri, l, &w, self.sides.of(tri))
            }
            NormalMethod::FiniteDifference => {
                // The patch varies on the scale of the distance to the nearest corner.
                let rho = 1.0 - l[0].max(l[1]).max(l[2]);
                let e = (1e-3 * rho).min(1e-5);
                let at = |a: f64, b: f64| self.position(tri, [l[0] + a, l[1] + b, l[2] - a - b]);
                let du = (at(e, 0.0) - at(-e, 0.0)) / (2.0 * e);
                let dv = (at(0.0, e) - at(0.0, -e)) / (2.0 * e);
                SurfacePoint {
                    position: self.position(tri, l),
                    normal: side::orient(corners, self.sides.of(tri), l, du, dv, curve_shares),
                }
            }
        }
    }

    fn evaluate_lattice(&self, tri: usize, level: u32, out: &mut Vec<SurfacePoint>) {
        out.reserve(lattice_len(level));
        let pattern = self.pattern(tri, level);
        let nets = self.sides.of(tri);
        for j in 0..=level {
            for i in 0..=level - j {
                out.push(match &pattern {
                    Some(p) => self.lattice_point(tri, level, p, nets, (i, j)),
                    None => self.evaluate(tri, lattice_bary(level, i, j)),
                });
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
        let pattern = self.pattern(tri, level);
        let nets = self.sides.of(tri);
        out.extend(points.iter().map(|&(i, j)| match &pattern {
            Some(p) => self.lattice_point(tri, level, p, nets, (i, j)),
            None => self.evaluate(tri, lattice_bary(level, i, j)),
        }));
    }
}
