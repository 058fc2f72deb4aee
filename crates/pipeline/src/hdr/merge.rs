//! The merge proper, one function per kind of bracket: 8-bit frames through a given or recovered
//! response (Debevec \& Malik 1997), 16-bit and RAW frames as linear data; each checks and corrects
//! the exposure times from the frames and divides out a flat frame.

use super::*;

/// What both kinds of bracket are merged with.
pub(super) struct MergeContext<'a> {
    /// The exposure times as given \[s\], shortest first.
    pub(super) times: &'a [f64],
    pub(super) dark: Option<CameraFrame>,
    pub(super) flat: Option<&'a (PathBuf, CameraFrame)>,
    pub(super) inputs: &'a HdrInputs,
    /// The frames by time, for the order check's message.
    pub(super) order: &'a dyn Fn() -> String,
}

/// What a merge gives besides the frames' bookkeeping.
pub(super) struct Merged {
    pub(super) hdr: HdrImage,
    pub(super) response: Option<ResponseCurve>,
    pub(super) kind: ResponseKind,
    pub(super) rms: Vec<f64>,
    pub(super) detection_limit: Vec<f64>,
}

pub(super) fn imaging(
    context: &str,
) -> impl FnOnce(scatterfit_imaging::ImagingError) -> PipelineError + use<> {
    let context = context.to_string();
    move |source| PipelineError::Imaging { context, source }
}

/// 8-bit frames: the response given or recovered (Debevec & Malik 1997), the exposure times checked
/// and corrected from the frames, the merge, the flat frame, the detection limit.
pub(super) fn merge_8bit(
    bufs: Vec<ImageBuf<u8>>,
    cx: MergeContext<'_>,
    corrections: &mut Corrections,
) -> Result<Merged> {
    let t = Instant::now();
    let (bufs, stated, signal) = keep_frames_with_signal(bufs, cx.times, u8::MAX, corrections)
        .map_err(imaging(&(cx.order)()))?;
    corrections.time("frames with signal", t.elapsed().as_secs_f64());
    let stated: &[f64] = &stated;
    corrections
        .timed("order check", || {
            check_order(&bufs, stated, u8::MAX, signal.as_ref())
        })
        .map_err(imaging(&(cx.order)()))?;
    corrections.registration =
        Some(corrections.timed("registration", || super::frames::registration_8bit(&bufs)));
    let samples = cx
        .inputs
        .samples
        .unwrap_or_else(|| default_response_samples(bufs.len()));
    // The recovered response (unbiased for the mean of a pixel's readings: the merge), its
    // first-order toe (unbiased for their median: the exposure estimate's medians), the residuals.
    let recover = |t: &[f64]| -> Result<(ResponseCurve, ResponseCurve, Vec<f64>)> {
        // The order is checked above, once.
        let opts = CalibrateOptions::new(samples, cx.inputs.lambda)
            .map_err(imaging("the response recovery's options"))?
            .order_checked();
        let cal = scatterfit_imaging::recover_response(&bufs, t, &opts).map_err(
            imaging("recovering the camera response (or give a known one: --response for merge, camera.response in sample.toml for measure)"),
        )?;
        let rms = cal.solutions.iter().map(|s| s.rms_residual).collect();
        Ok((cal.response, cal.median_response, rms))
    };
    let (mut response, mut median_response, kind, mut rms) = match &cx.inputs.response {
        Some(path) => {
            let r = load_response(path)?;
            (r.clone(), r, ResponseKind::Given, Vec::new())
        }
        None => {
            let (r, m, rms) = corrections.timed("response recovery", || recover(stated))?;
            (r, m, ResponseKind::Recovered, rms)
        }
    };
    // The code pairs the noise-aware detection codes are measured on (below), counted once.
    let pair_counts = corrections.timed("detection codes", || PairCounts::new(&bufs));
    // Exposure times from the frames: ratios of linearised codes in the well-exposed range.
    let mut times_used = stated.to_vec();
    if cx.inputs.exposure_correction != ExposureCorrection::Never {
        let recovered = kind == ResponseKind::Recovered;
        let ch = bufs[0].channels();
        let n = bufs[0].data().len();
        for round in 0..if recovered { 4 } else { 1 } {
            // The median of the pixels' ratios: the median-unbiased linearisation.
            let lin: Vec<Vec<f64>> = median_response
                .tables()
                .iter()
                .map(|g| g.iter().map(|v| v.exp()).collect())
                .collect();
            let p = bufs.len();
            // The noise-aware detection code per channel: the expected exposure a pixel must have.
            let t = Instant::now();
            let det = detection_codes(&pair_counts, &times_used, &response);
            corrections.time("detection codes", t.elapsed().as_secs_f64());
            let t = Instant::now();
            let est = estimate_exposures(
                &times_used,
                n,
                &|j, i| {
                    let l = &lin[if lin.len() == 1 { 0 } else { i % ch }];
                    let floor = usize::from(det[i % ch]);
                    let z = bufs[j].data()[i];
                    if z == 0 || z > 230 {
                        return None;
                    }
                    // Well exposed (above the channel's noise-aware detection code) by what a
                    // third frame predicts, not by this frame's own code:
                    // selecting on the noisy code itself truncates its noise (pixels that noise
                    // lifted over the threshold kept, those it pushed under dropped) and biases the
                    // ratio of the pair it belongs to (frame j is compared with j ± 1, so frame
                    // j ± 2 is independent of both).
                    let r = if j + 2 < p {
                        j + 2
                    } else if j >= 2 {
                        j - 2
                    } else {
                        return (usize::from(z) >= floor).then(|| l[usize::from(z)]);
                    };
                    let zr = bufs[r].data()[i];
                    if zr == 0 || zr == u8::MAX {
                        return None;
                    }
                    let expected = l[usize::from(zr)] * times_used[j] / times_used[r];
                    (expected >= l[floor]).then(|| l[usize::from(z)])
                },
                recovered,
            );
            corrections.time("exposure estimate", t.elapsed().as_secs_f64());
            let apply = cx.inputs.exposure_correction == ExposureCorrection::Always
                || (round == 0 && est.max_correction > EXPOSURE_AUTO_THRESHOLD)
                || (round > 0 && corrections.exposure_applied);
            if round == 0 {
                check_exposure(&est, stated)?;
                corrections.exposure = Some(est.clone());
            }
            if !apply {
                break;
            }
            let next: Vec<f64> = times_used
                .iter()
                .zip(&est.factor)
                .map(|(t, f)| t * f)
                .collect();
            if !keeps_the_steps(stated, &next) {
                // A correction that would shrink a step of the bracket to less than half its
                // stated size (or reverse it) is not a shutter's error: a response recovered from
                // the same frames trades its own bend against the times, and on processed frames
                // (a compact camera's JPEGs at 1.4× steps) the rounds walked two frames past each
                // other. The times of the last good round are kept.
                break;
            }
            corrections.exposure_applied = true;
            times_used = next;
            if recovered {
                (response, median_response, rms) =
                    corrections.timed("response recovery", || recover(&times_used))?;
            }
            if est.max_correction < 2e-4 {
                break;
            }
        }
        if corrections.exposure_applied
            && let Some(e) = corrections.exposure.as_mut()
        {
            // Report the total correction against the nominal times.
            e.factor = times_used.iter().zip(stated).map(|(u, t)| u / t).collect();
            e.max_correction = e.factor.iter().map(|f| (f - 1.0).abs()).fold(0.0, f64::max);
        }
    }
    let dark = cx.dark.and_then(|d| match d {
        CameraFrame::U8(b) => Some(b),
        CameraFrame::U16(_) => None,
    });
    // The noise-aware detection codes: where the linearised signal reaches a signal-to-noise
    // ratio of DETECTION_SNR per pixel. A fraction of their exposure is the merge's expected-signal
    // floor: a frame counts at a pixel only where the radiance around it predicts at least that,
    // so that readings censored at code 0 do not lift faint pixels (imaging::merge's second pass).
    let codes = corrections.timed("detection codes", || {
        detection_codes(&pair_counts, &times_used, &response)
    });
    let mut floor = [DETECTION_CODE; 4];
    for (c, (f, &det)) in floor.iter_mut().zip(&codes).enumerate() {
        let g = &response.tables()[if response.channels() == 1 { 0 } else { c }];
        let x_floor = EXPECTED_FLOOR_FRACTION * g[usize::from(det)].exp();
        *f = (1..=det)
            .find(|&z| g[usize::from(z)].exp() >= x_floor)
            .unwrap_or(det);
    }
    corrections.expected_floor = Some(floor);
    let merge_with = |weighting: Weighting,
                      corrections: &mut Corrections|
     -> Result<(HdrImage, SelfConsistency)> {
        let opts = MergeOptions {
            clipped_fill: cx.inputs.clipped_fill,
            weighting,
            expected_floor: Some(floor),
        };
        let hdr = corrections
            .timed("merge", || {
                scatterfit_imaging::merge(&bufs, &times_used, &response, dark.as_ref(), &opts)
            })
            .map_err(imaging("merging the bracket"))?;
        // Scored at the stated times: the map must imply them.
        let score = corrections
            .timed("self-consistency", || {
                scatterfit_imaging::self_consistency_sampled(
                    &bufs,
                    stated,
                    &response,
                    &hdr,
                    CONSISTENCY_PIXELS,
                )
            })
            .map_err(imaging("scoring the merge's self-consistency"))?;
        Ok((hdr, score))
    };
    let (mut hdr, score, weighting) = if cx.inputs.weighting_auto && dark.is_none() {
        // The weighting whose noise model explains the frames: the noise-aware merge (noise
        // constant in the linear signal, a sensor's) unless the paper's hat, robust to a
        // processed camera's noise and to the response's errors near the ends, explains them
        // clearly better.
        // Chosen on the frames decimated to about CONSISTENCY_PIXELS pixels (every d-th pixel
        // of every d-th row: both merges and their scores at a fraction of the cost), then the
        // bracket merged once with the weighting chosen.
        let n_px = bufs[0].width() * bufs[0].height();
        let d = ((n_px as f64 / CONSISTENCY_PIXELS as f64).sqrt().ceil() as usize).max(1);
        if d == 1 {
            let (a, sa) = merge_with(Weighting::NoiseOptimal, corrections)?;
            let (b, sb) = merge_with(Weighting::DebevecHat, corrections)?;
            if sb.rms < AUTO_HAT_MARGIN * sa.rms {
                (b, sb, Weighting::DebevecHat)
            } else {
                (a, sa, Weighting::NoiseOptimal)
            }
        } else {
            let t = Instant::now();
            let small = decimate(&bufs, d)?;
            let score_on = |weighting: Weighting| -> Result<f64> {
                let opts = MergeOptions {
                    clipped_fill: cx.inputs.clipped_fill,
                    weighting,
                    expected_floor: Some(floor),
                };
                let hdr = scatterfit_imaging::merge(&small, &times_used, &response, None, &opts)
                    .map_err(imaging("merging the decimated bracket"))?;
                Ok(
                    scatterfit_imaging::self_consistency(&small, stated, &response, &hdr)
                        .map_err(imaging("scoring the decimated merge's self-consistency"))?
                        .rms,
                )
            };
            let (sa, sb) = (
                score_on(Weighting::NoiseOptimal)?,
                score_on(Weighting::DebevecHat)?,
            );
            corrections.time("weighting choice", t.elapsed().as_secs_f64());
            let w = if sb < AUTO_HAT_MARGIN * sa {
                Weighting::DebevecHat
            } else {
                Weighting::NoiseOptimal
            };
            let (h, s) = merge_with(w, corrections)?;
            (h, s, w)
        }
    } else {
        let w = if cx.inputs.weighting_auto {
            Weighting::NoiseOptimal
        } else {
            cx.inputs.weighting
        };
        let (h, s) = merge_with(w, corrections)?;
        (h, s, w)
    };
    if weighting == Weighting::DebevecHat {
        longest_frame_below_floor(
            &mut hdr,
            &bufs,
            &times_used,
            &response,
            dark.as_ref(),
            floor,
        );
    }
    corrections.weighting = Some(weighting);
    corrections.self_consistency = Some(score);
    if let Some((path, CameraFrame::U8(f))) = cx.flat {
        let lin = linearise_u8(f, &response);
        corrections.flat = Some(divide_flat(
            &mut hdr,
            path,
            f.width(),
            f.height(),
            f.channels(),
            lin,
        )?);
    }
    let t_max = times_used.iter().copied().fold(0.0f64, f64::max);
    let detection_limit = (0..hdr.radiance.channels())
        .map(|c| {
            let g = &response.tables()[if response.channels() == 1 { 0 } else { c }];
            g[usize::from(codes[c])].exp() / t_max
        })
        .collect();
    Ok(Merged {
        hdr,
        response: Some(response),
        kind,
        rms,
        detection_limit,
    })
}

/// The hat merge's faint pixels from the longest frame alone: where the longest exposure reads
/// below the expected-signal floor (`floor`, [`EXPECTED_FLOOR_FRACTION`] of the detection code's
/// exposure), every shorter frame is expected lower still, so by the rule of the noise-aware
/// merge's second pass (a frame counts only where its expected signal reaches the floor; the
/// longest always counts) the longest frame is the pixel's only reading: E = X(z)/Δt_max, a code 0
/// counting as X = 0 (a censored reading), less the dark frame's X.
///
/// Why: Debevec & Malik's eq. 6 drops code 0 and averages ln X(z) − ln Δt over the codes left with
/// the hat's weights, so a pixel dark in the longest frame but reading code 1–2 in a short one
/// (noise, or the 8 × 8 blocks' quantisation error of a JPEG frame, about 1 code at quality 95) is
/// put at X(1)/Δt_short — 100–1000 × its radiance. The auto weighting takes the hat for
/// compressed brackets (the quick pink-plastic twin saved by Pillow at quality 95–75: 1.3–1.5 code
/// values RMS self-consistency against the noise-aware merge's 3.0–3.7), and there the frame's far
/// corners (G: the 1–8-pixel rings at 18.1–18.3 mm) were lifted 90–200 × above the profile, past
/// the detection limit, into the fit: rms log residual 0.84 and `poor_fit` with G's σ′s within
/// 1.5 %; at quality 85 the rings from 15.7 mm out, and G's σ′s −9 %. Pixels at or above the floor
/// (every pixel of the rings the fit uses, whose longest-frame codes are near the detection code or
/// above, bar noise) keep the hat's estimate.
fn longest_frame_below_floor(
    hdr: &mut HdrImage,
    bufs: &[ImageBuf<u8>],
    times: &[f64],
    response: &ResponseCurve,
    dark: Option<&ImageBuf<u8>>,
    floor: [u8; 4],
) {
    let Some((j, &t_max)) = times.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)) else {
        return;
    };
    let longest = &bufs[j];
    let ch = longest.channels();
    let lin = linearise_u8(longest, response);
    let dark_lin = dark.map(|d| linearise_u8(d, response));
    let mask = hdr.clipped.data();
    let radiance = hdr.radiance.data_mut();
    if radiance.len() != lin.len() || mask.len() != lin.len() {
        return;
    }
    for (i, (e, &z)) in radiance.iter_mut().zip(longest.data()).enumerate() {
        // Flagged pixel-channels (no reading in any frame) keep their fill.
        if mask[i] == 0 && z < floor[(i % ch).min(3)] {
            let x = f64::from(lin[i]) - dark_lin.as_ref().map_or(0.0, |d| f64::from(d[i]));
            *e = (x.max(0.0) / t_max) as f32;
        }
    }
}

/// The pixels the merge's self-consistency is scored on
/// ([`scatterfit_imaging::self_consistency_sampled`]: a regular subsample of the pixels), and the
/// size the bracket is decimated to for choosing the weighting (`weighting_auto`): on the real
/// brackets of the corpus the score is within −0.2 … +1.4 % of the full one and every bracket keeps
/// the weighting the full merges chose (BENCHMARKS.md, "Real brackets"), at a fraction of the cost.
pub const CONSISTENCY_PIXELS: usize = 65_536;

/// [`HdrInputs::weighting_auto`] takes the paper's hat ([`Weighting::DebevecHat`]) over the
/// noise-aware weighting when the hat's merge is more self-consistent
/// ([`scatterfit_imaging::self_consistency`]) by more than this factor: the noise-aware weighting
/// is the twin camera's optimum (BENCHMARKS.md, "dim pixels": unbiased for dim pixels, where the
/// hat reads 2.5 % high), so it stays unless its noise model clearly fails to explain the frames
/// (processed JPEGs, phones; BENCHMARKS.md, "Real brackets"). On the twin the hat scores within
/// 2–3 % of it (1.62 against 1.66 code values), on the JPEG brackets of the corpus 5–36 % lower.
pub const AUTO_HAT_MARGIN: f64 = 0.95;

/// Every `d`-th pixel of every `d`-th row of each frame (a regular decimation, for choosing the
/// weighting on a sample of the bracket).
fn decimate(bufs: &[ImageBuf<u8>], d: usize) -> Result<Vec<ImageBuf<u8>>> {
    use rayon::prelude::*;
    bufs.par_iter()
        .map(|f| {
            let (w, h, ch) = (f.width(), f.height(), f.channels());
            let (sw, sh) = (w.div_ceil(d), h.div_ceil(d));
            let mut data = Vec::with_capacity(sw * sh * ch);
            for y in (0..h).step_by(d) {
                let row = &f.data()[y * w * ch..(y + 1) * w * ch];
                for x in (0..w).step_by(d) {
                    data.extend_from_slice(&row[x * ch..(x + 1) * ch]);
                }
            }
            ImageBuf::new(sw, sh, ch, data)
                .map_err(|e| PipelineError::Input(format!("decimating a frame: {e}")))
        })
        .collect()
}

/// True when every step of `corrected` (times by rank) keeps at least half the stated step in
/// log time: corrections move frames by a shutter's error, they do not merge or swap them.
fn keeps_the_steps(stated: &[f64], corrected: &[f64]) -> bool {
    stated.windows(2).zip(corrected.windows(2)).all(|(s, c)| {
        let (ls, lc) = ((s[1] / s[0]).ln(), (c[1] / c[0]).ln());
        lc >= 0.5 * ls
    })
}

/// Leaves out of the merge the frames that carry no signal ([`scatterfit_imaging::bracket_signal`]:
/// fewer than 0.1 % of their values above their noise floor and below the clip), noting them in
/// `corrections.no_signal` (indices by time); all frames are kept when fewer than two would remain.
/// Returns the frames and times kept, and their signal when every frame was kept (for the order
/// check; a frame left out changes the others' noise floors, measured from the frames kept).
#[allow(clippy::type_complexity)]
pub(super) fn keep_frames_with_signal<T>(
    bufs: Vec<ImageBuf<T>>,
    times: &[f64],
    max: T,
    corrections: &mut Corrections,
) -> std::result::Result<
    (
        Vec<ImageBuf<T>>,
        Vec<f64>,
        Option<scatterfit_imaging::BracketSignal>,
    ),
    scatterfit_imaging::ImagingError,
>
where
    T: Copy + PartialOrd + Default + Sync + Into<f64>,
{
    let signal = scatterfit_imaging::bracket_signal(&bufs, times, max)?;
    let kept = signal.has_signal.iter().filter(|&&s| s).count();
    if kept == bufs.len() || kept < 2 {
        return Ok((bufs, times.to_vec(), Some(signal)));
    }
    corrections.no_signal = (0..bufs.len()).filter(|&j| !signal.has_signal[j]).collect();
    let t = times
        .iter()
        .zip(&signal.has_signal)
        .filter_map(|(&t, &s)| s.then_some(t))
        .collect();
    let b = bufs
        .into_iter()
        .zip(&signal.has_signal)
        .filter_map(|(b, &s)| s.then_some(b))
        .collect();
    Ok((b, t, None))
}

/// The bracket's order check ([`scatterfit_imaging::check_bracket_order`]), with the frames'
/// signal when it is already measured.
fn check_order<T>(
    bufs: &[ImageBuf<T>],
    times: &[f64],
    max: T,
    signal: Option<&scatterfit_imaging::BracketSignal>,
) -> std::result::Result<(), scatterfit_imaging::ImagingError>
where
    T: Copy + PartialOrd + PartialEq + Default + Sync + Into<f64>,
    [T]: PartialEq,
{
    match signal {
        Some(s) => scatterfit_imaging::check_bracket_order_with_signal(bufs, times, max, s),
        None => scatterfit_imaging::check_bracket_order(bufs, times, max),
    }
}

/// 16-bit and RAW frames as linear data: saturation and codes, black level, exposure times, the
/// merge, the flat frame, the detection limit.
pub(super) fn merge_linear(
    bufs: Vec<ImageBuf<u16>>,
    raw: Option<RawInfo>,
    cx: MergeContext<'_>,
    corrections: &mut Corrections,
) -> Result<Merged> {
    if let Some(path) = &cx.inputs.response {
        return Err(PipelineError::Input(format!(
            "{}: a response curve applies to 8-bit frames; these frames are 16-bit and are \
             merged as linear data — drop --response (or camera.response in the manifest)",
            path.display()
        )));
    }
    let saturation = match raw {
        Some(r) if !cx.inputs.saturation_given => {
            (r.levels.white.min(f64::from(u16::MAX)) as u16).max(2)
        }
        _ => cx.inputs.saturation,
    };
    // The codes the frames use (8- or 12-bit data in 16-bit files; hdr::frames); a stated
    // saturation is used as stated.
    let code_range = raw
        .is_none()
        .then(|| super::frames::code_range(&bufs, saturation))
        .transpose()?
        .map(|c| {
            if cx.inputs.saturation_given {
                super::frames::CodeRange {
                    saturation,
                    plateau_found: false,
                    ..c
                }
            } else {
                c
            }
        });
    let saturation = code_range.as_ref().map_or(saturation, |c| c.saturation);
    let (bufs, stated, signal) = keep_frames_with_signal(bufs, cx.times, saturation, corrections)
        .map_err(imaging(&(cx.order)()))?;
    let stated: &[f64] = &stated;
    check_order(&bufs, stated, saturation, signal.as_ref()).map_err(imaging(&(cx.order)()))?;
    corrections.registration = Some(super::frames::registration(
        bufs.len(),
        bufs[0].width(),
        bufs[0].height(),
        bufs[0].channels(),
        &|j, i| f64::from(bufs[j].data()[i]) / f64::from(saturation),
    ));
    let dark = cx.dark.and_then(|d| match d {
        CameraFrame::U16(b) => Some(b),
        CameraFrame::U8(_) => None,
    });
    let ch = bufs[0].channels();
    // The far corners' straight line in exposure time: the black level where nothing else gives
    // it, the check of a stated one, and the ambient-light check's evidence (light that changed
    // during the bracket bends it).
    let corners = {
        let refs: Vec<&ImageBuf<u16>> = bufs.iter().collect();
        estimate_black_level(&refs, stated, saturation)
    };
    // The black level: a dark frame is subtracted pixel by pixel (as before); otherwise a level
    // per channel from the settings, the RAW metadata or the far corners.
    let black: Option<(Vec<f64>, &'static str)> = if dark.is_some() {
        None
    } else {
        match &cx.inputs.black_level {
            BlackLevel::None => None,
            BlackLevel::Given(v) => Some((
                (0..ch)
                    .map(|c| v[if v.len() == 1 { 0 } else { c.min(v.len() - 1) }])
                    .collect(),
                "given",
            )),
            BlackLevel::Auto => match raw {
                Some(r) => Some((r.levels.black[..ch.min(3)].to_vec(), "metadata")),
                None => corners
                    .level
                    .iter()
                    .any(|l| *l >= 1.0)
                    .then(|| (corners.level.clone(), "far corners")),
            },
        }
    };
    // A level stated rather than read off the bracket is checked against the far corners'
    // intercept: a wrong level shifts every dim ring by a constant and bends the profile's tail.
    let stated_black: Option<(Vec<f64>, &'static str)> = match (&dark, &black) {
        (Some(d), _) => {
            let corners = crate::camera::corner_pixels(d.width(), d.height(), 1);
            let dch = d.channels();
            Some((
                (0..dch.min(ch))
                    .map(|c| {
                        corners
                            .iter()
                            .map(|&p| f64::from(d.data()[p * dch + c]))
                            .sum::<f64>()
                            / corners.len().max(1) as f64
                    })
                    .collect(),
                "dark frame",
            ))
        }
        (None, Some((b, source))) if *source != "far corners" => Some((b.clone(), *source)),
        (None, None) if cx.inputs.black_level == BlackLevel::None => Some((vec![0.0; ch], "none")),
        _ => None,
    };
    if let Some((levels, source)) = stated_black {
        corrections.black_level_check = Some(crate::hdr::BlackLevelCheck {
            source,
            stated: levels,
            corners: corners.level.clone(),
            corners_stderr: corners.level_stderr.clone(),
            saturation: f64::from(saturation),
            clipped_at_zero: corners.zero_fraction > 0.01,
        });
    }
    corrections.corners = Some(corners);
    let black_of = |c: usize| black.as_ref().map_or(0.0, |(b, _)| b[c]);
    // Exposure times from the frames: ratios of the linear values in the well-exposed range.
    let mut times_used = stated.to_vec();
    if cx.inputs.exposure_correction != ExposureCorrection::Never {
        let n = bufs[0].data().len();
        let sat = f64::from(saturation);
        let est = estimate_exposures(
            stated,
            n,
            &|j, i| {
                let b = black_of(i % ch);
                let v = f64::from(bufs[j].data()[i]);
                let d = dark.as_ref().map_or(b, |d| f64::from(d.data()[i]));
                (v >= d + 0.02 * (sat - d) && v <= d + 0.8 * (sat - d)).then_some(v - d)
            },
            false,
        );
        // A pedestal left in (or taken out twice) makes the short frames look too bright (or too
        // dark) for their times: where the black level disagrees with the corners, say so first.
        check_exposure(&est, stated).map_err(|e| match (e, &corrections.black_level_check) {
            (PipelineError::Imaging { context, source }, Some(b)) => PipelineError::Imaging {
                context: match b.disagreement() {
                    Some(m) => format!("{context} ({m})"),
                    None => context,
                },
                source,
            },
            (e, _) => e,
        })?;
        let apply = cx.inputs.exposure_correction == ExposureCorrection::Always
            || est.max_correction > EXPOSURE_AUTO_THRESHOLD;
        if apply {
            for (t, f) in times_used.iter_mut().zip(&est.factor) {
                *t *= f;
            }
        }
        corrections.exposure = Some(est);
        corrections.exposure_applied = apply;
    }
    let mut hdr = match &black {
        Some((b, _)) => scatterfit_imaging::merge_linear_black(
            &bufs,
            &times_used,
            b,
            saturation,
            cx.inputs.clipped_fill,
        )
        .map_err(imaging("merging the linear bracket less its black level"))?,
        None => {
            let opts = LinearMergeOptions::new(saturation, cx.inputs.clipped_fill)
                .map_err(imaging("the 16-bit merge's options"))?;
            scatterfit_imaging::merge_linear_u16(&bufs, &times_used, dark.as_ref(), &opts)
                .map_err(imaging("merging the 16-bit bracket"))?
        }
    };
    if let Some((path, CameraFrame::U16(f))) = cx.flat {
        let lin: Vec<f32> = f
            .data()
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let d = dark
                    .as_ref()
                    .map_or(black_of(i % ch), |d| f64::from(d.data()[i]));
                (f64::from(v) - d) as f32
            })
            .collect();
        corrections.flat = Some(divide_flat(&mut hdr, path, f.width(), f.height(), ch, lin)?);
    }
    corrections.black_level = black;
    corrections.codes = code_range;
    let t_max = times_used.iter().copied().fold(0.0f64, f64::max);
    let detection_limit = vec![DETECTION_DN_16BIT / t_max; hdr.radiance.channels()];
    Ok(Merged {
        hdr,
        response: None,
        kind: ResponseKind::Linear,
        rms: Vec::new(),
        detection_limit,
    })
}

/// Divides the radiance by a flat frame's smoothed, median-normalised linear values
/// ([`flat_divisor`]); returns the file and the divisor's range.
/// A flat frame's smoothed light may peak at most this many times its median: the brightest
/// middle of a lens vignetted to 10 % at the corners (the twin's strongest, `--vignetting 0.9`)
/// is about 1.6 × the median.
pub const FLAT_MAX_PEAK: f64 = 3.0;

/// A flat frame's smoothed light may fall to no less than this fraction of its median anywhere:
/// darker, the division multiplies the noise there by more than 20.
pub const FLAT_MIN_LOW: f64 = 0.05;

pub(super) fn divide_flat(
    hdr: &mut HdrImage,
    path: &Path,
    w: usize,
    h: usize,
    ch: usize,
    linear: Vec<f32>,
) -> Result<(PathBuf, f64, f64)> {
    let bad = || {
        PipelineError::Input(format!(
            "{}: the flat frame has no light (a frame of a uniform white target, exposed to \
             mid-range, is needed)",
            path.display()
        ))
    };
    let buf = ImageBuf::new(w, h, ch, linear).map_err(|_| bad())?;
    let div = flat_divisor(&buf).ok_or_else(bad)?;
    // A flat frame is a uniform white target seen through the lens: its smoothed light falls off
    // smoothly from the middle by the lens's vignetting, within a few times its median. A frame
    // that holds the spot (a frame of a bracket, another sample's picture) peaks far above it,
    // and one that is dark over part of the frame would divide that part by almost nothing.
    let peak = div.data().iter().copied().fold(0.0f32, f32::max);
    let low = div.data().iter().copied().fold(f32::INFINITY, f32::min);
    if f64::from(peak) > FLAT_MAX_PEAK || f64::from(low) < FLAT_MIN_LOW {
        return Err(PipelineError::Input(format!(
            "{}: not a flat frame — its light, smoothed, ranges from {:.3} to \
             {:.3} × its median, where a uniform white target seen through the lens stays within \
             {FLAT_MIN_LOW}–{FLAT_MAX_PEAK} × (vignetting falls off smoothly from the middle): \
             is it a frame of the bracket, of the spot, or of another scene? Photograph a \
             uniform white target at the bracket's lens settings, or drop camera.flat",
            path.display(),
            low,
            peak,
        )));
    }
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    let floor = 1e-3f32;
    let data: Vec<f32> = hdr
        .radiance
        .data()
        .iter()
        .zip(div.data())
        .map(|(&v, &d)| {
            lo = lo.min(f64::from(d));
            hi = hi.max(f64::from(d));
            v / d.max(floor)
        })
        .collect();
    if lo.is_nan() || lo <= 0.0 {
        return Err(bad());
    }
    hdr.radiance = ImageBuf::new(w, h, ch, data).map_err(|_| bad())?;
    Ok((path.to_path_buf(), lo, hi))
}

/// The code pairs of consecutive frames that [`detection_codes`] reads, counted once for the
/// bracket: per channel and pair of frames (j, j + 1), how many pixels read (z_j, z_{j+1}), both
/// unclipped (neither 0 nor 255); at most about 2.6·10⁵ pixels per frame pair are read (a 24-MP
/// frame is subsampled). The counts depend on the codes alone, so the response's rounds reuse
/// them.
pub(super) struct PairCounts {
    /// Per channel, per pair: the code pairs met and how often, (z_j, z_{j+1}, count), z_j
    /// ascending.
    cells: Vec<Vec<Vec<(u8, u8, u32)>>>,
}

impl PairCounts {
    pub(super) fn new(bufs: &[ImageBuf<u8>]) -> Self {
        use rayon::prelude::*;
        let ch = bufs[0].channels();
        let pairs = bufs.len().saturating_sub(1);
        let flat: Vec<Vec<(u8, u8, u32)>> = (0..ch * pairs)
            .into_par_iter()
            .map(|task| {
                let (c, j) = (task / pairs.max(1), task % pairs.max(1));
                let (a, b) = (bufs[j].data(), bufs[j + 1].data());
                // At most ~2.6·10⁵ pixels per pair: plenty for the per-code scatter.
                let step = (a.len() / ch / 262_144).max(1);
                let mut count = vec![0u32; 256 * 256];
                for i in (c..a.len()).step_by(ch * step) {
                    let (z1, z2) = (a[i], b[i]);
                    if z1 == 0 || z2 == u8::MAX || z1 == u8::MAX || z2 == 0 {
                        continue;
                    }
                    count[usize::from(z1) * 256 + usize::from(z2)] += 1;
                }
                count
                    .iter()
                    .enumerate()
                    .filter(|(_, n)| **n > 0)
                    .map(|(cell, &n)| ((cell / 256) as u8, (cell % 256) as u8, n))
                    .collect()
            })
            .collect();
        let mut cells: Vec<Vec<Vec<(u8, u8, u32)>>> = vec![Vec::with_capacity(pairs); ch];
        for (task, v) in flat.into_iter().enumerate() {
            cells[task / pairs.max(1)].push(v);
        }
        Self { cells }
    }
}

/// Per channel, the lowest code from [`DETECTION_CODE`] up from which the linearised signal's
/// relative noise stays within 1/[`DETECTION_SNR`] (codes 30–200 checked), measured on the bracket
/// itself in the manner of the photon-transfer method, which reads a sensor's noise from pairs of
/// frames (Janesick 2007, *Photon Transfer DN → λ*, SPIE Press, ch. 4): for every pair
/// of consecutive frames (exposure ratio k) and every pixel unclipped in both, q = ln X(z_{j+1}) −
/// ln X(z_j) − ln k; its scatter about its mean among the pixels with code z in the shorter frame
/// is σ²(z) + σ²(z_{j+1}) ≈ σ²(z)(1 + 1/k) for shot noise (the brighter reading's relative
/// variance a factor k smaller; for read noise it is 1 + 1/k², so σ is then overestimated by
/// ≤ 8 % for k ≈ 1.9), so σ²(z) = var(q | z)/(1 + 1/k). Codes with fewer than 50 pairs are
/// skipped; the pixels read are those of [`PairCounts`] (q depends on the two codes only, so
/// each code pair's q is weighted by its count).
fn detection_codes(counts: &PairCounts, times: &[f64], response: &ResponseCurve) -> Vec<u8> {
    use rayon::prelude::*;
    counts
        .cells
        .par_iter()
        .enumerate()
        .map(|(c, pairs)| {
            let g = &response.tables()[if response.channels() == 1 { 0 } else { c }];
            let (mut n, mut s1, mut s2) = ([0f64; 256], [0f64; 256], [0f64; 256]);
            let mut kk = 0.0f64;
            let mut n_pairs = 0.0f64;
            for (j, cells) in pairs.iter().enumerate() {
                let ln_k = (times[j + 1] / times[j]).ln();
                kk += ln_k;
                n_pairs += 1.0;
                for &(z1, z2, m) in cells {
                    let q = g[usize::from(z2)] - g[usize::from(z1)] - ln_k;
                    let (z, m) = (usize::from(z1), f64::from(m));
                    n[z] += m;
                    s1[z] += m * q;
                    s2[z] += m * q * q;
                }
            }
            let k = (kk / n_pairs.max(1.0)).exp();
            let limit = 1.0 / (DETECTION_SNR * DETECTION_SNR);
            let ok = |z: usize| {
                if n[z] < 50.0 {
                    return None;
                }
                let m = s1[z] / n[z];
                let var = (s2[z] / n[z] - m * m).max(0.0) / (1.0 + 1.0 / k);
                Some(var <= limit)
            };
            // The lowest code from DETECTION_CODE up above which no measured code is too noisy.
            let mut code = DETECTION_CODE;
            for z in usize::from(DETECTION_CODE)..=200 {
                if ok(z) == Some(false) {
                    code = (z + 1) as u8;
                }
            }
            code
        })
        .collect()
}
