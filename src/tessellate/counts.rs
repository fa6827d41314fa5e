//! How many segments each welded edge and each triangle's interior need for the output to stay
//! within a chord error of the smooth surface, or within a triangle budget.
//!
//! The chord error of linear interpolation over a triangle with edge vectors `d_ab` is, for a
//! surface that is locally quadratic, `S(λ) − L(λ) = ½ Σ_{a<b} λ_a λ_b d_abᵀ H d_ab`
//! (`estimate.rs` predicts it from a lattice's second differences); along a single edge curve
//! it is `K/8` at the midpoint, `K` the second difference along the edge. Both fall as `1/n²`
//! with the segment count. So one probe per triangle, the level-[`PROBE_LEVEL`] lattice and its
//! second differences in the three lattice directions, gives each triangle and each edge an
//! error constant `c` with error ≈ `c/n²`; the counts for any tolerance, and the tolerance that
//! meets a budget, follow without evaluating the surface again. A tolerance is then checked on
//! each triangle's lattice at its own resolution ([`ChordErrors::refine_to_tolerance`]).

//! Two balance rules keep the transition patterns well shaped (`transition.rs`): a triangle's
//! inner level is at least two thirds of each of its edge counts ([`inner_floor`]), and each
//! edge count is at least half the inner level of each triangle beside it. The inner level may
//! so stay below its edges where the interior needs less than they do (a triangle curved along
//! two edges and flat along the third, as on a torus), as the Direct3D 11 tessellator's outer
//! factors may exceed its inner one; and an edge raised by one does not raise the inner levels
//! beside it with it (which, on an evenly curved mesh, sent a wave of raised counts across it).
//! Raising one value raises its neighbours to a fraction of it, so the propagation dies out
//! within `log₁.₅(cap)` steps: a few sweeps over the mesh.
//!
//! It deliberately writes no vertex.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;

use rayon::prelude::*;

use super::chord::{boundary_error, measured_error, BoundaryTriangles, Reach};
use super::coarsen::coarsen;
use super::estimate::{Curvature, PatternError, PatternModel};
use super::evaluator;
use super::held::{HeldInteriors, Holding};
use super::kept_patterns;
use super::pairs::Pair;
use super::transition::{Pattern, PatternKey};
use crate::mesh::TriMesh;
use crate::surface::{lattice_index, Surface, SurfacePoint};
use crate::topology::{EdgeId, Topology};

/// Lattice level of the probe: 28 surface points per triangle, a fifth of what level 16
/// writes, and enough second differences to see a blending region's curvature.
pub const PROBE_LEVEL: u32 = 6;

/// Margin on the predicted error: the probe sees the curvature at its own points only, and
/// the transition rings hold triangles up to twice as long as the inner lattice's. Measured
/// on the icosphere, torus, bumpy sphere, height field and domed plate (`tests/integration/tessellate_adaptive.rs`),
/// the error reached without it is up to 4% over the target.
pub const MARGIN: f64 = 1.25;

/// Patterns up to this inner level are measured at every output triangle (at most 144 of
/// them, seven points each); finer ones at some of their boundary triangles only
/// ([`boundary_error`]: those at the source corners, or every one along the edges where the
/// lattice at their own resolution is not smooth), the rest resting on the lattice check at
/// twice their resolution, unless that lattice is rough ([`ROUGH`]).
/// Measuring every output triangle costs seven point evaluations per output triangle, many times
/// what tessellating it costs, while for fine patterns the lattice check is what holds: on the
/// height field at 1e-4 (counts up to 35) the error measured on the output stays at the
/// tolerance; with the lattice at the pattern's own resolution only it is 5% over, and with
/// full measurement stopping at 8 instead of 12 the height field at 1e-3 is 3% over.
const MEASURED_UP_TO: u32 = 12;

/// How much more error than the uniform pattern of its level a triangle's transition pattern
/// (an edge one step finer than its inner level) shows: a triangle whose uniform error at its
/// level, times this, is over the tolerance takes its finer neighbour's level in
/// [`ChordErrors::initial_counts`]'s start. On the 10k icosphere at the error level 16
/// reaches, 1.2 starts stage 0 at 2,657,600 triangles, which its wave takes to the 2,681,880
/// it settles at from the plain start (13,700 stage-0 checks instead of 56,460); 1.3 and 1.5
/// start past it (2,716,160 and 2,767,760), and below 1.1 the wave is as long as before.
const TRANSITION: f64 = 1.2;

/// Most passes of the lattice stages and the measurement of
/// [`ChordErrors::refine_to_tolerance`]: a pass after the first checks only the patterns the
/// measurement raised, and then measures only those the lattice stages raised in turn, so each
/// costs what changed; the bound keeps the whole linear in the mesh. At
/// `--relative-tolerance 2e-4` the measurement changes nothing in the second pass on Pirate and
/// the bundled icosahedron, in the third on Suzanne and DamagedHelmet, and by the fourth on
/// every mesh of PalmTree and 2CylinderEngine, none reaching the bound; the 10k icosphere at the
/// error level 16 reaches takes one pass.
const MEASURED_PASSES: usize = 4;

/// How much stage 1's bound may add to a fine pattern's inner error (`PatternModel::inner_growth`),
/// as a fraction of the tolerance, for the interior to rest on the lattice stages: past it the
/// lattice is rough at the scale of two steps, where the model at twice the resolution can
/// under-predict the interior, and the measurement takes every output triangle. The interiors
/// traced over the tolerance, each in a fine pattern whose check at twice the resolution passed,
/// had it at 0.89 (PalmTree, `--scheme coons`, `--relative-tolerance 5e-4`: 1.009 of the
/// tolerance), 1.37 (2CylinderEngine's `body_10` at 2e-4: 1.16) and 0.52 (2CylinderEngineDraco's
/// `body_8` at 2e-4: 1.24); on the 10k icosphere at the error level 16 reaches it is at most 0.10.
/// A quarter keeps twice the margin under the lowest of those: on the fixture comparison it writes
/// the same output as a half, for 3% more instructions on DamagedHelmet at 2e-4 and 4% on
/// 2CylinderEngineDraco.
const ROUGH: f64 = 0.25;

/// The triangles whose keys (or other per-triangle state) differ between `before` and `after`
/// (the same triangles), ascending.
fn changed<T: PartialEq>(before: &[T], after: &[T]) -> Vec<usize> {
    (0..before.len())
        .filter(|&t| before[t] != after[t])
        .collect()
}

/// The lattice level a pattern of inner level `inner` is checked on at `factor` times its
/// resolution: the probe's own lattice (`factor` 0), the pattern's own points (`factor` 1), or
/// also the midpoints of its lattice's edges (`factor` 2); the probe's level when that is
/// finer.
fn check_level(inner: u32, factor: u32) -> u32 {
    (factor * inner).max(PROBE_LEVEL)
}

/// The chord error constants of a mesh's surface: error ≈ `c / n²` at `n` segments.
#[derive(Debug, Clone)]
pub struct ChordErrors {
    /// Per source triangle, for its interior.
    pub triangles: Vec<f64>,
    /// Per welded edge, for its curve.
    pub edges: Vec<f64>,
    /// How far rounding the output's positions to `f32` can move a flat output triangle: the
    /// checks of [`ChordErrors::refine_to_tolerance`] keep this much under the tolerance, so that
    /// the written output meets it too. Half an `f32` ulp per coordinate of the largest
    /// coordinate the probe saw, `√3 · 2⁻²⁴ · max |x|` (1e-7 on the unit sphere, where level
    /// 16 of a 10k icosphere reaches 2.4e-6).
    pub rounding: f64,
    /// The smallest chord error that means anything for this mesh: eight `f32` units in the
    /// last place of the largest coordinate, `2⁻²⁰ · max |x|`. Constants at or below it are
    /// rounding noise (a flat part probed in floating point has them) and count as 0, and no
    /// tolerance below it is sought, so a budget never refines a flat part for nothing.
    pub floor: f64,
    /// The probe's second differences, `PROBE_STRIDE` values per source triangle as
    /// `Curvature::keep` wrote them: stage 0 of
    /// [`ChordErrors::refine_to_tolerance`] reads its checks from them instead of evaluating
    /// the probe's lattice again (the same lattice, bit for bit).
    probed: Vec<[f64; 3]>,
}

/// What the probe finds on one source triangle: its interior's and its edges' error constants,
/// its largest coordinate, and its second differences as `Curvature::keep` writes them.
type Probed = (f64, [f64; 3], f64, Vec<[f64; 3]>);

/// Values per source triangle in `ChordErrors::probed`: the probe lattice's interior points,
/// then `Curvature::keep`'s trailer.
const PROBE_STRIDE: usize = ((PROBE_LEVEL - 1) * (PROBE_LEVEL - 2) / 2) as usize + 1;

/// The most memory the probe's kept lattice may take (about 96,000 triangles): beyond it stage 0
/// evaluates the probe's lattice again. Kept whole it would take 696 bytes per triangle, more
/// than the rest of an adaptive run holds per triangle (a 1M-triangle icosphere at 1e-3 peaked
/// at 931 MB with it kept, 423 MB without).
pub const PROBE_KEPT_BYTES: usize = 64 << 20;

/// Segment counts of one mesh: per welded edge and per source triangle's interior.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SegmentCounts {
    /// Segments along each welded edge (both sides use them: watertight by construction).
    pub edges: Vec<u32>,
    /// Inner lattice level of each source triangle.
    pub inner: Vec<u32>,
    /// How each source triangle without interior fills the polygon of its edge samples: 0,
    /// by ears of largest minimum angle in the domain, but where the lowering of counts
    /// (`coarsen.rs`) chose a triangulation by measured chord error (`fill.rs`).
    pub fill: Vec<u16>,
    /// Pairs of triangles cut as one polygon across the edge between them (`pairs.rs`), or
    /// as one quad in rows with points inside (`rows.rs`), by their first triangle; none but
    /// where [`SegmentCounts::pair_across_edges`] and [`SegmentCounts::rows_across_edges`]
    /// made them.
    pub pairs: Vec<Pair>,
}

impl ChordErrors {
    /// Probes `surface` once per triangle, keeping the probe's lattice for stage 0 of
    /// [`ChordErrors::refine_to_tolerance`] when it fits in [`PROBE_KEPT_BYTES`].
    pub fn probe(mesh: &TriMesh, topo: &Topology, surface: &dyn Surface) -> ChordErrors {
        ChordErrors::probe_keeping(mesh, topo, surface, PROBE_KEPT_BYTES)
    }

    /// [`ChordErrors::probe`], keeping the probe's lattice only when it takes at most
    /// `kept_bytes` (696 bytes per triangle). Where it is not kept, stage 0 evaluates the same
    /// lattice again, so the counts are the same either way: only time and memory differ.
    pub fn probe_keeping(
        mesh: &TriMesh,
        topo: &Topology,
        surface: &dyn Surface,
        kept_bytes: usize,
    ) -> ChordErrors {
        let keep = mesh
            .triangles
            .len()
            .checked_mul(PROBE_STRIDE * std::mem::size_of::<[f64; 3]>())
            .is_some_and(|bytes| bytes <= kept_bytes);
        let p = PROBE_LEVEL;
        let scale = f64::from(p * p);
        let per_tri: Vec<Probed> = (0..mesh.triangles.len())
            .into_par_iter()
            .map_init(
                || (Vec::new(), Curvature::default()),
                |(points, curvature): &mut (Vec<SurfacePoint>, Curvature), tri| {
                    points.clear();
                    surface.evaluate_lattice(tri, p, points);
                    curvature.read(points, p);
                    let edges = edge_second_differences(points, p);
                    let largest = points
                        .iter()
                        .map(|s| s.position.abs().max_element())
                        .fold(0.0, f64::max);
                    // Kept with the lattice: stage 0 scales it for each inner level.
                    let inner = curvature.inner_error(p);
                    let mut kept = Vec::new();
                    if keep {
                        curvature.keep(&mut kept);
                        debug_assert_eq!(kept.len(), PROBE_STRIDE);
                    }
                    (
                        finite(inner * scale),
                        edges.map(|d| finite(d * scale / 8.0)),
                        largest,
                        kept,
                    )
                },
            )
            .collect();
        let mut edges = vec![0.0f64; topo.edge_count()];
        for (e, c) in edges.iter_mut().enumerate() {
            // The evaluator's side: the one whose samples are written.
            if let Some((tri, k)) = evaluator(topo, e) {
                *c = per_tri[tri].1[k];
            }
        }
        let largest = per_tri.iter().map(|t| t.2).fold(0.0, f64::max);
        let floor = finite(largest * 2f64.powi(-20));
        let audible = |c: f64| if c <= floor { 0.0 } else { c };
        ChordErrors {
            triangles: per_tri.iter().map(|t| audible(t.0)).collect(),
            edges: edges.into_iter().map(audible).collect(),
            rounding: finite(3f64.sqrt() * largest * 2f64.powi(-24)),
            floor,
            probed: per_tri.iter().flat_map(|t| t.3.iter().copied()).collect(),
        }
    }

    /// The probe's second differences of source triangle `tri` (empty if not probed).
    fn probed_at(&self, tri: usize) -> &[[f64; 3]] {
        self.probed
            .get(tri * PROBE_STRIDE..(tri + 1) * PROBE_STRIDE)
            .unwrap_or(&[])
    }

    /// The counts that keep the chord error at or below `tolerance`, each at most `cap`.
    pub fn counts(&self, topo: &Topology, tolerance: f64, cap: u32) -> SegmentCounts {
        self.counts_with_margin(topo, tolerance, cap, MARGIN)
    }

    fn counts_with_margin(
        &self,
        topo: &Topology,
        tolerance: f64,
        cap: u32,
        margin: f64,
    ) -> SegmentCounts {
        let need = |c: f64| segments_for(c, tolerance, cap, margin);
        let mut counts = SegmentCounts {
            edges: self.edges.iter().map(|&c| need(c)).collect(),
            inner: self
                .triangles
                .iter()
                .map(|&c| initial_inner(need(c)))
                .collect(),
            fill: vec![0; self.triangles.len()],
            pairs: Vec::new(),
        };
        counts.balance(topo);
        counts
    }

    /// The counts [`ChordErrors::refine_to_tolerance`] starts from, for `predicted` the
    /// tolerance its predictions check against: [`ChordErrors::counts`] without its margin,
    /// raised where patterns come out finer than [`MEASURED_UP_TO`] to the level where stage
    /// 0's wave would take them ([`ChordErrors::flooded_levels`]), so that the wave is short.
    fn initial_counts(&self, topo: &Topology, predicted: f64, cap: u32) -> SegmentCounts {
        let mut counts = self.counts_with_margin(topo, predicted, cap, 1.0);
        if let Some((inner, edges)) = self.flooded_levels(topo, predicted, cap) {
            for (c, n) in counts.inner.iter_mut().zip(inner) {
                *c = (*c).max(n);
            }
            for (c, n) in counts.edges.iter_mut().zip(edges) {
                *c = (*c).max(n);
            }
            counts.balance(topo);
        }
        counts
    }

    /// Where the probe's lattice was kept, the levels stage 0's wave raises fine patterns to,
    /// predicted without it: per triangle the level its uniform pattern needs by the stage-0
    /// model ([`ChordErrors::uniform_errors`], which scales as `1/n²`), where that is finer
    /// than [`MEASURED_UP_TO`] (0 elsewhere), and per edge the finer of its triangles'.
    ///
    /// The wave starts where a triangle beside a finer one fails its transition pattern (its
    /// ring along the finer edge), takes the inner level to that edge, then the coarse edges
    /// to the inner level, and goes on across every triangle without the slack for a
    /// transition: on an evenly curved mesh, most of it (10k icosphere at the error level 16
    /// reaches: from 2,283,360 triangles to 2,681,880 over 25 rounds, 56,460 checks). Here a
    /// triangle whose uniform error at its level, times [`TRANSITION`], is over the tolerance
    /// takes the level of its finest edge, edges take the finer of their triangles', until
    /// nothing changes: integers only, one model check per triangle.
    fn flooded_levels(
        &self,
        topo: &Topology,
        predicted: f64,
        cap: u32,
    ) -> Option<(Vec<u32>, Vec<u32>)> {
        let reference = MEASURED_UP_TO + 1;
        let errors = self.uniform_errors(reference, predicted)?;
        let scale = |n: u32| (f64::from(reference) / f64::from(n)).powi(2);
        let inner: Vec<u32> = errors
            .iter()
            .map(|&e| segments_for(e * scale(1), predicted, cap, 1.0))
            .map(|n| if n > MEASURED_UP_TO { n } else { 0 })
            .collect();
        let lacks_slack = |t: usize, n: u32| TRANSITION * errors[t] * scale(n) > predicted;
        Some(flood(topo, inner, lacks_slack))
    }

    /// Per triangle, the stage-0 model's error of the uniform pattern of level `reference` on
    /// the probe's kept lattice (`None` where it was not kept), its parts at or below
    /// `predicted` read only to that bound (they make no level finer than `reference`).
    fn uniform_errors(&self, reference: u32, predicted: f64) -> Option<Vec<f64>> {
        if self.probed.is_empty() {
            return None;
        }
        let key = PatternKey {
            edges: [reference; 3],
            inner: reference,
            fill: 0,
        };
        let model = PatternModel::new(&Pattern::new(key), PROBE_LEVEL);
        let errors = (0..self.triangles.len())
            .into_par_iter()
            .map_init(Curvature::default, |curvature, tri| {
                if !curvature.restore(PROBE_LEVEL, self.probed_at(tri)) {
                    return 0.0;
                }
                let error = model.error_deciding(curvature, [predicted; 3], predicted, |_| 0b111);
                error.edges.into_iter().fold(error.inner, f64::max)
            })
            .collect();
        Some(errors)
    }

    /// The counts that keep the measured chord error at or below `tolerance`: the prediction of
    /// [`ChordErrors::counts`] without its margin, then rounds of checks that raise the counts
    /// of each failing part of a pattern (its inner lattice, or the edges its boundary triangles
    /// touch; the inner level instead where such an edge is at least as fine as it) by
    /// `√(error/tolerance)` and rebalance, checking again only triangles whose counts changed,
    /// in four stages:
    ///
    /// 0. predicted from the probe's level-[`PROBE_LEVEL`] lattice, whatever the pattern's
    ///    inner level: the same model as stage 1 (the error of every boundary triangle from
    ///    the second differences at the lattice point nearest its corners, scaled by the
    ///    lattice's `L²`), on 28 points instead of the pattern's own. The probe's constants
    ///    alone under-predict what the ring triangles along an edge need (the edge curve's
    ///    `K/8` against the `K/6` at the centroid of a triangle curved along all three of its
    ///    edges, on a sphere), so every triangle failed its first check at its own resolution,
    ///    and the counts settled there in a wave of raised counts, one triangle per two rounds,
    ///    each round of a triangle whose inner level moved a new lattice of the pattern's
    ///    resolution. Here the wave runs on the kept probe lattice; on a surface smooth at the
    ///    probe's scale its counts are those of stage 1, which then checks each triangle about
    ///    once (10k icosphere at the error level 16 reaches: the same counts and output bytes,
    ///    11,100 lattices finer than the probe's evaluated instead of 23,828). Its checks read
    ///    the probe's lattice as the probe kept it (`ChordErrors::probed`): it evaluates none.
    ///    Patterns finer than `MEASURED_UP_TO` (inner level 12) start where the wave would take
    ///    them (`ChordErrors::flooded_levels`), so that it settles in a few rounds;
    /// 1. predicted from the lattice at the pattern's own resolution (`estimate.rs`: one lattice
    ///    evaluation per triangle through the surface's cached weights, its second differences
    ///    along the normal), where the counts settle at a quarter of the points of
    /// 2. the same at twice the pattern's resolution, which sees the blend bands narrower than
    ///    a lattice step (the height field at 1e-4 is 5% over the tolerance without it); once
    ///    the counts have settled it checks each triangle once, and raises few. A triangle
    ///    whose last check in stage 1 showed that this one would pass too is not checked again
    ///    (with the same counts): its prediction plus what the finer lattice can change of it
    ///    on a surface smooth at the scale of two lattice steps (`Curvature::spread`,
    ///    `PatternModel::bound`) is within the tolerance. On the 10k icosphere at the error
    ///    level 16 reaches that is 8,766 of its 9,680 triangles, and the counts are the same
    ///    as with every triangle checked;
    /// 3. measured at the chord module's sample points, on the triangles as written (positions
    ///    rounded to `f32`): every output triangle of patterns up to inner level 12; of finer
    ///    ones the triangles at the source corners where stage 1 resolved the pattern (the
    ///    bound of its finer check passed, as above), and every triangle along the source edges
    ///    where it did not: near a corner the blend's curvature varies on the scale of the
    ///    distance to the vertex and the lattice misses it (`chord::Reach`); and every output
    ///    triangle of those whose lattice stage 1 last found rough (`ROUGH`), once their
    ///    boundary triangles pass.
    ///
    /// A measurement that raises counts can lift a pattern above inner level 12, which it then
    /// measures at its boundary only, with no lattice stage having checked it: so stages 1 to
    /// 3 run again on the patterns it changed, and the measurement on those the lattice stages
    /// raise or find rough in turn, up to `MEASURED_PASSES` (4) passes (Suzanne at
    /// `--relative-tolerance 2e-4`: 61 source triangles over the tolerance with one pass, 40
    /// with two, with the corner triangles alone measured).
    ///
    /// The predictions check against the tolerance less the `f32` rounding of the written
    /// positions ([`ChordErrors::rounding`]), as they predict the error of the unrounded
    /// triangles; the measurement, which sees the rounding, against the tolerance itself. Stops
    /// when every triangle meets it or is at `cap`. `surface` is the one the probe read.
    ///
    /// The counts settled, those of patterns measured at every output triangle are lowered one
    /// step at a time where every pattern they belong to still measures within the tolerance
    /// (`coarsen.rs`): the raise rounds up and lifts neighbours with the balance, and so can
    /// end a step above what a pattern needs (50×20 torus at 1e-3: 13,500 → 13,200 triangles).
    pub fn refine_to_tolerance(
        &self,
        topo: &Topology,
        surface: &dyn Surface,
        tolerance: f64,
        cap: u32,
    ) -> SegmentCounts {
        self.refine(topo, surface, tolerance, cap, None)
    }

    /// [`ChordErrors::refine_to_tolerance`], holding up to `held_bytes` of the interior points
    /// stage 1 evaluates at the patterns' own resolution (`held.rs`) for the output to write
    /// instead of evaluating them again: the same counts, and with
    /// [`super::tessellate_with_held`] the same output bytes.
    pub fn refine_to_tolerance_holding(
        &self,
        topo: &Topology,
        surface: &dyn Surface,
        tolerance: f64,
        cap: u32,
        held_bytes: usize,
    ) -> (SegmentCounts, HeldInteriors) {
        let holding = Holding::new(held_bytes);
        let counts = self.refine(topo, surface, tolerance, cap, Some(&holding));
        let held = holding.finish(&counts.inner);
        (counts, held)
    }

    /// The counts a `--tolerance` run tessellates with:
    /// [`ChordErrors::refine_to_tolerance_holding`], then pairs of triangles cut as one polygon
    /// across the edge between them where that passes ([`SegmentCounts::pair_across_edges`]), then
    /// the quads left cut in rows ([`SegmentCounts::rows_across_edges`]). `h` and `groups` as the
    /// tessellators take them.
    #[allow(clippy::too_many_arguments)]
    pub fn counts_for_tolerance(
        &self,
        mesh: &TriMesh,
        topo: &Topology,
        h: &[f64],
        surface: &dyn Surface,
        tolerance: f64,
        cap: u32,
        held_bytes: usize,
        groups: &[std::ops::Range<usize>],
    ) -> (SegmentCounts, HeldInteriors) {
        let (mut counts, held) =
            self.refine_to_tolerance_holding(topo, surface, tolerance, cap, held_bytes);
        counts.pair_across_edges(mesh, topo, h, surface, tolerance, groups);
        counts.rows_across_edges(mesh, topo, h, surface, tolerance, cap, groups);
        (counts, held)
    }

    fn refine(
        &self,
        topo: &Topology,
        surface: &dyn Surface,
        tolerance: f64,
        cap: u32,
        holding: Option<&Holding>,
    ) -> SegmentCounts {
        let predicted = (tolerance - self.rounding).max(0.5 * tolerance);
        let mut counts = self.initial_counts(topo, predicted, cap);
        // Per triangle, the packed key of the pattern whose last check at its own resolution
        // showed the finer check would pass too (0: none).
        let resolved: Vec<AtomicU64> = (0..counts.inner.len()).map(|_| AtomicU64::new(0)).collect();
        // Per triangle, the last lattice stage 1 read while it did not resolve: stage 2 checks
        // it on the lattice of twice that level, whose even points these are (`Coarse`).
        let coarse = Coarse::new();
        // Per triangle, whether stage 1's last measured spread was rough (`ROUGH`).
        let rough: Vec<AtomicBool> = (0..counts.inner.len())
            .map(|_| AtomicBool::new(false))
            .collect();
        // Stages 0 to 2 (`factors` of them) from the triangles `first` on.
        let lattice_stages = |counts: &mut SegmentCounts, factors: &[u32], first: &[usize]| {
            for &factor in factors {
                counts.raise_until_met(
                    topo,
                    predicted,
                    cap,
                    first.to_vec(),
                    |key| kept_patterns::model(key, check_level(key.inner, factor)),
                    |tri,
                     model,
                     (points, curvature): &mut (Vec<SurfacePoint>, Curvature),
                     kept: &[[f64; 3]],
                     keep: &mut Vec<[f64; 3]>| {
                        let key = pack(model.key());
                        if factor == 2 && resolved[tri].load(Ordering::Relaxed) == key {
                            return PatternError::default();
                        }
                        let level = check_level(model.inner(), factor);
                        // The lattice depends on the triangle and the level alone: a triangle
                        // checked again with only its edge counts raised reads the second
                        // differences it kept. Stage 0 reads the probe's own lattice as the probe
                        // kept it, at every check, and so keeps nothing of its own.
                        let from_probe =
                            factor == 0 && curvature.restore(level, self.probed_at(tri));
                        let read = !(from_probe || curvature.restore(level, kept));
                        if read {
                            points.clear();
                            // Second differences are taken along interior points' normals only.
                            match coarse.take(tri, factor, level) {
                                Some(half) => surface.evaluate_lattice_positions_on_edges_refining(
                                    tri, level, &half, points,
                                ),
                                None => {
                                    surface.evaluate_lattice_positions_on_edges(tri, level, points)
                                }
                            }
                            curvature.read(points, level);
                            // At the pattern's own inner level the lattice's interior is the
                            // output's, if the counts stay.
                            if factor == 1 && level == model.inner() {
                                if let Some(holding) = holding {
                                    holding.offer(tri, level, points);
                                }
                            }
                        }
                        // Stages 0 and 2 compare passing parts with the tolerance and use the
                        // value of failing ones only; stage 1 also asks whether its bound of the
                        // finer check passes, which parts under `skip_floors` do whatever their
                        // value.
                        let inner = curvature.inner_error(model.inner());
                        let deciding = DecidingParts::new(model.key(), inner, predicted, cap);
                        let floors = if factor == 1 {
                            // The spread is needed where this check passes, or may pass when
                            // restored with its inner level as it is (its inner lattice passes).
                            if read && inner <= predicted {
                                curvature.measure_spread(points);
                            }
                            model.skip_floors(inner, predicted, curvature.spread())
                        } else {
                            [predicted; 3]
                        };
                        let error = model.error_deciding(curvature, floors, predicted, |failed| {
                            deciding.needed(failed)
                        });
                        if factor == 1 {
                            let finer = model.bound(&error, curvature.spread());
                            // What the bound adds to the inner error is the lattice's roughness;
                            // a spread not measured here (the inner lattice failed) leaves the
                            // last one measured.
                            let growth = model.inner_growth(curvature.spread());
                            if !growth.is_nan() {
                                rough[tri].store(growth > ROUGH * predicted, Ordering::Relaxed);
                            }
                            let skip = if finer.within(predicted) { key } else { 0 };
                            resolved[tri].store(skip, Ordering::Relaxed);
                            let twice = check_level(model.inner(), 2) == 2 * level;
                            coarse.note(
                                tri,
                                (skip == 0 && twice).then_some((level, read, &points[..])),
                            );
                        }
                        // A failing triangle is checked again next round; a passing one may be
                        // when a neighbour is raised. The latter keeps its lattice's second
                        // differences only where the lattice is at most twice the pattern's level
                        // (not a flat part's probe-level lattice), so what is held stays within a
                        // few times the output's own interior points.
                        if !from_probe && (!error.within(predicted) || level <= 2 * model.inner()) {
                            curvature.keep(keep);
                        }
                        error
                    },
                );
            }
        };
        // Stage 3, the measurement, from the triangles `first` on.
        let measurement = |counts: &mut SegmentCounts, first: Vec<usize>| {
            counts.raise_until_met(
                topo,
                tolerance,
                cap,
                first,
                |key| {
                    let pattern = kept_patterns::pattern(key);
                    let boundary = (key.inner > MEASURED_UP_TO).then(|| {
                        [Reach::Corners, Reach::Edges]
                            .map(|reach| BoundaryTriangles::new(&pattern, reach))
                    });
                    (pattern, boundary)
                },
                |tri, (pattern, boundary), samples, _: &[()], _: &mut Vec<()>| match boundary {
                    Some([at_corners, along_edges]) => {
                        // Where stage 1 resolved this very pattern (the bound of its check at
                        // twice the resolution passed), the model holds up to the corner
                        // triangles; elsewhere every boundary triangle is measured (`Reach`),
                        // and where the lattice is rough every triangle, once the boundary
                        // passes: its edges are raised first at the boundary's cost alone.
                        let rough = rough[tri].load(Ordering::Relaxed);
                        let smooth = resolved[tri].load(Ordering::Relaxed) == pack(pattern.key);
                        let measured = if smooth && !rough {
                            at_corners
                        } else {
                            along_edges
                        };
                        let boundary = boundary_error(surface, tri, measured, samples);
                        if rough && boundary.within(tolerance) {
                            measured_error(surface, tri, pattern, samples)
                        } else {
                            boundary
                        }
                    }
                    None => measured_error(surface, tri, pattern, samples),
                },
            );
        };
        // The lattice stages, then the measurement, again while the measurement raises counts
        // (see the docs above); each pass checks only the triangles whose patterns changed
        // since that stage last saw them.
        let mut recheck: Vec<usize> = (0..counts.inner.len()).collect();
        // Each triangle's key and roughness as the measurement last settled on them (none
        // before the first): a pattern the measurement raised to is first seen by stage 1 in
        // the next pass, which may find it rough, and it is then measured again at every
        // output triangle, its key unchanged (2CylinderEngineDraco at 2e-4: an interior at 1.11
        // of the tolerance otherwise).
        let states = |keys: &[PatternKey]| -> Vec<(PatternKey, bool)> {
            keys.iter()
                .copied()
                .zip(&rough)
                .map(|(k, r)| (k, r.load(Ordering::Relaxed)))
                .collect()
        };
        let mut measured: Option<Vec<(PatternKey, bool)>> = None;
        for pass in 0..MEASURED_PASSES {
            let factors: &[u32] = if pass == 0 { &[0, 1, 2] } else { &[1, 2] };
            lattice_stages(&mut counts, factors, &recheck);
            let before = counts.keys(topo);
            let remeasure = match &measured {
                Some(measured) => changed(measured, &states(&before)),
                None => std::mem::take(&mut recheck),
            };
            measurement(&mut counts, remeasure);
            let after = counts.keys(topo);
            recheck = changed(&before, &after);
            if recheck.is_empty() {
                break;
            }
            measured = Some(states(&after));
        }
        coarsen(&mut counts, topo, surface, tolerance, MEASURED_UP_TO);
        counts
    }

    /// The smallest tolerance (and its counts) whose output has at most `budget` triangles, by
    /// bisection on the tolerance with the counts alone; when even one segment everywhere is
    /// over the budget, those counts; when the counts at the noise floor (or at the cap)
    /// fit, those, so a flat mesh keeps one segment per edge whatever the budget.
    pub fn for_budget(&self, topo: &Topology, budget: u64, cap: u32) -> (f64, SegmentCounts) {
        let largest = self
            .triangles
            .iter()
            .chain(&self.edges)
            .fold(0.0f64, |a, &b| a.max(b));
        if largest <= 0.0 {
            return (0.0, self.counts(topo, 1.0, cap));
        }
        // At `hi` every count is 1 (the margin of `counts` included); at `lo` every count is
        // `cap`, or the tolerance is at the noise floor: when that fits, it is the answer (the
        // smallest counts reaching the finest tolerance that means anything), not the budget.
        let (mut lo, mut hi) = (
            (largest / (4.0 * f64::from(cap * cap))).max(self.floor),
            largest * MARGIN * 1.01,
        );
        let mut best = (hi, self.counts(topo, hi, cap));
        if best.1.triangle_count(topo) > budget {
            return best;
        }
        let finest = self.counts(topo, lo, cap);
        if finest.triangle_count(topo) <= budget {
            return (lo, finest);
        }
        for _ in 0..48 {
            let mid = (lo * hi).sqrt();
            let counts = self.counts(topo, mid, cap);
            if counts.triangle_count(topo) <= budget {
                best = (mid, counts);
                hi = mid;
            } else {
                lo = mid;
            }
            if hi / lo < 1.0 + 1e-6 {
                break;
            }
        }
        best
    }
}

/// The lattices stage 1 of [`ChordErrors::refine_to_tolerance`] read on triangles it left for
/// stage 2, which reads the lattice of twice their level: its even points are those of the
/// kept one, bit for bit ([`Surface::evaluate_lattice_positions_on_edges_refining`]), a
/// quarter of its points (on the 10k icosphere at the error level 16 reaches, 212,000 of
/// stage 2's 847,020). Only the last check of each triangle decides: a triangle stage 1
/// resolves frees what it kept, so what is held is the lattices of the triangles stage 2 will
/// check (1,420 there, about 11 MB), and none once stage 2 has read them. A table by triangle
/// rather than a slot per triangle, so that a mesh whose triangles nearly all resolve in stage
/// 1 pays for the few it keeps (a slot per triangle was 40 bytes each: 40 MB at 1M).
struct Coarse(Mutex<KeptLattices>);

/// [`Coarse`]'s lattices by triangle.
type KeptLattices = HashMap<u32, KeptLattice, BuildHasherDefault<KeyHasher>>;

/// A whole lattice as a check read it, and its level.
type KeptLattice = (u32, Vec<SurfacePoint>);

impl Coarse {
    fn new() -> Coarse {
        Coarse(Mutex::new(HashMap::default()))
    }

    fn lattices(&self) -> std::sync::MutexGuard<'_, KeptLattices> {
        self.0.lock().expect("no check panics while keeping")
    }

    /// After a stage-1 check of `tri`: `Some((level, read, points))` when stage 2 will check
    /// it at twice `level`, `points` the level-`level` lattice if this check `read` it
    /// (else the one kept, if of that level, stays); `None` when stage 2 will not check it at
    /// twice this level, which frees what was kept.
    fn note(&self, tri: usize, kept: Option<(u32, bool, &[SurfacePoint])>) {
        let tri = tri as u32;
        let mut lattices = self.lattices();
        match kept {
            Some((level, true, points)) => {
                let (l, held) = lattices.entry(tri).or_default();
                *l = level;
                held.clear();
                held.extend_from_slice(points);
            }
            Some((level, false, _)) => {
                if lattices.get(&tri).is_some_and(|(l, _)| *l != level) {
                    lattices.remove(&tri);
                }
            }
            None => {
                lattices.remove(&tri);
            }
        }
    }

    /// For a stage-2 read of `tri`'s level-`level` lattice, the kept lattice of half its
    /// level, if any; what is kept is freed either way (a later check of the triangle is at
    /// another level, or restores what it read).
    fn take(&self, tri: usize, factor: u32, level: u32) -> Option<Vec<SurfacePoint>> {
        if factor != 2 {
            return None;
        }
        let kept = self.lattices().remove(&(tri as u32));
        kept.filter(|(l, _)| 2 * l == level)
            .map(|(_, points)| points)
    }
}

/// The hash of [`SegmentCounts::raise_until_met`]'s table of built keys, looked up twice per
/// check (a key that changed, then the check's own): a multiply-rotate over the key's bytes
/// instead of the default SipHash, which was about 200 instructions a lookup (41M of the 10k
/// icosphere's run at the error level 16 reaches); also [`Coarse`]'s, by triangle index. The
/// keys are counts and indices, not input an attacker picks, and the tables are only looked
/// up, never walked, so nothing depends on the hash's values.
#[derive(Debug, Default)]
struct KeyHasher(u64);

impl Hasher for KeyHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(5) ^ u64::from(b)).wrapping_mul(0x517c_c1b7_2722_0a95);
        }
    }

    #[inline]
    fn write_u32(&mut self, x: u32) {
        self.0 = (self.0.rotate_left(5) ^ u64::from(x)).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    #[inline]
    fn write_usize(&mut self, x: usize) {
        self.0 = (self.0.rotate_left(5) ^ x as u64).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// A pattern key as one nonzero number (every count is between 1 and 255).
fn pack(key: PatternKey) -> u64 {
    let [a, b, c] = key.edges.map(u64::from);
    a | b << 8 | c << 16 | u64::from(key.inner) << 24 | u64::from(key.fill) << 32
}

/// A failing count `c` raised by the square root of its part's error ratio, rounded up: at
/// least one step, at most `cap`.
fn scaled(c: u32, error: f64, tolerance: f64, cap: u32) -> u32 {
    let n = (f64::from(c) * (error / tolerance).sqrt()).ceil() as u32;
    n.max(c + 1).min(cap)
}

/// What [`SegmentCounts::raise_until_met`] makes of one failing check of the pattern `key`:
/// the triangle's new inner level, and the count each edge is raised to at least (0: not
/// raised). Counts come from the key, the counts of the round the check was made in.
///
/// A failing part is raised where the step that fails is (see [`EdgeStep`]); coarse edges go
/// first: a corner triangle touches both its edges and fails with the coarser, and raising the
/// finer one too by the same ratio overshoots (50×20 torus at 1e-4: 132,800 triangles with
/// both raised, 119,500 with the coarse edge first).
fn raise_of(key: PatternKey, error: &PatternError, tolerance: f64, cap: u32) -> (u32, [u32; 3]) {
    let (inner_level, finest, steps) = edge_steps(key, error.inner, tolerance, cap);
    let mut inner = inner_level;
    let fails = |k: usize| error.edges[k] > tolerance;
    // While an edge below the inner level fails, the finer ones wait.
    let coarse_fails = (0..3).any(|k| fails(k) && steps[k] == EdgeStep::Coarse);
    let mut edges = [0; 3];
    for k in (0..3).filter(|&k| fails(k)) {
        let e = key.edges[k];
        match steps[k] {
            _ if coarse_fails && steps[k] != EdgeStep::Coarse => {}
            // An edge below its triangle's inner level is raised to that level at most: the
            // uniform lattice there meets what the lattice check already passed.
            EdgeStep::Coarse => {
                edges[k] = scaled(e, error.edges[k], tolerance, cap).min(inner_level)
            }
            // The edge is at least as fine as the inner level: its ring triangles reach one
            // inner step across it, so that step is what fails. The inner level is raised, to
            // the finest edge at most (the uniform lattice of that count).
            EdgeStep::Inner => {
                inner = inner.max(scaled(inner_level, error.edges[k], tolerance, cap).min(finest));
            }
            EdgeStep::Edge => edges[k] = scaled(e, error.edges[k], tolerance, cap),
        }
    }
    (inner, edges)
}

/// What [`SegmentCounts::raise_until_met`] raises for a failing edge part, from the edge's
/// count, the triangle's inner level after its own inner part's raise, and its finest edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum EdgeStep {
    /// The edge is coarser than the inner level: the edge, to that level at most.
    Coarse,
    /// The edge is at least as fine as the inner level, which is below the finest edge: the
    /// inner level, to the finest edge at most.
    Inner,
    /// All at one level: the edge, by its error ratio.
    Edge,
}

/// The inner level of a check of `key` after its inner part's raise (its error
/// `inner_error`), the finest edge, and each edge part's [`EdgeStep`].
fn edge_steps(
    key: PatternKey,
    inner_error: f64,
    tolerance: f64,
    cap: u32,
) -> (u32, u32, [EdgeStep; 3]) {
    let inner_level = if inner_error > tolerance {
        scaled(key.inner, inner_error, tolerance, cap)
    } else {
        key.inner
    };
    let finest = key.edges.into_iter().max().unwrap_or(1);
    let steps = key.edges.map(|edge| {
        if edge < inner_level {
            EdgeStep::Coarse
        } else if inner_level < finest {
            EdgeStep::Inner
        } else {
            EdgeStep::Edge
        }
    });
    (inner_level, finest, steps)
}

/// Which edge parts of a check can still change what the raise does with its triangle, once
/// some are known to fail: what lets a check stop reading samples
/// ([`PatternModel::error_deciding`]) with the same counts after the raise as with every part's
/// exact value.
///
/// A part whose raise is one step at most (a coarse edge one below the inner level, or the
/// inner level one below the finest edge) raises the same count whatever its error over the
/// tolerance, since a raise is at least one step; every part of the inner kind then raises the
/// inner level to the same finest edge, so once one has failed the others change nothing; and
/// once a coarse edge fails the finer ones are not raised at all. On the 10k icosphere at the
/// error level 16 reaches, the wave's checks of a triangle whose edge a neighbour raised (edges
/// `[e + 1, e, e]` around `e`, then around `e + 1`) mostly fail in the first ring read, and stop
/// there.
#[derive(Debug, Clone, Copy)]
struct DecidingParts {
    steps: [EdgeStep; 3],
    /// Per part: its raise is the same for any error over the tolerance.
    settled_by_failing: [bool; 3],
}

impl DecidingParts {
    /// For a check of `key` whose inner part's error is `inner_error`, against `tolerance`.
    fn new(key: PatternKey, inner_error: f64, tolerance: f64, cap: u32) -> DecidingParts {
        let (inner_level, finest, steps) = edge_steps(key, inner_error, tolerance, cap);
        let settled_by_failing = [0, 1, 2].map(|k| match steps[k] {
            EdgeStep::Coarse => key.edges[k] + 1 >= inner_level,
            EdgeStep::Inner => inner_level + 1 >= finest,
            EdgeStep::Edge => false,
        });
        DecidingParts {
            steps,
            settled_by_failing,
        }
    }

    /// The parts (bit `k`: edge `k`) whose value can still change the raise once those in
    /// `failed` are known to be over the tolerance.
    fn needed(&self, failed: u8) -> u8 {
        let failing = |k: usize| failed & (1 << k) != 0;
        let failed_as = |step: EdgeStep| (0..3).any(|k| failing(k) && self.steps[k] == step);
        let coarse_failed = failed_as(EdgeStep::Coarse);
        let inner_settled = (0..3)
            .any(|k| failing(k) && self.steps[k] == EdgeStep::Inner && self.settled_by_failing[k]);
        (0..3)
            .filter(|&k| {
                let decided = failing(k) && self.settled_by_failing[k];
                let waits = coarse_failed && self.steps[k] != EdgeStep::Coarse;
                let same_as_failed = inner_settled && self.steps[k] == EdgeStep::Inner;
                !(decided || waits || same_as_failed)
            })
            .fold(0, |mask, k| mask | 1 << k)
    }
}

/// The levels of [`ChordErrors::flooded_levels`] from per-triangle levels `inner` (0: not
/// taking part): edges take the finer of their triangles', and a taking-part triangle whose
/// level `lacks_slack` for a transition pattern takes its finest edge's, until nothing
/// moves. Rounds in step: every triangle decides on the edges as its round found them.
fn flood(
    topo: &Topology,
    mut inner: Vec<u32>,
    lacks_slack: impl Fn(usize, u32) -> bool,
) -> (Vec<u32>, Vec<u32>) {
    let mut edges = vec![0u32; topo.edge_count()];
    for (&n, tri_edges) in inner.iter().zip(&topo.tri_edges) {
        for e in tri_edges {
            let count = &mut edges[e.0 as usize];
            *count = (*count).max(n);
        }
    }
    // Rounds in step (every triangle decides on the edges as the round found them); after
    // the first only triangles beside an edge the last round raised can move, so a round
    // costs what moved, whatever the distance the levels travel.
    let mut candidates: Vec<usize> = (0..inner.len()).collect();
    let mut touched = Touched::new(inner.len());
    loop {
        let moved: Vec<(usize, u32)> = candidates
            .iter()
            .filter_map(|&t| {
                let n = inner[t];
                let finest = topo.tri_edges[t].iter().map(|e| edges[e.0 as usize]).max();
                let finest = finest.unwrap_or(0);
                let moves = n > 0 && finest > n && lacks_slack(t, n);
                moves.then_some((t, finest))
            })
            .collect();
        if moved.is_empty() {
            return (inner, edges);
        }
        for &(t, n) in &moved {
            inner[t] = n;
            for &e in &topo.tri_edges[t] {
                let count = &mut edges[e.0 as usize];
                if *count < n {
                    *count = n;
                    touched.edge(topo, e);
                }
            }
        }
        candidates = touched.take_sorted();
    }
}

/// The segments a part of error constant `c` needs for `tolerance` with `margin`:
/// `⌈√(margin · c / tolerance)⌉`, between 1 and `cap`.
fn segments_for(c: f64, tolerance: f64, cap: u32, margin: f64) -> u32 {
    let n = (margin * c / tolerance).sqrt().ceil();
    if n.is_nan() || n < 1.0 {
        1
    } else {
        n.min(f64::from(cap)) as u32
    }
}

/// The smallest inner level a triangle whose finest edge has `max_edge` segments may have:
/// `⌈2·max_edge/3⌉`, so no edge has more than 1.5 times the inner level's segments. Over every
/// pattern this allows with inner levels up to 20 (edges at least half the inner level) the
/// worst minimum angle in the domain is 19.1°, `atan(√3/5)` (edges 3, 3, 2 around an inner level
/// of 2, and every edge at 1.5 times the inner level); with edges up to twice the inner level
/// the stitched rings hold slivers (0.2° at 32 against 16). `transition.rs`'s tests check it.
pub(crate) fn inner_floor(max_edge: u32) -> u32 {
    (2 * max_edge).div_ceil(3).max(1)
}

/// The inner level a triangle starts from when its interior needs `need` by its chord-error
/// constant: that level when it has an inner lattice (4 and up, where the inner lattice's
/// triangles have edges along all three lattice directions and meet the constant's error
/// exactly), else 1, so the balance sets it from the edges. Below 4 every triangle of the
/// pattern touches the boundary and the constant, the worst over the three lattice
/// directions, overstates what the pattern needs: on a torus a triangle curved along two edges
/// and flat along the third is filled from its edge samples by triangles running along the
/// flat direction (3 + 3 + 1 samples: 5 triangles, not the 9 of level 3). The checks raise it
/// where that is not enough.
fn initial_inner(need: u32) -> u32 {
    if need >= 4 {
        need
    } else {
        1
    }
}

fn finite(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// Largest second difference along each of the triangle's three edges (edge `k` opposite
/// corner `k`) of a level-`p` lattice of surface points, along the surface normal at its middle
/// point (the component the chord error is measured in, `chord.rs`).
fn edge_second_differences(points: &[SurfacePoint], p: u32) -> [f64; 3] {
    let at = |i: u32, j: u32| &points[lattice_index(p, i, j)];
    let d2 = |a: (u32, u32), b: (u32, u32), c: (u32, u32)| {
        let middle = at(b.0, b.1);
        let d = at(a.0, a.1).position - 2.0 * middle.position + at(c.0, c.1).position;
        d.dot(middle.normal).abs()
    };
    let mut edges = [0.0f64; 3];
    for m in 1..p {
        // Edge 2: j = 0; edge 1: i = 0; edge 0: i + j = p.
        edges[2] = edges[2].max(d2((m - 1, 0), (m, 0), (m + 1, 0)));
        edges[1] = edges[1].max(d2((0, m - 1), (0, m), (0, m + 1)));
        edges[0] = edges[0].max(d2((p - m + 1, m - 1), (p - m, m), (p - m - 1, m + 1)));
    }
    edges
}

impl SegmentCounts {
    /// Every edge and every interior at `level`: the uniform tessellation.
    pub fn uniform(topo: &Topology, level: u32) -> SegmentCounts {
        SegmentCounts {
            edges: vec![level; topo.edge_count()],
            inner: vec![level; topo.tri_edges.len()],
            fill: vec![0; topo.tri_edges.len()],
            pairs: Vec::new(),
        }
    }

    /// The pair source triangle `tri` belongs to, and which of its two triangles it is, from a
    /// table of [`SegmentCounts::pair_table`].
    #[inline]
    pub(crate) fn pair_of<'a>(&'a self, table: &[u32], tri: usize) -> Option<(&'a Pair, usize)> {
        let index = *table.get(tri)?;
        let pair = self.pairs.get(index as usize)?;
        Some((pair, usize::from(pair.tris[1] as usize == tri)))
    }

    /// How many of the points inside source triangle `tri`'s pair (`rows.rs`) are its own, from
    /// a table of [`SegmentCounts::pair_table`]: 0 where it has none.
    #[inline]
    pub(crate) fn row_points_of(&self, table: &[u32], tri: usize) -> usize {
        self.pair_of(table, tri)
            .map_or(0, |(pair, side)| pair.interior_of(side))
    }

    /// Per source triangle, the index of its pair in [`SegmentCounts::pairs`] (`u32::MAX`:
    /// none); empty where there is no pair.
    pub(crate) fn pair_table(&self) -> Vec<u32> {
        if self.pairs.is_empty() {
            return Vec::new();
        }
        let mut table = vec![u32::MAX; self.inner.len()];
        for (i, pair) in self.pairs.iter().enumerate() {
            for &t in &pair.tris {
                table[t as usize] = i as u32;
            }
        }
        table
    }

    /// The pattern key of source triangle `tri`.
    #[inline]
    pub(crate) fn key(&self, topo: &Topology, tri: usize) -> PatternKey {
        PatternKey {
            edges: topo.tri_edges[tri].map(|e| self.edges[e.0 as usize]),
            inner: self.inner[tri],
            fill: self.fill[tri],
        }
    }

    /// Output triangles, from the counts alone.
    pub fn triangle_count(&self, topo: &Topology) -> u64 {
        let patterns: u64 = (0..self.inner.len())
            .map(|t| self.key(topo, t).triangle_count())
            .sum();
        // Two more per point inside a pair (`rows.rs`).
        patterns
            + self
                .pairs
                .iter()
                .map(|p| 2 * p.interior.len() as u64)
                .sum::<u64>()
    }

    /// Largest count anywhere.
    pub fn max(&self) -> u32 {
        self.edges
            .iter()
            .chain(&self.inner)
            .copied()
            .max()
            .unwrap_or(1)
    }

    /// Checks the patterns of the triangles `first` (ascending) with `check` (on what `build`
    /// makes of its key, built once per distinct key) and raises the counts of their failing
    /// parts until none fails or they are at `cap`; after the first round only triangles whose
    /// counts changed are checked.
    ///
    /// A failing check raises what [`raise_of`] says.
    ///
    /// `check` gets a per-thread scratch `S`, what the triangle's previous check kept (empty if
    /// none), and a buffer to append what its next check could reuse; that is held until the
    /// triangle is checked again, whether it passed or failed. A failing triangle is checked
    /// again next round, most often with only its edge counts raised, and a passing one when a
    /// failing neighbour raises the edge they share (the wave of raised counts across an evenly
    /// curved mesh: on the 10k icosphere at the error level 16 reaches, re-evaluating their
    /// lattices was a third of the first stage's 33,424); what to keep, and so the memory held,
    /// is the check's choice.
    fn raise_until_met<P: Send + Sync, S: Default + Send, K: Copy + Send + Sync>(
        &mut self,
        topo: &Topology,
        tolerance: f64,
        cap: u32,
        first: Vec<usize>,
        build: impl Fn(PatternKey) -> P + Sync,
        check: impl Fn(usize, &P, &mut S, &[K], &mut Vec<K>) -> PatternError + Sync,
    ) {
        let mut checked: Vec<Option<PatternKey>> = vec![None; self.inner.len()];
        // What each triangle's last check kept (empty: nothing).
        let mut kept: Vec<Vec<K>> = (0..self.inner.len()).map(|_| Vec::new()).collect();
        // Every key built so far, for all rounds: as the counts settle the same few keys come
        // back round after round (on the 10k icosphere at the error level 16 reaches, 502
        // builds over the stages), and a build depends on its key alone.
        let mut built: HashMap<PatternKey, P, BuildHasherDefault<KeyHasher>> = HashMap::default();
        // The triangles whose counts may have changed since their last check, ascending; a
        // round costs what they are, not the mesh (on a long tube the raise crosses it one ring
        // per round, thousands of rounds).
        let mut touched = Touched::new(self.inner.len());
        let mut dirty = first;
        loop {
            let to_check: Vec<(usize, PatternKey)> = dirty
                .iter()
                .map(|&t| (t, self.key(topo, t)))
                .filter(|(t, k)| checked[*t].as_ref() != Some(k))
                .collect();
            let mut distinct: Vec<PatternKey> = to_check
                .iter()
                .map(|&(_, k)| k)
                .filter(|k| !built.contains_key(k))
                .collect();
            distinct.sort_unstable();
            distinct.dedup();
            let fresh: Vec<P> = distinct.par_iter().map(|&k| build(k)).collect();
            built.extend(distinct.into_iter().zip(fresh));
            // Per checked triangle, in order: its errors and what it kept, if anything.
            let results: Vec<(usize, PatternError, Vec<K>)> = to_check
                .par_iter()
                .map_init(S::default, |scratch, &(t, key)| {
                    let p = built.get(&key).expect("every key to check was built");
                    let mut keep = Vec::new();
                    let error = check(t, p, scratch, &kept[t], &mut keep);
                    (t, error, keep)
                })
                .collect();
            let mut over: Vec<(usize, PatternError)> = Vec::new();
            for (t, error, keep) in results {
                if error.inner > tolerance || error.edges.iter().any(|&e| e > tolerance) {
                    over.push((t, error));
                }
                kept[t] = keep;
            }
            // Each failing part scales its count from this round's counts; an edge between two
            // failing triangles takes the larger, not both in turn.
            let mut raised = false;
            for (t, error) in over {
                let key = checked_key(&to_check, t);
                let (inner, edges) = raise_of(key, &error, tolerance, cap);
                raised |= inner > self.inner[t];
                if inner != self.inner[t] {
                    touched.triangle(t);
                }
                self.inner[t] = inner;
                for (e, next) in topo.tri_edges[t].into_iter().zip(edges) {
                    let count = &mut self.edges[e.0 as usize];
                    if next > *count {
                        raised = true;
                        *count = next;
                        touched.edge(topo, e);
                    }
                }
            }
            for &(t, k) in &to_check {
                checked[t] = Some(k);
            }
            if !raised {
                return;
            }
            let seeds = touched.pending();
            self.balance_from(topo, seeds, &mut touched);
            dirty = touched.take_sorted();
        }
    }

    /// Every triangle's pattern key, in triangle order.
    fn keys(&self, topo: &Topology) -> Vec<PatternKey> {
        (0..self.inner.len()).map(|t| self.key(topo, t)).collect()
    }

    /// Applies the two balance rules of the module docs until neither raises anything.
    fn balance(&mut self, topo: &Topology) {
        let mut touched = Touched::new(self.inner.len());
        self.balance_from(topo, (0..self.inner.len()).collect(), &mut touched);
    }

    /// [`SegmentCounts::balance`] where only the triangles `seeds` (and those their raises
    /// reach) can break a rule: a worklist, so the cost follows what changes. Both rules only
    /// raise, each to a value that grows with the others (an inner level to the floor of its
    /// finest edge, an edge to half the finer inner level beside it), so in any order they
    /// settle on the same counts: the least ones at or above the start that keep both. Every
    /// triangle whose counts change is noted in `touched`.
    fn balance_from(&mut self, topo: &Topology, seeds: Vec<usize>, touched: &mut Touched) {
        let mut work = seeds;
        while let Some(t) = work.pop() {
            let finest = topo.tri_edges[t]
                .iter()
                .map(|e| self.edges[e.0 as usize])
                .max()
                .unwrap_or(1);
            let need = inner_floor(finest);
            if self.inner[t] < need {
                self.inner[t] = need;
                touched.triangle(t);
            }
            let half = self.inner[t].div_ceil(2);
            for &e in &topo.tri_edges[t] {
                let count = &mut self.edges[e.0 as usize];
                if *count < half {
                    *count = half;
                    touched.edge(topo, e);
                    work.extend(topo.edge_uses(e).iter().map(|u| u.tri().0 as usize));
                }
            }
        }
    }
}

/// The triangles whose counts changed (their inner level, or an edge of theirs), each once.
struct Touched {
    marked: Vec<bool>,
    list: Vec<usize>,
}

impl Touched {
    fn new(triangles: usize) -> Touched {
        Touched {
            marked: vec![false; triangles],
            list: Vec::new(),
        }
    }

    fn triangle(&mut self, t: usize) {
        if !std::mem::replace(&mut self.marked[t], true) {
            self.list.push(t);
        }
    }

    fn edge(&mut self, topo: &Topology, e: EdgeId) {
        for u in topo.edge_uses(e) {
            self.triangle(u.tri().0 as usize);
        }
    }

    /// The triangles noted so far, still noted.
    fn pending(&self) -> Vec<usize> {
        self.list.clone()
    }

    /// The triangles noted, ascending, and forgets them.
    fn take_sorted(&mut self) -> Vec<usize> {
        let mut list = std::mem::take(&mut self.list);
        for &t in &list {
            self.marked[t] = false;
        }
        list.sort_unstable();
        list
    }
}

/// The key triangle `t` was checked with this round (`to_check` is ascending by triangle).
fn checked_key(to_check: &[(usize, PatternKey)], t: usize) -> PatternKey {
    let at = to_check
        .binary_search_by_key(&t, |&(u, _)| u)
        .expect("a failing triangle was checked");
    to_check[at].1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What an early stop of [`PatternModel::error_deciding`] may leave of `exact` when the
    /// parts are read in `order`, each `needed` one until it is known to fail: a failed part
    /// just over the tolerance, a part never read anything up to its value (here `fraction` of
    /// it, at most the tolerance, as an unread part is never known to fail), and a part read to
    /// its end its exact value.
    fn stopped_early(
        deciding: &DecidingParts,
        exact: &PatternError,
        tolerance: f64,
        order: [usize; 3],
        fraction: f64,
    ) -> (PatternError, bool) {
        let mut partial = PatternError {
            inner: exact.inner,
            edges: exact.edges.map(|e| fraction * e.min(tolerance)),
        };
        let (mut failed, mut skipped) = (0u8, false);
        for k in order {
            if deciding.needed(failed) & (1 << k) == 0 {
                skipped = true;
                continue;
            }
            partial.edges[k] = exact.edges[k];
            if exact.edges[k] > tolerance {
                failed |= 1 << k;
                // Read until known to fail, and on only while still needed.
                if deciding.needed(failed) & (1 << k) == 0 {
                    partial.edges[k] = exact.edges[k].min(tolerance * (1.0 + 1e-9));
                }
            }
        }
        (partial, skipped)
    }

    /// A check that stops once [`DecidingParts`] says nothing left can change the raise leaves
    /// the raise as every part's exact value does: over keys the balance allows, errors on
    /// both sides of the tolerance and at several distances over it (so that valued raises,
    /// one step and several steps, all occur), every order the parts can be read in, and
    /// unread parts at any value up to their own.
    #[test]
    fn stopping_where_nothing_is_left_to_decide_leaves_the_raise_as_it_is() {
        let tolerance = 1e-4;
        let ratios = [0.3, 1.0, 1.001, 1.3, 2.0, 5.0];
        let orders: Vec<[usize; 3]> = (0..27)
            .map(|i| [i % 3, (i / 3) % 3, i / 9])
            .filter(|[a, b, c]| a != b && b != c && a != c)
            .collect();
        let (mut checks, mut stopped) = (0usize, 0usize);
        for cap in [9, 255] {
            for inner in 1..=8u32 {
                for edges in (0..512u32).map(|i| [i & 7, (i >> 3) & 7, i >> 6].map(|c| c + 1)) {
                    let finest = edges.into_iter().max().unwrap_or(1);
                    if inner < inner_floor(finest) || edges.iter().any(|&e| 2 * e < inner) {
                        continue;
                    }
                    let key = PatternKey {
                        edges,
                        inner,
                        fill: 0,
                    };
                    for inner_ratio in [0.5, 1.7] {
                        for i in 0..ratios.len().pow(3) {
                            let n = ratios.len();
                            let r = [i % n, (i / n) % n, i / (n * n)].map(|j| ratios[j]);
                            let exact = PatternError {
                                inner: inner_ratio * tolerance,
                                edges: r.map(|x| x * tolerance),
                            };
                            let deciding = DecidingParts::new(key, exact.inner, tolerance, cap);
                            let expected = raise_of(key, &exact, tolerance, cap);
                            for &order in &orders {
                                for fraction in [0.0, 1.0] {
                                    let (partial, skipped) = stopped_early(
                                        &deciding, &exact, tolerance, order, fraction,
                                    );
                                    assert_eq!(
                                        raise_of(key, &partial, tolerance, cap),
                                        expected,
                                        "{key:?} cap {cap}: {exact:?} read as {partial:?}"
                                    );
                                    checks += 1;
                                    stopped += usize::from(skipped);
                                }
                            }
                        }
                    }
                }
            }
        }
        assert!(
            stopped > checks / 10,
            "{stopped} of {checks} reads stopped early"
        );
    }

    /// A small deterministic generator for the tests below.
    fn lcg(seed: u64) -> impl FnMut(u32) -> u32 {
        let mut state = seed;
        move |n| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) % u64::from(n)) as u32
        }
    }

    /// The rules swept over every triangle and edge until neither raises anything: the
    /// balance as first written, which the worklist must match.
    fn balanced_by_sweeps(counts: &mut SegmentCounts, topo: &Topology) {
        loop {
            let mut changed = false;
            for (inner, edges) in counts.inner.iter_mut().zip(&topo.tri_edges) {
                let finest = edges.iter().map(|e| counts.edges[e.0 as usize]).max();
                let need = inner_floor(finest.unwrap_or(1));
                if *inner < need {
                    *inner = need;
                    changed = true;
                }
            }
            for (&inner, edges) in counts.inner.iter().zip(&topo.tri_edges) {
                for e in edges {
                    let count = &mut counts.edges[e.0 as usize];
                    if *count < inner.div_ceil(2) {
                        *count = inner.div_ceil(2);
                        changed = true;
                    }
                }
            }
            if !changed {
                return;
            }
        }
    }

    /// The worklist balance gives the sweeps' counts, from scratch and from a few raised
    /// counts with only the triangles they touch as seeds, and notes every triangle whose
    /// counts it changed; on meshes with books, fans and open edges.
    #[test]
    fn the_worklist_balance_settles_where_the_sweeps_do() {
        for seed in 0..40u64 {
            let topo = Topology::build(&crate::topology::tests::odd_mesh(
                seed,
                30 + 11 * seed as usize,
            ));
            let mut next = lcg(seed);
            let mut counts = SegmentCounts::uniform(&topo, 1);
            counts.edges.iter_mut().for_each(|c| *c = 1 + next(24));
            counts.inner.iter_mut().for_each(|c| *c = 1 + next(24));
            let mut swept = counts.clone();
            balanced_by_sweeps(&mut swept, &topo);
            counts.balance(&topo);
            assert_eq!(counts, swept, "seed {seed}: from scratch");

            let before = counts.clone();
            let mut touched = Touched::new(counts.inner.len());
            for _ in 0..3 {
                let t = next(counts.inner.len() as u32) as usize;
                counts.inner[t] += 1 + next(20);
                touched.triangle(t);
                let e = topo.tri_edges[t][next(3) as usize];
                counts.edges[e.0 as usize] += 1 + next(30);
                touched.edge(&topo, e);
            }
            let mut swept = counts.clone();
            balanced_by_sweeps(&mut swept, &topo);
            let seeds = touched.pending();
            counts.balance_from(&topo, seeds, &mut touched);
            assert_eq!(counts, swept, "seed {seed}: from raised counts");
            let noted = touched.take_sorted();
            for t in 0..counts.inner.len() {
                let changed = counts.key(&topo, t) != before.key(&topo, t);
                assert!(
                    !changed || noted.binary_search(&t).is_ok(),
                    "seed {seed}: {t} not noted"
                );
            }
        }
    }

    /// The flood's worklist rounds give the levels of rounds over every triangle in step, for
    /// a slack that depends on the triangle and its level (so the order of moves matters).
    #[test]
    fn the_flood_moves_as_rounds_over_every_triangle_do() {
        let mut moved_in_all = 0;
        for seed in 0..40u64 {
            let topo = Topology::build(&crate::topology::tests::odd_mesh(
                seed,
                30 + 11 * seed as usize,
            ));
            let mut next = lcg(seed + 1000);
            let start: Vec<u32> = topo
                .tri_edges
                .iter()
                .map(|_| if next(3) == 0 { 0 } else { 13 + next(8) })
                .collect();
            let lacks = |t: usize, n: u32| (t as u32 * 7 + n * 3) % 5 != 0;
            let mut inner = start.clone();
            let mut edges = vec![0u32; topo.edge_count()];
            loop {
                for (&n, tri_edges) in inner.iter().zip(&topo.tri_edges) {
                    for e in tri_edges {
                        edges[e.0 as usize] = edges[e.0 as usize].max(n);
                    }
                }
                let mut changed = false;
                for (t, (n, tri_edges)) in inner.iter_mut().zip(&topo.tri_edges).enumerate() {
                    let finest = tri_edges
                        .iter()
                        .map(|e| edges[e.0 as usize])
                        .max()
                        .unwrap_or(0);
                    if *n > 0 && finest > *n && lacks(t, *n) {
                        *n = finest;
                        changed = true;
                    }
                }
                if !changed {
                    break;
                }
            }
            let moved = inner.iter().zip(&start).filter(|(a, b)| a != b).count();
            moved_in_all += moved;
            assert_eq!(
                flood(&topo, start, lacks),
                (inner, edges),
                "seed {seed} ({moved} moved)"
            );
        }
        assert!(moved_in_all > 100, "the cases move little: {moved_in_all}");
    }
}
