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
    seed=1, r_max_mm=10.0, bins=100, beam_radius_mm=None, beam="pencil", max_interactions=1e12,
    progress=None))]
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
    max_interactions: f64,
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
    // The tallies' memory, before they are allocated (the budget `scatterfit simulate` uses).
    let budget = scatterfit_io::budget::memory_budget_bytes();
    let needed = Simulation::tally_memory_bytes(bins, 0);
    if needed > budget {
        return Err(errors::input(format!(
            "bins={bins}: the tallies need {} of memory, more than the budget of {} ({})",
            scatterfit_io::budget::describe_bytes(needed),
            scatterfit_io::budget::describe_bytes(budget),
            scatterfit_io::budget::how_to_raise()
        )));
    }
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
    // Work that would not finish is refused before it starts, with the estimate (the same
    // cost model and default budget as `scatterfit simulate --max-interactions`).
    let cost = sim.cost_estimate();
    if cost.interactions > max_interactions {
        return Err(errors::input(format!(
            "this simulation is expected to take about {:.1e} interactions ({:.3e} per photon × \
             {photons} photons), about {} on {} threads, more than max_interactions={:.1e}; use \
             fewer photons, a larger sigma_a, a g further from 1, a thinner slab, or raise \
             max_interactions if you mean it",
            cost.interactions,
            cost.interactions_per_photon,
            scatterfit_io::budget::describe_seconds(cost.seconds(rayon::current_num_threads())),
            rayon::current_num_threads(),
            max_interactions
        )));
    }
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
