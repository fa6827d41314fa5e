//! Continuity of the G² surface, measured on generated meshes: G0, G1 and G2 across edges for
//! h > 0 and their failure for plain PN (h = 0), the paper's profile against the C² profile
//! inside the blending regions, and analytic against finite-difference normals.

use crate::support::*;
use g2tess::continuity::{self, angle_deg, normal_curvature, Sampling};
use g2tess::surface::coons::{Constituents, CoonsSurface};
use g2tess::surface::hybrid::HybridSurface;
use g2tess::surface::{lattice_index, G2Surface, PnSurface, Profile, SchemeParams, Surface, H_MAX};
use g2tess::topology::{EdgeKind, Topology};

/// Positions are sums of ten terms of size ~|p| ≤ 2L: a gap above 1e-13·L is not rounding.
const GAP_TOL: f64 = 1e-13;

fn report(mesh: &g2tess::mesh::TriMesh, h: f64, profile: Profile) -> continuity::ContinuityReport {
    let topo = Topology::build(mesh);
    let h_s = h_all(&topo, h);
    let s = G2Surface::new(mesh, &topo, &h_s, profile);
    continuity::measure(&s, &topo, &Sampling::default())
}

/// Below this (× L) a curvature jump is rounding: normals carry ~1e-16 error, differenced over
/// `2·step = eps/2`, so at eps = 1e-4 the estimate is good to ~1e-11; 1e-9 leaves a margin.
const CURVATURE_FLOOR: f64 = 1e-9;

/// Ratio of the curvature jump (max) from one eps to the next, ten times smaller. A jump that is
/// already below [`CURVATURE_FLOOR`] counts as falling by 10 (symmetric meshes such as the
/// icosahedron have no jump at all to measure).
fn decay(r: &continuity::ContinuityReport) -> [f64; 2] {
    let j: Vec<f64> = r.curvature_jump.iter().map(|c| c.jump.max).collect();
    let ratio = |a: f64, b: f64| if a <= CURVATURE_FLOOR { 10.0 } else { a / b };
    [ratio(j[0], j[1]), ratio(j[1], j[2])]
}

#[test]
fn blended_surface_is_g0_g1_g2_across_edges() {
    for (name, mesh) in smooth_meshes() {
        for h in [0.106, 0.212, H_MAX] {
            for profile in [Profile::Paper, Profile::C2] {
                let r = report(&mesh, h, profile);
                assert!(r.edges > 0);
                let ctx = format!("{name} h={h} {profile:?}: {r:?}");
                assert!(r.gap.max <= GAP_TOL, "G0 {ctx}");
                assert!(r.normal_jump_deg.max < 1e-6, "G1 {ctx}");
                let [a, b] = decay(&r);
                let jumps: Vec<f64> = r.curvature_jump.iter().map(|c| c.jump.max).collect();
                println!(
                    "{name:12} h={h:.3} {profile:5?}: normal jump {:.1e}°, curvature jump x L {}",
                    r.normal_jump_deg.max,
                    jumps
                        .iter()
                        .map(|j| format!("{j:.2e}"))
                        .collect::<Vec<_>>()
                        .join(" ")
                );
                assert!(a >= 5.0 && b >= 5.0, "G2 decay {a:.2} {b:.2} {ctx}");
            }
        }
    }
}

#[test]
fn plain_pn_is_g0_but_not_g1_or_g2() {
    let mesh = bumpy_sphere();
    let topo = Topology::build(&mesh);
    let r = continuity::measure(&PnSurface::new(&mesh, &topo), &topo, &Sampling::default());
    assert!(r.gap.max <= GAP_TOL, "{r:?}");
    assert!(r.normal_jump_deg.max > 1.0, "{r:?}");
    let [a, b] = decay(&r);
    assert!(a < 2.0 && b < 2.0, "curvature jump must not fall: {r:?}");
}

#[test]
fn split_normals_stay_watertight_at_h_zero_and_close_for_h_above() {
    let mesh = split_normals(&bumpy_sphere(), 0.5);
    let topo = Topology::build(&mesh);
    assert!(topo
        .edges()
        .all(|e| e.kind == EdgeKind::Interior && e.split_normals));
    // h = 0: the edge curves are averaged (PN-AEN); positions agree, normals do not.
    let r = continuity::measure(&PnSurface::new(&mesh, &topo), &topo, &Sampling::default());
    assert!(r.gap.max <= GAP_TOL, "{r:?}");
    assert!(r.normal_jump_deg.max > 1.0, "{r:?}");
    // h > 0: the blend closes the crease and is G2 again.
    for profile in [Profile::Paper, Profile::C2] {
        let r = report(&mesh, 0.212, profile);
        assert!(
            r.gap.max <= GAP_TOL && r.normal_jump_deg.max < 1e-6,
            "{r:?}"
        );
        let [a, b] = decay(&r);
        assert!(a >= 5.0 && b >= 5.0, "{a} {b} {r:?}");
    }
}

/// Two triangles f = ABC and g = BAD in the plane z = 0 meeting at the blended edge AB, with
/// split normals there that lean 78° from the plane and turn by half a turn from one side to
/// the other (f: A (1, −1, 0.2), B (−1, −1, 0.2); g: A (−1, 1, 0.2), B (1, 1, 0.2)); C and D
/// carry +z. The surface stands near a right angle to those normals along AB.
fn steep_split_edge() -> g2tess::mesh::TriMesh {
    let v = |x: f64, y: f64, z: f64| glam::DVec3::new(x, y, z);
    let (a, b, c, d) = (
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.5, 0.9, 0.0),
        v(0.5, -0.9, 0.0),
    );
    let n = |x: f64, y: f64, z: f64| v(x, y, z).normalize();
    g2tess::mesh::TriMesh {
        positions: vec![a, b, c, b, a, d],
        normals: vec![
            n(1.0, -1.0, 0.2),
            n(-1.0, -1.0, 0.2),
            n(0.0, 0.0, 1.0),
            n(1.0, 1.0, 0.2),
            n(-1.0, 1.0, 0.2),
            n(0.0, 0.0, 1.0),
        ],
        triangles: vec![[0, 1, 2], [3, 4, 5]],
    }
}

/// The side of the normal at a blended edge with split normals is chosen from the input normals
/// blended as the surface is, the same from both triangles: no 180° turn along the edge.
///
/// The mesh is one where each triangle's own interpolated normals pick opposite sides along the
/// edge (checked here: the rule that used them turned the normal by 180° on this edge). The
/// positions meet (G0) and the tangent planes agree (G1), as on any blended edge, so the jump
/// left is the tangent planes' rounding: tangents are sums of 20 terms each within 1e-16 of
/// their size, a few 1e-14 rad, well below the 1e-6° of the G1 checks above.
#[test]
fn split_normals_at_a_steep_blended_edge_keep_one_side() {
    let mesh = steep_split_edge();
    let topo = Topology::build(&mesh);
    let edge = topo.edges().find(|e| e.tris.len() == 2).expect("AB");
    assert!(edge.kind == EdgeKind::Interior && edge.split_normals);
    let interpolated =
        |c: [usize; 2], x: f64| (1.0 - x) * mesh.normals[c[0]] + x * mesh.normals[c[1]];
    for profile in [Profile::Paper, Profile::C2] {
        for h in [0.106, 0.212, H_MAX] {
            let h_s = h_all(&topo, h);
            let s = G2Surface::new(&mesh, &topo, &h_s, profile);
            // Point by point, nine samples along the edge.
            let r = continuity::measure(&s, &topo, &Sampling::default());
            assert!(r.gap.max <= GAP_TOL, "{h} {profile:?}: {r:?}");
            assert!(r.normal_jump_deg.max < 1e-6, "{h} {profile:?}: {r:?}");
            // The lattices: f's edge point (i, 0) is g's (n − i, 0).
            let n = 16;
            let (mut on_f, mut on_g) = (Vec::new(), Vec::new());
            s.evaluate_lattice(0, n, &mut on_f);
            s.evaluate_lattice(1, n, &mut on_g);
            let mut opposite = 0;
            for i in 1..n {
                let x = f64::from(i) / f64::from(n);
                let p = on_f[lattice_index(n, i, 0)];
                let q = on_g[lattice_index(n, n - i, 0)];
                assert!((p.position - q.position).length() <= GAP_TOL, "{i}");
                let jump = angle_deg(p.normal, q.normal);
                assert!(jump < 1e-6, "{h} {profile:?} {i}/{n}: {jump}°");
                // A (f 0, g 4) at 1 − x, B (f 1, g 3) at x.
                let own = [interpolated([0, 1], x), interpolated([4, 3], x)];
                if (p.normal.dot(own[0]) < 0.0) != (p.normal.dot(own[1]) < 0.0) {
                    opposite += 1;
                }
            }
            assert!(opposite > 0, "{h} {profile:?}: no point of the defect");
        }
    }
}

/// Two triangles f = ABC and g = BAD meeting at the smooth edge AB on the x axis, with split
/// normals there that lie 89° from the plane z = 0 and turn by half a turn from one side to the
/// other (f: A (1, −1, 0.02), B (−1, −1, 0.02); g: A (−1, 1, 0.02), B (1, 1, 0.02)), so that
/// both ends' mean normals are +z. C and D rise and fall out of that plane (z = ±0.45 at
/// y = ±0.9) and carry the normal of the plane z = y/2 through them: the hybrid and Coons
/// surfaces tilt across the middle of the edge, further than the own normals lean out of it.
fn steep_split_edge_tilted() -> g2tess::mesh::TriMesh {
    let v = |x: f64, y: f64, z: f64| glam::DVec3::new(x, y, z);
    let n = |x: f64, y: f64, z: f64| v(x, y, z).normalize();
    let (a, b, c, d) = (
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.5, 0.9, 0.45),
        v(0.5, -0.9, -0.45),
    );
    let e = 0.02;
    g2tess::mesh::TriMesh {
        positions: vec![a, b, c, b, a, d],
        normals: vec![
            n(1.0, -1.0, e),
            n(-1.0, -1.0, e),
            n(0.0, -0.5, 1.0),
            n(1.0, 1.0, e),
            n(-1.0, 1.0, e),
            n(0.0, -0.5, 1.0),
        ],
        triangles: vec![[0, 1, 2], [3, 4, 5]],
    }
}

/// The hybrid (seed 001) and Coons (seed 002, both constituents) schemes on a smooth edge with
/// split normals: the side of the normal follows the mean end normals the edge's net is built
/// from, the same from both triangles, so there is no 180° turn along the edge where the own
/// interpolated normals of the two triangles pick opposite sides (checked here: the rule that
/// used them turned the normal by 180° on this edge, at 18 to 20 of the 20 points). Both
/// schemes are G¹ across the edge, so the jump left is the tangent planes' rounding, well below
/// 1e-6°. Each side is evaluated alone, at lattice points and at points off any lattice.
#[test]
fn split_normals_at_a_steep_smooth_edge_keep_one_side_in_hybrid_and_coons() {
    let mesh = steep_split_edge_tilted();
    let topo = Topology::build(&mesh);
    let e = topo.edges().position(|e| e.tris.len() == 2).expect("AB");
    let h_s = h_all(&topo, 0.212);
    let interpolated =
        |c: [usize; 2], x: f64| (1.0 - x) * mesh.normals[c[0]] + x * mesh.normals[c[1]];
    let coons = |constituents| {
        let params = SchemeParams {
            constituents,
            ..SchemeParams::default()
        };
        CoonsSurface::new(&mesh, &topo, &h_s, &params)
    };
    let hybrid = HybridSurface::new(&mesh, &topo, &h_s);
    let (fo, avg) = (
        coons(Constituents::FoleyOpitz),
        coons(Constituents::PnAverage),
    );
    assert!(hybrid.smooth_edges()[e] && fo.smooth_edges()[e] && avg.smooth_edges()[e]);
    let schemes: [(&str, &dyn Surface); 3] = [
        ("hybrid", &hybrid),
        ("coons", &fo),
        ("coons pn-average", &avg),
    ];
    for (name, s) in schemes {
        let r = continuity::measure(s, &topo, &Sampling::default());
        assert!(r.gap.max <= GAP_TOL, "{name}: {r:?}");
        assert!(r.normal_jump_deg.max < 1e-6, "{name}: {r:?}");
        // f = ABC holds A, B in corners 0, 1; g = BAD in corners 1, 0. Lattice points i/16 and
        // points off the lattice, each side evaluated alone at the same barycentrics.
        let mut opposite = 0;
        let xs = (1..16)
            .map(|i| f64::from(i) / 16.0)
            .chain([0.01, 0.3, 1.0 / 3.0, 0.77, 0.99]);
        for x in xs {
            let p = s.evaluate(0, [1.0 - x, x, 0.0]);
            let q = s.evaluate(1, [x, 1.0 - x, 0.0]);
            assert!((p.position - q.position).length() <= GAP_TOL, "{name} {x}");
            let jump = angle_deg(p.normal, q.normal);
            assert!(jump < 1e-6, "{name} {x}: {jump}°");
            let own = [interpolated([0, 1], x), interpolated([4, 3], x)];
            if (p.normal.dot(own[0]) < 0.0) != (p.normal.dot(own[1]) < 0.0) {
                opposite += 1;
            }
        }
        assert!(opposite > 0, "{name}: no point of the defect");
        let n = 16;
        let (mut on_f, mut on_g) = (Vec::new(), Vec::new());
        s.evaluate_lattice(0, n, &mut on_f);
        s.evaluate_lattice(1, n, &mut on_g);
        for i in 1..n {
            let (p, q) = (
                on_f[lattice_index(n, i, 0)],
                on_g[lattice_index(n, n - i, 0)],
            );
            let jump = angle_deg(p.normal, q.normal);
            assert!(jump < 1e-6, "{name} lattice {i}/{n}: {jump}°");
        }
    }
}

/// Curvature jump × L along the edge direction across the four profile switch lines of every
/// interior edge, halfway into the blending region, at distance `eps` either side of the line.
fn switch_line_jump(mesh: &g2tess::mesh::TriMesh, h: f64, profile: Profile, eps: f64) -> f64 {
    let topo = Topology::build(mesh);
    let h_s = h_all(&topo, h);
    let s = G2Surface::new(mesh, &topo, &h_s, profile);
    let l = continuity::mean_edge_length(&topo);
    let mut worst: f64 = 0.0;
    for e in topo.edges().filter(|e| e.kind == EdgeKind::Interior) {
        let (t, k) = e.tris[0].at();
        let (a, b) = ((k + 2) % 3, (k + 1) % 3);
        for sw in Profile::switch_points(h) {
            // s runs from corner b (s = 0) to corner a (s = √2); r(sw) is the same for both
            // profiles at the switch points.
            let sn = sw.min(std::f64::consts::SQRT_2 - sw);
            let r = profile.radius(sn, h).0;
            let at = |s: f64| {
                let mut l = [0.0; 3];
                l[k] = 0.5 * r / 1.5f64.sqrt();
                l[a] = (s * std::f64::consts::SQRT_2 - l[k]) / 2.0;
                l[b] = 1.0 - l[a] - l[k];
                l
            };
            let mut dir = [0.0; 3];
            dir[a] = std::f64::consts::FRAC_1_SQRT_2;
            dir[b] = -std::f64::consts::FRAC_1_SQRT_2;
            let k1 = normal_curvature(&s, t, at(sw - eps), dir, eps / 4.0);
            let k2 = normal_curvature(&s, t, at(sw + eps), dir, eps / 4.0);
            worst = worst.max((k1 - k2).abs() * l);
        }
    }
    worst
}

#[test]
fn c2_profile_removes_the_curvature_jump_inside_regions_and_paper_profile_does_not() {
    for (name, mesh) in [("cube", cube()), ("bumpy_sphere", bumpy_sphere())] {
        for h in [0.106, 0.212] {
            let jumps = |p| [1e-2, 1e-3, 1e-4].map(|e| switch_line_jump(&mesh, h, p, e));
            let paper = jumps(Profile::Paper);
            let c2 = jumps(Profile::C2);
            println!("{name} h={h}: paper {paper:?}  c2 {c2:?}");
            assert!(
                paper[1] / paper[2] < 2.0 && paper[2] > 1e-3,
                "paper {name} {h}: {paper:?}"
            );
            assert!(
                c2[0] / c2[1] >= 5.0 && c2[1] / c2[2] >= 5.0,
                "c2 {name} {h}: {c2:?}"
            );
        }
    }
}

#[test]
fn analytic_normals_match_central_differences() {
    let mut rng = Lcg(7);
    let fd_step = 1e-6;
    let mut worst: f64 = 0.0;
    for (name, mesh) in smooth_meshes()
        .into_iter()
        .chain([("split", split_normals(&bumpy_sphere(), 0.5))])
    {
        let topo = Topology::build(&mesh);
        for h in [0.0, 0.106, 0.212, H_MAX] {
            for profile in [Profile::Paper, Profile::C2] {
                let h_s = h_all(&topo, h);
                let s = G2Surface::new(&mesh, &topo, &h_s, profile);
                for _ in 0..200 {
                    let t = (rng.next() * mesh.triangles.len() as f64) as usize;
                    let l = rng.bary(0.01);
                    let p = |du: f64, dv: f64| {
                        s.evaluate(t, [l[0] + du, l[1] + dv, l[2] - du - dv])
                            .position
                    };
                    let su = (p(fd_step, 0.0) - p(-fd_step, 0.0)) / (2.0 * fd_step);
                    let sv = (p(0.0, fd_step) - p(0.0, -fd_step)) / (2.0 * fd_step);
                    let n = s.evaluate(t, l).normal;
                    let fd = su.cross(sv).normalize();
                    let angle = angle_deg(n, fd).min(angle_deg(n, -fd));
                    worst = worst.max(angle);
                    assert!(
                        angle < 1e-5,
                        "{name} h={h} {profile:?} tri {t} at {l:?}: {angle}°"
                    );
                }
            }
        }
    }
    println!("worst analytic vs FD normal angle: {worst:.2e}°");
}
