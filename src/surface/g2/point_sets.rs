//! Weights of scattered points kept per set of points, as lattices' are per lattice part: the
//! chord error measurement asks for the same few dozen points (its triangles' vertices and
//! sample points at a source triangle's corners) on every source triangle with the same
//! pattern, and the weights of a point (Bernstein values and derivatives, subdomain, blend
//! weight, `pattern.rs`) cost about as much as combining them with the nets. With the weights
//! kept, a point costs its sums alone, two points at a time.
//!
//! A set is found by its points' bits, not by a name the caller gives: a hash picks the entry,
//! and the entry's points are compared before it is used, so a set is never taken for another.
//! Past [`MAX_SETS`] kept, points are evaluated one by one as before, with the same bits.

use std::hash::{Hash, Hasher};

use super::positions::Positions;
use super::{G2Surface, PartEvaluation, Points};
use crate::surface::lattice_cache::LatticeCache;
use crate::surface::pattern::Pattern;
use crate::surface::{LatticePart, Profile, SurfacePoint};

/// Most sets kept: about 20 kB each for the corner measurement's 40 points (the 10k icosphere
/// at the error level 16 reaches uses about 100), so at most about 5 MB.
pub(super) const MAX_SETS: usize = 256;

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
        let Some(set) = self.point_sets.get_or_build(key, build) else {
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
