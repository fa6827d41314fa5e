//! A union-find that many threads join at once, for the connectivity checks (bow-tie vertices,
//! pieces): the joins are independent of each other, so a sequential forest left one core idle
//! on large meshes.
//!
//! Every link puts the larger root under the smaller, with a compare-and-swap on the larger
//! root's parent, so a parent is never larger than its child and the root of every class is
//! its smallest member. The classes are the connected components of the joins, in whatever order
//! the threads ran them, so the roots, and every figure counted from them, are the same on any
//! thread count.

use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Classes of `0..n`, joined concurrently through a shared reference.
pub(super) struct UnionFind {
    parent: Vec<AtomicU32>,
}

impl UnionFind {
    /// `n` classes of one element each.
    pub(super) fn new(n: u32) -> UnionFind {
        UnionFind {
            parent: (0..n).map(AtomicU32::new).collect(),
        }
    }

    /// Joins the classes of `a` and `b`.
    pub(super) fn union(&self, a: u32, b: u32) {
        let (mut a, mut b) = (a, b);
        loop {
            let (ra, rb) = (self.root(a), self.root(b));
            if ra == rb {
                return;
            }
            let (low, high) = (ra.min(rb), ra.max(rb));
            // Another thread may have linked `high` meanwhile: then start again from the roots.
            if self.parent[high as usize]
                .compare_exchange(high, low, Relaxed, Relaxed)
                .is_ok()
            {
                return;
            }
            (a, b) = (high, low);
        }
    }

    /// The root of `i`'s class (its smallest member once every join is done), halving the path
    /// on the way: each parent is replaced by its grandparent, which is still an ancestor
    /// whatever other threads link meanwhile.
    pub(super) fn root(&self, mut i: u32) -> u32 {
        loop {
            let p = self.parent[i as usize].load(Relaxed);
            if p == i {
                return i;
            }
            let grand = self.parent[p as usize].load(Relaxed);
            if grand != p {
                self.parent[i as usize].store(grand, Relaxed);
            }
            i = grand;
        }
    }

    /// Whether `i` is the root of its class.
    pub(super) fn is_root(&self, i: u32) -> bool {
        self.parent[i as usize].load(Relaxed) == i
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn classes_are_the_components_with_their_smallest_member_as_root_on_any_thread_count() {
        // Pseudo-random joins over 20 000 elements: long chains, stars and isolated elements.
        let n = 20_000u32;
        let joins: Vec<(u32, u32)> = (0..15_000u64)
            .map(|k| {
                let h = k.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 17;
                (
                    (h % u64::from(n)) as u32,
                    ((h >> 20) % u64::from(n / 3)) as u32,
                )
            })
            .collect();
        // The components by a sequential search, each element's smallest class member.
        let mut smallest: Vec<u32> = (0..n).collect();
        let mut changed = true;
        while changed {
            changed = false;
            for &(a, b) in &joins {
                let m = smallest[a as usize].min(smallest[b as usize]);
                for x in [a, b] {
                    if smallest[x as usize] != m {
                        smallest[x as usize] = m;
                        changed = true;
                    }
                }
            }
        }
        for threads in [1, 2, 3, 8] {
            let classes = UnionFind::new(n);
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| joins.par_iter().for_each(|&(a, b)| classes.union(a, b)));
            let roots: Vec<u32> = (0..n).map(|i| classes.root(i)).collect();
            assert_eq!(roots, smallest, "{threads} threads");
            assert!((0..n).all(|i| classes.is_root(i) == (smallest[i as usize] == i)));
        }
    }
}
