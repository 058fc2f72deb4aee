//! The rig twin as the commands use it (`synth`, `demo`): a material → a synthetic sample →
//! a sample folder.

use std::path::Path;

use scatterfit_lab::twin::{TwinFolder, synth_provenance, write_twin_folder};
use scatterfit_lab::twin_settings::synthesize_material;
use scatterfit_synth::{RigSpec, SyntheticSample};

use crate::common::bar;

pub use scatterfit_lab::twin_settings::Material;

/// Synthesises `m` on the paper's rig (or the quick one), with a progress bar.
pub fn synthesize(
    m: &Material,
    seed: u64,
    cache: Option<&Path>,
    quiet: bool,
    quick: bool,
) -> anyhow::Result<SyntheticSample> {
    let rig = if quick {
        RigSpec::quick()
    } else {
        RigSpec::paper()
    };
    synthesize_on(m, &rig, seed, cache, quiet)
}

/// Synthesises `m` on `rig` (a camera, or a real rig's effects), with a progress bar.
pub fn synthesize_on(
    m: &Material,
    rig: &RigSpec,
    seed: u64,
    cache: Option<&Path>,
    quiet: bool,
) -> anyhow::Result<SyntheticSample> {
    let bar = bar(
        300,
        &format!("{} {{msg}} {{bar:30}} {{percent}}% {{elapsed}}", m.name),
        quiet,
    );
    let status = crate::common::StatusLines::new(quiet);
    bar.set_message("Monte Carlo");
    let sample = synthesize_material(m, rig, seed, cache, &|done| {
        bar.set_position((300.0 * done) as u64);
        status.update(|| format!("{}: Monte Carlo {:.0} %", m.name, 100.0 * done));
    })?;
    bar.finish_and_clear();
    Ok(sample)
}

/// Writes a synthetic sample into `dir` (its manifest's `[fit]` at the defaults), with its
/// truth.json.
pub fn write_sample(dir: &Path, s: &SyntheticSample) -> anyhow::Result<()> {
    write_sample_with(dir, s, scatterfit_io::manifest::FitSection::default())
}

/// Writes a synthetic sample into `dir` with this `[fit]` in its manifest, and its truth.json
/// (`scatterfit_lab::twin`).
pub fn write_sample_with(
    dir: &Path,
    s: &SyntheticSample,
    fit: scatterfit_io::manifest::FitSection,
) -> anyhow::Result<()> {
    let how = TwinFolder::new(fit, synth_provenance(s)).with_truth();
    write_twin_folder(dir, s, &how).map_err(anyhow::Error::msg)?;
    Ok(())
}
