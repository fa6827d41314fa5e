//! The interior points of the lattices the tolerance checks evaluate at a pattern's own
//! resolution, held from the checks to the write so that the output does not evaluate them
//! again.
//!
//! Stage 1 of [`super::ChordErrors::refine_to_tolerance`] reads each triangle's lattice of its
//! inner level `m` (when `m` is at least the probe's level). By the [`crate::surface::Surface`]
//! contract that lattice's points equal [`crate::surface::Surface::evaluate`] at
//! [`crate::surface::lattice_bary`] bit for bit, as the output's interior points, the level-`m`
//! lattice's [`crate::surface::LatticePart::Interior`], do: where the final inner level is the
//! one checked, the points the check read are the output's interior, and writing them as the
//! output writes a point (position and normal rounded to `f32`) gives the same bytes. On the
//! 10k icosphere at the error level 16 reaches that is about 1.2M of the output's 1.35M points
//! (the edges' samples are still evaluated by each welded edge's one evaluating triangle, as
//! for watertightness they must be).
//!
//! Only what the output writes is held, 24 bytes a point, and at most [`HELD_BYTES`] in all;
//! beyond it a triangle's interior is evaluated at the write, with the same bits. It
//! deliberately decides nothing: which lattice to offer is the checks' choice, which to use the
//! writer's (the one of the final inner level).

use std::collections::HashMap;
use std::sync::Mutex;

use super::blocks::Block;
use super::VertexSource;
use crate::surface::{lattice_index, LatticePart, SurfacePoint};

/// The most memory the held interiors may take (about 2.8M points): past it a triangle's
/// interior is evaluated again at the write. The 10k icosphere at the error level 16 reaches
/// holds about 29 MB.
pub const HELD_BYTES: usize = 64 << 20;

/// One output point as the output writes it: position and normal rounded to `f32`.
type HeldPoint = [[f32; 3]; 2];

/// Held interior points, by source triangle: the inner level they are the interior of, and
/// the points in the lattice's interior order.
#[derive(Debug, Default)]
pub struct HeldInteriors {
    by_tri: HashMap<u32, (u32, Box<[HeldPoint]>)>,
    bytes: usize,
}

/// [`HeldInteriors`] being filled by the checks, from many threads.
#[derive(Debug)]
pub(crate) struct Holding {
    held: Mutex<HeldInteriors>,
    limit: usize,
}

impl Holding {
    /// Holds at most `limit` bytes of points.
    pub fn new(limit: usize) -> Holding {
        Holding {
            held: Mutex::new(HeldInteriors::default()),
            limit,
        }
    }

    /// Holds the interior of `points`, the whole level-`level` lattice of `tri` in lattice
    /// order, in place of what `tri` held before (a lattice of a lower inner level, which the
    /// output will not use), when it fits.
    pub fn offer(&self, tri: usize, level: u32, points: &[SurfacePoint]) {
        let len = LatticePart::Interior.len(level);
        let bytes = len * std::mem::size_of::<HeldPoint>();
        let fits = |held: &HeldInteriors| self.held_after(held, tri, bytes);
        if len == 0 || fits(&self.held.lock().expect("no check panics while holding")).is_none() {
            return;
        }
        let mut interior = Vec::with_capacity(len);
        for j in 1..level {
            let start = lattice_index(level, 1, j);
            let row = &points[start..start + (level - 1 - j) as usize];
            interior.extend(row.iter().map(|p| {
                [
                    p.position.as_vec3().to_array(),
                    p.normal.as_vec3().to_array(),
                ]
            }));
        }
        debug_assert_eq!(interior.len(), len);
        let mut held = self.held.lock().expect("no check panics while holding");
        // Another thread may have taken the room meanwhile.
        if let Some(after) = fits(&held) {
            held.bytes = after;
            held.by_tri
                .insert(tri as u32, (level, interior.into_boxed_slice()));
        }
    }

    /// The bytes `held` would hold with `bytes` of points for `tri` in place of what it holds
    /// for it now, if that is within the limit.
    fn held_after(&self, held: &HeldInteriors, tri: usize, bytes: usize) -> Option<usize> {
        let before = held.by_tri.get(&(tri as u32)).map_or(0, |(_, p)| p.len());
        let after = held.bytes - before * std::mem::size_of::<HeldPoint>() + bytes;
        (after <= self.limit).then_some(after)
    }

    /// What is held for the triangles whose inner level in `inner` is the one held: the rest
    /// is freed.
    pub fn finish(self, inner: &[u32]) -> HeldInteriors {
        let mut held = self
            .held
            .into_inner()
            .expect("no check panics while holding");
        held.by_tri
            .retain(|&tri, (level, _)| inner.get(tri as usize) == Some(level));
        held.bytes = held
            .by_tri
            .values()
            .map(|(_, p)| p.len() * std::mem::size_of::<HeldPoint>())
            .sum();
        held.by_tri.shrink_to_fit();
        held
    }
}

impl HeldInteriors {
    /// Source triangles with a held interior.
    pub fn len(&self) -> usize {
        self.by_tri.len()
    }

    /// Whether nothing is held.
    pub fn is_empty(&self) -> bool {
        self.by_tri.is_empty()
    }

    /// Bytes of points held.
    pub fn bytes(&self) -> usize {
        self.bytes
    }

    /// The held interior of `tri` if it is that of the level-`level` lattice.
    pub(super) fn get(&self, tri: usize, level: u32) -> Option<&[HeldPoint]> {
        self.by_tri
            .get(&(tri as u32))
            .filter(|(l, _)| *l == level)
            .map(|(_, points)| &points[..])
    }
}

/// Writes a held interior as [`super::emit::TriangleWriter::interior`] writes an evaluated one:
/// `by_rank` gives, in output order, each interior point's local point and its index in the
/// interior; their slots are consecutive from `first_slot`.
pub(super) fn write_interior(
    block: &mut Block<'_>,
    local: &mut [u32],
    points: &[HeldPoint],
    first_slot: usize,
    by_rank: impl Iterator<Item = (usize, usize)>,
    source: impl Fn(usize) -> VertexSource,
) {
    for (rank, (point, index)) in by_rank.enumerate() {
        let slot = first_slot + rank;
        local[point] = slot as u32;
        let [position, normal] = points[index];
        block.put(slot, position, normal, source(point));
    }
}
