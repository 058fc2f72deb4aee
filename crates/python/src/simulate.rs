//! Monte Carlo ground truth over NumPy (`scatterfit.simulate`): `scatterfit_mc`'s photon
//! transport for a half-space or a slab, as `scatterfit simulate` runs it, with its progress shown
//! and Ctrl-C honoured between waves of photons (`Simulation::run_until`).

use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use scatterfit_mc::{Beam, BeamProfile, Layer, McMean, RadialGrid, Sample, Simulation};

use crate::errors;
use crate::run::{Control, run};

/// A value and its standard error as a Python pair.
fn pair(m: McMean) -> (f64, f64) {
    (m.value, m.stderr)
}

/// Simulates `photons` photons (private: `scatterfit.simulate`).
#[pyfunction]
#[pyo3(signature = (sigma_s_prime, sigma_a, eta, *, g=0.0, thickness_mm=None, photons=100_000,
    seed=1, r_max_mm=10.0, bins=100, beam_radius_mm=None, beam="pencil", progress=None))]
pub(crate) fn simulate<'py>(
    py: Python<'py>,
    sigma_s_prime: f64,
    sigma_a: f64,
    eta: f64,
    g: f64,
    thickness_mm: Option<f64>,
    photons: u64,
    seed: u64,
    r_max_mm: f64,
    bins: usize,
    beam_radius_mm: Option<f64>,
    beam: &str,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    // Below a micrometre the bins' areas underflow and the tallies divide by them.
    if !(1e-3..=1e6).contains(&r_max_mm) {
        return Err(errors::input(format!(
            "r_max_mm={r_max_mm}: the outer radius must lie in [1e-3, 1e6] mm"
        )));
    }
    if !(1..=1_000_000).contains(&bins) {
        return Err(errors::input(format!(
            "bins={bins}: the radial grid takes 1 to 1000000 bins"
        )));
    }
    if !(1.0..=10.0).contains(&eta) {
        return Err(errors::input(format!(
            "eta={eta}: the relative refractive index must lie in [1, 10]"
        )));
    }
    if let Some(t) = thickness_mm
        && (t.is_nan() || t <= 0.0)
    {
        return Err(errors::input(format!(
            "thickness_mm={t}: a slab thickness > 0 mm (None for a half-space)"
        )));
    }
    let profile = match (beam, beam_radius_mm) {
        ("pencil", None) => BeamProfile::Pencil,
        ("disk" | "gaussian", Some(r)) if r > 0.0 && r <= 1000.0 => {
            if beam == "disk" {
                BeamProfile::Disk { radius: r }
            } else {
                BeamProfile::Gaussian { radius: r }
            }
        }
        _ => {
            return Err(errors::input(format!(
                "beam={beam:?} with beam_radius_mm={beam_radius_mm:?}: \"pencil\" (no radius), or \
                 \"disk\" / \"gaussian\" with a radius in (0, 1000] mm"
            )));
        }
    };
    let layer = Layer::from_reduced(
        sigma_s_prime,
        sigma_a,
        g,
        eta,
        thickness_mm.unwrap_or(f64::INFINITY),
    )
    .map_err(|e| errors::bad_input(&e))?;
    let sample = Sample::slab(layer, 1.0).map_err(|e| errors::bad_input(&e))?;
    let beam = Beam::new(profile).map_err(|e| errors::bad_input(&e))?;
    let grid =
        RadialGrid::uniform(r_max_mm / bins as f64, bins).map_err(|e| errors::bad_input(&e))?;
    let sim =
        Simulation::new(sample, beam, grid, photons, seed).map_err(|e| errors::bad_input(&e))?;
    let result = run(py, progress.as_ref(), photons, |control: &Control| {
        sim.run_until(&|done| control.set_done(done), &|| control.stopped())
    })?
    .ok_or_else(|| errors::raise(errors::Kind::Measurement, "the simulation was stopped"))?;
    let dict = PyDict::new(py);
    let centres: Vec<f64> = (0..result.grid.bins())
        .map(|i| result.grid.center(i))
        .collect();
    dict.set_item("r_mm", centres.into_pyarray(py))?;
    dict.set_item("r_edges_mm", PyArray1::from_slice(py, result.grid.edges()))?;
    let (rd, rd_stderr): (Vec<f64>, Vec<f64>) = result
        .rd_profile
        .iter()
        .map(|m| (m.value, m.stderr))
        .unzip();
    dict.set_item("rd", rd.into_pyarray(py))?;
    dict.set_item("rd_stderr", rd_stderr.into_pyarray(py))?;
    dict.set_item("rd_total", pair(result.rd_total))?;
    dict.set_item("transmittance", pair(result.transmittance))?;
    dict.set_item("absorbed", pair(result.absorbed))?;
    dict.set_item("specular", result.specular)?;
    dict.set_item("photons", result.photons)?;
    dict.set_item("interactions", result.interactions)?;
    dict.set_item("seed", result.seed)?;
    Ok(dict)
}
