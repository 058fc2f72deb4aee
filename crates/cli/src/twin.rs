//! The rig twin as the commands use it (`synth`, `demo`): a material → a synthetic sample →
//! a sample folder.

use std::path::Path;
use std::sync::Mutex;

use anyhow::Context;
use scatterfit_io::image_files::CameraFrame;
use scatterfit_io::sample_folder::{CameraFiles, SampleFiles, write_sample_folder_with};
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
    let frame = |f: &scatterfit_synth::rig::Frame| match f {
        scatterfit_synth::rig::Frame::U8(b) => CameraFrame::U8(b.clone()),
        scatterfit_synth::rig::Frame::U16(b) => CameraFrame::U16(b.clone()),
    };
    let rig = &s.truth.rig;
    let extra = CameraFiles {
        frames_u16: s.bracket.frames_u16.clone(),
        dng_levels: match rig.camera.output {
            scatterfit_synth::rig::SensorOutput::Linear {
                black_level,
                white_level,
            } if white_level < 65535.0 => Some((
                black_level.map(|b| b.round() as u16),
                white_level.round() as u16,
            )),
            _ => None,
        },
        flat: s.bracket.flat.as_ref().map(frame),
        spot_image: s.bracket.spot_image.as_ref().map(frame),
        spot_profile: (rig.effects.gaussian_spot && s.bracket.spot_image.is_none())
            .then_some(scatterfit_io::manifest::SpotProfileName::Gaussian),
        spectro_port_mm: s
            .truth
            .port
            .as_ref()
            .map(|p| [p.illuminated_mm, p.aperture_mm]),
    };
    write_sample_folder_with(
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
        &extra,
    )
    .map_err(anyhow::Error::msg)?;
    Ok(())
}
