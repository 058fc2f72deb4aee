//! Random streams: one xoshiro256++ generator per chunk of photons, derived from (seed, chunk index),
//! so that results do not depend on how chunks are spread over threads.

use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};

/// SplitMix64 finaliser (Steele, Lea & Flood 2014; the mixer of `java.util.SplittableRandom`).
#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The generator of chunk `chunk` for `seed`: the pair is hashed with two SplitMix64 rounds and the
/// hash seeds xoshiro256++ through SplitMix64 (`seed_from_u64`). Streams of different chunks start at
/// unrelated points of the 2^256 − 1 period.
pub(crate) fn stream(seed: u64, chunk: u64) -> PhotonRng {
    let key = mix64(mix64(seed ^ 0x5CA7_7E2F_17D0_0001).wrapping_add(chunk));
    PhotonRng(Xoshiro256PlusPlus::seed_from_u64(key))
}

/// The photon tracer's generator with the two uniform variates it needs.
#[derive(Debug, Clone)]
pub(crate) struct PhotonRng(Xoshiro256PlusPlus);

const TWO_POW_M53: f64 = 1.0 / (1u64 << 53) as f64;

impl PhotonRng {
    /// Uniform in [0, 1), 53 random bits.
    #[inline(always)]
    pub(crate) fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * TWO_POW_M53
    }

    /// Standard exponential variate (rate 1), by the ziggurat method (Marsaglia & Tsang 2000, as
    /// implemented in `rand_distr::Exp1`): the same distribution as −ln ξ, without a logarithm in the
    /// common case.
    #[inline(always)]
    pub(crate) fn exp1(&mut self) -> f64 {
        rand_distr::Distribution::<f64>::sample(&rand_distr::Exp1, &mut self.0)
    }

    /// A uniformly distributed point (a, b) of the unit disk with s = a² + b² ∈ (0, 1], by rejection
    /// from the square (π/4 acceptance): an azimuth without trigonometry, cos ψ = a/√s, sin ψ = b/√s.
    #[inline(always)]
    pub(crate) fn unit_disk(&mut self) -> (f64, f64, f64) {
        loop {
            let a = 2.0 * self.uniform() - 1.0;
            let b = 2.0 * self.uniform() - 1.0;
            let s = a * a + b * b;
            if s <= 1.0 && s > 0.0 {
                return (a, b, s);
            }
        }
    }

    /// 64 random bits.
    #[inline(always)]
    pub(crate) fn bits(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Uniform in (0, 1]: safe for `ln` (MCML rejects ξ = 0 for the step length).
    #[inline(always)]
    pub(crate) fn uniform_open0(&mut self) -> f64 {
        ((self.0.next_u64() >> 11) + 1) as f64 * TWO_POW_M53
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_differ_and_repeat() {
        let mut s0 = stream(1, 0);
        let mut s0b = stream(1, 0);
        let mut s1 = stream(1, 1);
        let mut t0 = stream(2, 0);
        let x = s0.uniform();
        assert_eq!(x, s0b.uniform());
        assert_ne!(x, s1.uniform());
        assert_ne!(x, t0.uniform());
    }

    #[test]
    fn uniform_ranges() {
        let mut s = stream(7, 3);
        let mut sum = 0.0;
        let n = 100_000;
        for _ in 0..n {
            let u = s.uniform();
            let v = s.uniform_open0();
            assert!((0.0..1.0).contains(&u));
            assert!(v > 0.0 && v <= 1.0);
            sum += u;
        }
        // Mean of U(0,1) is 1/2 with s.e. sqrt(1/12/n) ≈ 9.1e-4; 5 s.e.
        assert!((sum / n as f64 - 0.5).abs() < 5.0 * (1.0 / 12.0 / n as f64).sqrt());
    }
}
