//! The fill of a pattern without interior chosen by measured chord error.
//!
//! A pattern whose inner level is 2 or less has no interior point: its output triangles
//! triangulate the convex polygon of its corners and edge samples (`transition.rs`). The
//! default fill cuts ears of largest minimum angle in the domain, which looks at the domain
//! alone: on a torus the triangles on either side of a ring edge are not mirror images in the
//! domain while the surface is mirrored across the equator, so the same default fill runs
//! across the direction of strong curvature on one side and along it on the other (edges 2,
//! 3, 3 around no interior: 9.5e-4 on one side of the outer equator, 1.3e-3 on the other).
//!
//! Here, where the default fill fails the tolerance, the fill is the triangulation whose
//! triangles all measure within it (the chord error of `chord.rs`, seven points per triangle on
//! the vertices rounded to `f32`) and keep the domain's minimum-angle floor (19.1°, the worst
//! of the default patterns the balance allows), with the largest smallest angle in space among
//! those. It is found by dynamic programming over the polygon's sub-polygons (the smallest
//! angle of a triangulation is the smallest of its apex triangle's and its two sub-polygons',
//! so each sub-polygon's best is best wherever it is used), a candidate triangle measured at
//! most once, and only where its error could change a sub-polygon's best (at most 84
//! candidates, for the 9 points of edges 3, 3, 3; on the Duck a quarter of them are measured,
//! which gives the choice that measuring all of them gives), and a side's midpoint sample once
//! for all the candidates that share that side. Its index in
//! [`triangulation`]'s order is the pattern key's `fill`, so the pattern is rebuilt from the
//! key alone wherever it is used. The choice is per source triangle and reads only its own
//! surface and its own edge samples (the same points its neighbour writes), so it is the same
//! at any thread count.

use glam::DVec3;

use super::chord::{angle_in_space, with_candidate_errors, Candidate, Samples};
use super::kept_patterns;
use super::transition::{
    min_angle, polygon, triangulation, triangulations, PatternKey, ANGLE_FLOOR,
};
use crate::surface::Surface;

/// The fill of `key` (its inner level at most 2) whose triangles on source triangle `tri` all
/// measure within `tolerance` and keep the floor, with the largest smallest angle in space;
/// `None` when there is none. `vertices` are the points of `key`'s counts as
/// [`written_vertices`](super::chord::written_vertices) gives them (the same for every fill).
pub(crate) fn fill_within(
    surface: &dyn Surface,
    tri: usize,
    key: PatternKey,
    vertices: &[DVec3],
    tolerance: f64,
    samples: &mut Samples,
) -> Option<u16> {
    let pattern = kept_patterns::pattern(PatternKey { fill: 0, ..key });
    let outer = polygon(&pattern);
    let n = outer.len();
    let at = |v: usize| pattern.domain(outer[v]);
    // Candidate triangles (lo < k < hi, counter-clockwise) keeping the floor.
    let mut candidates = Vec::new();
    let mut slot = vec![usize::MAX; n * n * n];
    for lo in 0..n {
        for k in lo + 1..n {
            for hi in k + 1..n {
                if min_angle(at(lo), at(k), at(hi)) >= ANGLE_FLOOR {
                    slot[(lo * n + k) * n + hi] = candidates.len();
                    candidates.push([lo, k, hi]);
                }
            }
        }
    }
    let points: Vec<[u32; 3]> = candidates.iter().map(|t| t.map(|v| outer[v])).collect();
    let best_whole = with_candidate_errors(surface, tri, &pattern, vertices, samples, |error_of| {
        // Every triangulation has a triangle on each side of the polygon, measuring at least
        // the side's midpoint sample: one side over the tolerance leaves none within it.
        if vertices.iter().all(|v| v.is_finite())
            && (0..n).any(|v| error_of(Candidate::Side(outer[v], outer[(v + 1) % n])) > tolerance)
        {
            return None;
        }
        let angle = |c: usize| angle_in_space(points[c].map(|p| vertices[p as usize]));
        // best[lo·n + hi]: the largest smallest angle in space of sub-polygon lo..=hi's
        // triangulations within the tolerance, and the first such triangulation's index. A
        // candidate's error is measured only where it could change that: both its
        // sub-polygons have such a triangulation and its angle beats the best found so far
        // (on the Duck at a relative tolerance of 2e-4, a quarter of the candidates).
        let mut best: Vec<Option<(f64, u32)>> = vec![None; n * n];
        for lo in 0..n - 1 {
            best[lo * n + lo + 1] = Some((f64::MAX, 0));
        }
        for span in 2..n {
            for lo in 0..n - span {
                let hi = lo + span;
                let mut offset = 0u32;
                let mut found: Option<(f64, u32)> = None;
                for k in lo + 1..hi {
                    let right_count = triangulations(hi - k + 1);
                    let c = slot[(lo * n + k) * n + hi];
                    if c != usize::MAX {
                        if let (Some((left, li)), Some((right, ri))) =
                            (best[lo * n + k], best[k * n + hi])
                        {
                            let angle = angle(c).min(left).min(right);
                            if found.is_none_or(|(a, _)| angle > a)
                                && error_of(Candidate::Triangle(points[c])) <= tolerance
                            {
                                found = Some((angle, offset + li * right_count + ri));
                            }
                        }
                    }
                    offset += triangulations(k - lo + 1) * right_count;
                }
                best[lo * n + hi] = found;
            }
        }
        best[n - 1]
    });
    let (_, index) = best_whole?;
    debug_assert!(triangulation(n, index).all(|t| slot[(t[0] * n + t[1]) * n + t[2]] != usize::MAX));
    Some(u16::try_from(index + 1).expect("at most 429 triangulations of 9 points"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::SurfacePoint;
    use crate::tessellate::chord::{measured_error, written_vertices};
    use crate::tessellate::transition::Pattern;
    use glam::DVec3;

    /// A cylinder of radius 1 over the reference triangle, its axis along the direction of
    /// edge 2 (corner 0 to corner 1) and then turned by `turn`: the triangles along the axis
    /// are flat, those across it curved.
    struct Cylinder {
        turn: f64,
    }

    impl Surface for Cylinder {
        fn evaluate(&self, _tri: usize, b: [f64; 3]) -> SurfacePoint {
            let (x, y) = (b[1] + 0.5 * b[2], 0.75f64.sqrt() * b[2]);
            let (s, c) = self.turn.sin_cos();
            let (u, v) = (c * x + s * y, -s * x + c * y);
            SurfacePoint {
                position: DVec3::new(u, v.sin(), v.cos()),
                normal: DVec3::new(0.0, v.sin(), v.cos()),
            }
        }
    }

    /// The fill chosen is the best of all triangulations, found by trying each: every one
    /// whose triangles keep the floor and measure within the tolerance is a candidate, and
    /// none has a larger smallest angle in space than the chosen one, which is one of them;
    /// where none is, none is chosen. Cylinders turned every way, edge counts from 1 to 3
    /// around no interior, tolerances from below the best fill's error to above the default's:
    /// the measurements skipped (those that could not change the choice) must not change it.
    #[test]
    fn the_fill_chosen_is_the_best_of_every_triangulation() {
        let mut samples = Samples::default();
        let (mut chosen, mut none) = (0, 0);
        for edges in [[2, 3, 3], [3, 3, 3], [1, 2, 3], [3, 2, 2]] {
            let key = PatternKey::new(edges, 2);
            let outer = polygon(&Pattern::new(key));
            for turn in [-1.2f64, -0.5, 0.3, 1.0, 2.0] {
                let surface = Cylinder { turn };
                // Per triangulation keeping the floor: its error and smallest angle in space.
                let tried: Vec<(u16, f64, f64)> = (1..=triangulations(outer.len()) as u16)
                    .filter_map(|fill| {
                        let pattern = Pattern::new(PatternKey { fill, ..key });
                        let domain_ok = pattern.triangles.iter().all(|t| {
                            let [a, b, c] = t.map(|p| pattern.domain(p));
                            min_angle(a, b, c) >= ANGLE_FLOOR
                        });
                        if !domain_ok {
                            return None;
                        }
                        let e = measured_error(&surface, 0, &pattern, &mut samples);
                        let error = e.edges.iter().fold(e.inner, |a, &b| a.max(b));
                        let written = |p: u32| {
                            let x = surface.evaluate(0, pattern.bary(p)).position;
                            x.as_vec3().as_dvec3()
                        };
                        let angle = pattern
                            .triangles
                            .iter()
                            .map(|t| angle_in_space(t.map(written)))
                            .fold(f64::MAX, f64::min);
                        Some((fill, error, angle))
                    })
                    .collect();
                let least = tried.iter().map(|t| t.1).fold(f64::MAX, f64::min);
                let most = tried.iter().map(|t| t.1).fold(0.0, f64::max);
                for tolerance in [0.9 * least, least, 0.5 * (least + most), most] {
                    let best = tried
                        .iter()
                        .filter(|t| t.1 <= tolerance)
                        .map(|t| t.2)
                        .fold(None, |a: Option<f64>, b| Some(a.map_or(b, |a| a.max(b))));
                    let vertices = written_vertices(&surface, 0, &Pattern::new(key), &mut samples);
                    let fill = fill_within(&surface, 0, key, &vertices, tolerance, &mut samples);
                    let at = format!("{edges:?} turn {turn} tolerance {tolerance}");
                    match (best, fill) {
                        (None, None) => none += 1,
                        (Some(best), Some(fill)) => {
                            let (_, error, angle) = tried
                                .iter()
                                .find(|t| t.0 == fill)
                                .unwrap_or_else(|| panic!("{at}: fill {fill} breaks the floor"));
                            assert!(*error <= tolerance, "{at}: fill {fill} over");
                            assert_eq!(*angle, best, "{at}: fill {fill} not the best");
                            chosen += 1;
                        }
                        (best, fill) => panic!("{at}: best {best:?}, chosen {fill:?}"),
                    }
                }
            }
        }
        assert!(
            chosen > 0 && none > 0,
            "{chosen} chosen, {none} without a fill"
        );
    }

    /// Where the default fill (ears by angle in the domain) fails on one of two mirrored
    /// cylinders, the fill chosen by measured error passes on both, keeps the floor, and is
    /// the one the pattern built from its key measures.
    #[test]
    fn the_fill_chosen_by_measured_error_passes_where_the_default_fails() {
        let key = PatternKey::new([2, 3, 3], 2);
        let default = Pattern::new(key);
        let mut samples = Samples::default();
        let mut default_failed = false;
        for turn in [1.0f64, -1.0].map(|s| s * std::f64::consts::FRAC_PI_3) {
            let surface = Cylinder { turn };
            let default_error = measured_error(&surface, 0, &default, &mut samples);
            let worst = |e: crate::tessellate::estimate::PatternError| {
                e.edges.iter().fold(e.inner, |a, &b| a.max(b))
            };
            // The tolerance between the default's error and the best fill's.
            let best = (1..=triangulations(polygon(&default).len()) as u16)
                .filter_map(|fill| {
                    let pattern = Pattern::new(PatternKey { fill, ..key });
                    let keeps = pattern.triangles.iter().all(|t| {
                        let [a, b, c] = t.map(|p| pattern.domain(p));
                        min_angle(a, b, c) >= ANGLE_FLOOR
                    });
                    keeps.then(|| worst(measured_error(&surface, 0, &pattern, &mut samples)))
                })
                .fold(f64::MAX, f64::min);
            let tolerance = 1.01 * best;
            default_failed |= worst(default_error) > tolerance;
            let vertices = written_vertices(&surface, 0, &default, &mut samples);
            let fill =
                fill_within(&surface, 0, key, &vertices, tolerance, &mut samples).expect("a fill");
            let pattern = Pattern::new(PatternKey { fill, ..key });
            assert!(
                measured_error(&surface, 0, &pattern, &mut samples).within(tolerance),
                "{turn}"
            );
            for t in &pattern.triangles {
                let [a, b, c] = t.map(|p| pattern.domain(p));
                assert!(min_angle(a, b, c) >= ANGLE_FLOOR, "{turn}: {t:?}");
            }
        }
        assert!(default_failed, "the default fill passes on both");
    }
}
