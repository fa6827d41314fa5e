//! A bounded, thread-safe store of per-lattice weights for the hybrid and Coons schemes, the
//! counterpart of the G² scheme's `PatternCache`.
//!
//! It deliberately knows nothing of what it stores: a key, and a function that builds the entry
//! on first use. Entries depend on the domain only, never on geometry, so whichever thread
//! builds one, every triangle reads the same values.

use std::collections::HashMap;
use std::fmt;
use std::hash::Hash;
use std::sync::{Arc, RwLock};

/// Weights per key, at most `max` of them. Past the bound nothing is built: the caller computes
/// its points directly, which gives the same values, so the bound affects speed only.
pub struct LatticeCache<K, P> {
    map: RwLock<HashMap<K, Arc<P>>>,
    max: usize,
}

impl<K: Hash + Eq, P> LatticeCache<K, P> {
    /// An empty store that keeps at most `max` entries.
    pub fn new(max: usize) -> Self {
        LatticeCache {
            map: RwLock::new(HashMap::new()),
            max,
        }
    }

    /// The entry for `key`, built by `build` on first use; `None` when it is absent and the
    /// store is full.
    pub fn get_or_build(&self, key: K, build: impl FnOnce() -> P) -> Option<Arc<P>> {
        if let Some(p) = self.map.read().expect("lattice cache lock").get(&key) {
            return Some(Arc::clone(p));
        }
        if self.map.read().expect("lattice cache lock").len() >= self.max {
            return None;
        }
        let built = Arc::new(build());
        let mut map = self.map.write().expect("lattice cache lock");
        if map.len() < self.max {
            // Another thread may have built the same entry meanwhile: equal values, keep one.
            Some(Arc::clone(map.entry(key).or_insert(built)))
        } else {
            Some(built)
        }
    }
}

/// A copy starts empty: entries are rebuilt on demand, with the same values.
impl<K: Hash + Eq, P> Clone for LatticeCache<K, P> {
    fn clone(&self) -> Self {
        LatticeCache::new(self.max)
    }
}

impl<K, P> fmt::Debug for LatticeCache<K, P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let len = self.map.read().map(|m| m.len()).unwrap_or(0);
        f.debug_struct("LatticeCache")
            .field("entries", &len)
            .field("max", &self.max)
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_entries_up_to_its_bound_then_builds_nothing() {
        let cache: LatticeCache<u32, u32> = LatticeCache::new(2);
        assert_eq!(cache.get_or_build(1, || 10).as_deref(), Some(&10));
        assert_eq!(cache.get_or_build(2, || 20).as_deref(), Some(&20));
        // Kept: not rebuilt.
        assert_eq!(cache.get_or_build(1, || 99).as_deref(), Some(&10));
        // Full: the caller computes directly.
        assert_eq!(cache.get_or_build(3, || 30), None);
        assert_eq!(cache.clone().get_or_build(3, || 30).as_deref(), Some(&30));
    }
}
