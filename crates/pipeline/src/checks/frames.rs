//! The checks on the bracket's frames: the codes they use (8- or 12-bit data in
//! 16-bit files, the clipping plateau), their registration (the spot's centroid per frame) and the
//! bracket's overlap (consecutive exposures, frames for a recovered response).

use super::*;

/// The codes 16-bit frames use: the largest, the clipping plateau found below the nominal
/// saturation, and the bits that implies. A camera of 12 bits writing 16-bit files (values
/// 0…4095, or shifted to the top bits) clips at 4095 (or 65520), where a 65535 saturation would
/// take clipped pixels for light.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct CodeRange {
    /// The largest code in any frame.
    pub max_code: u16,
    /// Samples at `max_code` in the frame holding most of them.
    pub at_max: usize,
    /// Bits the codes span: ⌈log2(max_code + 1)⌉ (after removing a common power-of-two factor).
    pub bits: u32,
    /// The saturation the merge uses: the nominal one, or the plateau found below it.
    pub saturation: u16,
    /// True when the plateau replaced the nominal saturation.
    pub plateau_found: bool,
}

/// Samples at one code below the nominal saturation that make it a clipping plateau: at least
/// this many, and at least 10⁻⁴ of a frame's samples (a linear sensor's unclipped maximum is held
/// by a handful of samples; a clipped spot by hundreds).
pub const PLATEAU_MIN_SAMPLES: usize = 16;

/// Finds the codes 16-bit frames use ([`CodeRange`]).
///
/// # Errors
/// [`crate::PipelineError::Input`] for 8-bit frames scaled into 16 bits (every code a multiple of 257,
/// as an image editor converts): their tone curve is not linear, and merging them as linear data
/// would give wrong radiances.
pub fn code_range(
    frames: &[scatterfit_imaging::ImageBuf<u16>],
    saturation: u16,
) -> crate::Result<CodeRange> {
    let mut max_code = 0u16;
    let mut all_257 = true;
    let mut or_bits = 0u16;
    for f in frames {
        for &v in f.data() {
            max_code = max_code.max(v);
            all_257 &= v % 257 == 0;
            or_bits |= v;
        }
    }
    if all_257 && max_code > 255 {
        return Err(crate::PipelineError::Input(
            "the 16-bit frames hold 8-bit codes scaled by 257 (every value a multiple of 257: an \
             image editor's conversion): their tone curve is not linear and cannot be merged as \
             16-bit linear data — give the camera's 8-bit frames (or its 16-bit linear ones)"
                .into(),
        ));
    }
    let at_max = frames
        .iter()
        .map(|f| f.data().iter().filter(|&&v| v == max_code).count())
        .max()
        .unwrap_or(0);
    let samples = frames.first().map_or(0, |f| f.data().len());
    let plateau_found = max_code < saturation
        && max_code > 0
        && at_max >= PLATEAU_MIN_SAMPLES.max(samples / 10_000);
    let shift = or_bits.trailing_zeros().min(15);
    let bits = 16 - (max_code >> shift).leading_zeros();
    Ok(CodeRange {
        max_code,
        at_max,
        bits,
        saturation: if plateau_found { max_code } else { saturation },
        plateau_found,
    })
}

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

/// A stated black level may lie this far from the far corners' intercept, as a fraction of the
/// full scale, beyond five of the intercept's standard errors: 0.05 % (33 DN at 16 bits, 8 DN at
/// 14). A level off by 0.2 % of full scale moves σ′s and σa of the rig twin's linear camera by
/// about 9 %; one off by this much, by about 2 %.
pub const MAX_BLACK_LEVEL_OFFSET: f64 = 5e-4;

/// The black level subtracted from linear frames against the bracket's own evidence
/// ([`crate::hdr::BlackLevelCheck`]): suspect when a channel's stated level and the far corners'
/// intercept at Δt = 0 differ by more than five standard errors and
/// [`MAX_BLACK_LEVEL_OFFSET`] of the full scale. Silent when the corners clip at 0 (no pedestal
/// to read) or have no intercept.
pub fn black_level_reasons(b: &crate::hdr::BlackLevelCheck) -> Vec<Reason> {
    if b.clipped_at_zero {
        return Vec::new();
    }
    let off: Vec<String> = b
        .stated
        .iter()
        .zip(&b.corners)
        .zip(&b.corners_stderr)
        .enumerate()
        .filter(|(_, ((stated, corners), se))| {
            se.is_finite()
                && (*stated - *corners).abs()
                    > (5.0 * **se).max(MAX_BLACK_LEVEL_OFFSET * b.saturation)
        })
        .map(|(c, ((stated, corners), se))| {
            format!(
                "{} {stated:.0} DN against {corners:.0} ± {se:.1} DN",
                ["R", "G", "B", "A"].get(c).copied().unwrap_or("?")
            )
        })
        .collect();
    if off.is_empty() {
        return Vec::new();
    }
    let what = match b.source {
        "dark frame" => "the dark frame's level (its far corners' mean)",
        "metadata" => "the RAW file's black level",
        "none" => "camera.black_level = \"none\" (no pedestal)",
        _ => "camera.black_level",
    };
    vec![suspect(
        ReasonKind::BlackLevel,
        format!(
            "{what} disagrees with the level the bracket's far corners show at zero exposure \
             time ({}; more than 5 standard errors and {:.2} % of the full scale {:.0} DN apart): \
             every dim ring is off by the difference — check the black level (or the dark frame \
             was taken at other camera settings)",
            off.join(", "),
            100.0 * MAX_BLACK_LEVEL_OFFSET,
            b.saturation,
        ),
    )]
}

/// Where the spot is in each frame of a bracket, to see whether the camera moved.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Registration {
    /// Per frame (shortest first), the centroid [x, y] px of the pixels at least half the
    /// saturation (a radially symmetric spot's half-saturated disk is centred on the spot in every
    /// frame); `None` where fewer than [`REGISTRATION_MIN_PIXELS`] pixels are, or the disk touches
    /// the frame's edge.
    pub centroids: Vec<Option<[f64; 2]>>,
    /// The largest shift between two frames' centroids \[px\].
    pub max_shift_px: f64,
}

/// Pixels a frame's half-saturated disk needs for its centroid to count.
pub const REGISTRATION_MIN_PIXELS: usize = 12;

/// A shift between frames beyond this \[px\] makes every channel suspect: the rings of the merged
/// map then average light from two positions. The demo's frames agree to 0.18 px.
pub const MAX_FRAME_SHIFT_PX: f64 = 1.5;

/// The spot's centroid in each frame ([`Registration`]); `level(j, i)` is sample `i` of frame `j`
/// as a fraction of its saturation, `w × h` pixels of `ch` channels.
pub fn registration(
    frames: usize,
    w: usize,
    h: usize,
    ch: usize,
    level: &(dyn Fn(usize, usize) -> f64 + Sync),
) -> Registration {
    use rayon::prelude::*;
    // The frames in parallel.
    let centroids: Vec<Option<[f64; 2]>> = (0..frames)
        .into_par_iter()
        .map(|j| {
            let (mut n, mut sx, mut sy) = (0usize, 0.0, 0.0);
            let mut edge = false;
            for y in 0..h {
                for x in 0..w {
                    let i = (y * w + x) * ch;
                    let v = (0..ch).map(|c| level(j, i + c)).sum::<f64>() / ch as f64;
                    if v >= 0.5 {
                        n += 1;
                        sx += x as f64;
                        sy += y as f64;
                        edge |= x == 0 || y == 0 || x + 1 == w || y + 1 == h;
                    }
                }
            }
            (n >= REGISTRATION_MIN_PIXELS && !edge).then(|| [sx / n as f64, sy / n as f64])
        })
        .collect();
    let found: Vec<[f64; 2]> = centroids.iter().flatten().copied().collect();
    let mut max_shift_px = 0.0f64;
    for a in &found {
        for b in &found {
            max_shift_px = max_shift_px.max((a[0] - b[0]).hypot(a[1] - b[1]));
        }
    }
    Registration {
        centroids,
        max_shift_px,
    }
}

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

/// The IJG quality of a baseline JPEG's first (luminance) quantisation table: the mean ratio S of
/// its entries to the standard table of ITU-T T.81 Annex K (Table K.1) in percent, and quality
/// (200 − S)/2 for S ≤ 100, 5000/S above (libjpeg's `jpeg_quality_scaling`, inverted). `None` for
/// a file that is not a JPEG or whose table cannot be found in its first 64 KiB. Hand-written:
/// the image crate decodes JPEGs but does not expose their quantisation tables.
pub fn jpeg_quality(path: &std::path::Path) -> Option<f64> {
    use std::io::Read;
    // ITU-T T.81 Annex K, Table K.1 (luminance), in the zig-zag order a DQT segment stores.
    const K1_ZIGZAG: [u16; 64] = [
        16, 11, 12, 14, 12, 10, 16, 14, 13, 14, 18, 17, 16, 19, 24, 40, 26, 24, 22, 22, 24, 49, 35,
        37, 29, 40, 58, 51, 61, 60, 57, 51, 56, 55, 64, 72, 92, 78, 64, 68, 87, 69, 55, 56, 80,
        109, 81, 87, 95, 98, 103, 104, 103, 62, 77, 113, 121, 112, 100, 120, 92, 101, 103, 99,
    ];
    let mut head = Vec::new();
    std::fs::File::open(path)
        .ok()?
        .take(64 * 1024)
        .read_to_end(&mut head)
        .ok()?;
    if head.get(..2)? != [0xFF, 0xD8] {
        return None;
    }
    let mut i = 2;
    while i + 4 <= head.len() {
        if head[i] != 0xFF {
            return None;
        }
        let marker = head[i + 1];
        let len = usize::from(u16::from_be_bytes([head[i + 2], head[i + 3]]));
        if marker == 0xDB {
            let seg = head.get(i + 4..i + 2 + len)?;
            let (pq, tq) = (seg.first()? >> 4, seg.first()? & 0x0F);
            if tq != 0 {
                i += 2 + len;
                continue;
            }
            let q: Vec<u16> = if pq == 0 {
                seg.get(1..65)?.iter().map(|&v| u16::from(v)).collect()
            } else {
                seg.get(1..129)?
                    .chunks(2)
                    .map(|b| u16::from_be_bytes([b[0], b[1]]))
                    .collect()
            };
            let s = 100.0
                * q.iter()
                    .zip(K1_ZIGZAG)
                    .map(|(&a, b)| f64::from(a) / f64::from(b))
                    .sum::<f64>()
                / 64.0;
            return Some(if s <= 100.0 {
                (200.0 - s) / 2.0
            } else {
                5000.0 / s
            });
        }
        if marker == 0xDA {
            return None;
        }
        i += 2 + len;
    }
    None
}

/// JPEG frames compressed below [`MIN_JPEG_QUALITY`]: one reason naming the lowest.
pub fn compression_reasons(m: &Measurement) -> Vec<Reason> {
    let worst = m
        .hdr
        .frames
        .iter()
        .filter_map(|f| jpeg_quality(&f.file).map(|q| (q, f)))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A JPEG header whose luminance table libjpeg's `jpeg_quality_scaling` made for quality q
    /// (S = 5000/q below 50, 200 − 2q above; entries (K.1 · S + 50) / 100, at least 1) reads
    /// back as q within the table's rounding; a PNG, or a JPEG without a table, reads as none.
    #[test]
    fn the_jpeg_quality_comes_back_from_the_quantisation_table() {
        const K1_ZIGZAG: [u32; 64] = [
            16, 11, 12, 14, 12, 10, 16, 14, 13, 14, 18, 17, 16, 19, 24, 40, 26, 24, 22, 22, 24, 49,
            35, 37, 29, 40, 58, 51, 61, 60, 57, 51, 56, 55, 64, 72, 92, 78, 64, 68, 87, 69, 55, 56,
            80, 109, 81, 87, 95, 98, 103, 104, 103, 62, 77, 113, 121, 112, 100, 120, 92, 101, 103,
            99,
        ];
        let dir = tempfile::tempdir().unwrap();
        for q in [30u32, 50, 75, 90, 95] {
            let s = if q < 50 { 5000 / q } else { 200 - 2 * q };
            let mut bytes = vec![0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x04, 0x00, 0x00];
            bytes.extend([0xFF, 0xDB, 0x00, 67, 0x00]);
            bytes.extend(K1_ZIGZAG.map(|k| ((k * s + 50) / 100).clamp(1, 255) as u8));
            bytes.extend([0xFF, 0xDA, 0x00, 0x02]);
            let path = dir.path().join(format!("q{q}.jpg"));
            std::fs::write(&path, &bytes).unwrap();
            let got = jpeg_quality(&path).unwrap();
            assert!((got - f64::from(q)).abs() < 2.5, "quality {q}: read {got}");
        }
        let png = dir.path().join("f.png");
        std::fs::write(&png, b"\x89PNG\r\n\x1a\n....").unwrap();
        assert_eq!(jpeg_quality(&png), None);
        let bare = dir.path().join("bare.jpg");
        std::fs::write(&bare, [0xFF, 0xD8, 0xFF, 0xDA, 0x00, 0x02]).unwrap();
        assert_eq!(jpeg_quality(&bare), None);
    }
}
