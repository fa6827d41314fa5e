//! The h every edge is built with, decided once: [`EffectiveH`]. It deliberately holds no
//! precedence logic ([`super::resolve`] picks the requested value); it only owns the rule that
//! turns a requested h into the one the surface uses, so no later stage decides it again.

use std::fmt;
use std::ops::Deref;

use crate::surface::H_MAX;
use crate::topology::{EdgeId, EdgeKind, Topology, Warning};

/// One blend width per welded edge (indexed by [`EdgeId`]), valid by construction: finite,
/// within `[0, H_MAX]`, and 0 on every boundary, non-manifold and degenerate edge (which the
/// surface never blends). Read-only: it derefs to `[f64]`.
///
/// It is built by [`super::AssetSharpness::resolve_mesh`] for the pipeline,
/// [`EffectiveH::from_requested`] for callers holding raw widths (applying the same rule), or
/// [`EffectiveH::new`], which checks values instead of fixing them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EffectiveH(Vec<f64>);

/// Why a list of widths is not a valid [`EffectiveH`].
#[derive(Debug, Clone, PartialEq)]
pub enum InvalidH {
    /// Not one width per welded edge.
    Count { widths: usize, edges: usize },
    /// A width that is not finite or outside `[0, H_MAX]`.
    OutOfRange { edge: EdgeId, h: f64 },
    /// A width above 0 on an edge the surface never blends.
    Unblended {
        edge: EdgeId,
        kind: EdgeKind,
        h: f64,
    },
}

impl fmt::Display for InvalidH {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InvalidH::Count { widths, edges } => {
                write!(f, "{widths} widths for {edges} welded edges")
            }
            InvalidH::OutOfRange { edge, h } => {
                write!(f, "edge {}: h = {h} is outside [0, {H_MAX}]", edge.0)
            }
            InvalidH::Unblended { edge, kind, h } => {
                write!(
                    f,
                    "edge {}: h = {h} on a {kind:?} edge, which is never blended",
                    edge.0
                )
            }
        }
    }
}

impl std::error::Error for InvalidH {}

impl EffectiveH {
    /// The rule, in one place: a requested width becomes itself on an interior edge, capped at
    /// [`H_MAX`] (values printed as the bound round above it), and 0 on every other edge and for
    /// anything not above 0 (NaN included).
    pub(super) fn of_edge(kind: EdgeKind, requested: f64) -> f64 {
        if kind == EdgeKind::Interior && requested > 0.0 {
            requested.min(H_MAX)
        } else {
            0.0
        }
    }

    /// Wraps widths that [`EffectiveH::of_edge`] produced, one per edge of `topo`.
    pub(super) fn from_rule(widths: Vec<f64>) -> Self {
        EffectiveH(widths)
    }

    /// Checks `widths` (one per edge of `topo`) and takes them as they are; the first width that
    /// the rule would change is an error naming its edge.
    pub fn new(topo: &Topology, widths: Vec<f64>) -> Result<Self, InvalidH> {
        if widths.len() != topo.edge_count() {
            return Err(InvalidH::Count {
                widths: widths.len(),
                edges: topo.edge_count(),
            });
        }
        for (e, &h) in widths.iter().enumerate() {
            let edge = EdgeId(e as u32);
            if !(0.0..=H_MAX).contains(&h) {
                return Err(InvalidH::OutOfRange { edge, h });
            }
            let kind = topo.edge_kind(edge);
            if h > 0.0 && kind != EdgeKind::Interior {
                return Err(InvalidH::Unblended { edge, kind, h });
            }
        }
        Ok(EffectiveH(widths))
    }

    /// Applies the rule to requested widths (one per edge of `topo`; values are clamped to
    /// `[0, H_MAX]`, NaN to 0), with one [`Warning::BlendIgnored`] per kind of edge that was
    /// asked to blend but cannot, naming the first such edge.
    ///
    /// # Panics
    /// If `requested` does not have one entry per edge of `topo` (a caller bug).
    pub fn from_requested(topo: &Topology, requested: &[f64]) -> (Self, Vec<Warning>) {
        assert_eq!(requested.len(), topo.edge_count(), "one h per welded edge");
        let mut ignored: Vec<(EdgeKind, usize, EdgeId)> = Vec::new();
        let widths = requested
            .iter()
            .enumerate()
            .map(|(e, &h)| {
                let edge = EdgeId(e as u32);
                let kind = topo.edge_kind(edge);
                if h > 0.0 && kind != EdgeKind::Interior {
                    match ignored.iter_mut().find(|(k, _, _)| *k == kind) {
                        Some(entry) => entry.1 += 1,
                        None => ignored.push((kind, 1, edge)),
                    }
                }
                Self::of_edge(kind, h)
            })
            .collect();
        let warnings = ignored
            .into_iter()
            .map(|(kind, edges, first)| Warning::BlendIgnored { kind, edges, first })
            .collect();
        (EffectiveH(widths), warnings)
    }

    /// h = 0 on every edge of `topo` (plain PN triangles).
    pub fn zero(topo: &Topology) -> Self {
        EffectiveH(vec![0.0; topo.edge_count()])
    }

    /// Whether edge `e` is blended (its width is above 0).
    pub fn blends(&self, e: EdgeId) -> bool {
        self.0[e.0 as usize] > 0.0
    }
}

impl Deref for EffectiveH {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::mesh::TriMesh;

    /// A tetrahedron's four faces (six interior edges) plus one loose triangle (three boundary
    /// edges) and a zero-area sliver on the loose triangle's first edge.
    fn mixed() -> Topology {
        let p = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(5.0, 0.0, 0.0),
            DVec3::new(6.0, 0.0, 0.0),
            DVec3::new(5.0, 1.0, 0.0),
            DVec3::new(7.0, 0.0, 0.0),
        ];
        Topology::build(&TriMesh {
            positions: p.to_vec(),
            normals: vec![DVec3::Z; p.len()],
            triangles: vec![
                [0, 2, 1],
                [0, 1, 3],
                [1, 2, 3],
                [2, 0, 3],
                [4, 5, 6],
                [4, 5, 7],
            ],
        })
    }

    #[test]
    fn the_rule_zeroes_every_edge_the_surface_cannot_blend() {
        let topo = mixed();
        let asked = vec![0.2; topo.edge_count()];
        let (h, warnings) = EffectiveH::from_requested(&topo, &asked);
        for (e, edge) in topo.edges().enumerate() {
            let want = if edge.kind == EdgeKind::Interior {
                0.2
            } else {
                0.0
            };
            assert_eq!(h[e], want, "edge {e} ({:?})", edge.kind);
        }
        assert_eq!(
            topo.edges()
                .filter(|e| e.kind == EdgeKind::Interior)
                .count(),
            6
        );
        let kinds: Vec<(EdgeKind, usize)> = warnings
            .iter()
            .map(|w| match w {
                Warning::BlendIgnored { kind, edges, .. } => (*kind, *edges),
                other => panic!("unexpected {other:?}"),
            })
            .collect();
        // Sliver 4-5-7 is degenerate: its three edges (one shared with 4-5-6) are degenerate,
        // the other two of 4-5-6 are boundary.
        assert_eq!(
            kinds,
            vec![(EdgeKind::Degenerate, 3), (EdgeKind::Boundary, 2)]
        );
    }

    #[test]
    fn the_rule_clamps_to_the_bound_and_sends_nan_and_negatives_to_zero() {
        let topo = mixed();
        let interior = topo
            .edges()
            .position(|e| e.kind == EdgeKind::Interior)
            .expect("an interior edge");
        for (asked, want) in [
            (f64::NAN, 0.0),
            (-0.1, 0.0),
            (f64::NEG_INFINITY, 0.0),
            (f64::INFINITY, H_MAX),
            (0.3536, H_MAX),
            (H_MAX, H_MAX),
            (0.1, 0.1),
        ] {
            let mut h = vec![0.0; topo.edge_count()];
            h[interior] = asked;
            let (effective, _) = EffectiveH::from_requested(&topo, &h);
            assert_eq!(effective[interior], want, "asked {asked}");
            assert!(EffectiveH::new(&topo, effective.to_vec()).is_ok());
        }
    }

    #[test]
    fn checked_construction_rejects_what_the_rule_would_change() {
        let topo = mixed();
        let n = topo.edge_count();
        let interior = topo
            .edges()
            .position(|e| e.kind == EdgeKind::Interior)
            .unwrap();
        let boundary = topo
            .edges()
            .position(|e| e.kind == EdgeKind::Boundary)
            .unwrap();
        let degenerate = topo
            .edges()
            .position(|e| e.kind == EdgeKind::Degenerate)
            .unwrap();
        let with = |e: usize, h: f64| {
            let mut v = vec![0.0; n];
            v[e] = h;
            EffectiveH::new(&topo, v)
        };
        assert!(with(interior, H_MAX).is_ok());
        for bad in [f64::NAN, -1e-9, H_MAX * (1.0 + f64::EPSILON), f64::INFINITY] {
            assert!(
                matches!(with(interior, bad), Err(InvalidH::OutOfRange { .. })),
                "{bad}"
            );
        }
        assert!(matches!(
            with(boundary, 0.1),
            Err(InvalidH::Unblended {
                kind: EdgeKind::Boundary,
                ..
            })
        ));
        assert!(matches!(
            with(degenerate, 0.1),
            Err(InvalidH::Unblended {
                kind: EdgeKind::Degenerate,
                ..
            })
        ));
        assert_eq!(
            EffectiveH::new(&topo, vec![0.0; n + 1]),
            Err(InvalidH::Count {
                widths: n + 1,
                edges: n
            })
        );
        assert!(EffectiveH::zero(&topo).iter().all(|&h| h == 0.0));
    }
}
