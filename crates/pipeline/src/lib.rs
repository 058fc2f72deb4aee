//! scatterfit-pipeline: the measurement, one function per stage, and the library a Rust program
//! measures with.
//!
//! 1. [`spectro::spectro_stage`] — η from SCI − SCE, Rd and α′ per channel;
//! 2. [`hdr::read_and_merge`] — the exposure bracket → a radiance map and its detection limits
//!    (in two halves, [`hdr::read_frames`] and [`hdr::merge_frames`], for a caller that reports
//!    between them);
//! 3. [`profile::profile_stage`] — spot centre and radial profile Rd(r);
//! 4. [`port::correct_port`] — the spectrophotometer port's edge loss, when the manifest gives the
//!    port (`spectro.aperture_mm`): Rd and α′ corrected from the fitted profile;
//! 5. [`fit::fit_stage`] — σ′s and σa per channel, and [`fit::propagate_spectro`], the
//!    spectrophotometer's part of their uncertainty; behind a port,
//!    [`port::propagate_fit_through_port`] carries the fit's error through the port's F.
//!
//! [`measure_sample`] runs them on a sample folder (its `sample.toml`) and returns a
//! [`Measurement`]: per channel ([`Rgb`], by [`Channel`]) σ′s, σa and α′ as [`Estimate`]s — the
//! value with the fit's and the spectrophotometer's standard errors apart, and their total —
//! and [`Measurement::to_result`], the content of `result.json`. [`batch`] measures many folders in
//! parallel within a memory budget, [`compare`] fits each both ways (the paper's Table 2), and
//! [`profile_fit`] fits a profile a user already has. Nothing here prints or writes files:
//! `scatterfit_report::write_measurement` writes a measurement's result files and plots.
//!
//! ```no_run
//! use std::path::Path;
//!
//! use scatterfit_pipeline::{ModelName, Overrides, measure_sample};
//!
//! let overrides = Overrides::default().model(ModelName::Mc); // exact transport
//! let m = measure_sample(Path::new("samples/pink-plastic"), &overrides, &|_| {})?;
//! for (c, fit) in m.fits.iter_channels() {
//!     if let Some(s) = fit.sigma_s_prime() {
//!         println!("{c}: σ′s = {:.4} ± {:.4} mm⁻¹", s.value, s.total().unwrap_or(f64::NAN));
//!     }
//! }
//! # Ok::<(), scatterfit_pipeline::PipelineError>(())
//! ```
//! `crates/pipeline/examples/` has the whole of it: `measure_folder.rs` (one folder) and
//! `batch_report.rs` (many folders, with the report files). The bias study over rig-twin samples
//! and the demo's accuracy table are `scatterfit-lab`'s, above this crate.

#![forbid(unsafe_code)]

pub mod anisotropy;
pub mod batch;
pub mod batch_args;
pub mod camera;
pub mod checks;
pub mod compare;
mod error;
pub mod export;
pub mod fit;
pub mod fit_args;
pub mod hdr;
pub mod measure;
pub mod measurement;
pub mod merge_settings;
pub mod model_term;
pub mod monte_carlo;
pub mod outputs;
pub mod port;
pub mod profile;
pub mod profile_fit;
pub mod profile_fit_args;
pub mod radiance;
mod result;
pub mod reuse;
pub mod samples;
pub mod settings;
pub mod spectro;
pub mod spectro_args;

pub use batch::{
    BatchError, BatchEvent, BatchOutcome, BatchRequest, BatchSample, JobPlan, SampleOutcome,
    measure_batch, measure_batch_with,
};
pub use compare::{Compared, compare_batch, compare_batch_with};
pub use error::{PipelineError, Result};
pub use fit::{ChannelFit, ChannelOutcome};
pub use measure::{measure_inputs, measure_inputs_until, measure_sample, measure_sample_until};
pub use measurement::{Measurement, Stage, Timings};
pub use result::g_record;
pub use samples::{SampleDirs, SampleInputs, misspelt_manifest, sample_dirs, sample_inputs};
/// What a result file holds, and where its named values come from.
pub use scatterfit_io::result_json::{
    AlbedoSource, ChannelResult, ChannelStatus, EtaSource, MeasurementResult, ResponseKind,
};
/// The one name → forward model factory (the Monte Carlo tables live in `scatterfit_mc`).
pub use scatterfit_mc::{albedo_family, family};
/// The vocabulary a program using the pipeline needs: what to fit with, per-channel values, and
/// a value with its uncertainty terms.
pub use scatterfit_optics::{AlbedoModel, Channel, Estimate, Method, ModelFamily, ModelName, Rgb};
pub use settings::{FitPlan, FitSettings, Overrides, SpotShape, fit_settings};
