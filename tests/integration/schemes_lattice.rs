//! The hybrid and Coons schemes' lattice paths (weights computed once per lattice and shared by
//! triangles; whole lattices, scattered points and the parts the tessellator asks for) give
//! exactly what `evaluate` gives at the same points, bit for bit, whatever the
//! corner order, reading of the papers, shape parameters or normal method.

use crate::support::*;
use g2tess::mesh::TriMesh;
use g2tess::surface::coons::patch::Definition2;
use g2tess::surface::coons::{Constituents, CoonsSurface, NormalMethod};
use g2tess::surface::hybrid::{HybridSurface, PaperReading};
use g2tess::surface::{
    lattice_bary, G2Surface, LatticePart, PnSurface, Profile, SchemeParams, Surface,
};
use g2tess::topology::Topology;

/// Whole lattices and scattered points of every triangle against `evaluate`, bit for bit.
fn assert_lattice_is_pointwise(name: &str, s: &dyn Surface, triangles: usize) {
    let mut rng = Lcg(5);
    for level in [1, 2, 5, 16] {
        for t in 0..triangles {
            let mut out = Vec::new();
            s.evaluate_lattice(t, level, &mut out);
            let mut idx = 0;
            for j in 0..=level {
                for i in 0..=level - j {
                    let want = s.evaluate(t, lattice_bary(level, i, j));
                    assert_eq!(
                        out[idx], want,
                        "{name}: triangle {t} level {level} ({i}, {j})"
                    );
                    idx += 1;
                }
            }
            assert_eq!(idx, out.len());

            let points: Vec<(u32, u32)> = (0..7)
                .map(|_| {
                    let j = (rng.next() * (level + 1) as f64) as u32 % (level + 1);
                    let i = (rng.next() * (level + 1 - j) as f64) as u32 % (level + 1 - j);
                    (i, j)
                })
                .collect();
            let mut some = Vec::new();
            s.evaluate_lattice_points(t, level, &points, &mut some);
            for (p, &(i, j)) in some.iter().zip(&points) {
                assert_eq!(*p, s.evaluate(t, lattice_bary(level, i, j)), "{name}");
            }

            // The parts the tessellator asks for: interior and each edge.
            for part in [
                LatticePart::Interior,
                LatticePart::Edge(0),
                LatticePart::Edge(1),
                LatticePart::Edge(2),
            ] {
                let mut got = Vec::new();
                s.evaluate_lattice_part(t, level, part, &mut got);
                let want: Vec<_> = part
                    .points(level)
                    .iter()
                    .map(|&(i, j)| s.evaluate(t, lattice_bary(level, i, j)))
                    .collect();
                assert_eq!(got, want, "{name}: triangle {t} level {level} {part:?}");
            }
        }
    }
}

/// The bumpy sphere with every corner order and both windings, and the height field (with
/// boundary creases).
fn meshes() -> Vec<(&'static str, TriMesh)> {
    vec![
        ("bumpy reordered", reorder(&bumpy_sphere(), 0.5, 3).mesh),
        ("height field", height_field(5)),
    ]
}

#[test]
fn hybrid_lattice_equals_evaluate_bit_for_bit() {
    for (name, mesh) in meshes() {
        let topo = Topology::build(&mesh);
        let h = h_all(&topo, 0.2);
        for reading in [PaperReading::Corrected, PaperReading::PrintedStrayK] {
            let s = HybridSurface::with_reading(&mesh, &topo, &h, reading);
            assert_lattice_is_pointwise(
                &format!("hybrid {reading:?} {name}"),
                &s,
                mesh.triangles.len(),
            );
        }
    }
}

#[test]
fn coons_lattice_equals_evaluate_bit_for_bit() {
    for (name, mesh) in meshes() {
        let topo = Topology::build(&mesh);
        let h = h_all(&topo, 0.2);
        let d = SchemeParams::default();
        let variants = [
            ("default", d),
            (
                "pn average",
                SchemeParams {
                    constituents: Constituents::PnAverage,
                    ..d
                },
            ),
            ("λ 0.3", SchemeParams { lambda: 0.3, ..d }),
            // Faired λ are mostly unique per triangle (computed point by point), some shared.
            ("faired", SchemeParams { fair: true, ..d }),
        ];
        for (label, params) in variants {
            let s = CoonsSurface::new(&mesh, &topo, &h, &params);
            let n = mesh.triangles.len();
            assert_lattice_is_pointwise(&format!("coons {label} {name}"), &s, n);
            if label == "default" {
                for def in [Definition2::PrintedQOutside, Definition2::PrintedCorrection] {
                    let printed = s.clone().with_definition(def);
                    assert_lattice_is_pointwise(&format!("coons {def:?} {name}"), &printed, n);
                }
                let fd = s.clone().with_normals(NormalMethod::FiniteDifference);
                assert_lattice_is_pointwise(&format!("coons differences {name}"), &fd, n);
            }
        }
    }
}

/// Several parts of one triangle asked for in one call (as the tessellator asks for a
/// triangle's owned edges and its interior) against each part asked for alone, bit for bit:
/// the G² surface sets the triangle up once for all of them and composes each neighbour's net
/// once for every part that blends across its edge, so a part read with another part's
/// neighbour, or in another part's slots, shows here.
#[test]
fn lattice_parts_together_equal_each_part_alone_bit_for_bit() {
    let orders: [&[LatticePart]; 4] = [
        &[
            LatticePart::Edge(0),
            LatticePart::Edge(1),
            LatticePart::Edge(2),
            LatticePart::Interior,
        ],
        &[
            LatticePart::Interior,
            LatticePart::Edge(2),
            LatticePart::Edge(0),
        ],
        &[LatticePart::Edge(1), LatticePart::All, LatticePart::Edge(1)],
        &[LatticePart::Edge(2)],
    ];
    for (name, mesh) in meshes() {
        let topo = Topology::build(&mesh);
        let h = h_all(&topo, 0.3);
        let surfaces: Vec<(String, Box<dyn Surface>)> = vec![
            (
                "g2 c2".into(),
                Box::new(G2Surface::new(&mesh, &topo, &h, Profile::C2)),
            ),
            (
                "g2 paper".into(),
                Box::new(G2Surface::new(&mesh, &topo, &h, Profile::Paper)),
            ),
            ("pn".into(), Box::new(PnSurface::new(&mesh, &topo))),
            (
                "hybrid".into(),
                Box::new(HybridSurface::with_reading(
                    &mesh,
                    &topo,
                    &h,
                    PaperReading::Corrected,
                )),
            ),
        ];
        for (label, s) in &surfaces {
            for level in [1, 2, 3, 5, 16] {
                for t in 0..mesh.triangles.len() {
                    for (o, order) in orders.iter().enumerate() {
                        // Mixed levels too, as the per-edge-count path has them.
                        let parts: Vec<(u32, LatticePart)> = order
                            .iter()
                            .enumerate()
                            .map(|(i, &p)| (if i == 1 { level + 1 } else { level }, p))
                            .collect();
                        let mut together = Vec::new();
                        s.evaluate_lattice_parts(t, &parts, &mut together);
                        let mut apart = Vec::new();
                        for &(l, p) in &parts {
                            s.evaluate_lattice_part(t, l, p, &mut apart);
                        }
                        assert!(!apart.is_empty() || level == 1);
                        assert_eq!(
                            together, apart,
                            "{label} {name}: triangle {t} level {level} order {o}"
                        );
                    }
                }
            }
        }
    }
}
