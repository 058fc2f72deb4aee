//! The verdicts on the bracket's frames: the codes they use (8- or 12-bit data in
//! 16-bit files, the clipping plateau), their registration (the spot's centroid per frame) and the
//! bracket's overlap (consecutive exposures, frames for a recovered response).

use super::*;

/// The bracket's codes as a finding: frames of 16-bit files holding 8 bits or fewer are suspect
/// (the detection limit and the noise model assume more); a plateau found and used is not.
pub fn code_reasons(m: &Measurement) -> Vec<Reason> {
    let Some(c) = m.hdr.corrections.codes else {
        return Vec::new();
    };
    if c.bits <= 8 {
        return vec![suspect(
            ReasonKind::BitDepth,
            format!(
                "the 16-bit frames use {} bits (largest code {}): 8-bit data in 16-bit files \
                 lose the range and precision the linear merge assumes — give the camera's own \
                 frames",
                c.bits, c.max_code
            ),
        )];
    }
    Vec::new()
}

/// The black level subtracted from linear frames against the bracket's own evidence
/// ([`crate::hdr::BlackLevelCheck::disagreement`]): every channel suspect when they disagree.
pub fn black_level_reasons(b: &crate::hdr::BlackLevelCheck) -> Vec<Reason> {
    b.disagreement()
        .map(|message| suspect(ReasonKind::BlackLevel, message))
        .into_iter()
        .collect()
}

/// A shift between frames beyond this \[px\] makes every channel suspect: the rings of the merged
/// map then average light from two positions. The demo's frames agree to 0.18 px.
pub const MAX_FRAME_SHIFT_PX: f64 = 1.5;

/// The frames' registration as a finding: suspect beyond [`MAX_FRAME_SHIFT_PX`].
pub fn registration_reasons(m: &Measurement) -> Vec<Reason> {
    let Some(r) = &m.hdr.corrections.registration else {
        return Vec::new();
    };
    if r.max_shift_px <= MAX_FRAME_SHIFT_PX {
        return Vec::new();
    }
    let list: Vec<String> = r
        .centroids
        .iter()
        .enumerate()
        .filter_map(|(j, c)| c.map(|[x, y]| format!("{j}: ({x:.1}, {y:.1})")))
        .collect();
    vec![suspect(
        ReasonKind::Misregistered,
        format!(
            "the spot moves by up to {:.1} px between the frames (its centre per frame, shortest \
             first: {}): the camera or the sample moved during the bracket — fix the rig and take \
             the bracket again",
            r.max_shift_px,
            list.join(", ")
        ),
    )]
}

/// The largest ratio of consecutive shutter times an 8-bit (tone-curved) bracket may have. Through
/// a gamma-like curve a frame's codes above the noise floor (≈ 5–250) span two to three decades of
/// radiance, coarsely at the bottom; measured: a 3-frame bracket with 42× steps (1/600, 0.07, 3 s)
/// still gives σ′s within 5 % (`cli/tests/measure.rs`), a 2-frame one 1800× apart is +712 % off.
/// 64× (6 stops) keeps every bracket that measured and flags the gap. (The demo's and the paper's
/// brackets step by 1.9×.)
pub const MAX_STEP_8BIT: f64 = 64.0;

/// The same for linear frames of more than 8 bits (RAW, 16-bit linear): 12 usable bits and more
/// overlap across 256× (8 stops).
pub const MAX_STEP_LINEAR: f64 = 256.0;

/// The largest *typical* (median) ratio of consecutive times from which a camera response is
/// recovered without a check: with times in a constant ratio k the bracket cannot see a ripple of
/// the response periodic in ln X with period ln k (the fractal ambiguity, docs/physics.md §7.1a),
/// and the wider the steps the less of the curve holds it. Measured on the camera sweep (five tone
/// curves, two noise levels, BENCHMARKS.md "Real cameras"): worst shape error 0.93 % at 1.87×,
/// 2.8 % at 2.5× (a filmic S-curve), 13–15 % at 3.5× (S-curve; a log curve at 15 e⁻), and some
/// good dark brackets refused at 4× — while the same brackets through the true response are
/// within 1 %. So a response recovered from steps wider than this makes every channel suspect.
pub const MAX_STEP_RECOVERED: f64 = 2.6;

/// The bracket's overlap: consecutive exposures more than [`MAX_STEP_8BIT`] (8-bit frames through
/// a recovered or given response) or [`MAX_STEP_LINEAR`] (linear frames) apart, or a recovered
/// response from fewer than 3 frames, make every channel suspect: the merge then interpolates
/// across radiances no frame measured (a 2-frame bracket of 1/600 and 3 s measured
/// +712 % and was called ok).
pub fn bracket_reasons(m: &Measurement) -> Vec<Reason> {
    let limit = match m.hdr.response_kind {
        ResponseKind::Recovered | ResponseKind::Given => MAX_STEP_8BIT,
        ResponseKind::Linear => MAX_STEP_LINEAR,
        _ => return Vec::new(),
    };
    let mut times: Vec<f64> = m.hdr.frames.iter().map(|f| f.time_s).collect();
    times.sort_by(f64::total_cmp);
    let mut reasons = Vec::new();
    if m.hdr.response_kind == ResponseKind::Recovered && times.len() < 3 {
        reasons.push(suspect(
            ReasonKind::BracketGap,
            format!(
                "the camera response was recovered from {} frame(s): with fewer than 3 the \
                 recovery is barely constrained — take a bracket of 5 or more exposures, at most \
                 {MAX_STEP_8BIT:.0}× apart",
                times.len()
            ),
        ));
    }
    let mut steps: Vec<f64> = times
        .windows(2)
        .filter(|w| w[0] > 0.0 && w[1] > w[0])
        .map(|w| w[1] / w[0])
        .collect();
    steps.sort_by(f64::total_cmp);
    if m.hdr.response_kind == ResponseKind::Recovered
        && times.len() >= 3
        && let Some(&median) = steps.get(steps.len() / 2)
        && median > MAX_STEP_RECOVERED
    {
        reasons.push(suspect(
            ReasonKind::ResponseSteps,
            format!(
                "the camera response was recovered from exposures {median:.1}× apart ({:.1} \
                 stops): beyond {MAX_STEP_RECOVERED}× a recovered response can carry a ripple \
                 the bracket cannot see (up to 13 % in the profile's shape at 3.5× on a filmic \
                 tone curve) — shoot steps of 2× (1 stop) or less, give the camera's response \
                 (camera.response), or use linear 16-bit or RAW frames",
                median.log2()
            ),
        ));
    }
    let worst = times
        .windows(2)
        .filter(|w| w[0] > 0.0)
        .map(|w| (w[1] / w[0], w[0], w[1]))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((ratio, t0, t1)) = worst
        && ratio > limit
    {
        reasons.push(suspect(
            ReasonKind::BracketGap,
            format!(
                "consecutive exposures {} s and {} s are {ratio:.0}× apart (at most {limit:.0}× for \
                 {} frames): radiances between them are well exposed in no frame — add exposures \
                 in between",
                short(t0),
                short(t1),
                if limit == MAX_STEP_8BIT { "8-bit" } else { "linear" }
            ),
        ));
    }
    reasons
}

/// A shutter time for a message (4 significant digits).
pub(super) fn short(t: f64) -> String {
    format!("{t:.4}")
        .trim_end_matches('0')
        .trim_end_matches('.')
        .to_string()
}

/// How one frame of an 8-bit bracket agrees with the merged radiance ([`frame_agreement`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FrameAgreement {
    /// The frame's index (shortest first).
    pub frame: usize,
    /// Well-exposed samples compared.
    pub samples: usize,
    /// The median of g(z) − ln(E·Δt): the frame's exposure against the merge's (0 when it holds
    /// the light its time says), in natural log units.
    pub offset_ln: f64,
    /// The robust spread of g(z) − ln(E·Δt) about that median (1.4826 × the median absolute
    /// deviation): how far the frame's picture differs from the merged one in shape.
    pub spread_ln: f64,
}

/// Codes a frame's sample must lie within to be compared: away from the tone curve's toe, where
/// the response is least certain and one code is a large step in log exposure, and from clipping.
pub const AGREEMENT_CODES: (u8, u8) = (40, 230);

/// Well-exposed samples a frame needs for its agreement to be judged.
pub const AGREEMENT_MIN_SAMPLES: usize = 50;

/// A frame whose spread about the merge is larger than this (natural log units: 10 %) and four
/// times the bracket's median spread disagrees with the others in shape: a frame from elsewhere,
/// room light, a change in the scene. The quick twins' frames lie at 0.006–0.03.
pub const MAX_FRAME_SPREAD_LN: f64 = 0.10;

/// A frame whose median exposure is off the merge's by more than this (natural log units: a
/// factor 1.22 either way) after the bracket's own exposure estimate holds a different light: a
/// gain changed, a light switched on or off, a frame from another session.
pub const MAX_FRAME_OFFSET_LN: f64 = 0.20;

/// The merged radiance predicts every frame: per frame, g(z) − ln(E·Δt) over its well-exposed
/// samples (Debevec & Malik 1997, eq. 2, g(Z_ij) = ln E_i + ln Δt_j, read the other way: the
/// merge's E and the frame's time predict its codes). Computed on the frames' thumbnails (one
/// sample per block of the image, the block's centre: up to 96 × 96 per frame), against the
/// radiance at the same pixels. Only 8-bit brackets with their response, and without a dark or
/// flat frame (whose corrections the prediction would have to repeat); `None` otherwise.
pub fn frame_agreement(m: &Measurement) -> Option<Vec<FrameAgreement>> {
    let response = m.hdr.response.as_ref()?;
    if m.hdr.thumbnails.len() != m.hdr.frames.len()
        || m.hdr.corrections.flat.is_some()
        || m.manifest.camera.dark.is_some()
    {
        return None;
    }
    let radiance = &m.hdr.hdr.radiance;
    let clipped = &m.hdr.hdr.clipped;
    let (w, h) = (radiance.width(), radiance.height());
    let step = w.max(h).div_ceil(crate::hdr::THUMBNAIL_SIDE).max(1);
    let ch = radiance.channels().min(3);
    let tables = response.tables();
    let factors = m
        .hdr
        .corrections
        .exposure
        .as_ref()
        .filter(|_| m.hdr.corrections.exposure_applied)
        .map(|e| e.factor.clone());
    let mut out = Vec::new();
    for (j, (thumb, info)) in m.hdr.thumbnails.iter().zip(&m.hdr.frames).enumerate() {
        let t = info.time_s
            * factors
                .as_ref()
                .and_then(|f| f.get(j))
                .copied()
                .unwrap_or(1.0);
        if t.is_nan() || t <= 0.0 {
            continue;
        }
        let mut d = Vec::new();
        for ty in 0..thumb.height() {
            let y = (ty * step + step / 2).min(h - 1);
            for tx in 0..thumb.width() {
                let x = (tx * step + step / 2).min(w - 1);
                let (Some(z), Some(e), Some(cl)) = (
                    thumb.pixel(tx, ty),
                    radiance.pixel(x, y),
                    clipped.pixel(x, y),
                ) else {
                    continue;
                };
                for c in 0..ch {
                    let zc = z[c.min(z.len() - 1)];
                    let ec = f64::from(e[c]);
                    if zc < AGREEMENT_CODES.0
                        || zc > AGREEMENT_CODES.1
                        || cl[c] != 0
                        || ec.is_nan()
                        || ec <= 0.0
                    {
                        continue;
                    }
                    let g = &tables[c.min(tables.len() - 1)];
                    d.push(g[usize::from(zc)] - (ec * t).ln());
                }
            }
        }
        if d.len() < AGREEMENT_MIN_SAMPLES {
            continue;
        }
        let mid = d.len() / 2;
        let offset = *d.select_nth_unstable_by(mid, f64::total_cmp).1;
        let mut dev: Vec<f64> = d.iter().map(|v| (v - offset).abs()).collect();
        let mad = *dev.select_nth_unstable_by(mid, f64::total_cmp).1;
        out.push(FrameAgreement {
            frame: j,
            samples: d.len(),
            offset_ln: offset,
            spread_ln: 1.4826 * mad,
        });
    }
    Some(out)
}

/// Frames that the merged radiance does not predict ([`frame_agreement`],
/// [`MAX_FRAME_SPREAD_LN`], [`MAX_FRAME_OFFSET_LN`]): one reason naming them, for every channel.
pub fn frame_agreement_reasons(m: &Measurement) -> Vec<Reason> {
    let Some(frames) = frame_agreement(m) else {
        return Vec::new();
    };
    let mut spreads: Vec<f64> = frames.iter().map(|f| f.spread_ln).collect();
    if spreads.is_empty() {
        return Vec::new();
    }
    spreads.sort_by(f64::total_cmp);
    let typical = spreads[spreads.len() / 2];
    let bad: Vec<String> = frames
        .iter()
        .filter(|f| {
            (f.spread_ln > MAX_FRAME_SPREAD_LN && f.spread_ln > 4.0 * typical)
                || f.offset_ln.abs() > MAX_FRAME_OFFSET_LN
        })
        .map(|f| {
            let name = m.hdr.frames[f.frame]
                .file
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            format!(
                "frame {} ({}, {} s) holds {:.2}× the light the merge predicts, spread {:.0} % \
                 about it",
                f.frame,
                scatterfit_io::escape::one_line(&name),
                short(m.hdr.frames[f.frame].time_s),
                f.offset_ln.exp(),
                100.0 * f.spread_ln
            )
        })
        .collect();
    if bad.is_empty() {
        return Vec::new();
    }
    vec![suspect(
        ReasonKind::FrameDisagrees,
        format!(
            "the merged radiance does not predict every frame (the others agree within {:.0} %): \
             {} — a frame from another sample or session, a gain or light changed during the \
             bracket, or a frame repeated with the wrong time; remove or retake it",
            100.0 * typical,
            bad.join("; ")
        ),
    )]
}

/// The lowest JPEG quality (the IJG scale, estimated from the file's luminance quantisation
/// table) a bracket's frames may have before every channel is suspect. At libjpeg's default of
/// 75 and above the 8 × 8 blocks' quantisation stays within a code or two on a smooth profile;
/// at 50 a quick twin's σ′s moved by up to +36 % with every other check passing.
pub const MIN_JPEG_QUALITY: f64 = 75.0;

/// JPEG frames compressed below [`MIN_JPEG_QUALITY`]: one reason naming the lowest.
pub fn compression_reasons(m: &Measurement) -> Vec<Reason> {
    let worst = m
        .hdr
        .frames
        .iter()
        .filter_map(|f| f.jpeg_quality.map(|q| (q, f)))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    match worst {
        Some((q, f)) if q < MIN_JPEG_QUALITY => vec![suspect(
            ReasonKind::Compression,
            format!(
                "the JPEG frames are compressed to quality {q:.0} (lowest: {}; at least \
                 {MIN_JPEG_QUALITY:.0} needed): the 8 × 8 blocks' quantisation changes the \
                 profile's codes by more than the noise — save the bracket as PNG, TIFF or RAW, \
                 or as JPEG at quality 90 or more",
                scatterfit_io::escape::one_line(
                    &f.file
                        .file_name()
                        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
                )
            ),
        )],
        _ => Vec::new(),
    }
}
