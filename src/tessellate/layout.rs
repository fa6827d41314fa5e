//! Where every output vertex of one group goes, by index arithmetic on the input triangles
//! alone, before anything is evaluated.
//!
//! Source triangles are taken in order; each one owns the corners and input edges it is the
//! first to use, and its interior. Its vertices come as one contiguous block: owned corners,
//! owned edges (`n − 1` samples each, walked from the lower input vertex index), interior (in
//! the plan's first-use order). So every block of consecutive source triangles owns a
//! contiguous vertex range and `n²` triangles per source triangle: blocks are written in
//! parallel into disjoint slices of the final buffers, and the numbering never depends on how
//! the work was split. It deliberately evaluates nothing.

use std::ops::Range;

use std::sync::atomic::{AtomicU32, Ordering};

use rayon::prelude::*;

use crate::mesh::TriMesh;
use crate::topology::{EdgeId, Topology};

use super::is_crease;

/// Output vertex numbering of one group of source triangles.
#[derive(Debug, Clone)]
pub(crate) struct GroupLayout {
    /// Per source triangle of the group, its first owned vertex; one more entry holds the
    /// group's vertex count.
    pub base: Vec<u32>,
    /// Per corner (`3·offset + c`): its output vertex.
    pub corner_slot: Vec<u32>,
    /// Per half-edge (`3·offset + k`, the edge opposite corner `k`): the output vertex of its
    /// first sample, walked from the lower input vertex index.
    pub edge_slot: Vec<u32>,
    /// Per source triangle: bit `c` set if it writes corner `c`, bit `3 + k` if it writes the
    /// samples of edge `k`.
    pub owns: Vec<u8>,
}

impl GroupLayout {
    /// Numbers the output vertices of triangles `range` of `mesh` at level `n`, `interior`
    /// points per triangle. `h` decides which interior edges are creases: their two sides get
    /// their own samples.
    pub fn new(
        mesh: &TriMesh,
        topo: &Topology,
        h: &[f64],
        n: u32,
        interior: usize,
        range: Range<usize>,
    ) -> GroupLayout {
        let per_edge = n.saturating_sub(1);
        Self::with_counts(mesh, topo, h, range, |_, _| per_edge, |_| interior as u32)
    }

    /// As [`GroupLayout::new`], with `per_edge(tri, k)` samples on the edge opposite corner `k`
    /// of source triangle `tri` (the same for every triangle on that input edge) and
    /// `interior(tri)` interior points.
    ///
    /// Every step is a parallel map or a prefix sum, so the numbering scales with the threads:
    /// which triangle first uses each vertex (a minimum over its uses) and each input edge (a
    /// sort), what each triangle owns and how many vertices that is, where each triangle's
    /// block starts (an exclusive prefix sum of those counts), and every slot from the owner's
    /// block start and rank. The result is the serial first-use numbering, whatever the split.
    pub fn with_counts(
        mesh: &TriMesh,
        topo: &Topology,
        h: &[f64],
        range: Range<usize>,
        per_edge: impl Fn(usize, usize) -> u32 + Sync,
        interior: impl Fn(usize) -> u32 + Sync,
    ) -> GroupLayout {
        let first = range.start;
        let triangles = &mesh.triangles[range.clone()];
        // Where no edge has a sample (level 1), which half-edge owns an input edge changes no
        // slot: the edges own nothing, and the pass that finds their first uses (about a
        // tenth of a level-1 run) is skipped. Their slots are then never read.
        let sampled = range
            .clone()
            .into_par_iter()
            .any(|tri| (0..3).any(|k| per_edge(tri, k) > 0));
        let first_half = if sampled {
            first_use_of_each_input_edge(mesh, topo, h, range.clone())
        } else {
            Vec::new()
        };
        let first_corner = first_use_of_each_vertex(triangles, mesh.positions.len());
        let first_corner_of = |v: u32| first_corner[v as usize].load(Ordering::Relaxed);
        let owns: Vec<u8> = (0..triangles.len())
            .into_par_iter()
            .map(|offset| {
                let mut owns = 0u8;
                for (c, &v) in triangles[offset].iter().enumerate() {
                    if first_corner_of(v) as usize == 3 * offset + c {
                        owns |= 1 << c;
                    }
                }
                for k in 0..3 {
                    if sampled && first_half[3 * offset + k] as usize == 3 * offset + k {
                        owns |= 8 << k;
                    }
                }
                owns
            })
            .collect();
        // Where owned vertex runs start inside a triangle's block: corners, then edges in order.
        let edge_start = |offset: usize, k: usize| -> u32 {
            let o = owns[offset];
            let corners = (o & 7).count_ones();
            corners
                + (0..k)
                    .filter(|&k2| o & (8 << k2) != 0)
                    .map(|k2| per_edge(first + offset, k2))
                    .sum::<u32>()
        };
        let base = exclusive_prefix_sum(triangles.len(), |offset| {
            edge_start(offset, 3) + interior(first + offset)
        });
        let mut corner_slot = vec![0u32; 3 * triangles.len()];
        let mut edge_slot = vec![0u32; 3 * triangles.len()];
        corner_slot
            .par_chunks_mut(3)
            .zip(edge_slot.par_chunks_mut(3))
            .enumerate()
            .for_each(|(offset, (corners, edges))| {
                for (c, &v) in triangles[offset].iter().enumerate() {
                    let owner = first_corner_of(v) as usize;
                    let (o, c2) = (owner / 3, owner % 3);
                    let rank = (owns[o] & ((1 << c2) - 1)).count_ones();
                    corners[c] = base[o] + rank;
                }
                if !sampled {
                    return;
                }
                for (k, slot) in edges.iter_mut().enumerate() {
                    let owner = first_half[3 * offset + k] as usize;
                    let (o, k2) = (owner / 3, owner % 3);
                    *slot = base[o] + edge_start(o, k2);
                }
            });
        GroupLayout {
            base,
            corner_slot,
            edge_slot,
            owns,
        }
    }

    /// Number of output vertices.
    pub fn vertex_count(&self) -> usize {
        *self.base.last().unwrap_or(&0) as usize
    }
}

/// For each of `vertices` input vertices, its first corner in `triangles` (`3·offset + c`), or
/// `u32::MAX` if unused: the minimum over its uses, whatever order the threads find them in.
fn first_use_of_each_vertex(triangles: &[[u32; 3]], vertices: usize) -> Vec<AtomicU32> {
    let first: Vec<AtomicU32> = (0..vertices)
        .into_par_iter()
        .map(|_| AtomicU32::new(u32::MAX))
        .collect();
    triangles.par_iter().enumerate().for_each(|(offset, t)| {
        for (c, &v) in t.iter().enumerate() {
            first[v as usize].fetch_min((3 * offset + c) as u32, Ordering::Relaxed);
        }
    });
    first
}

/// `count(i)` for `i` in `0..len` summed before each `i`, and the total as one more entry:
/// per-chunk sums in parallel, a serial pass over the chunks' totals, then each chunk filled in
/// parallel. The counts are computed twice rather than stored: one array less to fault in.
fn exclusive_prefix_sum(len: usize, count: impl Fn(usize) -> u32 + Sync) -> Vec<u32> {
    const CHUNK: usize = 1 << 14;
    let chunk = |c: usize| c * CHUNK..((c + 1) * CHUNK).min(len);
    let totals: Vec<u32> = (0..len.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| chunk(c).map(&count).sum())
        .collect();
    let mut starts = Vec::with_capacity(totals.len());
    let mut sum = 0u32;
    for t in &totals {
        starts.push(sum);
        sum += t;
    }
    let mut out = vec![0u32; len + 1];
    out[len] = sum;
    out[..len]
        .par_chunks_mut(CHUNK)
        .zip(starts)
        .enumerate()
        .for_each(|(c, (out, mut at))| {
            for (o, i) in out.iter_mut().zip(chunk(c)) {
                *o = at;
                at += count(i);
            }
        });
    out
}

/// For each half-edge of the group, the first half-edge (in group order) of the same input
/// edge: the unordered pair of input vertex indices, kept apart per side on creases.
///
/// Two half-edges on the same input edge lie on the same welded edge, whose uses the topology
/// keeps in (triangle, corner) order, which is group order: so each half-edge looks only at
/// its welded edge's uses, and the whole pass is a parallel map. A welded edge with more than
/// [`FEW_USES`] uses (a book of triangles on one edge) is looked up in a table sorted once per
/// such edge, so that it costs `m log m`, not `m²`.
fn first_use_of_each_input_edge(
    mesh: &TriMesh,
    topo: &Topology,
    h: &[f64],
    range: Range<usize>,
) -> Vec<u32> {
    let start = range.start;
    // What makes two uses of a welded edge the same input edge: the input vertex pair, and on
    // a crease the half-edge itself (each side its own). `None` outside the group.
    // `crease`: whether the welded edge is a crease, the same for all its uses, so it is
    // decided once per half-edge, not once per use compared.
    let key_on = |crease: bool, tri: usize, k: usize| -> Option<InputEdge> {
        if !range.contains(&tri) {
            return None;
        }
        let t = mesh.triangles[tri];
        let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
        let side = if crease {
            (3 * (tri - start) + k) as u32
        } else {
            u32::MAX
        };
        Some((a.min(b), a.max(b), side))
    };
    let key = |tri: usize, k: usize| key_on(is_crease(topo, h, topo.tri_edges[tri][k]), tri, k);
    let half_of = |tri: usize, k: usize| (3 * (tri - start) + k) as u32;
    // Books: per welded edge with many uses, its group uses sorted by (key, half-edge).
    let mut books: Vec<(u32, Vec<(InputEdge, u32)>)> = (0..topo.edge_count())
        .into_par_iter()
        .filter(|&e| topo.edge_uses(EdgeId(e as u32)).len() > FEW_USES)
        .map(|e| {
            let mut uses: Vec<_> = topo
                .edge_uses(EdgeId(e as u32))
                .iter()
                .filter_map(|u| {
                    let (tri, k) = u.at();
                    Some((key(tri, k)?, half_of(tri, k)))
                })
                .collect();
            uses.sort_unstable();
            (e as u32, uses)
        })
        .collect();
    books.sort_unstable_by_key(|b| b.0);
    (0..3 * range.len())
        .into_par_iter()
        .map(|half| {
            let (tri, k) = (start + half / 3, half % 3);
            let e = topo.tri_edges[tri][k];
            let crease = is_crease(topo, h, e);
            let own = key_on(crease, tri, k).expect("in the group");
            let uses = topo.edge_uses(e);
            if uses.len() > FEW_USES {
                let book = &books[books.binary_search_by_key(&e.0, |b| b.0).expect("a book")].1;
                let at = book.partition_point(|&(key, _)| key < own);
                return book[at].1;
            }
            uses.iter()
                .find_map(|u| {
                    let (t, c) = u.at();
                    (key_on(crease, t, c) == Some(own)).then(|| half_of(t, c))
                })
                .expect("a half-edge is a use of its own welded edge")
        })
        .collect()
}

/// An input edge: its lower and higher input vertex, and on a crease the half-edge (each side
/// is its own edge there), else `u32::MAX`.
type InputEdge = (u32, u32, u32);

/// Uses of one welded edge up to which each half-edge scans them all (see
/// [`first_use_of_each_input_edge`]): a closed manifold has two, a seam or a crease a few more.
const FEW_USES: usize = 8;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::tests::odd_mesh;

    /// For each half-edge of the group, the first half-edge of the same input edge, by
    /// sorting every half-edge's key: the definition the welded-edge scan must reproduce.
    fn first_use_by_sorting(
        mesh: &TriMesh,
        topo: &Topology,
        h: &[f64],
        range: Range<usize>,
    ) -> Vec<u32> {
        let mut keys = Vec::new();
        for (offset, tri) in range.enumerate() {
            let t = mesh.triangles[tri];
            for k in 0..3 {
                let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
                let half = (3 * offset + k) as u32;
                let crease = is_crease(topo, h, topo.tri_edges[tri][k]);
                let side = if crease { half } else { u32::MAX };
                keys.push((a.min(b), a.max(b), side, half));
            }
        }
        keys.sort_unstable();
        let mut first = vec![0u32; keys.len()];
        let mut run_start = 0;
        for i in 0..keys.len() {
            let (a, b) = (keys[run_start], keys[i]);
            if (a.0, a.1, a.2) != (b.0, b.1, b.2) {
                run_start = i;
            }
            first[keys[i].3 as usize] = keys[run_start].3;
        }
        first
    }

    /// The numbering as one serial pass in triangle order: the definition the parallel
    /// steps must reproduce.
    fn serial(
        mesh: &TriMesh,
        topo: &Topology,
        h: &[f64],
        range: Range<usize>,
        per_edge: impl Fn(usize, usize) -> u32,
        interior: impl Fn(usize) -> u32,
    ) -> GroupLayout {
        let count = range.len();
        let first_half = first_use_by_sorting(mesh, topo, h, range.clone());
        let mut corner_of_vertex = vec![u32::MAX; mesh.positions.len()];
        let mut layout = GroupLayout {
            base: Vec::new(),
            corner_slot: vec![0; 3 * count],
            edge_slot: vec![0; 3 * count],
            owns: vec![0; count],
        };
        let mut next = 0u32;
        for (offset, tri) in range.enumerate() {
            layout.base.push(next);
            let mut owns = 0u8;
            for (c, &v) in mesh.triangles[tri].iter().enumerate() {
                let slot = &mut corner_of_vertex[v as usize];
                if *slot == u32::MAX {
                    *slot = next;
                    next += 1;
                    owns |= 1 << c;
                }
                layout.corner_slot[3 * offset + c] = *slot;
            }
            for k in 0..3 {
                let half = 3 * offset + k;
                let first = first_half[half] as usize;
                layout.edge_slot[half] = if first == half {
                    owns |= 8 << k;
                    next += per_edge(tri, k);
                    next - per_edge(tri, k)
                } else {
                    layout.edge_slot[first]
                };
            }
            layout.owns[offset] = owns;
            next += interior(tri);
        }
        layout.base.push(next);
        layout
    }

    /// `mesh` cut into pieces of `per` triangles, each on its own copy of the positions moved
    /// apart, so that welded edges have a few uses (seams, duplicates) instead of hundreds.
    fn spread(mesh: TriMesh, per: usize) -> TriMesh {
        let count = mesh.positions.len() as u32;
        let pieces = mesh.triangles.len().div_ceil(per);
        let offset = |piece: usize| glam::DVec3::X * (10 * piece) as f64;
        TriMesh {
            positions: (0..pieces)
                .flat_map(|p| mesh.positions.iter().map(move |&x| x + offset(p)))
                .collect(),
            normals: (0..pieces).flat_map(|_| mesh.normals.clone()).collect(),
            triangles: (mesh.triangles.iter().enumerate())
                .map(|(i, t)| t.map(|v| v + count * (i / per) as u32))
                .collect(),
        }
    }

    /// Without edge samples (level 1) the edges' first uses are not looked for: the corners'
    /// numbering is still the serial one, and no triangle writes an edge.
    #[test]
    fn without_edge_samples_the_corners_are_numbered_as_with_them() {
        for seed in 0..4 {
            let mesh = odd_mesh(seed, 20_000 + 1_000 * seed as usize);
            let mesh = if seed % 2 == 1 { spread(mesh, 6) } else { mesh };
            let topo = Topology::build(&mesh);
            let h: Vec<f64> = (0..topo.edge_count())
                .map(|e| if e % 3 == 0 { 0.0 } else { 0.5 })
                .collect();
            let len = mesh.triangles.len();
            for range in [0..len, 700..len - 300] {
                let expected = serial(&mesh, &topo, &h, range.clone(), |_, _| 0, |_| 0);
                let got = GroupLayout::new(&mesh, &topo, &h, 1, 0, range.clone());
                assert_eq!(got.base, expected.base, "seed {seed}");
                assert_eq!(got.corner_slot, expected.corner_slot, "seed {seed}");
                let corners: Vec<u8> = expected.owns.iter().map(|o| o & 7).collect();
                assert_eq!(got.owns, corners, "seed {seed}");
            }
        }
    }

    #[test]
    fn parallel_numbering_is_the_serial_first_use_numbering_at_any_thread_count() {
        for seed in 0..6 {
            // Enough triangles for several prefix-sum chunks; books, duplicates, degenerate
            // triangles and a vertex used twice by one triangle all occur; odd seeds spread
            // them out so that most welded edges have few uses.
            let mesh = odd_mesh(seed, 40_000 + 3_000 * seed as usize);
            let mesh = if seed % 2 == 1 { spread(mesh, 6) } else { mesh };
            let topo = Topology::build(&mesh);
            // Every third welded edge a crease, so creased sides get their own samples.
            let h: Vec<f64> = (0..topo.edge_count())
                .map(|e| if e % 3 == 0 { 0.0 } else { 0.5 })
                .collect();
            // Counts that differ per input edge (the same on both sides) and per triangle.
            let per_edge = |tri: usize, k: usize| {
                let t = mesh.triangles[tri];
                let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
                1 + (a.min(b) * 7 + a.max(b)) % 5
            };
            let interior = |tri: usize| (tri % 4) as u32;
            let len = mesh.triangles.len();
            for range in [0..len, 1_000..len - 2_000, 5..6] {
                let expected = serial(&mesh, &topo, &h, range.clone(), per_edge, interior);
                for threads in [1, 2, 3] {
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .unwrap();
                    let got = pool.install(|| {
                        GroupLayout::with_counts(
                            &mesh,
                            &topo,
                            &h,
                            range.clone(),
                            per_edge,
                            interior,
                        )
                    });
                    let what = format!("seed {seed}, triangles {range:?}, {threads} threads");
                    assert_eq!(got.base, expected.base, "{what}");
                    assert_eq!(got.owns, expected.owns, "{what}");
                    assert_eq!(got.corner_slot, expected.corner_slot, "{what}");
                    assert_eq!(got.edge_slot, expected.edge_slot, "{what}");
                }
            }
        }
    }
}
