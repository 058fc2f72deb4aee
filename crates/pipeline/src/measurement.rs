//! [`Measurement`]: everything a measurement of one sample produced, stage by stage — what
//! `measure_sample` ([`crate::measure`]) assembles, the checks judge ([`crate::checks`]) and the
//! result file records ([`Measurement::to_result`]).

use scatterfit_io::manifest::SampleManifest;
use scatterfit_optics::{Estimate, Rgb};
use serde::Serialize;

use crate::checks::evidence::Evidence;
use crate::checks::findings::SampleChecks;
use crate::fit::outcome::ChannelOutcome;
use crate::hdr::HdrStage;
use crate::port::PortCorrection;
use crate::profile::ProfileStage;
use crate::settings::FitSettings;
use crate::spectro::SpectroStage;

/// A stage of [`measure_sample`](crate::measure_sample), for progress reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Stage {
    /// Reading and analysing the spectrophotometer file.
    Spectro,
    /// Reading the frames (called per frame).
    ReadFrame,
    /// Recovering the response and merging.
    Merge,
    /// Spot and rings.
    Profile,
    /// Fitting the channels.
    Fit,
    /// Checking the image and the bracket against the fits ([`crate::checks::image_checks`]).
    Checks,
}

/// Everything a measurement produced.
#[derive(Debug, Clone)]
pub struct Measurement {
    /// The manifest.
    pub manifest: SampleManifest,
    /// Fit settings used.
    pub settings: FitSettings,
    /// Spectrophotometer stage.
    pub spectro: SpectroStage,
    /// The merged bracket.
    pub hdr: HdrStage,
    /// Spot and rings.
    pub profile: ProfileStage,
    /// Per channel: σ′s, σa and α′ with their uncertainty terms, the solver's report, or why the
    /// channel was not fitted.
    pub fits: Rgb<ChannelOutcome>,
    /// The port's edge-loss correction (`spectro.aperture_mm` given; `spectro` is then the
    /// corrected stage and the correction keeps the reading), or `None`: the reading was taken as
    /// loss-free.
    pub port: Option<PortCorrection>,
    /// Wall times per stage \[s\].
    pub timings: Timings,
    /// What the data's redundancy says (the profile's own α′; [`crate::checks::evidence`]).
    pub evidence: Evidence,
    /// The checks of the image, the bracket and the manifest that no fit enters
    /// ([`crate::checks::image_checks`]): made once, when the measurement is made, and kept by
    /// its refits; [`Measurement::quality`] adds the fits' own checks to them.
    pub image_checks: SampleChecks,
}

/// Wall times per stage \[s\].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Timings {
    /// Spectro stage.
    pub spectro_s: f64,
    /// Reading frames.
    pub read_s: f64,
    /// Response recovery and merge.
    pub merge_s: f64,
    /// Spot centre and profile.
    pub profile_s: f64,
    /// The three fits (start search + solver).
    pub fit_s: f64,
    /// The checks of the image and the bracket ([`crate::checks::image_checks`]) and the spot's
    /// scale against the fits ([`crate::checks::spot_scale`]).
    pub checks_s: f64,
    /// The whole measurement.
    pub total_s: f64,
}

impl Measurement {
    /// True when every channel gave constrained parameters.
    pub fn complete(&self) -> bool {
        self.fits.iter().all(ChannelOutcome::is_measurement)
    }

    /// η with the spectrophotometer's standard error (none when η was given).
    pub fn eta(&self) -> Estimate {
        self.spectro.eta_estimate()
    }
}
