//! What the pipeline's integration tests share: the rig twin of a built-in material, made one way.
//!
//! The test binary (`tests/suite.rs`) declares this module once, and each file uses a part of it,
//! hence the `dead_code` allowance.
#![allow(dead_code)]

use std::path::Path;

use scatterfit_optics::materials::{PublishedMaterial, by_name};
use scatterfit_synth::{RigSpec, SyntheticSample, synthesize};

/// The built-in material `name` (`scatterfit synth --material` lists them).
///
/// # Panics
/// There is no such material: a test's own typo.
pub fn material(name: &str) -> &'static PublishedMaterial {
    by_name(name).unwrap_or_else(|| panic!("no built-in material {name:?}"))
}

/// The twin of material `m` at refractive index `eta` on `rig`, seed `seed`: the Monte Carlo
/// profile and spectrophotometer reading (cached in `cache` when given) and the exposure bracket;
/// no progress shown.
///
/// # Panics
/// The twin cannot be made (a test's own bad rig or material).
pub fn twin_of(
    m: &PublishedMaterial,
    eta: f64,
    rig: &RigSpec,
    seed: u64,
    cache: Option<&Path>,
) -> SyntheticSample {
    synthesize(
        m.name,
        m.sigma_s_prime,
        m.sigma_a,
        eta,
        rig,
        seed,
        cache,
        &|_, _, _| {},
    )
    .unwrap_or_else(|e| panic!("the twin of {} (seed {seed}): {e}", m.name))
}

/// [`twin_of`] the built-in material `name` at its own η on `rig`, without a cache.
pub fn twin(name: &str, rig: &RigSpec, seed: u64) -> SyntheticSample {
    let m = material(name);
    twin_of(m, m.eta, rig, seed, None)
}

/// [`twin`] on the quick rig (256² px at 0.1 mm/px, a tenth of the paper rig's photons).
pub fn quick_twin(name: &str, seed: u64) -> SyntheticSample {
    twin(name, &RigSpec::quick(), seed)
}
