//! What is odd about a mesh's geometry, summed up as one warning per kind for the report:
//! degenerate and sliver triangles, duplicate triangles, unused vertices, normals facing away
//! from their faces, open, non-manifold and inconsistently wound edges, bow-tie vertices, many
//! disconnected pieces.
//!
//! It only counts: the fallbacks live where the data is used (degenerate and non-manifold edges
//! act as h = 0 in [`crate::topology`], normals orient the surface, unused vertices are not
//! written). It deliberately reports one line per kind, with the first few triangles or vertices
//! as examples, so that a scan of a million bad triangles gives a readable report.

use std::sync::atomic::{AtomicBool, Ordering::Relaxed};

use glam::DVec3;
use rayon::prelude::*;

use super::warning::Warning;
use crate::mesh::TriMesh;
use crate::topology::{EdgeId, EdgeKind, Topology, TriId};

mod union_find;
use union_find::UnionFind;

/// Triangles whose smallest angle is below this (in radians, about 0.06°) are slivers: valid,
/// but their normals and parameterization are numerically fragile.
const SLIVER_ANGLE: f64 = 1e-3;
/// Disconnected pieces above this count are worth a warning (debris, or a mesh exported
/// without welding).
const MANY_PIECES: usize = 1000;
/// Examples listed per warning.
const EXAMPLES: usize = 3;

/// One warning per odd kind of geometry found in `mesh` (the joined triangle primitives of mesh
/// `index`), each naming the fallback applied.
pub fn mesh_warnings(index: usize, mesh: &TriMesh, topo: &Topology) -> Vec<Warning> {
    let mut out = Vec::new();
    // One parallel pass over the triangles for every per-triangle test.
    let sliver_cos = SLIVER_ANGLE.cos();
    let [degenerate, slivers, facing_away] = Tally::of_each(mesh.triangles.len(), |t| {
        if topo.degenerate[t] {
            return [true, false, false];
        }
        let tri = mesh.triangles[t];
        let [a, b, c] = tri.map(|v| mesh.positions[v as usize]);
        let face = (b - a).cross(c - a);
        let away = tri
            .iter()
            .all(|&v| mesh.normals[v as usize].dot(face) < 0.0);
        let sliver = !clearly_not_sliver(face, [b - a, c - a, c - b])
            && largest_angle_cosine([a, b, c]) > sliver_cos;
        [false, sliver, away]
    });
    if degenerate.count > 0 {
        out.push(Warning::DegenerateTriangles {
            mesh: index,
            count: degenerate.count,
            triangles: degenerate.examples().to_vec(),
        });
    }
    if slivers.count > 0 {
        out.push(Warning::SliverTriangles {
            mesh: index,
            count: slivers.count,
            triangles: slivers.examples().to_vec(),
        });
    }

    let duplicates = duplicate_triangles(topo);
    if duplicates.count > 0 {
        out.push(Warning::DuplicateTriangles {
            mesh: index,
            count: duplicates.count,
            triangles: duplicates.examples().to_vec(),
        });
    }

    // Every store writes `true`, so the order the threads run in does not matter.
    let used: Vec<AtomicBool> = (0..mesh.positions.len())
        .map(|_| AtomicBool::new(false))
        .collect();
    mesh.triangles.par_iter().for_each(|t| {
        for &c in t {
            used[c as usize].store(true, Relaxed);
        }
    });
    let unused = Tally::of(used.len(), |v| !used[v].load(Relaxed));
    drop(used);
    if unused.count > 0 {
        out.push(Warning::UnusedVertices {
            mesh: index,
            count: unused.count,
            vertices: unused.examples().to_vec(),
        });
    }

    if facing_away.count > 0 {
        out.push(Warning::NormalsFacingAway {
            mesh: index,
            count: facing_away.count,
            triangles: facing_away.examples().to_vec(),
        });
    }

    // And one over the edges.
    let [boundary, non_manifold, flipped] = Tally::of_each(topo.edge_count(), |e| {
        match topo.edge_kind(EdgeId(e as u32)) {
            EdgeKind::Boundary => [true, false, false],
            EdgeKind::NonManifold => [false, true, false],
            EdgeKind::Interior => [false, false, same_direction(topo, e)],
            EdgeKind::Degenerate => [false; 3],
        }
    });
    if boundary.count > 0 {
        out.push(Warning::BoundaryEdges {
            mesh: index,
            count: boundary.count,
        });
    }
    if non_manifold.count > 0 {
        out.push(Warning::NonManifoldEdges {
            mesh: index,
            count: non_manifold.count,
            edges: non_manifold.examples().to_vec(),
        });
    }

    if flipped.count > 0 {
        out.push(Warning::OppositeWindingEdges {
            mesh: index,
            count: flipped.count,
            edges: flipped.examples().to_vec(),
        });
    }

    let bow_ties = bow_tie_vertices(topo);
    if bow_ties.count > 0 {
        out.push(Warning::BowTieVertices {
            mesh: index,
            count: bow_ties.count,
            vertices: bow_ties.examples().to_vec(),
        });
    }

    let pieces = pieces(topo);
    if pieces > MANY_PIECES {
        out.push(Warning::ManyPieces {
            mesh: index,
            pieces,
        });
    }
    out
}

/// How many indices passed a test, and the first [`EXAMPLES`] of them, found without listing
/// them all (a scan of a million bad triangles keeps three).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Tally {
    count: usize,
    first: [usize; EXAMPLES],
}

impl Tally {
    /// The indices in `0..n` for which `hit` holds, tested in parallel; the examples are the
    /// smallest whatever the thread count (parts are merged in index order).
    fn of(n: usize, hit: impl Fn(usize) -> bool + Sync) -> Tally {
        (0..n)
            .into_par_iter()
            .fold(Tally::default, |mut t, i| {
                if hit(i) {
                    t.add(i);
                }
                t
            })
            .reduce(Tally::default, |mut a, b| {
                a.merge(&b);
                a
            })
    }

    /// [`Tally::of`] for `N` tests at once, in one pass: `hit(i)[k]` says whether `i` passes
    /// test `k`.
    fn of_each<const N: usize>(n: usize, hit: impl Fn(usize) -> [bool; N] + Sync) -> [Tally; N] {
        (0..n)
            .into_par_iter()
            .fold(
                || [Tally::default(); N],
                |mut t, i| {
                    for (k, passed) in hit(i).into_iter().enumerate() {
                        if passed {
                            t[k].add(i);
                        }
                    }
                    t
                },
            )
            .reduce(
                || [Tally::default(); N],
                |mut a, b| {
                    for (a, b) in a.iter_mut().zip(&b) {
                        a.merge(b);
                    }
                    a
                },
            )
    }

    /// Adds `later` (a tally of larger indices than any in `self`).
    fn merge(&mut self, later: &Tally) {
        for &i in later.examples() {
            self.add(i);
        }
        self.count += later.count - later.examples().len();
    }

    /// Counts `i`, keeping it as an example if it is among the smallest seen; indices must come
    /// in ascending order.
    fn add(&mut self, i: usize) {
        if self.count < EXAMPLES {
            self.first[self.count] = i;
        }
        self.count += 1;
    }

    /// Counts `i`, keeping it as an example if it is among the smallest seen, in any order.
    fn insert(&mut self, i: usize) {
        let kept = self.count.min(EXAMPLES);
        let at = self.first[..kept].partition_point(|&x| x < i);
        if at < EXAMPLES {
            self.first.copy_within(at..EXAMPLES - 1, at + 1);
            self.first[at] = i;
        }
        self.count += 1;
    }

    fn examples(&self) -> &[usize] {
        &self.first[..self.count.min(EXAMPLES)]
    }
}

/// Whether a triangle with cross product `face` of its sides and sides `sides` has no angle
/// near [`SLIVER_ANGLE`]: a bound that spares nearly every triangle the three square roots and
/// divisions of [`largest_angle_cosine`], which then decides only the few it leaves.
///
/// The smallest angle `α` lies between the two longer sides `b` and `c`, so
/// `sin α = |face| / (b·c) ≥ |face| / L²` with `L` the longest side. Where
/// `|face|² ≥ 4 sin²(SLIVER_ANGLE) · L⁴`, `sin α ≥ 2 sin(SLIVER_ANGLE)`, so `α` is more than
/// twice the sliver angle (`α ≤ 60°`, where the sine rises): a factor no rounding of these few
/// operations (relative `1e-15`; the squares of `f32` coordinates neither overflow nor
/// underflow an `f64`) comes near, so the exact test would have said "not a sliver" too and the
/// count is unchanged.
#[inline]
fn clearly_not_sliver(face: DVec3, sides: [DVec3; 3]) -> bool {
    let longest = sides.iter().map(|s| s.length_squared()).fold(0.0, f64::max);
    let bound = 2.0 * SLIVER_ANGLE.sin();
    face.length_squared() >= bound * bound * longest * longest
}

/// The cosine of the smallest angle of the triangle with corners `p`: comparing cosines instead
/// of angles spares three arc cosines per triangle, and the order is the same (the cosine falls
/// as the angle grows).
fn largest_angle_cosine(p: [DVec3; 3]) -> f64 {
    (0..3)
        .map(|k| {
            let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            (a.dot(b) / (a.length_squared() * b.length_squared()).sqrt()).clamp(-1.0, 1.0)
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Edges with more uses than this have their triangles sorted to find copies; on the others a
/// triangle looks among the few triangles on its edge.
const CROWDED: usize = 8;

/// Triangles with the same three welded corners as an earlier triangle (in any order).
///
/// A copy has every edge of its original, so each triangle looks for an earlier one with its
/// corners among the uses of one edge chosen by the corners alone (between its two smallest
/// vertex ids, so that every copy picks the same edge): on a manifold mesh that is one other
/// triangle, with no array over every triangle. The triangles of crowded edges (books, many
/// copies of one triangle) are sorted by their corners instead, so that no shape makes this
/// worse than a sort.
fn duplicate_triangles(topo: &Topology) -> Tally {
    let corners = |t: usize| {
        let mut key = topo.tri_verts[t].map(|x| x.0);
        key.sort_unstable();
        key
    };
    // The uses of the edge between the two smallest corners (opposite the largest), or `None`
    // for a triangle with a repeated corner, which is degenerate rather than a copy.
    let chosen = |t: usize, key: &[u32; 3]| {
        if key[0] == key[1] || key[1] == key[2] {
            return None;
        }
        let v = topo.tri_verts[t];
        let largest = v.iter().position(|x| x.0 == key[2]).unwrap_or(0);
        Some(topo.edge_uses(topo.tri_edges[t][largest]))
    };
    // Whether any triangle chose a crowded edge: on most meshes none does, and the pass that
    // sorts their triangles is skipped.
    let crowded_seen = AtomicBool::new(false);
    let mut found = Tally::of(topo.tri_verts.len(), |t| {
        let key = corners(t);
        chosen(t, &key).is_some_and(|uses| {
            if uses.len() > CROWDED {
                crowded_seen.store(true, Relaxed);
                return false;
            }
            uses.iter()
                .take_while(|u| (u.tri().0 as usize) < t)
                .any(|u| corners(u.tri().0 as usize) == key)
        })
    });
    if !crowded_seen.load(Relaxed) {
        return found;
    }
    let mut crowded: Vec<([u32; 3], u32)> = (0..topo.tri_verts.len())
        .into_par_iter()
        .filter_map(|t| {
            let key = corners(t);
            let uses = chosen(t, &key)?;
            (uses.len() > CROWDED).then_some((key, t as u32))
        })
        .collect();
    // Entries are distinct (the triangle index differs), so the order is the one there is.
    crowded.par_sort_unstable();
    // Every entry after the first of its group is a copy.
    for w in crowded.windows(2).filter(|w| w[0].0 == w[1].0) {
        found.insert(w[1].1 as usize);
    }
    found
}

/// Do both triangles of interior edge `e` run along it in the same direction (one of them is
/// wound the other way)?
///
/// Read from the first triangle's neighbour: its edge runs from its corner i to its corner j,
/// and the neighbour's edge from its slot `r + 1` to `r + 2`, so both run the same way exactly
/// when the neighbour holds i in slot `r + 1` (no triangle lookup needed).
fn same_direction(topo: &Topology, e: usize) -> bool {
    let (t, k) = topo.edge_uses(EdgeId(e as u32))[0].at();
    topo.neighbour(TriId(t as u32), k)
        .is_some_and(|n| n.slots[0] == (n.slots[2] + 1) % 3)
}

/// Welded vertices whose triangles form more than one fan (connected through edges that contain
/// the vertex).
///
/// One union-find over the triangle corners (`3 × triangle + corner`, a triangle with two
/// welded corners at one vertex counting once, by its first): every edge joins the corners of
/// all its triangles at each of its end points, straight from its uses. Walking edges rather than
/// triangles keeps this linear in the corners whatever the valence (a book of 100 000 triangles
/// on one edge, or 100 000 copies of one triangle), where joining per triangle and edge use was
/// cubic in it. The edges are joined in parallel ([`UnionFind`]). A vertex is a bow-tie when its
/// corners fall into two or more classes.
fn bow_tie_vertices(topo: &Topology) -> Tally {
    // The corner of `t` holding the welded vertex of its corner `c`: the first with it.
    let canonical = |t: usize, c: usize| {
        let v = topo.tri_verts[t];
        let first = v.iter().position(|&x| x == v[c]).unwrap_or(c);
        (3 * t + first) as u32
    };
    let corners = UnionFind::new(3 * topo.tri_verts.len() as u32);
    (0..topo.edge_count()).into_par_iter().for_each(|e| {
        let uses = topo.edge_uses(EdgeId(e as u32));
        let Some((&head, rest)) = uses.split_first() else {
            return;
        };
        let (t0, k0) = head.at();
        for end in [1, 2] {
            let anchor = canonical(t0, (k0 + end) % 3);
            for u in rest {
                let (t, k) = u.at();
                // The use's corner at the same welded vertex as the anchor.
                let c = if topo.tri_verts[t][(k + end) % 3] == topo.tri_verts[t0][(k0 + end) % 3] {
                    (k + end) % 3
                } else {
                    (k + 3 - end) % 3
                };
                corners.union(anchor, canonical(t, c));
            }
        }
    });
    // A vertex is a bow-tie when two of its canonical corners are roots (the smallest corner of
    // each class): the first root marks the vertex seen, any later one marks it a bow-tie.
    let blank = || -> Vec<AtomicBool> {
        (0..topo.welded_positions.len())
            .map(|_| AtomicBool::new(false))
            .collect()
    };
    let (seen, bow_tie) = (blank(), blank());
    (0..topo.tri_verts.len()).into_par_iter().for_each(|t| {
        for c in 0..3 {
            let corner = (3 * t + c) as u32;
            if canonical(t, c) == corner && corners.is_root(corner) {
                let v = topo.tri_verts[t][c].0 as usize;
                if seen[v].swap(true, Relaxed) {
                    bow_tie[v].store(true, Relaxed);
                }
            }
        }
    });
    Tally::of(bow_tie.len(), |v| bow_tie[v].load(Relaxed))
}

/// Connected pieces of triangles (through welded edges), joined in parallel.
fn pieces(topo: &Topology) -> usize {
    let n = topo.tri_verts.len() as u32;
    let tris = UnionFind::new(n);
    (0..topo.edge_count()).into_par_iter().for_each(|e| {
        for w in topo.edge_uses(EdgeId(e as u32)).windows(2) {
            tris.union(w[0].tri().0, w[1].tri().0);
        }
    });
    (0..n).into_par_iter().filter(|&i| tris.is_root(i)).count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::tests::odd_mesh;
    use crate::topology::VertId;

    /// The bound never spares a triangle the exact test calls a sliver, and spares every
    /// triangle whose smallest angle is ten times the sliver angle: needles and flat
    /// triangles from 1e-5 to 1 radian, at scales from 1e-30 to 1e30, in every corner order.
    #[test]
    fn the_sliver_bound_spares_only_triangles_that_are_not_slivers() {
        let sliver_cos = SLIVER_ANGLE.cos();
        let (mut spared, mut slivers) = (0, 0);
        for step in 0..400 {
            // Smallest angle from 1e-5 to 1 rad, log-spaced, as a needle (apex angle) or a flat
            // triangle (two small angles at the ends of the long side).
            let angle = 1e-5 * 10f64.powf(5.0 * f64::from(step) / 399.0);
            let scale = 10f64.powi(step % 61 - 30);
            let needle = [
                DVec3::ZERO,
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(angle.cos(), angle.sin(), 0.0),
            ];
            let flat = [
                DVec3::ZERO,
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(1.0, angle.tan(), 0.5 * angle.tan()),
            ];
            for shape in [needle, flat] {
                for r in 0..3 {
                    let p = [0, 1, 2].map(|k| scale * shape[(k + r) % 3] + DVec3::splat(scale));
                    let [a, b, c] = p;
                    let face = (b - a).cross(c - a);
                    let exact = largest_angle_cosine(p) > sliver_cos;
                    let cleared = clearly_not_sliver(face, [b - a, c - a, c - b]);
                    assert!(!(exact && cleared), "angle {angle}, scale {scale}");
                    // On a flat triangle b·c is a quarter of L²: cleared from about 8e-3 rad.
                    if angle > 10.0 * SLIVER_ANGLE {
                        assert!(cleared, "angle {angle}, scale {scale}");
                    }
                    spared += usize::from(cleared);
                    slivers += usize::from(exact);
                }
            }
        }
        assert!(spared > 0 && slivers > 0);
    }

    /// Bow-tie vertices the slow way: per vertex, its distinct triangles joined when they
    /// share an edge through it, components counted by search.
    fn bow_ties_by_search(topo: &Topology) -> Vec<usize> {
        let n = topo.welded_positions.len();
        (0..n)
            .filter(|&x| {
                let x = VertId(x as u32);
                let around: Vec<usize> = (0..topo.tri_verts.len())
                    .filter(|&t| topo.tri_verts[t].contains(&x))
                    .collect();
                let shares_edge = |a: usize, b: usize| {
                    let [va, vb] = [topo.tri_verts[a], topo.tri_verts[b]];
                    // An edge through x: x with another corner of a that b also has, or x
                    // twice in a triangle (a degenerate edge from x to x) that b shares.
                    va.iter().any(|&y| y != x && vb.contains(&y))
                        || (va.iter().filter(|&&y| y == x).count() > 1
                            && vb.iter().filter(|&&y| y == x).count() > 1)
                };
                let mut seen = vec![false; around.len()];
                let mut pieces = 0;
                for s in 0..around.len() {
                    if seen[s] {
                        continue;
                    }
                    pieces += 1;
                    let mut stack = vec![s];
                    seen[s] = true;
                    while let Some(i) = stack.pop() {
                        for j in 0..around.len() {
                            if !seen[j] && shares_edge(around[i], around[j]) {
                                seen[j] = true;
                                stack.push(j);
                            }
                        }
                    }
                }
                pieces > 1
            })
            .collect()
    }

    #[test]
    fn bow_ties_and_duplicates_match_the_slow_definitions_on_odd_shapes() {
        for seed in 0..30 {
            let mesh = odd_mesh(seed, 8 + 5 * seed as usize);
            let topo = Topology::build(&mesh);
            let want = bow_ties_by_search(&topo);
            let got = bow_tie_vertices(&topo);
            assert_eq!(got.count, want.len(), "seed {seed}");
            assert_eq!(got.examples(), &want[..want.len().min(EXAMPLES)]);

            let key = |t: usize| {
                let mut k = topo.tri_verts[t];
                k.sort_unstable();
                k
            };
            let copies: Vec<usize> = (0..mesh.triangles.len())
                .filter(|&t| {
                    let k = key(t);
                    k[0] != k[1] && k[1] != k[2] && (0..t).any(|s| key(s) == k)
                })
                .collect();
            let got = duplicate_triangles(&topo);
            assert_eq!(got.count, copies.len(), "seed {seed}");
            assert_eq!(got.examples(), &copies[..copies.len().min(EXAMPLES)]);
        }
    }

    /// Pieces the slow way: a search from each unvisited triangle through the triangles that
    /// share a welded edge with it.
    fn pieces_by_search(topo: &Topology) -> usize {
        let n = topo.tri_verts.len();
        let mut seen = vec![false; n];
        let mut pieces = 0;
        for s in 0..n {
            if seen[s] {
                continue;
            }
            pieces += 1;
            seen[s] = true;
            let mut stack = vec![s];
            while let Some(t) = stack.pop() {
                for e in topo.tri_edges[t] {
                    for u in topo.edge_uses(e) {
                        let g = u.tri().0 as usize;
                        if !seen[g] {
                            seen[g] = true;
                            stack.push(g);
                        }
                    }
                }
            }
        }
        pieces
    }

    #[test]
    fn bow_ties_and_pieces_match_the_slow_definitions_on_any_thread_count() {
        for seed in 0..12 {
            // Odd shapes, and many small pieces of them (the same triangles shifted apart).
            let mut mesh = odd_mesh(seed, 200 + 150 * seed as usize);
            let (count, tris) = (mesh.positions.len() as u32, mesh.triangles.clone());
            for shift in 1..4 {
                let moved: Vec<DVec3> = mesh.positions[..count as usize]
                    .iter()
                    .map(|p| *p + DVec3::splat(10.0 * f64::from(shift)))
                    .collect();
                mesh.positions.extend(moved);
                mesh.normals.extend_from_within(..count as usize);
                mesh.triangles.extend(
                    tris.iter()
                        .step_by(shift as usize + 1)
                        .map(|t| t.map(|v| v + shift * count)),
                );
            }
            let topo = Topology::build(&mesh);
            let want = bow_ties_by_search(&topo);
            let pieces_want = pieces_by_search(&topo);
            for threads in [1, 2, 3, 8] {
                let (got, pieces_got) = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| (bow_tie_vertices(&topo), pieces(&topo)));
                assert_eq!(got.count, want.len(), "seed {seed}, {threads} threads");
                assert_eq!(got.examples(), &want[..want.len().min(EXAMPLES)]);
                assert_eq!(pieces_got, pieces_want, "seed {seed}, {threads} threads");
            }
        }
    }

    #[test]
    fn a_tally_keeps_the_smallest_examples_whatever_the_split() {
        let hits = |i: usize| i % 7 == 3 || i > 99_990;
        let t = Tally::of(100_000, hits);
        assert_eq!(t.count, (0..100_000).filter(|&i| hits(i)).count());
        assert_eq!(t.examples(), &[3, 10, 17]);
        assert_eq!(Tally::of(10, |i| i == 9).examples(), &[9]);
        assert_eq!(Tally::of(0, |_| true), Tally::default());
    }
}
