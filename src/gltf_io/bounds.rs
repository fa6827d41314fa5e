//! Accessor `min`/`max`: every new accessor needs them, and a dense primitive's arrays have
//! millions of elements, so they are computed in parallel over fixed-size blocks (the blocks
//! and the order their results are combined in never depend on the thread count, so neither
//! do the written bytes).

use rayon::prelude::*;

/// Elements per block.
const BLOCK: usize = 1 << 16;

/// Per-component minimum and maximum of `values` (`n ≥ 1` components per element), NaN ignored
/// (as `f32::min`/`f32::max` do); ±infinity for a component with no number at all.
pub(crate) fn float_bounds(values: &[f32], n: usize) -> (Vec<f32>, Vec<f32>) {
    match n {
        1 => fixed::<1>(values),
        2 => fixed::<2>(values),
        3 => fixed::<3>(values),
        4 => fixed::<4>(values),
        _ => {
            let (mut lo, mut hi) = (vec![f32::INFINITY; n], vec![f32::NEG_INFINITY; n]);
            for e in values.chunks_exact(n) {
                for (k, x) in e.iter().enumerate() {
                    lo[k] = lo[k].min(*x);
                    hi[k] = hi[k].max(*x);
                }
            }
            (lo, hi)
        }
    }
}

/// [`float_bounds`] for a component count known at compile time, so the inner loop has no
/// bounds checks and keeps its running bounds in registers.
fn fixed<const N: usize>(values: &[f32]) -> (Vec<f32>, Vec<f32>) {
    let blocks: Vec<([f32; N], [f32; N])> = values
        .par_chunks(BLOCK * N)
        .map(|block| {
            let (mut lo, mut hi) = ([f32::INFINITY; N], [f32::NEG_INFINITY; N]);
            for e in block.chunks_exact(N) {
                for k in 0..N {
                    lo[k] = lo[k].min(e[k]);
                    hi[k] = hi[k].max(e[k]);
                }
            }
            (lo, hi)
        })
        .collect();
    let (mut lo, mut hi) = ([f32::INFINITY; N], [f32::NEG_INFINITY; N]);
    for (l, h) in blocks {
        for k in 0..N {
            lo[k] = lo[k].min(l[k]);
            hi[k] = hi[k].max(h[k]);
        }
    }
    (lo.to_vec(), hi.to_vec())
}

/// Smallest and largest of `values`, `None` when empty.
pub(crate) fn uint_bounds(values: &[u32]) -> Option<(u32, u32)> {
    if values.is_empty() {
        return None;
    }
    let bounds = values
        .par_chunks(BLOCK)
        .map(|block| {
            block
                .iter()
                .fold((u32::MAX, 0), |(lo, hi), &x| (lo.min(x), hi.max(x)))
        })
        .reduce(|| (u32::MAX, 0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
    Some(bounds)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_bounds_match_a_plain_loop_for_every_component_count() {
        for n in 1..=6 {
            // Enough elements for several blocks, with a NaN that must be ignored.
            let mut values: Vec<f32> = (0..n * (2 * BLOCK + 7))
                .map(|i| ((i * 7919) % 10007) as f32 - 5000.0)
                .collect();
            values[n] = f32::NAN;
            let (lo, hi) = float_bounds(&values, n);
            for k in 0..n {
                let comp = values.iter().skip(k).step_by(n).copied();
                assert_eq!(lo[k], comp.clone().fold(f32::INFINITY, f32::min));
                assert_eq!(hi[k], comp.fold(f32::NEG_INFINITY, f32::max));
            }
        }
    }

    #[test]
    fn uint_bounds_of_empty_and_full_arrays() {
        assert_eq!(uint_bounds(&[]), None);
        let values: Vec<u32> = (0..3 * BLOCK as u32)
            .map(|i| (i * 31) % 100_003 + 5)
            .collect();
        assert_eq!(
            uint_bounds(&values),
            Some((*values.iter().min().unwrap(), *values.iter().max().unwrap()))
        );
    }
}
