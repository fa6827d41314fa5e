//! Transition patterns and their error models, each built once per process and shared by every
//! check, stage and mesh that asks for the same key.
//!
//! A pattern depends on its counts alone, and a model on the pattern and the lattice level it
//! reads, so whichever caller builds one, every caller reads the same values. The tolerance
//! checks of `counts.rs` used to build them per stage (one map per call of its raise), the
//! lowering of counts (`coarsen.rs`) and the tessellator once more, and every mesh of a file
//! its own: the 10 meshes of the PalmTree sample at a relative tolerance of 2e-4 built 17,631
//! patterns and as many models for 1,769 distinct keys, 42% of the whole run's instructions.
//!
//! The stores are bounded by bytes, first built, first kept: past the bound a pattern is built
//! for its caller and not kept, which costs time, never a difference in values.

use std::collections::HashMap;
use std::hash::Hash;
use std::sync::{Arc, Mutex, OnceLock};

use super::estimate::PatternModel;
use super::transition::{Pattern, PatternKey};

/// Most bytes of patterns kept: about 60 kB for a pattern of inner level 64, 2 kB at 12.
const PATTERN_BYTES: usize = 16 << 20;

/// Most bytes of models kept: about 80 bytes per boundary sample, 45 kB at inner level 64.
const MODEL_BYTES: usize = 16 << 20;

/// The pattern of `key`, kept for every later caller while the store has room.
pub(crate) fn pattern(key: PatternKey) -> Arc<Pattern> {
    static PATTERNS: OnceLock<Store<PatternKey, Pattern>> = OnceLock::new();
    PATTERNS
        .get_or_init(|| Store::new(PATTERN_BYTES))
        .get_or_build(key, || {
            let pattern = Pattern::new(key);
            let bytes = pattern.bytes();
            (pattern, bytes)
        })
}

/// The model of `key`'s pattern over a level-`level` lattice ([`PatternModel::new`]), kept as
/// [`pattern`] keeps patterns.
pub(crate) fn model(key: PatternKey, level: u32) -> Arc<PatternModel> {
    static MODELS: OnceLock<Store<(PatternKey, u32), PatternModel>> = OnceLock::new();
    MODELS
        .get_or_init(|| Store::new(MODEL_BYTES))
        .get_or_build((key, level), || {
            let model = PatternModel::new(&pattern(key), level);
            let bytes = model.bytes();
            (model, bytes)
        })
}

/// Values by key, at most `limit` bytes of them.
struct Store<K, V> {
    kept: Mutex<(HashMap<K, Arc<V>>, usize)>,
    limit: usize,
}

impl<K: Hash + Eq + Copy, V> Store<K, V> {
    fn new(limit: usize) -> Store<K, V> {
        Store {
            kept: Mutex::new((HashMap::new(), 0)),
            limit,
        }
    }

    /// The value of `key`: the kept one, or `build`'s (the value and its size in bytes),
    /// kept if it fits. Built outside the lock, so threads building different keys do not
    /// wait for each other; two building the same key at once both build it, and the first
    /// to finish is kept (the values are equal).
    fn get_or_build(&self, key: K, build: impl FnOnce() -> (V, usize)) -> Arc<V> {
        if let Some(value) = self.lock().0.get(&key) {
            return Arc::clone(value);
        }
        let (value, bytes) = build();
        let value = Arc::new(value);
        let mut kept = self.lock();
        if let Some(first) = kept.0.get(&key) {
            return Arc::clone(first);
        }
        if kept.1 + bytes <= self.limit {
            kept.1 += bytes;
            kept.0.insert(key, Arc::clone(&value));
        }
        value
    }

    /// The kept values; a poisoned lock still holds whole entries (they are inserted whole).
    fn lock(&self) -> std::sync::MutexGuard<'_, (HashMap<K, Arc<V>>, usize)> {
        self.kept
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A kept pattern or model is the one built for its key, whichever key was asked for
    /// before it, and a store past its bound still gives every caller its value.
    #[test]
    fn kept_patterns_and_models_are_those_of_their_keys() {
        let keys = [
            PatternKey::new([3, 4, 5], 4),
            PatternKey::new([5, 4, 3], 4),
            PatternKey::new([2, 3, 3], 2),
            PatternKey::new([12, 12, 12], 12),
        ];
        for _ in 0..2 {
            for key in keys {
                let kept = pattern(key);
                let built = Pattern::new(key);
                assert_eq!(kept.key, key);
                assert_eq!(kept.triangles, built.triangles, "{key:?}");
                assert_eq!(kept.lattice, built.lattice, "{key:?}");
                for level in [6, key.inner.max(3), 2 * key.inner] {
                    let kept = model(key, level);
                    let built = PatternModel::new(&built, level);
                    assert_eq!(format!("{kept:?}"), format!("{built:?}"), "{key:?} {level}");
                }
            }
        }
        let full: Store<u32, u32> = Store::new(8);
        for x in 0..4 {
            assert_eq!(*full.get_or_build(x, || (10 * x, 4)), 10 * x);
        }
        assert_eq!(full.lock().0.len(), 2, "kept past the bound");
        assert_eq!(
            *full.get_or_build(3, || (99, 4)),
            99,
            "not kept: built again"
        );
        assert_eq!(
            *full.get_or_build(1, || (99, 4)),
            10,
            "kept: not built again"
        );
    }
}
