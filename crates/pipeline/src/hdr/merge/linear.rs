//! The merge of a 16-bit or RAW bracket as linear data: black level or dark frame, the exposure
//! check and correction, the flat frame.

use super::flat::divide_flat;
use super::*;

/// 16-bit and RAW frames as linear data: saturation and codes, black level, exposure times, the
/// merge, the flat frame, the detection limit.
pub(in crate::hdr) fn merge_linear(
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
