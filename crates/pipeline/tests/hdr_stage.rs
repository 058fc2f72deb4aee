//! The HDR stage's two halves (`read_frames`, `merge_frames`), which `scatterfit merge` calls
//! separately to report on the frames and check the merge's memory in between: together they are
//! `read_and_merge`, the budget is the caller's, and a bad dark frame is named as such.

use std::path::Path;

use scatterfit_imaging::ImageBuf;
use scatterfit_io::image_files::{CameraFrame, write_camera_frame};
use scatterfit_pipeline::PipelineError;
use scatterfit_pipeline::hdr::{
    HdrInputs, default_response_samples, merge_frames, read_and_merge, read_frames,
};

const W: usize = 24;
const H: usize = 16;

/// A gamma-2.2 camera looking at a smooth ramp (every code between the clips is used), 6
/// exposures a factor 2 apart, written as PNGs with `exposures.csv`.
fn write_bracket(dir: &Path) -> HdrInputs {
    let mut csv = String::from("file,time_s\n");
    for j in 0..6 {
        let t = 2f64.powi(j) / 64.0;
        let mut data = Vec::with_capacity(W * H * 3);
        for y in 0..H {
            for x in 0..W {
                for c in 0..3 {
                    let e = 0.05
                        * 10f64.powf(3.0 * (x + W * y) as f64 / (W * H) as f64)
                        * [1.0, 0.8, 0.6][c];
                    let z = 255.0 * (e * t).clamp(0.0, 1.0).powf(1.0 / 2.2);
                    data.push(z.round() as u8);
                }
            }
        }
        let name = format!("f_{j}.png");
        let frame = CameraFrame::U8(ImageBuf::new(W, H, 3, data).unwrap());
        write_camera_frame(&dir.join(&name), &frame).unwrap();
        csv.push_str(&format!("{name},{t}\n"));
    }
    std::fs::write(dir.join("exposures.csv"), csv).unwrap();
    let mut inputs = HdrInputs::new(Some(dir.join("exposures.csv")), Vec::new());
    inputs.samples = Some(60);
    inputs
}

#[test]
fn the_two_halves_are_read_and_merge() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = write_bracket(dir.path());
    let read = read_frames(&inputs, &|_| {}).unwrap();
    assert_eq!(read.frames.len(), 6);
    assert_eq!(read.samples_per_frame(), (W * H * 3) as u64);
    assert_eq!(read.decoded_bytes(), (6 * W * H * 3) as u64);
    let split = merge_frames(read, &inputs).unwrap();
    let whole = read_and_merge(&inputs, &|_| {}).unwrap();
    assert_eq!(split.response_kind, "recovered");
    assert_eq!(split.rms, whole.rms);
    assert_eq!(split.frames, whole.frames);
    let bits = |m: &ImageBuf<f32>| m.data().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&split.hdr.radiance), bits(&whole.hdr.radiance));
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
