//! Lowering counts the raise left higher than the tolerance needs, after it has settled.
//!
//! The raise of `counts.rs` only ever raises: a failing part is scaled by the square root of
//! its error ratio and rounded up, and the balance rules lift its neighbours with it, so a
//! count can end one or more steps above what its patterns need (on a torus a tube edge at 3
//! segments where its curve needs 2.1, because a ring triangle beside it failed at 2). Here
//! each count is tried one step lower, an edge's count or a triangle's inner level, and kept
//! there when every pattern it belongs to still measures within the tolerance.
//!
//! Only patterns that the raise measures at every output triangle (inner level up to
//! `MEASURED_UP_TO` of `counts.rs`) take part, before and after the step, so the check that
//! keeps a step is the one the raise ends with on those patterns: the chord error along the
//! normal at seven points of every output triangle, on the vertices rounded to `f32` as written
//! (`chord.rs`). A triangle a step leaves without interior points whose default fill fails is
//! given, if there is one, a fill of its edge samples that passes (`fill.rs`), and the step
//! kept with it; its fill goes back with its counts when the step fails. Steps keep both
//! balance rules (an edge at least half the inner level of each triangle beside it, an inner
//! level at least [`inner_floor`] of its finest edge).
//!
//! Steps are tried in rounds. A round takes steps whose triangles are disjoint (a step is an
//! edge, touching the triangles beside it, or one triangle's inner level), chosen in a fixed
//! order, so that whether one step passes does not depend on another tried with it: the result
//! is the same at any thread count. A step that fails is tried again only once a triangle it
//! touches has changed. The rounds stop when no step is left to try, or after [`ROUNDS`].

use std::collections::HashMap;

use rayon::prelude::*;

use super::chord::{measured_within, written_vertices, Samples};
use super::counts::{inner_floor, SegmentCounts};
use super::fill::fill_within;
use super::kept_patterns::{self, Kept};
use super::transition::{Pattern, PatternKey};
use crate::surface::Surface;
use crate::topology::{EdgeId, Topology};

/// Most rounds of steps: each takes at most one step per triangle, and a triangle has four
/// counts (three edges, its inner level), so a few rounds try every step once; more let steps
/// that failed beside a triangle that has since changed be tried again. A bound keeps the pass
/// linear in the mesh whatever its shape.
pub(crate) const ROUNDS: usize = 24;

/// One count one step lower.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Step {
    Edge(u32),
    Inner(u32),
}

/// Lowers `counts` by single steps while every pattern touched still measures at or below
/// `tolerance` (see the module docs); patterns of inner level above `measured_up_to` are left
/// as they are.
pub(crate) fn coarsen(
    counts: &mut SegmentCounts,
    topo: &Topology,
    surface: &dyn Surface,
    tolerance: f64,
    measured_up_to: u32,
) {
    let tris = counts.inner.len();
    // Per triangle, bumped whenever its pattern changes; a failed step remembers the sum over
    // the triangles it touches, and is tried again only once that has grown.
    let mut version = vec![0u64; tris];
    let mut failed_edge: Vec<Option<u64>> = vec![None; counts.edges.len()];
    let mut failed_inner: Vec<Option<u64>> = vec![None; tris];
    let mut built: HashMap<PatternKey, Kept<Pattern>> = HashMap::new();
    let mut busy = vec![false; tris];
    for _ in 0..ROUNDS {
        busy.iter_mut().for_each(|b| *b = false);
        let mut steps: Vec<Step> = Vec::new();
        // Inner levels first: one step of inner level M saves 2M − 4 triangles (2 from 3 to
        // 2), an edge's step one per triangle beside it.
        for t in 0..tris {
            let m = counts.inner[t];
            if m < 3 || m > measured_up_to || busy[t] {
                continue;
            }
            if failed_inner[t] == Some(version[t]) {
                continue;
            }
            let finest = topo.tri_edges[t]
                .iter()
                .map(|e| counts.edges[e.0 as usize])
                .max()
                .unwrap_or(1);
            if m - 1 < inner_floor(finest) {
                continue;
            }
            busy[t] = true;
            steps.push(Step::Inner(t as u32));
        }
        for (e, (&c, failed)) in counts.edges.iter().zip(&failed_edge).enumerate() {
            if c < 2 {
                continue;
            }
            let uses = topo.edge_uses(EdgeId(e as u32));
            let allowed = uses.iter().all(|u| {
                let t = u.tri().0 as usize;
                let m = counts.inner[t];
                !busy[t] && m <= measured_up_to && c > m.div_ceil(2)
            });
            if !allowed || uses.is_empty() {
                continue;
            }
            let sum: u64 = uses.iter().map(|u| version[u.tri().0 as usize]).sum();
            if *failed == Some(sum) {
                continue;
            }
            for u in uses {
                busy[u.tri().0 as usize] = true;
            }
            steps.push(Step::Edge(e as u32));
        }
        if steps.is_empty() {
            return;
        }
        for &step in &steps {
            match step {
                Step::Edge(e) => counts.edges[e as usize] -= 1,
                Step::Inner(t) => counts.inner[t as usize] -= 1,
            }
        }
        let touched = |step: Step| -> Vec<usize> {
            match step {
                Step::Edge(e) => topo
                    .edge_uses(EdgeId(e))
                    .iter()
                    .map(|u| u.tri().0 as usize)
                    .collect(),
                Step::Inner(t) => vec![t as usize],
            }
        };
        let mut checked: Vec<usize> = steps.iter().flat_map(|&s| touched(s)).collect();
        checked.sort_unstable();
        checked.dedup();
        // A triangle whose counts change starts from the default fill; its fill before is
        // restored if the step fails.
        let fills_before: Vec<u16> = checked
            .iter()
            .map(|&t| std::mem::take(&mut counts.fill[t]))
            .collect();
        let mut fresh: Vec<PatternKey> = checked
            .iter()
            .map(|&t| counts.key(topo, t))
            .filter(|k| !built.contains_key(k))
            .collect();
        fresh.sort_unstable();
        fresh.dedup();
        let patterns: Vec<Kept<Pattern>> = fresh
            .par_iter()
            .map(|&k| kept_patterns::pattern(k))
            .collect();
        built.extend(fresh.into_iter().zip(patterns));
        // Per checked triangle, its edge whose count its step lowers, if it is an edge's: the
        // check measures that edge's sides first.
        let mut lowered: Vec<Option<usize>> = vec![None; checked.len()];
        for &step in &steps {
            if let Step::Edge(e) = step {
                for t in touched(step) {
                    let at = checked.binary_search(&t).expect("checked");
                    lowered[at] = topo.tri_edges[t].iter().position(|x| x.0 == e);
                }
            }
        }
        // Per checked triangle, whether it passes and with which fill (0 unless the default
        // fill fails and one chosen by measured error passes); its points evaluated once for
        // every fill tried.
        let passes: Vec<Option<u16>> = checked
            .par_iter()
            .zip(&lowered)
            .map_init(Samples::default, |samples, (&t, &lowered)| {
                let key = counts.key(topo, t);
                let pattern = &built[&key];
                let vertices = written_vertices(surface, t, pattern, samples);
                let within = |pattern: &Pattern, lowered, samples: &mut Samples| {
                    measured_within(surface, t, pattern, &vertices, tolerance, lowered, samples)
                };
                let pass = if within(pattern, lowered, samples) {
                    Some(0)
                } else if key.inner >= 3 {
                    None
                } else {
                    fill_within(surface, t, key, &vertices, tolerance, samples).filter(|&fill| {
                        let filled = kept_patterns::pattern(PatternKey { fill, ..key });
                        within(&filled, None, samples)
                    })
                };
                samples.give_back(vertices);
                pass
            })
            .collect();
        let passes_at = |t: usize| passes[checked.binary_search(&t).expect("checked")];
        for &step in &steps {
            let on = touched(step);
            if on.iter().all(|&t| passes_at(t).is_some()) {
                for &t in &on {
                    version[t] += 1;
                    counts.fill[t] = passes_at(t).expect("passes");
                }
                continue;
            }
            for &t in &on {
                counts.fill[t] = fills_before[checked.binary_search(&t).expect("checked")];
            }
            let sum: u64 = on.iter().map(|&t| version[t]).sum();
            match step {
                Step::Edge(e) => {
                    counts.edges[e as usize] += 1;
                    failed_edge[e as usize] = Some(sum);
                }
                Step::Inner(t) => {
                    counts.inner[t as usize] += 1;
                    failed_inner[t as usize] = Some(sum);
                }
            }
        }
    }
}
