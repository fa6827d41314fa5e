//! Accessor `min`/`max`: every new accessor needs them, and a dense primitive's arrays have
//! millions of elements, so they are computed in parallel over fixed-size blocks (the blocks
//! and the order their results are combined in never depend on the thread count, so neither
//! do the written bytes).

use rayon::prelude::*;

/// Elements per block.
const BLOCK: usize = 1 << 16;

/// Per-component minimum and maximum of `values` (`n ≥ 1` components per element), NaN ignored;
/// ±infinity for a component with no number at all. Of a `0.0` and a `-0.0` that are both the
/// least (or greatest), the first in `values` is the bound, as a plain left-to-right
/// `f32::min` fold gives it where it compiles to a compare and select.
pub(crate) fn float_bounds(values: &[f32], n: usize) -> (Vec<f32>, Vec<f32>) {
    let (mut lo, mut hi) = match n {
        1 => fixed::<1>(values),
        2 => fixed::<2>(values),
        3 => fixed::<3>(values),
        4 => fixed::<4>(values),
        _ => {
            let (mut lo, mut hi) = (vec![f32::INFINITY; n], vec![f32::NEG_INFINITY; n]);
            for e in values.chunks_exact(n) {
                for (k, &x) in e.iter().enumerate() {
                    lo[k] = least(lo[k], x);
                    hi[k] = greatest(hi[k], x);
                }
            }
            (lo, hi)
        }
    };
    // Lanes see the elements out of order: a zero bound takes the sign of the first zero.
    for (k, bound) in lo.iter_mut().chain(hi.iter_mut()).enumerate() {
        if *bound == 0.0 {
            let first = values[k % n..].iter().step_by(n).find(|&&x| x == 0.0);
            *bound = *first.expect("a zero bound is one of the values");
        }
    }
    (lo, hi)
}

/// The smaller of `lo` and `x`, `lo` when they compare equal or `x` is NaN: a compare and a
/// select, which vectorize where `f32::min`'s NaN handling of both operands does not.
#[inline(always)]
fn least(lo: f32, x: f32) -> f32 {
    if x < lo {
        x
    } else {
        lo
    }
}

/// [`least`] the other way.
#[inline(always)]
fn greatest(hi: f32, x: f32) -> f32 {
    if x > hi {
        x
    } else {
        hi
    }
}

/// Floats a block's bounds are kept in, lane by lane: a multiple of every component count of
/// [`fixed`], so lane `j` always holds component `j % N`, and wide enough for the compiler to
/// keep them in vector registers (a 3-component array read element by element did not).
const LANES: usize = 24;

/// [`float_bounds`] for a component count known at compile time: each block is read
/// [`LANES`] floats at a time, then its lanes are folded into the `N` components.
fn fixed<const N: usize>(values: &[f32]) -> (Vec<f32>, Vec<f32>) {
    let blocks: Vec<([f32; N], [f32; N])> = values
        .par_chunks(BLOCK * N)
        .map(|block| {
            let (mut lanes_lo, mut lanes_hi) = ([f32::INFINITY; LANES], [f32::NEG_INFINITY; LANES]);
            let mut wide = block.chunks_exact(LANES);
            for chunk in &mut wide {
                for j in 0..LANES {
                    lanes_lo[j] = least(lanes_lo[j], chunk[j]);
                    lanes_hi[j] = greatest(lanes_hi[j], chunk[j]);
                }
            }
            let (mut lo, mut hi) = ([f32::INFINITY; N], [f32::NEG_INFINITY; N]);
            for j in 0..LANES {
                lo[j % N] = least(lo[j % N], lanes_lo[j]);
                hi[j % N] = greatest(hi[j % N], lanes_hi[j]);
            }
            // A block's length is a multiple of `N`, and so is `LANES`: the rest starts at an
            // element.
            for e in wide.remainder().chunks_exact(N) {
                for k in 0..N {
                    lo[k] = least(lo[k], e[k]);
                    hi[k] = greatest(hi[k], e[k]);
                }
            }
            (lo, hi)
        })
        .collect();
    let (mut lo, mut hi) = ([f32::INFINITY; N], [f32::NEG_INFINITY; N]);
    for (l, h) in blocks {
        for k in 0..N {
            lo[k] = least(lo[k], l[k]);
            hi[k] = greatest(hi[k], h[k]);
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
            // Enough elements for several blocks and a partial one, with a NaN that must be
            // ignored.
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

    /// Where the bound is zero and both signs occur, the first in the array is the bound, in
    /// whichever lane or block the other sign lies: the bytes written must not depend on how
    /// the elements were split.
    #[test]
    fn a_zero_bound_has_the_sign_of_the_first_zero() {
        for n in 1..=6 {
            for (first, second) in [(0.0f32, -0.0f32), (-0.0, 0.0)] {
                for late in [1, LANES + 1, BLOCK + 3] {
                    // Component 0 is never below zero, component 1 never above, and the others
                    // have no zero at all.
                    let mut values: Vec<f32> = (0..n * (BLOCK + 40))
                        .map(|i| match i % n {
                            0 => 1.0 + (i % 13) as f32,
                            1 => -1.0 - (i % 11) as f32,
                            _ => 2.0 + (i / n % 5) as f32,
                        })
                        .collect();
                    let at = |element: usize, k: usize| element * n + k;
                    values[at(late, 0)] = first;
                    values[at(late + 5, 0)] = second;
                    values[at(late - 1, 0)] = second;
                    if n > 1 {
                        values[at(late, 1)] = first;
                        values[at(late + 7, 1)] = second;
                    }
                    let (lo, hi) = float_bounds(&values, n);
                    // The earliest zero of component 0 is at `late - 1`.
                    assert_eq!(lo[0].to_bits(), second.to_bits(), "n {n} late {late}");
                    if n > 1 {
                        assert_eq!(hi[1].to_bits(), first.to_bits(), "n {n} late {late}");
                    }
                    for k in 2..n {
                        assert_eq!(lo[k], 2.0);
                        assert_eq!(hi[k], 6.0);
                    }
                }
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
