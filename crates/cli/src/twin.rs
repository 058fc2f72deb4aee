//! The rig twin as the commands use it (`synth`, `demo`): a material → a synthetic sample →
//! a sample folder.

use std::path::Path;
use std::sync::Mutex;

use anyhow::Context;
use scatterfit_io::sample_folder::{SampleFiles, write_sample_folder};
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
    let bar = bar(
        3,
        &format!("{} {{msg}} {{bar:30}} {{percent}}% {{elapsed}}", m.name),
        quiet,
    );
    let done = Mutex::new([0.0f64; 3]);
    let sample = scatterfit_synth::synthesize(
        &m.name,
        m.sigma_s_prime,
        m.sigma_a,
        m.eta,
        &rig,
        seed,
        cache,
        &|c, d, t| {
            if let Ok(mut f) = done.lock() {
                f[c] = d as f64 / t.max(1) as f64;
                bar.set_length(300);
                bar.set_position((100.0 * f.iter().sum::<f64>()) as u64);
                bar.set_message("Monte Carlo");
            }
        },
    )
    .with_context(|| format!("synthesising {}", m.name))?;
    bar.finish_and_clear();
    Ok(sample)
}

/// Writes a synthetic sample into `dir` (its manifest's `[fit]` at the defaults).
pub fn write_sample(dir: &Path, s: &SyntheticSample) -> anyhow::Result<()> {
    write_sample_with(dir, s, scatterfit_io::manifest::FitSection::default())
}

/// Writes a synthetic sample into `dir` with this `[fit]` in its manifest.
pub fn write_sample_with(
    dir: &Path,
    s: &SyntheticSample,
    fit: scatterfit_io::manifest::FitSection,
) -> anyhow::Result<()> {
    let truth = serde_json::to_string_pretty(&s.truth).context("serialising the truth")?;
    write_sample_folder(
        dir,
        &SampleFiles {
            name: &s.truth.name,
            reading: &s.reading,
            lab10: Some([s.lab10.l, s.lab10.a, s.lab10.b]),
            frames: &s.bracket.frames,
            times_s: &s.bracket.times_s,
            mm_per_pixel: s.truth.rig.mm_per_pixel,
            spot_diameter_mm: 2.0 * s.truth.rig.spot_radius_mm,
            truth_json: Some(&truth),
            provenance: &format!(
                "synthetic sample `{}` made by `scatterfit synth` (Monte Carlo rig twin, seed {}); \
                 truth.json holds the parameters",
                s.truth.name, s.truth.seed
            ),
            fit,
        },
    )
    .map_err(anyhow::Error::msg)?;
    Ok(())
}
