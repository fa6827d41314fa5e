//! The choice of surface construction (`--scheme g2|pn|hybrid|coons`), its parameters, and the one
//! constructor that builds any of them over a whole mesh.
//!
//! It deliberately parses no command line and prints nothing: the scheme comes in as a value and
//! fallbacks go out as [`Warning`]s.
//!
//! How per-edge `h` maps onto each scheme (h is the width of seed 000; `h = 0` is a crease):
//!
//! | scheme | `h = 0` | `h > 0` |
//! |---|---|---|
//! | `g2` | PN crease (G0) | G² blend of width h |
//! | `pn` | PN crease (G0) | ignored: PN is G0 everywhere |
//! | `hybrid` | each side its own PN interior (G0) | Foley–Opitz interiors (G1); the value of h does not matter |
//! | `coons` | each side joins its own PN patch C1 (G0 across) | shared edge surface (G1); the value of h does not matter |
//!
//! In every scheme the boundary curve of an edge is computed once for both sides, so the surface
//! is watertight at any h; at a crease each side stays tangent to its own input normals
//! ([`creases`]). Where a smooth edge of the hybrid or Coons scheme has split normals, both
//! sides turn their normals to the side of the end normals they share ([`side`]).

pub mod creases;
pub mod side;

use std::fmt;
use std::str::FromStr;

use crate::mesh::TriMesh;
use crate::sharpness::EffectiveH;
use crate::topology::{EdgeId, Topology};

use super::coons::{Constituents, CoonsSurface};
use super::hybrid::HybridSurface;
use super::{G2Surface, Nets, PnSurface, Profile, Surface};

/// A surface construction.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Deserialize, serde::Serialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Scheme {
    /// PN triangles blended across edges for G² (Lee–Hwang–Yoon, seed 000).
    #[default]
    G2,
    /// Plain PN triangles (Vlachos et al.): G0 across edges, for comparison.
    Pn,
    /// Mann–Davidchuk parametric hybrid cubic patches (seed 001): G1.
    Hybrid,
    /// Szilvási-Nagy–Szabó C¹ Coons-type blending of shared edge surfaces (seed 002): G1.
    Coons,
}

impl Scheme {
    /// Every scheme, in `--help` order.
    pub const ALL: [Scheme; 4] = [Scheme::G2, Scheme::Pn, Scheme::Hybrid, Scheme::Coons];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Scheme::G2 => "g2",
            Scheme::Pn => "pn",
            Scheme::Hybrid => "hybrid",
            Scheme::Coons => "coons",
        }
    }
}

impl fmt::Display for Scheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown scheme name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownScheme(pub String);

impl fmt::Display for UnknownScheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "unknown scheme '{}', expected one of g2, pn, hybrid, coons",
            self.0
        )
    }
}

impl std::error::Error for UnknownScheme {}

impl FromStr for Scheme {
    type Err = UnknownScheme;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Scheme::ALL
            .into_iter()
            .find(|x| x.name() == s)
            .ok_or_else(|| UnknownScheme(s.to_string()))
    }
}

/// Parameters of the schemes that have any; each scheme reads only its own.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SchemeParams {
    /// Blend profile of the G² scheme. Default value: [`Profile::C2`].
    pub profile: Profile,
    /// Coons shape parameter λ of seed 002 (the same for λ1, λ2, λ3), clamped to
    /// [`CoonsSurface::LAMBDA_RANGE`]. Default value: [`SchemeParams::DEFAULT_LAMBDA`].
    pub lambda: f64,
    /// Coons: choose λ per triangle by minimising the thin-plate energy of seed 002 Eq. 5
    /// instead of using `lambda`. Default value: `false`.
    pub fair: bool,
    /// Coons: the edge surfaces blended. Default value: [`Constituents::FoleyOpitz`].
    pub constituents: Constituents,
    /// Control nets of the G² and PN schemes. Default value: [`Nets::Round`].
    pub nets: Nets,
}

impl SchemeParams {
    /// Default Coons λ: symmetric, deterministic, and no worse than the faired values (see
    /// [`super::coons`]).
    pub const DEFAULT_LAMBDA: f64 = 0.5;
}

impl Default for SchemeParams {
    fn default() -> Self {
        SchemeParams {
            profile: Profile::default(),
            lambda: Self::DEFAULT_LAMBDA,
            fair: false,
            constituents: Constituents::default(),
            nets: Nets::default(),
        }
    }
}

/// A fallback taken while building a surface.
///
/// Edges a surface cannot blend (boundary, non-manifold, degenerate) are not among them: every
/// surface is built from [`EffectiveH`], already 0 on those edges, and the sharpness stage and
/// the geometry checks report them.
#[derive(Debug, Clone, PartialEq)]
pub enum Warning {
    /// Seed 001 found no usable projection plane for `edges` interior edges (first: `first`),
    /// so they were made creases (h = 0): their two triangles are too folded against each
    /// other or against their end normals for the Foley–Opitz construction.
    NoProjectionPlane { edges: usize, first: EdgeId },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::NoProjectionPlane { edges, first } => write!(
                f,
                "no projection plane for {edges} folded edge(s) (first: edge {}); they are creases",
                first.0
            ),
        }
    }
}

/// Builds `scheme` over `mesh`, one `h` per welded edge of `topo` (indexed by
/// [`EdgeId`]) as the one rule of [`EffectiveH`] decided it, and returns it with the fallbacks
/// it took.
///
/// # Panics
/// If `h_per_edge`, `topo` and `mesh` do not belong together (a caller bug).
pub fn build_surface<'a>(
    scheme: Scheme,
    mesh: &'a TriMesh,
    topo: &'a Topology,
    h_per_edge: &'a EffectiveH,
    params: &SchemeParams,
) -> (Box<dyn Surface + 'a>, Vec<Warning>) {
    match scheme {
        Scheme::G2 => (
            Box::new(G2Surface::with_nets(
                mesh,
                topo,
                h_per_edge,
                params.profile,
                params.nets,
            )),
            Vec::new(),
        ),
        Scheme::Pn => (
            Box::new(PnSurface::with_nets(mesh, topo, params.nets)),
            Vec::new(),
        ),
        Scheme::Hybrid => {
            let s = HybridSurface::new(mesh, topo, h_per_edge);
            let w = s.warnings().to_vec();
            (Box::new(s), w)
        }
        Scheme::Coons => {
            let s = CoonsSurface::new(mesh, topo, h_per_edge, params);
            let w = s.warnings().to_vec();
            (Box::new(s), w)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for s in Scheme::ALL {
            assert_eq!(s.to_string().parse::<Scheme>(), Ok(s));
        }
        let e = "gregory".parse::<Scheme>().unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown scheme 'gregory', expected one of g2, pn, hybrid, coons"
        );
    }
}
