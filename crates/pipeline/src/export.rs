//! What an export needs from the Monte Carlo tables (`scatterfit export`): the exact-transport
//! figures that `scatterfit_io::export`, which does not depend on `scatterfit_mc`, takes from its
//! caller in [`ExportOptions`]; and the checks of the export's output file
//! ([`check_export_output`]).

use std::path::{Path, PathBuf};

use scatterfit_io::export::{ExportOptions, Format, MitsubaVariant, SceneUnit};
use scatterfit_io::result_json::MeasurementResult;
use scatterfit_optics::{ModelFamily, ModelName};

use crate::outputs::{OutputError, check_destination, check_output_folder, same_file};

/// The options of an export of `result` in `unit` for `mitsuba_variant`, with the exact-transport
/// figures of the Monte Carlo tables shipped with scatterfit ([`exact_transport_rd`],
/// [`spectral_albedo`]) where they cover the result.
pub fn export_options(
    result: &MeasurementResult,
    unit: SceneUnit,
    mitsuba_variant: MitsubaVariant,
) -> ExportOptions {
    ExportOptions {
        unit,
        exact_rd: exact_transport_rd(result),
        spectral_albedo: spectral_albedo(result),
        mitsuba_variant,
    }
}

/// Exact transport's total diffuse reflectance Rd_exact(α′, η) of each channel's exported medium (a
/// half-space with the result's σ′s, σa, g = 0 and η), from the Monte Carlo tables shipped with
/// scatterfit: what Mitsuba's and pbrt's volumetric path tracers render, which the export's header
/// compares with the measured Rd. `None` when the tables do not cover the result (η outside 1.0–2.5)
/// or a channel has no coefficients (the export then refuses it anyway).
pub fn exact_transport_rd(result: &MeasurementResult) -> Option<[f64; 3]> {
    let mc = scatterfit_mc::family(ModelName::Mc).ok()?;
    let rd = result.coefficients().ok()?.map(|(sp, sa)| {
        let rd = mc.rd_total(sp / (sp + sa), result.eta, 0.0).ok()?;
        (rd.is_finite() && (0.0..=1.0).contains(&rd)).then_some(rd)
    });
    Some(rd.transpose()?.into_array())
}

/// The single-scattering albedo whose exact-transport total Rd is the measured Rd(λ), at each
/// wavelength of the result's spectrum (the Monte Carlo tables' inversion): the spectral medium's
/// albedo. Rd(λ) beyond what the tables reach at this η (a nearly black band, Rd below the lowest
/// tabulated albedo's; or above the highest's) takes that end albedo: the light it misplaces is at
/// most the lowest albedo's Rd (a few 10⁻³ at most). `None` without a spectrum or where the tables do
/// not cover η (1.0–2.5).
pub fn spectral_albedo(result: &MeasurementResult) -> Option<Vec<f64>> {
    let spec = result.rd_spectrum.as_ref()?;
    let mc = scatterfit_mc::family(ModelName::Mc).ok()?;
    albedo_at(mc, &spec.rd, result.eta)
}

/// [`spectral_albedo`] of the reflectances `rd` through `family`'s total at η.
fn albedo_at(family: &dyn ModelFamily, rd: &[f64], eta: f64) -> Option<Vec<f64>> {
    let reach = |grid: &[f64]| {
        grid.iter().copied().find_map(|a| {
            family
                .rd_total(a, eta, 0.0)
                .ok()
                .filter(|rd| rd.is_finite())
                .map(|rd| (a, rd))
        })
    };
    let (a_lo, rd_lo) = reach(&[1e-3, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5])?;
    let (a_hi, rd_hi) = reach(&[0.9999, 0.9995, 0.999, 0.995, 0.99])?;
    rd.iter()
        .map(|&rd| {
            if rd <= rd_lo {
                Some(a_lo)
            } else if rd >= rd_hi {
                Some(a_hi)
            } else {
                family.albedo_from_rd(rd, eta, 0.0).ok()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The inversion undoes the tables' total inside their reach, and clamps to the end albedos
    /// beyond it (a black band, a white one) instead of failing.
    #[test]
    fn spectral_albedo_inverts_and_clamps() {
        let mc = scatterfit_mc::family(ModelName::Mc).expect("the shipped tables");
        let eta = 1.4;
        let a = [0.3, 0.8, 0.99];
        let rd: Vec<f64> = a
            .iter()
            .map(|&a| mc.rd_total(a, eta, 0.0).unwrap())
            .collect();
        let back = albedo_at(mc, &rd, eta).expect("covered");
        for (want, got) in a.iter().zip(&back) {
            assert!((want - got).abs() < 1e-6, "{want} → {got}");
        }
        let ends = albedo_at(mc, &[0.0, 1.0], eta).expect("covered");
        // The lowest and highest albedos the tables reach (they start at a = 0.02, end at 0.9999).
        assert!(ends[0] <= 0.02 && ends[1] >= 0.99, "{ends:?}");
    }

    /// η outside the tables (1.0–2.5): no figures rather than wrong ones.
    #[test]
    fn uncovered_eta_gives_none() {
        let mc = scatterfit_mc::family(ModelName::Mc).expect("the shipped tables");
        assert_eq!(albedo_at(mc, &[0.5], 3.5), None);
    }
}

/// Why an export's output file is refused ([`check_export_output`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportOutputError {
    /// The file's extension is not the format's.
    #[error(
        "output {}: a {} export is written to a .{} file; name it e.g. `{}`",
        path.display(),
        format.name(),
        format.extension(),
        path.with_extension(format.extension()).display()
    )]
    Extension {
        /// The output.
        path: PathBuf,
        /// The format asked for.
        format: Format,
    },
    /// The output is the result being exported.
    #[error("output {} is the input result; write the export to another file", path.display())]
    IsInput {
        /// The output.
        path: PathBuf,
    },
    /// The output exists and `force` was not given.
    #[error("output {} exists; pass --force to replace it, or choose another name", path.display())]
    Exists {
        /// The output.
        path: PathBuf,
    },
    /// The output is a folder.
    #[error("output {} is a folder; name a file", path.display())]
    IsFolder {
        /// The output.
        path: PathBuf,
    },
    /// A link at the output's name, or its folder cannot take the file.
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// Checks an export's output file `out` before the result is read: its extension is `format`'s,
/// it is not a link, not the `input` result (by resolved path, or by device and inode: a hard
/// link), not an existing file unless `force`, not a folder; its folder exists and is writable.
///
/// # Errors
/// The first problem, naming the file and what to do.
pub fn check_export_output(
    out: &Path,
    format: Format,
    input: &Path,
    force: bool,
) -> Result<(), ExportOutputError> {
    let path = || out.to_path_buf();
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if ext.as_deref() != Some(format.extension()) {
        return Err(ExportOutputError::Extension {
            path: path(),
            format,
        });
    }
    check_destination(out, "output")?;
    if out.exists() {
        if same_file(out, input) {
            return Err(ExportOutputError::IsInput { path: path() });
        }
        if !force {
            return Err(ExportOutputError::Exists { path: path() });
        }
        if out.is_dir() {
            return Err(ExportOutputError::IsFolder { path: path() });
        }
    }
    Ok(check_output_folder(out, "-o")?)
}
