//! The merge of an 8-bit bracket through a given or recovered response (Debevec & Malik 1997):
//! the exposure check and correction, the detection limit, the flat frame.

use super::detection::{PairCounts, detection_codes};
use super::flat::divide_flat;
use super::*;

/// 8-bit frames: the response given or recovered (Debevec & Malik 1997), the exposure times checked
/// and corrected from the frames, the merge, the flat frame, the detection limit.
pub(in crate::hdr) fn merge_8bit(
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
    // The sample pixels are chosen in the first recovery (from the codes alone, not the times)
    // and kept for the rounds with corrected times.
    let mut pixels: Option<Vec<Vec<scatterfit_imaging::SamplePixel>>> = None;
    let mut recover = |t: &[f64]| -> Result<(ResponseCurve, ResponseCurve, Vec<f64>)> {
        // The order is checked above, once.
        let mut opts = CalibrateOptions::new(samples, cx.inputs.lambda)
            .map_err(imaging("the response recovery's options"))?
            .order_checked();
        if let Some(p) = pixels.take() {
            opts = opts.with_sample_pixels(p);
        }
        let cal = scatterfit_imaging::recover_response(&bufs, t, &opts).map_err(
            imaging("recovering the camera response (or give a known one: --response for merge, camera.response in sample.toml for measure)"),
        )?;
        let rms = cal.solutions.iter().map(|s| s.rms_residual).collect();
        pixels = Some(cal.samples);
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
    // The decimated frames the weighting is chosen on, and the refit and the corrected times
    // judged (every d-th pixel of every d-th row, about CONSISTENCY_PIXELS pixels).
    let n_px = bufs[0].width() * bufs[0].height();
    let d = ((n_px as f64 / CONSISTENCY_PIXELS as f64).sqrt().ceil() as usize).max(1);
    let small_frames = if d == 1 {
        None
    } else {
        Some(decimate(&bufs, d)?)
    };
    let small: &[ImageBuf<u8>] = small_frames.as_deref().unwrap_or(&bufs);
    let at_stated = (response.clone(), rms.clone());
    if cx.inputs.exposure_correction != ExposureCorrection::Never {
        let recovered = kind == ResponseKind::Recovered;
        let ch = bufs[0].channels();
        // The exposure estimate reads every s-th pixel in raster order, at most EXPOSURE_PIXELS
        // (index i of the estimate: pixel (i / ch)·s, channel i % ch).
        let n_px = bufs[0].data().len() / ch;
        let s = n_px.div_ceil(EXPOSURE_PIXELS).max(1);
        let n = n_px.div_ceil(s) * ch;
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
                    let i = (i / ch) * s * ch + i % ch;
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
        if corrections.exposure_applied && cx.inputs.exposure_correction == ExposureCorrection::Auto
        {
            // Corrected times are kept only where they explain the frames better: the merge at
            // the corrected times (with the response recovered at them), scored at those times,
            // against the merge at the stated times. A response recovered from the same frames
            // trades its own bend against the times; on a processed camera's JPEGs the estimate
            // moved frames by 10–25 % into maps that explain the frames worse at any times
            // (BENCHMARKS.md, "Real brackets"), where a shutter's real error (the twin's) leaves
            // the corrected merge clearly better.
            let t = Instant::now();
            let best = |r: &ResponseCurve, t: &[f64]| -> Result<f64> {
                let mut best = f64::INFINITY;
                for weighting in [Weighting::NoiseOptimal, Weighting::DebevecHat] {
                    let opts = MergeOptions {
                        clipped_fill: cx.inputs.clipped_fill,
                        weighting,
                        expected_floor: None,
                    };
                    let hdr = scatterfit_imaging::merge(small, t, r, None, &opts)
                        .map_err(imaging("merging the decimated bracket"))?;
                    let score = scatterfit_imaging::self_consistency(small, t, r, &hdr)
                        .map_err(imaging("scoring the decimated merge's self-consistency"))?;
                    best = best.min(score.rms);
                }
                Ok(best)
            };
            let stated_score = best(&at_stated.0, stated)?;
            let corrected_score = best(&response, &times_used)?;
            corrections.exposure_judged = Some([stated_score, corrected_score]);
            // A score that is not a number (no well-exposed code) keeps the stated times.
            let better = corrected_score < EXPOSURE_KEEP_MARGIN * stated_score;
            if !better {
                corrections.exposure_applied = false;
                times_used = stated.to_vec();
                (response, rms) = at_stated;
            }
            corrections.time("exposure judged", t.elapsed().as_secs_f64());
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
    let ch = bufs[0].channels();
    let merge_with = |weights: &[Weighting],
                      response: &ResponseCurve,
                      corrections: &mut Corrections|
     -> Result<(HdrImage, SelfConsistency)> {
        let hdr = corrections
            .timed("merge", || {
                merge_by_channel(
                    &bufs,
                    &times_used,
                    response,
                    dark.as_ref(),
                    cx.inputs.clipped_fill,
                    floor,
                    weights,
                )
            })
            .map_err(imaging("merging the bracket"))?;
        // Scored at the stated times: the map must imply them.
        let score = corrections
            .timed("self-consistency", || {
                scatterfit_imaging::self_consistency_sampled(
                    &bufs,
                    stated,
                    response,
                    &hdr,
                    CONSISTENCY_PIXELS,
                )
            })
            .map_err(imaging("scoring the merge's self-consistency"))?;
        Ok((hdr, score))
    };
    let auto = cx.inputs.weighting_auto && dark.is_none();
    // The response is refitted to the merged map where it was recovered from these frames (not
    // given, no dark frame to subtract); the weighting chosen, and the refit judged, on the frames
    // decimated to about CONSISTENCY_PIXELS pixels (every d-th pixel of every d-th row: the merges
    // and their scores at a fraction of the cost), then the bracket merged once.
    let refit = kind == ResponseKind::Recovered && dark.is_none();
    let weights: Vec<Weighting> = if auto || refit {
        let t = Instant::now();
        let merge_small = |weights: &[Weighting],
                           response: &ResponseCurve|
         -> Result<(HdrImage, SelfConsistency)> {
            let hdr = merge_by_channel(
                small,
                &times_used,
                response,
                None,
                cx.inputs.clipped_fill,
                floor,
                weights,
            )
            .map_err(imaging("merging the decimated bracket"))?;
            let score = scatterfit_imaging::self_consistency(small, stated, response, &hdr)
                .map_err(imaging("scoring the decimated merge's self-consistency"))?;
            Ok((hdr, score))
        };
        // Per channel, the weighting whose noise model explains the frames: the noise-aware
        // merge (noise constant in the linear signal, a sensor's) unless the paper's hat, robust
        // to a processed camera's noise and to the response's errors near the ends, explains
        // them clearly better. Per channel, because a camera's processing treats them apart
        // (JPEG's chroma, a dark channel's gain): on a Canon JPEG bracket the hat explained red
        // and green 30–50 % better and blue 75 % worse (BENCHMARKS.md, "Real brackets").
        let (weights, chosen) = if auto {
            let a = merge_small(&vec![Weighting::NoiseOptimal; ch], &response)?;
            let b = merge_small(&vec![Weighting::DebevecHat; ch], &response)?;
            let weights: Vec<Weighting> = (0..ch)
                .map(|c| {
                    if b.1.per_channel[c] < AUTO_HAT_MARGIN * a.1.per_channel[c] {
                        Weighting::DebevecHat
                    } else {
                        Weighting::NoiseOptimal
                    }
                })
                .collect();
            let chosen = if weights.iter().all(|&w| w == Weighting::NoiseOptimal) {
                a
            } else if weights.iter().all(|&w| w == Weighting::DebevecHat) {
                b
            } else {
                merge_small(&weights, &response)?
            };
            (weights, chosen)
        } else {
            let w = vec![cx.inputs.weighting; ch];
            let chosen = merge_small(&w, &response)?;
            (w, chosen)
        };
        corrections.time("weighting choice", t.elapsed().as_secs_f64());
        if refit {
            // Rounds of refit and merge (Robertson et al.'s alternation) while each explains the
            // frames better by the margin.
            let t = Instant::now();
            let (mut hdr, first) = chosen;
            let first = first.rms;
            let mut score = first;
            for _ in 0..REFIT_ROUNDS {
                let refitted = scatterfit_imaging::refit_response_to_map(
                    small,
                    &times_used,
                    &response,
                    &hdr,
                    usize::MAX,
                )
                .map_err(imaging("refitting the response to the merged map"))?;
                let (next, after) = merge_small(&weights, &refitted)?;
                if after.rms >= REFIT_MARGIN * score {
                    break;
                }
                (response, hdr, score) = (refitted, next, after.rms);
                corrections.response_refit = Some([first, score]);
            }
            corrections.time("response refit", t.elapsed().as_secs_f64());
        }
        weights
    } else if cx.inputs.weighting_auto {
        vec![Weighting::NoiseOptimal; ch]
    } else {
        vec![cx.inputs.weighting; ch]
    };
    let (mut hdr, score) = merge_with(&weights, &response, corrections)?;
    if weights.contains(&Weighting::DebevecHat) {
        longest_frame_below_floor(
            &mut hdr,
            &bufs,
            &times_used,
            &response,
            dark.as_ref(),
            floor,
            &weights,
        );
    }
    corrections.weighting = weights;
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
    weights: &[Weighting],
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
        let c = i % ch;
        if mask[i] == 0 && weights.get(c) == Some(&Weighting::DebevecHat) && z < floor[c.min(3)] {
            let x = f64::from(lin[i]) - dark_lin.as_ref().map_or(0.0, |d| f64::from(d[i]));
            *e = (x.max(0.0) / t_max) as f32;
        }
    }
}

/// The pixels the exposure estimate reads ([`crate::camera::estimate_exposures`]): every s-th pixel
/// in raster order, s the smallest step that leaves at most this many (every pixel of a smaller
/// frame). Each adjacent pair's median log ratio then comes from up to 2·10⁵ values (three
/// channels), its standard error from their spread.
pub const EXPOSURE_PIXELS: usize = 65_536;

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

/// The bracket merged with a weighting per channel (`weights[c]`; [`MergeOptions::expected_floor`]
/// for the noise-aware channels): one merge when every channel has the same, else one per
/// weighting, each channel's radiance and mask taken from its own.
fn merge_by_channel(
    frames: &[ImageBuf<u8>],
    times: &[f64],
    response: &ResponseCurve,
    dark: Option<&ImageBuf<u8>>,
    clipped_fill: scatterfit_imaging::ClippedFill,
    floor: [u8; 4],
    weights: &[Weighting],
) -> std::result::Result<HdrImage, scatterfit_imaging::ImagingError> {
    let merge = |weighting: Weighting| {
        let opts = MergeOptions {
            clipped_fill,
            weighting,
            expected_floor: Some(floor),
        };
        scatterfit_imaging::merge(frames, times, response, dark, &opts)
    };
    let first = weights.first().copied().unwrap_or_default();
    if weights.iter().all(|&w| w == first) {
        return merge(first);
    }
    let mut out = merge(Weighting::NoiseOptimal)?;
    let hat = merge(Weighting::DebevecHat)?;
    let ch = out.radiance.channels();
    let from_hat = |i: usize| weights.get(i % ch) == Some(&Weighting::DebevecHat);
    for (i, (e, &h)) in out
        .radiance
        .data_mut()
        .iter_mut()
        .zip(hat.radiance.data())
        .enumerate()
    {
        if from_hat(i) {
            *e = h;
        }
    }
    for (i, (m, &h)) in out
        .clipped
        .data_mut()
        .iter_mut()
        .zip(hat.clipped.data())
        .enumerate()
    {
        if from_hat(i) {
            *m = h;
        }
    }
    out.clipped_count = out.clipped.data().iter().filter(|&&m| m != 0).count();
    Ok(out)
}

/// Exposure times corrected from the frames ([`ExposureCorrection::Auto`]) are kept only when the
/// decimated bracket's merge at them explains the frames better, at those times, than the merge at
/// the stated times does by more than this factor (the better of the two weightings each).
pub const EXPOSURE_KEEP_MARGIN: f64 = 0.98;

/// The merge keeps the response refitted to its map
/// ([`scatterfit_imaging::refit_response_to_map`]) when the refit's merge explains the decimated
/// frames better than the recovered curve's by more than this factor: the refit sees every pixel
/// where Debevec & Malik's recovery saw a hundred, and on real brackets it explains the frames
/// 2–16 % better (BENCHMARKS.md, "Real brackets"); on the twin, whose recovered curve is already
/// its camera's within the noise, it changes the score by less than 0.1 %, and the recovered curve
/// is kept.
pub const REFIT_MARGIN: f64 = 0.98;

/// Most rounds of refit and merge ([`REFIT_MARGIN`] ends them sooner).
pub const REFIT_ROUNDS: usize = 3;

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

#[cfg(test)]
mod tests {
    use super::*;

    /// Three channels of a ramp bracket merged [noise-aware, hat, noise-aware]: each channel is
    /// the one its weighting's whole merge gives (the two merges differ, so a channel taken from
    /// the wrong one fails).
    #[test]
    fn each_channel_comes_from_its_own_weighting() {
        let (w, h, ch) = (64usize, 8usize, 3usize);
        let times = [0.25, 1.0, 4.0];
        let frames: Vec<ImageBuf<u8>> = times
            .iter()
            .map(|t| {
                let data = (0..w * h * ch)
                    .map(|i| {
                        let x = (i / ch) % w;
                        let v = 255.0
                            * (t * (x + 1) as f64 / 64.0 / (1.0 + t * (x + 1) as f64 / 64.0))
                                .powf(0.45);
                        // A little per-channel noise-like texture so the weightings disagree.
                        (v + ((i * 7919) % 5) as f64 - 2.0).clamp(0.0, 255.0) as u8
                    })
                    .collect();
                ImageBuf::new(w, h, ch, data).unwrap()
            })
            .collect();
        let response = ResponseCurve::linear(ch).unwrap();
        let merge = |weights: &[Weighting]| {
            merge_by_channel(
                &frames,
                &times,
                &response,
                None,
                scatterfit_imaging::ClippedFill::Nan,
                [1; 4],
                weights,
            )
            .unwrap()
        };
        let no = merge(&[Weighting::NoiseOptimal; 3]);
        let hat = merge(&[Weighting::DebevecHat; 3]);
        let mixed = merge(&[
            Weighting::NoiseOptimal,
            Weighting::DebevecHat,
            Weighting::NoiseOptimal,
        ]);
        let same = |a: f32, b: f32| a == b || (a.is_nan() && b.is_nan());
        let mut differ = 0;
        for (i, &e) in mixed.radiance.data().iter().enumerate() {
            let want = if i % ch == 1 {
                hat.radiance.data()[i]
            } else {
                no.radiance.data()[i]
            };
            assert!(
                same(e, want),
                "value {i} (channel {}): {e} against {want}",
                i % ch
            );
            differ += usize::from(!same(no.radiance.data()[i], hat.radiance.data()[i]));
        }
        assert!(
            differ > 0,
            "the two weightings gave the same map: the test shows nothing"
        );
        let flagged = mixed.clipped.data().iter().filter(|&&m| m != 0).count();
        assert_eq!(mixed.clipped_count, flagged);
    }
}
