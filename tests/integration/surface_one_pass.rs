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

/// Share of the interior edges of `mesh` whose two triangles lie 512 or more apart in triangle
/// order (half the memo of rebuilt nets).
fn far_share(topo: &Topology) -> f64 {
    let (mut far, mut pairs) = (0, 0);
    for t in 0..topo.tri_edges.len() {
        for k in 0..3 {
            if let Some(n) = topo.neighbour(g2tess::topology::TriId(t as u32), k) {
                pairs += 1;
                if (n.tri.0 as usize).abs_diff(t) >= 512 {
                    far += 1;
                }
            }
        }
    }
    far as f64 / pairs as f64
}

#[test]
fn a_few_far_neighbours_still_make_the_patches_on_demand() {
    // The grid-order torus with 60 pairs of triangles swapped: about one neighbour pair in 17
    // lies far apart (the bench's 10k icosphere has one in 30, across the faces of its
    // icosahedron), where the memo loses a net and it is made again; on-demand patches still
    // take fewer instructions there than stored ones (see `FAR_SHARE`).
    let mesh = torus_rings(40, 40, 0.4);
    let mut rng = Lcg(5);
    let mut triangles = mesh.triangles.clone();
    for _ in 0..60 {
        let i = (rng.next() * triangles.len() as f64) as usize;
        let j = (rng.next() * triangles.len() as f64) as usize;
        triangles.swap(i, j);
    }
    let mesh = TriMesh { triangles, ..mesh };
    let topo = Topology::build(&mesh);
    let share = far_share(&topo);
    assert!(share > 1.0 / 32.0 && share < 1.0 / 8.0, "far share {share}");
    let h = h_all(&topo, 0.212);
    assert_eq!(assert_same_points("partly shuffled", &mesh, &topo, &h), 2);
}
