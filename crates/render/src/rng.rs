//! Random streams keyed by (seed, index): every pixel and every row of light samples has its own
//! xoshiro256++ generator, so renders are identical for a seed whatever the thread count.

use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};

/// SplitMix64 finaliser (Steele, Lea & Flood 2014).
#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The generator for `index` under `seed`.
pub(crate) fn stream(seed: u64, index: u64) -> Stream {
    let key = mix64(mix64(seed ^ 0x7E4D_E12F_0A11_5EED).wrapping_add(index));
    Stream(Xoshiro256PlusPlus::seed_from_u64(key))
}

/// A uniform generator.
#[derive(Debug, Clone)]
pub(crate) struct Stream(Xoshiro256PlusPlus);

impl Stream {
    /// Uniform in [0, 1), 53 random bits.
    #[inline]
    pub(crate) fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}
