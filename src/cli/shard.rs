//! `--shard K/N`: one of N deterministic slices of a batch, for CI matrices that spread a
//! library over machines.
//!
//! An input's shard is a hash of its own path (as given, or the folder input joined with the
//! path below it), never its position in the walk: adding or removing a file elsewhere in the
//! tree moves no other file to another shard, so each machine's outputs and caches stay put.
//! It deliberately knows nothing of sizes; balance comes from the hash over many files.

use std::hash::Hasher as _;
use std::path::Path;

use super::scope::Job;

/// Shard `index` (0-based) of `count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    index: u64,
    count: u64,
}

impl Shard {
    /// Parses `K/N` with 1 ≤ K ≤ N (clap's value parser; the message follows its flag name).
    pub fn parse(text: &str) -> Result<Shard, String> {
        let expected = "expected K/N with 1 <= K <= N, e.g. 1/4";
        let (k, n) = text
            .split_once('/')
            .ok_or_else(|| format!("no '/' ({expected})"))?;
        let parse = |s: &str| {
            s.trim()
                .parse::<u64>()
                .map_err(|_| format!("{s:?} is not a count ({expected})"))
        };
        let (k, n) = (parse(k)?, parse(n)?);
        if n == 0 || k == 0 || k > n {
            return Err(format!("{k}/{n} is out of range ({expected})"));
        }
        Ok(Shard {
            index: k - 1,
            count: n,
        })
    }

    /// Whether `path` belongs to this shard.
    pub fn holds(&self, path: &Path) -> bool {
        shard_of(path, self.count) == self.index
    }

    /// The jobs of this shard, in their order.
    pub fn select(&self, jobs: Vec<Job>) -> Vec<Job> {
        jobs.into_iter().filter(|j| self.holds(&j.input)).collect()
    }
}

/// The 0-based shard of `path` among `count`: FNV-1a 64 of its `/`-separated form without a
/// leading `./`, so that `a/b.glb` and `./a/b.glb` agree and so do Windows and Unix runners.
fn shard_of(path: &Path, count: u64) -> u64 {
    let text = path.to_string_lossy().replace('\\', "/");
    let mut rest = text.as_str();
    while let Some(r) = rest.strip_prefix("./") {
        rest = r;
    }
    let mut h = fnv::FnvHasher::default();
    h.write(rest.as_bytes());
    h.finish() % count
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn k_of_n_is_parsed_one_based_and_checked() {
        assert_eq!(Shard::parse("2/4"), Ok(Shard { index: 1, count: 4 }));
        for bad in ["0/4", "5/4", "1/0", "4", "a/4", "-1/4"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn every_path_is_in_exactly_one_shard() {
        let shards: Vec<Shard> = (1..=5)
            .map(|k| Shard::parse(&format!("{k}/5")).unwrap())
            .collect();
        for i in 0..500 {
            let p = format!("assets/set{}/prop_{i}.glb", i % 7);
            let holders = shards.iter().filter(|s| s.holds(Path::new(&p))).count();
            assert_eq!(holders, 1, "{p}");
        }
    }

    #[test]
    fn the_shard_ignores_a_leading_dot_slash() {
        for n in 2..9 {
            let a = shard_of(Path::new("props/crate.glb"), n);
            assert_eq!(a, shard_of(Path::new("./props/crate.glb"), n));
        }
    }

    #[test]
    fn shards_are_balanced_over_many_files() {
        // 4,000 names into 4 shards: each count is binomial (n = 4000, p = 1/4), σ ≈ 27.4;
        // a hash that clustered (say, on the shared prefix) would miss 1,000 ± 5σ.
        let mut counts = [0u32; 4];
        for i in 0..4000 {
            counts[shard_of(Path::new(&format!("lib/kit_{}/m{i}.glb", i / 100)), 4) as usize] += 1;
        }
        for c in counts {
            assert!((863..=1137).contains(&c), "{counts:?}");
        }
    }
}
