//! A bounded, thread-safe store of per-lattice weights, shared by every scheme: the G² patterns
//! ([`super::pattern::PatternCache`]) and the hybrid and Coons lattice weights.
//!
//! It deliberately knows nothing of what it stores: a key, and a function that builds the entry
//! on first use. Entries depend on the domain only, never on geometry, so whichever thread
//! builds one, every triangle reads the same values.
//!
//! A tessellation asks for an entry once per triangle and lattice part, from every thread at
//! once, and almost always for the same few keys. The first [`HOT_ENTRIES`] entries built are
//! therefore also kept in slots that are written once and then only read: a lookup that hits
//! them takes no lock and no reference count. Through the lock alone, the lock word and the
//! count, written by both threads on every lookup, held two threads to 1.4× one in the G²
//! tessellator (1.9× with the slots).

use std::collections::HashMap;
use std::fmt;
use std::hash::Hash;
use std::ops::Deref;
use std::sync::{Arc, OnceLock, RwLock};

/// Entries kept in write-once slots, read without a lock (see the module docs): a triangle's
/// interior and its three edges for four width triples.
pub const HOT_ENTRIES: usize = 16;

/// Weights per key, at most `max` of them, or entries weighing at most `max` in all
/// ([`LatticeCache::weighed`]). Past the bound nothing is built: the caller decides what to do
/// instead (compute its points directly, or build an entry it does not keep), which gives the
/// same values, so the bound affects speed only.
pub struct LatticeCache<K, P> {
    /// The first entries built, in the order they were built (filled slots form a prefix).
    hot: HotSlots<K, P>,
    /// The entries and their total weight.
    map: RwLock<(HashMap<K, Arc<P>>, usize)>,
    max: usize,
    /// What an entry counts against `max`: 1 each, or, for entries whose sizes differ many
    /// times over (transition patterns), their bytes.
    weigh: fn(&P) -> usize,
}

/// The hot slots on cache lines of their own: they are read by every thread for every triangle,
/// and a line shared with memory another thread writes (the store sits on the heap among the
/// tessellator's scratch buffers) would be pulled back and forth between the cores.
#[repr(align(128))]
struct HotSlots<K, P>([OnceLock<(K, Arc<P>)>; HOT_ENTRIES]);

/// An entry of a [`LatticeCache`]: borrowed from a hot slot, or shared.
#[derive(Debug)]
pub enum Entry<'a, P> {
    /// An entry held in one of the store's hot slots.
    Borrowed(&'a P),
    /// Any other entry.
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
        LatticeCache::weighed(max, |_| 1)
    }

    /// An empty store that keeps entries while their total `weigh` is at most `max`.
    pub fn weighed(max: usize, weigh: fn(&P) -> usize) -> Self {
        LatticeCache {
            hot: HotSlots(std::array::from_fn(|_| OnceLock::new())),
            map: RwLock::new((HashMap::new(), 0)),
            max,
            weigh,
        }
    }

    /// The entry for `key`, built by `build` on first use; `None` when it is absent and the
    /// store is full.
    pub fn get_or_build(&self, key: K, build: impl FnOnce() -> P) -> Option<Entry<'_, P>> {
        for slot in &self.hot.0 {
            match slot.get() {
                Some((k, p)) if *k == key => return Some(Entry::Borrowed(p)),
                Some(_) => continue,
                None => break,
            }
        }
        {
            let map = self.map.read().expect("lattice cache lock");
            if let Some(p) = map.0.get(&key) {
                return Some(Entry::Shared(Arc::clone(p)));
            }
            if map.1 >= self.max {
                return None;
            }
        }
        let built = Arc::new(build());
        let weight = (self.weigh)(&built);
        let mut map = self.map.write().expect("lattice cache lock");
        // Another thread may have built the same entry meanwhile: equal values, keep one.
        if let Some(p) = map.0.get(&key) {
            return Some(Entry::Shared(Arc::clone(p)));
        }
        if map.1 + weight > self.max {
            return Some(Entry::Shared(built));
        }
        map.1 += weight;
        map.0.insert(key.clone(), Arc::clone(&built));
        let kept = built;
        // Slots are tried in order, so the filled ones stay a prefix.
        for slot in &self.hot.0 {
            if slot.get().is_some_and(|(k, _)| *k == key)
                || slot.set((key.clone(), Arc::clone(&kept))).is_ok()
            {
                break;
            }
        }
        Some(Entry::Shared(kept))
    }
}

/// A copy starts empty: entries are rebuilt on demand, with the same values.
impl<K: Hash + Eq + Clone, P> Clone for LatticeCache<K, P> {
    fn clone(&self) -> Self {
        LatticeCache::weighed(self.max, self.weigh)
    }
}

impl<K, P> fmt::Debug for LatticeCache<K, P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let len = self.map.read().map(|m| m.0.len()).unwrap_or(0);
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
        // Kept entries are then read from the hot slots, without a lock.
        assert!(matches!(
            cache.get_or_build(1, || 99),
            Some(Entry::Borrowed(&10))
        ));
        assert!(matches!(
            cache.get_or_build(2, || 99),
            Some(Entry::Borrowed(&20))
        ));
    }

    /// A weighed store keeps entries while their weights fit, gives one that does not fit to
    /// its caller without keeping it, and builds nothing once the weights reach the bound.
    #[test]
    fn a_weighed_store_keeps_entries_while_their_weights_fit() {
        let cache: LatticeCache<u32, u32> = LatticeCache::weighed(10, |&v| v as usize);
        assert_eq!(cache.get_or_build(1, || 4).as_deref(), Some(&4));
        // 4 + 7 > 10: given, not kept.
        assert_eq!(cache.get_or_build(2, || 7).as_deref(), Some(&7));
        assert_eq!(cache.get_or_build(2, || 5).as_deref(), Some(&5));
        // 4 + 5 + 1 = 10: kept, and the store is full.
        assert_eq!(cache.get_or_build(3, || 1).as_deref(), Some(&1));
        assert_eq!(cache.get_or_build(2, || 99).as_deref(), Some(&5));
        assert!(cache.get_or_build(4, || 0).is_none());
        assert_eq!(cache.get_or_build(1, || 99).as_deref(), Some(&4));
    }

    #[test]
    fn the_first_entries_are_hot_and_later_ones_come_from_the_map() {
        let cache: LatticeCache<usize, usize> = LatticeCache::new(100);
        let n = HOT_ENTRIES + 4;
        for k in 0..n {
            assert_eq!(cache.get_or_build(k, || 10 * k).as_deref(), Some(&(10 * k)));
        }
        for k in 0..n {
            let entry = cache.get_or_build(k, || unreachable!("kept"));
            assert_eq!(*entry.as_deref().unwrap(), 10 * k);
            assert_eq!(
                matches!(entry, Some(Entry::Borrowed(_))),
                k < HOT_ENTRIES,
                "key {k}"
            );
        }
    }
}
