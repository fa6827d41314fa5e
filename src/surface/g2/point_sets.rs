//! Weights of scattered points kept per set of points, as lattices' are per lattice part: the
//! chord error measurement asks for the same few dozen points (its triangles' vertices and
//! sample points at a source triangle's corners) on every source triangle with the same
//! pattern, and the weights of a point (Bernstein values and derivatives, subdomain, blend
//! weight, `pattern.rs`) cost about as much as combining them with the nets. With the weights
//! kept, a point costs its sums alone, two points at a time.
//!
//! A set is found by its points' bits, not by a name the caller gives: a hash picks the entry,
//! and the entry's points are compared before it is used, so a set is never taken for another.
//! The chord error measurement of whole patterns (seven samples of every output triangle: the
//! tolerance checks' and the report's) asks for sets too, one per pattern and width triple, far
//! larger; they are kept in stores of their own ([`TIERS`]). Past the bounds, points are
//! evaluated one by one as before, with the same bits.

use std::hash::{Hash, Hasher};

use super::positions::Positions;
use super::{G2Surface, PartEvaluation, Points};
use crate::surface::lattice_cache::LatticeCache;
use crate::surface::pattern::Pattern;
use crate::surface::{LatticePart, Profile, SurfacePoint};

/// The stores of sets by size: `(most points of a set, most sets kept)`, a set going to the
/// first whose size it fits. Weights take about 520 bytes per point (a whole level-16 lattice,
/// 153 points, about 80 kB). Sets are kept in the order first asked for; past a store's count,
/// or past the largest size, points are evaluated one by one: a bound on speed, never a
/// difference in bits. Each size has its own store so that the many large sets neither take
/// the small ones' places nor grow past a few tens of megabytes.
pub(super) const TIERS: [(usize, usize); 3] = [
    // A pattern's corner triangles' vertices and samples (the corner measurement's 40
    // points; the 10k icosphere at the error level 16 reaches uses about 100 sets): at most
    // about 8 MB.
    (64, 256),
    // The seven samples of each of the 144 output triangles of a pattern of inner level 12,
    // the finest the tolerance checks measure at every output triangle
    // (`tessellate::counts`), one set per pattern and width triple: at most about 33 MB.
    (7 * 144, 64),
    // The report's measurement of every output triangle, up to a uniform level 32's 1,024
    // (about 3.7 MB a set): at most about 30 MB. Finer patterns are measured point by point.
    (7 * 1024, 8),
];

/// One store per entry of [`TIERS`].
#[derive(Debug)]
pub(super) struct PointSetStores([PointSets; TIERS.len()]);

impl Default for PointSetStores {
    fn default() -> Self {
        PointSetStores(TIERS.map(|(_, sets)| PointSets::new(sets)))
    }
}

/// A set's key: its points' hash, how many are positions alone, the widths' bits, the profile.
type Key = (u64, usize, [u64; 3], Profile);

/// The kept sets of a surface.
pub(super) type PointSets = LatticeCache<Key, PointSet>;

/// The weights of one set of points: the first `positions.len` as positions alone, the rest
/// whole.
#[derive(Debug)]
pub(super) struct PointSet {
    barys: Vec<[f64; 3]>,
    positions: Pattern,
    whole: Pattern,
}

/// A hash of the points' bits (FNV-1a over the words: fast, and a collision only costs a
/// comparison, never a wrong entry).
fn hash_points(barys: &[[f64; 3]]) -> u64 {
    let mut hasher = Fnv(0xcbf2_9ce4_8422_2325);
    for b in barys {
        for x in b {
            x.to_bits().hash(&mut hasher);
        }
    }
    hasher.finish()
}

struct Fnv(u64);

impl Hasher for Fnv {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }

    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0 ^ x).wrapping_mul(0x0100_0000_01b3).rotate_left(29);
    }
}

impl G2Surface<'_> {
    /// The points at `barys` of triangle `tri`, the first `positions_only` as positions alone
    /// (normals zero), appended to `out` through the kept weights of the set; `false` (and
    /// nothing appended) when the set is not kept and there is no room to keep it.
    pub(super) fn point_set(
        &self,
        tri: usize,
        barys: &[[f64; 3]],
        positions_only: usize,
        out: &mut Vec<SurfacePoint>,
    ) -> bool {
        let Some(sets) = TIERS
            .iter()
            .zip(&self.point_sets.0)
            .find_map(|(&(points, _), sets)| (barys.len() <= points).then_some(sets))
        else {
            return false;
        };
        let widths = self.widths(tri);
        let key = (
            hash_points(barys),
            positions_only,
            widths.map(f64::to_bits),
            self.profile,
        );
        let build = || PointSet {
            barys: barys.to_vec(),
            positions: Pattern::at_points(&barys[..positions_only], widths, self.profile),
            whole: Pattern::at_points(&barys[positions_only..], widths, self.profile),
        };
        let Some(set) = sets.get_or_build(key, build) else {
            return false;
        };
        let same = set.barys.len() == barys.len()
            && set
                .barys
                .iter()
                .zip(barys)
                .all(|(a, b)| a.map(f64::to_bits) == b.map(f64::to_bits));
        if !same {
            return false;
        }
        let zero = SurfacePoint {
            position: glam::DVec3::ZERO,
            normal: glam::DVec3::ZERO,
        };
        let base = out.len();
        out.resize(base + barys.len(), zero);
        let (first, rest) = out[base..].split_at_mut(positions_only);
        PartEvaluation::set_up(self, tri, false, |evaluation| {
            evaluation.pattern_into(
                &set.positions,
                LatticePart::All,
                &mut Positions {
                    len: first.len(),
                    out: first,
                    slot: |target| target as usize,
                },
            );
            evaluation.pattern_into(&set.whole, LatticePart::All, &mut Points(rest));
        });
        true
    }
}
