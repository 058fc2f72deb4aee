//! The rig twin as the commands use it (`synth`, `demo`): a material → a synthetic sample →
//! a sample folder.

use std::path::Path;
use std::sync::Mutex;

use anyhow::Context;
use scatterfit_lab::twin::{TwinFolder, synth_provenance, write_twin_folder};
use scatterfit_synth::{RigSpec, SyntheticSample};

use crate::common::bar;

/// What a material to synthesise is.
#[derive(Debug, Clone)]
pub struct Material {
    /// Name.
    pub name: String,
    /// σ′s per channel.
    pub sigma_s_prime: [f64; 3],
    /// σa per channel.
    pub sigma_a: [f64; 3],
    /// η.
    pub eta: f64,
}

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
        3,
        &format!("{} {{msg}} {{bar:30}} {{percent}}% {{elapsed}}", m.name),
        quiet,
    );
    let done = Mutex::new([0.0f64; 3]);
    let status = crate::common::StatusLines::new(quiet);
    let sample = scatterfit_synth::synthesize(
        &m.name,
        m.sigma_s_prime,
        m.sigma_a,
        m.eta,
        rig,
        seed,
        cache,
        &|c, d, t| {
            if let Ok(mut f) = done.lock() {
                f[c] = d as f64 / t.max(1) as f64;
                bar.set_length(300);
                bar.set_position((100.0 * f.iter().sum::<f64>()) as u64);
                bar.set_message("Monte Carlo");
                let percent = 100.0 * f.iter().sum::<f64>() / 3.0;
                status.update(|| format!("{}: Monte Carlo {percent:.0} %", m.name));
            }
        },
    )
    .with_context(|| format!("synthesising {}", m.name))?;
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
