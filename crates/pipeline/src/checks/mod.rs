//! The data checks a careful experimentalist makes before calling a value a measurement
//! (RELIABILITY.md "Numbers that look right and are not"), and the per-channel
//! [`Quality`] verdict they give.
//!
//! Each check is a function of what the stages produced (the radiance map, the profile, the fits,
//! the manifest); none changes a number. A finding is a [`Reason`] with a typed kind, a severity
//! and a message with the numbers and what to do; the verdict of a channel is the worst severity
//! among its reasons ([`Quality::from_reasons`]). `status` in `result.json` is unchanged (did the
//! fit give parameters); `quality` says whether they can be trusted.
//!
//! The thresholds are set against the demo (the paper rig's twins of the seven materials, dipole
//! fits: rms log residual over the rings' pixels ≤ 0.15, spot-size ratio 1.02–1.04, frame shifts
//! ≤ 0.18 px; every channel `ok`) and the quick twins the tests use, with the bad cases of `scatterfit_synth::mishaps` on the
//! other side (`tests/checks.rs`).

use scatterfit_fit::FitReport;
pub use scatterfit_io::quality::{Quality, Reason, ReasonKind, Verdict};
use scatterfit_io::result_json::ResponseKind;
use scatterfit_optics::Rgb;

use crate::fit::outcome::ChannelOutcome;
use crate::measurement::Measurement;

mod ambient;
pub mod evidence;
pub mod findings;
mod frames;
mod image;

pub use crate::hdr::frames::{
    CodeRange, MAX_BLACK_LEVEL_OFFSET, PLATEAU_MIN_SAMPLES, REGISTRATION_MIN_PIXELS, Registration,
    code_range, registration,
};
pub use ambient::{
    FAR_FIELD_FRACTION, FAR_FIELD_MIN_SAMPLES, FarField, MAX_CORNER_Z, MAX_FAR_FIELD_CODES,
    MIN_CORNER_RELATIVE, MIN_FAR_FIELD_RATIO, ambient_light_reasons, far_field_agreement,
    far_field_agreement_in,
};
pub use findings::SampleChecks;
pub use frames::{
    AGREEMENT_CODES, AGREEMENT_MIN_SAMPLES, FrameAgreement, MAX_FRAME_OFFSET_LN,
    MAX_FRAME_SHIFT_PX, MAX_FRAME_SPREAD_LN, MAX_STEP_8BIT, MAX_STEP_LINEAR, MAX_STEP_RECOVERED,
    MIN_JPEG_QUALITY, black_level_reasons, bracket_reasons, code_reasons, compression_reasons,
    frame_agreement, frame_agreement_reasons, registration_reasons,
};
pub use image::{
    image_checks, incomplete_rings, lab_disagreement, sample_checks, spot_hwhm_px, spot_scale,
};

/// A fit whose rms log residual over the fitted rings' pixels
/// ([`FitReport::pixel_rms_log_residual`]) exceeds this is suspect: the profile differs from the
/// model by more than e^0.4 − 1 ≈ 50 % on average over what the rings hold. Weighted by pixels, a
/// ring of one corner pixel counts once and a ring of 700 pixels 700 times: a few lifted far pixels
/// (hot pixels, a JPEG block's code 1 in a short frame) no longer outweigh the profile, while a
/// wrong centre (2.2–2.8), a second spot as bright (0.41–0.59) or a two-frame bracket's G and B
/// (0.74, 0.90) stay above. Good data: the demo's largest is 0.15 (blue coating, B, the dipole's
/// own error; 0.05 with exact transport), the quick twins' 0.13, a 12-bit linear twin's G 0.28
/// (RELIABILITY.md, "(a) Fit quality"). χ² is reported but not judged here: with the diffusion
/// models its model-error part dominates (26–2300 on the demo), so no noise-based threshold
/// separates a good sample from a bad one.
pub const MAX_RMS_LOG_RESIDUAL: f64 = 0.4;

/// The spot's half width at half maximum in the image, over the light spot's radius
/// (`spot_diameter_mm / 2 / mm_per_pixel`), outside this range makes every channel suspect: the
/// scale or the spot's diameter is wrong (a 10× typo gives 0.1 or 10). Good samples give 1.02–1.04
/// (demo) and 1.02–1.19 (quick twins; the blur of subsurface scattering widens the spot, never shrinks it much).
pub const SPOT_SIZE_RATIO: (f64, f64) = (0.6, 2.5);

/// A pixel at least this many times its ring's median and [`SECOND_SPOT_Z`] robust standard
/// deviations above it, with 6 of its 8 neighbours at least 60 % as far above, is part of a second
/// spot (a reflection, a second light). A ghost of a tenth of the spot's power 63 px away on pink
/// plastic's long tail stands 1.4× above its ring (σ′s −8 %); the good twins' rings hold no pixel
/// group above 1.1×.
pub const SECOND_SPOT_RATIO: f64 = 1.25;

/// See [`SECOND_SPOT_RATIO`].
pub const SECOND_SPOT_Z: f64 = 8.0;

/// An approximate model whose χ²/dof on the profile exceeds this many times exact transport's on
/// the same rings (floored at 1, what the noise allows) does not describe the profile: its
/// channel is suspect even with its `model` term. On the demo's twins the dipole's ratio is
/// 2–1000 (red aluminium, blue coating and pink plastic well beyond); noise alone gives ≈ 1.
pub const MAX_MODEL_CHI2_RATIO: f64 = 3.0;

/// A manifest L\*a\*b\* further than this CIE 1976 ΔE\*ab from the colour of the spectrum beside
/// it (its SCE or, where the instrument reported specular-included colour, its SCI; D65, the
/// same observer) makes every channel suspect. ΔE\*ab ≈ 1 is a just-noticeable difference and
/// d/8 instruments of one model agree within about 0.5; at 3 the two cannot be readings of one
/// sample by one instrument (a copied row, another sample's file). Rd, hence α′ and σa, follows
/// the L\*a\*b\*: an L\* off by 3 moves Rd by about 7 %.
pub const MAX_LAB_DELTA_E: f64 = 3.0;

/// The image's spot half width over the one the fitted model predicts at the stated scale and
/// spot ([`spot_scale`]) outside this range makes every channel suspect: a scale (or a
/// spot diameter) 10 % off gives 0.91 or 1.10. The demo's twins give 0.99–1.01, the quick twins
/// and the camera sweep 0.97–1.03 (RELIABILITY.md, "The evidence behind ok").
pub const SPOT_FACTOR_RANGE: (f64, f64) = (0.94, 1.06);

/// The spot-size check ([`SPOT_FACTOR_RANGE`]) also needs every channel, measured alone, beyond
/// 1 by this much on the same side as the channel sum: a scale is common to the channels. Alone,
/// the demo's channels give 0.972–1.004, the quick demo's 0.944–1.008 (the quick pink-plastic
/// twin's PNG bracket R 1.008, G 1.003, B 0.966); `mm_per_pixel` × 1.1 gives R 1.088, G 1.085,
/// B 1.044 (sum 1.082), × 0.9 0.900, 0.898, 0.864. Pillow's JPEG quality 75 with 4:2:0 chroma
/// moves the quick twin's 10-pixel spot by R +5, G +10, B −2 % (sum 1.073, σ′s within 1.6 %),
/// `jpeg-encoder`'s by +4, +10, −6 % (sum 1.074).
pub const SPOT_CHANNEL_MARGIN: f64 = 0.01;

/// The profile's own α′ and the spectrophotometer's further apart than this many standard
/// errors (in ln(1 − α′), [`evidence::AlbedoCheck`]) …
pub const ALBEDO_Z: f64 = 5.0;

/// … with the proposed fit's χ²/dof more than this many times the two-parameter fit's (floored
/// at 1) make the channel suspect: the reading does not describe this profile. Both are needed:
/// a model's small near-field error can move the free fit's α′ by several of its (tiny) errors
/// without the reading being wrong, and then the proposed fit is nearly as good.
pub const ALBEDO_CHI2_RATIO: f64 = 3.0;

/// The documented ranges a value must lie in before it is called a measurement [mm⁻¹]
/// (ARCHITECTURE.md, "The measurement, as files").
pub const SIGMA_S_PRIME_RANGE: (f64, f64) = (1e-3, 1e3);
/// σa's documented range [mm⁻¹].
pub const SIGMA_A_RANGE: (f64, f64) = (0.0, 1e3);
/// η's documented range.
pub const ETA_RANGE: (f64, f64) = (1.0, 3.0);

pub(crate) fn suspect(kind: ReasonKind, message: String) -> Reason {
    Reason {
        kind,
        severity: Verdict::Suspect,
        message,
    }
}

/// The fit's own checks on one channel: converged, constrained, residuals the model's error and
/// the noise explain, values in their documented ranges.
pub fn fit_reasons(outcome: &ChannelOutcome, eta: f64) -> Vec<Reason> {
    let mut reasons = Vec::new();
    let r: &FitReport = match outcome {
        ChannelOutcome::NotFitted { problem } => {
            return vec![Reason {
                kind: ReasonKind::FitFailed,
                severity: Verdict::Failed,
                message: problem.clone(),
            }];
        }
        ChannelOutcome::Fitted(f) => &f.report,
    };
    if !r.converged {
        reasons.push(Reason {
            kind: ReasonKind::FitFailed,
            severity: Verdict::Failed,
            message: format!("the fit failed: {}", r.termination),
        });
    }
    if !r.unconstrained.is_empty() {
        reasons.push(suspect(
            ReasonKind::Unconstrained,
            format!(
                "the profile does not constrain {}",
                r.unconstrained
                    .iter()
                    .map(|p| p.name())
                    .collect::<Vec<_>>()
                    .join(" and ")
            ),
        ));
    }
    // An unknown g whose term could not be evaluated over its whole range: the error bars would
    // look complete and are not (never a 10 % bias behind a 0.3 % bar).
    if let ChannelOutcome::Fitted(f) = outcome
        && let Some(gap) = &f.g_term_gap
    {
        reasons.push(suspect(
            ReasonKind::GTermIncomplete,
            format!(
                "g is not known and {gap}, so the error bars leave out part of what g does to the \
                 values (σa computed at g = 0 is 5–25 % off for a forward-scattering material): \
                 give g if it is known (`[fit] g`, `--g`), or a g range the tables cover \
                 (`[fit] g_range`, `--g-range`)"
            ),
        ));
    }
    // (a) Fit quality, judged over the rings' pixels (the per-ring rms where a report has none).
    let rms = if r.pixel_rms_log_residual.is_finite() {
        r.pixel_rms_log_residual
    } else {
        r.rms_log_residual
    };
    if rms.is_finite() && rms > MAX_RMS_LOG_RESIDUAL {
        reasons.push(suspect(
            ReasonKind::PoorFit,
            format!(
                "rms log residual {rms:.2} over the fitted rings' pixels > {MAX_RMS_LOG_RESIDUAL} \
                 ({:.2} per ring, χ²/dof {:.0}): the profile differs from the model by more than \
                 the noise and the model's known error explain — look at fit.png (a second spot, \
                 a bumped camera, wrong exposure times, clipped or mis-scaled codes)",
                r.rms_log_residual, r.chi2_reduced
            ),
        ));
    }
    // (g) Values in their documented ranges.
    let mut out = Vec::new();
    let check = |name: &str, v: f64, (lo, hi): (f64, f64), out: &mut Vec<String>| {
        if !(v.is_finite() && v >= lo && v <= hi) {
            out.push(format!("{name} = {v:.4e} outside [{lo:e}, {hi:e}]"));
        }
    };
    check("σ′s", r.sigma_s_prime.value, SIGMA_S_PRIME_RANGE, &mut out);
    check("σa", r.sigma_a.value, SIGMA_A_RANGE, &mut out);
    check("α′", r.albedo_prime, (0.0, 1.0), &mut out);
    check("η", eta, ETA_RANGE, &mut out);
    if !out.is_empty() {
        reasons.push(suspect(
            ReasonKind::OutOfRange,
            format!(
                "{} (the documented ranges): not a measurement this rig can make",
                out.join(", ")
            ),
        ));
    }
    reasons
}

/// What the stages recorded about one channel, as reasons: a port correction that could not be
/// made fails the channel (its α′ and σa would be the uncorrected reading's, biased by the port's
/// edge loss, and reported as if corrected); behind a port with g not known the ± g term keeps
/// the port's F at one g, so it understates (F changes by 2–9 % between g = 0 and 0.8 at
/// α′ ≥ 0.99 behind an 8 mm port; BENCHMARKS.md, "The port's conditioning") and the channel is
/// suspect.
pub fn stage_reasons(m: &Measurement, c: scatterfit_optics::Channel) -> Vec<Reason> {
    let mut reasons = Vec::new();
    if let Some(p) = &m.port
        && p.problems[c].is_none()
        && let Some([lo, hi]) = m.settings.g_prior.propagated_range()
    {
        reasons.push(suspect(
            ReasonKind::GTermIncomplete,
            format!(
                "behind the spectrophotometer port the ± g term (g in {lo}–{hi}) keeps the port's \
                 correction at g = {}, but the port's loss itself changes with g, so the term \
                 understates: give [fit] g (or --g) if it is known",
                m.settings.g
            ),
        ));
    }
    if let Some(p) = &m.port
        && let Some(problem) = &p.problems[c]
    {
        reasons.push(Reason {
            kind: ReasonKind::PortNotCorrected,
            severity: Verdict::Failed,
            message: format!(
                "the spectrophotometer port's edge-loss correction ({} mm aperture lit over {} \
                 mm) could not be made: {problem}; α′ and σa would be the uncorrected reading's, \
                 not a measurement",
                p.aperture_mm, p.illuminated_mm
            ),
        });
    }
    reasons
}

/// An approximate forward model's checks on one channel ([`crate::model_term`]): its error
/// measured against exact transport (else the channel is suspect: the bar lacks it), and its
/// χ²/dof against exact transport's on the same rings ([`MAX_MODEL_CHI2_RATIO`]).
pub fn model_reasons(outcome: &ChannelOutcome, model: scatterfit_optics::ModelName) -> Vec<Reason> {
    let Some(f) = outcome.fit() else {
        return Vec::new();
    };
    let mut reasons = Vec::new();
    if let Some(note) = &f.model_note {
        reasons.push(suspect(
            ReasonKind::ModelError,
            format!("{note}: the error bars leave out the model's error; use --model mc"),
        ));
    }
    if let Some(x) = &f.exact {
        let allowed = MAX_MODEL_CHI2_RATIO * x.chi2_reduced.max(1.0);
        let chi2 = f.report.chi2_reduced;
        if chi2.is_finite() && chi2 > allowed {
            let pct = |a: f64, b: f64| 100.0 * (a / b - 1.0);
            reasons.push(suspect(
                ReasonKind::ModelError,
                format!(
                    "the {model} model does not describe this profile: χ²/dof {chi2:.1} against \
                     {:.1} for exact transport on the same rings (more than {MAX_MODEL_CHI2_RATIO}×); \
                     its σ′s and σa differ from exact transport's by {:+.1} % and {:+.1} % (the \
                     ± model term) — measure with --model mc",
                    x.chi2_reduced,
                    pct(f.sigma_s_prime.value, x.sigma_s_prime),
                    pct(f.sigma_a.value, x.sigma_a),
                ),
            ));
        }
    }
    reasons
}

/// The profile's own α′ against the spectrophotometer's, per channel ([`ALBEDO_Z`],
/// [`ALBEDO_CHI2_RATIO`]); when two channels disagree the reading is likely not this sample's,
/// and the third is suspect too. With g not known, both α′ are taken at the assumed g (0), and a
/// forward-scattering material opens the same gap (at g 0.9 and α′ 0.07–0.3 the profile's shape
/// at g = 0 reads α′ 0.8–0.97): the advice then names g first.
pub fn albedo_reasons(m: &Measurement) -> Rgb<Vec<Reason>> {
    let flagged = m.evidence.albedo.as_ref().map(|check| {
        check.filter(|a| {
            a.z > ALBEDO_Z && a.chi2_proposed > ALBEDO_CHI2_RATIO * a.chi2_profile.max(1.0)
        })
    });
    let count = flagged.iter().filter(|f| f.is_some()).count();
    let advice = match m.settings.g_prior.propagated_range() {
        Some([lo, hi]) => format!(
            "g is not known and was taken as {}, and a material that scatters forward (g up to \
             {hi}; the range is {lo}–{hi}) shows such a gap: give [fit] g (or --g) if it is \
             known; otherwise check that the spectro file is this sample's (and the port, \
             spectro.aperture_mm)",
            m.settings.g
        ),
        None => "check that the spectro file is this sample's (and the port, \
                 spectro.aperture_mm), or measure with --method existing"
            .to_owned(),
    };
    flagged.as_ref().map(|f| match f {
        Some(a) => vec![suspect(
            ReasonKind::AlbedoDisagrees,
            format!(
                "the profile's own shape gives α′ {:.4} (σ′s and σa both fitted), the \
                 spectrophotometer α′ {:.4}: {:.0} standard errors apart, and the fit with the \
                 reading's α′ has χ²/dof {:.1} against {:.1} — {advice}",
                a.profile, a.spectro, a.z, a.chi2_proposed, a.chi2_profile
            ),
        )],
        None if count >= 2 => vec![suspect(
            ReasonKind::AlbedoDisagrees,
            format!(
                "two other channels' α′ from the profile disagree with the spectrophotometer's, \
                 so this channel's α′ is in doubt too — {advice}"
            ),
        )],
        None => Vec::new(),
    })
}

/// The verdict on each channel (R, G, B): the fit's checks, the stages' and the sample's.
pub fn quality(m: &Measurement) -> Rgb<Quality> {
    let sample = sample_checks(m);
    let albedo = albedo_reasons(m);
    m.fits.as_ref().map_with_channel(|c, o| {
        let mut reasons = fit_reasons(o, m.spectro.eta);
        reasons.extend(stage_reasons(m, c));
        reasons.extend(model_reasons(o, m.settings.model));
        reasons.extend(albedo[c].iter().cloned());
        // A failed channel has no value the sample's findings could qualify.
        if !reasons.iter().any(|r| r.severity == Verdict::Failed) {
            reasons.extend(sample.reasons.iter().cloned());
        }
        Quality::from_reasons(reasons)
    })
}

impl Measurement {
    /// The data checks' verdict per channel ([`quality`]): the fits' checks and the sample's, with
    /// the image checks made at measurement ([`Measurement::image_checks`]).
    pub fn quality(&self) -> Rgb<Quality> {
        quality(self)
    }
}
