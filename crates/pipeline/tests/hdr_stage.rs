//! The HDR stage's two halves (`read_frames`, `merge_frames`), which `scatterfit merge` calls
//! separately to report on the frames and check the merge's memory in between: together they are
//! `read_and_merge`, the budget is the caller's, and a bad dark frame is named as such.

use std::path::Path;

use scatterfit_imaging::{CalibrateOptions, ImageBuf, MergeOptions, merge, recover_response};
use scatterfit_io::image_files::{CameraFrame, write_camera_frame};
use scatterfit_pipeline::PipelineError;
use scatterfit_pipeline::hdr::{
    HdrInputs, default_response_samples, merge_frames, read_and_merge, read_frames,
};

const W: usize = 24;
const H: usize = 16;

/// The scene: a smooth ramp over three decades with a tint per channel, so every code between the
/// clips is used.
fn scene_radiance(x: usize, y: usize, c: usize) -> f64 {
    0.05 * 10f64.powf(3.0 * (x + W * y) as f64 / (W * H) as f64) * [1.0, 0.8, 0.6][c]
}

/// A gamma-2.2 camera looking at the scene: 6 exposures a factor 2 apart, shortest first, with
/// their times [s].
fn bracket() -> (Vec<ImageBuf<u8>>, Vec<f64>) {
    let times: Vec<f64> = (0..6).map(|j| 2f64.powi(j) / 64.0).collect();
    let frames = times
        .iter()
        .map(|&t| {
            let mut data = Vec::with_capacity(W * H * 3);
            for y in 0..H {
                for x in 0..W {
                    for c in 0..3 {
                        let z = 255.0
                            * (scene_radiance(x, y, c) * t)
                                .clamp(0.0, 1.0)
                                .powf(1.0 / 2.2);
                        data.push(z.round() as u8);
                    }
                }
            }
            ImageBuf::new(W, H, 3, data).unwrap()
        })
        .collect();
    (frames, times)
}

/// The bracket written as PNGs with `exposures.csv`, and inputs that read it with 60 samples.
fn write_bracket(dir: &Path) -> HdrInputs {
    let mut csv = String::from("file,time_s\n");
    let (frames, times) = bracket();
    for (j, (frame, t)) in frames.into_iter().zip(times).enumerate() {
        let name = format!("f_{j}.png");
        write_camera_frame(&dir.join(&name), &CameraFrame::U8(frame)).unwrap();
        csv.push_str(&format!("{name},{t}\n"));
    }
    std::fs::write(dir.join("exposures.csv"), csv).unwrap();
    let mut inputs = HdrInputs::new(Some(dir.join("exposures.csv")), Vec::new());
    inputs.samples = Some(60);
    inputs
}

/// The two halves read and merge the bracket, checked against what they must reproduce rather than
/// against `read_and_merge` alone: (1) the merged map is the scene's radiance up to one factor per
/// channel (the response is known only up to its gauge g(128) = 0), within half a code of rounding
/// at the dimmest pixel — 2.2 × 0.5/z in ln radiance, 2.3–2.9 % at z = 48…38, where only the
/// longest frame sees it — plus 0.005 for the recovered response's own error (docs/physics.md §7.1:
/// about 0.004 in g); (2) it is the map that
/// `scatterfit_imaging`'s recovery and merge make, run directly on the frames as they were built in
/// memory (no files, no pipeline) with the options the inputs name, bit for bit — so the files were
/// decoded to the same codes, in time order, and the options reached the merge. `read_and_merge`
/// gives the same map again.
#[test]
fn the_two_halves_are_read_and_merge() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = write_bracket(dir.path());
    let read = read_frames(&inputs, &|_| {}).unwrap();
    assert_eq!(read.frames.len(), 6);
    assert_eq!(read.samples_per_frame(), (W * H * 3) as u64);
    assert_eq!(read.decoded_bytes(), (6 * W * H * 3) as u64);
    let split = merge_frames(read, &inputs).unwrap();
    assert_eq!(
        split.response_kind,
        scatterfit_pipeline::ResponseKind::Recovered
    );
    let (_, times) = bracket();
    let frame_times: Vec<f64> = split.frames.iter().map(|f| f.time_s).collect();
    assert_eq!(frame_times, times);

    // (1) The scene, up to a factor per channel.
    let map = &split.hdr;
    for c in 0..3 {
        let mut ln_ratio = Vec::new();
        for y in 0..H {
            for x in 0..W {
                if map.is_valid(x, y, c) {
                    let e = f64::from(map.radiance.pixel(x, y).unwrap()[c]);
                    ln_ratio.push((e / scene_radiance(x, y, c)).ln());
                }
            }
        }
        assert!(
            ln_ratio.len() > W * H / 2,
            "channel {c}: {} valid",
            ln_ratio.len()
        );
        let mut sorted = ln_ratio.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[sorted.len() / 2];
        let worst = ln_ratio
            .iter()
            .map(|r| (r - median).abs())
            .fold(0.0, f64::max);
        // The dimmest pixel's code in the longest frame, the only frame that sees it.
        let z_min = 255.0 * (scene_radiance(0, 0, c) * times[5]).powf(1.0 / 2.2);
        let tolerance = 2.2 * 0.5 / z_min + 0.005;
        assert!(
            worst < tolerance,
            "channel {c}: radiance off the scene by {worst:.4} in ln (tolerance {tolerance:.4})"
        );
    }

    // (2) The imaging crate directly, on the frames as made.
    let (frames, times) = bracket();
    let opts = CalibrateOptions::new(60, inputs.lambda).unwrap();
    let response = recover_response(&frames, &times, &opts).unwrap().response;
    let merge_opts = MergeOptions {
        clipped_fill: inputs.clipped_fill,
        weighting: inputs.weighting,
        expected_floor: split.corrections.expected_floor,
    };
    let direct = merge(&frames, &times, &response, None, &merge_opts).unwrap();
    // Values (bit patterns, so NaN = NaN) that differ from the direct merge's.
    let differing = |m: &ImageBuf<f32>| {
        (m.data().iter().zip(direct.radiance.data()))
            .filter(|(a, b)| a.to_bits() != b.to_bits())
            .count()
    };
    assert_eq!(differing(&split.hdr.radiance), 0, "of {}", W * H * 3);
    assert_eq!(split.hdr.clipped.data(), direct.clipped.data());

    let whole = read_and_merge(&inputs, &|_| {}).unwrap();
    assert_eq!(split.rms, whole.rms);
    assert_eq!(split.frames, whole.frames);
    assert_eq!(differing(&whole.hdr.radiance), 0, "of {}", W * H * 3);
}

#[test]
fn the_callers_memory_budget_is_used() {
    let dir = tempfile::tempdir().unwrap();
    let mut inputs = write_bracket(dir.path());
    inputs.memory_budget = Some(1024);
    let err = read_frames(&inputs, &|_| {}).unwrap_err();
    assert!(matches!(err, PipelineError::Bracket(_)), "{err}");
    assert!(err.to_string().contains("memory budget"), "{err}");
}

#[test]
fn a_bad_dark_frame_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut inputs = write_bracket(dir.path());
    let small = CameraFrame::U8(ImageBuf::new(W - 1, H, 3, vec![2; (W - 1) * H * 3]).unwrap());
    write_camera_frame(&dir.path().join("dark.png"), &small).unwrap();
    inputs.dark = Some(dir.path().join("dark.png"));
    let err = read_frames(&inputs, &|_| {}).unwrap_err();
    assert!(matches!(err, PipelineError::DarkFrameShape(_)), "{err}");
    assert!(err.to_string().contains("dark.png"), "{err}");

    std::fs::write(dir.path().join("dark.png"), b"not an image").unwrap();
    let err = read_frames(&inputs, &|_| {}).unwrap_err();
    assert!(matches!(err, PipelineError::DarkFrame(_)), "{err}");
    assert!(
        err.to_string().starts_with("reading the dark frame: ")
            && err.to_string().contains("dark.png"),
        "{err}"
    );
}

/// Debevec & Malik's N(P − 1) ≥ 256: 256 samples for 2 frames, 128 for 3, else 100.
#[test]
fn default_samples_follow_the_frame_count() {
    assert_eq!(default_response_samples(2), 256);
    assert_eq!(default_response_samples(3), 128);
    assert_eq!(default_response_samples(13), 100);
}
