//! `scatterfit bench fit`: a rig-twin sample of the wood tile written as `synth` writes it, then
//! the fit and the whole measurement timed on it (`scatterfit_bench::fit`).

use anyhow::Context;
use scatterfit_optics::materials::by_name;

use super::{Args, Figure};

/// The figures of `scatterfit_bench::fit` on a fresh rig-twin sample (quick with `--quick`).
pub fn figures(args: &Args) -> anyhow::Result<Vec<Figure>> {
    let temp = tempfile::tempdir()?;
    let dir = temp.path().join("wood-tile");
    let m = by_name("wood-tile").context("the built-in material")?;
    let material = crate::twin::Material::from(m);
    let cache = crate::common::cache_dir(None);
    let sample = crate::twin::synthesize(&material, 1, cache.as_deref(), true, args.quick)?;
    crate::twin::write_sample(&dir, &sample)?;
    let pixels = sample.truth.rig.width * sample.truth.rig.height;
    Ok(scatterfit_bench::fit::figures(&dir, pixels, args.quick)?)
}
