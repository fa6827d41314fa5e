//! A lattice evaluated from the one of half its level: the chord error checks read a triangle's
//! lattice at its pattern's own level, then, where they cannot show that the finer check
//! passes, the lattice of twice that level, whose even points `(2i, 2j)` are the coarser
//! lattice's points `(i, j)`. Their barycentrics are the same bits (`2i/2n` and `i/n` are the
//! same real number, rounded once), so are their weights and their sums: the coarse points are
//! copied and only the other three quarters evaluated.
//!
//! The points a level-`n` lattice adds to the level-`n/2` one have their weights kept per
//! level, widths and profile, as a lattice part's are ([`OddPoints`]): the interior ones whole
//! (the checks read their normals), the edge ones as positions alone (`positions.rs`), each
//! group through a pattern built from its points' barycentrics, whose sums give every point
//! the bits its lattice part's pattern gives it (each lane's sums are its own).

use std::sync::Arc;

use glam::DVec3;

use super::positions::Positions;
use super::{PartEvaluation, PointSink};
use crate::surface::lattice_cache::{Entry, LatticeCache};
use crate::surface::pattern::Pattern;
use crate::surface::{
    lattice_bary, lattice_index, lattice_len, LatticePart, Profile, SurfacePoint,
};

/// Most kept entries: a level for each of a few width triples (on the 10k icosphere at the
/// error level 16 reaches, levels 32 to 34 with one triple, about 100 kB each).
pub(super) const MAX_LEVELS: usize = 64;

/// An entry's key: the fine level, the widths' bits, the profile.
type Key = (u32, [u64; 3], Profile);

/// The kept entries of a surface.
pub(super) type OddPointsCache = LatticeCache<Key, OddPoints>;

/// The points of the level-`n` lattice (`n` even) that are not points of the level-`n/2` one:
/// interior and per edge, each with the lattice index its targets go to.
#[derive(Debug)]
pub(super) struct OddPoints {
    interior: Pattern,
    interior_slots: Vec<u32>,
    edges: [(Pattern, Vec<u32>); 3],
}

/// Whether lattice point `(i, j)` is a point of the lattice of half the level.
#[inline]
fn even(i: u32, j: u32) -> bool {
    i % 2 == 0 && j % 2 == 0
}

impl OddPoints {
    fn new(n: u32, h: [f64; 3], profile: Profile) -> OddPoints {
        let odd = |part: LatticePart| -> (Pattern, Vec<u32>) {
            let points: Vec<(u32, u32)> = part
                .points(n)
                .into_iter()
                .filter(|&(i, j)| !even(i, j))
                .collect();
            let barys: Vec<[f64; 3]> = points.iter().map(|&(i, j)| lattice_bary(n, i, j)).collect();
            let slots = points
                .iter()
                .map(|&(i, j)| lattice_index(n, i, j) as u32)
                .collect();
            (Pattern::at_part_points(&barys, part, h, profile), slots)
        };
        let (interior, interior_slots) = odd(LatticePart::Interior);
        OddPoints {
            interior,
            interior_slots,
            edges: [0, 1, 2].map(|k| odd(LatticePart::Edge(k))),
        }
    }
}

/// Whole points written at the lattice indices `slots` gives their targets.
struct WholeAt<'o, 's> {
    out: &'o mut [SurfacePoint],
    slots: &'s [u32],
}

impl PointSink for WholeAt<'_, '_> {
    fn len(&self) -> usize {
        self.slots.len()
    }

    #[inline(always)]
    fn put(&mut self, target: u32, point: SurfacePoint) {
        self.out[self.slots[target as usize] as usize] = point;
    }
}

impl PartEvaluation<'_, '_> {
    /// [`PartEvaluation::lattice_with_edge_positions`] of the level-`level` lattice (`level`
    /// even), appended to `out`, with its even points copied from `coarse`, that lattice of
    /// level `level / 2`.
    pub(super) fn refined_lattice_with_edge_positions(
        &mut self,
        level: u32,
        coarse: &[SurfacePoint],
        out: &mut Vec<SurfacePoint>,
    ) {
        debug_assert!(level % 2 == 0 && coarse.len() == lattice_len(level / 2));
        let zero = SurfacePoint {
            position: DVec3::ZERO,
            normal: DVec3::ZERO,
        };
        let base = out.len();
        out.resize(base + lattice_len(level), zero);
        let lattice = &mut out[base..];
        let half = level / 2;
        for j in 0..=half {
            let from = lattice_index(half, 0, j);
            let row = &coarse[from..from + (half + 1 - j) as usize];
            let start = lattice_index(level, 0, 2 * j);
            for (i, p) in row.iter().enumerate() {
                lattice[start + 2 * i] = *p;
            }
        }
        let surface = self.surface;
        let key = (level, self.widths.map(f64::to_bits), surface.profile);
        let build = || OddPoints::new(level, self.widths, surface.profile);
        let odd = surface
            .odd_points
            .get_or_build(key, build)
            .unwrap_or_else(|| Entry::Shared(Arc::new(build())));
        self.pattern_into(
            &odd.interior,
            LatticePart::Interior,
            &mut WholeAt {
                out: &mut *lattice,
                slots: &odd.interior_slots,
            },
        );
        for (k, (pattern, slots)) in odd.edges.iter().enumerate() {
            self.pattern_into(
                pattern,
                LatticePart::Edge(k as u8),
                &mut Positions {
                    out: &mut *lattice,
                    len: slots.len(),
                    slot: |target| slots[target as usize] as usize,
                },
            );
        }
    }
}
