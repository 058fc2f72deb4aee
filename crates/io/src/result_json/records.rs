//! The result's sample-level records beside the channels: how g entered it ([`GUncertainty`]),
//! what the spectrophotometer port correction did ([`PortResult`]) and the measured
//! diffuse reflectance spectrum ([`RdSpectrum`]).

use serde::{Deserialize, Serialize};

/// Where the result's knowledge of g came from ([`GUncertainty::source`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GSource {
    /// `[fit] g` (or `--g`) without a range: g is known, the g term is 0.
    Given,
    /// `[fit] g_range` (or `--g-range`): the stated range, with or without a g.
    Range,
    /// Neither: the values at g = 0 (the paper's isotropic assumption), the term over the default
    /// range 0–0.95.
    DefaultRange,
    /// `[fit] g = "fit"` (or `--g fit`): g fitted per channel from the profile
    /// ([`GUncertainty::fitted`]); where the data do not determine it, the range's term.
    Fit,
}

impl GSource {
    /// The name in the file: `given`, `range`, `default_range`.
    pub fn name(self) -> &'static str {
        match self {
            GSource::Given => "given",
            GSource::Range => "range",
            GSource::DefaultRange => "default_range",
            GSource::Fit => "fit",
        }
    }
}

/// How g entered a result
/// ([`MeasurementResult::g_uncertainty`](super::MeasurementResult::g_uncertainty)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GUncertainty {
    /// Given, a stated range, or the default range.
    pub source: GSource,
    /// The g the values were computed at; `None` when they are the midpoint of the estimates over
    /// the range (a range without a g).
    pub g: Option<f64>,
    /// The range of g propagated, \[lo, hi\]; `None` when g was given.
    pub range: Option<[f64; 2]>,
    /// The g at which the g-aware model (the `mc` tables) was evaluated for the term: the tables'
    /// g nodes inside the range, and the range's ends where the tables cover them.
    #[serde(default)]
    pub evaluated: Vec<f64>,
    /// The parts of the range the tables do not cover (not evaluated, never extrapolated), in
    /// words; `None` when the whole range is covered.
    #[serde(default)]
    pub not_covered: Option<String>,
    /// With `g = "fit"`: each channel's fit of g (absent otherwise, and for a channel with no fit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fitted: Option<scatterfit_optics::Rgb<Option<GFitRecord>>>,
}

/// One channel's fit of g (`[fit] g = "fit"`): a profile likelihood over g with the
/// `mc` model. The g and its errors are given only where the data determine g
/// ([`GFitRecord::determined`]); elsewhere [`GFitRecord::reason`] says why not, and the channel's
/// values carry the search range's "± g" term instead.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GFitRecord {
    /// Whether the data determine g (the rule: ARCHITECTURE.md, "Fitting g").
    pub determined: bool,
    /// The fitted g (the minimum of χ²(g)); `None` where not determined.
    pub g: Option<f64>,
    /// Its standard error: the fit's, the model's and the spectrophotometer's parts in
    /// quadrature; `None` where not determined.
    pub g_stderr: Option<f64>,
    /// The fit's part: from the curvature of χ²(g), scaled by the reduced χ² when above 1.
    pub g_stderr_fit: Option<f64>,
    /// The model's part: the `mc` tables' shape noise read as a change of g.
    pub g_stderr_model: Option<f64>,
    /// The spectrophotometer's part: how far the minimum moves with the reading at ± its error.
    #[serde(default)]
    pub g_stderr_spectro: Option<f64>,
    /// The correlation of σ′s and g in the joint covariance.
    pub corr_sigma_s_prime_g: Option<f64>,
    /// The RMS change of the profile's shape (ln, after refitting the other unknowns) that
    /// Δg = 0.05 makes at the fitted g: the signal g is read from.
    pub shape_change: Option<f64>,
    /// The range searched, \[lo, hi\] (the part of the stated or default range the tables answer
    /// at the sample's η).
    pub searched: Option<[f64; 2]>,
    /// Why g is not given; `None` where it is.
    pub reason: Option<String>,
}

impl GFitRecord {
    /// "0.893 ± 0.021 (corr. with σ′s −0.62)" or "not determined (reason)".
    pub fn describe(&self) -> String {
        match (self.determined, self.g, self.g_stderr) {
            (true, Some(g), Some(sd)) => {
                let mut t = format!("{g:.3} ± {sd:.3}");
                if let Some(c) = self.corr_sigma_s_prime_g {
                    t.push_str(&format!(" (corr. with σ′s {c:+.2})"));
                }
                t
            }
            _ => format!(
                "not determined ({})",
                self.reason.as_deref().unwrap_or("no fit")
            ),
        }
    }
}

impl GUncertainty {
    /// One line for people: "g = 0.85 given (no g term)", or "g not stated, so taken as unknown in
    /// 0–0.95: values at g = 0; ± g from the g-aware `mc` model at g = 0, 0.15, 0.3, 0.5, 0.7, 0.8,
    /// 0.9, 0.95", with "(not evaluated, no tables: …)" where the tables miss part of the range.
    pub fn describe(&self) -> String {
        let list = |v: &[f64]| {
            v.iter()
                .map(|g| format!("{g}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match (self.source, self.range) {
            (GSource::Fit, range) => {
                let within = range.map_or(String::new(), |[lo, hi]| format!(" within {lo}–{hi}"));
                let mut t = format!(
                    "g fitted per channel from the profile{within} (the `mc` model's profile \
                     likelihood)"
                );
                if let Some(fitted) = &self.fitted {
                    let parts: Vec<String> = fitted
                        .iter_channels()
                        .filter_map(|(c, f)| {
                            f.as_ref().map(|f| format!("{} {}", c.name(), f.describe()))
                        })
                        .collect();
                    if !parts.is_empty() {
                        t.push_str(&format!(": {}", parts.join("; ")));
                    }
                }
                t.push_str(&format!(
                    "; ± g: where g is fitted, the values at it and sd(g) propagated; where not, the \
                     middle of the estimates over the range and half their spread (g = {})",
                    list(&self.evaluated)
                ));
                if let Some(n) = &self.not_covered {
                    t.push_str(&format!(" (not evaluated, no tables: {n})"));
                }
                t
            }
            (GSource::Given, _) | (_, None) => {
                format!("g = {} given (no g term)", self.g.unwrap_or(0.0))
            }
            (source, Some([lo, hi])) => {
                let at = match self.g {
                    Some(g) => format!("values at g = {g}"),
                    None => "values at the middle of the estimates over the range".into(),
                };
                let what = if source == GSource::DefaultRange {
                    "not stated, so taken as unknown in"
                } else {
                    "stated to lie in"
                };
                let mut t = format!(
                    "g {what} {lo}–{hi}: {at}; ± g from the g-aware `mc` model at g = {}",
                    list(&self.evaluated)
                );
                if let Some(n) = &self.not_covered {
                    t.push_str(&format!(" (not evaluated, no tables: {n})"));
                }
                t
            }
        }
    }
}

/// What the port correction did
/// ([`MeasurementResult::spectro_port`](super::MeasurementResult::spectro_port)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PortResult {
    /// Diameter of the measured aperture \[mm\].
    pub aperture_mm: f64,
    /// Diameter of the lit disc \[mm\].
    pub illuminated_mm: f64,
    /// Rd per channel as the instrument read it.
    pub rd_read: scatterfit_optics::Rgb<f64>,
    /// The fraction of the true Rd the instrument read, per channel (`None`: the channel was left
    /// uncorrected, see `problems`).
    pub reading_fraction: scatterfit_optics::Rgb<Option<f64>>,
    /// Why a channel was left uncorrected.
    #[serde(default)]
    pub problems: scatterfit_optics::Rgb<Option<String>>,
}

/// A measured diffuse reflectance spectrum
/// ([`MeasurementResult::rd_spectrum`](super::MeasurementResult::rd_spectrum)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RdSpectrum {
    /// Wavelengths \[nm\], increasing.
    pub wavelength_nm: Vec<f64>,
    /// The diffuse reflectance (SCE, fraction 0–1) at each wavelength.
    pub rd: Vec<f64>,
}
