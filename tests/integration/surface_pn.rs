//! The G² surface's fixed points: h = 0 is the PN triangle of Eq. 1–2, flat stays flat, corners
//! are the input vertices, lattice evaluation equals point evaluation, and reordering or
//! flipping triangles does not move the surface.

use crate::support::*;
use g2tess::mesh::TriMesh;
use g2tess::sharpness::EffectiveH;
use g2tess::surface::{
    lattice_bary, G2Surface, LatticePart, Nets, PnSurface, Profile, Surface, H_MAX,
};
use g2tess::topology::Topology;
use glam::DVec3;

/// Eq. 1–2 written out directly (Vlachos et al. 2001, E over all six edge points), and the
/// largest distance of a control point from its place in the flat net, which the surface stores
/// in `f32`.
fn pn_reference_net(p: [DVec3; 3], n: [DVec3; 3], [u, v, w]: [f64; 3]) -> (DVec3, f64) {
    let b = |i: usize, j: usize| (2.0 * p[i] + p[j] - (p[j] - p[i]).dot(n[i]) * n[i]) / 3.0;
    let (b210, b120, b021, b012, b102, b201) =
        (b(0, 1), b(1, 0), b(1, 2), b(2, 1), b(2, 0), b(0, 2));
    let e = (b210 + b120 + b021 + b012 + b102 + b201) / 6.0;
    let b111 = e + (e - (p[0] + p[1] + p[2]) / 3.0) / 2.0;
    let flat = |i: usize, j: usize| (2.0 * p[i] + p[j]) / 3.0;
    let offset = [(0, 1), (1, 0), (1, 2), (2, 1), (2, 0), (0, 2)]
        .iter()
        .map(|&(i, j)| (b(i, j) - flat(i, j)).length())
        .fold((b111 - (p[0] + p[1] + p[2]) / 3.0).length(), f64::max);
    let point = p[0] * u * u * u
        + p[1] * v * v * v
        + p[2] * w * w * w
        + 3.0 * (b210 * u * u * v + b120 * u * v * v + b021 * v * v * w)
        + 3.0 * (b012 * v * w * w + b102 * u * w * w + b201 * u * u * w)
        + 6.0 * b111 * u * v * w;
    (point, offset)
}

/// On the paper's nets; on the round ones `PnSurface` is the G² surface at h = 0 just the same.
#[test]
fn h_zero_is_the_pn_triangle() {
    let mut rng = Lcg(3);
    for (name, mesh) in smooth_meshes() {
        let topo = Topology::build(&mesh);
        let h0 = h_all(&topo, 0.0);
        let pn = PnSurface::with_nets(&mesh, &topo, Nets::Paper);
        let g2 = G2Surface::with_nets(&mesh, &topo, &h0, Profile::Paper, Nets::Paper);
        let (pn_round, g2_round) = (
            PnSurface::new(&mesh, &topo),
            G2Surface::new(&mesh, &topo, &h0, Profile::Paper),
        );
        for t in 0..mesh.triangles.len() {
            let c = mesh.triangles[t].map(|i| i as usize);
            for _ in 0..10 {
                let l = rng.bary(0.0);
                let (want, offset) =
                    pn_reference_net(c.map(|i| mesh.positions[i]), c.map(|i| mesh.normals[i]), l);
                let got = pn.evaluate(t, l);
                // Same sums in another order: a few ulps of |p| ≤ 2; and each control point's
                // offset from the flat net is stored in f32, to 2⁻²⁴ of it per coordinate
                // (√3 of that as a vector, at most, weights summing to 1).
                let bound = 1e-14 + 3f64.sqrt() * 2f64.powi(-24) * offset;
                let err = (got.position - want).length();
                assert!(err < bound, "{name} tri {t}: {err:e} > {bound:e}");
                assert_eq!(
                    got,
                    g2.evaluate(t, l),
                    "{name}: PnSurface is the G² surface at h = 0"
                );
                assert_eq!(pn_round.evaluate(t, l), g2_round.evaluate(t, l), "{name}");
            }
        }
    }
}

#[test]
fn flat_mesh_with_equal_normals_stays_exactly_flat() {
    let mesh = flat_grid(4);
    let topo = Topology::build(&mesh);
    let mut rng = Lcg(5);
    let h: Vec<f64> = topo.edges().map(|_| rng.next() * H_MAX).collect();
    for profile in [Profile::Paper, Profile::C2] {
        let h_s = widths(&topo, &h);
        let s = G2Surface::new(&mesh, &topo, &h_s, profile);
        for t in 0..mesh.triangles.len() {
            let mut out = Vec::new();
            s.evaluate_lattice(t, 9, &mut out);
            for _ in 0..20 {
                out.push(s.evaluate(t, rng.bary(0.0)));
            }
            for p in out {
                assert_eq!(p.position.z, 0.0);
                assert_eq!(p.normal, DVec3::Z);
            }
        }
    }
}

#[test]
fn corners_are_the_input_vertices_bit_for_bit() {
    let mesh = split_normals(&bumpy_sphere(), 0.5);
    let topo = Topology::build(&mesh);
    for h in [0.0, 0.212] {
        let h_s = h_all(&topo, h);
        let s = G2Surface::new(&mesh, &topo, &h_s, Profile::C2);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for c in 0..3 {
                let mut l = [0.0; 3];
                l[c] = 1.0;
                let v = tri[c] as usize;
                let p = s.evaluate(t, l);
                assert_eq!(p.position, mesh.positions[v]);
                assert_eq!(p.normal, mesh.normals[v].normalize());
            }
        }
    }
}

#[test]
fn lattice_evaluation_equals_point_evaluation() {
    let mesh = bumpy_sphere();
    let topo = Topology::build(&mesh);
    let mut rng = Lcg(11);
    let h: Vec<f64> = topo
        .edges()
        .map(|_| (rng.next() * 4.0).floor() * 0.1)
        .collect();
    let h_s = widths(&topo, &h);
    let s = G2Surface::new(&mesh, &topo, &h_s, Profile::C2);
    for level in [1, 4, 7] {
        for t in 0..mesh.triangles.len() {
            let mut out = Vec::new();
            s.evaluate_lattice(t, level, &mut out);
            let mut idx = 0;
            for j in 0..=level {
                for i in 0..=level - j {
                    assert_eq!(out[idx], s.evaluate(t, lattice_bary(level, i, j)));
                    idx += 1;
                }
            }
            assert_eq!(idx, out.len());
        }
    }
}

#[test]
fn reordering_corners_or_flipping_triangles_does_not_move_the_surface() {
    let mut rng = Lcg(13);
    for (name, mesh) in [
        ("bumpy_sphere", bumpy_sphere()),
        ("split", split_normals(&bumpy_sphere(), 0.5)),
    ] {
        let topo = Topology::build(&mesh);
        let scale = mesh
            .positions
            .iter()
            .map(|p| p.length())
            .fold(0.0, f64::max);
        for (reversed, seed) in [(0.0, 1), (0.3, 2)] {
            let re = reorder(&mesh, reversed, seed);
            let topo2 = Topology::build(&re.mesh);
            assert_eq!(topo2.edge_count(), topo.edge_count());
            // The same h per welded edge: look each edge up by its end positions.
            let h_of = |topo: &Topology, e: &g2tess::topology::Edge| {
                let [a, b] = e.verts.map(|v| topo.welded_positions[v.0 as usize]);
                ((a.x + b.x) * 7.0 + (a.y + b.y) * 3.0 + (a.z + b.z))
                    .sin()
                    .abs()
                    * H_MAX
            };
            let h1: Vec<f64> = topo.edges().map(|e| h_of(&topo, &e)).collect();
            let h2: Vec<f64> = topo2.edges().map(|e| h_of(&topo2, &e)).collect();
            for profile in [Profile::Paper, Profile::C2] {
                let h_s1 = widths(&topo, &h1);
                let s1 = G2Surface::new(&mesh, &topo, &h_s1, profile);
                let h_s2 = widths(&topo2, &h2);
                let s2 = G2Surface::new(&re.mesh, &topo2, &h_s2, profile);
                let mut worst: f64 = 0.0;
                for t in 0..mesh.triangles.len() {
                    for _ in 0..10 {
                        let l = rng.bary(0.0);
                        let (a, b) = (s1.evaluate(t, l), s2.evaluate(t, re.bary(t, l)));
                        worst = worst.max((a.position - b.position).length() / scale);
                        assert!(a.normal.dot(b.normal) > 1.0 - 1e-12, "{name} normal");
                    }
                }
                println!("{name} reversed={reversed} {profile:?}: max relative position change {worst:.1e}");
                assert!(worst < 1e-12, "{name} reversed={reversed}: {worst}");
            }
        }
    }
}

#[test]
fn h_is_clamped_and_unblendable_edges_are_reported() {
    let mesh = height_field(3);
    let topo = Topology::build(&mesh);
    let (h, ignored) = EffectiveH::from_requested(&topo, &vec![5.0; topo.edge_count()]);
    let boundary = topo
        .edges()
        .filter(|e| e.kind == g2tess::topology::EdgeKind::Boundary)
        .count();
    for (e, &h) in topo.edges().zip(h.iter()) {
        let want = if e.kind == g2tess::topology::EdgeKind::Interior {
            H_MAX
        } else {
            0.0
        };
        assert_eq!(h, want);
    }
    assert!(matches!(
        ignored[..],
        [g2tess::topology::Warning::BlendIgnored { kind: g2tess::topology::EdgeKind::Boundary, edges, .. }] if edges == boundary
    ));
    // The widest blend the surface is ever given: every point is finite and unit-normal.
    let s = G2Surface::new(&mesh, &topo, &h, Profile::C2);
    for t in 0..mesh.triangles.len() {
        let p = s.evaluate(t, [0.2, 0.3, 0.5]);
        assert!(p.position.is_finite() && (p.normal.length() - 1.0).abs() < 1e-12);
    }
}

/// Edge parts sum only the seven control points of their edge's rows, on both nets, and
/// rebuild only the neighbour points an edge's composition reads: each edge part, alone and
/// with the others, must still equal `evaluate` at its points (which sums all ten of every
/// net and composes the whole neighbour net) bit for bit, on split normals (edge points kept
/// as stored) and with some edges at h = 0 (plain points on an edge), in every corner order.
#[test]
fn edge_parts_equal_point_evaluation_bit_for_bit() {
    random_h_surfaces(&mut Lcg(29), |s, mesh, _| {
        for level in [2, 3, 6] {
            for t in 0..mesh.triangles.len() {
                let parts: Vec<_> = (0..3).map(|k| (level, LatticePart::Edge(k))).collect();
                let mut together = Vec::new();
                s.evaluate_lattice_parts(t, &parts, &mut together);
                let mut want = Vec::new();
                for &(_, part) in &parts {
                    let mut alone = Vec::new();
                    s.evaluate_lattice_part(t, level, part, &mut alone);
                    let points: Vec<_> = part
                        .points(level)
                        .iter()
                        .map(|&(i, j)| s.evaluate(t, lattice_bary(level, i, j)))
                        .collect();
                    assert_eq!(alone, points, "triangle {t} level {level} {part:?}");
                    want.extend(points);
                }
                assert_eq!(together, want, "triangle {t} level {level}");
            }
        }
    });
}

/// Runs `body` on each G² surface the bit-for-bit tests compare two paths on: the bumpy
/// sphere as it is and with split normals, reordered, each edge a random h in {0, 0.1, 0.2,
/// 0.3} (some unblended), with both profiles.
fn random_h_surfaces(rng: &mut Lcg, mut body: impl FnMut(&G2Surface, &TriMesh, &mut Lcg)) {
    for mesh in [
        bumpy_sphere(),
        reorder(&split_normals(&bumpy_sphere(), 0.5), 0.4, 7).mesh,
    ] {
        let topo = Topology::build(&mesh);
        let h: Vec<f64> = topo
            .edges()
            .map(|_| (rng.next() * 4.0).floor() * 0.1)
            .collect();
        let h_s = widths(&topo, &h);
        for profile in [Profile::C2, Profile::Paper] {
            body(&G2Surface::new(&mesh, &topo, &h_s, profile), &mesh, rng);
        }
    }
}

/// The bits of a point's coordinates (`==` on floats would take `-0` for `+0`).
fn bits(p: DVec3) -> [u64; 3] {
    p.to_array().map(f64::to_bits)
}

/// The check at twice a pattern's resolution copies the even points of its lattice from the
/// lattice at the pattern's own level: the lattice it gives must be the one evaluated whole,
/// bit for bit (every position, the corners' and interior points' normals), on split normals
/// and with some edges at h = 0; a coarse lattice of the wrong level is not read.
#[test]
fn a_lattice_refined_from_half_its_level_equals_it_bit_for_bit() {
    random_h_surfaces(&mut Lcg(47), |s, mesh, _| {
        for t in 0..mesh.triangles.len() {
            for level in [4, 6, 12, 26] {
                let (mut direct, mut coarse, mut refined) = (Vec::new(), Vec::new(), Vec::new());
                s.evaluate_lattice_positions_on_edges(t, level, &mut direct);
                s.evaluate_lattice_positions_on_edges(t, level / 2, &mut coarse);
                s.evaluate_lattice_positions_on_edges_refining(t, level, &coarse, &mut refined);
                assert_eq!(direct.len(), refined.len());
                for (index, (d, r)) in direct.iter().zip(&refined).enumerate() {
                    let what = format!("triangle {t} level {level} point {index}");
                    assert_eq!(bits(r.position), bits(d.position), "{what}");
                    assert_eq!(bits(r.normal), bits(d.normal), "{what}");
                }
                let mut unread = Vec::new();
                s.evaluate_lattice_positions_on_edges_refining(t, level + 1, &coarse, &mut unread);
                direct.clear();
                s.evaluate_lattice_positions_on_edges(t, level + 1, &mut direct);
                assert_eq!(unread, direct, "triangle {t} level {}", level + 1);
            }
        }
    });
}

/// The chord error checks read positions alone where they read no normal (a lattice's edge
/// points, the vertices of the triangles they measure), summed without the tangents: every
/// position, and every normal they do read, must be what the whole evaluation gives, bit for
/// bit (the held interiors and the edges the output writes are those points), on split
/// normals and with some edges at h = 0, at levels with one-lane and two-lane blocks on the
/// edges. The edge points' normals are left out (zero), so the cheaper sums did run.
#[test]
fn positions_alone_equal_the_whole_evaluation_bit_for_bit() {
    random_h_surfaces(&mut Lcg(31), |s, mesh, rng| {
        for t in 0..mesh.triangles.len() {
            for level in [2, 3, 6, 7, 13] {
                let (mut whole, mut fast) = (Vec::new(), Vec::new());
                s.evaluate_lattice(t, level, &mut whole);
                s.evaluate_lattice_positions_on_edges(t, level, &mut fast);
                assert_eq!(whole.len(), fast.len());
                let mut index = 0;
                for j in 0..=level {
                    for i in 0..=level - j {
                        let (w, f) = (whole[index], fast[index]);
                        let what = format!("triangle {t} level {level} ({i}, {j})");
                        assert_eq!(bits(f.position), bits(w.position), "{what}");
                        let corner = [i, j, level - i - j].iter().filter(|&&x| x == 0).count() == 2;
                        let edge = !corner && (i == 0 || j == 0 || i + j == level);
                        if edge {
                            assert_eq!(f.normal, DVec3::ZERO, "{what}: the cheap sums ran");
                        } else {
                            assert_eq!(bits(f.normal), bits(w.normal), "{what}");
                        }
                        index += 1;
                    }
                }
            }
            let mut barys = vec![[1.0, 0.0, 0.0], [0.0, 0.5, 0.5], [0.25, 0.0, 0.75]];
            for _ in 0..12 {
                let (u, v) = (rng.next(), rng.next());
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                barys.push([1.0 - u - v, u, v]);
            }
            // A set asked for on every triangle, whose weights the surface keeps, and sets
            // of their own.
            let fixed: Vec<[f64; 3]> = (0..40)
                .map(|x| {
                    let (u, v) = (f64::from(x % 7) / 9.0, f64::from(x / 7) / 8.0);
                    [1.0 - u - v, u, v]
                })
                .collect();
            // Sets of the sizes the whole-pattern measurements ask for, kept in the stores of
            // larger sets, and one too large to keep, evaluated point by point (on a few
            // triangles: thousands of points each).
            let large = |n: u32| -> Vec<[f64; 3]> {
                (0..n)
                    .map(|x| {
                        let (u, v) = (f64::from(x % 97) / 200.0, f64::from(x / 97) / 200.0);
                        [1.0 - u - v, u, v]
                    })
                    .collect()
            };
            let larger: Vec<Vec<[f64; 3]>> = if t < 3 {
                [700, 700, 3000, 3000, 7300].map(large).into()
            } else {
                Vec::new()
            };
            for (set, first) in [(&fixed, 12), (&fixed, 12), (&barys, 0), (&barys, 5)]
                .into_iter()
                .chain([(&barys, barys.len())])
                .chain(larger.iter().map(|set| (set, 0)))
            {
                let barys = set;
                let (mut whole, mut fast) = (Vec::new(), Vec::new());
                s.evaluate_points(t, barys, &mut whole);
                s.evaluate_points_positions_first(t, barys, first, &mut fast);
                assert_eq!(whole.len(), fast.len());
                for (x, (w, f)) in whole.iter().zip(&fast).enumerate() {
                    assert_eq!(bits(f.position), bits(w.position), "triangle {t} point {x}");
                    if x >= first {
                        assert_eq!(bits(f.normal), bits(w.normal), "triangle {t} point {x}");
                    }
                }
            }
        }
    });
}

/// The early-exit chord check and the fill choice ask for a triangle's points on demand, piece
/// by piece in an order of their own: each piece must be those points evaluated whole, bit for
/// bit, whatever was asked for before it, on split normals and with some edges at h = 0,
/// through the PN surface's forwarding too, with one call of `drive`.
#[test]
fn points_on_demand_equal_the_whole_evaluation() {
    let check = |s: &dyn Surface, t: usize, barys: &[[f64; 3]]| {
        let mut whole = Vec::new();
        s.evaluate_points(t, barys, &mut whole);
        // On demand, in pieces of 1, 2, 3 … points asked for from the last piece to the first:
        // each point as the whole evaluation gives it, whatever was asked for before it.
        let mut pieces = Vec::new();
        let mut start = 0;
        while start < barys.len() {
            let end = (start + pieces.len() + 1).min(barys.len());
            pieces.push(start..end);
            start = end;
        }
        let (mut drives, mut on_demand) = (0, vec![None; barys.len()]);
        s.evaluate_points_on_demand(t, &mut |evaluate| {
            drives += 1;
            let mut out = Vec::new();
            for piece in pieces.iter().rev() {
                out.clear();
                evaluate(&barys[piece.clone()], &mut out);
                assert_eq!(out.len(), piece.len(), "triangle {t} piece {piece:?}");
                for (x, p) in piece.clone().zip(&out) {
                    on_demand[x] = Some(*p);
                }
            }
        });
        assert_eq!(drives, 1, "triangle {t}");
        for (x, (h, w)) in on_demand.iter().zip(&whole).enumerate() {
            let h = h.expect("every point asked for");
            assert_eq!(bits(h.position), bits(w.position), "triangle {t} point {x}");
            assert_eq!(bits(h.normal), bits(w.normal), "triangle {t} point {x}");
        }
    };
    let random_barys = |rng: &mut Lcg| -> Vec<[f64; 3]> {
        let corner_and_edge = [[0.0, 1.0, 0.0], [0.5, 0.0, 0.5]];
        corner_and_edge
            .into_iter()
            .chain((0..40).map(|_| rng.bary(0.0)))
            .collect()
    };
    random_h_surfaces(&mut Lcg(53), |s, mesh, rng| {
        for t in 0..mesh.triangles.len() {
            check(s, t, &random_barys(rng));
        }
    });
    let mesh = split_normals(&bumpy_sphere(), 0.5);
    let topo = Topology::build(&mesh);
    let pn = PnSurface::new(&mesh, &topo);
    let mut rng = Lcg(59);
    for t in 0..mesh.triangles.len() {
        check(&pn, t, &random_barys(&mut rng));
    }
}
