//! The G² surface built for one pass in triangle order (`G2Surface::with_nets_for_one_pass`):
//! its patches are made on demand where every edge curve is its own triangle's and neighbours
//! lie near in triangle order, stored otherwise, and every point it gives has the bits of the
//! surface that stores them, in whatever order the triangles are asked for.

use g2tess::mesh::TriMesh;
use g2tess::sharpness::EffectiveH;
use g2tess::surface::{G2Surface, LatticePart, Nets, Profile, Surface, SurfacePoint};
use g2tess::topology::Topology;

use crate::support::{
    h_all, icosahedron, split_normals, subdivide, torus, torus_rings, widths, Lcg,
};

fn bits(points: &[SurfacePoint]) -> Vec<[u64; 6]> {
    points
        .iter()
        .map(|p| {
            let [a, b, c] = p.position.to_array().map(f64::to_bits);
            let [d, e, f] = p.normal.to_array().map(f64::to_bits);
            [a, b, c, d, e, f]
        })
        .collect()
}

/// Every lattice part at levels 2, 3 and 5 (each triangle's owned edges and interior in one
/// call, as the tessellator asks), then random points, first in triangle order and then
/// backwards (where the memo of rebuilt nets keeps little): the same bits from both surfaces.
fn assert_same_points(name: &str, mesh: &TriMesh, topo: &Topology, h: &EffectiveH) -> usize {
    let mut on_demand = 0;
    for nets in [Nets::Round, Nets::Paper] {
        let stored = G2Surface::with_nets(mesh, topo, h, Profile::C2, nets);
        let one_pass = G2Surface::with_nets_for_one_pass(mesh, topo, h, Profile::C2, nets);
        if one_pass.heap_bytes() == 0 {
            on_demand += 1;
        }
        let tris = mesh.triangles.len();
        let order: Vec<usize> = (0..tris).chain((0..tris).rev()).collect();
        let mut rng = Lcg(7);
        for (i, &t) in order.iter().enumerate() {
            let level = [2, 3, 5][i % 3];
            let parts = [
                (level, LatticePart::Edge(0)),
                (level, LatticePart::Edge(1)),
                (level, LatticePart::Edge(2)),
                (level, LatticePart::Interior),
            ];
            let (mut a, mut b) = (Vec::new(), Vec::new());
            stored.evaluate_lattice_parts(t, &parts, &mut a);
            one_pass.evaluate_lattice_parts(t, &parts, &mut b);
            assert_eq!(
                bits(&a),
                bits(&b),
                "{name} {nets:?} triangle {t} level {level}"
            );
            let barys: Vec<[f64; 3]> = (0..4).map(|_| rng.bary(0.0)).collect();
            let (mut a, mut b) = (Vec::new(), Vec::new());
            stored.evaluate_points(t, &barys, &mut a);
            one_pass.evaluate_points(t, &barys, &mut b);
            assert_eq!(bits(&a), bits(&b), "{name} {nets:?} triangle {t} points");
        }
    }
    on_demand
}

fn sphere(subdivisions: usize) -> TriMesh {
    (0..subdivisions).fold(icosahedron(), |mesh, _| subdivide(&mesh))
}

#[test]
fn smooth_meshes_make_their_patches_on_demand_with_the_same_points() {
    let meshes = [
        ("icosphere", sphere(2)),
        ("torus", torus(12)),
        // Every edge blended between split normals: the neighbours' normals are read.
        ("split normals", split_normals(&sphere(2), 0.3)),
    ];
    for (name, mesh) in meshes {
        let topo = Topology::build(&mesh);
        let h = h_all(&topo, 0.212);
        assert_eq!(assert_same_points(name, &mesh, &topo, &h), 2, "{name}");
    }
}

#[test]
fn an_unblended_edge_between_two_triangles_keeps_the_patches_stored() {
    // One crease (h = 0 on one interior edge) on split normals: its triangles share one
    // averaged curve, which only stored patches hold.
    let mesh = split_normals(&sphere(2), 0.3);
    let topo = Topology::build(&mesh);
    let mut asked = vec![0.212; topo.edge_count()];
    let crease = (0..topo.edge_count())
        .find(|&e| topo.edge_uses(g2tess::topology::EdgeId(e as u32)).len() == 2)
        .expect("an interior edge");
    asked[crease] = 0.0;
    let h = widths(&topo, &asked);
    assert_eq!(assert_same_points("crease", &mesh, &topo, &h), 0);
}

#[test]
fn neighbours_far_apart_in_triangle_order_keep_the_patches_stored() {
    // A torus of 3,200 triangles in grid order (neighbours at most two rows apart but for the
    // seam row's, 1.7% of the pairs), then in a random order: most neighbours thousands of
    // triangles apart, where the memo would lose their nets and each would be made again.
    let mesh = torus_rings(40, 40, 0.4);
    let mut rng = Lcg(11);
    let mut triangles = mesh.triangles.clone();
    for i in (1..triangles.len()).rev() {
        let j = (rng.next() * (i + 1) as f64) as usize;
        triangles.swap(i, j);
    }
    let shuffled = TriMesh {
        triangles,
        ..mesh.clone()
    };
    for (name, mesh, made) in [("in order", &mesh, 2), ("shuffled", &shuffled, 0)] {
        let topo = Topology::build(mesh);
        let h = h_all(&topo, 0.212);
        assert_eq!(assert_same_points(name, mesh, &topo, &h), made, "{name}");
    }
}
