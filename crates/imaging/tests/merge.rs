//! HDR merge: refusals, linear 16-bit merge, dark frames.

use scatterfit_imaging::{
    CLIPPED_HIGH, CLIPPED_LOW, ClippedFill, ImageBuf, ImagingError, LinearMergeOptions,
    MergeOptions, ResponseCurve, Weighting, merge, merge_linear_u16,
};

fn frames_u8(n: usize) -> Vec<ImageBuf<u8>> {
    (0..n)
        .map(|j| ImageBuf::filled(4, 3, 3, 50 + j as u8).unwrap())
        .collect()
}

/// Every refusal of bad input: fewer than 2 frames, a time per frame, positive and distinct times,
/// same shapes, a response with the images' channel count, a dark frame of the right shape.
#[test]
fn merge_refuses_bad_brackets() {
    let resp = ResponseCurve::linear(3).unwrap();
    let opts = MergeOptions::default();
    let f = frames_u8(3);
    let e = |r: Result<_, ImagingError>| r.unwrap_err();
    assert!(matches!(
        e(merge(&f[..1], &[1.0], &resp, None, &opts)),
        ImagingError::TooFewFrames { got: 1 }
    ));
    assert!(matches!(
        e(merge(&f, &[1.0, 2.0], &resp, None, &opts)),
        ImagingError::TimeCountMismatch { .. }
    ));
    assert!(matches!(
        e(merge(&f, &[1.0, 0.0, 2.0], &resp, None, &opts)),
        ImagingError::NonPositiveTime { index: 1, .. }
    ));
    assert!(matches!(
        e(merge(&f, &[1.0, f64::NAN, 2.0], &resp, None, &opts)),
        ImagingError::NonPositiveTime { index: 1, .. }
    ));
    assert!(matches!(
        e(merge(&f, &[1.0, 2.0, 1.0], &resp, None, &opts)),
        ImagingError::DuplicateTime {
            first: 0,
            second: 2,
            ..
        }
    ));
    let mut g = frames_u8(2);
    g.push(ImageBuf::filled(4, 3, 1, 9u8).unwrap());
    let err = e(merge(&g, &[1.0, 2.0, 3.0], &resp, None, &opts));
    assert!(
        matches!(err, ImagingError::ShapeMismatch { ref what, .. } if what == "frame 2"),
        "{err}"
    );
    let resp2 = ResponseCurve::linear(2).unwrap();
    assert!(matches!(
        e(merge(&f, &[1.0, 2.0, 3.0], &resp2, None, &opts)),
        ImagingError::ChannelMismatch { .. }
    ));
    let dark = ImageBuf::filled(5, 3, 3, 0u8).unwrap();
    assert!(matches!(
        e(merge(&f, &[1.0, 2.0, 3.0], &resp, Some(&dark), &opts)),
        ImagingError::ShapeMismatch { .. }
    ));
    // A one-channel response is applied to all channels.
    assert!(
        merge(
            &f,
            &[1.0, 2.0, 3.0],
            &ResponseCurve::linear(1).unwrap(),
            None,
            &opts
        )
        .is_ok()
    );
    let u: Vec<ImageBuf<u16>> = (0..2)
        .map(|_| ImageBuf::filled(4, 3, 1, 9u16).unwrap())
        .collect();
    let lin = LinearMergeOptions::default();
    assert!(matches!(
        e(merge_linear_u16(&u, &[1.0, 1.0], None, &lin)),
        ImagingError::DuplicateTime { .. }
    ));
    // A saturation below 2 cannot even be put into the options.
    assert!(matches!(
        LinearMergeOptions::new(1, ClippedFill::Nan),
        Err(ImagingError::InvalidOption { .. })
    ));
}

/// Linear 16-bit data with a dark offset: E·Δt + dark, rounded and clipped at 60 000 (a sensor that
/// clips below 65 535). With the dark frame subtracted the merge returns E in counts per second to
/// 0.1 % wherever some frame has ≥ 1000 counts of signal; without it, a pixel of 2 counts/s is
/// biased far upwards (check that the subtraction matters). Saturated-everywhere pixels are
/// flagged high, with the documented lower bound (59 999 − dark)/Δt_min as fill.
#[test]
fn linear_u16_merge_with_dark_frame() {
    let (w, h) = (64, 8);
    let times = [0.001, 0.01, 0.1, 1.0];
    let e = |x: usize, y: usize| -> f64 {
        if y == 0 {
            1e9
        } else {
            2.0 * 10f64.powf(7.0 * x as f64 / (w - 1) as f64)
        }
    };
    let dark_v = |x: usize, y: usize| -> u16 { 400 + ((x * 7 + y * 13) % 50) as u16 };
    let sat = 60_000u16;
    let frames: Vec<ImageBuf<u16>> = times
        .iter()
        .map(|t| {
            let data = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| {
                    (e(x, y) * t + f64::from(dark_v(x, y)))
                        .round()
                        .min(f64::from(sat)) as u16
                })
                .collect();
            ImageBuf::new(w, h, 1, data).unwrap()
        })
        .collect();
    let dark = ImageBuf::new(
        w,
        h,
        1,
        (0..h)
            .flat_map(|y| (0..w).map(move |x| dark_v(x, y)))
            .collect(),
    )
    .unwrap();
    let opts = LinearMergeOptions::new(sat, ClippedFill::LowerBound).unwrap();
    let hdr = merge_linear_u16(&frames, &times, Some(&dark), &opts).unwrap();
    for y in 1..h {
        for x in 0..w {
            let truth = e(x, y);
            if truth * times[3] < 1000.0 {
                continue;
            }
            let got = f64::from(hdr.radiance.pixel(x, y).unwrap()[0]);
            assert!(
                (got / truth - 1.0).abs() < 1e-3,
                "({x},{y}): {got} vs {truth}"
            );
        }
    }
    for x in 0..w {
        assert_eq!(hdr.clipped.pixel(x, 0).unwrap()[0], CLIPPED_HIGH);
        let bound = f64::from(hdr.radiance.pixel(x, 0).unwrap()[0]);
        let expected = (f64::from(sat - 1) - f64::from(dark_v(x, 0))) / times[0];
        assert!((bound / expected - 1.0).abs() < 1e-5);
    }
    assert_eq!(hdr.clipped_count, w);
    let no_dark = merge_linear_u16(&frames, &times, None, &opts).unwrap();
    let biased = f64::from(no_dark.radiance.pixel(0, 3).unwrap()[0]);
    assert!(
        biased > 100.0,
        "without the dark frame a 2 counts/s pixel reads {biased}"
    );
}

/// 8-bit dark frame with a linear response X(z) = z/128: subtracting in the linearised domain
/// recovers E, a pixel at the dark level in every frame is flagged low, and without the dark frame
/// the result is biased.
#[test]
fn u8_dark_frame_is_subtracted_in_linear_domain() {
    let times = [0.25, 0.5, 1.0, 2.0];
    let dark_code = 20.0f64;
    // E in units of X per second; Z = round(128·(E·Δt) + dark).
    let es = [0.05f64, 0.2, 0.6, 0.0];
    let frames: Vec<ImageBuf<u8>> = times
        .iter()
        .map(|t| {
            let data = es
                .iter()
                .map(|e| (128.0 * e * t + dark_code).round().min(255.0) as u8)
                .collect();
            ImageBuf::new(4, 1, 1, data).unwrap()
        })
        .collect();
    let dark = ImageBuf::filled(4, 1, 1, dark_code as u8).unwrap();
    let resp = ResponseCurve::linear(1).unwrap();
    let hdr = merge(
        &frames,
        &times,
        &resp,
        Some(&dark),
        &MergeOptions::default(),
    )
    .unwrap();
    for (x, e) in es.iter().enumerate().take(3) {
        let got = f64::from(hdr.radiance.pixel(x, 0).unwrap()[0]);
        // Quantisation: ±0.5 code over ≥ 12 codes of signal in the best frames.
        assert!((got / e - 1.0).abs() < 0.03, "pixel {x}: {got} vs {e}");
    }
    assert_eq!(hdr.clipped.pixel(3, 0).unwrap()[0], CLIPPED_LOW);
    assert!(hdr.radiance.pixel(3, 0).unwrap()[0].is_nan());
    let raw = merge(&frames, &times, &resp, None, &MergeOptions::default()).unwrap();
    assert!(f64::from(raw.radiance.pixel(0, 0).unwrap()[0]) > 2.0 * es[0]);
}

/// The merge formula itself, on a 2-frame, 1-pixel bracket computed by hand (Debevec & Malik 1997,
/// eq. 6): Z = (64, 200), Δt = (1, 4), g(z) = ln(z/128) ⇒ ln E = [64(ln ½ − 0) + 55(ln(200/128) − ln 4)]/119.
#[test]
fn merge_formula_by_hand() {
    let f = vec![
        ImageBuf::new(1, 1, 1, vec![64u8]).unwrap(),
        ImageBuf::new(1, 1, 1, vec![200u8]).unwrap(),
    ];
    let hdr = merge(
        &f,
        &[1.0, 4.0],
        &ResponseCurve::linear(1).unwrap(),
        None,
        &hat(),
    )
    .unwrap();
    let ln_e = (64.0 * 0.5f64.ln() + 55.0 * ((200.0f64 / 128.0).ln() - 4.0f64.ln())) / 119.0;
    let got = f64::from(hdr.radiance.data()[0]);
    assert!(
        (got / ln_e.exp() - 1.0).abs() < 1e-6,
        "{got} vs {}",
        ln_e.exp()
    );
    assert_eq!(hdr.clipped_count, 0);
}

fn hat() -> MergeOptions {
    MergeOptions {
        weighting: Weighting::DebevecHat,
        ..Default::default()
    }
}

/// The noise-aware merge by hand (Robertson, Borman & Stevenson 2003: E = Σ u Δt X / Σ u Δt², with
/// u(z) = 1 up to code 128 and the hat's (255 − z)/127 above) on the same bracket: X = z/128,
/// Z = (64, 200), Δt = (1, 4), u = (1, 55/127) ⇒ E = (0.5 + 4u₂·200/128)/(1 + 16u₂). A code-0 sample
/// counts as X = 0 with u = 1: adding a frame Δt = 0.5 at code 0 adds 0.25 to the denominator.
#[test]
fn noise_aware_formula_by_hand() {
    let one = |z: u8| ImageBuf::new(1, 1, 1, vec![z]).unwrap();
    let resp = ResponseCurve::linear(1).unwrap();
    let opts = MergeOptions::default();
    assert_eq!(opts.weighting, Weighting::NoiseOptimal);
    let hdr = merge(&[one(64), one(200)], &[1.0, 4.0], &resp, None, &opts).unwrap();
    let u2 = 55.0 / 127.0;
    let expected = (0.5 + 4.0 * u2 * 200.0 / 128.0) / (1.0 + 16.0 * u2);
    let got = f64::from(hdr.radiance.data()[0]);
    assert!((got / expected - 1.0).abs() < 1e-6, "{got} vs {expected}");
    let hdr = merge(
        &[one(0), one(64), one(200)],
        &[0.5, 1.0, 4.0],
        &resp,
        None,
        &opts,
    )
    .unwrap();
    let expected = (0.5 + 4.0 * u2 * 200.0 / 128.0) / (1.25 + 16.0 * u2);
    let got = f64::from(hdr.radiance.data()[0]);
    assert!((got / expected - 1.0).abs() < 1e-6, "{got} vs {expected}");
    // Zero in every frame, or saturated in every frame: no estimate, flagged (beside a pixel that
    // has one: a map with no estimate at all is refused, see `all_clipped_map_is_refused`).
    let two = |z: u8| ImageBuf::new(2, 1, 1, vec![z, 100]).unwrap();
    let hdr = merge(&[two(0), two(0)], &[1.0, 4.0], &resp, None, &opts).unwrap();
    assert_eq!(hdr.clipped.data(), &[CLIPPED_LOW, 0]);
    assert!(hdr.radiance.data()[0].is_nan());
    let hdr = merge(&[two(255), two(255)], &[1.0, 4.0], &resp, None, &opts).unwrap();
    assert_eq!(hdr.clipped.data()[0], CLIPPED_HIGH);
}

/// Regression: a bracket saturated (or black) everywhere gave an all-NaN map and exit 0. Now fewer
/// than `MIN_VALID_FRACTION` of a channel's pixels with an estimate is a failed measurement naming
/// the channel and what to change; 0.1 % valid pixels is still a map.
#[test]
fn all_clipped_map_is_refused() {
    let resp = ResponseCurve::linear(3).unwrap();
    let opts = MergeOptions::default();
    let (w, h) = (50, 40);
    let frame = |v: u8| ImageBuf::filled(w, h, 3, v).unwrap();
    for (v, needle) in [(255u8, "overexposed"), (0, "too dark")] {
        let err = merge(&[frame(v), frame(v)], &[1.0, 2.0], &resp, None, &opts).unwrap_err();
        assert!(err.is_failed_measurement(), "{err:?}");
        assert!(
            matches!(
                err,
                ImagingError::NoValidRadiance {
                    channel: 0,
                    valid: 0,
                    total: 2000,
                    ..
                }
            ),
            "{err:?}"
        );
        assert!(err.to_string().contains(needle), "{err}");
    }
    // Two valid pixels of 2000 (0.1 %) in every channel: accepted.
    let mut f = frame(255);
    f.data_mut()[..6].fill(100);
    assert!(merge(&[f.clone(), f], &[1.0, 2.0], &resp, None, &opts).is_ok());
    // The 16-bit linear merge refuses the same way.
    let u = |v: u16| ImageBuf::filled(w, h, 1, v).unwrap();
    let err = merge_linear_u16(
        &[u(65535), u(65535)],
        &[1.0, 2.0],
        None,
        &LinearMergeOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, ImagingError::NoValidRadiance { .. }),
        "{err:?}"
    );
}

/// Regression: a dark frame brighter than the bracket wrote an all-NaN map. It is refused before the
/// merge (bad input, not a failed measurement), for 8- and 16-bit data; a dark frame below the
/// signal where the spot is, equal to it elsewhere, is accepted.
#[test]
fn dark_frame_at_or_above_the_signal_is_refused() {
    let resp = ResponseCurve::linear(1).unwrap();
    let opts = MergeOptions::default();
    let (w, h) = (40, 30);
    let frames: Vec<ImageBuf<u8>> = [30u8, 60]
        .iter()
        .map(|&v| ImageBuf::filled(w, h, 1, v).unwrap())
        .collect();
    let times = [1.0, 2.0];
    for dark_level in [60u8, 200] {
        let dark = ImageBuf::filled(w, h, 1, dark_level).unwrap();
        let err = merge(&frames, &times, &resp, Some(&dark), &opts).unwrap_err();
        assert!(!err.is_failed_measurement());
        assert!(
            matches!(
                err,
                ImagingError::DarkFrameAboveSignal {
                    above: 0,
                    total: 1200,
                    ..
                }
            ),
            "{err:?}"
        );
        assert!(err.to_string().contains("light on"), "{err}");
    }
    // A background at the dark level with a small bright spot (4 px of 1200, above 0.1 %).
    let mut spot = frames.clone();
    for f in &mut spot {
        f.data_mut().fill(20);
        f.data_mut()[..4].fill(90);
    }
    let dark = ImageBuf::filled(w, h, 1, 20u8).unwrap();
    assert!(merge(&spot, &times, &resp, Some(&dark), &opts).is_ok());
    let u = |v: u16| ImageBuf::filled(w, h, 1, v).unwrap();
    let err = merge_linear_u16(
        &[u(100), u(200)],
        &times,
        Some(&u(200)),
        &LinearMergeOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, ImagingError::DarkFrameAboveSignal { .. }),
        "{err:?}"
    );
}

/// With an 8-bit dark frame the hat is taken over the signal range above the dark code, like the
/// 16-bit path: w = min(z − z_dark, 255 − z). By hand: dark code 20, X = z/128, Z = (64, 200),
/// Δt = (1, 4) ⇒ w = (44, 55) and ln E = [44 ln(44/128) + 55(ln(180/128) − ln 4)]/99 (with the raw
/// code's hat the weights would be (64, 55) and ln E differs by 0.1).
#[test]
fn u8_dark_frame_hat_uses_signal_above_dark() {
    let one = |z: u8| ImageBuf::new(1, 1, 1, vec![z]).unwrap();
    let resp = ResponseCurve::linear(1).unwrap();
    let dark = one(20);
    let hdr = merge(
        &[one(64), one(200)],
        &[1.0, 4.0],
        &resp,
        Some(&dark),
        &hat(),
    )
    .unwrap();
    let ln_e =
        (44.0 * (44.0f64 / 128.0).ln() + 55.0 * ((180.0f64 / 128.0).ln() - 4.0f64.ln())) / 99.0;
    let got = f64::from(hdr.radiance.data()[0]);
    assert!(
        (got.ln() - ln_e).abs() < 1e-6,
        "ln E {} vs {ln_e}",
        got.ln()
    );
    // The noise-aware weighting with the same dark frame: E = Σ u Δt (X − X_dark)/Σ u Δt², u as above.
    let hdr = merge(
        &[one(64), one(200)],
        &[1.0, 4.0],
        &resp,
        Some(&dark),
        &MergeOptions::default(),
    )
    .unwrap();
    let u2 = 55.0 / 127.0;
    let expected = (44.0 / 128.0 + 4.0 * u2 * 180.0 / 128.0) / (1.0 + 16.0 * u2);
    let got = f64::from(hdr.radiance.data()[0]);
    assert!((got / expected - 1.0).abs() < 1e-6, "{got} vs {expected}");
}

/// The expected-signal floor (`MergeOptions::expected_floor`): a flat field through a log tone
/// curve (T(s) = ln(1 + 500 s)/ln 501, code 1 ≈ 1 e⁻ of a 20 000 e⁻ well) with 15 e⁻ read noise and
/// shot noise, 13 exposures 1/600–3 s, the longest expecting code 40, merged with the true
/// response (each code's midpoint of linear signal). Every shorter frame is within a few σ of
/// black, reads code 0 for each negative excursion of its noise and so averages high: the merge
/// of every frame is biased upward (+1.7 % here; +1.6 % in BENCHMARKS.md's flat-field study, "Real
/// cameras"). With a floor at code 30 the frames whose *predicted* code is below 30 are left out
/// and the mean is the truth within 0.5 % (+0.27 % here: the per-pixel noise at code 40 is ~26 %,
/// over 65 536 pixels a standard error of ~0.1 %, and the longest frame's code midpoints are not
/// its conditional means).
#[test]
fn the_expected_signal_floor_removes_the_censoring_bias_at_code_zero() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let (full_well, read) = (20_000.0f64, 15.0f64);
    let tone = |s: f64| (500.0 * s.clamp(0.0, 1.0)).ln_1p() / 501f64.ln();
    let inv = |v: f64| ((v * 501f64.ln()).exp() - 1.0) / 500.0;
    let code = |e: f64| (255.0 * tone(e / full_well)).round().clamp(0.0, 255.0) as u8;
    // The true response: ln of each code's midpoint of linear signal (in units of the full well).
    let g: [f64; 256] = std::array::from_fn(|z| {
        let a = inv(((z as f64 - 0.5) / 255.0).max(0.0));
        let b = inv(((z as f64 + 0.5) / 255.0).min(1.0));
        (0.5 * (a + b)).max(1e-12).ln()
    });
    let response = ResponseCurve::from_log_exposure(vec![g]).unwrap();
    let k = (3.0f64 * 600.0).powf(1.0 / 12.0);
    let times: Vec<f64> = (0..13).map(|j| k.powi(j) / 600.0).collect();
    let t_max = times[12];
    // The rate [e⁻/s] whose longest frame expects code 40.
    let rate = inv(40.0 / 255.0) * full_well / t_max;
    let (w, h) = (256, 256);
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(16);
    let frames: Vec<ImageBuf<u8>> = times
        .iter()
        .map(|t| {
            let mean = rate * t;
            let noise = Normal::new(0.0, (mean + read * read).sqrt()).unwrap();
            let d = (0..w * h)
                .map(|_| code(mean + noise.sample(&mut rng)))
                .collect();
            ImageBuf::new(w, h, 1, d).unwrap()
        })
        .collect();
    let truth = rate / full_well;
    let bias = |opts: &MergeOptions| {
        let hdr = merge(&frames, &times, &response, None, opts).unwrap();
        let v: Vec<f64> = hdr
            .radiance
            .data()
            .iter()
            .map(|&v| if v.is_finite() { f64::from(v) } else { 0.0 })
            .collect();
        v.iter().sum::<f64>() / v.len() as f64 / truth - 1.0
    };
    let every_frame = bias(&MergeOptions::default());
    let floored = bias(&MergeOptions {
        expected_floor: Some([30; 4]),
        ..Default::default()
    });
    eprintln!(
        "flat field, log curve, code 40: bias {every_frame:+.4} (every frame), {floored:+.4} (floor 30)"
    );
    assert!(every_frame > 0.008, "every frame: bias {every_frame:+.4}");
    assert!(floored.abs() < 0.005, "with the floor: bias {floored:+.4}");
}
