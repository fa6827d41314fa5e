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

mod connectivity;
use connectivity::{around_vertices, bow_tie_vertices, pieces};

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
    // The search for pieces and the tally of each vertex's triangles are each one pass on one
    // thread: they run beside the parallel passes over the triangles and the edges, which the
    // other threads share out (and this one joins once they are done), instead of after them
    // with the other threads idle.
    let ((pieces, around), mut out) = rayon::join(
        || (pieces(topo), around_vertices(topo)),
        || parallel_warnings(index, mesh, topo),
    );
    let bow_ties = bow_tie_vertices(topo, around);
    if bow_ties.count > 0 {
        out.push(Warning::BowTieVertices {
            mesh: index,
            count: bow_ties.count,
            vertices: bow_ties.examples().to_vec(),
        });
    }
    if pieces > MANY_PIECES {
        out.push(Warning::ManyPieces {
            mesh: index,
            pieces,
        });
    }
    out
}

/// The warnings of [`mesh_warnings`] found by parallel passes over the triangles and the
/// edges, in the order they are reported.
fn parallel_warnings(index: usize, mesh: &TriMesh, topo: &Topology) -> Vec<Warning> {
    let mut out = Vec::new();
    // One parallel pass over the triangles for every per-triangle test, which also marks the
    // vertices their corners use (every store writes `true`, so the order the threads run in
    // does not matter).
    let used: Vec<AtomicBool> = (0..mesh.positions.len())
        .map(|_| AtomicBool::new(false))
        .collect();
    let sliver_cos = SLIVER_ANGLE.cos();
    let [degenerate, slivers, facing_away] = Tally::of_each(mesh.triangles.len(), |t| {
        let tri = mesh.triangles[t];
        for &c in &tri {
            used[c as usize].store(true, Relaxed);
        }
        if topo.degenerate[t] {
            return [true, false, false];
        }
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

    out
}

/// Indices one task of [`Tally::of_each`] tests.
const TALLY_BLOCK: usize = 4096;

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
        let [t] = Tally::of_each(n, |i| [hit(i)]);
        t
    }

    /// [`Tally::of`] for `N` tests at once, in one pass: `hit(i)[k]` says whether `i` passes
    /// test `k`.
    ///
    /// Each task tallies a block of [`TALLY_BLOCK`] indices in a plain loop and only the
    /// blocks' tallies are merged (in block order): a fold over single indices moved the
    /// tallies in and out of the folding closure once per index.
    fn of_each<const N: usize>(n: usize, hit: impl Fn(usize) -> [bool; N] + Sync) -> [Tally; N] {
        (0..n.div_ceil(TALLY_BLOCK))
            .into_par_iter()
            .map(|b| {
                let mut t = [Tally::default(); N];
                for i in b * TALLY_BLOCK..((b + 1) * TALLY_BLOCK).min(n) {
                    for (k, passed) in hit(i).into_iter().enumerate() {
                        if passed {
                            t[k].add(i);
                        }
                    }
                }
                t
            })
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
/// wound the other way)? Read from the first triangle's neighbour's slots
/// ([`Neighbour::runs_same_way`](crate::topology::Neighbour::runs_same_way)).
fn same_direction(topo: &Topology, e: usize) -> bool {
    let (t, k) = topo.edge_uses(EdgeId(e as u32))[0].at();
    topo.neighbour(TriId(t as u32), k)
        .is_some_and(|n| n.runs_same_way())
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
            let got = bow_tie_vertices(&topo, around_vertices(&topo));
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
                    .install(|| {
                        (
                            bow_tie_vertices(&topo, around_vertices(&topo)),
                            pieces(&topo),
                        )
                    });
                assert_eq!(got.count, want.len(), "seed {seed}, {threads} threads");
                assert_eq!(got.examples(), &want[..want.len().min(EXAMPLES)]);
                assert_eq!(pieces_got, pieces_want, "seed {seed}, {threads} threads");
            }
        }
    }

    /// The searches that run beside the parallel passes change neither the warnings nor their
    /// order: a mesh of more than [`MANY_PIECES`] pieces (copies of two triangles sharing one
    /// vertex, a bow-tie each, some wound against the other, with boundary edges and unused
    /// vertices) gives the same list on every thread count, the bow-ties and the pieces last,
    /// as they were reported when they ran after the other checks.
    #[test]
    fn warnings_keep_their_order_with_the_searches_beside_the_passes() {
        let mut mesh = TriMesh::default();
        for i in 0..1200u32 {
            let o = DVec3::new(f64::from(i) * 10.0, 0.0, 0.0);
            mesh.positions.extend(
                [
                    (0.0, 0.0),
                    (1.0, 0.0),
                    (0.0, 1.0),
                    (-1.0, 0.0),
                    (0.0, -1.0),
                    (5.0, 5.0),
                ]
                .map(|(x, y)| o + DVec3::new(x, y, 0.0)),
            );
            let b = 6 * i;
            mesh.triangles.push([b, b + 1, b + 2]);
            if i % 2 == 0 {
                mesh.triangles.push([b, b + 3, b + 4]);
            } else {
                mesh.triangles.push([b, b + 4, b + 3]);
            }
        }
        mesh.normals = vec![DVec3::Z; mesh.positions.len()];
        let topo = Topology::build(&mesh);
        let on = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| mesh_warnings(0, &mesh, &topo))
        };
        let one = on(1);
        let kinds: Vec<&str> = one
            .iter()
            .map(|w| match w {
                Warning::UnusedVertices { .. } => "unused",
                Warning::NormalsFacingAway { .. } => "away",
                Warning::BoundaryEdges { .. } => "boundary",
                Warning::BowTieVertices { count: 1200, .. } => "bow-ties",
                Warning::ManyPieces { pieces: 2400, .. } => "pieces",
                _ => "other",
            })
            .collect();
        assert_eq!(kinds, ["unused", "away", "boundary", "bow-ties", "pieces"]);
        for threads in [2, 3] {
            assert_eq!(on(threads), one, "{threads} threads");
        }
    }

    /// A named shape for the fan walk: triangles over vertex ids, and whether every edge is
    /// interior or boundary (so the walk alone decides every vertex).
    type Shape = (&'static str, Vec<[u32; 3]>, bool);

    /// Shapes whose bow-ties and pieces differ in how their fans close: closed fans meeting at
    /// one vertex, open fans split in three, isolated triangles, mixed winding, pinched tori
    /// (more vertices than one block of the walk), copies of a triangle, and, to leave to the
    /// corners, a book of pages beside a fan and triangles with a repeated corner. Corners are
    /// rotated per triangle so the vertex sits in every slot.
    fn fan_shapes() -> Vec<Shape> {
        let rotate = |tris: Vec<[u32; 3]>| -> Vec<[u32; 3]> {
            tris.into_iter()
                .enumerate()
                .map(|(i, t)| [t[i % 3], t[(i + 1) % 3], t[(i + 2) % 3]])
                .collect()
        };
        let tet = |a: u32, b: u32, c: u32, d: u32| [[a, b, c], [a, d, b], [a, c, d], [b, d, c]];
        let mut two_tets = tet(0, 1, 2, 3).to_vec();
        two_tets.extend(tet(0, 4, 5, 6));
        let closed_fan: Vec<[u32; 3]> = (1..=6).map(|i| [0, i, i % 6 + 1]).collect();
        let mut mixed = closed_fan.clone();
        mixed[2] = [mixed[2][0], mixed[2][2], mixed[2][1]];
        mixed[4] = [mixed[4][0], mixed[4][2], mixed[4][1]];
        // Two closed fans at vertex 0 (a double cone), interleaved in triangle order.
        let cone = |ring: [u32; 4]| -> Vec<[u32; 3]> {
            (0..4).map(|i| [0, ring[i], ring[(i + 1) % 4]]).collect()
        };
        let (a, b) = (cone([1, 2, 3, 4]), cone([5, 6, 7, 8]));
        let double_cone = a.iter().zip(&b).flat_map(|(x, y)| [*x, *y]).collect();
        let torus = |m: u32, n: u32, base: u32, pinch: u32| -> Vec<[u32; 3]> {
            let at = |i: u32, j: u32| {
                let k = (i % m) * n + (j % n);
                if k == 0 {
                    pinch
                } else {
                    base + k
                }
            };
            (0..m)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .flat_map(|(i, j)| {
                    [
                        [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                        [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
                    ]
                })
                .collect()
        };
        let mut pinched = torus(50, 45, 0, 0);
        pinched.extend(torus(40, 30, 50 * 45, 0));
        let mut book: Vec<[u32; 3]> = (2..7).map(|k| [0, 1, k]).collect();
        book.extend([[0, 7, 8], [0, 8, 9], [10, 11, 12]]);
        vec![
            ("two tetrahedra on one vertex", rotate(two_tets), true),
            ("double cone", rotate(double_cone), true),
            (
                "fan split in three",
                rotate(vec![
                    [0, 4, 5],
                    [0, 1, 2],
                    [0, 8, 9],
                    [0, 2, 3],
                    [0, 5, 6],
                    [0, 7, 8],
                ]),
                true,
            ),
            ("closed fan", rotate(closed_fan), true),
            ("mixed winding", rotate(mixed), true),
            (
                "isolated triangles",
                vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]],
                true,
            ),
            ("pinched tori", rotate(pinched), true),
            ("two copies", vec![[0, 1, 2], [1, 2, 0], [0, 3, 4]], true),
            (
                "three copies",
                vec![[0, 1, 2], [1, 2, 0], [2, 1, 0], [0, 3, 4]],
                false,
            ),
            ("book beside a fan", rotate(book), false),
            (
                "repeated corners",
                vec![
                    [0, 0, 1],
                    [0, 1, 2],
                    [0, 2, 3],
                    [0, 4, 5],
                    [4, 4, 4],
                    [5, 6, 6],
                ],
                false,
            ),
        ]
    }

    /// The mesh of a shape, each vertex on the moment curve (no three collinear, so only a
    /// repeated corner makes a triangle degenerate).
    fn shape_mesh(tris: &[[u32; 3]]) -> TriMesh {
        let n = tris.iter().flatten().max().map_or(0, |&v| v + 1);
        let positions: Vec<DVec3> = (0..n)
            .map(|i| {
                let t = f64::from(i) / f64::from(n);
                DVec3::new(t, t * t, t * t * t)
            })
            .collect();
        TriMesh {
            normals: vec![DVec3::Z; positions.len()],
            positions,
            triangles: tris.to_vec(),
        }
    }

    #[test]
    fn fan_walks_match_the_slow_definitions_on_fans_of_every_kind() {
        let mut all: Vec<[u32; 3]> = Vec::new();
        let mut shapes = fan_shapes();
        for (_, tris, _) in &shapes {
            let base = all.iter().flatten().max().map_or(0, |&v| v + 1);
            all.extend(tris.iter().map(|t| t.map(|v| v + base)));
        }
        shapes.push(("all at once", all, false));
        for (name, tris, clean) in &shapes {
            let topo = Topology::build(&shape_mesh(tris));
            if *clean {
                assert_eq!(
                    connectivity::undecided(&topo),
                    Vec::<usize>::new(),
                    "{name}"
                );
            }
            let want = bow_ties_by_search(&topo);
            let pieces_want = pieces_by_search(&topo);
            for threads in [1, 2] {
                let (got, pieces_got) = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| {
                        (
                            bow_tie_vertices(&topo, around_vertices(&topo)),
                            pieces(&topo),
                        )
                    });
                assert_eq!(got.count, want.len(), "{name}, {threads} threads");
                assert_eq!(got.examples(), &want[..want.len().min(EXAMPLES)], "{name}");
                assert_eq!(pieces_got, pieces_want, "{name}, {threads} threads");
            }
        }
        // Each kind of fan was met: bow-ties through closed and open fans alike.
        let count = |name: &str| {
            let (_, tris, _) = shapes.iter().find(|s| s.0 == name).unwrap();
            bow_ties_by_search(&Topology::build(&shape_mesh(tris))).len()
        };
        for name in [
            "two tetrahedra on one vertex",
            "double cone",
            "fan split in three",
        ] {
            assert_eq!(count(name), 1, "{name}");
        }
        assert_eq!(count("pinched tori"), 1);
        assert_eq!(count("closed fan") + count("mixed winding"), 0);
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
