//! What choosing per-edge counts costs, per output triangle, on the 10k icosphere at the chord
//! error level 16 reaches (the run the speed goal of the adaptive tessellation names):
//!
//! - `uniform level 16`: the surface for one pass and the tessellation at level 16;
//! - `adaptive to level 16's error`: the surface, the probe, the checked refinement (the lattice
//!   stages and the measurement, holding the interiors they evaluate), the pairs and rows across
//!   edges, and the tessellation with those counts: what `--tolerance` runs;
//! - `counts from the probe alone`: the surface, the probe, the counts it predicts with nothing
//!   checked, and the tessellation with them. No option runs this, because its output is not
//!   within the tolerance (the bench prints its measured error): it is the floor under any way
//!   of choosing counts that starts from the probe, whatever checks follow.
//!
//! Each function's throughput is its own output triangles, so criterion's rates compare per
//! output triangle as the goal does. The whole-process figures in the README also count
//! reading and writing the file, the same work per output triangle in every run.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use g2tess::options::{Options, DEFAULT_H};
use g2tess::surface::G2Surface;
use g2tess::tessellate::{
    chord_error, tessellate, tessellate_with_counts, tessellate_with_held, ChordErrors,
    SegmentCounts, HELD_BYTES,
};
use g2tess::topology::Topology;
use std::hint::black_box;

#[path = "../integration/support.rs"]
mod support;

const LEVEL: u32 = 16;

fn bench(c: &mut Criterion) {
    // The 10k icosphere: frequency 22, 9,680 triangles.
    let mesh = support::icosphere(22);
    let topo = Topology::build(&mesh);
    let h = support::h_all(&topo, DEFAULT_H);
    let options = Options::default();
    let cap = options.max_segments;
    let whole = 0..mesh.triangles.len();
    let all = std::slice::from_ref(&whole);
    let one_pass =
        || G2Surface::with_nets_for_one_pass(&mesh, &topo, &h, options.profile, options.nets);
    let checked = || G2Surface::with_nets(&mesh, &topo, &h, options.profile, options.nets);

    // The tolerance: level 16's own chord error, as the report measures it.
    let surface = checked();
    let uniform = SegmentCounts::uniform(&topo, LEVEL);
    let dense = tessellate(&mesh, &topo, &h, &surface, LEVEL, all).remove(0);
    let tolerance = chord_error(&topo, &surface, &uniform, whole.clone(), &dense);
    drop(dense);
    let errors = ChordErrors::probe(&mesh, &topo, &surface);
    let (refined, _) =
        errors.counts_for_tolerance(&mesh, &topo, &h, &surface, tolerance, cap, HELD_BYTES, all);
    let predicted = errors.counts(&topo, tolerance, cap);
    let dense = tessellate_with_counts(&mesh, &topo, &h, &surface, &predicted, all).remove(0);
    let predicted_error = chord_error(&topo, &surface, &predicted, whole.clone(), &dense);
    drop(dense);
    let triangles = |counts: &SegmentCounts| counts.triangle_count(&topo);
    eprintln!(
        "10k icosphere ({} triangles), tolerance {tolerance:.4e} (level 16's error): level 16 \
         writes {} triangles, the checked counts {} (within the tolerance), the probe's counts \
         alone {} ({:.3} of the tolerance)",
        mesh.triangles.len(),
        triangles(&uniform),
        triangles(&refined),
        triangles(&predicted),
        predicted_error / tolerance,
    );

    let mut g = c.benchmark_group("adaptive, 10k icosphere, per output triangle");
    g.sample_size(10);
    g.throughput(Throughput::Elements(triangles(&uniform)));
    g.bench_function("uniform level 16", |b| {
        b.iter(|| {
            let surface = one_pass();
            black_box(tessellate(&mesh, &topo, &h, &surface, LEVEL, all))
        })
    });
    g.throughput(Throughput::Elements(triangles(&refined)));
    g.bench_function("adaptive to level 16's error", |b| {
        b.iter(|| {
            let surface = checked();
            let errors = ChordErrors::probe(&mesh, &topo, &surface);
            let (counts, held) = errors
                .counts_for_tolerance(&mesh, &topo, &h, &surface, tolerance, cap, HELD_BYTES, all);
            black_box(tessellate_with_held(
                &mesh, &topo, &h, &surface, &counts, &held, all,
            ))
        })
    });
    g.throughput(Throughput::Elements(triangles(&predicted)));
    g.bench_function(
        "counts from the probe alone (not within the tolerance)",
        |b| {
            b.iter(|| {
                let surface = checked();
                let errors = ChordErrors::probe(&mesh, &topo, &surface);
                let counts = errors.counts(&topo, tolerance, cap);
                black_box(tessellate_with_counts(
                    &mesh, &topo, &h, &surface, &counts, all,
                ))
            })
        },
    );
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
