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
//! The default is the Foley–Opitz one because it is measurably better (`tests/schemes_shape.rs`,
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
//! ([`NormalMethod::FiniteDifference`]) agree to 1.7e-7° but cost more: per point with its normal
//! on the bumpy sphere (`benches/schemes.rs`), 1.4 µs analytic against 2.7 µs by differences
//! (PN: 0.13 µs), so analytic is the default.
//!
//! Measured (`tests/schemes_continuity.rs`): gap ≤ 3e-15 L and normal jump ≤ 7e-13° across
//! every smooth edge of the generated meshes (analytic normals; 2e-6° by differences).

pub mod dual;
pub mod fair;
pub mod patch;

use glam::DVec3;

use super::hybrid::{EdgeNets, PaperReading};
use super::pn::{compose, Net, IJK};
use super::scheme::creases::{own_nets, smooth_edges, Corners};
use super::scheme::{SchemeParams, Warning};
use super::{blend, Surface, SurfacePoint};
use crate::mesh::TriMesh;
use crate::topology::Topology;
use dual::Dual;
use patch::Definition2;

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
    normals: NormalMethod,
    definition: Definition2,
}

impl CoonsSurface {
    /// λ is clamped to this range: towards 0 or 1, μ becomes discontinuous at a corner.
    pub const LAMBDA_RANGE: (f64, f64) = (0.05, 0.95);
    /// The range searched by fairing (see [`fair`]).
    pub const FAIR_RANGE: (f64, f64) = (0.25, 0.75);

    /// Builds the surface: edges with `h > 0` are G¹, edges with `h = 0` creases (see the module
    /// docs); `h_per_edge` has one entry per welded edge of `topo`. Reads `params.lambda`,
    /// `params.fair` and `params.constituents`.
    ///
    /// # Panics
    /// If `h_per_edge`, `topo` and `mesh` do not belong together (a caller bug).
    pub fn new(mesh: &TriMesh, topo: &Topology, h_per_edge: &[f64], params: &SchemeParams) -> Self {
        super::assert_belong_together(mesh, topo, h_per_edge);
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
            nets.iter()
                .map(|r| fair::fair_lambda(r, start, Self::FAIR_RANGE))
                .collect()
        } else {
            vec![[start; 3]; nets.len()]
        };
        CoonsSurface {
            corners,
            perm,
            nets,
            lambda,
            smooth,
            warnings,
            normals: NormalMethod::default(),
            definition: Definition2::Corrected,
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

    fn position(&self, tri: usize, l: [f64; 3]) -> DVec3 {
        let x = self.perm[tri].map(|c| l[c]);
        let f = patch::point(&self.nets[tri], self.lambda[tri], x, self.definition);
        DVec3::from_array(f)
    }
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
fn pn_average(mesh: &TriMesh, topo: &Topology, h: &[f64]) -> Built {
    let corners: Vec<Corners> = (0..mesh.triangles.len())
        .map(|t| Corners::of(mesh, t))
        .collect();
    let (smooth, warnings) = smooth_edges(topo, h);
    let own = own_nets(&corners, topo, &smooth);
    let nets = (0..own.len())
        .map(|t| {
            std::array::from_fn(|k| {
                if !smooth[topo.tri_edges[t][k].0 as usize] {
                    return own[t];
                }
                let n = topo.neighbours[t][k].expect("smooth edges are interior");
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
        let (position, du, dv) = match self.normals {
            NormalMethod::Analytic => {
                // ∂_u and ∂_v of the input barycentrics, seeded into the canonical ones.
                const SEED: [[f64; 2]; 3] = [[1.0, 0.0], [0.0, 1.0], [-1.0, -1.0]];
                let x = self.perm[tri].map(|c| Dual::new(l[c], SEED[c]));
                let f = patch::point(&self.nets[tri], self.lambda[tri], x, self.definition);
                (
                    DVec3::new(f[0].v, f[1].v, f[2].v),
                    DVec3::new(f[0].d[0], f[1].d[0], f[2].d[0]),
                    DVec3::new(f[0].d[1], f[1].d[1], f[2].d[1]),
                )
            }
            NormalMethod::FiniteDifference => {
                // The patch varies on the scale of the distance to the nearest corner.
                let rho = 1.0 - l[0].max(l[1]).max(l[2]);
                let e = (1e-3 * rho).min(1e-5);
                let at = |a: f64, b: f64| self.position(tri, [l[0] + a, l[1] + b, l[2] - a - b]);
                (
                    self.position(tri, l),
                    (at(e, 0.0) - at(-e, 0.0)) / (2.0 * e),
                    (at(0.0, e) - at(0.0, -e)) / (2.0 * e),
                )
            }
        };
        SurfacePoint {
            position,
            normal: corners.orient(l, du, dv),
        }
    }
}
