//! A channel's quality verdict in `result.json`: what the data checks a careful experimentalist
//! makes found (RELIABILITY.md, "Numbers that look right and are not"). `status` says whether the
//! fit gave parameters; `quality` says whether the data and the fit can be trusted to give them.
//!
//! ```json
//! "quality": { "verdict": "suspect",
//!              "reasons": [ { "kind": "poor_fit", "severity": "suspect",
//!                             "message": "rms log residual 0.95 > 0.40: …" } ] }
//! ```

use serde::{Deserialize, Serialize};

/// The verdict on a channel, worst first in severity: `ok` < `suspect` < `failed`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Every check passed: the values are measurements.
    #[default]
    Ok,
    /// Values were found, but a check says a lab must look before trusting them (exit 1).
    Suspect,
    /// No value to trust (the fit failed, or a check found the data unusable).
    Failed,
}

impl Verdict {
    /// `ok`, `suspect`, `failed`.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Ok => "ok",
            Verdict::Suspect => "suspect",
            Verdict::Failed => "failed",
        }
    }
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which check found a problem.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum ReasonKind {
    /// The fit's residuals are beyond what the noise and the model's known error explain.
    PoorFit,
    /// The spot is near the frame's edge: rings the fit used are cut by the frame asymmetrically.
    IncompleteRings,
    /// The spot centre (given) is away from the spot found in the image.
    CenterOffSpot,
    /// The spot's size in the image disagrees with `spot_diameter_mm / mm_per_pixel`.
    SpotSize,
    /// More than one spot in the frame.
    SecondSpot,
    /// The frames' codes do not use the range their bit depth claims (8-in-16, 12-in-16).
    BitDepth,
    /// The frames are not registered (the camera moved during the bracket).
    Misregistered,
    /// Consecutive exposures too far apart for the frames' codes to overlap (a gap in the
    /// bracket: some radiances are well exposed in no frame).
    BracketGap,
    /// The camera response was recovered from exposures too far apart to pin it: a ripple of the
    /// bracket's period in log exposure is invisible to such a bracket (the fractal ambiguity).
    ResponseSteps,
    /// g is not known, but the anisotropy's uncertainty term could be evaluated over only part
    /// of its range, or not at all (the `mc` tables at some g do not cover the material's η): the
    /// error bars leave out what g can do to the values (5–25 % in σa for forward-scattering
    /// materials).
    GTermIncomplete,
    /// A value outside its documented range.
    OutOfRange,
    /// The fit gave no parameters or did not converge.
    FitFailed,
    /// The data do not constrain a parameter.
    Unconstrained,
    /// The spectrophotometer port's edge-loss correction could not be made for the channel: its
    /// α′ (and so σa) would be the uncorrected reading's.
    PortNotCorrected,
    /// The profile's own reduced albedo (its shape under exact transport) disagrees with the
    /// spectrophotometer's beyond both their errors: another sample's reading, a wrong port, a
    /// profile from elsewhere.
    AlbedoDisagrees,
    /// The manifest's L*a*b* disagrees with the colour of the spectrum beside it.
    LabDisagrees,
    /// An approximate forward model does not describe the profile (its χ²/dof against exact
    /// transport's), or its error could not be evaluated.
    ModelError,
    /// JPEG frames compressed so far that the quantisation changes the profile.
    Compression,
    /// A frame of the bracket that the merged radiance does not predict (a frame from elsewhere,
    /// a gain or light changed during the bracket).
    FrameDisagrees,
    /// The black level subtracted from linear frames (given, from the RAW metadata, or a dark
    /// frame) disagrees with the level the bracket's far corners show at zero exposure time.
    BlackLevel,
    /// Light other than the spot's reached the sample in some frames and not in others: a
    /// frame's far corners read far from the codes the merged radiance predicts (room light
    /// switched on or off during the bracket).
    AmbientLight,
}

/// One finding of a check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reason {
    /// The check.
    pub kind: ReasonKind,
    /// How bad it is.
    pub severity: Verdict,
    /// What was found, with the numbers, and what to do.
    pub message: String,
}

/// A channel's verdict and the reasons for it (none when `ok`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Quality {
    /// The worst severity among the reasons (`ok` without one).
    pub verdict: Verdict,
    /// What the checks found.
    #[serde(default)]
    pub reasons: Vec<Reason>,
}

impl Quality {
    /// A verdict from its reasons: the worst severity among them.
    pub fn from_reasons(reasons: Vec<Reason>) -> Self {
        let verdict = reasons
            .iter()
            .map(|r| r.severity)
            .max()
            .unwrap_or(Verdict::Ok);
        Self { verdict, reasons }
    }

    /// The reasons' messages, `; `-joined (empty when ok).
    pub fn summary(&self) -> String {
        self.reasons
            .iter()
            .map(|r| r.message.as_str())
            .collect::<Vec<_>>()
            .join("; ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_verdict_is_the_worst_reason_and_round_trips() {
        let q = Quality::from_reasons(vec![
            Reason {
                kind: ReasonKind::SpotSize,
                severity: Verdict::Suspect,
                message: "a".into(),
            },
            Reason {
                kind: ReasonKind::FitFailed,
                severity: Verdict::Failed,
                message: "b".into(),
            },
        ]);
        assert_eq!(q.verdict, Verdict::Failed);
        assert_eq!(q.summary(), "a; b");
        let s = serde_json::to_string(&q).unwrap();
        assert!(s.contains(r#""kind":"spot_size""#), "{s}");
        assert_eq!(serde_json::from_str::<Quality>(&s).unwrap(), q);
        assert_eq!(Quality::default().verdict, Verdict::Ok);
    }
}
