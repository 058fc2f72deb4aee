//! The forward models over NumPy arrays (`scatterfit.models`), and `fit_profile`: a profile a
//! user already has, fitted as `scatterfit fit` fits it.
//!
//! The arrays arrive broadcast to one length by the package (NumPy's rules, in Python) and
//! contiguous; runs of equal material parameters are evaluated in one call of the model (the
//! usual case: one material at many radii).

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use scatterfit_fit::{ProfileData, Ring, Spot, model_profile};
use scatterfit_optics::{Method, ModelFamily, ModelName, OpticalProperties, Rgb};
use scatterfit_pipeline::profile_fit::{ProfileFitRequest, fit_profile as fit};

use crate::errors;
use crate::options::{g_prior, name};

/// The model family of `model` (the Monte Carlo tables are loaded once per process).
fn family(model: &str) -> PyResult<&'static dyn ModelFamily> {
    let name = name::<ModelName>("model", Some(model))?.expect("given");
    scatterfit_mc::family(name).map_err(|e| errors::bad_input(&e))
}

/// A contiguous view of a 1-D array.
fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, what: &str) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| errors::input(format!("{what}: not a contiguous array")))
}

/// Rd(r) \[mm⁻²\] of the model at each element (private: `scatterfit.models.profile`).
#[pyfunction]
#[pyo3(signature = (r_mm, sigma_s_prime, sigma_a, eta, g, *, model, spot_diameter_mm=None))]
pub(crate) fn profile<'py>(
    py: Python<'py>,
    r_mm: PyReadonlyArray1<'py, f64>,
    sigma_s_prime: PyReadonlyArray1<'py, f64>,
    sigma_a: PyReadonlyArray1<'py, f64>,
    eta: PyReadonlyArray1<'py, f64>,
    g: PyReadonlyArray1<'py, f64>,
    model: &str,
    spot_diameter_mm: Option<f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let family = family(model)?;
    let (r, s, a, n, gs) = (
        slice(&r_mm, "r_mm")?,
        slice(&sigma_s_prime, "sigma_s_prime")?,
        slice(&sigma_a, "sigma_a")?,
        slice(&eta, "eta")?,
        slice(&g, "g")?,
    );
    if let Some(bad) = r.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(errors::input(format!(
            "r_mm: {bad} is not a radius (finite, ≥ 0 mm)"
        )));
    }
    let spot = match spot_diameter_mm {
        None => Spot::Point,
        Some(d) if d > 0.0 && d <= 20.0 => Spot::Disk { radius_mm: 0.5 * d },
        Some(d) => {
            return Err(errors::input(format!(
                "spot_diameter_mm={d}: must lie in (0, 20] mm (or None for a point of incidence)"
            )));
        }
    };
    let values = py
        .detach(|| -> Result<Vec<f64>, String> {
            let mut out = vec![0.0; r.len()];
            let mut start = 0;
            while start < r.len() {
                // A run of elements with the same material.
                let same = |k: usize| {
                    s[k] == s[start] && a[k] == a[start] && n[k] == n[start] && gs[k] == gs[start]
                };
                let mut end = start + 1;
                while end < r.len() && same(end) {
                    end += 1;
                }
                let props = material(s[start], a[start], n[start], gs[start])
                    .map_err(|e| format!("element {start}: {e}"))?;
                family
                    .profile(&props)
                    .map_err(|e| format!("element {start}: {e}"))?;
                let v = model_profile(family, &props, spot, &r[start..end])
                    .map_err(|e| format!("element {start}: {e}"))?;
                out[start..end].copy_from_slice(&v);
                start = end;
            }
            Ok(out)
        })
        .map_err(errors::input)?;
    Ok(values.into_pyarray(py))
}

/// σ′s, σa, η and g as the models take them.
fn material(
    sigma_s_prime: f64,
    sigma_a: f64,
    eta: f64,
    g: f64,
) -> scatterfit_optics::Result<OpticalProperties> {
    OpticalProperties::new(sigma_s_prime, sigma_a, eta)?.with_g(g)
}

/// Applies `f(x, η, g)` elementwise with the GIL released; an error names the element.
fn elementwise<'py>(
    py: Python<'py>,
    x: &[f64],
    eta: &[f64],
    g: &[f64],
    f: impl Fn(f64, f64, f64) -> scatterfit_optics::Result<f64> + Send + Sync,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let out = py
        .detach(|| {
            x.iter()
                .zip(eta)
                .zip(g)
                .enumerate()
                .map(|(k, ((&x, &eta), &g))| f(x, eta, g).map_err(|e| format!("element {k}: {e}")))
                .collect::<Result<Vec<f64>, String>>()
        })
        .map_err(errors::input)?;
    Ok(out.into_pyarray(py))
}

/// Total diffuse reflectance Rd(α′, η, g) of the model (private: `scatterfit.models.rd_total`).
#[pyfunction]
#[pyo3(signature = (albedo_prime, eta, g, *, model))]
pub(crate) fn rd_total<'py>(
    py: Python<'py>,
    albedo_prime: PyReadonlyArray1<'py, f64>,
    eta: PyReadonlyArray1<'py, f64>,
    g: PyReadonlyArray1<'py, f64>,
    model: &str,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let family = family(model)?;
    elementwise(
        py,
        slice(&albedo_prime, "albedo_prime")?,
        slice(&eta, "eta")?,
        slice(&g, "g")?,
        |a, eta, g| family.rd_total(a, eta, g),
    )
}

/// The reduced albedo α′ whose total Rd is `rd` (private: `scatterfit.models.albedo_from_rd`).
#[pyfunction]
#[pyo3(signature = (rd, eta, g, *, model))]
pub(crate) fn albedo_from_rd<'py>(
    py: Python<'py>,
    rd: PyReadonlyArray1<'py, f64>,
    eta: PyReadonlyArray1<'py, f64>,
    g: PyReadonlyArray1<'py, f64>,
    model: &str,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let family = family(model)?;
    elementwise(
        py,
        slice(&rd, "rd")?,
        slice(&eta, "eta")?,
        slice(&g, "g")?,
        |rd, eta, g| family.albedo_from_rd(rd, eta, g),
    )
}

/// Three channels' rings from (n,) radii and (n, 3) values, standard errors and pixel counts.
fn rings(
    r_mm: &[f64],
    value: &PyReadonlyArray2<'_, f64>,
    stderr: &PyReadonlyArray2<'_, f64>,
    count: Option<&PyReadonlyArray2<'_, f64>>,
    limit: Option<&PyReadonlyArray2<'_, f64>>,
) -> PyResult<Rgb<ProfileData>> {
    let n = r_mm.len();
    let (v, e) = (value.as_array(), stderr.as_array());
    for (what, shape) in [("value", v.shape()), ("stderr", e.shape())] {
        if shape != [n, 3] {
            return Err(errors::input(format!(
                "{what}: shape {shape:?}, expected ({n}, 3): one column per channel R, G, B, one \
                 row per radius"
            )));
        }
    }
    let c = count.map(|c| c.as_array());
    let l = limit.map(|l| l.as_array());
    for (what, shape) in [
        ("count", c.as_ref().map(|c| c.shape())),
        ("limit", l.as_ref().map(|l| l.shape())),
    ] {
        if let Some(shape) = shape
            && shape != [n, 3]
        {
            return Err(errors::input(format!(
                "{what}: shape {shape:?}, expected ({n}, 3)"
            )));
        }
    }
    Rgb::from_fn(|ch| {
        let k = ch.index();
        let rings = (0..n)
            .map(|i| Ring {
                r_mm: r_mm[i],
                value: v[[i, k]],
                stderr: e[[i, k]],
                // Without counts every ring counts as one measured point.
                count: c.as_ref().map_or(1, |c| c[[i, k]].max(0.0) as u64),
                detection_limit: l.as_ref().map_or(f64::NAN, |l| l[[i, k]]),
            })
            .collect();
        ProfileData::new(rings)
    })
    .transpose()
    .map_err(|e| errors::bad_input(&e))
}

/// Fits a profile given as arrays (private: `scatterfit.fit_profile`); the result as
/// `result.json`'s text.
#[pyfunction]
#[pyo3(signature = (r_mm, value, stderr, *, eta, albedo=None, rd=None, count=None, limit=None,
    method="proposed", model="mc", g=None, g_range=None, spot_diameter_mm=1.0, r_min_mm=None,
    normalise_with_spectro=false, name="profile"))]
pub(crate) fn fit_profile<'py>(
    py: Python<'py>,
    r_mm: PyReadonlyArray1<'py, f64>,
    value: PyReadonlyArray2<'py, f64>,
    stderr: PyReadonlyArray2<'py, f64>,
    eta: f64,
    albedo: Option<[f64; 3]>,
    rd: Option<[f64; 3]>,
    count: Option<PyReadonlyArray2<'py, f64>>,
    limit: Option<PyReadonlyArray2<'py, f64>>,
    method: &str,
    model: &str,
    g: Option<Bound<'py, PyAny>>,
    g_range: Option<(f64, f64)>,
    spot_diameter_mm: f64,
    r_min_mm: Option<f64>,
    normalise_with_spectro: bool,
    name: &str,
) -> PyResult<(String, bool)> {
    let profile = rings(
        slice(&r_mm, "r_mm")?,
        &value,
        &stderr,
        count.as_ref(),
        limit.as_ref(),
    )?;
    let request = ProfileFitRequest {
        name: name.to_owned(),
        profile_file: None,
        eta,
        albedo_prime: albedo.map(Rgb::from_array),
        rd: rd.map(Rgb::from_array),
        method: crate::options::name::<Method>("method", Some(method))?.expect("given"),
        model: crate::options::name::<ModelName>("model", Some(model))?.expect("given"),
        spot_diameter_mm,
        r_min_mm,
        normalise_with_spectro,
        g_prior: g_prior(g.as_ref(), g_range)?.unwrap_or_default(),
    };
    let fitted = py
        .detach(|| fit(&profile, &request))
        .map_err(|e| errors::pipeline(&e))?;
    let json = serde_json::to_string(&fitted.to_result()).map_err(|e| errors::bad_input(&e))?;
    Ok((json, fitted.complete()))
}
