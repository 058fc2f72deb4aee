//! scatterfit-pipeline: the measurement, one function per stage.
//!
//! 1. [`spectro::spectro_stage`] — η from SCI − SCE, Rd and α′ per channel;
//! 2. [`hdr::read_and_merge`] — the exposure bracket → a radiance map and its detection limits
//!    (in two halves, [`hdr::read_frames`] and [`hdr::merge_frames`], for a caller that reports
//!    between them);
//! 3. [`profile::profile_stage`] — spot centre and radial profile Rd(r);
//! 4. [`port::correct_port`] — the spectrophotometer port's edge loss, when the manifest gives the
//!    port (`spectro.aperture_mm`): Rd and α′ corrected from the fitted profile;
//! 5. [`fit::fit_stage`] — σ′s and σa per channel.
//!
//! [`measure_sample`] runs them on a sample folder (its `sample.toml`). The command-line tool's
//! commands parse their arguments, call these functions and print; no command calls another's file.
//! Inputs are typed (paths, options); results are typed; nothing here prints or writes files.
//! [`study`] is the bias study's measuring and tabulating over a grid of rig-twin samples.

#![forbid(unsafe_code)]

pub mod camera;
pub mod checks;
mod error;
pub mod fit;
pub mod hdr;
pub mod measure;
pub mod port;
pub mod profile;
pub mod spectro;
pub mod study;

pub use error::{PipelineError, Result};
pub use measure::{
    Measurement, Overrides, SampleDirs, SampleInputs, Stage, Timings, measure_sample,
    misspelt_manifest, sample_dirs, sample_inputs,
};
/// The one name → forward model factory (the Monte Carlo tables live in `scatterfit_mc`).
pub use scatterfit_mc::{albedo_family, family};
/// The vocabulary a program using the pipeline needs: what to fit with, and per-channel values.
pub use scatterfit_optics::{AlbedoModel, Channel, Method, ModelFamily, ModelName, Rgb};
