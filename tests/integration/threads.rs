//! Output does not depend on the thread count: the tessellator splits work into blocks that run
//! in parallel, and neither its arrays nor the written file may change with the number of
//! threads (1 against 2, and against the default pool).

use crate::corpus;

use std::path::Path;

use crate::support::*;
use g2tess::options::Options;
use g2tess::pipeline::process_file;
use g2tess::surface::{G2Surface, Profile};
use g2tess::tessellate::{tessellate, DenseMesh};
use g2tess::topology::Topology;

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(f)
}

/// A torus with split normals on one band of faces and two groups, at a level where the
/// tessellator cuts each group into many blocks.
fn dense(threads: usize) -> Vec<DenseMesh> {
    let mesh = split_normals(&torus(12), 0.2);
    let topo = Topology::build(&mesh);
    let mut asked = vec![0.2; topo.edge_count()];
    asked.iter_mut().step_by(5).for_each(|x| *x = 0.0);
    let h = widths(&topo, &asked);
    let surface = G2Surface::new(&mesh, &topo, &h, Profile::C2);
    let half = mesh.triangles.len() / 3;
    in_pool(threads, || {
        tessellate(
            &mesh,
            &topo,
            &h,
            &surface,
            24,
            &[0..half, half..mesh.triangles.len()],
        )
    })
}

/// Positions, normals (as bits) and indices of one dense mesh.
type Bits = (Vec<[u32; 3]>, Vec<[u32; 3]>, Vec<u32>);

fn bits(d: &[DenseMesh]) -> Vec<Bits> {
    d.iter()
        .map(|d| {
            (
                d.positions.iter().map(|p| p.map(f32::to_bits)).collect(),
                d.normals.iter().map(|p| p.map(f32::to_bits)).collect(),
                d.indices.clone(),
            )
        })
        .collect()
}

#[test]
fn tessellation_is_bit_identical_on_one_and_two_threads() {
    let one = dense(1);
    assert_eq!(bits(&one), bits(&dense(2)));
    assert_eq!(one, dense(3));
}

fn smooth(input: &Path, threads: usize) -> Vec<u8> {
    let dir = corpus::temp_dir();
    let output = dir.path().join("out.glb");
    let mut options = Options::default();
    options.level = 40;
    in_pool(threads, || process_file(input, &output, &options)).expect("smooths");
    std::fs::read(&output).unwrap()
}

#[test]
fn written_files_are_byte_identical_on_one_and_two_threads() {
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb");
    let one = smooth(&input, 1);
    assert!(one.len() > 500_000, "level 40 gives a dense file");
    assert_eq!(one, smooth(&input, 2));
}
