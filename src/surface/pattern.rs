//! Everything about a domain point that does not depend on geometry: the Bernstein basis, the
//! subdomain and the blend weight. Computed per point for [`Surface::evaluate`](super::Surface),
//! and once per (level, edge widths, profile) for a whole lattice, then reused by every triangle
//! with the same widths.
//!
//! It deliberately holds no positions or normals; combining weights with control nets is
//! `g2.rs`'s job.

use std::collections::HashMap;
use std::sync::{Arc, RwLock};

use super::blend::BlendWeight;
use super::pn::Bernstein;
use super::profile::Profile;
use super::{lattice_bary, lattice_len};

/// The geometry-free data of one domain point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointWeights {
    /// The point's barycentrics.
    pub bary: [f64; 3],
    /// `Some(c)` when the point is exactly corner `c`.
    pub corner: Option<u8>,
    /// Bernstein basis and derivatives at `bary`.
    pub basis: Bernstein,
    /// Subdomain and blend weight.
    pub blend: BlendWeight,
}

impl PointWeights {
    /// Weights at barycentrics `bary` for widths `h` (by opposite corner) and `profile`.
    pub fn at(bary: [f64; 3], h: [f64; 3], profile: Profile) -> PointWeights {
        let corner = (0..3)
            .find(|&c| bary[c] == 1.0 && bary[(c + 1) % 3] == 0.0 && bary[(c + 2) % 3] == 0.0);
        PointWeights {
            bary,
            corner: corner.map(|c| c as u8),
            basis: Bernstein::at(bary),
            blend: BlendWeight::at(bary, h, profile),
        }
    }
}

/// The weights of every point of a level-`n` lattice, in lattice order.
#[derive(Debug, Clone, PartialEq)]
pub struct Pattern {
    pub points: Vec<PointWeights>,
}

impl Pattern {
    /// Computes the pattern for level `n ≥ 1`.
    pub fn new(n: u32, h: [f64; 3], profile: Profile) -> Pattern {
        let mut points = Vec::with_capacity(lattice_len(n));
        for j in 0..=n {
            for i in 0..=n - j {
                points.push(PointWeights::at(lattice_bary(n, i, j), h, profile));
            }
        }
        Pattern { points }
    }
}

/// Patterns keyed by level, the bit patterns of the three widths, and the profile.
type Key = (u32, [u64; 3], Profile);

/// A shared, thread-safe store of patterns. Meshes with many distinct width triples would make
/// it grow without reuse, so past [`PatternCache::MAX_ENTRIES`] new patterns are built but not
/// kept.
#[derive(Debug, Default)]
pub struct PatternCache {
    map: RwLock<HashMap<Key, Arc<Pattern>>>,
}

impl PatternCache {
    /// Most patterns kept (a level-16 pattern is about 40 kB).
    pub const MAX_ENTRIES: usize = 1024;

    /// The pattern for this key, built on first use.
    pub fn get(&self, n: u32, h: [f64; 3], profile: Profile) -> Arc<Pattern> {
        let key = (n, h.map(f64::to_bits), profile);
        if let Some(p) = self.map.read().expect("pattern cache lock").get(&key) {
            return Arc::clone(p);
        }
        let pattern = Arc::new(Pattern::new(n, h, profile));
        let mut map = self.map.write().expect("pattern cache lock");
        if map.len() < Self::MAX_ENTRIES {
            map.entry(key).or_insert_with(|| Arc::clone(&pattern));
        }
        pattern
    }
}
