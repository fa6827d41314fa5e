//! How finely one mesh is tessellated: one level everywhere, or a segment count per edge from a
//! chord tolerance (world units or relative to the mesh's bounding-box diagonal) or a triangle
//! budget, and the figures the report gives for it.
//!
//! It deliberately decides and measures only; the tessellators do the work, and morph targets
//! are tessellated with the base mesh's density so their vertices correspond one to one.

use std::ops::Range;
use std::sync::Mutex;

use rayon::prelude::*;
use serde::Serialize;

use crate::mesh::TriMesh;
use crate::options::Options;
use crate::surface::Surface;
use crate::tessellate::{
    chord_error, tessellate_vertices, tessellate_with_held, ChordErrors, DenseMesh, HeldInteriors,
    SegmentCounts, Tessellation, HELD_BYTES,
};
use crate::topology::Topology;

/// The density of one mesh.
#[derive(Debug, Clone)]
pub(super) enum Density {
    /// Every edge at this level.
    Level(u32),
    /// Per-edge counts, reaching `target` (the tolerance asked for, or found for the budget),
    /// with the interior points the checks evaluated for them, for the output to write.
    Counts {
        counts: SegmentCounts,
        target: f64,
        held: Held,
    },
}

/// The interior points a tolerance's checks evaluated at the patterns' own resolution
/// ([`HeldInteriors`]), until the first tessellation takes them: the output is the same with
/// or without them, so a copy of the density goes without (it is kept only to compare counts)
/// and they are freed as soon as the output is evaluated, not held through the write.
#[derive(Debug, Default)]
pub(super) struct Held(Mutex<Option<HeldInteriors>>);

impl Clone for Held {
    fn clone(&self) -> Held {
        Held::default()
    }
}

impl Held {
    fn new(held: HeldInteriors) -> Held {
        Held(Mutex::new(Some(held)))
    }

    fn take(&self) -> HeldInteriors {
        // A poisoned lock held no points worth keeping: evaluate them instead.
        self.0
            .lock()
            .ok()
            .and_then(|mut held| held.take())
            .unwrap_or_default()
    }
}

/// What the report says of an adaptive mesh.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct AdaptiveFigures {
    /// The chord tolerance aimed at (asked for, or found for the budget), world units.
    pub tolerance: f64,
    /// The chord error measured on the output (sampled points of every output triangle
    /// against the surface), when the report computes figures.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub chord_error: Option<f64>,
    /// The largest segment count of any edge or interior.
    pub max_segments: u32,
    /// The smallest angle of any output triangle, in degrees, when the report computes
    /// figures (else 180).
    pub min_angle_degrees: f64,
    /// The largest ratio of longest edge to shortest altitude × 2/√3 (1 for equilateral), when
    /// the report computes figures (else 1).
    pub max_aspect_ratio: f64,
}

impl Density {
    /// The density the options ask for; `level` is the file's level.
    /// `h` the edges' widths and `groups` the output groups, as the tessellators take them.
    pub fn choose(
        options: &Options,
        level: u32,
        mesh: &TriMesh,
        topo: &Topology,
        h: &[f64],
        surface: &dyn Surface,
        groups: &[Range<usize>],
    ) -> Density {
        if !options.adaptive() {
            return Density::Level(level);
        }
        let cap = options.max_segments;
        let errors = ChordErrors::probe(mesh, topo, surface);
        if options.triangle_budget > 0 {
            let (target, counts) = errors.for_budget(topo, options.triangle_budget, cap);
            return Density::Counts {
                counts,
                target,
                held: Held::default(),
            };
        }
        let mut target = f64::INFINITY;
        if options.tolerance > 0.0 {
            target = options.tolerance;
        }
        if options.relative_tolerance > 0.0 {
            target = target.min(options.relative_tolerance * diagonal(mesh));
        }
        let (counts, held) = if target > 0.0 && target.is_finite() {
            errors.counts_for_tolerance(mesh, topo, h, surface, target, cap, HELD_BYTES, groups)
        } else {
            // A mesh of one point: nothing to refine.
            (SegmentCounts::uniform(topo, 1), HeldInteriors::default())
        };
        Density::Counts {
            counts,
            target,
            held: Held::new(held),
        }
    }

    /// Whether `self` gives the same output as `other`: the same level, or the same counts.
    pub fn same_output(&self, other: &Density) -> bool {
        match (self, other) {
            (Density::Level(a), Density::Level(b)) => a == b,
            (Density::Counts { counts: a, .. }, Density::Counts { counts: b, .. }) => a == b,
            _ => false,
        }
    }

    /// Output triangles, before tessellating.
    pub fn triangle_count(&self, mesh: &TriMesh, topo: &Topology) -> u64 {
        match self {
            Density::Level(l) => mesh.triangles.len() as u64 * u64::from(l * l),
            Density::Counts { counts, .. } => counts.triangle_count(topo),
        }
    }

    /// Tessellates `groups` at this density; what is left once the surface may be freed is
    /// written by [`Tessellation::finish`].
    pub fn tessellate<'a>(
        &self,
        mesh: &'a TriMesh,
        topo: &Topology,
        h: &[f64],
        surface: &dyn Surface,
        groups: &[Range<usize>],
    ) -> Tessellation<'a> {
        match self {
            Density::Level(level) => tessellate_vertices(mesh, topo, h, surface, *level, groups),
            Density::Counts { counts, held, .. } => Tessellation::done(tessellate_with_held(
                mesh,
                topo,
                h,
                surface,
                counts,
                &held.take(),
                groups,
            )),
        }
    }

    /// The report's figures: always for per-edge counts; at a uniform level only when `measure`
    /// (then the tolerance is the measured error), so uniform and adaptive runs compare. The
    /// surface is read only to measure; without it nothing is measured.
    pub fn figures(
        &self,
        topo: &Topology,
        surface: Option<&dyn Surface>,
        groups: &[Range<usize>],
        dense: &[DenseMesh],
        measure: bool,
    ) -> Option<AdaptiveFigures> {
        let surface = surface.filter(|_| measure);
        let measure = surface.is_some();
        let (counts, target) = match self {
            Density::Counts { counts, target, .. } => (counts.clone(), Some(*target)),
            Density::Level(level) if measure => (SegmentCounts::uniform(topo, *level), None),
            Density::Level(_) => return None,
        };
        // Only a report shows them, and they take a pass over every output triangle.
        let (mut min_angle, mut max_aspect) = (180.0f64, 1.0f64);
        for d in dense.iter().filter(|_| measure) {
            let (a, r) = shape(d);
            min_angle = min_angle.min(a);
            max_aspect = max_aspect.max(r);
        }
        let chord = surface.map(|surface| {
            groups
                .iter()
                .zip(dense)
                .map(|(g, d)| chord_error(topo, surface, &counts, g.clone(), d))
                .fold(0.0, f64::max)
        });
        Some(AdaptiveFigures {
            tolerance: target.or(chord).unwrap_or(0.0),
            chord_error: chord,
            max_segments: counts.max(),
            min_angle_degrees: min_angle,
            max_aspect_ratio: max_aspect,
        })
    }
}

/// Length of the diagonal of the bounding box of `mesh`'s positions.
///
/// Folded in parallel blocks: on a million vertices a fold on one thread took about 2 ms at the
/// end of each mesh with the other threads idle. The bounds are the same whatever the blocks:
/// every block starts from the first position (one of the positions, so it moves no bound),
/// the componentwise minimum and maximum pick one of their operands and skip a NaN whichever
/// side it is on, and a bound that is +0 in one order and −0 in another changes no difference
/// `hi − lo` it enters.
pub(super) fn diagonal(mesh: &TriMesh) -> f64 {
    let Some(&first) = mesh.positions.first() else {
        return 0.0;
    };
    let (lo, hi) = mesh
        .positions
        .par_chunks(DIAGONAL_BLOCK)
        .map(|block| {
            block
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)))
        })
        .reduce(
            || (first, first),
            |(lo, hi), (block_lo, block_hi)| (lo.min(block_lo), hi.max(block_hi)),
        );
    (hi - lo).length()
}

/// Positions one task of [`diagonal`] folds.
const DIAGONAL_BLOCK: usize = 1 << 16;

/// Smallest angle (degrees) and largest aspect ratio of the triangles of `dense`; degenerate
/// triangles (zero area) are skipped, as the input's own can be.
fn shape(dense: &DenseMesh) -> (f64, f64) {
    let p = |v: u32| glam::DVec3::from(dense.positions[v as usize].map(f64::from));
    let (mut min_angle, mut max_aspect) = (180.0f64, 1.0f64);
    for t in dense.indices.chunks_exact(3) {
        let [a, b, c] = [p(t[0]), p(t[1]), p(t[2])];
        let twice_area = (b - a).cross(c - a).length();
        if twice_area <= 0.0 {
            continue;
        }
        let sides = [(b - c).length(), (c - a).length(), (a - b).length()];
        let longest = sides.iter().copied().fold(0.0, f64::max);
        // Smallest angle is opposite the shortest side: sin = 2A / (product of the other two).
        let angle = |k: usize| {
            let (u, v) = (sides[(k + 1) % 3], sides[(k + 2) % 3]);
            (twice_area / (u * v)).clamp(-1.0, 1.0).asin().to_degrees()
        };
        let shortest = (0..3)
            .min_by(|&x, &y| sides[x].total_cmp(&sides[y]))
            .unwrap_or(0);
        min_angle = min_angle.min(angle(shortest));
        // Longest edge over the altitude onto it, scaled so the equilateral triangle gives 1.
        let altitude = twice_area / longest;
        max_aspect = max_aspect.max(longest / altitude * (3f64.sqrt() / 2.0));
    }
    (min_angle, max_aspect)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The diagonal folded in parallel blocks is bit for bit the one-thread fold, on one thread
    /// and on two, with a NaN, signed zeros and infinities among positions spread over several
    /// blocks (the first position's own NaN included).
    #[test]
    fn diagonal_in_blocks_is_the_one_thread_fold() {
        let serial = |mesh: &TriMesh| {
            let first = mesh.positions[0];
            let (lo, hi) = mesh
                .positions
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
            (hi - lo).length()
        };
        let n = 3 * DIAGONAL_BLOCK + 17;
        let spread = |i: usize| ((i * 7919) % 10007) as f64 * 1e-3 - 5.0;
        let mut cases: Vec<Vec<DVec3>> = Vec::new();
        let plain: Vec<DVec3> = (0..n)
            .map(|i| DVec3::new(spread(i), spread(i + 1), spread(i + 2)))
            .collect();
        cases.push(plain.clone());
        let mut odd = plain.clone();
        odd[0] = DVec3::new(f64::NAN, 0.0, -0.0);
        odd[DIAGONAL_BLOCK + 3] = DVec3::new(-0.0, f64::NAN, 0.0);
        odd[2 * DIAGONAL_BLOCK] = DVec3::new(0.0, -0.0, f64::INFINITY);
        cases.push(odd);
        let zeros: Vec<DVec3> = (0..n)
            .map(|i| DVec3::splat(if i % 3 == 0 { -0.0 } else { 0.0 }))
            .collect();
        cases.push(zeros);
        for positions in cases {
            let mesh = TriMesh {
                positions,
                ..TriMesh::default()
            };
            let want = serial(&mesh);
            for threads in [1, 2] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let got = pool.install(|| diagonal(&mesh));
                assert_eq!(got.to_bits(), want.to_bits(), "{threads} threads");
            }
        }
    }
}
