//! What the g stage gives a fitted channel: its g term ([`GTerm`]) and, with `g = "fit"`, its fit
//! of g ([`GFit`]).

use scatterfit_fit::FitReport;
use scatterfit_io::result_json::GFitRecord;
use serde::Serialize;

/// How α′ follows g in the term.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AlbedoAtG {
    /// Inverted from the reading's Rd at each g (a measurement with a spectrophotometer, or
    /// `fit --rd`).
    FromRd,
    /// Held at the given α′ (`fit --albedo` without `--rd`: the term then holds the profile's
    /// dependence on g only).
    Fixed,
}

/// One channel's g term.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GTerm {
    /// The term of σ′s \[mm⁻¹\].
    pub sigma_s_prime: f64,
    /// The term of σa \[mm⁻¹\].
    pub sigma_a: f64,
    /// The term of α′.
    pub albedo_prime: f64,
    /// The middle (max + min)/2 of σ′s, σa, α′ over the points: the values, for a range without a
    /// g when the value's model is the g-aware `mc` ([`GTerm::centre_applies`]).
    pub centre: [f64; 3],
    /// Whether [`GTerm::centre`] replaces the values.
    pub centre_applies: bool,
    /// The g the estimates were computed at (the plan's points where the fits succeeded).
    pub evaluated: Vec<f64>,
    /// What the user should know: points where the estimate could not be computed.
    pub note: Option<String>,
}
/// One channel's fit of g.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GFit {
    /// The g of χ²'s minimum (given out only when [`GFit::determined`]).
    pub g: f64,
    /// sd(g), the fit's and the model's parts in quadrature.
    pub stderr: f64,
    /// The fit's part (curvature of χ², scaled by the reduced χ²).
    pub stderr_fit: f64,
    /// The model's part (0.05·δ/S, δ the fit's misfit beyond the rings' noise, at least 0.3 %).
    pub stderr_model: f64,
    /// The spectrophotometer's part (the minimum's shift with the reading at ± its error).
    pub stderr_spectro: f64,
    /// corr(σ′s, g) in the joint covariance.
    pub corr_sigma_s_prime: f64,
    /// S: the RMS shape change (ln) of Δg = 0.05 after refitting the other unknowns.
    pub shape_change: f64,
    /// The g searched: the first and last scan point the tables answered.
    pub searched: [f64; 2],
    /// χ²(g) over the scan, (g, χ²).
    pub scan: Vec<(f64, f64)>,
    /// Whether the data determine g (module docs).
    pub determined: bool,
    /// Why not, when not.
    pub reason: Option<String>,
    /// The channel's fit at ĝ (values, standard errors, residuals).
    #[serde(skip)]
    pub report: Option<FitReport>,
    /// α′, σ′s, σa at ĝ − sd(g) and ĝ + sd(g) (clamped to the searched range): the g term.
    #[serde(skip)]
    pub term: Option<[f64; 3]>,
}

impl GFit {
    /// The result file's record: g and its errors only where determined.
    pub fn record(&self) -> GFitRecord {
        let d = self.determined;
        GFitRecord {
            determined: d,
            g: d.then_some(self.g),
            g_stderr: d.then_some(self.stderr),
            g_stderr_fit: d.then_some(self.stderr_fit),
            g_stderr_model: d.then_some(self.stderr_model),
            g_stderr_spectro: d.then_some(self.stderr_spectro),
            corr_sigma_s_prime_g: d
                .then_some(self.corr_sigma_s_prime)
                .filter(|c| c.is_finite()),
            shape_change: self.shape_change.is_finite().then_some(self.shape_change),
            searched: Some(self.searched),
            reason: self.reason.clone(),
        }
    }
}
