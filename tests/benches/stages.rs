//! The pipeline's stages on one dense job, each alone: evaluating the surface over every
//! lattice, tessellating (evaluation, shared edges, layout, triangles), meshoptimizer's vertex
//! cache pass on the tessellated output (which the pipeline no longer runs: it measured slower
//! and worse than the tessellator's own order), writing the finished document, and the whole
//! file from read to write.
//!
//! The mesh is a 1 280-triangle geodesic sphere at level 16 (327 680 output triangles): small
//! enough for criterion's repetitions, large enough that every stage runs in parallel blocks.
//!
//! The per-input stages have a group of their own, timed per input triangle on an 81 920-triangle
//! GLB (the fixture icosahedron smoothed at level 64): reading the file (parse, validate, load),
//! and reading it through to every edge's resolved h (decode, join, weld and topology, the
//! geometry checks, h), which is what a large input costs before its surface is built.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use g2tess::gltf_io::{self, ReadOptions, WriteOptions};
use g2tess::mesh::TriMesh;
use g2tess::optimize;
use g2tess::options::Options;
use g2tess::pipeline::{process_document, process_file, resolved_edges};
use g2tess::surface::{G2Surface, Profile, Surface, SurfacePoint};
use g2tess::tessellate::tessellate;
use g2tess::topology::Topology;
use std::hint::black_box;
use std::path::Path;

#[path = "../integration/support.rs"]
mod support;

const LEVEL: u32 = 16;

/// The icosahedron split `times` times into four, on the unit sphere, with exact normals.
fn sphere(times: usize) -> TriMesh {
    (0..times).fold(support::icosahedron(), |m, _| support::subdivide(&m))
}

fn bench(c: &mut Criterion) {
    let mesh = sphere(3);
    let topo = Topology::build(&mesh);
    let h = support::h_all(&topo, 0.212);
    let surface = G2Surface::new(&mesh, &topo, &h, Profile::C2);
    let out_tris = (mesh.triangles.len() as u64) * u64::from(LEVEL * LEVEL);
    let whole = 0..mesh.triangles.len();
    let all = std::slice::from_ref(&whole);

    let mut g = c.benchmark_group("stages");
    g.sample_size(10);
    g.throughput(Throughput::Elements(out_tris));
    g.bench_function("evaluate", |b| {
        let mut out: Vec<SurfacePoint> = Vec::new();
        b.iter(|| {
            for t in 0..mesh.triangles.len() {
                out.clear();
                surface.evaluate_lattice(t, LEVEL, &mut out);
                black_box(&out);
            }
        })
    });
    g.bench_function("tessellate", |b| {
        b.iter(|| black_box(tessellate(&mesh, &topo, &h, &surface, LEVEL, all)))
    });
    let dense = tessellate(&mesh, &topo, &h, &surface, LEVEL, all).remove(0);
    g.bench_function("meshopt vertex cache + fetch (not in the pipeline)", |b| {
        b.iter_batched(
            || dense.clone(),
            |mut d| black_box(optimize::optimize(&mut d, false)),
            criterion::BatchSize::LargeInput,
        )
    });

    // Writing and the whole file, on the fixture icosahedron at level 128 (327 680 triangles).
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb");
    let dir = tempfile::tempdir().expect("temp dir");
    let output = dir.path().join("out.glb");
    let mut options = Options::default();
    options.level = 128;
    let mut doc = gltf_io::read(&input, &ReadOptions::default()).expect("fixture reads");
    process_document(&mut doc, &input, &options).expect("smooths");
    g.bench_function("write", |b| {
        let opts = WriteOptions::new(Some(input.clone()), false);
        b.iter(|| gltf_io::write(&doc, &output, &opts).expect("writes"))
    });
    g.bench_function("whole file", |b| {
        b.iter(|| process_file(&input, &output, &options).expect("smooths"))
    });
    g.finish();
    per_input(c);
}

/// The stages whose cost grows with the input triangles rather than the output's.
fn per_input(c: &mut Criterion) {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb");
    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("input.glb");
    let mut make = Options::default();
    make.level = 64;
    let made = process_file(&fixture, &input, &make).expect("smooths");
    let triangles = made.triangles_out;
    let options = Options::default();

    let mut g = c.benchmark_group("per input triangle");
    g.sample_size(10);
    g.throughput(Throughput::Elements(triangles as u64));
    g.bench_function("read", |b| {
        b.iter(|| black_box(gltf_io::read(&input, &ReadOptions::default()).expect("reads")))
    });
    g.bench_function("read, decode, weld, checks, h", |b| {
        b.iter(|| {
            let doc = gltf_io::read(&input, &ReadOptions::default()).expect("reads");
            black_box(resolved_edges(&doc, &input, &options).expect("resolves"))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
