//! Per-edge sharpness and the fallbacks of the hybrid and Coons schemes: h = 0 is a watertight
//! crease where each side keeps its own tangent plane, h > 0 is G¹, and boundary, non-manifold,
//! degenerate and folded edges fall back to creases with a warning.

use crate::schemes_support::*;
use crate::support::*;
use g2tess::continuity::{self, angle_deg, Sampling};
use g2tess::mesh::TriMesh;
use g2tess::sharpness::EffectiveH;
use g2tess::surface::coons::Constituents;
use g2tess::surface::hybrid::HybridSurface;
use g2tess::surface::scheme::Warning;
use g2tess::surface::{build_surface, Scheme, SchemeParams};
use g2tess::topology::{self, EdgeId, EdgeKind, Topology};
use glam::DVec3;

const GAP_TOL: f64 = 1e-13;

/// The two G¹ schemes, Coons with both edge surfaces.
fn schemes() -> Vec<(&'static str, Scheme, SchemeParams)> {
    let fo = SchemeParams {
        constituents: Constituents::FoleyOpitz,
        ..SchemeParams::default()
    };
    let pnavg = SchemeParams {
        constituents: Constituents::PnAverage,
        ..SchemeParams::default()
    };
    vec![
        ("hybrid", Scheme::Hybrid, SchemeParams::default()),
        ("coons pnavg", Scheme::Coons, pnavg),
        ("coons fo", Scheme::Coons, fo),
    ]
}

fn sampling() -> Sampling {
    Sampling {
        eps: vec![],
        per_edge: 21,
        margin: 0.02,
    }
}

#[test]
fn h_zero_is_a_watertight_crease_in_every_scheme() {
    for (mesh_name, mesh) in [
        ("bumpy", bumpy_sphere()),
        ("bumpy split", split_normals(&bumpy_sphere(), 0.5)),
    ] {
        let topo = Topology::build(&mesh);
        for (name, scheme, params) in schemes() {
            let h_s = h_all(&topo, 0.0);
            let (s, w) = build_surface(scheme, &mesh, &topo, &h_s, &params);
            assert!(w.is_empty(), "{w:?}");
            let r = continuity::measure(s.as_ref(), &topo, &sampling());
            println!(
                "{name} {mesh_name} h=0: gap {:.1e} L, normal jump max {:.2}°",
                r.gap.max, r.normal_jump_deg.max
            );
            assert!(r.gap.max <= GAP_TOL, "{name} {mesh_name}: {r:?}");
            assert!(r.normal_jump_deg.max > 1.0, "{name} {mesh_name}: {r:?}");
        }
    }
}

#[test]
fn each_side_keeps_its_own_tangent_plane_at_a_crease() {
    // Hard edges everywhere: along each edge, close to a corner, the normal is that side's own
    // input normal, not a shared one.
    let mesh = split_normals(&bumpy_sphere(), 0.5);
    let topo = Topology::build(&mesh);
    for (name, scheme, params) in schemes() {
        let h_s = h_all(&topo, 0.0);
        let (s, _) = build_surface(scheme, &mesh, &topo, &h_s, &params);
        let mut worst: f64 = 0.0;
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for c in 0..3 {
                let own = mesh.normals[tri[c] as usize];
                for e in [(c + 1) % 3, (c + 2) % 3] {
                    let mut l = [0.0; 3];
                    l[c] = 1.0 - 1e-6;
                    l[e] = 1e-6;
                    worst = worst.max(angle_deg(s.evaluate(t, l).normal, own));
                }
            }
        }
        println!("{name}: normal 1e-6 from a crease corner vs own normal: {worst:.1e}°");
        assert!(worst < 1e-3, "{name}: {worst}°");
    }
}

#[test]
fn mixed_h_gives_g1_on_smooth_edges_and_creases_elsewhere() {
    let mesh = bumpy_sphere();
    let topo = Topology::build(&mesh);
    let mut rng = Lcg(17);
    let h: Vec<f64> = topo
        .edges()
        .map(|_| if rng.next() < 0.3 { 0.0 } else { 0.2 })
        .collect();
    let l = continuity::mean_edge_length(&topo);
    for (name, scheme, params) in schemes() {
        let h_s = widths(&topo, &h);
        let (s, _) = build_surface(scheme, &mesh, &topo, &h_s, &params);
        let jumps = edge_jumps(s.as_ref(), &topo, 11, 0.02);
        let mut crease_max: f64 = 0.0;
        for (e, gap, angle) in jumps {
            assert!(gap <= GAP_TOL * l, "{name} edge {e}: gap {gap}");
            if h[e] > 0.0 {
                assert!(angle < 1e-5, "{name} smooth edge {e}: {angle}°");
            } else {
                crease_max = crease_max.max(angle);
            }
        }
        assert!(
            crease_max > 1.0,
            "{name}: creases are creases ({crease_max}°)"
        );
    }
}

#[test]
fn boundary_edges_asked_to_blend_are_reported_once_by_the_rule_and_not_again_by_any_scheme() {
    let mesh = height_field(6);
    let topo = Topology::build(&mesh);
    let boundary = topo
        .edges()
        .filter(|e| e.kind == EdgeKind::Boundary)
        .count();
    let (h, ignored) = EffectiveH::from_requested(&topo, &vec![0.2; topo.edge_count()]);
    assert!(
        matches!(
            ignored[..],
            [topology::Warning::BlendIgnored { kind: EdgeKind::Boundary, edges, .. }] if edges == boundary
        ),
        "{ignored:?}"
    );
    for scheme in [Scheme::G2, Scheme::Hybrid, Scheme::Coons] {
        let (_, w) = build_surface(scheme, &mesh, &topo, &h, &SchemeParams::default());
        assert!(w.is_empty(), "{scheme}: {w:?}");
    }
}

#[test]
fn a_folded_edge_with_no_projection_plane_becomes_a_reported_crease() {
    let mesh = knife_edge();
    let topo = Topology::build(&mesh);
    let h = h_all(&topo, 0.2);
    let s = HybridSurface::new(&mesh, &topo, &h);
    let fold = topo
        .edges()
        .position(|e| e.kind == EdgeKind::Interior)
        .expect("the fold");
    assert!(s.warnings().contains(&Warning::NoProjectionPlane {
        edges: 1,
        first: EdgeId(fold as u32)
    }));
    assert!(!s.smooth_edges()[fold]);
    for (name, scheme, params) in schemes() {
        let (s, _) = build_surface(scheme, &mesh, &topo, &h, &params);
        for (_, gap, _) in edge_jumps(s.as_ref(), &topo, 11, 0.0) {
            assert!(gap < 1e-15, "{name}: {gap}");
        }
        for t in 0..2 {
            let p = s.evaluate(t, [0.2, 0.3, 0.5]);
            assert!(p.position.is_finite() && p.normal.is_finite(), "{name}");
        }
    }
}

#[test]
fn non_manifold_edges_are_reported_and_every_triangle_shares_the_edge_curve() {
    let mesh = non_manifold_fan();
    let topo = Topology::build(&mesh);
    let (h, ignored) = EffectiveH::from_requested(&topo, &vec![0.2; topo.edge_count()]);
    assert!(
        ignored.iter().any(|w| matches!(
            w,
            topology::Warning::BlendIgnored {
                kind: EdgeKind::NonManifold,
                edges: 1,
                ..
            }
        )),
        "{ignored:?}"
    );
    for (name, scheme, params) in schemes() {
        let (s, w) = build_surface(scheme, &mesh, &topo, &h, &params);
        assert!(w.is_empty(), "{name}: {w:?}");
        // Triangle t = [0, 1, apex]: the shared edge is opposite corner 2.
        for x in [0.1, 0.5, 0.9] {
            let p: Vec<DVec3> = (0..3)
                .map(|t| s.evaluate(t, [1.0 - x, x, 0.0]).position)
                .collect();
            assert!((p[0] - p[1]).length() < 1e-15 && (p[0] - p[2]).length() < 1e-15);
        }
    }
}

#[test]
fn degenerate_triangles_evaluate_to_finite_points() {
    let mut mesh: TriMesh = bumpy_sphere();
    // A zero-area sliver: its edges become degenerate, its neighbours creases along them.
    let (a, b) = (mesh.triangles[0][0], mesh.triangles[0][1]);
    let mid = (mesh.positions[a as usize] + mesh.positions[b as usize]) / 2.0;
    mesh.positions.push(mid);
    mesh.normals.push(mid.normalize());
    let m = mesh.positions.len() as u32 - 1;
    mesh.triangles.push([a, b, m]);
    let topo = Topology::build(&mesh);
    assert!(topo.degenerate[mesh.triangles.len() - 1]);
    let mut rng = Lcg(2);
    for (name, scheme, params) in schemes() {
        let h_s = h_all(&topo, 0.2);
        let (s, _) = build_surface(scheme, &mesh, &topo, &h_s, &params);
        for t in 0..mesh.triangles.len() {
            let p = s.evaluate(t, rng.bary(0.0));
            assert!(
                p.position.is_finite() && p.normal.is_finite(),
                "{name} tri {t}"
            );
            assert!((p.normal.length() - 1.0).abs() < 1e-12, "{name} tri {t}");
        }
    }
}
