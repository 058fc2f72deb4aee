//! The measured profile a validation render is compared with (Choi et al. 2014, §4.4, Table 2):
//! found through the result (`inputs.profile`, relative to the result's folder, under the input path
//! policy and checked to come from the same run as the result) or given, then read with the
//! result's fitted scales and geometry into a [`MeasuredProfile`].

use std::path::{Path, PathBuf};

use scatterfit_io::inputs::{InputPolicy, same_file};
use scatterfit_io::profile_csv::read_profile_csv;
use scatterfit_io::result_set::{self, SetStatus};
use scatterfit_optics::Rgb;

use crate::error::{RenderError, Result};
use crate::params::ParameterSet;
use crate::validation::MeasuredProfile;

/// A result and the profile it names share a folder without a result set to tie them to one run
/// (results of an older scatterfit, or of an interrupted run): worth a note, not a refusal.
#[derive(Debug, Clone, PartialEq)]
pub struct UncheckedRun {
    /// The folder.
    pub folder: PathBuf,
    /// The result file's name.
    pub result: String,
    /// The profile's file name.
    pub profile: String,
}

impl std::fmt::Display for UncheckedRun {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} has no {}: {} and {} cannot be checked to come from one run (results of an older \
             scatterfit, or of a run that was interrupted — then measure again)",
            self.folder.display(),
            result_set::SET_FILE,
            self.result,
            self.profile
        )
    }
}

/// The measured profile's file for `params`: `given`, else the result's `inputs.profile` resolved
/// in the result's folder (inside it unless `allow_outside_paths`), checked against the folder's
/// result set when both are listed there.
///
/// # Errors
/// [`RenderError::NotAResult`] for a published set; [`RenderError::Measurement`] for a result
/// without `inputs.profile`; the input path policy's and the result set's errors (a profile from
/// another run is refused).
pub fn profile_path(
    params: &ParameterSet,
    given: Option<&Path>,
    allow_outside_paths: bool,
) -> Result<(PathBuf, Option<UncheckedRun>)> {
    let Some((result, json, folder)) = params.result() else {
        return Err(RenderError::NotAResult {
            source_name: params.source.clone(),
        });
    };
    if let Some(path) = given {
        return Ok((path.to_path_buf(), None));
    }
    let Some(rel) = &result.inputs.profile else {
        return Err(RenderError::Measurement {
            file: json.to_path_buf(),
            detail: "no `inputs.profile`; give the measured profile with --measured-profile \
                     FILE.csv"
                .into(),
        });
    };
    // A result names files inside its folder (the input path policy), and the result and the
    // profile it names must come from one run (the folder's result set).
    let csv = InputPolicy::new(folder, allow_outside_paths)?.resolve(
        json,
        "`inputs.profile`",
        folder,
        Path::new(rel),
    )?;
    let unchecked = check_one_run(json, &csv)?;
    Ok((csv, unchecked))
}

/// The result `json` and the profile `csv` it names, when they share a folder: listed in the
/// folder's result set with the hashes they have now (one run's files), else refused; a folder
/// without a set is returned as an [`UncheckedRun`].
fn check_one_run(json: &Path, csv: &Path) -> Result<Option<UncheckedRun>> {
    let folder = json.parent().unwrap_or(Path::new(""));
    let folder = if folder.as_os_str().is_empty() {
        Path::new(".")
    } else {
        folder
    };
    let (Some(j), Some(c)) = (json.file_name(), csv.file_name()) else {
        return Ok(None);
    };
    if !same_file(csv.parent().unwrap_or(Path::new(".")), folder) {
        return Ok(None);
    }
    let (j, c) = (j.to_string_lossy(), c.to_string_lossy());
    Ok(match result_set::verify(folder, &[&j, &c])? {
        SetStatus::Unknown => Some(UncheckedRun {
            folder: folder.to_path_buf(),
            result: j.into_owned(),
            profile: c.into_owned(),
        }),
        _ => None,
    })
}

/// Reads the profile `csv` (value_r, value_g, value_b columns) with `params`' result: its fitted
/// scales, its mm per pixel (else derived from the profile's r_px column) and its spot radius
/// (`spot_radius_mm` overrides it).
///
/// # Errors
/// [`RenderError::NotAResult`] for a published set; [`RenderError::ProfileCsv`];
/// [`RenderError::Measurement`] naming what the result or the profile lacks.
pub fn read_measured(
    params: &ParameterSet,
    csv: &Path,
    spot_radius_mm: Option<f64>,
) -> Result<MeasuredProfile> {
    let Some((result, json, _)) = params.result() else {
        return Err(RenderError::NotAResult {
            source_name: params.source.clone(),
        });
    };
    let lacks = |file: &Path, detail: String| RenderError::Measurement {
        file: file.to_path_buf(),
        detail,
    };
    let table = read_profile_csv(csv)?;
    let values = Rgb::from_fn(|c| {
        table
            .channels
            .iter()
            .find(|col| col.name == c.key())
            .map(|col| col.value.clone())
            .ok_or_else(|| {
                lacks(
                    csv,
                    format!(
                        "no value_{} column; --profile compares an RGB profile (value_r, \
                             value_g, value_b)",
                        c.key()
                    ),
                )
            })
    })
    .transpose()?;
    let scales = Rgb::from_fn(|c| {
        result.channels[c]
            .scale
            .filter(|k| k.is_finite() && *k > 0.0)
            .ok_or_else(|| {
                lacks(
                    json,
                    format!(
                        "`channels.{}.scale` (the fitted profile scale k) is missing or not \
                             positive; --profile needs it to put the measured profile in mm⁻²",
                        c.key()
                    ),
                )
            })
    })
    .transpose()?;
    let mm_per_pixel = match result.inputs.mm_per_pixel {
        Some(v) => v,
        None => table
            .r_mm
            .iter()
            .zip(&table.r_px)
            .rev()
            .find(|(mm, px)| mm.is_finite() && px.is_finite() && **px > 0.0)
            .map(|(mm, px)| mm / px)
            .ok_or_else(|| {
                lacks(
                    json,
                    "no `inputs.mm_per_pixel` and no r_px column to derive it".into(),
                )
            })?,
    };
    let spot_radius_mm = spot_radius_mm
        .or(result.inputs.spot_radius_mm)
        .ok_or_else(|| {
            lacks(
                json,
                "no `inputs.spot_radius_mm`; give the light spot's radius with --spot-radius-mm"
                    .into(),
            )
        })?;
    Ok(MeasuredProfile {
        file: csv.to_path_buf(),
        r_mm: table.r_mm,
        values,
        scales,
        fit_mse: Rgb::from_fn(|c| result.channels[c].mse),
        mm_per_pixel,
        spot_radius_mm,
    })
}
