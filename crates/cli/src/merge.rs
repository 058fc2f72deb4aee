//! `scatterfit merge`: an exposure bracket → an HDR radiance map (Debevec & Malik 1997).
//!
//! Reads the frames (in parallel), recovers the camera response (or takes a known one), merges,
//! saves the radiance map (EXR or HDR) and the response (CSV), and prints a summary. 8-bit frames use a
//! response curve; 16-bit frames are merged as linear data (raw or linear TIFF).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use crate::output::{errln, outln};
use anyhow::{Context, bail};
use scatterfit_imaging::{
    CalibrateOptions, ClippedFill, HdrImage, ImageBuf, LEVELS, LinearMergeOptions, MergeOptions,
    ResponseCurve,
};
use scatterfit_io::bracket::{Bracket, read_bracket_within};
use scatterfit_io::image_files::{CameraFrame, read_camera_frame, write_radiance};
use scatterfit_io::response_csv::{ResponseTable, read_response_csv, write_response_csv};
use serde::Serialize;

/// What to store for a pixel-channel clipped in every exposure (it is always counted and reported).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Fill {
    /// NaN: the profile and spot finder skip it.
    Nan,
    /// The largest radiance the data prove (saturated) or 0 (dark).
    LowerBound,
}

/// How 8-bit samples are weighted across the bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum WeightingArg {
    /// Noise-aware linear-domain average (Robertson et al. 2003 / Granados et al. 2010): unbiased for
    /// dim pixels (BENCHMARKS.md, "dim pixels").
    NoiseOptimal,
    /// The paper's hat on ln E (Debevec & Malik 1997, eq. 6), as OpenCV's MergeDebevec.
    DebevecHat,
}

/// Arguments of `scatterfit merge`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The frames of the bracket (PNG, TIFF or JPEG; 8- or 16-bit; grey or RGB). May be omitted when
    /// --exposures lists them.
    pub images: Vec<PathBuf>,
    /// Exposure times: a CSV with header `file,time_s` (paths relative to the CSV's folder; times in
    /// seconds, `0.01` or `1/100`). Without it, times come from each file's EXIF ExposureTime.
    #[arg(long, value_name = "CSV")]
    pub exposures: Option<PathBuf>,
    /// A known camera response (CSV `z,g_r,g_g,g_b`, as written by --response-out) instead of
    /// recovering one. 8-bit frames only.
    #[arg(long, value_name = "CSV")]
    pub response: Option<PathBuf>,
    /// A dark frame (lens capped, same settings), subtracted before merging.
    #[arg(long, value_name = "IMAGE")]
    pub dark: Option<PathBuf>,
    /// Smoothness weight λ of the response recovery (Debevec & Malik 1997, eq. 3), in [0, 10⁶]
    /// (dimensionless; OpenCV's default 10).
    #[arg(long, default_value_t = 10.0, value_parser = crate::numeric::parse_finite)]
    pub lambda: f64,
    /// Sample pixels per channel for the response recovery: a count from ⌈256/(P − 1)⌉ for P frames
    /// (22 for 13; Debevec & Malik's N(P − 1) ≥ 256, fewer leave the curve undetermined) to 1000
    /// (more only cost time: the solve grows as N·P). Default 100, or that minimum when larger.
    #[arg(long, value_parser = crate::numeric::parse_size)]
    pub samples: Option<usize>,
    /// 16-bit frames: raw value at and above which a sample counts as saturated, 2 to 65535.
    #[arg(long, default_value_t = u16::MAX, value_parser = clap::value_parser!(u16).range(2..))]
    pub saturation: u16,
    /// Value stored for pixels clipped in every exposure.
    #[arg(long, value_enum, default_value_t = Fill::Nan)]
    pub clipped_fill: Fill,
    /// Sample weighting of 8-bit brackets.
    #[arg(long, value_enum, default_value_t = WeightingArg::NoiseOptimal)]
    pub weighting: WeightingArg,
    /// The radiance map to write (.exr: 32-bit float, PIZ lossless; .hdr: Radiance RGBE); checked
    /// with --response-out before any work; existing files only with --force.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Where to save the camera response (.csv; default: beside the output, `<name>.response.csv`).
    /// Written after the radiance map, so a map that cannot be written leaves no response behind.
    #[arg(long, value_name = "CSV")]
    pub response_out: Option<PathBuf>,
    /// Replace existing output files.
    #[arg(long)]
    pub force: bool,
    #[arg(long, value_parser = crate::numeric::parse_mib, help = crate::numeric::MAX_MEMORY_HELP)]
    pub max_memory_mib: Option<u64>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The summary `scatterfit merge` prints.
#[derive(Debug, Serialize)]
pub struct Summary {
    /// The frames, shortest exposure first.
    pub frames: Vec<FrameSummary>,
    /// Image size and kind, e.g. `6000×4000 RGB 8-bit`.
    pub image: String,
    /// Width [px].
    pub width: usize,
    /// Height [px].
    pub height: usize,
    /// `recovered`, `given` (file) or `linear` (16-bit).
    pub response: String,
    /// RMS residual of the response fit per channel (recovered responses only).
    pub response_rms_residual: Vec<f64>,
    /// Smallest positive finite radiance (relative units).
    pub radiance_min: f64,
    /// Largest finite radiance.
    pub radiance_max: f64,
    /// Dynamic range radiance_max / radiance_min, in stops (log2).
    pub dynamic_range_stops: f64,
    /// Pixel-channels clipped in every exposure (flagged, stored per --clipped-fill).
    pub clipped_everywhere_samples: usize,
    /// Pixels with at least one channel clipped in every exposure.
    pub clipped_everywhere_pixels: usize,
    /// The radiance map written.
    pub output: PathBuf,
    /// The response CSV written (none for a linear 16-bit merge).
    pub response_out: Option<PathBuf>,
    /// Wall time for reading the frames [s].
    pub read_s: f64,
    /// Wall time for response recovery and merge [s].
    pub merge_s: f64,
}

/// One frame in the summary.
#[derive(Debug, Serialize)]
pub struct FrameSummary {
    /// The file.
    pub file: PathBuf,
    /// Shutter time [s].
    pub time_s: f64,
}

fn default_response_out(output: &Path) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or_else(|| "radiance".into(), |s| s.to_string_lossy().into_owned());
    output.with_file_name(format!("{stem}.response.csv"))
}

/// Reads a response CSV into a curve with 256 levels.
fn load_response(path: &Path) -> anyhow::Result<ResponseCurve> {
    let table = read_response_csv(path)?;
    if table.levels() != LEVELS {
        bail!(
            "{}: {} rows, but a response for 8-bit frames lists g(z) for z = 0..255 (256 rows)",
            path.display(),
            table.levels()
        );
    }
    let g: Vec<[f64; LEVELS]> = table
        .g
        .iter()
        .map(|c| {
            let mut t = [0.0; LEVELS];
            t.copy_from_slice(c);
            t
        })
        .collect();
    ResponseCurve::from_log_exposure(g)
        .with_context(|| format!("camera response {}", path.display()))
}

/// The outcome of reading and merging, before anything is written.
pub(crate) struct Merged {
    pub hdr: HdrImage,
    pub response: Option<ResponseCurve>,
    pub response_kind: &'static str,
    pub rms: Vec<f64>,
    pub read_s: f64,
    pub merge_s: f64,
    pub frames: Vec<FrameSummary>,
    pub image: String,
}

/// Reads the bracket and merges it (shared by `run` and the benchmark).
pub(crate) fn read_and_merge(args: &Args, progress: bool) -> anyhow::Result<Merged> {
    let t0 = Instant::now();
    let bar = if progress && std::io::stderr().is_terminal() {
        let n = if args.images.is_empty() {
            0
        } else {
            args.images.len() as u64
        };
        let bar = indicatif::ProgressBar::new(n);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "reading frames {bar:30} {pos}/{len} {elapsed}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    } else {
        indicatif::ProgressBar::hidden()
    };
    let budget = crate::numeric::memory_budget(args.max_memory_mib);
    let bracket: Bracket =
        read_bracket_within(&args.images, args.exposures.as_deref(), budget, &|_| {
            bar.inc(1)
        })
        .context("reading the exposure bracket")?;
    bar.finish_and_clear();
    for f in bracket.frames().iter().filter(|f| f.dropped_alpha) {
        errln!("note: {}: alpha channel ignored", f.path.display());
    }
    let dark = match &args.dark {
        Some(path) => {
            let d = read_camera_frame(path).context("reading the dark frame")?;
            bracket.check_same_shape(&d.frame, path)?;
            Some(d.frame)
        }
        None => None,
    };
    let read_s = t0.elapsed().as_secs_f64();
    let frames: Vec<FrameSummary> = bracket
        .frames()
        .iter()
        .map(|f| FrameSummary {
            file: f.path.clone(),
            time_s: f.time_s,
        })
        .collect();
    let image = bracket.describe();
    let times = bracket.times_s();
    // The merge's own allocations (radiance f32 + clipping mask + the encoded file), beside the
    // frames already read, before any is made.
    let first = &bracket.frames()[0].frame;
    let samples = (first.width() * first.height() * first.channels()) as u64;
    let frames_bytes = samples * u64::from(first.bit_depth() / 8) * bracket.frames().len() as u64;
    crate::numeric::check_memory(
        &format!("merging {} frames of {image}", bracket.frames().len()),
        frames_bytes + samples * (4 + 1 + 4),
        budget,
    )?;
    let t1 = Instant::now();
    let first = first.bit_depth();
    let merged = if first == 8 {
        let bufs: Vec<ImageBuf<u8>> = bracket
            .into_frames()
            .into_iter()
            .filter_map(|f| match f.frame {
                CameraFrame::U8(b) => Some(b),
                _ => None,
            })
            .collect();
        let (response, kind, rms) = match &args.response {
            Some(path) => (load_response(path)?, "given", Vec::new()),
            None => {
                let samples = args.samples.unwrap_or_else(|| {
                    100.max(scatterfit_imaging::min_response_samples(bufs.len()))
                });
                let opts = CalibrateOptions::new(samples, args.lambda)
                    .context("response recovery options")?;
                let cal = scatterfit_imaging::recover_response(&bufs, &times, &opts).context(
                    "recovering the camera response (or give a known one with --response)",
                )?;
                let rms = cal.solutions.iter().map(|s| s.rms_residual).collect();
                (cal.response, "recovered", rms)
            }
        };
        let dark = dark.and_then(|d| match d {
            CameraFrame::U8(b) => Some(b),
            _ => None,
        });
        let opts = MergeOptions {
            clipped_fill: fill(args.clipped_fill),
            weighting: match args.weighting {
                WeightingArg::NoiseOptimal => scatterfit_imaging::Weighting::NoiseOptimal,
                WeightingArg::DebevecHat => scatterfit_imaging::Weighting::DebevecHat,
            },
        };
        let hdr = scatterfit_imaging::merge(&bufs, &times, &response, dark.as_ref(), &opts)
            .context("merging the bracket")?;
        drop(bufs);
        Merged {
            hdr,
            response: Some(response),
            response_kind: kind,
            rms,
            read_s,
            merge_s: 0.0,
            frames,
            image,
        }
    } else {
        if let Some(path) = &args.response {
            bail!(
                "{}: a response curve applies to 8-bit frames; these frames are 16-bit and are merged as \
                 linear data — drop --response",
                path.display()
            );
        }
        let bufs: Vec<ImageBuf<u16>> = bracket
            .into_frames()
            .into_iter()
            .filter_map(|f| match f.frame {
                CameraFrame::U16(b) => Some(b),
                _ => None,
            })
            .collect();
        let dark = dark.and_then(|d| match d {
            CameraFrame::U16(b) => Some(b),
            _ => None,
        });
        let opts = LinearMergeOptions::new(args.saturation, fill(args.clipped_fill))
            .context("--saturation")?;
        let hdr = scatterfit_imaging::merge_linear_u16(&bufs, &times, dark.as_ref(), &opts)
            .context("merging the 16-bit bracket")?;
        Merged {
            hdr,
            response: None,
            response_kind: "linear",
            rms: Vec::new(),
            read_s,
            merge_s: 0.0,
            frames,
            image,
        }
    };
    Ok(Merged {
        merge_s: t1.elapsed().as_secs_f64(),
        ..merged
    })
}

fn fill(f: Fill) -> ClippedFill {
    match f {
        Fill::Nan => ClippedFill::Nan,
        Fill::LowerBound => ClippedFill::LowerBound,
    }
}

/// Checks every number before any file is read: λ and the sample count (its lower bound follows
/// from the number of frames, known from the list or the exposures CSV).
fn check_numbers(args: &Args, frames: usize) -> anyhow::Result<()> {
    use crate::numeric::ensure;
    ensure(
        (0.0..=1e6).contains(&args.lambda),
        "--lambda",
        args.lambda,
        "the smoothness weight must lie in [0, 1e6] (Debevec & Malik 1997, eq. 3; default 10)",
    )?;
    let Some(samples) = args.samples else {
        return Ok(());
    };
    let min = scatterfit_imaging::min_response_samples(frames.max(2));
    let max = scatterfit_imaging::MAX_RESPONSE_SAMPLES;
    ensure(
        (min..=max).contains(&samples),
        "--samples",
        samples,
        &format!(
            "the response recovery takes {min} to {max} sample pixels per channel for {frames} \
             frames: with N samples and P frames Debevec & Malik's N(P − 1) ≥ 256 must hold, or \
             the curve is undetermined; more than {max} only cost time"
        ),
    )
}

/// Runs `scatterfit merge`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut inputs: Vec<&Path> = args.images.iter().map(PathBuf::as_path).collect();
    inputs.extend(args.exposures.as_deref());
    inputs.extend(args.response.as_deref());
    inputs.extend(args.dark.as_deref());
    // Frame paths listed in the CSV are inputs too.
    let listed = match &args.exposures {
        Some(csv) => scatterfit_io::bracket::read_exposures_csv(csv)?,
        None => Vec::new(),
    };
    inputs.extend(listed.iter().map(|e| e.path.as_path()));
    let frames = if args.images.is_empty() {
        listed.len()
    } else {
        args.images.len()
    };
    if args.response.is_none() {
        check_numbers(&args, frames)?;
    }
    crate::common::check_output_file(
        &args.output,
        "-o",
        crate::common::Format {
            extensions: &["exr", "hdr"],
            what: "the radiance map is written as OpenEXR or Radiance HDR",
        },
        &inputs,
        args.force,
    )?;
    let response_out = args
        .response_out
        .clone()
        .unwrap_or_else(|| default_response_out(&args.output));
    if crate::common::identity(&response_out) == crate::common::identity(&args.output) {
        bail!(
            "--response-out and -o are the same file {}; choose two files",
            args.output.display()
        );
    }
    let writes_response = args.response.is_none() || args.response_out.is_some();
    if writes_response {
        crate::common::check_output_file(
            &response_out,
            "--response-out",
            crate::common::Format {
                extensions: &["csv"],
                what: "the camera response is written as CSV",
            },
            &inputs,
            args.force,
        )?;
    }

    let merged = read_and_merge(&args, !args.json)?;
    let Merged {
        hdr,
        response,
        response_kind,
        rms,
        read_s,
        merge_s,
        frames,
        image,
    } = merged;
    let (width, height) = (hdr.radiance.width(), hdr.radiance.height());
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for (&v, &m) in hdr.radiance.data().iter().zip(hdr.clipped.data()) {
        let v = f64::from(v);
        if m == 0 && v.is_finite() && v > 0.0 {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    let ch = hdr.clipped.channels();
    let clipped_pixels = hdr
        .clipped
        .data()
        .chunks_exact(ch)
        .filter(|p| p.iter().any(|&m| m != 0))
        .count();
    // The radiance map first: if it cannot be written, no response CSV is left without it.
    write_radiance(&args.output, &hdr.radiance).context("saving the radiance map")?;
    let response_written = match &response {
        Some(curve) if writes_response => {
            let table = ResponseTable {
                g: curve.tables().iter().map(|t| t.to_vec()).collect(),
            };
            write_response_csv(&response_out, &table)?;
            Some(response_out)
        }
        _ => None,
    };

    let summary = Summary {
        frames,
        image,
        width,
        height,
        response: response_kind.to_string(),
        response_rms_residual: rms,
        radiance_min: if lo.is_finite() { lo } else { f64::NAN },
        radiance_max: if hi > 0.0 { hi } else { f64::NAN },
        dynamic_range_stops: if lo.is_finite() && hi > 0.0 {
            (hi / lo).log2()
        } else {
            f64::NAN
        },
        clipped_everywhere_samples: hdr.clipped_count,
        clipped_everywhere_pixels: clipped_pixels,
        output: args.output.clone(),
        response_out: response_written,
        read_s,
        merge_s,
    };
    if args.json {
        crate::output::print_json(&summary)?;
    } else {
        print_summary(&summary)?;
    }
    Ok(ExitCode::SUCCESS)
}

fn print_summary(s: &Summary) -> anyhow::Result<()> {
    let t_min = s.frames.first().map_or(f64::NAN, |f| f.time_s);
    let t_max = s.frames.last().map_or(f64::NAN, |f| f.time_s);
    outln!(
        "frames        {} × {} ({:.3} s read)",
        s.frames.len(),
        s.image,
        s.read_s
    )?;
    outln!(
        "times         {} s … {} s",
        crate::common::shutter(t_min),
        crate::common::shutter(t_max)
    )?;
    for f in &s.frames {
        outln!(
            "  {:>10} s  {}",
            crate::common::shutter(f.time_s),
            f.file.display()
        )?;
    }
    let rms = if s.response_rms_residual.is_empty() {
        String::new()
    } else {
        let v: Vec<String> = s
            .response_rms_residual
            .iter()
            .map(|r| format!("{r:.3}"))
            .collect();
        format!(" (weighted RMS residual {})", v.join(", "))
    };
    outln!("response      {}{rms}", s.response)?;
    outln!("merge         {:.3} s", s.merge_s)?;
    outln!(
        "radiance      {:.4e} … {:.4e} (relative), dynamic range {:.1} stops ({:.1} decades)",
        s.radiance_min,
        s.radiance_max,
        s.dynamic_range_stops,
        s.dynamic_range_stops * std::f64::consts::LOG10_2
    )?;
    outln!(
        "clipped       {} pixels ({} pixel-channels) clipped in every exposure{}",
        s.clipped_everywhere_pixels,
        s.clipped_everywhere_samples,
        if s.clipped_everywhere_samples > 0 {
            " — flagged, not estimated"
        } else {
            ""
        }
    )?;
    outln!("wrote         {}", s.output.display())?;
    if let Some(r) = &s.response_out {
        outln!("wrote         {}", r.display())?;
    }
    Ok(())
}

/// A synthetic spot bracket: a radially decaying radiance (a light spot on a translucent sample)
/// through a gamma-2.2 camera with a 1 % shot-like noise, 13 shutter times 1/600 s … 3 s.
pub(crate) fn synthetic_bracket(width: usize, height: usize) -> (Vec<ImageBuf<u8>>, Vec<f64>) {
    use rayon::prelude::*;
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
pub(crate) fn write_bracket_png(
    dir: &Path,
    frames: Vec<ImageBuf<u8>>,
    times: &[f64],
) -> anyhow::Result<PathBuf> {
    use rayon::prelude::*;
    frames
        .into_par_iter()
        .enumerate()
        .try_for_each(|(j, f)| -> anyhow::Result<()> {
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
pub(crate) fn write_bracket_jpeg(
    dir: &Path,
    frames: &[ImageBuf<u8>],
    times: &[f64],
    quality: u8,
) -> anyhow::Result<PathBuf> {
    use rayon::prelude::*;
    frames
        .par_iter()
        .enumerate()
        .try_for_each(|(j, f)| -> anyhow::Result<()> {
            let path = dir.join(format!("frame_{j:02}.jpg"));
            Ok(scatterfit_io::image_files::write_jpeg(&path, f, quality)?)
        })?;
    write_exposures_csv(dir, "jpg", "exposures_jpeg.csv", times)
}

fn write_exposures_csv(
    dir: &Path,
    ext: &str,
    name: &str,
    times: &[f64],
) -> anyhow::Result<PathBuf> {
    let mut csv = String::from("file,time_s\n");
    for (j, t) in times.iter().enumerate() {
        csv.push_str(&format!("frame_{j:02}.{ext},{t}\n"));
    }
    let csv_path = dir.join(name);
    scatterfit_io::atomic::write_atomic(&csv_path, csv.as_bytes())
        .with_context(|| format!("writing {}", csv_path.display()))?;
    Ok(csv_path)
}

/// Contributes this area's figures to `scatterfit bench`: the end-to-end merge of a 13-exposure
/// 24-MP 8-bit RGB bracket (PNG files read from disk, response recovered, merged; the same from
/// quality-90 JPEGs) and the radial
/// profile of the 24-MP radiance map. Set `SCATTERFIT_BENCH_BRACKET_DIR` to keep the bracket there
/// (for timing `scatterfit merge` itself, e.g. under `/usr/bin/time -v`).
pub fn bench(args: &crate::bench::Args) -> anyhow::Result<Vec<crate::bench::Figure>> {
    use crate::bench::Figure;
    let (width, height) = if args.quick {
        (1200, 800)
    } else {
        (6000, 4000)
    };
    let mp = (width * height) as f64 / 1e6;
    let threads = rayon::current_num_threads();
    let (frames, times) = synthetic_bracket(width, height);
    let keep = std::env::var_os("SCATTERFIT_BENCH_BRACKET_DIR").map(PathBuf::from);
    let temp = tempfile::tempdir().context("creating a temporary folder for the bracket")?;
    let dir = match &keep {
        Some(d) => {
            std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
            d.clone()
        }
        None => temp.path().to_path_buf(),
    };
    // JPEG first (it borrows the frames), quality 90 as a camera would write; then the PNGs.
    let jpeg_csv = write_bracket_jpeg(&dir, &frames, &times, 90)?;
    let csv = write_bracket_png(&dir, frames, &times)?;
    let merge_args = Args {
        images: Vec::new(),
        exposures: Some(csv),
        response: None,
        dark: None,
        lambda: 10.0,
        samples: None,
        saturation: u16::MAX,
        clipped_fill: Fill::Nan,
        weighting: WeightingArg::NoiseOptimal,
        output: dir.join("radiance.exr"),
        response_out: None,
        force: true,
        max_memory_mib: None,
        json: true,
    };
    let t0 = Instant::now();
    let merged = read_and_merge(&merge_args, false)?;
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
            note,
        },
    ];
    drop(merged.hdr.clipped);
    let radiance = merged.hdr.radiance;
    // The same bracket as quality-90 JPEGs (files as a camera writes them): reading only, then the
    // whole read + recover + merge. The PNG result is kept for the profile below.
    let jpeg_args = Args {
        exposures: Some(jpeg_csv),
        output: dir.join("radiance_jpeg.exr"),
        ..merge_args
    };
    let t0 = Instant::now();
    let jpeg = read_and_merge(&jpeg_args, false)?;
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
