//! A result as a material renderers read (`scatterfit.export`): pbrt-v4, Mitsuba 3, Blender or
//! renderer-neutral JSON, through `scatterfit_io::export` with the exact-transport figures of
//! `scatterfit_pipeline::export`, as `scatterfit export` writes them; and a `result.json` file
//! read (schema 1 files upgraded) for the package's `load`.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use scatterfit_io::export::{ExportError, Format, MitsubaVariant, SceneUnit, export_with};
use scatterfit_io::result_json::{parse_result_json, read_result_json};

use crate::errors;

/// Exports a result given as `result.json`'s text (private: `scatterfit.export`). Returns the
/// text, the export's warnings, and why the result is not trusted (`None` when every channel is
/// `ok`).
#[pyfunction]
#[pyo3(signature = (result_json, *, to, scale="mm", mitsuba_variant="rgb", source="the result"))]
pub(crate) fn export(
    result_json: &str,
    to: &str,
    scale: &str,
    mitsuba_variant: &str,
    source: &str,
) -> PyResult<(String, Vec<String>, Option<String>)> {
    let format = Format::ALL
        .into_iter()
        .find(|f| f.name() == to)
        .ok_or_else(|| {
            errors::input(format!(
                "to={to:?}: the formats are {}",
                Format::ALL.map(Format::name).join(", ")
            ))
        })?;
    let (exported, untrusted) = exported(result_json, format, scale, mitsuba_variant, source)?;
    Ok((exported.text, exported.warnings, untrusted))
}

/// The Mitsuba export's objects as `mitsuba.load_dict` dictionaries (private:
/// `scatterfit.mitsuba_dict`, `mitsuba_integrator`): JSON text of `{"bsdf", "interior",
/// "integrator"}` ([`scatterfit_io::export::MitsubaObject::to_dict`]), the export's warnings, and
/// why the result is not trusted.
#[pyfunction]
#[pyo3(signature = (result_json, *, scale="mm", mitsuba_variant="rgb", source="the result"))]
pub(crate) fn mitsuba_dict(
    result_json: &str,
    scale: &str,
    mitsuba_variant: &str,
    source: &str,
) -> PyResult<(String, Vec<String>, Option<String>)> {
    let (exported, untrusted) =
        exported(result_json, Format::Mitsuba, scale, mitsuba_variant, source)?;
    let material = exported
        .mitsuba
        .ok_or_else(|| errors::input(format!("{source}: the Mitsuba export has no objects")))?;
    let dict = serde_json::json!({
        "bsdf": material.boundary.to_dict(),
        "interior": material.medium.to_dict(),
        "integrator": material.integrator.to_dict(),
    });
    Ok((dict.to_string(), exported.warnings, untrusted))
}

/// The export of `result_json` in `format`, as `scatterfit export` makes it, with why the result
/// is not trusted.
fn exported(
    result_json: &str,
    format: Format,
    scale: &str,
    mitsuba_variant: &str,
    source: &str,
) -> PyResult<(scatterfit_io::export::Export, Option<String>)> {
    let unit = match scale {
        "mm" => SceneUnit::Millimetre,
        "m" => SceneUnit::Metre,
        _ => {
            return Err(errors::input(format!(
                "scale={scale:?}: \"mm\" (1 scene unit = 1 mm) or \"m\""
            )));
        }
    };
    let variant = match mitsuba_variant {
        "rgb" => MitsubaVariant::Rgb,
        "spectral" => MitsubaVariant::Spectral,
        _ => {
            return Err(errors::input(format!(
                "mitsuba_variant={mitsuba_variant:?}: \"rgb\" or \"spectral\""
            )));
        }
    };
    let result =
        parse_result_json(result_json, Path::new(source)).map_err(|e| errors::bad_input(&e))?;
    let options = scatterfit_pipeline::export::export_options(&result, unit, variant);
    let exported = export_with(&result, format, &options).map_err(|e| match e {
        ExportError::FailedChannel { .. } => {
            errors::raise(errors::Kind::Measurement, format!("{source}: {e}"))
        }
        other => errors::input(format!("{source}: {other}")),
    })?;
    Ok((exported, result.untrusted()))
}

/// A `result.json` file as the current schema's JSON text (private: `scatterfit.load`).
#[pyfunction]
pub(crate) fn read_result(path: PathBuf) -> PyResult<String> {
    let result = read_result_json(&path).map_err(|e| errors::bad_input(&e))?;
    serde_json::to_string(&result).map_err(|e| errors::bad_input(&e))
}
