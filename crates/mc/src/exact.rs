//! Exact, order-independent sums of floating-point numbers, so that a Monte Carlo tally split over
//! shards (machines, array tasks) and added up in any order is the same number, bit for bit, as the
//! tally of one run.
//!
//! A sum is kept as a floating-point *expansion* (Shewchuk 1997, "Adaptive Precision Floating-Point
//! Arithmetic and Fast Robust Geometric Predicates", Discrete Comput. Geom. 18:305, §2): a list of
//! non-overlapping f64 components, increasing in magnitude, whose exact (real-number) sum is the sum
//! of everything added. Adding x is Shewchuk's GROW-EXPANSION with zero elimination (his Theorem 10)
//! in the form of Python's `math.fsum` (R. Hettinger's `msum`): each component is met with Knuth's
//! TWO-SUM, which splits a + b into the rounded sum and its exact rounding error. Nothing is ever
//! rounded away, so the represented value does not depend on the order of the additions; only its
//! components do. [`ExactSum::value`] rounds the exact value once, to the nearest f64 (ties to
//! even, `math.fsum`'s final step), which is therefore order-independent too.
//!
//! Hand-written because the state must be stored and read back: a shard's partial file carries its
//! sums exactly, to be added to the other shards' later. Crates with exact summation (`accurate`,
//! `xsum`) keep their accumulators private.
//!
//! Range: the components are finite f64; a tally's per-photon scores are weights ≤ 4 (and their
//! squares), so no partial sum comes near overflow. Non-finite input is refused by the caller's
//! checks (a score is a finite weight), and [`ExactSum::add`] debug-asserts it.

use serde::{Deserialize, Serialize};

/// An exact sum of f64 values (module docs): non-overlapping components, increasing in magnitude,
/// no zeros. Serialised as the list of components.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct ExactSum(Vec<f64>);

/// Knuth's TWO-SUM (TAOCP vol. 2, §4.2.2, Theorem B; Shewchuk 1997, Theorem 7): s = fl(a + b) and
/// e with a + b = s + e exactly, for any finite a, b (no ordering of magnitudes needed).
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bv = s - a;
    let av = s - bv;
    (s, (a - av) + (b - bv))
}

impl ExactSum {
    /// The empty sum (0).
    pub fn new() -> Self {
        Self(Vec::new())
    }

    /// Adds `x` exactly.
    pub fn add(&mut self, mut x: f64) {
        debug_assert!(x.is_finite(), "exact sums take finite values");
        if x == 0.0 {
            return;
        }
        // GROW-EXPANSION with zero elimination: x meets every component from the smallest up; each
        // TWO-SUM's error is a new (smaller, non-overlapping) component, its sum travels on.
        let mut kept = 0;
        for i in 0..self.0.len() {
            let (hi, lo) = two_sum(x, self.0[i]);
            if lo != 0.0 {
                self.0[kept] = lo;
                kept += 1;
            }
            x = hi;
        }
        self.0.truncate(kept);
        if x != 0.0 {
            self.0.push(x);
        }
    }

    /// Adds another exact sum exactly.
    pub fn add_sum(&mut self, other: &ExactSum) {
        for &x in &other.0 {
            self.add(x);
        }
    }

    /// The components (non-overlapping, increasing in magnitude).
    pub fn components(&self) -> &[f64] {
        &self.0
    }

    /// Whether the components have an expansion's shape: finite, non-zero and strictly increasing
    /// in magnitude. What a file's sums must satisfy before they are used.
    pub fn is_valid(&self) -> bool {
        self.0.iter().all(|c| c.is_finite() && *c != 0.0)
            && self.0.windows(2).all(|w| w[1].abs() > w[0].abs())
    }

    /// The exact sum rounded to the nearest f64, ties to even (the final step of Python's
    /// `math.fsum`: the largest components are added until one addition is inexact; a tie is
    /// broken by the sign of what is left below).
    pub fn value(&self) -> f64 {
        let p = &self.0;
        let mut n = p.len();
        if n == 0 {
            return 0.0;
        }
        n -= 1;
        let mut hi = p[n];
        let mut lo = 0.0;
        while n > 0 {
            let x = hi;
            let y = p[n - 1];
            n -= 1;
            hi = x + y;
            let yr = hi - x;
            lo = y - yr;
            if lo != 0.0 {
                break;
            }
        }
        // Half-way case: hi + lo with lo exactly half an ulp of hi rounds to even above, but the
        // components below lo push the exact sum off the tie, towards lo's sign.
        if n > 0 && ((lo < 0.0 && p[n - 1] < 0.0) || (lo > 0.0 && p[n - 1] > 0.0)) {
            let y = lo * 2.0;
            let x = hi + y;
            let yr = x - hi;
            if y == yr {
                hi = x;
            }
        }
        hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator for the tests (SplitMix64).
    fn splitmix(state: &mut u64) -> u64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Cancellation that a running f64 sum loses entirely is kept.
    #[test]
    fn catastrophic_cancellation() {
        let mut s = ExactSum::new();
        for x in [1e100, 1.0, -1e100, 1e-30] {
            s.add(x);
        }
        assert_eq!(s.value(), 1.0 + 1e-30);
        assert!(s.is_valid());
        let mut t = ExactSum::new();
        for x in [0.1; 10] {
            t.add(x);
        }
        // The exact sum of ten copies of fl(0.1) is 1.0000000000000000555…, which rounds to 1.
        assert_eq!(t.value(), 1.0);
        assert_ne!([0.1f64; 10].iter().sum::<f64>(), 1.0);
    }

    /// Against an independent exact sum: integers scaled by a power of two (exact in i128, then
    /// rounded once by the integer-to-float conversion, which rounds to nearest, ties to even);
    /// the values span 2⁻¹²⁰ … 2⁻³, with both signs. The order of additions and the grouping into
    /// partial sums (shards) do not change the result's bits.
    #[test]
    fn matches_integer_arithmetic_in_any_order() {
        let mut state = 7;
        for trial in 0..200 {
            let count = 1 + (splitmix(&mut state) % 300) as usize;
            let mut ints: Vec<i128> = Vec::with_capacity(count);
            for _ in 0..count {
                let r = splitmix(&mut state);
                // A 53-bit mantissa shifted by 0..64 bits: |k| < 2¹¹⁷, a sum of 300 < 2¹²⁶.
                let mant = (r >> 11) as i128;
                let shift = (splitmix(&mut state) % 65) as u32;
                let k = mant << shift;
                ints.push(if r & 1 == 0 { k } else { -k });
            }
            // Values k·2⁻¹²⁰ are exact f64 (53 significant bits, exponents in range).
            let scale = 2f64.powi(-120);
            let values: Vec<f64> = ints.iter().map(|&k| k as f64 * scale).collect();
            let exact: i128 = ints.iter().sum();
            let expected = exact as f64 * scale;
            let mut s = ExactSum::new();
            for &v in &values {
                s.add(v);
            }
            assert!(s.is_valid(), "trial {trial}: {:?}", s.components());
            assert_eq!(s.value().to_bits(), expected.to_bits(), "trial {trial}");
            // Reversed, and in three groups added together.
            let mut r = ExactSum::new();
            for &v in values.iter().rev() {
                r.add(v);
            }
            assert_eq!(r.value().to_bits(), expected.to_bits(), "trial {trial}");
            let mut groups = [ExactSum::new(), ExactSum::new(), ExactSum::new()];
            for (i, &v) in values.iter().enumerate() {
                groups[i % 3].add(v);
            }
            let mut g = ExactSum::new();
            for part in groups.iter().rev() {
                g.add_sum(part);
            }
            assert_eq!(g.value().to_bits(), expected.to_bits(), "trial {trial}");
        }
    }

    /// A tie broken by what lies below it: 1 + 2⁻⁵³ is half-way between 1 and its successor; with
    /// 2⁻¹⁰⁰ more it must round up, with 2⁻¹⁰⁰ less down.
    #[test]
    fn ties_are_broken_by_the_rest() {
        let half_ulp = 2f64.powi(-53);
        let tiny = 2f64.powi(-100);
        let mut up = ExactSum::new();
        for x in [1.0, half_ulp, tiny] {
            up.add(x);
        }
        assert_eq!(up.value(), 1.0 + 2.0 * half_ulp);
        let mut down = ExactSum::new();
        for x in [1.0, half_ulp, -tiny] {
            down.add(x);
        }
        assert_eq!(down.value(), 1.0);
        // Exactly a tie: to even (1.0).
        let mut tie = ExactSum::new();
        for x in [1.0, half_ulp] {
            tie.add(x);
        }
        assert_eq!(tie.value(), 1.0);
    }

    /// Files: an expansion survives JSON (serde_json's `float_roundtrip`) and a forged one is caught.
    #[test]
    fn json_round_trip_and_validation() {
        let mut s = ExactSum::new();
        for x in [1e16, 1.0, 0.1, 3e-20] {
            s.add(x);
        }
        let text = serde_json::to_string(&s).unwrap();
        let back: ExactSum = serde_json::from_str(&text).unwrap();
        assert_eq!(back, s);
        assert!(back.is_valid());
        let forged: ExactSum = serde_json::from_str("[1.0, 1.0]").unwrap();
        assert!(!forged.is_valid());
        let zero: ExactSum = serde_json::from_str("[0.0]").unwrap();
        assert!(!zero.is_valid());
    }
}
