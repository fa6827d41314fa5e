//! Evaluated surface points per second, with normals: PN triangles alone and the G² blend with
//! each profile, through cached lattice patterns and through point-by-point evaluation.
//!
//! The mesh is a 320-triangle bumpy sphere with shared normals, tessellated at level 16
//! (153 points per triangle, 48 960 per pass).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use g2tess::mesh::TriMesh;
use g2tess::surface::{lattice_bary, lattice_len, G2Surface, PnSurface, Profile, Surface};
use g2tess::topology::Topology;
use glam::DVec3;
use std::hint::black_box;

const LEVEL: u32 = 16;

fn bumpy_sphere() -> TriMesh {
    let p = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<DVec3> = [
        [-1.0, p, 0.0],
        [1.0, p, 0.0],
        [-1.0, -p, 0.0],
        [1.0, -p, 0.0],
        [0.0, -1.0, p],
        [0.0, 1.0, p],
        [0.0, -1.0, -p],
        [0.0, 1.0, -p],
        [p, 0.0, -1.0],
        [p, 0.0, 1.0],
        [-p, 0.0, -1.0],
        [-p, 0.0, 1.0],
    ]
    .iter()
    .map(|v| DVec3::from_array(*v).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..2 {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::new();
        for [a, b, c] in triangles {
            let mut m = |x: u32, y: u32| {
                *mid.entry((x.min(y), x.max(y))).or_insert_with(|| {
                    positions
                        .push(((positions[x as usize] + positions[y as usize]) / 2.0).normalize());
                    positions.len() as u32 - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        triangles = next;
    }
    for q in &mut positions {
        *q *= 1.0 + 0.12 * (3.0 * q.x).sin() * (2.0 * q.y + 1.0).cos();
    }
    let mut normals = vec![DVec3::ZERO; positions.len()];
    for t in &triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        for &i in t {
            normals[i as usize] += (b - a).cross(c - a);
        }
    }
    let normals = normals.into_iter().map(DVec3::normalize).collect();
    TriMesh {
        positions,
        normals,
        triangles,
    }
}

fn bench(c: &mut Criterion) {
    let mesh = bumpy_sphere();
    let topo = Topology::build(&mesh);
    let h = vec![0.212; topo.edges.len()];
    let surfaces: Vec<(&str, Box<dyn Surface>)> = vec![
        ("pn", Box::new(PnSurface::new(&mesh, &topo))),
        (
            "g2_paper_h0.212",
            Box::new(G2Surface::new(&mesh, &topo, &h, Profile::Paper)),
        ),
        (
            "g2_c2_h0.212",
            Box::new(G2Surface::new(&mesh, &topo, &h, Profile::C2)),
        ),
    ];
    let points = mesh.triangles.len() * lattice_len(LEVEL);
    let mut group = c.benchmark_group("surface_points_with_normals");
    group.throughput(Throughput::Elements(points as u64));
    group.sample_size(20);
    let mut out = Vec::with_capacity(lattice_len(LEVEL));
    for (name, s) in &surfaces {
        group.bench_function(BenchmarkId::new("lattice", name), |b| {
            b.iter(|| {
                for t in 0..mesh.triangles.len() {
                    out.clear();
                    s.evaluate_lattice(t, LEVEL, &mut out);
                    black_box(&out);
                }
            })
        });
        group.bench_function(BenchmarkId::new("pointwise", name), |b| {
            b.iter(|| {
                for t in 0..mesh.triangles.len() {
                    for j in 0..=LEVEL {
                        for i in 0..=LEVEL - j {
                            black_box(s.evaluate(t, lattice_bary(LEVEL, i, j)));
                        }
                    }
                }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
