//! Continuity of the hybrid (seed 001) and Coons (seed 002) schemes across mesh edges, on the
//! generated meshes, their shuffled and reversed copies and split normals: no gap, and normal
//! jumps at rounding level where plain PN jumps by degrees.

use crate::support::*;
use g2tess::continuity::{self, ContinuityReport, Sampling};
use g2tess::mesh::TriMesh;
use g2tess::surface::coons::{Constituents, CoonsSurface, NormalMethod};
use g2tess::surface::hybrid::HybridSurface;
use g2tess::surface::scheme::Warning;
use g2tess::surface::{Nets, PnSurface, SchemeParams, Surface};
use g2tess::topology::Topology;

/// Positions are sums of ten terms of size ~|p| ≤ 2L: a gap above 1e-13·L is not rounding.
const GAP_TOL: f64 = 1e-13;
/// Largest normal jump across edges, in degrees, away from the corners.
const HYBRID_TOL: f64 = 1e-5;
const COONS_TOL: f64 = 1e-4;

/// 21 samples per edge, leaving out 2% at each end (the patches are G¹ at the vertices only in
/// the limit); no curvature.
fn sampling() -> Sampling {
    Sampling {
        eps: vec![],
        per_edge: 21,
        margin: 0.02,
    }
}

/// The generated meshes with shared normals, a shuffled copy of each with a third of its
/// triangles reversed, and hard edges everywhere.
fn meshes() -> Vec<(String, TriMesh)> {
    let mut out: Vec<(String, TriMesh)> = Vec::new();
    for (i, (name, mesh)) in smooth_meshes().into_iter().enumerate() {
        out.push((
            format!("{name} shuffled"),
            reorder(&mesh, 0.33, 11 + i as u64).mesh,
        ));
        out.push((name.to_string(), mesh));
    }
    out.push(("bumpy split".into(), split_normals(&bumpy_sphere(), 0.5)));
    out
}

/// No edge fell back to a crease for want of a projection plane.
fn no_plane_fallback(w: &[Warning]) -> bool {
    !w.iter()
        .any(|w| matches!(w, Warning::NoProjectionPlane { .. }))
}

fn measure(s: &dyn Surface, topo: &Topology) -> ContinuityReport {
    let r = continuity::measure(s, topo, &sampling());
    assert!(r.edges > 0);
    r
}

fn coons(mesh: &TriMesh, topo: &Topology, c: Constituents, n: NormalMethod) -> CoonsSurface {
    let params = SchemeParams {
        constituents: c,
        ..SchemeParams::default()
    };
    CoonsSurface::new(mesh, topo, &h_all(topo, 0.2), &params).with_normals(n)
}

#[test]
fn hybrid_is_g1_across_every_smooth_edge() {
    for (name, mesh) in meshes() {
        let topo = Topology::build(&mesh);
        let s = HybridSurface::new(&mesh, &topo, &h_all(&topo, 0.2));
        assert!(
            no_plane_fallback(s.warnings()),
            "{name}: {:?}",
            s.warnings()
        );
        let r = measure(&s, &topo);
        println!(
            "hybrid {name:22} gap {:.1e} L, normal jump max {:.1e}° p95 {:.1e}°",
            r.gap.max, r.normal_jump_deg.max, r.normal_jump_deg.p95
        );
        assert!(r.gap.max <= GAP_TOL, "{name}: {r:?}");
        assert!(r.normal_jump_deg.max < HYBRID_TOL, "{name}: {r:?}");
    }
}

#[test]
fn coons_is_g1_across_every_smooth_edge_with_either_constituents_and_normals() {
    for (name, mesh) in meshes() {
        let topo = Topology::build(&mesh);
        for c in [Constituents::PnAverage, Constituents::FoleyOpitz] {
            for n in [NormalMethod::Analytic, NormalMethod::FiniteDifference] {
                let s = coons(&mesh, &topo, c, n);
                assert!(
                    no_plane_fallback(s.warnings()),
                    "{name}: {:?}",
                    s.warnings()
                );
                let r = measure(&s, &topo);
                println!(
                    "coons {c:?} {n:?} {name:22} gap {:.1e} L, normal jump max {:.1e}° p95 {:.1e}°",
                    r.gap.max, r.normal_jump_deg.max, r.normal_jump_deg.p95
                );
                assert!(r.gap.max <= GAP_TOL, "{name} {c:?} {n:?}: {r:?}");
                assert!(
                    r.normal_jump_deg.max < COONS_TOL,
                    "{name} {c:?} {n:?}: {r:?}"
                );
            }
        }
    }
}

/// PN is only G0: its normals jump across edges, by more than a degree on the paper's nets and
/// still by more than a tenth of one on the round nets (whose patches lie far closer to round
/// shapes, so that their cross-edge tangents disagree less).
#[test]
fn plain_pn_jumps_by_more_than_a_degree_on_the_same_meshes() {
    for (name, mesh) in meshes() {
        let topo = Topology::build(&mesh);
        for (nets, least) in [(Nets::Paper, 1.0), (Nets::Round, 0.1)] {
            let r = measure(&PnSurface::with_nets(&mesh, &topo, nets), &topo);
            println!(
                "pn {nets:?} {name:22} normal jump max {:.2}°",
                r.normal_jump_deg.max
            );
            assert!(r.gap.max <= GAP_TOL, "{name}: {r:?}");
            assert!(r.normal_jump_deg.max > least, "{name} {nets:?}: {r:?}");
        }
    }
}

#[test]
fn coons_stays_g1_for_any_lambda_and_with_fairing() {
    let mesh = bumpy_sphere();
    let topo = Topology::build(&mesh);
    let h = h_all(&topo, 0.2);
    for (lambda, fair) in [(0.2, false), (0.8, false), (0.5, true)] {
        let params = SchemeParams {
            lambda,
            fair,
            ..SchemeParams::default()
        };
        let s = CoonsSurface::new(&mesh, &topo, &h, &params);
        if fair {
            let range = CoonsSurface::FAIR_RANGE;
            assert!(s
                .lambda()
                .iter()
                .flatten()
                .all(|l| *l >= range.0 && *l <= range.1));
            assert!(
                s.lambda().iter().flatten().any(|l| *l != 0.5),
                "fairing moved λ"
            );
        }
        let r = measure(&s, &topo);
        println!(
            "coons λ={lambda} fair={fair}: gap {:.1e} L, normal jump max {:.1e}°",
            r.gap.max, r.normal_jump_deg.max
        );
        assert!(
            r.gap.max <= GAP_TOL && r.normal_jump_deg.max < COONS_TOL,
            "{r:?}"
        );
    }
}
