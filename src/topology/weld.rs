//! The weld: one id per distinct position (bit-equal after mapping -0.0 to +0.0), numbered by
//! first use in input order.
//!
//! Equal positions are grouped by a hash of their bits. Instead of one comparison sort of every
//! (hash, index) pair, the pairs are counting-sorted by the hash's top bits (a bucket of about
//! [`PER_BUCKET`] pairs each), in parallel blocks of vertices, and then only each bucket's few
//! pairs are sorted, in parallel tasks of consecutive buckets: equal hashes share a bucket, so
//! every run of equal hashes lies inside one task, and the buckets in order are the pairs in
//! order. Deciding each position's first use and the
//! numbering are parallel too (a count per block and a prefix sum), so no pass over the
//! vertices runs on one thread. The result is the one a sort of every pair gives, whatever the
//! hash, the blocks, the buckets and the threads.

use std::ops::Range;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

use glam::DVec3;
use rayon::prelude::*;

use super::{filled, pieces_of, VertId};

/// Vertices one task of the partition (and of the numbering) reads.
const BLOCK: usize = 1 << 16;
/// Pairs per bucket aimed at: small enough that sorting a bucket is a few compares per pair.
const PER_BUCKET: usize = 32;
/// Pairs one task of the bucket sort aims at.
const PER_TASK: usize = 1 << 13;
/// The most hash bits a bucket is chosen by (a bucket table per block of 256 KiB).
const MAX_BUCKET_BITS: u32 = 16;

/// One block's (hash, index) pairs counting-sorted by bucket, and where each bucket starts
/// among them (one more entry: the block's length).
type Partition = (Vec<u32>, Vec<(u64, u32)>);

/// Welds bit-equal positions (after mapping -0.0 to +0.0), numbering them by first use:
/// per input vertex its welded id, and one position per welded vertex (its first use's).
pub(super) fn weld(positions: &[DVec3]) -> (Vec<VertId>, Vec<DVec3>) {
    weld_by(positions, position_hash)
}

/// [`weld`] with the hash given, so that tests can make every position collide.
///
/// The rare run of equal hashes is ordered by the position bits themselves, so the result is
/// the one a sort by position gives, whatever the hash.
pub(super) fn weld_by(
    positions: &[DVec3],
    hash: impl Fn([u64; 3]) -> u64 + Sync,
) -> (Vec<VertId>, Vec<DVec3>) {
    weld_with(positions, hash, bucket_bits(positions.len()))
}

/// The hash bits that choose a bucket for `n` pairs: about [`PER_BUCKET`] pairs per bucket.
fn bucket_bits(n: usize) -> u32 {
    (n / PER_BUCKET)
        .checked_ilog2()
        .unwrap_or(0)
        .min(MAX_BUCKET_BITS)
}

/// [`weld_by`] with `bits` hash bits choosing the bucket (0: one bucket), for the tests that
/// check the result does not depend on them.
fn weld_with(
    positions: &[DVec3],
    hash: impl Fn([u64; 3]) -> u64 + Sync,
    bits: u32,
) -> (Vec<VertId>, Vec<DVec3>) {
    let n = positions.len();
    // x + 0.0 is +0.0 for x = -0.0 and x itself otherwise.
    let key = |i: u32| {
        let p = positions[i as usize];
        [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits)
    };
    let buckets = 1usize << bits;
    let bucket_of = |h: u64| {
        if bits == 0 {
            0
        } else {
            (h >> (64 - bits)) as usize
        }
    };
    let blocks: Vec<Range<usize>> = (0..n.div_ceil(BLOCK))
        .map(|b| b * BLOCK..((b + 1) * BLOCK).min(n))
        .collect();
    // Each block's (hash, index) pairs, counting-sorted by bucket: the hash is computed twice
    // (to count, then to place) rather than held in a second array.
    let partitioned: Vec<Partition> = blocks
        .par_iter()
        .map(|r| {
            let mut start = vec![0u32; buckets + 1];
            for i in r.clone() {
                start[bucket_of(hash(key(i as u32))) + 1] += 1;
            }
            let mut sum = 0;
            for s in &mut start {
                sum += *s;
                *s = sum;
            }
            let mut next = start[..buckets].to_vec();
            let mut pairs = vec![(0u64, 0u32); r.len()];
            for i in r.clone() {
                let h = hash(key(i as u32));
                let b = bucket_of(h);
                pairs[next[b] as usize] = (h, i as u32);
                next[b] += 1;
            }
            (start, pairs)
        })
        .collect();

    // `first[i]`: the first input vertex at vertex i's position. Every index is written once,
    // by the task whose buckets hold its hash, so the order the threads run in does not matter.
    let first: Vec<AtomicU32> = (0..n as u32).into_par_iter().map(AtomicU32::new).collect();
    let tasks = n.div_ceil(PER_TASK).clamp(1, buckets);
    (0..tasks)
        .into_par_iter()
        .for_each_init(Vec::new, |run, t| {
            let (lo, hi) = (t * buckets / tasks, (t + 1) * buckets / tasks);
            run.clear();
            // Bucket after bucket (the buckets follow the hash's order), each sorted alone: a
            // few dozen pairs, where one sort of the task's pairs took a dozen compares a pair.
            for b in lo..hi {
                let from = run.len();
                for (start, pairs) in &partitioned {
                    run.extend_from_slice(&pairs[start[b] as usize..start[b + 1] as usize]);
                }
                // Pairs are distinct (the index differs), so the order is the one there is.
                run[from..].sort_unstable();
            }
            settle_runs(run, &key, &first);
        });
    drop(partitioned);
    let first: Vec<u32> = first.into_iter().map(AtomicU32::into_inner).collect();
    number_by_first_use(positions, &first)
}

/// Writes `first[i]` for every index of `sorted` (pairs sorted by hash, then index): within a
/// run of equal hashes, the smallest index of each group of equal position bits.
fn settle_runs(sorted: &mut [(u64, u32)], key: &impl Fn(u32) -> [u64; 3], first: &[AtomicU32]) {
    for run in sorted.chunk_by_mut(|a, b| a.0 == b.0) {
        if let [(_, i)] = run {
            first[*i as usize].store(*i, Relaxed);
            continue;
        }
        // Equal hashes: copies of one position, or (rarely) different positions.
        run.sort_unstable_by_key(|&(_, i)| (key(i), i));
        for group in run.chunk_by(|a, b| key(a.1) == key(b.1)) {
            for &(_, i) in group {
                first[i as usize].store(group[0].1, Relaxed);
            }
        }
    }
}

/// In input order each first use (`first[i] == i`) takes the next id and every later use the
/// id of its first use: a count of first uses per block, a prefix sum over the blocks, then
/// each block's ranks, all in parallel. Returns the ids and the first uses' positions.
fn number_by_first_use(positions: &[DVec3], first: &[u32]) -> (Vec<VertId>, Vec<DVec3>) {
    let is_first = |i: usize| first[i] as usize == i;
    let counts: Vec<u32> = (0..first.len().div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| {
            let r = b * BLOCK..((b + 1) * BLOCK).min(first.len());
            r.filter(|&i| is_first(i)).count() as u32
        })
        .collect();
    let distinct = counts.iter().sum::<u32>() as usize;
    let mut before = 0u32;
    let bases: Vec<u32> = counts
        .iter()
        .map(|&c| {
            before += c;
            before - c
        })
        .collect();
    // `rank[i]`: the first uses before i, which is i's id where i is a first use.
    let mut rank = vec![0u32; first.len()];
    rank.par_chunks_mut(BLOCK)
        .zip(&bases)
        .enumerate()
        .for_each(|(b, (out, &base))| {
            let mut r = base;
            for (j, o) in out.iter_mut().enumerate() {
                *o = r;
                r += u32::from(is_first(b * BLOCK + j));
            }
        });
    let ids = first
        .par_iter()
        .map(|&f| VertId(rank[f as usize]))
        .collect();
    // Each block's first uses straight into their place: a filtered parallel iterator would
    // gather them in per-thread pieces and copy those into the result on one thread.
    let mut welded = filled(DVec3::ZERO, distinct);
    let lengths: Vec<usize> = counts.iter().map(|&c| c as usize).collect();
    pieces_of(&mut welded, &lengths)
        .into_par_iter()
        .enumerate()
        .for_each(|(b, out)| {
            let r = b * BLOCK..((b + 1) * BLOCK).min(first.len());
            for (o, i) in out.iter_mut().zip(r.filter(|&i| is_first(i))) {
                *o = positions[i];
            }
        });
    (ids, welded)
}

/// A 64-bit hash of a position's bits: equal bits give equal hashes. Each coordinate passes
/// through the SplitMix64 finalizer, so that positions read from `f32` (whose low 29 bits are
/// zero) still spread over every bit, the top ones that choose a bucket included.
fn position_hash(bits: [u64; 3]) -> u64 {
    fn mix(mut z: u64) -> u64 {
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    mix(mix(mix(bits[0]) ^ bits[1]) ^ bits[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weld the obvious way: an ordered map from position bits to the next id.
    fn by_map(positions: &[DVec3]) -> (Vec<VertId>, Vec<DVec3>) {
        let mut ids = std::collections::BTreeMap::new();
        let mut welded = Vec::new();
        let of = positions
            .iter()
            .map(|p| {
                let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
                *ids.entry(key).or_insert_with(|| {
                    welded.push(*p);
                    VertId(welded.len() as u32 - 1)
                })
            })
            .collect();
        (of, welded)
    }

    /// Positions on a small grid (many copies of each), signed zeros among them, more than one
    /// block of them.
    fn crowded(n: usize) -> Vec<DVec3> {
        let mut state = 7u64;
        (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let c = |s: u64| match s % 5 {
                    0 => -0.0,
                    k => k as f64 * 0.25,
                };
                DVec3::new(c(state >> 20), c(state >> 30), c(state >> 40))
            })
            .collect()
    }

    /// Every number of buckets (one, a few, one per pair and more) and every hash (the real one,
    /// one that sends all positions to one bucket and one run, one that sends half of them
    /// there) give the map's weld, over more than one block of vertices and with the pairs
    /// spread over many tasks: the partition decides nothing.
    #[test]
    fn the_buckets_and_the_hash_decide_nothing() {
        let mut positions = crowded(BLOCK + 5000);
        positions.extend((0..3000).map(|i| DVec3::new(f64::from(i), 1.0, 2.0)));
        let want = by_map(&positions);
        for bits in [0, 1, 5, bucket_bits(positions.len()), MAX_BUCKET_BITS] {
            assert_eq!(
                weld_with(&positions, position_hash, bits),
                want,
                "{bits} bits"
            );
            assert_eq!(weld_with(&positions, |_| 7, bits), want, "{bits} bits");
            let half = |b: [u64; 3]| b[0] & 1;
            assert_eq!(weld_with(&positions, half, bits), want, "{bits} bits");
            let top = |b: [u64; 3]| position_hash(b) | (1 << 63);
            assert_eq!(weld_with(&positions, top, bits), want, "{bits} bits");
        }
    }

    #[test]
    fn no_vertices_weld_to_nothing() {
        assert_eq!(weld(&[]), (Vec::new(), Vec::new()));
        assert_eq!(bucket_bits(0), 0);
    }

    /// The welded positions are held exactly: as many as there are ids, no spare capacity.
    #[test]
    fn the_welded_positions_take_no_spare_room() {
        let positions = crowded(10_000);
        let (_, welded) = weld(&positions);
        assert_eq!(welded.capacity(), welded.len());
        assert_eq!(welded.len(), 125);
    }
}
