//! scatterfit for Python: the compiled module `scatterfit._scatterfit` under the `scatterfit`
//! package (crates/python/python/scatterfit), built with PyO3 as one abi3 wheel for CPython ≥ 3.9.
//!
//! This module is the thin, typed edge between Python and the Rust library: options arrive as
//! keyword arguments and are parsed into the library's own types (`Overrides`, `ModelName`, …,
//! with the library's error messages), arrays arrive as NumPy `float64` arrays and leave as new
//! ones, and results leave as the library's own serialisation (`result.json`'s text, which the
//! package turns into objects), so that `measure(...).to_dict()` is what `scatterfit measure`
//! writes. Long work runs with the GIL released on a worker thread while the calling thread
//! watches for Ctrl-C and reports progress (`run.rs`). The Python-facing API — names, docstrings,
//! the objects a measurement becomes — is the package's (`python/scatterfit/*.py`); everything
//! here is private to it.

mod errors;
mod export;
mod measure;
mod models;
mod options;
mod run;
mod simulate;
mod spectro;

use pyo3::prelude::*;

/// The compiled part of the `scatterfit` package (private: use `scatterfit`).
#[pymodule]
fn _scatterfit(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<measure::MeasurementHandle>()?;
    m.add_function(wrap_pyfunction!(measure::measure, m)?)?;
    m.add_function(wrap_pyfunction!(measure::batch, m)?)?;
    m.add_function(wrap_pyfunction!(models::fit_profile, m)?)?;
    m.add_function(wrap_pyfunction!(models::profile, m)?)?;
    m.add_function(wrap_pyfunction!(models::rd_total, m)?)?;
    m.add_function(wrap_pyfunction!(models::albedo_from_rd, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(spectro::spectro_file, m)?)?;
    m.add_function(wrap_pyfunction!(spectro::spectro_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(export::export, m)?)?;
    m.add_function(wrap_pyfunction!(export::mitsuba_dict, m)?)?;
    m.add_function(wrap_pyfunction!(export::read_result, m)?)?;
    Ok(())
}
