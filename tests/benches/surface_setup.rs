//! Setting up the G² surface over a large mesh: the pipeline's `surface` stage alone (control
//! nets, neighbours, shared edge curves), on geodesic spheres of 81 920 and 1 310 720 triangles,
//! h = 0.212 on every edge, round nets.
//!
//! It prints the median of 7 set-ups in wall time and in process CPU time (user + system, all
//! threads), and the surface's heap bytes per input triangle. CPU time is the figure to compare
//! on a busy machine: it counts the work and the page faults, not the waiting. Run it with
//! `cargo bench --bench surface_setup`; `RAYON_NUM_THREADS` sets the threads.

use std::hint::black_box;
use std::time::{Duration, Instant};

use g2tess::mesh::TriMesh;
use g2tess::surface::{G2Surface, Profile};
use g2tess::topology::Topology;

#[path = "../integration/support.rs"]
mod support;

const RUNS: usize = 7;

/// CPU time of the whole process so far (every thread, user and system).
fn cpu_time() -> Duration {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for clock_gettime to write.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    assert_eq!(rc, 0, "clock_gettime");
    Duration::new(t.tv_sec as u64, t.tv_nsec as u32)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    // `cargo bench` passes `--bench`; a filter argument, if any, selects sizes by name.
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    for times in [6, 8] {
        let mesh: TriMesh = (0..times).fold(support::icosahedron(), |m, _| support::subdivide(&m));
        let name = format!("g2_setup/{}_triangles", mesh.triangles.len());
        if filter.as_ref().is_some_and(|f| !name.contains(f.as_str())) {
            continue;
        }
        let topo = Topology::build(&mesh);
        let h = support::h_all(&topo, 0.212);
        let (mut wall, mut cpu) = (Vec::new(), Vec::new());
        let mut bytes = 0;
        for _ in 0..RUNS {
            let (c0, w0) = (cpu_time(), Instant::now());
            let surface = G2Surface::new(&mesh, &topo, &h, Profile::C2);
            wall.push(w0.elapsed().as_secs_f64());
            cpu.push((cpu_time() - c0).as_secs_f64());
            bytes = surface.heap_bytes();
            // Freed outside the timed part, as the pipeline frees it after the last level.
            black_box(surface);
        }
        println!(
            "{name}: wall {:.4} s, cpu {:.4} s (medians of {RUNS}), {:.1} heap bytes per triangle",
            median(wall),
            median(cpu),
            bytes as f64 / mesh.triangles.len() as f64
        );
    }
}
