//! Cost per evaluated point, with its normal, of every scheme (PN, G², hybrid, Coons with
//! analytic and with finite-difference normals, Coons over Foley–Opitz edge surfaces), and the
//! cost of building each surface.
//!
//! The mesh is the 320-triangle bumpy sphere of the tests, evaluated on the level-16 lattice of
//! every triangle (153 points per triangle, 48 960 per pass): point by point through
//! `evaluate`, and whole lattices through `evaluate_lattice` as the tessellator does (Coons also
//! with per-triangle faired λ, where lattice weights are not shared).

#[path = "../integration/support.rs"]
mod support;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use g2tess::surface::coons::{Constituents, CoonsSurface, NormalMethod};
use g2tess::surface::{build_surface, lattice_bary, lattice_len, Scheme, SchemeParams, Surface};
use g2tess::topology::Topology;
use std::hint::black_box;
use std::time::Duration;

const LEVEL: u32 = 16;

fn bench(c: &mut Criterion) {
    let mesh = support::bumpy_sphere();
    let topo = Topology::build(&mesh);
    let h = support::h_all(&topo, 0.212);
    let d = SchemeParams::default();
    let fo = SchemeParams {
        constituents: Constituents::FoleyOpitz,
        ..d
    };
    let pnavg = SchemeParams {
        constituents: Constituents::PnAverage,
        ..d
    };
    let coons = CoonsSurface::new(&mesh, &topo, &h, &pnavg);
    let faired = SchemeParams { fair: true, ..fo };
    let surfaces: Vec<(&str, Box<dyn Surface>)> = vec![
        ("pn", build_surface(Scheme::Pn, &mesh, &topo, &h, &d).0),
        (
            "g2_h0.212",
            build_surface(Scheme::G2, &mesh, &topo, &h, &d).0,
        ),
        (
            "hybrid",
            build_surface(Scheme::Hybrid, &mesh, &topo, &h, &d).0,
        ),
        ("coons_pnavg_analytic", Box::new(coons.clone())),
        (
            "coons_pnavg_fd",
            Box::new(coons.with_normals(NormalMethod::FiniteDifference)),
        ),
        (
            "coons_fo",
            build_surface(Scheme::Coons, &mesh, &topo, &h, &fo).0,
        ),
        (
            "coons_fo_faired",
            build_surface(Scheme::Coons, &mesh, &topo, &h, &faired).0,
        ),
    ];

    let points = mesh.triangles.len() * lattice_len(LEVEL);
    let mut group = c.benchmark_group("scheme_points_with_normals");
    group.throughput(Throughput::Elements(points as u64));
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(4));
    for (name, s) in &surfaces {
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
    for (name, s) in &surfaces {
        let mut out = Vec::with_capacity(lattice_len(LEVEL));
        group.bench_function(BenchmarkId::new("lattice", name), |b| {
            b.iter(|| {
                for t in 0..mesh.triangles.len() {
                    out.clear();
                    s.evaluate_lattice(t, LEVEL, &mut out);
                    black_box(&out);
                }
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group("scheme_build");
    group.throughput(Throughput::Elements(mesh.triangles.len() as u64));
    group.sample_size(10);
    for (name, scheme, params) in [
        ("g2", Scheme::G2, d),
        ("hybrid", Scheme::Hybrid, d),
        ("coons_pnavg", Scheme::Coons, pnavg),
        ("coons_fo", Scheme::Coons, fo),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| black_box(build_surface(scheme, &mesh, &topo, &h, &params)))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
