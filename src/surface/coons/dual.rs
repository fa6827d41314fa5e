//! Forward-mode dual numbers, so that the Coons patch formula is written once and yields
//! positions (on `f64`), exact tangents (on [`Dual`]) and the directional derivatives inside its
//! correction term (on a [`Dual`] of those).
//!
//! It deliberately implements only the four operations the patch needs, with no transcendental
//! functions.

use std::ops::{Add, Div, Mul, Sub};

/// The arithmetic the patch formula uses.
pub trait Num:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// A constant.
    fn cst(x: f64) -> Self;
    /// `self · k` for a constant `k`.
    fn scale(self, k: f64) -> Self;
}

impl Num for f64 {
    #[inline]
    fn cst(x: f64) -> Self {
        x
    }
    #[inline]
    fn scale(self, k: f64) -> Self {
        self * k
    }
}

/// `v + Σ d[n] ε_n` with `ε_n ε_m = 0`: a value and its derivatives along `N` directions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual<T, const N: usize> {
    pub v: T,
    pub d: [T; N],
}

impl<T: Num, const N: usize> Dual<T, N> {
    /// A variable with value `v` and derivatives `d`.
    #[inline]
    pub fn new(v: T, d: [T; N]) -> Self {
        Dual { v, d }
    }
}

impl<T: Num, const N: usize> Add for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Dual {
            v: self.v + o.v,
            d: std::array::from_fn(|n| self.d[n] + o.d[n]),
        }
    }
}

impl<T: Num, const N: usize> Sub for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Dual {
            v: self.v - o.v,
            d: std::array::from_fn(|n| self.d[n] - o.d[n]),
        }
    }
}

// The product and quotient rules use + and − by nature.
#[allow(clippy::suspicious_arithmetic_impl)]
impl<T: Num, const N: usize> Mul for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        Dual {
            v: self.v * o.v,
            d: std::array::from_fn(|n| self.d[n] * o.v + self.v * o.d[n]),
        }
    }
}

#[allow(clippy::suspicious_arithmetic_impl)]
impl<T: Num, const N: usize> Div for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        let v = self.v / o.v;
        Dual {
            v,
            d: std::array::from_fn(|n| (self.d[n] - v * o.d[n]) / o.v),
        }
    }
}

impl<T: Num, const N: usize> Num for Dual<T, N> {
    #[inline]
    fn cst(x: f64) -> Self {
        Dual {
            v: T::cst(x),
            d: [T::cst(0.0); N],
        }
    }
    #[inline]
    fn scale(self, k: f64) -> Self {
        Dual {
            v: self.v.scale(k),
            d: self.d.map(|x| x.scale(k)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nested_duals_give_the_mixed_second_derivative() {
        // f(x, y) = x² y / (1 + x): f_xy = 2x/(1+x) − x²/(1+x)² at x = 2: 4/3 − 4/9 = 8/9.
        type D = Dual<f64, 1>;
        let x = Dual::<D, 1>::new(D::new(2.0, [1.0]), [D::cst(0.0)]);
        let y = Dual::<D, 1>::new(D::cst(3.0), [D::cst(1.0)]);
        let f = x * x * y / (Dual::cst(1.0) + x);
        assert!((f.d[0].d[0] - 8.0 / 9.0).abs() < 1e-15);
    }
}
