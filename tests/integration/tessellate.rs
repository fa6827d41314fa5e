//! Uniform tessellation on generated meshes: counts, watertightness, identity at level 1,
//! seams kept where the input had them, and agreement with the surface.

// One group is one output primitive; a single range is the common case, not a mistake.
#![allow(clippy::single_range_in_vec_init)]

use crate::support::*;
use g2tess::mesh::TriMesh;
use g2tess::sharpness::EffectiveH;
use g2tess::surface::{G2Surface, Profile, Surface};
use g2tess::tessellate::{tessellate, DenseMesh, VertexSource};
use g2tess::topology::Topology;
use glam::DVec3;

fn run(mesh: &TriMesh, h: f64, level: u32) -> (Topology, EffectiveH, DenseMesh) {
    let topo = Topology::build(mesh);
    let hs = h_all(&topo, h);
    let surface = G2Surface::new(mesh, &topo, &hs, Profile::C2);
    let dense = tessellate(
        mesh,
        &topo,
        &hs,
        &surface,
        level,
        &[0..mesh.triangles.len()],
    )
    .pop()
    .unwrap();
    (topo, hs, dense)
}

fn input_boundary_edges(mesh: &TriMesh) -> usize {
    let positions: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|p| p.as_vec3().to_array())
        .collect();
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    boundary_edges(&positions, &indices)
}

#[test]
fn every_triangle_becomes_level_squared_triangles() {
    let mesh = icosahedron();
    for level in 1..=6 {
        let (_, _, dense) = run(&mesh, 0.2, level);
        assert_eq!(
            dense.indices.len() / 3,
            mesh.triangles.len() * (level * level) as usize
        );
        // A closed welded mesh shares every edge and corner sample: V - E + F = 2.
        let v = dense.positions.len() as i64;
        let f = (dense.indices.len() / 3) as i64;
        assert_eq!(v - 3 * f / 2 + f, 2, "level {level}");
    }
}

#[test]
fn output_is_watertight_wherever_the_input_was() {
    let cases: Vec<(&str, TriMesh)> = vec![
        ("icosahedron", icosahedron()),
        ("cube", cube()),
        ("bumpy", bumpy_sphere()),
        ("height field", height_field(5)),
        ("split normals", split_normals(&bumpy_sphere(), 0.3)),
        ("shuffled soup", reorder(&bumpy_sphere(), 0.3, 7).mesh),
    ];
    for (name, mesh) in &cases {
        let before = input_boundary_edges(mesh);
        for h in [0.0, 0.2] {
            for level in [2, 5] {
                let (_, _, dense) = run(mesh, h, level);
                let after = boundary_edges(&dense.positions, &dense.indices);
                assert_eq!(
                    after,
                    before * level as usize,
                    "{name}, h = {h}, level {level}: new boundary edges"
                );
            }
        }
    }
}

#[test]
fn level_one_at_h_zero_is_the_identity() {
    let mesh = bumpy_sphere();
    let (_, _, dense) = run(&mesh, 0.0, 1);
    assert_eq!(dense.positions.len(), mesh.positions.len());
    let mut expected: Vec<[[u32; 3]; 3]> = mesh
        .triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                mesh.positions[v as usize]
                    .as_vec3()
                    .to_array()
                    .map(f32::to_bits)
            })
        })
        .collect();
    let mut got: Vec<[[u32; 3]; 3]> = dense
        .indices
        .chunks(3)
        .map(|t| [0, 1, 2].map(|k| dense.positions[t[k] as usize].map(f32::to_bits)))
        .collect();
    expected.sort();
    got.sort();
    assert_eq!(got, expected);
}

#[test]
fn seams_in_the_input_stay_seams_with_identical_positions() {
    // The split-normal soup has every vertex split; the output must split every shared edge
    // sample too (one copy per side) while the positions agree bit for bit.
    let mesh = split_normals(&icosahedron(), 0.3);
    let level = 4;
    let (_, _, dense) = run(&mesh, 0.15, level);
    let per_tri = ((level + 1) * (level + 2) / 2) as usize;
    assert_eq!(dense.positions.len(), mesh.triangles.len() * per_tri);
    assert_eq!(boundary_edges(&dense.positions, &dense.indices), 0);
}

#[test]
fn vertices_lie_on_the_surface_with_its_normals() {
    let mesh = bumpy_sphere();
    let (topo, hs, dense) = run(&mesh, 0.2, 3);
    let surface = G2Surface::new(&mesh, &topo, &hs, Profile::C2);
    let scale = mean_edge(&mesh);
    for (i, source) in dense.sources.iter().enumerate() {
        let bary = source.bary().map(f64::from);
        let p = surface.evaluate(source.tri as usize, bary);
        let got = DVec3::from(dense.positions[i].map(f64::from));
        // f32 storage and the f32 barycentrics of the source bound the difference.
        assert!((got - p.position).length() < 1e-5 * scale, "vertex {i}");
        let n = DVec3::from(dense.normals[i].map(f64::from));
        assert!((n.length() - 1.0).abs() < 1e-6);
        assert!(n.dot(p.normal) > 1.0 - 1e-6, "vertex {i}");
    }
}

#[test]
fn groups_split_the_output_but_not_the_surface() {
    // Two groups over one closed mesh: each output is open, and together they close.
    let mesh = icosahedron();
    let topo = Topology::build(&mesh);
    let hs = h_all(&topo, 0.2);
    let surface = G2Surface::new(&mesh, &topo, &hs, Profile::C2);
    let half = mesh.triangles.len() / 2;
    let parts = tessellate(
        &mesh,
        &topo,
        &hs,
        &surface,
        4,
        &[0..half, half..mesh.triangles.len()],
    );
    let mut positions = parts[0].positions.clone();
    let mut indices = parts[0].indices.clone();
    let offset = positions.len() as u32;
    positions.extend_from_slice(&parts[1].positions);
    indices.extend(parts[1].indices.iter().map(|i| i + offset));
    assert!(boundary_edges(&parts[0].positions, &parts[0].indices) > 0);
    assert_eq!(boundary_edges(&positions, &indices), 0);
}

/// A surface whose two sides of an edge disagree in the last digits, as any scheme may after
/// rounding: the tessellator alone must keep the output watertight.
struct Jittered<'a>(&'a dyn Surface);

impl Surface for Jittered<'_> {
    fn evaluate(&self, tri: usize, bary: [f64; 3]) -> g2tess::surface::SurfacePoint {
        let mut p = self.0.evaluate(tri, bary);
        p.position += DVec3::splat(1e-6 * (tri % 7) as f64);
        p
    }
}

#[test]
fn shared_samples_are_evaluated_once_even_if_the_sides_disagree() {
    for mesh in [bumpy_sphere(), split_normals(&bumpy_sphere(), 0.3)] {
        let topo = Topology::build(&mesh);
        let hs = h_all(&topo, 0.1);
        let inner = G2Surface::new(&mesh, &topo, &hs, Profile::C2);
        let surface = Jittered(&inner);
        let dense = tessellate(&mesh, &topo, &hs, &surface, 3, &[0..mesh.triangles.len()])
            .pop()
            .unwrap();
        assert_eq!(boundary_edges(&dense.positions, &dense.indices), 0);
    }
}

#[test]
fn corner_tests_on_lattice_coordinates_agree_with_the_barycentrics() {
    // The integer forms replace comparisons on the float barycentrics: they must pick the same
    // corner (largest coordinate, ties to the lowest) at every point of every level.
    for n in 1..=g2tess::options::MAX_LEVEL {
        for j in 0..=n {
            for i in 0..=n - j {
                let s = VertexSource::lattice(7, n, i, j);
                let b = s.bary();
                let mut largest = 0;
                for c in 1..3 {
                    if b[c] > b[largest] {
                        largest = c;
                    }
                }
                assert_eq!(s.nearest_corner(), largest, "level {n}, ({i}, {j})");
                assert_eq!(
                    s.corner(),
                    b.iter().position(|&x| x == 1.0),
                    "level {n}, ({i}, {j})"
                );
            }
        }
    }
}

/// The vertices are evaluated first and the triangles and vertex sources written from the
/// numbering alone, so the surface can be freed in between (the pipeline does, to keep the
/// surface and the output's index buffer out of memory at the same time): the result is the
/// same mesh as with the surface alive throughout, seams, creases and groups included.
#[test]
fn the_surface_can_be_freed_before_the_triangles_are_written() {
    use g2tess::tessellate::tessellate_vertices;
    for mesh in [icosahedron(), split_normals(&bumpy_sphere(), 0.3)] {
        let topo = Topology::build(&mesh);
        // Every third welded edge a crease: its two sides get their own samples.
        let requested: Vec<f64> = (0..topo.edge_count())
            .map(|e| if e % 3 == 0 { 0.0 } else { 0.2 })
            .collect();
        let hs = widths(&topo, &requested);
        let third = mesh.triangles.len() / 3;
        let groups = [0..third, third..mesh.triangles.len()];
        for level in 1..=5 {
            let surface = G2Surface::new(&mesh, &topo, &hs, Profile::C2);
            let whole = tessellate(&mesh, &topo, &hs, &surface, level, &groups);
            let vertices = tessellate_vertices(&mesh, &topo, &hs, &surface, level, &groups);
            drop(surface);
            let finished = vertices.finish();
            assert!(finished == whole, "level {level}");
            assert_eq!(finished.len(), 2);
            for dense in &finished {
                assert_eq!(dense.sources.len(), dense.positions.len(), "level {level}");
            }
        }
    }
}

/// A dense mesh's positions and normals as bits, its sources and its indices.
type Bits<'a> = (Vec<[u32; 3]>, Vec<[u32; 3]>, &'a [VertexSource], &'a [u32]);

/// Every output value of `dense` as bits, so that `-0.0` and `0.0` differ.
fn bits(dense: &DenseMesh) -> Bits<'_> {
    let b = |v: &[[f32; 3]]| v.iter().map(|p| p.map(f32::to_bits)).collect();
    (
        b(&dense.positions),
        b(&dense.normals),
        &dense.sources,
        &dense.indices,
    )
}

#[test]
fn level_one_on_the_flat_surface_is_every_schemes_level_one_bit_for_bit() {
    use g2tess::surface::{build_surface, FlatSurface, Scheme, SchemeParams};
    // Shared normals, split normals on every edge (a seam everywhere), a cube whose input
    // normals are not the faces', and signed zeros in the coordinates.
    let mut signed = icosahedron();
    for p in &mut signed.positions {
        *p = p.map(|x| if x.abs() < 1e-12 { -0.0 } else { x });
    }
    let meshes = [
        bumpy_sphere(),
        split_normals(&bumpy_sphere(), 0.3),
        cube(),
        signed,
    ];
    for (m, mesh) in meshes.iter().enumerate() {
        let topo = Topology::build(mesh);
        // Every third welded edge a crease, where the output is split.
        let requested: Vec<f64> = (0..topo.edge_count())
            .map(|e| if e % 3 == 0 { 0.0 } else { 0.2 })
            .collect();
        let hs = widths(&topo, &requested);
        let half = mesh.triangles.len() / 2;
        let groups = [0..half, half..mesh.triangles.len()];
        let flat = FlatSurface::new(mesh);
        let on_flat = tessellate(mesh, &topo, &hs, &flat, 1, &groups);
        for scheme in Scheme::ALL {
            let params = SchemeParams::default();
            let (surface, _) = build_surface(scheme, mesh, &topo, &hs, &params);
            let on_scheme = tessellate(mesh, &topo, &hs, surface.as_ref(), 1, &groups);
            for (a, b) in on_flat.iter().zip(&on_scheme) {
                assert_eq!(bits(a), bits(b), "mesh {m}, scheme {scheme}");
            }
            // The corners are the input's: the positions bit for bit, the normals normalized.
            for (g, dense) in groups.iter().zip(&on_scheme) {
                for (t, tri) in dense
                    .indices
                    .chunks_exact(3)
                    .zip(&mesh.triangles[g.clone()])
                {
                    for (&out, &v) in t.iter().zip(tri) {
                        let v = v as usize;
                        let want = mesh.positions[v].as_vec3().to_array().map(f32::to_bits);
                        assert_eq!(dense.positions[out as usize].map(f32::to_bits), want);
                        let n = mesh.normals[v].normalize().as_vec3().to_array();
                        assert_eq!(dense.normals[out as usize], n);
                    }
                }
            }
        }
    }
}
