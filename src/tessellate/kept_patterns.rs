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
//! They are kept in the stores the surfaces keep their lattice weights in ([`LatticeCache`]),
//! bounded by bytes rather than by count, as a pattern of inner level 64 takes thirty times
//! what one of level 12 does: first built, first kept, and past the bound a pattern is built for
//! its caller and not kept, which costs time, never a difference in values.

use std::sync::{Arc, OnceLock};

use super::estimate::PatternModel;
use super::transition::{Pattern, PatternKey};
use crate::surface::lattice_cache::{Entry, LatticeCache};

/// Most bytes of patterns kept: about 60 kB for a pattern of inner level 64, 2 kB at 12.
const PATTERN_BYTES: usize = 16 << 20;

/// Most bytes of models kept: about 80 bytes per boundary sample, 45 kB at inner level 64.
const MODEL_BYTES: usize = 16 << 20;

/// A kept pattern or model, or one built for its caller alone.
pub(crate) type Kept<P> = Entry<'static, P>;

/// The pattern of `key`, kept for every later caller while the store has room.
pub(crate) fn pattern(key: PatternKey) -> Kept<Pattern> {
    static PATTERNS: OnceLock<LatticeCache<PatternKey, Pattern>> = OnceLock::new();
    let build = || Pattern::new(key);
    PATTERNS
        .get_or_init(|| LatticeCache::weighed(PATTERN_BYTES, Pattern::bytes))
        .get_or_build(key, build)
        .unwrap_or_else(|| Entry::Shared(Arc::new(build())))
}

/// The model of `key`'s pattern over a level-`level` lattice ([`PatternModel::new`]), kept as
/// [`pattern`] keeps patterns.
pub(crate) fn model(key: PatternKey, level: u32) -> Kept<PatternModel> {
    static MODELS: OnceLock<LatticeCache<(PatternKey, u32), PatternModel>> = OnceLock::new();
    let build = || PatternModel::new(&pattern(key), level);
    MODELS
        .get_or_init(|| LatticeCache::weighed(MODEL_BYTES, PatternModel::bytes))
        .get_or_build((key, level), build)
        .unwrap_or_else(|| Entry::Shared(Arc::new(build())))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A kept pattern or model is the one built for its key, whichever key was asked for
    /// before it, the first time and every time after.
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
                    assert_eq!(
                        format!("{:?}", &*kept),
                        format!("{built:?}"),
                        "{key:?} {level}"
                    );
                }
            }
        }
    }
}
