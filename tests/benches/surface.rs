//! Evaluated surface points per second, with normals: PN triangles alone and the G² blend with
//! each profile, through cached lattice patterns and through point-by-point evaluation.
//!
//! The mesh is a 320-triangle bumpy sphere with shared normals, tessellated at level 16
//! (153 points per triangle, 48 960 per pass).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use g2tess::surface::{lattice_bary, lattice_len, G2Surface, PnSurface, Profile, Surface};
use g2tess::topology::Topology;
use std::hint::black_box;

#[path = "../integration/support.rs"]
mod support;

const LEVEL: u32 = 16;

fn bench(c: &mut Criterion) {
    let mesh = support::bumpy_sphere();
    let topo = Topology::build(&mesh);
    let h = support::h_all(&topo, 0.212);
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
