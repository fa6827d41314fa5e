//! Drawing a dense output: a 2.5-million-triangle G² surface (the 5 120-triangle geodesic
//! sphere at level 22: 2 478 080 triangles) rasterized and shaded at 800 × 800, one view;
//! then the picture of a processing run's preview (input beside output, four views, three
//! modes at 320 pixels) for the same pair.
//!
//! Goal: the 800 × 800 picture of the dense output in under a second on two cores.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use g2tess::mesh::TriMesh;
use g2tess::render::{sheet, Mode, Scene, Settings, Subject, View};
use g2tess::surface::{G2Surface, Profile};
use g2tess::tessellate::tessellate;
use g2tess::topology::Topology;
use glam::{Mat4, Vec3};
use std::hint::black_box;

#[path = "../integration/support.rs"]
mod support;

const LEVEL: u32 = 22;

fn scene_of(positions: Vec<Vec3>, normals: Vec<Vec3>, indices: &[u32]) -> Scene {
    Scene {
        positions,
        normals,
        triangles: indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
        instances: vec![(0, Mat4::IDENTITY)],
    }
}

fn low_poly(mesh: &TriMesh) -> Scene {
    let flat: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    scene_of(
        mesh.positions.iter().map(|p| p.as_vec3()).collect(),
        mesh.normals.iter().map(|n| n.as_vec3()).collect(),
        &flat,
    )
}

fn bench(c: &mut Criterion) {
    let mesh = (0..4).fold(support::icosahedron(), |m, _| support::subdivide(&m));
    let topo = Topology::build(&mesh);
    let h = support::h_all(&topo, 0.212);
    let surface = G2Surface::new(&mesh, &topo, &h, Profile::C2);
    let whole = 0..mesh.triangles.len();
    let dense = tessellate(
        &mesh,
        &topo,
        &h,
        &surface,
        LEVEL,
        std::slice::from_ref(&whole),
    )
    .remove(0);
    let output = scene_of(
        dense.positions.iter().map(|p| Vec3::from(*p)).collect(),
        dense.normals.iter().map(|n| Vec3::from(*n)).collect(),
        &dense.indices,
    );
    drop(dense);
    let input = low_poly(&mesh);

    let mut g = c.benchmark_group("render");
    g.sample_size(10);
    g.throughput(Throughput::Elements(output.triangles.len() as u64));
    let one = Settings {
        modes: vec![Mode::Shaded],
        views: vec![View::Iso],
        size: 800,
    };
    let out = [Subject {
        scene: &output,
        edges: None,
    }];
    g.bench_function("2.5M triangles, 800 px, shaded", |b| {
        b.iter(|| black_box(sheet(&out, &one)))
    });
    g.bench_function("2.5M triangles, 800 px, shaded, PNG", |b| {
        b.iter(|| black_box(sheet(&out, &one).to_png()))
    });
    let preview = Settings {
        modes: vec![Mode::Shaded, Mode::Zebra, Mode::Flat],
        views: View::ALL.to_vec(),
        size: 320,
    };
    let pair = [
        Subject {
            scene: &input,
            edges: None,
        },
        Subject {
            scene: &output,
            edges: None,
        },
    ];
    g.bench_function(
        "preview: input and 2.5M output, 4 views x 3 modes, 320 px, PNG",
        |b| b.iter(|| black_box(sheet(&pair, &preview).to_png())),
    );
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
