//! The proposed and the existing method on the same data (Choi et al. 2014, Table 2 and Figure 6):
//! each sample measured once with the proposed method, then refitted with the existing one from
//! the same merge and profile ([`Measurement::refit`]); optionally also fitted with the paper's
//! own forward model (the dipole of Jensen et al. 2001, α′ from its total) when the measurement
//! used another — the exact `mc` tables by default — so the paper's numbers stay side by side.

use std::path::Path;

use scatterfit_optics::{AlbedoModel, Method, ModelName};

use crate::batch::{BatchError, BatchEvent, BatchOutcome, BatchRequest, for_each_sample};
use crate::error::Result;
use crate::measure::measure_inputs;
use crate::measurement::Measurement;
use crate::samples::SampleInputs;
use crate::settings::FitSettings;
use crate::settings::Overrides;

/// One sample fitted both ways (and, when asked, with the paper's model).
#[derive(Debug)]
pub struct Compared {
    /// The proposed method (α′ from the spectrophotometer, σ′s fitted): the measurement.
    pub proposed: Measurement,
    /// The existing method (σ′s and σa fitted) on the same profile.
    pub existing: Measurement,
    /// When asked: the proposed method with the paper's model — the dipole, α′ from the dipole's
    /// total (Choi et al. 2014 eq. 1) — or why that fit could not run; its values only (no
    /// uncertainty terms).
    pub paper: Option<Result<Measurement>>,
}

/// The settings of the paper's own fit of a measurement made with `settings`: the dipole (Jensen
/// et al. 2001), α′ from the dipole's total Rd (Choi et al. 2014 eq. 1), the proposed method.
pub fn paper_settings(settings: &FitSettings) -> FitSettings {
    FitSettings {
        method: Method::Proposed,
        model: ModelName::Dipole,
        albedo_model: AlbedoModel::Diffusion,
        normalise_with_spectro: false,
        ..*settings
    }
}

/// Fits `proposed` (a measurement) the existing way and, with `paper`, the paper's way
/// ([`paper_settings`]).
///
/// # Errors
/// [`crate::PipelineError`] when the existing method's refit cannot run (its model cannot be
/// loaded).
pub fn compare_measurement(proposed: Measurement, paper: bool) -> Result<Compared> {
    let existing = proposed.refit(Method::Existing)?;
    // Values only: the paper's column is printed beside the measurement, not measured again
    // with its bars and cross-checks.
    let paper = paper.then(|| proposed.refit_values_only(paper_settings(&proposed.settings)));
    Ok(Compared {
        proposed,
        existing,
        paper,
    })
}

/// Measures one resolved sample with the proposed method (whatever `overrides.method` says) and
/// compares ([`compare_measurement`]).
///
/// # Errors
/// As [`crate::measure_inputs`] and [`compare_measurement`].
pub fn compare_sample(
    inputs: &SampleInputs,
    overrides: &Overrides,
    paper: bool,
) -> Result<Compared> {
    let overrides = overrides.method(Method::Proposed);
    compare_measurement(measure_inputs(inputs, &overrides, &|_| {})?, paper)
}

/// Compares every sample of `request` ([`compare_batch_with`] keeping each comparison).
///
/// # Errors
/// [`BatchError`] only when the worker threads cannot start.
pub fn compare_batch(
    request: BatchRequest,
    paper: bool,
    on_event: &(dyn Fn(BatchEvent<'_>) + Sync),
) -> std::result::Result<BatchOutcome<Result<Compared>>, BatchError> {
    compare_batch_with(request, paper, &|_, c| c, on_event)
}

/// Measures every sample of `request` with the proposed method and compares it
/// ([`compare_sample`]), in parallel as [`crate::batch::measure_batch_with`] does; `work` runs on
/// each comparison as soon as it is done (write its files there) and returns the sample's outcome.
///
/// # Errors
/// [`BatchError`] only when the worker threads cannot start.
pub fn compare_batch_with<T: Send>(
    request: BatchRequest,
    paper: bool,
    work: &(dyn Fn(&Path, Result<Compared>) -> T + Sync),
    on_event: &(dyn Fn(BatchEvent<'_>) + Sync),
) -> std::result::Result<BatchOutcome<T>, BatchError> {
    for_each_sample(
        request,
        &|sample| {
            let compared = sample
                .inputs
                .and_then(|inputs| compare_sample(&inputs, &sample.overrides, paper));
            work(&sample.dir, compared)
        },
        on_event,
    )
}
