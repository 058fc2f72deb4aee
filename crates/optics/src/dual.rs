//! Forward-mode automatic differentiation with two directions, for the diffusion models whose
//! derivatives are long chains (photon beam diffusion sums 100 depth terms; the better dipole has
//! four parameter-dependent lengths). A [`Dual`] carries a value and its partial derivatives in two
//! chosen inputs; every operation applies the chain rule exactly, so the result is the analytic
//! derivative of the same arithmetic (no step size, no truncation error). Written by hand: the
//! crates that do this (`num-dual`, `autodiff`) bring generic machinery we do not need for two
//! directions and would put a dependency into the physics core's hot loop.
//!
//! [`Real`] lets a formula be written once and evaluated on `f64` (value only, fast) or on [`Dual`].

use std::ops::{Add, Div, Mul, Neg, Sub};

/// A value with its partial derivatives in two inputs: v + d₀ε₀ + d₁ε₁ with ε² = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Dual {
    /// The value.
    pub v: f64,
    /// ∂/∂(input 0), ∂/∂(input 1).
    pub d: [f64; 2],
}

impl Dual {
    /// A constant (zero derivatives).
    #[inline(always)]
    pub const fn constant(v: f64) -> Self {
        Self { v, d: [0.0, 0.0] }
    }

    /// Input number `k` (0 or 1) with value `v`: derivative 1 in its own direction.
    #[inline(always)]
    pub fn variable(v: f64, k: usize) -> Self {
        let mut d = [0.0, 0.0];
        d[k] = 1.0;
        Self { v, d }
    }

    /// f(x) given f(v) and f′(v): the chain rule.
    #[inline(always)]
    fn chain(self, f: f64, df: f64) -> Self {
        Self {
            v: f,
            d: [df * self.d[0], df * self.d[1]],
        }
    }
}

/// The arithmetic a formula needs, on `f64` or on [`Dual`].
pub(crate) trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    /// A constant.
    fn cst(v: f64) -> Self;
    /// eˣ.
    fn exp(self) -> Self;
    /// √x.
    fn sqrt(self) -> Self;
    /// 1/x.
    fn recip(self) -> Self;
}

impl Real for f64 {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn exp(self) -> Self {
        f64::exp(self)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn recip(self) -> Self {
        1.0 / self
    }
}

impl Real for Dual {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        Dual::constant(v)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        let e = self.v.exp();
        self.chain(e, e)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        self.chain(s, 0.5 / s)
    }
    #[inline(always)]
    fn recip(self) -> Self {
        let r = 1.0 / self.v;
        self.chain(r, -r * r)
    }
}

impl Add for Dual {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            d: [self.d[0] + o.d[0], self.d[1] + o.d[1]],
        }
    }
}

impl Sub for Dual {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            v: self.v - o.v,
            d: [self.d[0] - o.d[0], self.d[1] - o.d[1]],
        }
    }
}

impl Mul for Dual {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self {
            v: self.v * o.v,
            d: [
                self.d[0] * o.v + self.v * o.d[0],
                self.d[1] * o.v + self.v * o.d[1],
            ],
        }
    }
}

impl Div for Dual {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let inv = 1.0 / o.v;
        let q = self.v * inv;
        Self {
            v: q,
            d: [
                (self.d[0] - q * o.d[0]) * inv,
                (self.d[1] - q * o.d[1]) * inv,
            ],
        }
    }
}

impl Neg for Dual {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self {
            v: -self.v,
            d: [-self.d[0], -self.d[1]],
        }
    }
}

impl Add<f64> for Dual {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: f64) -> Self {
        Self {
            v: self.v + o,
            d: self.d,
        }
    }
}

impl Sub<f64> for Dual {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: f64) -> Self {
        Self {
            v: self.v - o,
            d: self.d,
        }
    }
}

impl Mul<f64> for Dual {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: f64) -> Self {
        Self {
            v: self.v * o,
            d: [self.d[0] * o, self.d[1] * o],
        }
    }
}

impl Div<f64> for Dual {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: f64) -> Self {
        self * (1.0 / o)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(x, y) = √(x² + y)·e^{−x/y}/(x + 1): the dual derivatives equal the hand-derived ones.
    #[test]
    fn chain_rule_matches_hand_derivatives() {
        fn f<T: Real>(x: T, y: T) -> T {
            (x * x + y).sqrt() * (-(x / y)).exp() / (x + 1.0)
        }
        let (x0, y0) = (0.7, 1.9);
        let got = f(Dual::variable(x0, 0), Dual::variable(y0, 1));
        let s = (x0 * x0 + y0).sqrt();
        let e = (-x0 / y0).exp();
        let v = s * e / (x0 + 1.0);
        let dx = v * (x0 / (s * s) - 1.0 / y0 - 1.0 / (x0 + 1.0));
        let dy = v * (0.5 / (s * s) + x0 / (y0 * y0));
        assert!((got.v - v).abs() < 1e-15);
        assert!((got.d[0] - dx).abs() < 1e-14, "{} vs {dx}", got.d[0]);
        assert!((got.d[1] - dy).abs() < 1e-14, "{} vs {dy}", got.d[1]);
        assert_eq!(f(x0, y0), got.v);
        let r = Dual::variable(4.0, 1).recip();
        assert_eq!((r.v, r.d), (0.25, [0.0, -1.0 / 16.0]));
    }
}
