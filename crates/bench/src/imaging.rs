//! The imaging figures (`scatterfit bench imaging`): the HDR merge (through the pipeline's HDR
//! stage, as `scatterfit merge` runs it), the radial profile and the spot centre on a synthetic
//! 24-MP bracket.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;
use scatterfit_imaging::ImageBuf;
use scatterfit_io::image_files::CameraFrame;
use scatterfit_pipeline::hdr::{HdrInputs, read_and_merge};

use crate::{BenchError, Figure, Result};

/// A synthetic spot bracket: a radially decaying radiance (a light spot on a translucent sample)
/// through a gamma-2.2 camera with a 1 % shot-like noise, 13 shutter times 1/600 s … 3 s.
fn synthetic_bracket(width: usize, height: usize) -> (Vec<ImageBuf<u8>>, Vec<f64>) {
    let n = 13;
    let times: Vec<f64> = (0..n)
        .map(|k| (1.0f64 / 600.0) * (1800.0f64).powf(k as f64 / (n - 1) as f64))
        .collect();
    let (cx, cy) = (width as f64 * 0.5 + 0.3, height as f64 * 0.5 - 0.2);
    let scale = width.min(height) as f64 / 40.0;
    let frames = times
        .par_iter()
        .enumerate()
        .map(|(j, &t)| {
            let mut data = vec![0u8; width * height * 3];
            data.par_chunks_mut(width * 3)
                .enumerate()
                .for_each(|(y, row)| {
                    let mut state =
                        (y as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ (j as u64 + 1);
                    for x in 0..width {
                        let r = ((x as f64 - cx).powi(2) + (y as f64 - cy).powi(2)).sqrt();
                        let e = 200.0 * (-r / scale).exp() / (1.0 + r / scale) + 0.002;
                        for (c, k) in [1.0, 0.7, 0.45].iter().enumerate() {
                            state ^= state << 13;
                            state ^= state >> 7;
                            state ^= state << 17;
                            let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                            let x_exp = (e * k * t * (1.0 + 0.02 * u)).clamp(0.0, 1.0);
                            row[x * 3 + c] = (255.0 * x_exp.powf(1.0 / 2.2)).round() as u8;
                        }
                    }
                });
            ImageBuf::new(width, height, 3, data).expect("width × height × 3 samples")
        })
        .collect();
    (frames, times)
}

/// Writes a bracket as fast-compressed PNGs plus `exposures.csv` into `dir`.
fn write_bracket_png(dir: &Path, frames: Vec<ImageBuf<u8>>, times: &[f64]) -> Result<PathBuf> {
    frames
        .into_par_iter()
        .enumerate()
        .try_for_each(|(j, f)| -> Result<()> {
            let path = dir.join(format!("frame_{j:02}.png"));
            Ok(scatterfit_io::image_files::write_camera_frame(
                &path,
                &CameraFrame::U8(f),
            )?)
        })?;
    write_exposures_csv(dir, "png", "exposures.csv", times)
}

/// Writes a bracket as JPEGs of the given quality plus `exposures_jpeg.csv` into `dir` (frames are
/// borrowed: the PNG bracket is written from the same frames afterwards).
fn write_bracket_jpeg(
    dir: &Path,
    frames: &[ImageBuf<u8>],
    times: &[f64],
    quality: u8,
) -> Result<PathBuf> {
    frames
        .par_iter()
        .enumerate()
        .try_for_each(|(j, f)| -> Result<()> {
            let path = dir.join(format!("frame_{j:02}.jpg"));
            Ok(scatterfit_io::image_files::write_jpeg(&path, f, quality)?)
        })?;
    write_exposures_csv(dir, "jpg", "exposures_jpeg.csv", times)
}

fn write_exposures_csv(dir: &Path, ext: &str, name: &str, times: &[f64]) -> Result<PathBuf> {
    let mut csv = String::from("file,time_s\n");
    for (j, t) in times.iter().enumerate() {
        csv.push_str(&format!("frame_{j:02}.{ext},{t}\n"));
    }
    let csv_path = dir.join(name);
    scatterfit_io::atomic::write_atomic(&csv_path, csv.as_bytes()).map_err(|source| {
        BenchError::Io {
            what: format!("writing {}", csv_path.display()),
            source,
        }
    })?;
    Ok(csv_path)
}

/// The parts of a merge's time ([`scatterfit_pipeline::hdr::Corrections::timings`]: the checks,
/// the response recovery in all its rounds, the exposure estimate, each merge and its score), one
/// figure each.
fn merge_parts(stage: &scatterfit_pipeline::hdr::HdrStage, note: &str) -> Vec<Figure> {
    stage
        .corrections
        .timings
        .iter()
        .map(|(part, s)| Figure {
            name: format!("    {part}"),
            value: *s,
            unit: "s".into(),
            note: note.to_string(),
        })
        .collect()
}

/// The end-to-end merge of a 13-exposure
/// 24-MP 8-bit RGB bracket (PNG files read from disk, response recovered, merged; the same from
/// quality-90 JPEGs) and the radial
/// profile of the 24-MP radiance map; each with the parts of the merge's time. Set
/// `SCATTERFIT_BENCH_BRACKET_DIR` to keep the bracket there (for timing `scatterfit merge` itself,
/// e.g. under `/usr/bin/time -v`), and `SCATTERFIT_BENCH_EXPOSURES` to an `exposures.csv` to see
/// the parts of that bracket's merge too.
pub fn figures(quick: bool) -> Result<Vec<Figure>> {
    let (width, height) = if quick { (1200, 800) } else { (6000, 4000) };
    let mp = (width * height) as f64 / 1e6;
    let threads = rayon::current_num_threads();
    let (frames, times) = synthetic_bracket(width, height);
    let keep = std::env::var_os("SCATTERFIT_BENCH_BRACKET_DIR").map(PathBuf::from);
    let temp = tempfile::tempdir().map_err(|source| BenchError::Io {
        what: "creating a temporary folder for the bracket".into(),
        source,
    })?;
    let dir = match &keep {
        Some(d) => {
            std::fs::create_dir_all(d).map_err(|source| BenchError::Io {
                what: format!("creating {}", d.display()),
                source,
            })?;
            d.clone()
        }
        None => temp.path().to_path_buf(),
    };
    // JPEG first (it borrows the frames), quality 90 as a camera would write; then the PNGs.
    let jpeg_csv = write_bracket_jpeg(&dir, &frames, &times, 90)?;
    let csv = write_bracket_png(&dir, frames, &times)?;
    // What `scatterfit merge` runs for this bracket with its default flags.
    let inputs = HdrInputs::new(Some(csv), Vec::new());
    let t0 = Instant::now();
    let merged = read_and_merge(&inputs, &|_| {})?;
    let total = t0.elapsed().as_secs_f64();
    let note = format!("13 × {mp:.0} MP RGB 8-bit PNG, {threads} threads");
    let mut figures = vec![
        Figure {
            name: format!("merge end to end: read + recover + merge, {mp:.0} MP"),
            value: total,
            unit: "s".into(),
            note: note.clone(),
        },
        Figure {
            name: "  of which reading (decode 13 PNG)".into(),
            value: merged.read_s,
            unit: "s".into(),
            note: note.clone(),
        },
        Figure {
            name: "  of which response recovery + merge".into(),
            value: merged.merge_s,
            unit: "s".into(),
            note: note.clone(),
        },
    ];
    figures.extend(merge_parts(&merged, &note));
    // A bracket of the user's own (SCATTERFIT_BENCH_EXPOSURES=DIR/exposures.csv): where its merge's
    // time goes, with the same parts.
    if let Some(csv) = std::env::var_os("SCATTERFIT_BENCH_EXPOSURES").map(PathBuf::from) {
        let t0 = Instant::now();
        let own = read_and_merge(&HdrInputs::new(Some(csv.clone()), Vec::new()), &|_| {})?;
        let own_note = format!("{} × {}, {threads} threads", own.frames.len(), own.image);
        figures.push(Figure {
            name: format!("merge end to end: {}", csv.display()),
            value: t0.elapsed().as_secs_f64(),
            unit: "s".into(),
            note: own_note.clone(),
        });
        figures.push(Figure {
            name: "  of which reading".into(),
            value: own.read_s,
            unit: "s".into(),
            note: own_note.clone(),
        });
        figures.push(Figure {
            name: "  of which response recovery + merge".into(),
            value: own.merge_s,
            unit: "s".into(),
            note: own_note.clone(),
        });
        figures.extend(merge_parts(&own, &own_note));
    }
    drop(merged.hdr.clipped);
    let radiance = merged.hdr.radiance;
    // The same bracket as quality-90 JPEGs (files as a camera writes them): reading only, then the
    // whole read + recover + merge. The PNG result is kept for the profile below.
    let jpeg_inputs = HdrInputs::new(Some(jpeg_csv), Vec::new());
    let t0 = Instant::now();
    let jpeg = read_and_merge(&jpeg_inputs, &|_| {})?;
    let jpeg_total = t0.elapsed().as_secs_f64();
    drop(jpeg.hdr);
    let jpeg_note = format!("13 × {mp:.0} MP RGB 8-bit JPEG quality 90, {threads} threads");
    figures.push(Figure {
        name: format!("merge end to end from JPEG: read + recover + merge, {mp:.0} MP"),
        value: jpeg_total,
        unit: "s".into(),
        note: jpeg_note.clone(),
    });
    figures.push(Figure {
        name: "  of which reading (decode 13 JPEG)".into(),
        value: jpeg.read_s,
        unit: "s".into(),
        note: jpeg_note,
    });
    let center = scatterfit_imaging::find_spot_center(&radiance, &Default::default())?;
    let opts = scatterfit_imaging::ProfileOptions::default();
    let reps = 10;
    let t0 = Instant::now();
    for _ in 0..reps {
        std::hint::black_box(scatterfit_imaging::radial_profile(
            &radiance,
            center.xy(),
            None,
            0.1,
            &opts,
        )?);
    }
    figures.push(Figure {
        name: format!("radial profile, {mp:.0} MP, r_max 300 px, 1 px rings"),
        value: t0.elapsed().as_secs_f64() / f64::from(reps) * 1e3,
        unit: "ms".into(),
        note: format!("mean of {reps}"),
    });
    let t0 = Instant::now();
    std::hint::black_box(scatterfit_imaging::find_spot_center(
        &radiance,
        &Default::default(),
    )?);
    figures.push(Figure {
        name: format!("spot centre, {mp:.0} MP"),
        value: t0.elapsed().as_secs_f64() * 1e3,
        unit: "ms".into(),
        note: String::new(),
    });
    Ok(figures)
}
