//! The per-input stages (weld, geometry checks, generated normals, h, surface, tessellation at
//! level 1) on the shapes that used to be superlinear in the valence: a book of triangles on one
//! edge, a fan around one vertex, copies of one triangle and triangles collapsed to one point,
//! each at 10 000 and 100 000 triangles, with and without input normals. Near-linear means the
//! 100 000 figure is about ten times the 10 000 one.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use g2tess::gltf_io::{self, ReadOptions};
use g2tess::options::Options;
use g2tess::pipeline::process_document;
use std::path::Path;

#[path = "../integration/hostile.rs"]
mod hostile;

/// Positions and indices of `n` triangles of one kind.
fn shape(kind: &str, n: usize) -> (Vec<[f32; 3]>, Vec<u32>) {
    let turn = |i: usize| std::f32::consts::TAU * i as f32 / n as f32;
    match kind {
        "book" => {
            let mut p = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
            p.extend((0..n).map(|i| [turn(i).cos(), turn(i).sin(), 0.5]));
            (p, (0..n as u32).flat_map(|i| [0, 1, i + 2]).collect())
        }
        "fan" => {
            let mut p = vec![[0.0, 0.0, 0.0]];
            p.extend((0..n).map(|i| [turn(i).cos(), turn(i).sin(), 0.3 * (7.0 * turn(i)).sin()]));
            let idx = (0..n as u32).flat_map(|i| [0, i + 1, (i + 1) % n as u32 + 1]);
            (p, idx.collect())
        }
        "duplicates" => (
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            [0, 1, 2].repeat(n),
        ),
        _ => (vec![[0.0, 0.0, 0.0]; 3], [0, 1, 2].repeat(n)),
    }
}

fn bench(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let mut options = Options::default();
    options.level = 1;
    let mut g = c.benchmark_group("hostile shapes, level 1");
    g.sample_size(10);
    for kind in ["book", "fan", "duplicates", "one point"] {
        for n in [10_000, 100_000] {
            for with_normals in [true, false] {
                let (p, idx) = shape(kind, n);
                let normals = vec![[0.0, 0.0, 1.0]; p.len()];
                let normals = with_normals.then_some(&normals[..]);
                let path = hostile::write_mesh(dir.path(), &p, normals, &idx);
                let doc = gltf_io::read(&path, &ReadOptions::default()).unwrap();
                let label = format!("{kind}{}", if with_normals { "" } else { ", no normals" });
                g.throughput(Throughput::Elements(n as u64));
                g.bench_with_input(BenchmarkId::new(label, n), &doc, |b, doc| {
                    b.iter_batched(
                        || doc.clone(),
                        |mut doc| process_document(&mut doc, Path::new(&path), &options).unwrap(),
                        criterion::BatchSize::LargeInput,
                    )
                });
            }
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
