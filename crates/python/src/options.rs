//! Keyword arguments → the library's option types, with the library's names and checks (the
//! names a Python user passes are the CLI's: `model="dipole"`, `g="fit"`, `g_range=(0.7, 0.95)`).

use std::str::FromStr;

use pyo3::prelude::*;
use scatterfit_io::manifest::GSetting;
use scatterfit_optics::{AlbedoModel, Method, ModelName};
use scatterfit_pipeline::Overrides;
use scatterfit_pipeline::anisotropy::GPrior;

use crate::errors;

/// A name (`method`, `model`, `albedo_model`) parsed by the library's `FromStr`, whose error lists
/// the valid names.
pub(crate) fn name<T>(argument: &str, value: Option<&str>) -> PyResult<Option<T>>
where
    T: FromStr,
    T::Err: std::fmt::Display,
{
    value
        .map(|v| T::from_str(v).map_err(|e| errors::input(format!("{argument}={v:?}: {e}"))))
        .transpose()
}

/// `g`: a number in (−1, 1), the text `"fit"`, or `None` (the manifest's setting).
pub(crate) fn g_setting(g: Option<&Bound<'_, PyAny>>) -> PyResult<Option<GSetting>> {
    let Some(g) = g else { return Ok(None) };
    if g.is_none() {
        return Ok(None);
    }
    if let Ok(text) = g.extract::<String>() {
        return text
            .parse::<GSetting>()
            .map(Some)
            .map_err(|e| errors::input(format!("g: {e}")));
    }
    let value: f64 = g.extract().map_err(|_| {
        errors::input(format!(
            "g={}: a number in (−1, 1) or \"fit\"",
            g.repr().map_or_else(|_| "?".into(), |r| r.to_string())
        ))
    })?;
    if !value.is_finite() {
        return Err(errors::input(format!(
            "g={value}: a finite number in (−1, 1) or \"fit\""
        )));
    }
    Ok(Some(GSetting::Value(value)))
}

/// What is known about g from `g` and `g_range` (`None` when neither is given: the manifest's).
/// The prior's own rules (the range inside (−1, 1), a value inside the range) are checked by the
/// measurement, with its messages.
pub(crate) fn g_prior(
    g: Option<&Bound<'_, PyAny>>,
    g_range: Option<(f64, f64)>,
) -> PyResult<Option<GPrior>> {
    let setting = g_setting(g)?;
    if let Some((lo, hi)) = g_range
        && !(lo.is_finite() && hi.is_finite())
    {
        return Err(errors::input(format!(
            "g_range=({lo}, {hi}): two finite numbers, low and high"
        )));
    }
    Ok((setting.is_some() || g_range.is_some())
        .then(|| GPrior::from_setting(setting, g_range.map(|(lo, hi)| [lo, hi]))))
}

/// The fit options a measurement or a batch takes.
#[derive(Debug, Clone, Default)]
pub(crate) struct FitOptions<'py> {
    pub method: Option<String>,
    pub model: Option<String>,
    pub albedo_model: Option<String>,
    pub eta: Option<f64>,
    pub normalise_with_spectro: Option<bool>,
    pub g: Option<Bound<'py, PyAny>>,
    pub g_range: Option<(f64, f64)>,
    pub allow_outside_paths: bool,
}

impl FitOptions<'_> {
    /// The library's overrides of the manifest's `[fit]` choices.
    pub(crate) fn overrides(&self) -> PyResult<Overrides> {
        if let Some(e) = self.eta
            && !(e.is_finite() && (1.0..=3.0).contains(&e))
        {
            return Err(errors::input(format!(
                "eta={e}: the relative refractive index must lie in [1, 3]"
            )));
        }
        Ok(Overrides {
            method: name::<Method>("method", self.method.as_deref())?,
            model: name::<ModelName>("model", self.model.as_deref())?,
            albedo_model: name::<AlbedoModel>("albedo_model", self.albedo_model.as_deref())?,
            eta: self.eta,
            normalise_with_spectro: self.normalise_with_spectro,
            g: g_prior(self.g.as_ref(), self.g_range)?,
            allow_outside_paths: self.allow_outside_paths,
        })
    }
}
