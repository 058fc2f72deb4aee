//! The spectrophotometer's reading → η, colour, Rd and α′ per channel (`scatterfit.spectro`), as
//! `scatterfit spectro` computes them (`scatterfit_optics::spectro::analyse`); the analysis leaves
//! as its JSON text (the package returns the dict).

use std::path::PathBuf;

use pyo3::prelude::*;
use scatterfit_optics::colour::{Lab, Observer};
use scatterfit_optics::spectro::{SpectroOptions, SpectroReading, analyse};

use crate::errors;

/// The options: a measured L*a*b* with its observer, a known η.
fn options(
    lab: Option<(f64, f64, f64)>,
    observer: u32,
    eta: Option<f64>,
) -> PyResult<SpectroOptions> {
    let lab = match lab {
        None => None,
        Some((l, a, b)) => {
            if !((0.0..=100.0).contains(&l) && a.is_finite() && b.is_finite()) {
                return Err(errors::input(format!(
                    "lab=({l}, {a}, {b}): L* must lie in 0..100 and a*, b* be finite numbers"
                )));
            }
            let observer = Observer::from_degrees(observer).ok_or_else(|| {
                errors::input(format!("observer={observer}: use 2 or 10 (degrees)"))
            })?;
            Some((Lab { l, a, b }, observer))
        }
    };
    if let Some(e) = eta
        && !(e.is_finite() && (1.0..=3.0).contains(&e))
    {
        return Err(errors::input(format!(
            "eta={e}: the relative refractive index must lie in [1, 3]"
        )));
    }
    Ok(SpectroOptions { lab, eta })
}

/// The analysis of `reading`, as JSON text, and whether every channel has its α′.
fn analysed(
    reading: &SpectroReading,
    options: &SpectroOptions,
    what: &str,
) -> PyResult<(String, bool)> {
    let analysis = analyse(reading, options)
        .map_err(|e| errors::input(format!("{what}: {}", errors::text(&e))))?;
    let json = serde_json::to_string(&analysis).map_err(|e| errors::bad_input(&e))?;
    Ok((json, analysis.complete()))
}

/// A reading from a spectrophotometer CSV file (private: `scatterfit.spectro`).
#[pyfunction]
#[pyo3(signature = (path, *, lab=None, observer=10, eta=None))]
pub(crate) fn spectro_file(
    path: PathBuf,
    lab: Option<(f64, f64, f64)>,
    observer: u32,
    eta: Option<f64>,
) -> PyResult<(String, bool)> {
    let options = options(lab, observer, eta)?;
    let reading =
        scatterfit_io::spectro::read_spectro_csv(&path).map_err(|e| errors::bad_input(&e))?;
    analysed(&reading, &options, &path.display().to_string())
}

/// A reading given as arrays: wavelengths \[nm\], SCI and SCE reflectance (fractions) (private:
/// `scatterfit.spectro`).
#[pyfunction]
#[pyo3(signature = (wavelengths_nm, sci, sce, *, lab=None, observer=10, eta=None))]
pub(crate) fn spectro_arrays(
    wavelengths_nm: Vec<f64>,
    sci: Vec<f64>,
    sce: Vec<f64>,
    lab: Option<(f64, f64, f64)>,
    observer: u32,
    eta: Option<f64>,
) -> PyResult<(String, bool)> {
    let options = options(lab, observer, eta)?;
    let reading = SpectroReading::new(wavelengths_nm, sci, sce)
        .map_err(|e| errors::input(format!("the spectrum: {}", errors::text(&e))))?;
    analysed(&reading, &options, "the spectrum")
}
