//! scatterfit-fit: the inverse problem — σ′s and σa from a measured radial profile.
//!
//! Choi, Lee & Chin (2014) fit the dipole diffusion profile of Jensen et al. (2001) to the radial
//! profile Rd(r) of a light spot on the sample by Levenberg–Marquardt. Two methods:
//! - **proposed** (the paper, §3.2, eq. 2): the spectrophotometer's reduced albedo α′ fixes
//!   σa = σ′s(1/α′ − 1), leaving σ′s and the profile's scale k (the HDR profile is relative; the
//!   light's and the camera's gain per channel are unknown) — or σ′s alone with
//!   [`FitOptions::normalise_with_spectro`];
//! - **existing** (Jensen et al. 2001): σ′s, σa and k from the profile alone, η given.
//!
//! Residuals are logarithmic and weighted by each ring's relative standard error; unknowns are
//! logarithms (so coefficients stay positive); the Jacobian is analytic (`problem.rs` documents the
//! equations). The light spot is a disk, not a point: by default the model is convolved with it
//! ([`spot`]) and rings inside one spot diameter are skipped ([`RingSelection::for_spot`]). Rings
//! below the bracket's detection limit are excluded and counted ([`profile`]).
//!
//! The outcome is a [`FitReport`], not an error: parameters with standard errors (from the Jacobian
//! at the solution, scaled by the reduced χ² when the model misfits), their correlations, which
//! parameters the data do not constrain, iterations, the termination reason, the fit time and the
//! residual MSE of the paper's Table 2.
//!
//! ```
//! use scatterfit_fit::{ChannelInput, FitOptions, Method, ProfileData, Ring, Spot, fit_channel};
//! use scatterfit_optics::{DiffusionModel, OpticalProperties, dipole::Dipole};
//! // A profile with no noise from a known dipole (σ′s = 1.2, σa = 0.03 mm⁻¹, η = 1.3), scale 5.
//! let truth = OpticalProperties::new(1.2, 0.03, 1.3)?;
//! let d = Dipole::new(&truth);
//! let rings = (1..200).map(|i| { let r = 0.05 * i as f64;
//!     Ring { r_mm: r, value: 5.0 * d.rd(r), stderr: 0.01 * 5.0 * d.rd(r), count: 100, detection_limit: 0.0 } })
//!     .collect();
//! let mut opts = FitOptions::new(Method::Proposed);
//! opts.spot = Spot::Point;
//! opts.selection = opts.selection.with_r_min_mm(0.5)?;
//! let input = ChannelInput { eta: 1.3, albedo_prime: Some(truth.albedo_prime()), rd_total: None };
//! let report = fit_channel(&ProfileData::new(rings)?, &input, &DiffusionModel::Dipole, &opts)?;
//! assert!((report.sigma_s_prime.value / 1.2 - 1.0).abs() < 1e-6);
//! assert!((report.scale.value / 5.0 - 1.0).abs() < 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![forbid(unsafe_code)]

mod error;
pub mod model;
mod problem;
pub mod profile;
pub mod radial_spot;
pub mod spot;

use std::time::Instant;

use levenberg_marquardt::{LevenbergMarquardt, TerminationReason};
use nalgebra::DMatrix;
use scatterfit_optics::Termination;
use serde::{Deserialize, Serialize};

pub use error::{FitError, Result};
pub use model::{Spot, model_profile, model_profiles, node_spacing};
pub use profile::{ProfileData, Ring, RingSelection, Selected, select_rings};
pub use radial_spot::RadialSpot;
pub use spot::SpotKernel;

use error::check;
use problem::{Data, Forward, Problem, Unknowns};

/// Which unknowns are fitted (the vocabulary's [`Method`], re-exported): `Proposed` — Choi, Lee &
/// Chin 2014, α′ from the spectrophotometer, unknowns σ′s and the scale k; `Existing` — Jensen et al.
/// 2001, unknowns σ′s, σa and k.
pub use scatterfit_optics::{Method, Parameter};
/// The forward model's family and name (re-exported from `scatterfit_optics`).
pub use scatterfit_optics::{ModelFamily, ModelName};

/// A user-given starting point (replaces the automatic start).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Start {
    /// σ′s [mm⁻¹].
    pub sigma_s_prime: f64,
    /// σa [mm⁻¹] (existing method; ignored by the proposed one). Default: from α′ = 0.99.
    pub sigma_a: Option<f64>,
    /// The scale k. Default: the best k for the starting shape.
    pub scale: Option<f64>,
}

/// How to fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// The unknowns.
    pub method: Method,
    /// The light spot (default: a disk of radius 0.5 mm, the paper's spot "under 1 mm").
    pub spot: Spot,
    /// Which rings to fit.
    pub selection: RingSelection,
    /// Proposed method only: fix k by the spectrophotometer instead of fitting it.
    pub normalise_with_spectro: bool,
    /// A starting point, or `None` for the automatic one.
    pub start: Option<Start>,
    /// Most residual evaluations per unknown (the LM crate's "patience").
    pub patience: usize,
}

/// A parameter whose logarithm has a standard error above this (a factor 1.5 either way) is
/// reported as not constrained by the data.
pub const UNCONSTRAINED_SD_LN: f64 = 0.4;

/// The paper's spot: "a point less than 1 mm in diameter" (§3.1); we take a 1 mm disk.
pub const DEFAULT_SPOT_RADIUS_MM: f64 = 0.5;

impl FitOptions {
    /// Defaults for `method`: a disk spot of radius [`DEFAULT_SPOT_RADIUS_MM`] convolved into the
    /// model, rings from one spot diameter out, fitted scale, automatic start.
    pub fn new(method: Method) -> Self {
        Self {
            method,
            spot: Spot::Disk {
                radius_mm: DEFAULT_SPOT_RADIUS_MM,
            },
            selection: RingSelection::DEFAULT,
            normalise_with_spectro: false,
            start: None,
            patience: 100,
        }
    }
}

/// What the fit of one channel knows besides the profile.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ChannelInput {
    /// Relative refractive index η (from the spectrophotometer or given).
    pub eta: f64,
    /// Reduced albedo α′ from the spectrophotometer (required by the proposed method).
    pub albedo_prime: Option<f64>,
    /// The spectrophotometer's total diffuse reflectance Rd (required by
    /// [`FitOptions::normalise_with_spectro`]; informational otherwise).
    pub rd_total: Option<f64>,
}

/// A fitted quantity and its standard error from the fit alone (the pipeline makes it the `fit`
/// term of a `scatterfit_optics::Estimate`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FittedValue {
    /// The value.
    pub value: f64,
    /// Its standard error (NaN when the data do not constrain it).
    pub stderr: f64,
}

/// One fitted ring: data and model in the profile's units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FittedRing {
    /// Index of the ring in the profile.
    pub index: usize,
    /// Radius \[mm\].
    pub r_mm: f64,
    /// Measured value \[relative\].
    pub measured: f64,
    /// Model × scale at the solution \[relative\].
    pub model: f64,
    /// Standard deviation of ln(measured) used as the weight.
    pub sigma_ln: f64,
    /// Pixels the ring averages (0 in a report written before it was recorded).
    #[serde(default)]
    pub count: u64,
}

/// The outcome of one channel's fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitReport {
    /// The method.
    pub method: Method,
    /// The forward model.
    pub model: ModelName,
    /// η used.
    pub eta: f64,
    /// σ′s [mm⁻¹].
    pub sigma_s_prime: FittedValue,
    /// σa [mm⁻¹] (proposed: σ′s(1/α′ − 1), its error from σ′s's alone).
    pub sigma_a: FittedValue,
    /// α′ = σ′s/(σ′s + σa): the spectrophotometer's (proposed) or the fitted (existing).
    pub albedo_prime: f64,
    /// The scale k: measured = k · model [relative units per mm⁻²].
    pub scale: FittedValue,
    /// The free parameters, in the order of `correlation`.
    pub parameters: Vec<Parameter>,
    /// Correlation matrix of the free parameters (rows of `parameters.len()`).
    pub correlation: Vec<Vec<f64>>,
    /// Parameters the data do not constrain (standard error of the logarithm above
    /// [`UNCONSTRAINED_SD_LN`], or a singular Jacobian): the values are the solver's end point, not measurements.
    pub unconstrained: Vec<Parameter>,
    /// Whether the solver met a convergence criterion.
    pub converged: bool,
    /// Why the solver stopped.
    pub termination: Termination,
    /// Residual evaluations.
    pub evaluations: usize,
    /// Wall time of the start search and the solver \[s\].
    pub fit_time_s: f64,
    /// Wall time of the preparation (ring selection, spot kernel) \[s\].
    pub prepare_time_s: f64,
    /// Mean of (measured/k − model)² over the fitted rings [mm⁻⁴] (Choi et al. 2014, Table 2).
    pub mse: f64,
    /// Root mean square of ln(measured/(k·model)) over the fitted rings.
    pub rms_log_residual: f64,
    /// The same over the fitted rings' pixels: each ring's squared log residual weighted by the
    /// pixels it averages, √(Σ nᵢ eᵢ² / Σ nᵢ). A ring of one pixel at the frame's corner counts
    /// once, a ring of 700 pixels 700 times, so how far the profile lies from the model is judged
    /// by what the rings hold, not by how many rings there are. NaN when not recorded.
    #[serde(default = "not_recorded")]
    pub pixel_rms_log_residual: f64,
    /// χ² of the weighted log residuals per degree of freedom.
    pub chi2_reduced: f64,
    /// Rings fitted.
    pub rings_used: usize,
    /// Rings inside the spot (r < r_min), not fitted.
    pub rings_inside_spot: usize,
    /// Rings below the detection limit, not fitted.
    pub rings_below_detection: usize,
    /// Rings with no valid value, or beyond r_max, not fitted.
    pub rings_invalid: usize,
    /// The fitted rings with the model at the solution.
    pub fitted: Vec<FittedRing>,
}

fn not_recorded() -> f64 {
    f64::NAN
}

impl FitReport {
    /// True when the solver converged and every parameter is constrained.
    pub fn is_measurement(&self) -> bool {
        self.converged && self.unconstrained.is_empty()
    }
}

/// A fit made ready: rings selected and the spot kernel built. Solving it is the part whose speed
/// matters (it runs per channel, per method); preparing is per profile geometry.
pub struct PreparedFit<'a> {
    model: &'a dyn ModelFamily,
    input: ChannelInput,
    opts: FitOptions,
    selected: Selected,
    ln_y: Vec<f64>,
    w: Vec<f64>,
    area: Vec<f64>,
    kernel: Option<SpotKernel>,
    unknowns: Unknowns,
    prepare_time_s: f64,
}

impl<'a> PreparedFit<'a> {
    /// Selects the rings and builds the spot kernel.
    ///
    /// # Errors
    /// [`FitError::InvalidInput`] for a bad η, α′, Rd or option; [`FitError::TooFewRings`] when the
    /// selection leaves fewer rings than unknowns + 2.
    pub fn new(
        profile: &ProfileData,
        input: &ChannelInput,
        model: &'a dyn ModelFamily,
        opts: &FitOptions,
    ) -> Result<Self> {
        let t0 = Instant::now();
        let unknowns = unknowns_for(input, opts)?;
        let selected = select_rings(profile, &opts.selection)?;
        let needed = unknowns.count() + 2;
        if selected.r_mm.len() < needed {
            return Err(FitError::TooFewRings {
                usable: selected.r_mm.len(),
                needed,
                unknowns: unknowns.count(),
                inside_spot: selected.inside_spot,
                below_detection: selected.below_detection,
                invalid: selected.invalid,
                hint: "the signal lies (almost) only inside the light spot or under the noise floor; \
                       take longer exposures, a smaller spot, or a finer image scale",
            });
        }
        let ln_y: Vec<f64> = selected.value.iter().map(|v| v.ln()).collect();
        let w: Vec<f64> = selected.sigma_ln.iter().map(|s| 1.0 / s).collect();
        let area = ring_areas(&selected.r_mm);
        let unknowns = match unknowns {
            Unknowns::Normalised { c, .. } => Unknowns::Normalised {
                c,
                flux: selected.value.iter().zip(&area).map(|(y, a)| y * a).sum(),
            },
            u => u,
        };
        let kernel = model::spot_kernel(opts.spot, &selected.r_mm)?;
        Ok(Self {
            model,
            input: *input,
            opts: *opts,
            selected,
            ln_y,
            w,
            area,
            kernel,
            unknowns,
            prepare_time_s: t0.elapsed().as_secs_f64(),
        })
    }

    /// The same prepared rings and spot kernel for another input (η, α′, Rd) and start: a refit at
    /// perturbed spectrophotometer values costs the solve only, not the kernel's construction
    /// (`pipeline::fit::propagate_spectro`).
    ///
    /// # Errors
    /// As [`PreparedFit::new`] for a bad η, α′ or Rd.
    pub fn with_input(&self, input: &ChannelInput, start: Option<Start>) -> Result<Self> {
        let unknowns = match (unknowns_for(input, &self.opts)?, self.unknowns) {
            (Unknowns::Normalised { c, .. }, Unknowns::Normalised { flux, .. }) => {
                Unknowns::Normalised { c, flux }
            }
            (u, _) => u,
        };
        Ok(Self {
            model: self.model,
            input: *input,
            opts: FitOptions { start, ..self.opts },
            selected: self.selected.clone(),
            ln_y: self.ln_y.clone(),
            w: self.w.clone(),
            area: self.area.clone(),
            kernel: self.kernel.clone(),
            unknowns,
            prepare_time_s: 0.0,
        })
    }

    /// The selected rings.
    pub fn selected(&self) -> &Selected {
        &self.selected
    }

    /// Runs the start search and Levenberg–Marquardt, and reports.
    pub fn solve(&self) -> FitReport {
        let t0 = Instant::now();
        let data = Data {
            r: &self.selected.r_mm,
            ln_y: &self.ln_y,
            w: &self.w,
            area: &self.area,
        };
        let forward = Forward {
            model: self.model,
            eta: self.input.eta,
            kernel: self.kernel.as_ref(),
        };
        // Proposed: one start (the user's, else the automatic one). Existing: the user's start
        // (if any) and every automatic basin; the lowest objective wins.
        let mut starts = Vec::new();
        if let Some(s) = self.opts.start {
            starts.push(self.user_start(&s));
        }
        if starts.is_empty() || self.unknowns == Unknowns::Existing {
            starts.extend(problem::start(&data, &forward, self.unknowns));
        }
        if starts.is_empty() {
            // The search found no shape the model can evaluate (the model's range does not meet
            // the data): start from σ′s = 1 mm⁻¹, α′ = 0.99; the solver then reports why it fails.
            starts.push(problem::solver_x(self.unknowns, 1.0, 1.0 / 0.99 - 1.0));
        }
        let lm = LevenbergMarquardt::new()
            .with_ftol(1e-10)
            .with_xtol(1e-10)
            .with_gtol(1e-12)
            .with_patience(self.opts.patience);
        let mut best: Option<(Problem<'_>, levenberg_marquardt::MinimizationReport<f64>)> = None;
        let mut evaluations = 0;
        for x0 in &starts {
            let (problem, report) = lm.minimize(Problem::new(data, forward, self.unknowns, x0));
            evaluations += report.number_of_evaluations;
            let better = best.as_ref().is_none_or(|(bp, br)| {
                (problem.valid && !bp.valid)
                    || (problem.valid == bp.valid
                        && report.objective_function < br.objective_function)
            });
            if better {
                best = Some((problem, report));
            }
        }
        let (problem, report) = best.expect("at least one start");
        let fit_time_s = t0.elapsed().as_secs_f64();
        self.report(&problem, &report.termination, evaluations, fit_time_s)
    }

    /// x₀ from a user's start: σ′s (and σa for the existing method) as given; σa defaults to
    /// α′ = 0.99. (The scale is projected out; a given one is not needed.)
    fn user_start(&self, s: &Start) -> Vec<f64> {
        let sp = s.sigma_s_prime.max(problem::COEFF_RANGE.0);
        let sa = match self.unknowns {
            Unknowns::Existing => s
                .sigma_a
                .unwrap_or(sp * (1.0 / 0.99 - 1.0))
                .max(problem::COEFF_RANGE.0),
            Unknowns::Proposed { c } | Unknowns::Normalised { c, .. } => c * sp,
        };
        problem::solver_x(self.unknowns, sp, sa)
    }

    fn report(
        &self,
        problem: &Problem<'_>,
        termination: &TerminationReason,
        evaluations: usize,
        fit_time_s: f64,
    ) -> FitReport {
        let phys = problem::physical(self.unknowns, problem.params_slice());
        let (sp, sa) = (phys.sigma_s_prime, phys.sigma_a);
        let ln_k = problem.ln_k;
        let k = ln_k.exp();
        let n = self.selected.r_mm.len();
        let p = self.unknowns.count();
        let res = problem.residual_vector();
        let chi2: f64 = res.iter().map(|e| e * e).sum();
        let dof = (n - p).max(1) as f64;
        let chi2_reduced = chi2 / dof;
        let names: Vec<Parameter> = match self.unknowns {
            Unknowns::Proposed { .. } => vec![Parameter::SigmaSPrime, Parameter::Scale],
            Unknowns::Normalised { .. } => vec![Parameter::SigmaSPrime],
            Unknowns::Existing => vec![Parameter::SigmaSPrime, Parameter::SigmaA, Parameter::Scale],
        };
        // Covariance of the full problem's unknowns (x, ln k): (JᵀJ)⁻¹, inflated by the reduced
        // χ² when the model misfits (the ring errors then understate the scatter), never
        // deflated; then mapped to the logarithms of the reported parameters
        // y = (ln σ′s[, ln σa], ln k): C_y = T C Tᵀ with T = ∂y/∂(x, ln k).
        let jtj = problem.full_jtj();
        let t = match self.unknowns {
            Unknowns::Existing => {
                let [c0, c1] = phys.chain;
                DMatrix::from_row_slice(
                    3,
                    3,
                    &[
                        c0[0] / sp,
                        c1[0] / sp,
                        0.0,
                        c0[1] / sa,
                        c1[1] / sa,
                        0.0,
                        0.0,
                        0.0,
                        1.0,
                    ],
                )
            }
            _ => DMatrix::identity(p, p),
        };
        let cov = if problem.valid {
            jtj.cholesky()
                .map(|c| &t * c.inverse() * t.transpose() * chi2_reduced.max(1.0))
        } else {
            None
        };
        let mut unconstrained = Vec::new();
        let (mut sd, mut corr) = (vec![f64::NAN; p], vec![vec![f64::NAN; p]; p]);
        match &cov {
            Some(c) => {
                for a in 0..p {
                    sd[a] = c[(a, a)].max(0.0).sqrt();
                    for b in 0..p {
                        corr[a][b] = c[(a, b)] / (c[(a, a)] * c[(b, b)]).sqrt();
                    }
                }
            }
            None => unconstrained.extend(names.iter().filter(|n| **n != Parameter::Scale)),
        }
        if cov.is_some() {
            // NaN (a negative variance) counts as unconstrained too.
            if sd[0].is_nan() || sd[0] > UNCONSTRAINED_SD_LN {
                unconstrained.push(Parameter::SigmaSPrime);
            }
            if self.unknowns == Unknowns::Existing
                && (sd[1].is_nan() || sd[1] > UNCONSTRAINED_SD_LN)
            {
                unconstrained.push(Parameter::SigmaA);
            }
        }
        let (sp_err, sa_err, k_err) = match self.unknowns {
            Unknowns::Proposed { c } => (sp * sd[0], c * sp * sd[0], k * sd[1]),
            Unknowns::Normalised { c, .. } => {
                // ln k moves with ln σ′s through the flux constraint.
                let dlnk = problem.dlnk_dx0();
                (sp * sd[0], c * sp * sd[0], k * dlnk.abs() * sd[0])
            }
            Unknowns::Existing => (sp * sd[0], sa * sd[1], k * sd[2]),
        };
        let m = problem.model_values();
        let model_at = |i: usize| if m.len() == n { m[i] } else { f64::NAN };
        let mut fitted = Vec::with_capacity(n);
        let mut mse = 0.0;
        let inv_k = 1.0 / k;
        for i in 0..n {
            let (y, model) = (self.selected.value[i], model_at(i));
            mse += (y * inv_k - model).powi(2);
            fitted.push(FittedRing {
                index: self.selected.index[i],
                r_mm: self.selected.r_mm[i],
                measured: y,
                model: k * model,
                sigma_ln: self.selected.sigma_ln[i],
                count: self.selected.count[i],
            });
        }
        // ln(k m) − ln y = eᵢ/wᵢ, the residual without its weight (no logarithms to take again).
        let (msl, pixel_msl) = if problem.valid && res.len() == n {
            let (mut sum, mut weighted, mut pixels) = (0.0, 0.0, 0.0);
            for ((e, w), &count) in res.iter().zip(&self.w).zip(&self.selected.count) {
                let e2 = (e / w).powi(2);
                sum += e2;
                weighted += count as f64 * e2;
                pixels += count as f64;
            }
            (sum, weighted / pixels)
        } else {
            (f64::NAN, f64::NAN)
        };
        let converged = termination.was_successful() && problem.valid;
        FitReport {
            method: self.opts.method,
            model: self.model.name(),
            eta: self.input.eta,
            sigma_s_prime: FittedValue {
                value: sp,
                stderr: sp_err,
            },
            sigma_a: FittedValue {
                value: sa,
                stderr: sa_err,
            },
            albedo_prime: sp / (sp + sa),
            scale: FittedValue {
                value: k,
                stderr: k_err,
            },
            parameters: names,
            correlation: corr,
            unconstrained,
            converged,
            termination: if termination.was_successful() && !problem.valid {
                // The solver's own criterion was met, but on a model that answered non-finite
                // values: not a convergence (the message said "did not converge: converged (…)").
                Termination::NonFiniteModel
            } else {
                termination_of(termination)
            },
            evaluations,
            fit_time_s,
            prepare_time_s: self.prepare_time_s,
            mse: mse / n as f64,
            rms_log_residual: (msl / n as f64).sqrt(),
            pixel_rms_log_residual: pixel_msl.sqrt(),
            chi2_reduced,
            rings_used: n,
            rings_inside_spot: self.selected.inside_spot,
            rings_below_detection: self.selected.below_detection,
            rings_invalid: self.selected.invalid,
            fitted,
        }
    }
}

/// The unknowns for `input` and `opts`, after checking η, α′ (proposed) and Rd (normalised); the
/// normalised method's flux is left 0 for the caller to fill in from the rings.
fn unknowns_for(input: &ChannelInput, opts: &FitOptions) -> Result<Unknowns> {
    check(
        input.eta.is_finite() && input.eta >= 1.0,
        "eta",
        input.eta,
        "the relative refractive index must be finite and ≥ 1",
    )?;
    let unknowns = match opts.method {
        Method::Existing => Unknowns::Existing,
        Method::Proposed => {
            let a = input.albedo_prime.unwrap_or(f64::NAN);
            check(
                a > 0.0 && a <= 1.0,
                "albedo_prime",
                a,
                "the proposed method needs the spectrophotometer's reduced albedo α′ in (0, 1]",
            )?;
            let c = 1.0 / a - 1.0;
            if opts.normalise_with_spectro {
                // The caller fills in the flux once the rings are known.
                Unknowns::Normalised { c, flux: 0.0 }
            } else {
                Unknowns::Proposed { c }
            }
        }
    };
    if opts.normalise_with_spectro {
        check(
            opts.method == Method::Proposed,
            "normalise_with_spectro",
            1.0,
            "applies to the proposed method only (the existing method has no α′)",
        )?;
        let rd = input.rd_total.unwrap_or(f64::NAN);
        check(
            rd > 0.0 && rd <= 1.0,
            "rd_total",
            rd,
            "normalising with the spectrophotometer needs its diffuse reflectance Rd in (0, 1]",
        )?;
    }
    Ok(unknowns)
}

/// Fits one channel: [`PreparedFit::new`] then [`PreparedFit::solve`].
///
/// # Errors
/// As [`PreparedFit::new`]. A fit that runs but does not converge is a report with
/// `converged = false`, not an error.
pub fn fit_channel(
    profile: &ProfileData,
    input: &ChannelInput,
    model: &dyn ModelFamily,
    opts: &FitOptions,
) -> Result<FitReport> {
    Ok(PreparedFit::new(profile, input, model, opts)?.solve())
}

/// Ring areas 2πrΔr [mm²] from the ring radii (Δr from the midpoints to the neighbours).
fn ring_areas(r: &[f64]) -> Vec<f64> {
    let n = r.len();
    (0..n)
        .map(|i| {
            let lo = if i == 0 {
                r[0] - 0.5 * r.get(1).map_or(0.0, |x| x - r[0])
            } else {
                0.5 * (r[i - 1] + r[i])
            };
            let hi = if i + 1 == n {
                r[i] + 0.5 * (r[i] - r[i.saturating_sub(1)])
            } else {
                0.5 * (r[i] + r[i + 1])
            };
            std::f64::consts::PI * (hi * hi - lo.max(0.0).powi(2))
        })
        .collect()
}

/// The solver's reason as the report names it.
fn termination_of(t: &TerminationReason) -> Termination {
    match t {
        TerminationReason::Converged { ftol, xtol } => match (ftol, xtol) {
            (true, true) => Termination::ConvergedResidualAndStep,
            (true, false) => Termination::ConvergedResidual,
            _ => Termination::ConvergedStep,
        },
        TerminationReason::Orthogonal => Termination::ConvergedOrthogonal,
        TerminationReason::ResidualsZero => Termination::ConvergedResidualsZero,
        TerminationReason::LostPatience => Termination::EvaluationLimit,
        TerminationReason::Numerical(_) => Termination::NonFinite,
        TerminationReason::NoImprovementPossible(_) => Termination::NoImprovement,
        other => Termination::Other(format!("stopped: {other:?}")),
    }
}
