//! The result's sample-level records beside the channels: how g entered it ([`GUncertainty`],
//! issue 15), what the spectrophotometer port correction did ([`PortResult`]) and the measured
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
}

impl GSource {
    /// The name in the file: `given`, `range`, `default_range`.
    pub fn name(self) -> &'static str {
        match self {
            GSource::Given => "given",
            GSource::Range => "range",
            GSource::DefaultRange => "default_range",
        }
    }
}

/// How g entered a result
/// ([`MeasurementResult::g_uncertainty`](super::MeasurementResult::g_uncertainty), issue 15).
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
}

impl GUncertainty {
    /// One line for people: "g = 0.85 given (no g term)", or "g not stated, so taken as unknown in
    /// 0–0.95: values at g = 0; ± g from the g-aware `mc` model at g = 0, 0.8, 0.9, 0.95 (not evaluated,
    /// no tables: …)".
    pub fn describe(&self) -> String {
        let list = |v: &[f64]| {
            v.iter()
                .map(|g| format!("{g}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match (self.source, self.range) {
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
