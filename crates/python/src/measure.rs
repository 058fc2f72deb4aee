//! `measure` and `batch`: sample folders → measurements, through `scatterfit_pipeline`'s
//! `measure_sample` and `measure_batch_with`, as `scatterfit measure` and `scatterfit batch` run
//! them; and the handle a measurement is kept in, for its arrays and its result files.

use std::path::{Path, PathBuf};

use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use scatterfit_pipeline::outputs::{
    RESULT_FILES, check_destination, check_output_dir, refuse_foreign_results,
    refuse_outputs_that_are_inputs,
};
use scatterfit_pipeline::{
    BatchEvent, BatchRequest, Measurement, PipelineError, Stage, measure_batch_with,
    measure_sample_until, sample_inputs,
};

use crate::errors;
use crate::options::FitOptions;
use crate::run::{Control, run};

/// A measurement, kept whole: its result (`result.json`'s text), its profile as arrays, and the
/// result files on request (private: the package's `Measurement` wraps it).
#[pyclass(module = "scatterfit._scatterfit", frozen)]
pub(crate) struct MeasurementHandle {
    measurement: Measurement,
    result_json: String,
    allow_outside_paths: bool,
}

impl MeasurementHandle {
    fn new(measurement: Measurement, allow_outside_paths: bool) -> PyResult<Self> {
        // What `scatterfit measure` writes as result.json (its profile beside it as profile.csv).
        let result = measurement.to_result(Some("profile.csv"));
        let result_json = serde_json::to_string(&result).map_err(|e| errors::bad_input(&e))?;
        Ok(Self {
            measurement,
            result_json,
            allow_outside_paths,
        })
    }
}

#[pymethods]
impl MeasurementHandle {
    /// The result as `result.json` holds it (JSON text).
    fn result_json(&self) -> &str {
        &self.result_json
    }

    /// True when every channel has constrained parameters.
    fn complete(&self) -> bool {
        self.measurement.complete()
    }

    /// The radial profile: `r_mm` (n,), and per channel (n, 3) arrays `value` (relative
    /// radiance), `stderr`, `count` (pixels per ring) and `limit` (detection limit; NaN unknown).
    fn profile<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let table = self.measurement.profile.to_table();
        let n = table.r_mm.len();
        let k = table.channels.len();
        let column = |f: &dyn Fn(&scatterfit_io::profile_csv::ProfileColumn, usize) -> f64| {
            let mut out = vec![f64::NAN; n * k];
            for (c, col) in table.channels.iter().enumerate() {
                for i in 0..n {
                    out[i * k + c] = f(col, i);
                }
            }
            out
        };
        let matrix = |values: Vec<f64>| -> PyResult<Bound<'py, PyArray2<f64>>> {
            values.into_pyarray(py).reshape([n, k])
        };
        let dict = PyDict::new(py);
        dict.set_item("r_mm", PyArray1::from_slice(py, &table.r_mm))?;
        dict.set_item("r_px", PyArray1::from_slice(py, &table.r_px))?;
        dict.set_item("value", matrix(column(&|c, i| c.value[i]))?)?;
        dict.set_item("stderr", matrix(column(&|c, i| c.stderr[i]))?)?;
        dict.set_item("count", matrix(column(&|c, i| c.count[i] as f64))?)?;
        dict.set_item(
            "limit",
            matrix(column(&|c, i| c.limit.get(i).copied().unwrap_or(f64::NAN)))?,
        )?;
        let names: Vec<&str> = table.channels.iter().map(|c| c.name.as_str()).collect();
        dict.set_item("channels", names)?;
        Ok(dict)
    }

    /// Wall times of the stages [s].
    fn timings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let t = &self.measurement.timings;
        let dict = PyDict::new(py);
        for (k, v) in [
            ("spectro_s", t.spectro_s),
            ("read_s", t.read_s),
            ("merge_s", t.merge_s),
            ("profile_s", t.profile_s),
            ("fit_s", t.fit_s),
            ("checks_s", t.checks_s),
            ("total_s", t.total_s),
        ] {
            dict.set_item(k, v)?;
        }
        Ok(dict)
    }

    /// The sample folder.
    fn sample_dir(&self) -> PathBuf {
        self.measurement.manifest.dir.clone()
    }

    /// Writes the result files into `folder` (default: the sample folder) with the same checks
    /// as `scatterfit measure -o`: not over one of the sample's inputs, not into another sample's
    /// folder or results unless `force`. Returns the files written.
    #[pyo3(signature = (folder=None, force=false))]
    fn write(
        &self,
        py: Python<'_>,
        folder: Option<PathBuf>,
        force: bool,
    ) -> PyResult<Vec<PathBuf>> {
        let m = &self.measurement;
        let out = folder.unwrap_or_else(|| m.manifest.dir.clone());
        let allow_outside = self.allow_outside_paths;
        py.detach(|| -> Result<Vec<PathBuf>, WriteError> {
            check_output_dir(&out, "folder").map_err(WriteError::input)?;
            let inputs =
                sample_inputs(&m.manifest.dir, allow_outside).map_err(WriteError::Pipeline)?;
            refuse_foreign_results(&inputs.manifest.dir, &out, force).map_err(WriteError::input)?;
            let outputs: Vec<PathBuf> = RESULT_FILES.iter().map(|f| out.join(f)).collect();
            refuse_outputs_that_are_inputs("write", &outputs, &inputs.files)
                .map_err(WriteError::input)?;
            for o in &outputs {
                check_destination(o, "folder").map_err(WriteError::input)?;
            }
            let written = scatterfit_report::write_measurement(&out, m)
                .map_err(|e| WriteError::Output(errors::text(&e)))?;
            Ok(written.files)
        })
        .map_err(WriteError::into_py)
    }
}

/// Why writing failed, carried out of the GIL-free section (a `PyErr` is made with the GIL).
enum WriteError {
    Input(String),
    Pipeline(PipelineError),
    Output(String),
}

impl WriteError {
    fn input(e: impl std::error::Error + 'static) -> Self {
        WriteError::Input(errors::text(&e))
    }

    fn into_py(self) -> PyErr {
        match self {
            WriteError::Input(t) => errors::input(t),
            WriteError::Pipeline(e) => errors::pipeline(&e),
            WriteError::Output(t) => errors::raise(errors::Kind::Output, t),
        }
    }
}

/// The stage's place among the five a measurement reports (the progress count).
fn stage_number(stage: Stage) -> u64 {
    match stage {
        Stage::Spectro => 1,
        Stage::ReadFrame => 2,
        Stage::Merge => 3,
        Stage::Profile => 4,
        Stage::Fit => 5,
        _ => 6,
    }
}

/// Measures one sample folder (private: `scatterfit.measure`).
#[pyfunction]
#[pyo3(signature = (folder, *, method=None, model=None, albedo_model=None, eta=None,
    normalise_with_spectro=None, g=None, g_range=None, allow_outside_paths=false, progress=None))]
pub(crate) fn measure<'py>(
    py: Python<'py>,
    folder: PathBuf,
    method: Option<String>,
    model: Option<String>,
    albedo_model: Option<String>,
    eta: Option<f64>,
    normalise_with_spectro: Option<bool>,
    g: Option<Bound<'py, PyAny>>,
    g_range: Option<(f64, f64)>,
    allow_outside_paths: bool,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<MeasurementHandle> {
    let overrides = FitOptions {
        method,
        model,
        albedo_model,
        eta,
        normalise_with_spectro,
        g,
        g_range,
        allow_outside_paths,
    }
    .overrides()?;
    let measured = run(py, progress.as_ref(), 6, |control: &Control| {
        measure_sample_until(
            &folder,
            &overrides,
            &|stage| control.set_done(stage_number(stage) - 1),
            &|| control.stopped(),
        )
    })?;
    let m = measured.map_err(|e| errors::pipeline(&e))?;
    MeasurementHandle::new(m, allow_outside_paths)
}

/// Measures many sample folders in parallel within the memory budget (private:
/// `scatterfit.batch`). Returns, in the folders' order, `(folder, handle, None)` for a
/// measurement and `(folder, None, (kind, message))` for a sample that failed, `kind` being
/// `"input"` or `"measurement"`: one bad sample never stops the others.
#[pyfunction]
#[pyo3(signature = (folders, *, jobs=None, method=None, model=None, albedo_model=None, eta=None,
    normalise_with_spectro=None, g=None, g_range=None, allow_outside_paths=false, progress=None))]
pub(crate) fn batch<'py>(
    py: Python<'py>,
    folders: Vec<PathBuf>,
    jobs: Option<usize>,
    method: Option<String>,
    model: Option<String>,
    albedo_model: Option<String>,
    eta: Option<f64>,
    normalise_with_spectro: Option<bool>,
    g: Option<Bound<'py, PyAny>>,
    g_range: Option<(f64, f64)>,
    allow_outside_paths: bool,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Vec<BatchItem>> {
    let overrides = FitOptions {
        method,
        model,
        albedo_model,
        eta,
        normalise_with_spectro,
        g,
        g_range,
        allow_outside_paths,
    }
    .overrides()?;
    if jobs == Some(0) {
        return Err(errors::input(
            "jobs=0: measure at least one sample at a time",
        ));
    }
    let total = folders.len() as u64;
    let outcome = run(py, progress.as_ref(), total, |control: &Control| {
        // A Ctrl-C: the samples not yet started are not measured (the running ones finish).
        let mut request = BatchRequest::new(folders, overrides).stop_when(control.stop_flag());
        if let Some(j) = jobs {
            request = request.jobs(j);
        }
        measure_batch_with(request, &|dir: &Path, m| (dir.to_path_buf(), m), &|event| {
            if let BatchEvent::Finished { .. } = event {
                control.add_done();
            }
        })
    })?;
    let outcome = outcome.map_err(|e| errors::bad_input(&e))?;
    outcome
        .samples
        .into_iter()
        .map(|s| {
            let (dir, measured) = s.outcome;
            Ok(match measured {
                Ok(m) => (
                    dir,
                    Some(MeasurementHandle::new(m, allow_outside_paths)?),
                    None,
                ),
                Err(e) => {
                    let kind = if e.is_measurement_failure() {
                        "measurement"
                    } else {
                        "input"
                    };
                    (dir, None, Some((kind.to_owned(), errors::text(&e))))
                }
            })
        })
        .collect()
}

/// One sample of a batch: its folder, its measurement or why it has none.
type BatchItem = (PathBuf, Option<MeasurementHandle>, Option<(String, String)>);
