//! A bounded, thread-safe store of per-lattice weights for the hybrid and Coons schemes, the
//! counterpart of the G² scheme's `PatternCache`.
//!
//! It deliberately knows nothing of what it stores: a key, and a function that builds the entry
//! on first use. Entries depend on the domain only, never on geometry, so whichever thread
//! builds one, every triangle reads the same values.

use std::collections::HashMap;
use std::fmt;
use std::hash::Hash;
use std::ops::Deref;
use std::sync::{Arc, OnceLock, RwLock};

/// Weights per key, at most `max` of them. Past the bound nothing is built: the caller computes
/// its points directly, which gives the same values, so the bound affects speed only.
pub struct LatticeCache<K, P> {
    /// The first entry built, read with no lock and no reference count: a tessellation asks
    /// for one key from every thread for every triangle, and the lock word and the count,
    /// written by both threads on each lookup, cost more than the lookup itself.
    first: OnceLock<(K, Arc<P>)>,
    map: RwLock<HashMap<K, Arc<P>>>,
    max: usize,
}

/// An entry of a [`LatticeCache`]: borrowed when it is the store's first entry, shared
/// otherwise.
#[derive(Debug)]
pub enum Entry<'a, P> {
    /// The first entry, held by the store.
    Borrowed(&'a P),
    /// Any other entry (or one built past the bound).
    Shared(Arc<P>),
}

impl<P> Deref for Entry<'_, P> {
    type Target = P;
    fn deref(&self) -> &P {
        match self {
            Entry::Borrowed(p) => p,
            Entry::Shared(p) => p,
        }
    }
}

impl<K: Hash + Eq + Clone, P> LatticeCache<K, P> {
    /// An empty store that keeps at most `max` entries.
    pub fn new(max: usize) -> Self {
        LatticeCache {
            first: OnceLock::new(),
            map: RwLock::new(HashMap::new()),
            max,
        }
    }

    /// The entry for `key`, built by `build` on first use; `None` when it is absent and the
    /// store is full.
    pub fn get_or_build(&self, key: K, build: impl FnOnce() -> P) -> Option<Entry<'_, P>> {
        if let Some((first, p)) = self.first.get() {
            if *first == key {
                return Some(Entry::Borrowed(p));
            }
        }
        if let Some(p) = self.map.read().expect("lattice cache lock").get(&key) {
            return Some(Entry::Shared(Arc::clone(p)));
        }
        if self.map.read().expect("lattice cache lock").len() >= self.max {
            return None;
        }
        let built = Arc::new(build());
        let mut map = self.map.write().expect("lattice cache lock");
        if map.len() < self.max {
            // Another thread may have built the same entry meanwhile: equal values, keep one.
            let kept = Arc::clone(map.entry(key.clone()).or_insert(built));
            let _ = self.first.set((key, Arc::clone(&kept)));
            Some(Entry::Shared(kept))
        } else {
            Some(Entry::Shared(built))
        }
    }
}

/// A copy starts empty: entries are rebuilt on demand, with the same values.
impl<K: Hash + Eq + Clone, P> Clone for LatticeCache<K, P> {
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
        assert!(cache.get_or_build(3, || 30).is_none());
        assert_eq!(cache.clone().get_or_build(3, || 30).as_deref(), Some(&30));
        // The first entry is the one read without a lock; the second comes from the map.
        assert!(matches!(
            cache.get_or_build(1, || 99),
            Some(Entry::Borrowed(&10))
        ));
        assert!(matches!(
            cache.get_or_build(2, || 99),
            Some(Entry::Shared(_))
        ));
    }
}
