//! The data checks (`scatterfit_pipeline::checks`, RELIABILITY.md "Numbers that look right and
//! are not"): each bad case is made from one good quick twin (pink plastic, seed 1) by
//! `scatterfit_synth::mishaps` or a manifest edit, measured, and must be called suspect for the
//! right reason — where, without the check, it was "ok" with σ′s off (the errors each case gave
//! before the checks are in RELIABILITY.md). The good twin itself must stay ok.

use crate::common;

use std::path::Path;
use std::sync::OnceLock;

use scatterfit_imaging::ImageBuf;
use scatterfit_io::sample_folder::{SampleFiles, write_sample_folder};
use scatterfit_pipeline::checks::{Quality, ReasonKind, Verdict};
use scatterfit_pipeline::{Measurement, Overrides, measure_sample};
use scatterfit_synth::mishaps;
use scatterfit_synth::{CameraModel, RigSpec, SyntheticSample};

const MATERIAL: &str = "pink-plastic";

fn twin() -> &'static SyntheticSample {
    static TWIN: OnceLock<SyntheticSample> = OnceLock::new();
    TWIN.get_or_init(|| common::quick_twin(MATERIAL, 1))
}

fn write(dir: &Path, frames: &[ImageBuf<u8>], times: &[f64], mm_per_pixel: f64) {
    let s = twin();
    write_sample_folder(
        dir,
        &SampleFiles {
            name: MATERIAL,
            reading: &s.reading,
            lab10: None,
            frames,
            times_s: times,
            mm_per_pixel,
            spot_diameter_mm: 2.0 * RigSpec::quick().spot_radius_mm,
            truth_json: None,
            provenance: "test",
            fit: Default::default(),
        },
    )
    .unwrap();
}

/// Measures the folder; prints σ′s's error per channel and the verdicts.
fn measure(label: &str, dir: &Path) -> (Measurement, [Quality; 3]) {
    let m = measure_sample(dir, &Overrides::default(), &|_| {}).unwrap();
    let q = m.quality().into_array();
    let truth = common::material(MATERIAL).sigma_s_prime;
    let mut line = format!("{label:24}");
    for c in 0..3 {
        let err = m.fits[scatterfit_optics::Channel::ALL[c]]
            .report()
            .map_or(f64::NAN, |r| {
                100.0 * (r.sigma_s_prime.value / truth[c] - 1.0)
            });
        let (rms, pixel_rms) = m.fits[scatterfit_optics::Channel::ALL[c]]
            .report()
            .map_or((f64::NAN, f64::NAN), |r| {
                (r.rms_log_residual, r.pixel_rms_log_residual)
            });
        let kinds: Vec<ReasonKind> = q[c].reasons.iter().map(|r| r.kind).collect();
        line += &format!(
            " | {err:+6.1} % rms {rms:.3}/{pixel_rms:.3} {} {kinds:?}",
            q[c].verdict
        );
    }
    println!("{line}");
    (m, q)
}

fn has(q: &[Quality; 3], kind: ReasonKind) -> bool {
    q.iter()
        .all(|q| q.verdict >= Verdict::Suspect && q.reasons.iter().any(|r| r.kind == kind))
}

#[test]
fn the_good_twin_is_ok_and_a_spot_off_centre_or_doubled_is_suspect() {
    let root = tempfile::tempdir().unwrap();
    let s = twin();
    let (f, t) = (&s.bracket.frames, &s.bracket.times_s);
    let mmpp = RigSpec::quick().mm_per_pixel;
    let d = root.path().join("good");
    write(&d, f, t, mmpp);
    let (good, q) = measure("good", &d);
    assert!(
        q.iter().all(|q| q.verdict == Verdict::Ok),
        "no false alarm on the good twin: {q:?}"
    );
    let [cx, cy] = good.profile.center.xy();
    // (b) The spot near a corner and near an edge: the fitted rings are cut on one side.
    let (x0, y0) = ((cx - 30.0) as usize, (cy - 30.0) as usize);
    let d = root.path().join("corner");
    let w = f[0].width() - x0;
    let h = f[0].height() - y0;
    write(&d, &mishaps::crop(f, x0, y0, w, h), t, mmpp);
    let (_, q) = measure("corner (30 px)", &d);
    assert!(has(&q, ReasonKind::IncompleteRings), "{q:?}");
    let d = root.path().join("edge");
    let x0 = (cx - 15.0) as usize;
    write(
        &d,
        &mishaps::crop(f, x0, 0, f[0].width() - x0, f[0].height()),
        t,
        mmpp,
    );
    let (_, q) = measure("edge (15 px)", &d);
    assert!(has(&q, ReasonKind::IncompleteRings), "{q:?}");
    // (d) A second spot, as bright as the first and a tenth as bright, 63 px away.
    let cam = CameraModel::default();
    for (label, strength) in [("second spot ×1", 1.0), ("second spot ×0.1", 0.1)] {
        let d = root.path().join(label.replace([' ', '×'], "_"));
        write(
            &d,
            &mishaps::second_spot(f, &cam, 60, 20, strength),
            t,
            mmpp,
        );
        let (_, q) = measure(label, &d);
        assert!(has(&q, ReasonKind::SecondSpot), "{label}: {q:?}");
    }
}

#[test]
fn a_wrong_scale_a_bumped_camera_and_a_centre_off_the_spot_are_suspect() {
    let root = tempfile::tempdir().unwrap();
    let s = twin();
    let (f, t) = (&s.bracket.frames, &s.bracket.times_s);
    let mmpp = RigSpec::quick().mm_per_pixel;
    let [cx, cy] = s.bracket.center_px;
    // (c) mm_per_pixel 10× too large and 10× too small: the spot's size in the image disagrees.
    for (label, scale) in [("mm_per_pixel ×10", 10.0), ("mm_per_pixel ×0.1", 0.1)] {
        let d = root.path().join(label.replace([' ', '×'], "_"));
        write(&d, f, t, mmpp * scale);
        let (_, q) = measure(label, &d);
        let suspect = q
            .iter()
            .filter(|q| q.reasons.iter().any(|r| r.kind == ReasonKind::SpotSize))
            .count();
        // A channel the scale leaves unfittable fails; every other one is suspect for the size.
        assert!(
            q.iter().all(|q| q.verdict >= Verdict::Suspect) && suspect >= 1,
            "{label}: {q:?}"
        );
    }
    // (f) The camera bumped by 8 px (and by 3 px) before the 7th frame.
    for (label, dx) in [("bumped 8 px", 8), ("bumped 3 px", 3)] {
        let d = root.path().join(label.replace(' ', "_"));
        write(&d, &mishaps::bump(f, 6, dx, 0), t, mmpp);
        let (_, q) = measure(label, &d);
        assert!(has(&q, ReasonKind::Misregistered), "{label}: {q:?}");
    }
    // A given centre 100 px off the spot.
    let d = root.path().join("centre-off");
    write(&d, f, t, mmpp);
    let toml = std::fs::read_to_string(d.join("sample.toml")).unwrap();
    let toml = toml.replacen(
        "[camera]\n",
        &format!("[camera]\ncenter_px = [{:.1}, {:.1}]\n", cx - 100.0, cy),
        1,
    );
    std::fs::write(d.join("sample.toml"), toml).unwrap();
    let (_, q) = measure("centre given 100 px off", &d);
    assert!(has(&q, ReasonKind::CenterOffSpot), "{q:?}");
}

#[test]
fn a_fit_the_noise_does_not_explain_is_suspect() {
    let root = tempfile::tempdir().unwrap();
    let s = twin();
    let (f, t) = (&s.bracket.frames, &s.bracket.times_s);
    // (a) Two frames 1/600 s and 3 s apart: the merge's linearisation fails silently; the fit's
    // residuals show it.
    let last = f.len() - 1;
    let d = root.path().join("two-frames");
    write(
        &d,
        &[f[0].clone(), f[last].clone()],
        &[t[0], t[last]],
        RigSpec::quick().mm_per_pixel,
    );
    let (_, q) = measure("2 frames 1/600–3 s", &d);
    assert!(
        q.iter()
            .any(|q| q.reasons.iter().any(|r| r.kind == ReasonKind::PoorFit)),
        "{q:?}"
    );
    // The bracket's overlap: 1800× between the two frames (and a response from 2 frames) makes
    // every channel suspect, including the one whose residuals look fine (R +712 %).
    assert!(has(&q, ReasonKind::BracketGap), "{q:?}");
    // Every other frame of the good bracket (steps of 3.5×) still overlaps, but a response
    // recovered from steps that wide can carry a ripple the bracket cannot see (13 % on the camera sweep's
    // sweep): suspect for that, and only that.
    let d = root.path().join("every-other");
    let (fs, ts): (Vec<_>, Vec<_>) = f
        .iter()
        .zip(t)
        .step_by(2)
        .map(|(f, t)| (f.clone(), *t))
        .unzip();
    write(&d, &fs, &ts, RigSpec::quick().mm_per_pixel);
    let (_, q) = measure("every other frame", &d);
    assert!(
        !q.iter()
            .any(|q| q.reasons.iter().any(|r| r.kind == ReasonKind::BracketGap)),
        "{q:?}"
    );
    assert!(has(&q, ReasonKind::ResponseSteps), "{q:?}");
    assert!(
        q[0].reasons
            .iter()
            .any(|r| r.kind == ReasonKind::ResponseSteps && r.message.contains("3.5×")),
        "{q:?}"
    );
    // The same frames through a given response (the twin camera's own) are not.
    let response = d.join("response.csv");
    let g = CameraModel::default().true_log_response().to_vec();
    scatterfit_io::response_csv::write_response_csv(
        &response,
        &scatterfit_io::response_csv::ResponseTable { g: vec![g; 3] },
    )
    .unwrap();
    let toml = d.join("sample.toml");
    let text = std::fs::read_to_string(&toml).unwrap();
    std::fs::write(
        &toml,
        text.replacen("[camera]\n", "[camera]\nresponse = \"response.csv\"\n", 1),
    )
    .unwrap();
    let (_, q) = measure("every other, response given", &d);
    assert!(
        !q.iter().any(|q| q
            .reasons
            .iter()
            .any(|r| r.kind == ReasonKind::ResponseSteps)),
        "{q:?}"
    );
}

#[test]
fn frames_that_do_not_use_their_bit_depth_are_found() {
    use scatterfit_io::image_files::{CameraFrame, write_camera_frame};
    use scatterfit_synth::mishaps::{Alignment, linear_u16, scaled_to_u16};
    let root = tempfile::tempdir().unwrap();
    let s = twin();
    let (f, t) = (&s.bracket.frames, &s.bracket.times_s);
    let cam = CameraModel::default();
    let with_frames = |label: &str, frames: Vec<ImageBuf<u16>>| {
        let d = root.path().join(label.replace(' ', "_"));
        write(&d, f, t, RigSpec::quick().mm_per_pixel);
        for (j, fr) in frames.into_iter().enumerate() {
            write_camera_frame(&d.join(format!("frame_{j:02}.png")), &CameraFrame::U16(fr))
                .unwrap();
        }
        d
    };
    // (e) 12-bit data in 16-bit files, low-aligned: the plateau at 4095 is the saturation.
    let d = with_frames("12-in-16 low", linear_u16(f, &cam, 12, Alignment::Low));
    let (m, _) = measure("12-in-16 low", &d);
    let codes = m.hdr.corrections.codes.expect("16-bit frames' codes");
    assert!(codes.plateau_found && codes.saturation == 4095, "{codes:?}");
    // 8-bit linear data in 16-bit files: suspect.
    let d = with_frames("8-in-16 low", linear_u16(f, &cam, 8, Alignment::Low));
    let (_, q) = measure("8-in-16 low", &d);
    assert!(has(&q, ReasonKind::BitDepth), "{q:?}");
    // 8-bit frames scaled by 257: refused with the reason.
    let d = with_frames("8-in-16 x257", scaled_to_u16(f));
    let e = measure_sample(&d, &Overrides::default(), &|_| {}).expect_err("refused");
    assert!(e.to_string().contains("multiple of 257"), "{e}");
}

/// `camera.saturation`: a sensor that stops being linear below its largest code (a compressive
/// shoulder above 1000 of 4095, so the clipped pixels form a plateau at 1929 that is taken for the
/// saturation) biases σ′s by −15 %, −6 %, −7 % (R, G, B) against the same frames without the
/// shoulder; with `camera.saturation = 1000` in the manifest the bias is −1.5 %, −0.5 %, −0.5 % (the
/// rest: fewer codes per frame). The test asks for < 2 % stated and a third of the unstated bias or
/// less (the frames' codes, or `camera.saturation`); 8-bit frames with the key are
/// refused with the reason.
#[test]
fn a_stated_saturation_is_used() {
    use scatterfit_io::image_files::{CameraFrame, write_camera_frame};
    use scatterfit_optics::Channel;
    use scatterfit_synth::mishaps::{Alignment, linear_u16};
    let root = tempfile::tempdir().unwrap();
    let s = twin();
    let (f, t) = (&s.bracket.frames, &s.bracket.times_s);
    let cam = CameraModel::default();
    let sample = |label: &str, frames: Vec<ImageBuf<u16>>, saturation: Option<u16>| {
        let d = root.path().join(label.replace(' ', "_"));
        write(&d, f, t, RigSpec::quick().mm_per_pixel);
        for (j, fr) in frames.into_iter().enumerate() {
            write_camera_frame(&d.join(format!("frame_{j:02}.png")), &CameraFrame::U16(fr))
                .unwrap();
        }
        if let Some(s) = saturation {
            let toml = d.join("sample.toml");
            let text = std::fs::read_to_string(&toml).unwrap();
            let text = text.replacen("[camera]\n", &format!("[camera]\nsaturation = {s}\n"), 1);
            std::fs::write(&toml, text).unwrap();
        }
        d
    };
    let clean = linear_u16(f, &cam, 12, Alignment::Low);
    let shoulder: Vec<ImageBuf<u16>> = clean
        .iter()
        .map(|fr| {
            let data = fr
                .data()
                .iter()
                .map(|&v| {
                    if v > 1000 {
                        1000 + ((f64::from(v) - 1000.0) * 0.3).round() as u16
                    } else {
                        v
                    }
                })
                .collect();
            ImageBuf::new(fr.width(), fr.height(), fr.channels(), data).unwrap()
        })
        .collect();
    let sigma =
        |m: &Measurement| Channel::ALL.map(|c| m.fits[c].sigma_s_prime().expect("fitted").value);
    let (reference, _) = measure("12-bit clean", &sample("clean", clean, None));
    let (unstated, _) = measure("shoulder", &sample("shoulder", shoulder.clone(), None));
    let (stated, _) = measure(
        "shoulder + saturation",
        &sample("stated", shoulder, Some(1000)),
    );
    let codes = stated.hdr.corrections.codes.expect("16-bit frames' codes");
    assert!(
        codes.saturation == 1000 && !codes.plateau_found,
        "{codes:?}"
    );
    let (r, u, st) = (sigma(&reference), sigma(&unstated), sigma(&stated));
    println!("σ′s clean {r:?}, shoulder {u:?}, shoulder with camera.saturation {st:?}");
    for c in 0..3 {
        let (e_stated, e_unstated) = ((st[c] / r[c] - 1.0).abs(), (u[c] / r[c] - 1.0).abs());
        assert!(e_stated < 0.02, "channel {c}: {} vs {}", st[c], r[c]);
        assert!(
            e_unstated > 3.0 * e_stated,
            "channel {c}: {e_unstated} vs {e_stated}"
        );
    }
    // 8-bit frames clip at 255: the key is refused, saying so.
    let d = root.path().join("eight-bit");
    write(&d, f, t, RigSpec::quick().mm_per_pixel);
    let toml = d.join("sample.toml");
    let text = std::fs::read_to_string(&toml).unwrap();
    std::fs::write(
        &toml,
        text.replacen("[camera]\n", "[camera]\nsaturation = 250\n", 1),
    )
    .unwrap();
    let e = measure_sample(&d, &Overrides::default(), &|_| {}).expect_err("refused");
    assert!(
        e.to_string().contains("applies to 16-bit and RAW frames"),
        "{e}"
    );
}

/// Four hot pixels at the frame's corners (200 e⁻/s of dark current each, every frame): the
/// outermost rings hold one to a few pixels, so each lifted pixel lifts its ring's mean 10–100×
/// above the profile and past the detection limit into the fit. Counted per ring, those rings
/// put G's rms log residual above the check's 0.4 (0.51; `poor_fit` before the check weighed
/// rings by their pixels) with σ′s within 1.3 %; over the rings' pixels it is 0.10, as on the
/// good twin, and every channel stays ok.
#[test]
fn a_few_hot_pixels_in_the_corners_are_not_a_poor_fit() {
    use scatterfit_pipeline::checks::MAX_RMS_LOG_RESIDUAL;
    let root = tempfile::tempdir().unwrap();
    let s = twin();
    let (f, t) = (&s.bracket.frames, &s.bracket.times_s);
    let (w, h) = (f[0].width(), f[0].height());
    let corners = [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)];
    let cam = CameraModel::default();
    let d = root.path().join("hot-pixels");
    write(
        &d,
        &mishaps::hot_pixels(f, &cam, t, &corners, 200.0),
        t,
        RigSpec::quick().mm_per_pixel,
    );
    let (m, q) = measure("4 hot corner pixels", &d);
    let truth = common::material(MATERIAL).sigma_s_prime;
    let mut per_ring_max = 0.0f64;
    for (c, channel) in scatterfit_optics::Channel::ALL.into_iter().enumerate() {
        let r = m.fits[channel].report().expect("fitted");
        per_ring_max = per_ring_max.max(r.rms_log_residual);
        assert!(
            r.pixel_rms_log_residual < 0.5 * MAX_RMS_LOG_RESIDUAL,
            "{channel:?}: {}",
            r.pixel_rms_log_residual
        );
        let e = r.sigma_s_prime.value / truth[c] - 1.0;
        assert!(e.abs() < 0.03, "{channel:?}: σ′s {e:+.4}");
        assert_eq!(q[c].verdict, Verdict::Ok, "{channel:?}: {:?}", q[c]);
    }
    // The case is one the per-ring residual called a poor fit.
    assert!(per_ring_max > MAX_RMS_LOG_RESIDUAL, "{per_ring_max}");
}
