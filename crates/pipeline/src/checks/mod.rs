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
use scatterfit_imaging::{CenterOptions, find_spot_center};
pub use scatterfit_io::quality::{Quality, Reason, ReasonKind, Verdict};
use scatterfit_io::result_json::ResponseKind;
use scatterfit_optics::Rgb;

use crate::fit::ChannelOutcome;
use crate::measure::Measurement;

mod ambient;
pub mod evidence;
mod frames;

pub use crate::hdr::frames::{
    CodeRange, MAX_BLACK_LEVEL_OFFSET, PLATEAU_MIN_SAMPLES, REGISTRATION_MIN_PIXELS, Registration,
    code_range, registration,
};
pub use ambient::{
    FAR_FIELD_FRACTION, FAR_FIELD_MIN_SAMPLES, FarField, MAX_FAR_FIELD_CODES, MIN_FAR_FIELD_RATIO,
    ambient_light_reasons, far_field_agreement, far_field_agreement_in,
};
pub use frames::{
    AGREEMENT_CODES, AGREEMENT_MIN_SAMPLES, FrameAgreement, MAX_FRAME_OFFSET_LN,
    MAX_FRAME_SHIFT_PX, MAX_FRAME_SPREAD_LN, MAX_STEP_8BIT, MAX_STEP_LINEAR, MAX_STEP_RECOVERED,
    MIN_JPEG_QUALITY, black_level_reasons, bracket_reasons, code_reasons, compression_reasons,
    frame_agreement, frame_agreement_reasons, registration_reasons,
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
/// spot ([`evidence::spot_scale`]) outside this range makes every channel suspect: a scale (or a
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

/// Checks that concern the whole sample (the image, the manifest), made once per measurement.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SampleChecks {
    /// Findings that apply to every channel.
    pub reasons: Vec<Reason>,
}

fn suspect(kind: ReasonKind, message: String) -> Reason {
    Reason {
        kind,
        severity: Verdict::Suspect,
        message,
    }
}

/// The sample's checks: the spot inside the frame with its fitted rings complete (or cut
/// symmetrically), the measurement's image checks ([`Measurement::image_checks`], made once when
/// the bracket was merged), and the spot's size in the image against the one the fitted model
/// predicts at the manifest's scale ([`evidence::spot_scale`], made with the measurement:
/// [`evidence::Evidence::spot_scale`]).
pub fn sample_checks(m: &Measurement) -> SampleChecks {
    let mut reasons = Vec::new();
    let radiance = &m.hdr.hdr.radiance;
    let [cx, cy] = m.profile.center.xy();
    let mmpp = m.profile.profile.mm_per_pixel;
    // (b) Rings complete to the fitted radius, or cut by the frame the same on both sides.
    let r_fit_px = m
        .fits
        .iter()
        .filter_map(ChannelOutcome::report)
        .flat_map(|r| r.fitted.iter().map(|f| f.r_mm / mmpp))
        .fold(0.0f64, f64::max);
    if let Some(msg) = incomplete_rings(radiance.width(), radiance.height(), [cx, cy], r_fit_px) {
        reasons.push(suspect(ReasonKind::IncompleteRings, msg));
    }
    reasons.extend(m.image_checks.reasons.iter().cloned());
    if let Some(scale) = m.evidence.spot_scale
        && !(SPOT_FACTOR_RANGE.0..=SPOT_FACTOR_RANGE.1).contains(&scale.factor)
        && scale.every_channel_agrees(scale.factor > 1.0)
    {
        let factor = scale.factor;
        reasons.push(suspect(
            ReasonKind::SpotSize,
            format!(
                "the spot in the image is {factor:.3}× the size the fitted model predicts for a \
                 {:.3} mm spot at {mmpp} mm per pixel (expected {}–{}; each channel alone: {}): \
                 camera.mm_per_pixel or camera.spot_diameter_mm is about {:.0} % off (the true \
                 scale is near {:.4} mm per pixel if the diameter is right); σ′s and σa scale \
                 with it",
                2.0 * m.settings.spot_radius_mm,
                SPOT_FACTOR_RANGE.0,
                SPOT_FACTOR_RANGE.1,
                scale
                    .channels
                    .iter()
                    .map(|c| c.map_or("–".into(), |f| format!("{f:.3}")))
                    .collect::<Vec<_>>()
                    .join(", "),
                100.0 * (1.0 / factor - 1.0),
                mmpp / factor,
            ),
        ));
    }
    SampleChecks { reasons }
}

/// The checks of the image, the bracket and the manifest that no fit enters: a given centre on
/// the spot, the codes the frames use, the black level, the frames registered, the bracket's
/// order and exposures, each frame against the merged radiance, the JPEG compression, the
/// manifest's L\*a\*b\* against its spectrum, one spot, and the spot's half width against the
/// manifest's scale. They read every frame's pixels, so a measurement makes them once
/// ([`Measurement::image_checks`]) and every refit of the same bracket keeps them.
pub fn image_checks(m: &Measurement) -> SampleChecks {
    let mut reasons = Vec::new();
    let radiance = &m.hdr.hdr.radiance;
    let [cx, cy] = m.profile.center.xy();
    let mmpp = m.profile.profile.mm_per_pixel;
    let a_px = m.settings.spot_radius_mm / mmpp;
    // A given centre must lie on the spot the image shows.
    if m.profile.center_source == crate::profile::CenterSource::Given
        && let Ok(found) = find_spot_center(radiance, &CenterOptions::default())
    {
        let [fx, fy] = found.xy();
        let d = (fx - cx).hypot(fy - cy);
        let tol = (0.5 * a_px).max(3.0);
        if d > tol {
            reasons.push(suspect(
                ReasonKind::CenterOffSpot,
                format!(
                    "the given spot centre ({cx:.1}, {cy:.1}) px is {d:.0} px from the spot the \
                     image shows at ({fx:.1}, {fy:.1}) px (more than {tol:.0} px): correct \
                     camera.center_px or drop it"
                ),
            ));
        }
    }
    // (e) The codes the frames use; (f) the frames registered.
    reasons.extend(code_reasons(m));
    if let Some(b) = &m.hdr.corrections.black_level_check {
        reasons.extend(black_level_reasons(b));
    }
    reasons.extend(registration_reasons(m));
    reasons.extend(bracket_reasons(m));
    reasons.extend(frame_agreement_reasons(m));
    reasons.extend(ambient_light_reasons(m));
    reasons.extend(compression_reasons(m));
    if let Some(msg) = lab_disagreement(m) {
        reasons.push(suspect(ReasonKind::LabDisagrees, msg));
    }
    // (d) Exactly one spot.
    if let Some(msg) = second_spot(m, a_px) {
        reasons.push(suspect(ReasonKind::SecondSpot, msg));
    }
    // (c) The spot's size in the image against the manifest's scale and spot diameter.
    if let Some(hwhm) = spot_hwhm_px(m)
        && a_px.is_finite()
        && a_px > 0.0
    {
        let ratio = hwhm / a_px;
        if !(SPOT_SIZE_RATIO.0..=SPOT_SIZE_RATIO.1).contains(&ratio) {
            reasons.push(suspect(
                ReasonKind::SpotSize,
                format!(
                    "the spot's half width in the image is {hwhm:.1} px, but spot_diameter_mm / 2 / \
                     mm_per_pixel = {:.3} / {mmpp} = {a_px:.1} px (ratio {ratio:.2}, expected \
                     {}–{}): check camera.mm_per_pixel and camera.spot_diameter_mm (a scale {:.2}× \
                     off makes σ′s and σa as many times off)",
                    m.settings.spot_radius_mm,
                    SPOT_SIZE_RATIO.0,
                    SPOT_SIZE_RATIO.1,
                    ratio
                ),
            ));
        }
    }
    SampleChecks { reasons }
}

/// The manifest's L\*a\*b\* against the spectrum beside it ([`MAX_LAB_DELTA_E`]): the message
/// when they disagree, `None` when they agree or only one of them is given.
pub fn lab_disagreement(m: &Measurement) -> Option<String> {
    use scatterfit_optics::colour::{Lab, Observer, spectrum_to_xyz, xyz_to_lab};
    let [l, a, b] = m.manifest.spectro.lab?;
    let analysis = m.spectro.analysis.as_ref()?;
    let observer = match m.manifest.spectro.lab_observer {
        Some(2) => Observer::TwoDegree,
        _ => Observer::TenDegree,
    };
    let wl: Vec<f64> = analysis.spectral.iter().map(|p| p.wavelength_nm).collect();
    let lab_of = |values: Vec<f64>| -> Option<Lab> {
        spectrum_to_xyz(&wl, &values, observer)
            .ok()
            .map(|xyz| xyz_to_lab(xyz, observer.d65_white()))
    };
    let sce = lab_of(analysis.spectral.iter().map(|p| p.sce).collect())?;
    let sci = lab_of(analysis.spectral.iter().map(|p| p.sci).collect());
    // CIE 1976 colour difference ΔE*ab: the Euclidean distance in L*a*b*.
    let delta = |x: &Lab| ((x.l - l).powi(2) + (x.a - a).powi(2) + (x.b - b).powi(2)).sqrt();
    let (d_sce, d_sci) = (delta(&sce), sci.as_ref().map_or(f64::INFINITY, delta));
    let d = d_sce.min(d_sci);
    (d > MAX_LAB_DELTA_E).then(|| {
        format!(
            "spectro.lab = [{l}, {a}, {b}] is ΔE*ab {d:.1} from the colour of the spectrum in \
             the spectro file (SCE L*a*b* [{:.1}, {:.1}, {:.1}]{}; more than {MAX_LAB_DELTA_E}): \
             they are not one reading of one sample — α′ and σa follow the L*a*b*; check that \
             both are this sample's, or drop spectro.lab to use the spectrum",
            sce.l,
            sce.a,
            sce.b,
            sci.map_or(String::new(), |s| format!(
                ", SCI [{:.1}, {:.1}, {:.1}]",
                s.l, s.a, s.b
            )),
        )
    })
}

/// Whether rings to `r_fit_px` around `c` in a `w × h` frame are cut by its edges on one side
/// more than on the other (a spot near an edge or a corner). A centred spot whose outer rings are
/// cut the same on both sides keeps an unbiased ring mean; an off-centre one does not (its centre
/// is also found from a truncated image). Tolerance: 10 % of the nearer margin + 2 px.
pub fn incomplete_rings(w: usize, h: usize, c: [f64; 2], r_fit_px: f64) -> Option<String> {
    let [cx, cy] = c;
    let mut bad = Vec::new();
    for (axis, lo, hi) in [
        ("left/right", cx + 0.5, w as f64 - 0.5 - cx),
        ("top/bottom", cy + 0.5, h as f64 - 0.5 - cy),
    ] {
        let near = lo.min(hi);
        if r_fit_px > near && (lo - hi).abs() > 0.1 * near + 2.0 {
            bad.push(format!("{axis} margins {lo:.0} and {hi:.0} px"));
        }
    }
    (!bad.is_empty()).then(|| {
        format!(
            "the spot at ({cx:.1}, {cy:.1}) px lies off the frame's centre ({}) and the fit used \
             rings to {r_fit_px:.0} px, which the frame cuts on one side only: centre the spot \
             in the frame, or lower fit.r_max_px below the nearer margin",
            bad.join(", ")
        )
    })
}

/// The profile's half width at half maximum \[px\], on the channel sum (the first ring where the
/// sum falls below half the maximum of the first rings, linearly interpolated).
pub fn spot_hwhm_px(m: &Measurement) -> Option<f64> {
    let rings = &m.profile.profile.rings;
    let sum: Vec<f64> = rings
        .iter()
        .map(|r| r.channels.iter().map(|c| c.mean).sum())
        .collect();
    let radii: Vec<f64> = rings.iter().map(|r| r.r_px).collect();
    evidence::hwhm_of(&sum, &radii)
}

/// A second spot: pixels (channel sum) well above their ring's median (a spot on a ring leaves its
/// median alone; [`SECOND_SPOT_RATIO`], [`SECOND_SPOT_Z`]), away from the spot (beyond 3 spot
/// radii), on rings whose median is well above the detection limit, with at least 6 of their 8
/// neighbours nearly as far above (not a hot pixel). Returns the message for the brightest.
fn second_spot(m: &Measurement, a_px: f64) -> Option<String> {
    let img = &m.hdr.hdr.radiance;
    let prof = &m.profile.profile;
    let width = prof.options.ring_width_px();
    let n_rings = prof.rings.len();
    let [cx, cy] = m.profile.center.xy();
    let ch = img.channels();
    let (w, h) = (img.width(), img.height());
    let limit: f64 = m
        .profile
        .detection_limit
        .iter()
        .map(|l| if l.is_finite() { *l } else { 0.0 })
        .sum();
    let ring_of =
        |x: usize, y: usize| -> usize { ((x as f64 - cx).hypot(y as f64 - cy) / width) as usize };
    let value = |x: usize, y: usize| -> f64 {
        img.pixel(x, y).map_or(f64::NAN, |p| {
            p.iter().take(ch).map(|&v| f64::from(v)).sum::<f64>()
        })
    };
    let mut per_ring: Vec<Vec<f64>> = vec![Vec::new(); n_rings];
    for y in 0..h {
        for x in 0..w {
            let k = ring_of(x, y);
            let v = value(x, y);
            if k < n_rings && v.is_finite() {
                per_ring[k].push(v);
            }
        }
    }
    // Per ring: the median and the robust spread (1.4826 × the median absolute deviation).
    let stats: Vec<(f64, f64)> = per_ring
        .into_iter()
        .map(|mut v| {
            if v.len() < 8 {
                return (f64::NAN, f64::NAN);
            }
            let mid = v.len() / 2;
            let med = *v.select_nth_unstable_by(mid, f64::total_cmp).1;
            let mut dev: Vec<f64> = v.iter().map(|x| (x - med).abs()).collect();
            let mad = *dev.select_nth_unstable_by(mid, f64::total_cmp).1;
            if med > 3.0 * limit && med > 0.0 {
                (med, 1.4826 * mad)
            } else {
                (f64::NAN, f64::NAN)
            }
        })
        .collect();
    // (ratio to the ring's median, robust z-score) of a pixel.
    let score = |x: usize, y: usize| -> (f64, f64) {
        stats
            .get(ring_of(x, y))
            .map_or((f64::NAN, f64::NAN), |&(med, spread)| {
                let v = value(x, y);
                (v / med, (v - med) / spread.max(1e-3 * med))
            })
    };
    let spot_like = |(q, z): (f64, f64), strict: bool| -> bool {
        if strict {
            q >= SECOND_SPOT_RATIO && z >= SECOND_SPOT_Z
        } else {
            q >= 1.0 + 0.6 * (SECOND_SPOT_RATIO - 1.0) && z >= 0.6 * SECOND_SPOT_Z
        }
    };
    let r_min = (3.0 * a_px).max(6.0);
    let mut best: Option<(f64, usize, usize)> = None;
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            if (x as f64 - cx).hypot(y as f64 - cy) < r_min {
                continue;
            }
            let sc = score(x, y);
            if !spot_like(sc, true) || best.is_some_and(|(b, ..)| sc.0 <= b) {
                continue;
            }
            let bright = [
                (0, 0),
                (1, 0),
                (2, 0),
                (0, 1),
                (2, 1),
                (0, 2),
                (1, 2),
                (2, 2),
            ]
            .iter()
            .filter(|&&(dx, dy)| spot_like(score(x + dx - 1, y + dy - 1), false))
            .count();
            if bright >= 6 {
                best = Some((sc.0, x, y));
            }
        }
    }
    best.map(|(q, x, y)| {
        let d = (x as f64 - cx).hypot(y as f64 - cy);
        format!(
            "a second bright spot at ({x}, {y}) px, {d:.0} px from the spot centre ({cx:.1}, \
             {cy:.1}): {q:.1}× its ring's median (a reflection off the rig, a second light?); \
             the rings through it are not the sample's profile — remove it and measure again"
        )
    })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_centred_spot_cut_on_both_sides_is_complete_an_off_centre_one_is_not() {
        assert!(incomplete_rings(256, 256, [130.2, 128.8], 180.0).is_none());
        assert!(incomplete_rings(1024, 1024, [512.0, 511.0], 300.0).is_none());
        assert!(incomplete_rings(158, 158, [32.2, 30.8], 170.0).is_some());
        assert!(incomplete_rings(143, 256, [18.0, 128.8], 100.0).is_some());
        // Rings inside the nearer margin are complete wherever the spot is.
        assert!(incomplete_rings(143, 256, [18.0, 128.8], 15.0).is_none());
    }
}
