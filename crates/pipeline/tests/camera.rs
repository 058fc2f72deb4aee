//! Real cameras: the HDR stage on the rig twin's brackets from many cameras — tone
//! curves, channel gains, reflectances and noise levels — must never refuse a good bracket and must
//! give the profile's shape within 1 % on the rings it calls measurable (the aim; this build
//! meets it on all 120 channels, see `sweep`); a bracket in the wrong order is
//! still refused, saying what was seen.
//!
//! The profiles are diffusion dipoles (Jensen et al. 2001, eq. 4, written out here) so that no
//! Monte Carlo runs: this tests the imaging, not the physics.

use std::path::Path;

use scatterfit_imaging::{ImageBuf, ProfileOptions, radial_profile};
use scatterfit_io::image_files::{CameraFrame, write_camera_frame};
use scatterfit_pipeline::hdr::{HdrInputs, read_and_merge};
use scatterfit_pipeline::profile::{ProfileSettings, profile_stage};
use scatterfit_synth::rig::{CameraModel, RigSpec, ToneCurve, render_bracket_fn};

/// The dipole's Rd(r) [mm⁻²] for σ′s = 0.5 mm⁻¹, albedo α′ and η (Jensen et al. 2001, eq. 4, with
/// A from Groenhuis' Fdr).
fn dipole(alpha: f64, eta: f64) -> impl Fn(f64) -> f64 + Sync + Copy {
    let fdr = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
    let a = (1.0 + fdr) / (1.0 - fdr);
    let sigma_s = 0.5;
    let sigma_t = sigma_s / alpha;
    let sigma_a = sigma_t - sigma_s;
    let tr = (3.0 * sigma_a * sigma_t).sqrt();
    let zr = 1.0 / sigma_t;
    let zv = zr * (1.0 + 4.0 * a / 3.0);
    move |r: f64| {
        let s = |z: f64| {
            let d = (r * r + z * z).sqrt();
            z * (tr * d + 1.0) * (-tr * d).exp() / (d * d * d)
        };
        alpha / (4.0 * std::f64::consts::PI) * (s(zr) + s(zv))
    }
}

/// ∫ 2πr Rd dr, numerically.
fn total(f: impl Fn(f64) -> f64) -> f64 {
    let (n, r_max) = (200_000, 200.0);
    let h = r_max / n as f64;
    (0..n)
        .map(|k| {
            let r = (k as f64 + 0.5) * h;
            2.0 * std::f64::consts::PI * r * f(r) * h
        })
        .sum()
}

/// The α′ whose dipole has total reflectance `rd` at η (bisection).
fn albedo_for(rd: f64, eta: f64) -> f64 {
    let (mut lo, mut hi) = (1e-3, 1.0 - 1e-9);
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if total(dipole(mid, eta)) < rd {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Writes a bracket as PNGs with exposures.csv; returns the merge's inputs.
fn write(dir: &Path, frames: &[ImageBuf<u8>], times: &[f64]) -> HdrInputs {
    let mut csv = String::from("file,time_s\n");
    for (j, (f, t)) in frames.iter().zip(times).enumerate() {
        let name = format!("frame_{j:02}.png");
        write_camera_frame(&dir.join(&name), &CameraFrame::U8(f.clone())).unwrap();
        csv.push_str(&format!("{name},{t}\n"));
    }
    std::fs::write(dir.join("exposures.csv"), csv).unwrap();
    let mut inputs = HdrInputs::new(Some(dir.join("exposures.csv")), Vec::new());
    inputs.clipped_fill = scatterfit_imaging::ClippedFill::LowerBound;
    if let Ok(n) = std::env::var("CAMERA_SAMPLES") {
        inputs.samples = n.parse().ok();
    }
    if std::env::var("CAMERA_NO_EXPOSURE").is_ok() {
        // Diagnosis: the nominal times, no estimate from the frames.
        inputs.exposure_correction = scatterfit_io::manifest::ExposureCorrection::Never;
    }
    if let Ok(l) = std::env::var("CAMERA_LAMBDA") {
        inputs.lambda = l.parse().unwrap_or(10.0);
    }
    inputs
}

/// Three channels (α′ from Rd, gain relative to a white reference) through `camera`; returns the
/// largest shape error per channel over the measurable 2-pixel rings from 0.5 mm out, or the error
/// that stopped the merge.
fn shape_errors(
    camera: CameraModel,
    channels: [(f64, f64); 3],
    seed: u64,
) -> Result<[f64; 3], String> {
    let eta = 1.3;
    let mut rig = RigSpec::quick();
    rig.camera = camera;
    if let Ok(b) = std::env::var("CAMERA_BRACKET") {
        // Diagnosis: another bracket, "N,K": N frames from 1/600 s, each K times the last.
        let v: Vec<f64> = b.split(',').map(|x| x.parse().unwrap()).collect();
        rig.times_s = (0..v[0] as usize)
            .map(|k| v[1].powi(k as i32) / 600.0)
            .collect();
    }
    let profiles: Vec<_> = channels
        .iter()
        .map(|&(rd, _)| dipole(albedo_for(rd, eta), eta))
        .collect();
    // The brightest centre of the sweep's materials at gain 1 is the reference (a dark material's
    // centre is the brighter at equal σ′s: its light stays near the point of entry).
    let white = [0.005, 0.02, 0.1, 0.5, 0.9]
        .iter()
        .map(|&rd| dipole(albedo_for(rd, eta), eta)(0.0))
        .fold(0.0f64, f64::max);
    let peak = (0..3)
        .map(|c| channels[c].1 * profiles[c](0.0))
        .fold(0.0f64, f64::max);
    // Each channel as bright as its gain × its reflectance make it next to a white reference at
    // gain 1 that would fill 80 % of the well in the shortest exposure.
    rig.peak_fill = 0.8 * peak / white;
    let gains = [channels[0].1, channels[1].1, channels[2].1];
    let b = render_bracket_fn(&|c, r| profiles[c](r), Some(gains), &rig, seed).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut inputs = write(dir.path(), &b.frames, &b.times_s);
    // The camera's own tone curve as a response: the midpoint of each code's interval of linear
    // signal.
    let true_g = || camera.true_log_response().to_vec();
    if std::env::var("CAMERA_TRUE_RESPONSE").is_ok() {
        // Diagnosis: the true response given, to tell response errors from the merge's.
        let g = true_g();
        let path = dir.path().join("response.csv");
        scatterfit_io::response_csv::write_response_csv(
            &path,
            &scatterfit_io::response_csv::ResponseTable { g: vec![g; 3] },
        )
        .unwrap();
        inputs.response = Some(path);
    }
    let stage = read_and_merge(&inputs, &|_| {}).map_err(|e| format!("{e:#}"))?;
    // Only the spot's light: every frame's far field agrees with the next longer frame's (no false
    // alarm of the ambient-light check on any tone curve or noise level).
    if let Some(f) = scatterfit_pipeline::checks::far_field_agreement_in(&stage, b.center_px)
        .and_then(|v| v.into_iter().find(|f| f.disagrees()))
    {
        return Err(format!("the far field disagrees between frames: {f:?}"));
    }
    if std::env::var("CAMERA_DEBUG_G").is_ok()
        && let Some(r) = &stage.response
    {
        // The recovered response against the truth, both on the gauge g(128) = 0 [% in X].
        let t = true_g();
        for (c, g) in r.tables().iter().enumerate() {
            let d: Vec<String> = [5usize, 10, 20, 30, 40, 50, 60, 80, 100, 160, 200, 240]
                .iter()
                .map(|&z| {
                    let e = (g[z] - g[128]) - (t[z] - t[128]);
                    format!("z{z} {:+.1}", 100.0 * e)
                })
                .collect();
            eprintln!("  g error channel {c}: {}", d.join(" "));
            if std::env::var("CAMERA_DEBUG_G").as_deref() == Ok("2") {
                let d: Vec<String> = (20..=250)
                    .map(|z| format!("{:+.1}", 100.0 * ((g[z] - g[128]) - (t[z] - t[128]))))
                    .collect();
                eprintln!("    codes 20..=250: {}", d.join(" "));
            }
        }
    }
    if std::env::var("CAMERA_DEBUG").is_ok() {
        let e = stage.corrections.exposure.as_ref();
        eprintln!(
            "{} {channels:?}: merge {:.2} s, exposure correction {:.4} applied {}",
            camera.curve.name(),
            stage.merge_s,
            e.map_or(f64::NAN, |e| e.max_correction),
            stage.corrections.exposure_applied
        );
    }
    let settings = ProfileSettings {
        mm_per_pixel: rig.mm_per_pixel,
        r_max_px: 128.0,
        ring_width_px: 2.0,
        center_px: Some(b.center_px),
    };
    let prof = profile_stage(
        &stage.hdr.radiance,
        Some(&stage.hdr.clipped),
        &stage.detection_limit,
        &settings,
    )
    .map_err(|e| e.to_string())?;
    // The truth: the noise-free rate at every pixel, averaged on the same rings.
    let (w, h) = (rig.width, rig.height);
    let mut truth = vec![0f32; w * h * 3];
    for y in 0..h {
        for x in 0..w {
            let r = (x as f64 - b.center_px[0]).hypot(y as f64 - b.center_px[1]) * rig.mm_per_pixel;
            for c in 0..3 {
                truth[(y * w + x) * 3 + c] = (gains[c] * profiles[c](r)) as f32;
            }
        }
    }
    let truth = ImageBuf::new(w, h, 3, truth).unwrap();
    let t = radial_profile(
        &truth,
        b.center_px,
        None,
        rig.mm_per_pixel,
        &ProfileOptions::new(2.0, 128.0).unwrap(),
    )
    .unwrap();
    let mut worst = [0.0; 3];
    #[allow(clippy::needless_range_loop)]
    for c in 0..3 {
        let ratios: Vec<f64> = prof
            .profile
            .rings
            .iter()
            .zip(&t.rings)
            .filter(|(m, _)| m.r_px * rig.mm_per_pixel >= 0.5)
            .filter(|(m, _)| m.channels[c].mean >= prof.detection_limit[c])
            .map(|(m, tr)| m.channels[c].mean / tr.channels[c].mean)
            .collect();
        if ratios.len() < 3 {
            // Nothing measurable beyond 0.5 mm (a very dark channel at a low gain): the fit
            // reports too few rings; nothing to compare.
            worst[c] = f64::NAN;
            continue;
        }
        let mut sorted = ratios.clone();
        sorted.sort_by(f64::total_cmp);
        let k = sorted[sorted.len() / 2];
        worst[c] = ratios
            .iter()
            .map(|r| (r / k - 1.0).abs())
            .fold(0.0, f64::max);
        if std::env::var("CAMERA_DEBUG").is_ok() && worst[c] > 0.01 {
            let v: Vec<String> = ratios
                .iter()
                .map(|r| format!("{:+.3}", r / k - 1.0))
                .collect();
            eprintln!("  channel {c}: {}", v.join(" "));
        }
    }
    Ok(worst)
}

/// The camera sweep: five tone curves (linear, gamma 2.2, sRGB, log, a filmic S-curve with a
/// shoulder), channel gains 0.3–1, total reflectance 0.005–0.9, read noise 3 and 15 e⁻ (with shot
/// noise): no bracket refused; on the measurable rings the profile's shape within 0.65 % of the
/// truth for 90 % of the channels and within 1 % for every one (BENCHMARKS.md, "Real cameras").
#[test]
#[ignore = "the whole sweep takes about 5 min on 2 cores; CI runs every third combination (below)"]
fn no_good_bracket_is_refused_and_shapes_hold() {
    sweep(1, 110);
}

/// The sweep above at every third channel combination (a third of the time; every curve and
/// noise level still seen): what CI runs on every change.
#[test]
fn no_good_bracket_is_refused_and_shapes_hold_on_a_third_of_the_sweep() {
    sweep(3, 36);
}

/// Runs the camera sweep over every `stride`-th combination of three channels (per curve and noise
/// level) and asserts the bounds; `min_measured` channels must have had measurable rings.
fn sweep(stride: usize, min_measured: usize) {
    let curves = [
        ToneCurve::Linear,
        ToneCurve::Gamma22,
        ToneCurve::Srgb,
        ToneCurve::Log,
        ToneCurve::SCurve,
    ];
    let rds = [0.005, 0.02, 0.1, 0.5, 0.9];
    let gains = [0.3, 0.6, 1.0];
    let combos: Vec<(f64, f64)> = rds
        .iter()
        .flat_map(|&rd| gains.iter().map(move |&g| (rd, g)))
        .collect();
    let mut failures = Vec::new();
    let mut worst: f64 = 0.0;
    let (mut measured, mut unmeasurable) = (0, 0);
    let mut all: Vec<f64> = Vec::new();
    // The worst shape error per curve and noise level, for BENCHMARKS.md.
    let mut by_curve: Vec<(String, f64)> = Vec::new();
    let only = std::env::var("CAMERA_CURVE").ok();
    for (ci, curve) in curves.iter().enumerate() {
        if only.as_deref().is_some_and(|o| o != curve.name()) {
            continue;
        }
        for (ni, noise) in [3.0, 15.0].into_iter().enumerate() {
            let camera = CameraModel {
                curve: *curve,
                read_noise_e: noise,
                ..CameraModel::default()
            };
            for (k, chunk) in combos.chunks(3).enumerate() {
                if (k + ci + ni) % stride != 0 {
                    continue;
                }
                let ch = [chunk[0], chunk[1], chunk[2]];
                let seed = 100 + (ci * 10 + ni) as u64 * 10 + k as u64;
                match shape_errors(camera, ch, seed) {
                    Ok(e) => {
                        for c in 0..3 {
                            if e[c].is_nan() {
                                unmeasurable += 1;
                                continue;
                            }
                            measured += 1;
                            if std::env::var("CAMERA_DEBUG_ALL").is_ok() {
                                eprintln!(
                                    "{} {noise} e⁻ Rd {} gain {}: {:.2} %",
                                    curve.name(),
                                    ch[c].0,
                                    ch[c].1,
                                    100.0 * e[c]
                                );
                            }
                            worst = worst.max(e[c]);
                            let key = format!("{} {noise} e⁻", curve.name());
                            match by_curve.iter_mut().find(|(k, _)| *k == key) {
                                Some((_, w)) => *w = w.max(e[c]),
                                None => by_curve.push((key, e[c])),
                            }
                            all.push(e[c]);
                            // The bound, met on every channel (worst 0.93 %). With the
                            // trusted codes from 100 instead of 120: 1.31 % (two log channels
                            // above 1 %); before the toe's smoothing and second-order term:
                            // 1.37 % (116 of 120 within 1 %); before the merge's expected-signal
                            // floor and the response's comb: 2.08 % (log, 15 e⁻); before the
                            // forward-direction toe 3.1 % (sRGB) and 3.5 % (log).
                            let bound = 0.01;
                            if e[c] > bound {
                                failures.push(format!(
                                    "{} noise {noise}: Rd {} gain {}: shape error {:.4}",
                                    curve.name(),
                                    ch[c].0,
                                    ch[c].1,
                                    e[c]
                                ));
                            }
                        }
                    }
                    Err(e) => failures.push(format!("{} noise {noise} {ch:?}: {e}", curve.name())),
                }
            }
        }
    }
    all.sort_by(f64::total_cmp);
    let q = |p: f64| {
        all.get(((all.len() as f64 - 1.0) * p) as usize)
            .copied()
            .unwrap_or(0.0)
    };
    eprintln!(
        "shape error over the sweep: median {:.4}, 90 % {:.4}, worst {worst:.4}; within 1 %: {} of \
         {measured} channels measured ({unmeasurable} with nothing measurable beyond 0.5 mm)",
        q(0.5),
        q(0.9),
        all.iter().filter(|e| **e <= 0.01).count()
    );
    let worst_by: Vec<String> = by_curve
        .iter()
        .map(|(k, w)| format!("{k} {:.2} %", 100.0 * w))
        .collect();
    eprintln!("worst by curve and read noise: {}", worst_by.join(", "));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(
        measured >= min_measured,
        "{measured} channels measured (at least {min_measured} expected)"
    );
    // The median: 0.90 % over the whole sweep (0.90 % on a third) before the response's spline
    // refit, 0.34 % (0.49 %) with it, 0.25 % (0.23 %) with the comb, 0.24 % (0.25 %) now
    // (BENCHMARKS.md, "The response recovery and the sweep").
    assert!(q(0.5) <= 0.0035, "median shape error {:.4}", q(0.5));
    // The 90th percentile: 1.35 % over the whole sweep before the response's forward-direction
    // toe and the exposure estimate's independent selection, 0.91 % with them, 0.62 % (0.58 % on
    // a third) with the merge's expected-signal floor and the response's comb, 0.56 % (0.44 %)
    // with the toe's smoothing and second-order term and the trusted codes from 120.
    assert!(
        q(0.9) <= 0.0065,
        "90th percentile of the shape error {:.4}",
        q(0.9)
    );
}

/// The dim channel beside bright ones, made exactly: an sRGB-like 8-bit camera, 13 exposures 1/600–3 s, a
/// dark channel (Rd ≈ 0.02: α′ = 0.5 at η = 1.94) at gain 0.6 beside bright ones, shot and read
/// noise. Without the monotone recovery the response "falls" at low codes and the bracket is
/// refused; with it the bracket measures and the shape holds.
#[test]
fn a_dim_channel_beside_bright_ones_measures() {
    let camera = CameraModel::named("srgb").unwrap();
    for seed in 1..=4 {
        let e = shape_errors(camera, [(0.02, 0.6), (0.2, 1.0), (0.41, 0.75)], seed).unwrap();
        assert!(e.iter().all(|&x| x < 0.02), "seed {seed}: {e:?}");
    }
}

/// The sweep's worst case before the noise-aware detection limit: a log curve (code 30 ≈ 30 e⁻)
/// with 15 e⁻ read noise and a dark material (Rd 0.02) at gains 0.3–1 (the sweep's seed). With a
/// fixed detection code 30 its last rings had a per-pixel signal-to-noise ratio near 2 and came out
/// 15–25 % low; the limit measured on the bracket (code ≈ 75 here) leaves them out and the shape
/// holds within 5 %, with every channel still measured.
#[test]
fn a_noisy_log_camera_gets_a_higher_detection_limit() {
    let camera = CameraModel {
        curve: ToneCurve::Log,
        read_noise_e: 15.0,
        ..CameraModel::default()
    };
    let e = shape_errors(camera, [(0.02, 0.3), (0.02, 0.6), (0.02, 1.0)], 411).unwrap();
    assert!(e.iter().all(|&x| x < 0.05), "{e:?}");
}

/// Frames whose times were reversed, shuffled or duplicated are refused before any response is
/// recovered, as a failed measurement, with a message that says what was seen.
#[test]
fn a_wrong_order_is_refused_saying_what_was_seen() {
    let rig = RigSpec::quick();
    let f = dipole(0.9, 1.3);
    let b = render_bracket_fn(&|_, r| f(r), Some([1.0, 0.8, 0.6]), &rig, 3).unwrap();
    type Case = (&'static str, Vec<f64>, Vec<ImageBuf<u8>>);
    let cases: Vec<Case> = vec![
        (
            "reversed",
            b.times_s.iter().rev().copied().collect(),
            b.frames.clone(),
        ),
        (
            "shuffled",
            {
                let mut t = b.times_s.clone();
                t.swap(3, 9);
                t
            },
            b.frames.clone(),
        ),
        ("repeated", b.times_s.clone(), {
            let mut fr = b.frames.clone();
            fr[6] = fr[5].clone();
            fr
        }),
    ];
    for (what, times, frames) in cases {
        let dir = tempfile::tempdir().unwrap();
        let inputs = write(dir.path(), &frames, &times);
        let err = read_and_merge(&inputs, &|_| {}).unwrap_err();
        assert!(err.is_measurement_failure(), "{what}: {err:#}");
        let text = format!("{err:#}");
        assert!(
            (text.contains("do not brighten with their exposure times")
                && text.contains("frame_")
                && text.contains("right order"))
                || (what == "repeated" && text.contains("the right file for that time")),
            "{what}: {text}"
        );
    }
}

/// What a real rig adds, each with the pipeline's handling on and off: the largest shape error on
/// the rings measurable with the handling (R, G, B of a wood-like sample, Rd 0.5/0.2/0.1).
fn effect(
    rig: RigSpec,
    tweak: &dyn Fn(&mut HdrInputs, &Path),
    background: scatterfit_io::manifest::AutoOrNone,
    handled: bool,
) -> f64 {
    let eta = 1.3;
    let channels = [(0.5, 0.75), (0.2, 1.0), (0.1, 0.6)];
    let profiles: Vec<_> = channels
        .iter()
        .map(|&(rd, _)| dipole(albedo_for(rd, eta), eta))
        .collect();
    let gains = [channels[0].1, channels[1].1, channels[2].1];
    let b = render_bracket_fn(&|c, r| profiles[c](r), Some(gains), &rig, 5).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("file,time_s\n");
    let n = b.frames.len().max(b.frames_u16.len());
    for j in 0..n {
        let name = format!("frame_{j:02}.png");
        let frame = if b.frames.is_empty() {
            CameraFrame::U16(b.frames_u16[j].clone())
        } else {
            CameraFrame::U8(b.frames[j].clone())
        };
        write_camera_frame(&dir.path().join(&name), &frame).unwrap();
        csv.push_str(&format!("{name},{}\n", b.times_s[j]));
    }
    std::fs::write(dir.path().join("exposures.csv"), csv).unwrap();
    if let Some(f) = &b.flat {
        let frame = match f {
            scatterfit_synth::rig::Frame::U8(x) => CameraFrame::U8(x.clone()),
            scatterfit_synth::rig::Frame::U16(x) => CameraFrame::U16(x.clone()),
        };
        write_camera_frame(&dir.path().join("flat.png"), &frame).unwrap();
    }
    let mut inputs = HdrInputs::new(Some(dir.path().join("exposures.csv")), Vec::new());
    inputs.clipped_fill = scatterfit_imaging::ClippedFill::LowerBound;
    if handled {
        tweak(&mut inputs, dir.path());
    } else {
        inputs.exposure_correction = scatterfit_io::manifest::ExposureCorrection::Never;
        inputs.black_level = scatterfit_pipeline::hdr::BlackLevel::None;
    }
    let stage = read_and_merge(&inputs, &|_| {}).unwrap();
    let settings = ProfileSettings {
        mm_per_pixel: rig.mm_per_pixel,
        r_max_px: 128.0,
        ring_width_px: 2.0,
        center_px: Some(b.center_px),
    };
    let bg = if handled {
        background
    } else {
        scatterfit_io::manifest::AutoOrNone::None
    };
    let prof = scatterfit_pipeline::profile::profile_stage_with(
        &stage.hdr.radiance,
        Some(&stage.hdr.clipped),
        &stage.detection_limit,
        &settings,
        bg,
    )
    .unwrap();
    let mut worst: f64 = 0.0;
    for c in 0..3 {
        let ratios: Vec<f64> = prof
            .profile
            .rings
            .iter()
            .filter(|m| m.r_px * rig.mm_per_pixel >= 0.5)
            .filter(|m| m.channels[c].mean >= 3.0 * prof.detection_limit[c])
            .map(|m| {
                let r = m.r_px * rig.mm_per_pixel;
                m.channels[c].mean / (gains[c] * profiles[c](r))
            })
            .collect();
        let mut sorted = ratios.clone();
        sorted.sort_by(f64::total_cmp);
        let k = sorted[sorted.len() / 2];
        worst = worst.max(
            ratios
                .iter()
                .map(|r| (r / k - 1.0).abs())
                .fold(0.0, f64::max),
        );
    }
    worst
}

/// Veiling glare (3·10⁻⁴ of the spot's radiance over the frame) lifts the far rings; the fitted
/// background removes it.
#[test]
fn glare_is_estimated_and_subtracted() {
    let mut rig = RigSpec::quick();
    rig.effects.glare = 3e-4;
    let on = effect(
        rig.clone(),
        &|_, _| {},
        scatterfit_io::manifest::AutoOrNone::Auto,
        true,
    );
    let off = effect(
        rig,
        &|_, _| {},
        scatterfit_io::manifest::AutoOrNone::Auto,
        false,
    );
    eprintln!("glare: shape error {on:.4} handled, {off:.4} not");
    assert!(on < 0.08 && off > 3.0 * on, "{on} vs {off}");
}

/// A linear 16-bit camera's black level (1024 DN) adds 1024/Δt to every pixel of the merge unless
/// it is found (far corners) and subtracted.
#[test]
fn black_level_is_found_in_the_corners() {
    let mut rig = RigSpec::quick();
    rig.camera = CameraModel::named("linear16").unwrap();
    let on = effect(
        rig.clone(),
        &|_, _| {},
        scatterfit_io::manifest::AutoOrNone::None,
        true,
    );
    let off = effect(
        rig,
        &|_, _| {},
        scatterfit_io::manifest::AutoOrNone::None,
        false,
    );
    eprintln!("black level: shape error {on:.4} handled, {off:.4} not");
    assert!(on < 0.03 && off > 3.0 * on, "{on} vs {off}");
}

/// A black level stated wrongly (0.2 % of full scale, 131 DN, either way) for a linear 16-bit
/// camera (1024 DN) bends every dim ring; the far corners' intercept at Δt = 0 contradicts it and
/// the check says so, while the right level (and a dark frame of the right level) passes.
#[test]
fn a_stated_black_level_the_corners_contradict_is_suspect() {
    use scatterfit_pipeline::checks::{ReasonKind, black_level_reasons};
    use scatterfit_pipeline::hdr::BlackLevel;
    let mut rig = RigSpec::quick();
    rig.camera = CameraModel::named("linear16").unwrap();
    let eta = 1.3;
    let profile = dipole(albedo_for(0.4, eta), eta);
    let b = render_bracket_fn(&|_, r| profile(r), None, &rig, 5).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("file,time_s\n");
    for (j, f) in b.frames_u16.iter().enumerate() {
        let name = format!("frame_{j:02}.png");
        write_camera_frame(&dir.path().join(&name), &CameraFrame::U16(f.clone())).unwrap();
        csv.push_str(&format!("{name},{}\n", b.times_s[j]));
    }
    std::fs::write(dir.path().join("exposures.csv"), csv).unwrap();
    // A dark frame: the pedestal alone, as the camera reads with the cap on.
    let (w, h, ch) = (
        b.frames_u16[0].width(),
        b.frames_u16[0].height(),
        b.frames_u16[0].channels(),
    );
    let dark = |level: u16| ImageBuf::new(w, h, ch, vec![level; w * h * ch]).unwrap();
    let kinds = |level: BlackLevel, dark_level: Option<u16>| {
        let mut inputs = HdrInputs::new(Some(dir.path().join("exposures.csv")), Vec::new());
        inputs.black_level = level;
        if let Some(d) = dark_level {
            let path = dir.path().join(format!("dark_{d}.png"));
            write_camera_frame(&path, &CameraFrame::U16(dark(d))).unwrap();
            inputs.dark = Some(path);
        }
        let stage = match read_and_merge(&inputs, &|_| {}) {
            Ok(s) => s,
            // Refused (a pedestal left in makes the short frames too bright for their times):
            // the message must name the black level.
            Err(e) => {
                let text = format!("{e:#}");
                eprintln!("{:?}: refused: {text}", inputs.black_level);
                assert!(text.contains("black_level"), "{text}");
                return (true, vec![ReasonKind::BlackLevel]);
            }
        };
        let check = stage.corrections.black_level_check.clone();
        let reasons = check.as_ref().map(black_level_reasons).unwrap_or_default();
        eprintln!("{:?}: {check:?} → {reasons:?}", inputs.black_level);
        (
            check.is_some(),
            reasons.iter().map(|r| r.kind).collect::<Vec<_>>(),
        )
    };
    // The right level, given or as a dark frame: checked, nothing found.
    assert_eq!(kinds(BlackLevel::Given(vec![1024.0]), None), (true, vec![]));
    assert_eq!(kinds(BlackLevel::Auto, Some(1024)), (true, vec![]));
    // Off by 131 DN either way, given or as a dark frame at other settings; or said to be none.
    for (level, dark_level) in [
        (BlackLevel::Given(vec![1155.0]), None),
        (BlackLevel::Given(vec![893.0]), None),
        (BlackLevel::Auto, Some(1155)),
        (BlackLevel::None, None),
    ] {
        assert_eq!(
            kinds(level, dark_level),
            (true, vec![ReasonKind::BlackLevel])
        );
    }
    // The level found in the corners is its own evidence: nothing to check.
    assert_eq!(kinds(BlackLevel::Auto, None), (false, vec![]));
}

/// Vignetting (30 % at the corner) bends the far profile; the flat frame divides it out.
#[test]
fn the_flat_frame_removes_vignetting() {
    let mut rig = RigSpec::quick();
    rig.effects.vignetting = 0.3;
    let on = effect(
        rig.clone(),
        &|i, d| i.flat = Some(d.join("flat.png")),
        scatterfit_io::manifest::AutoOrNone::None,
        true,
    );
    let off = effect(
        rig,
        &|_, _| {},
        scatterfit_io::manifest::AutoOrNone::None,
        false,
    );
    eprintln!("vignetting: shape error {on:.4} handled, {off:.4} not");
    assert!(on < 0.03 && off > 2.0 * on, "{on} vs {off}");
}

/// Shutter times off by 3 % (each frame its own error) put steps into the profile where the
/// dominant frame changes; the times estimated from the frames remove them.
#[test]
fn exposure_times_are_estimated_from_the_frames() {
    let mut rig = RigSpec::quick();
    rig.effects.exposure_error = 0.03;
    let on = effect(
        rig.clone(),
        &|_, _| {},
        scatterfit_io::manifest::AutoOrNone::None,
        true,
    );
    let off = effect(
        rig,
        &|_, _| {},
        scatterfit_io::manifest::AutoOrNone::None,
        false,
    );
    eprintln!("exposure error: shape error {on:.4} handled, {off:.4} not");
    assert!(off > 1.5 * on, "{on} vs {off}");
}

/// A RAW bracket (the twin's 14-bit DNG: RGGB mosaic, black level 512 in its metadata, exposure
/// times in its EXIF, no exposures.csv needed) measures end to end and agrees with the same
/// scene's 8-bit bracket (same Monte Carlo profiles, seed and gains) within 3 % on σ′s and 4 % on σa
/// (exact transport: the mc model, so the difference is the imaging's).
#[test]
fn a_raw_bracket_agrees_with_the_8_bit_one() {
    use scatterfit_io::manifest::ModelName;
    use scatterfit_io::sample_folder::{CameraFiles, SampleFiles, write_sample_folder_with};
    use scatterfit_pipeline::{Overrides, measure_sample};
    let m = scatterfit_optics::materials::by_name("wood-tile").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut results = Vec::new();
    for camera in ["naka-rushton", "dng"] {
        let mut rig = RigSpec::quick();
        rig.camera = CameraModel::named(camera).unwrap();
        let s = scatterfit_synth::synthesize(
            m.name,
            m.sigma_s_prime,
            m.sigma_a,
            m.eta,
            &rig,
            11,
            None,
            &|_, _, _| {},
        )
        .unwrap();
        let folder = dir.path().join(camera);
        let extra = CameraFiles {
            frames_u16: s.bracket.frames_u16.clone(),
            dng_levels: (camera == "dng").then_some(([512; 3], 16383)),
            ..Default::default()
        };
        write_sample_folder_with(
            &folder,
            &SampleFiles {
                name: m.name,
                reading: &s.reading,
                lab10: None,
                frames: &s.bracket.frames,
                times_s: &s.bracket.times_s,
                mm_per_pixel: rig.mm_per_pixel,
                spot_diameter_mm: 2.0 * rig.spot_radius_mm,
                truth_json: None,
                provenance: "test",
                fit: Default::default(),
            },
            &extra,
        )
        .unwrap();
        if camera == "dng" {
            // Times from the files' metadata: list the frames instead of the CSV.
            let frames: Vec<String> = (0..13).map(|j| format!("\"frame_{j:02}.dng\"")).collect();
            let toml = std::fs::read_to_string(folder.join("sample.toml")).unwrap();
            let toml = toml.replace(
                "exposures = \"exposures.csv\"",
                &format!("images = [{}]", frames.join(", ")),
            );
            std::fs::write(folder.join("sample.toml"), toml).unwrap();
        }
        let meas = measure_sample(
            &folder,
            &Overrides {
                model: Some(ModelName::Mc),
                ..Overrides::default()
            },
            &|_| {},
        )
        .unwrap();
        if camera == "dng" {
            assert_eq!(
                meas.hdr.response_kind,
                scatterfit_pipeline::ResponseKind::Linear
            );
            let (black, source) = meas.hdr.corrections.black_level.clone().unwrap();
            assert_eq!(source, "metadata");
            assert!(black.iter().all(|b| (b - 512.0).abs() < 1e-9), "{black:?}");
        }
        results.push(
            (0..3)
                .map(|c| {
                    let r = meas.fits[scatterfit_optics::Channel::ALL[c]]
                        .report()
                        .unwrap();
                    (r.sigma_s_prime.value, r.sigma_a.value)
                })
                .collect::<Vec<_>>(),
        );
    }
    for (c, (&(s8, a8), &(sr, ar))) in results[0].iter().zip(&results[1]).enumerate() {
        assert!(
            (sr / s8 - 1.0).abs() < 0.03,
            "channel {c}: σ′s {sr} vs {s8}"
        );
        assert!((ar / a8 - 1.0).abs() < 0.04, "channel {c}: σa {ar} vs {a8}");
    }
}
