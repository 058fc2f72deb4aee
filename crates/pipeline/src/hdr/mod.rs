//! Stage 2: the exposure bracket → a relative radiance map (Debevec & Malik 1997), and the
//! bracket's detection limit per channel.
//!
//! The detection limit is the radiance that gives [`DETECTION_CODE`] in the longest exposure
//! (8-bit: E = exp g(z)/Δt_max; 16-bit linear: [`DETECTION_DN_16BIT`] counts/Δt_max). Below it a
//! pixel's best frame reads the sensor's noise floor — a few codes of read noise, quantisation and
//! the toe of the tone curve, where the recovered response is least certain — so a ring whose mean
//! lies below it is "there, not measured" and the fit leaves it out (`scatterfit_fit::profile`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use scatterfit_imaging::{
    CalibrateOptions, HdrImage, ImageBuf, LEVELS, LinearMergeOptions, MergeOptions, ResponseCurve,
    SelfConsistency, Weighting,
};
use scatterfit_io::bracket::{Bracket, read_bracket_within};
use scatterfit_io::image_files::{CameraFrame, RawInfo, read_camera_frame};
use scatterfit_io::manifest::ExposureCorrection;
use scatterfit_io::response_csv::read_response_csv;
use serde::Serialize;

use crate::camera::{ExposureEstimate, estimate_black_level, estimate_exposures, flat_divisor};
use crate::error::{PipelineError, Result};

/// How the bracket became radiance (the name `result.json` records).
pub use scatterfit_io::result_json::ResponseKind;

pub mod frames;
pub mod inputs;
mod merge;
pub mod radiance_map;
pub mod spot_image;
pub use inputs::{BlackLevel, HdrInputs};
pub use merge::{FLAT_MAX_PEAK, FLAT_MIN_LOW};
pub use radiance_map::read_radiance_map;
pub use spot_image::spot_kernel_from_image;

use merge::*;

/// Exposure corrections estimated from the frames are applied automatically
/// ([`ExposureCorrection::Auto`]) when some frame's time is off by more than this (1 %): a good
/// shutter's scatter and the estimate's own (about 0.1 % on the twin) stay below it.
pub const EXPOSURE_AUTO_THRESHOLD: f64 = 0.01;

/// A frame whose estimated exposure differs from its nominal time by more than half a stop
/// (a factor 2^±½ = 0.707–1.414) beyond three standard errors of the estimate is refused
/// ([`scatterfit_imaging::ImagingError::ExposureMismatch`]): no shutter errs so much, so the file
/// does not belong to its time (a frame listed twice is a whole bracket step off: 1.9× or more).
/// Within half a stop the estimate is a correction, not a refusal: real cameras' times are
/// rounded to the marked speeds (1/3000 s for 1/3049 s on a phone), long film exposures fail
/// reciprocity (Debevec's memorial at 32 s: 0.75×), and a response recovered from the same bracket
/// leaves the times known only up to its own bend (BENCHMARKS.md, "Real brackets").
pub const EXPOSURE_MISMATCH_STOPS: f64 = 0.5;

/// Refuses an exposure estimate that moves a frame by more than [`EXPOSURE_MISMATCH_STOPS`] beyond
/// three standard errors.
fn check_exposure(est: &ExposureEstimate, times: &[f64]) -> Result<()> {
    let limit = EXPOSURE_MISMATCH_STOPS * std::f64::consts::LN_2;
    if let Some((frame, f)) = est.factor.iter().enumerate().find(|(j, f)| {
        let se = est.stderr_ln.get(*j).copied().unwrap_or(0.0);
        f.ln().abs() > limit + 3.0 * se
    }) {
        return Err(PipelineError::Imaging {
            context: "estimating the exposures from the frames".into(),
            source: scatterfit_imaging::ImagingError::ExposureMismatch {
                frame,
                time_s: times[frame],
                factor: *f,
                limit: 2f64.powf(EXPOSURE_MISMATCH_STOPS),
            },
        });
    }
    Ok(())
}

/// What the HDR stage found and corrected of a real camera (BENCHMARKS.md, "Real cameras").
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Corrections {
    /// The black level subtracted from linear frames [DN per channel] and where it came from
    /// (`dark frame`, `metadata`, `given`, `far corners`); `None` when none was.
    pub black_level: Option<(Vec<f64>, &'static str)>,
    /// A black level not read off the bracket itself (given, stated as none, from the RAW
    /// metadata, or a dark frame) against the far corners' intercept at Δt = 0 ([`BlackLevelCheck::disagreement`];
    /// not written).
    #[serde(skip)]
    pub black_level_check: Option<BlackLevelCheck>,
    /// The exposure times estimated from the frames, and whether they replaced the nominal ones.
    pub exposure: Option<ExposureEstimate>,
    /// True when the estimated times were used.
    pub exposure_applied: bool,
    /// 8-bit merges whose estimated times would have been applied: the decimated bracket's
    /// self-consistency merged at the stated times and at the corrected ones, each scored at its
    /// own times \[code values\] (the corrected times kept only when clearly better; not written).
    #[serde(skip)]
    pub exposure_judged: Option<[f64; 2]>,
    /// The flat frame divided out, with its smoothed fall-off (min and max of the divisor).
    pub flat: Option<(PathBuf, f64, f64)>,
    /// The codes 16-bit frames use and the saturation found ([`frames::code_range`]; not
    /// written: the quality verdict reports what matters).
    #[serde(skip)]
    pub codes: Option<frames::CodeRange>,
    /// The spot's centroid per frame ([`frames::registration`]; not written).
    #[serde(skip)]
    pub registration: Option<frames::Registration>,
    /// 8-bit merges: the expected-signal floor per channel given to the merge
    /// ([`scatterfit_imaging::MergeOptions::expected_floor`]: the code whose exposure is
    /// [`EXPECTED_FLOOR_FRACTION`] of the noise-aware detection code's; not written).
    #[serde(skip)]
    pub expected_floor: Option<[u8; 4]>,
    /// The frames (indices by time, shortest first) left out of the merge because they carry no
    /// signal: nothing above their noise floor but for a few values, or everything clipped
    /// ([`scatterfit_imaging::bracket_signal`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub no_signal: Vec<usize>,
    /// 8-bit merges: the weighting used per channel ([`HdrInputs::weighting_auto`] chooses it;
    /// empty for other merges; not written).
    #[serde(skip)]
    pub weighting: Vec<Weighting>,
    /// 8-bit merges: the response refitted to the merged map, with the decimated bracket's
    /// self-consistency before and after \[code values\] (`None`: the recovered curve kept; not
    /// written).
    #[serde(skip)]
    pub response_refit: Option<[f64; 2]>,
    /// 8-bit merges: how well the merged map and the response explain the frames at their stated
    /// times ([`scatterfit_imaging::self_consistency`]; not written).
    #[serde(skip)]
    pub self_consistency: Option<SelfConsistency>,
    /// Where the merge's time went: (part, wall seconds) in the order the parts ran, a part that
    /// ran more than once (the response recovery's rounds) summed (not written; `scatterfit bench
    /// imaging` shows them).
    #[serde(skip)]
    pub timings: Vec<(&'static str, f64)>,
    /// Linear merges: the far corners' straight line in exposure time and the frame that departs
    /// most from it, per channel ([`crate::camera::estimate_black_level`]; the ambient-light check
    /// reads it; not written).
    #[serde(skip)]
    pub corners: Option<crate::camera::BlackLevelEstimate>,
}

impl Corrections {
    /// Adds `seconds` to the part `name` of [`Corrections::timings`].
    pub(crate) fn time(&mut self, name: &'static str, seconds: f64) {
        match self.timings.iter_mut().find(|(n, _)| *n == name) {
            Some((_, s)) => *s += seconds,
            None => self.timings.push((name, seconds)),
        }
    }

    /// Runs `f`, adding its wall time to the part `name`.
    pub(crate) fn timed<R>(&mut self, name: &'static str, f: impl FnOnce() -> R) -> R {
        let t = Instant::now();
        let r = f();
        self.time(name, t.elapsed().as_secs_f64());
        r
    }
}

/// A stated black level beside what the bracket's far corners say it is.
#[derive(Debug, Clone, PartialEq)]
pub struct BlackLevelCheck {
    /// Where the stated level came from: `given`, `none` (stated as no pedestal), `metadata` or
    /// `dark frame`.
    pub source: &'static str,
    /// The level subtracted, per channel \[DN\] (a dark frame's: its far corners' mean).
    pub stated: Vec<f64>,
    /// The far corners' level at Δt = 0 and its standard error, per channel \[DN\]
    /// ([`crate::camera::estimate_black_level`]).
    pub corners: Vec<f64>,
    /// The standard errors of `corners` \[DN\].
    pub corners_stderr: Vec<f64>,
    /// The saturation code the merge uses \[DN\] (the full scale the tolerance is a part of).
    pub saturation: f64,
    /// True when the shortest frame's corners clip at 0 (no pedestal to read: the check says
    /// nothing).
    pub clipped_at_zero: bool,
}

/// The 8-bit code at which a pixel counts as detected in the longest exposure. Below it the tone
/// curve's toe, where the recovered response is least certain, and quantisation bias the merged
/// radiance: on the rig twin's steep profiles (α′ = 0.3–0.7, η = 2.4, exact forward model) a
/// threshold of code 5 left σ′s errors up to 5.6 %, code 15 up to 3 %, code 30 up to 1.5 % with no
/// loss elsewhere (BENCHMARKS.md, "the bias study"). Code 30 is about 200 photo-electrons on the
/// twin's camera (a signal-to-noise ratio near 14 per pixel). It is the floor: a camera whose
/// codes are noisier there (a log curve, high read noise) gets a higher code per channel, the
/// lowest at which the noise measured on its bracket gives a signal-to-noise ratio of
/// [`DETECTION_SNR`] per pixel (`merge::detection_codes`).
pub const DETECTION_CODE: u8 = 30;

/// The per-pixel signal-to-noise ratio a code must reach in the longest exposure to count as
/// detected (`merge::detection_codes`). The twin's default camera reaches about 14 at code 30; a log
/// curve with 15 e⁻ read noise puts code 30 at about 30 e⁻ (SNR 2) and reaches 10 near code 75.
/// Below it the merged radiance of the twin's camera sweep was biased by up to 25 % (BENCHMARKS.md).
pub const DETECTION_SNR: f64 = 10.0;

/// The merge's expected-signal floor as a fraction of the detection code's exposure X(z_det)
/// (`imaging::MergeOptions::expected_floor`): a frame whose expected exposure at a pixel is below
/// 0.3·X(z_det) is left out there. At the detection code the signal-to-noise ratio is
/// [`DETECTION_SNR`] = 10, so at 0.3 of it at least 3 (read noise) to 5.5 (shot noise): a reading
/// is then negative (censored at code 0) with probability ≈ 0.1 % or less, and the frames between keep
/// counting. With the detection code itself as the floor the far field's ring medians, which the
/// second-spot check uses, moved by 5 % on the checks test's twin (a tenth-strength second spot
/// was no longer found; likely because those pixels kept their longest frame alone, whose codes
/// are coarse there).
pub const EXPECTED_FLOOR_FRACTION: f64 = 0.3;

/// The 16-bit linear value at which a pixel counts as detected in the longest exposure.
pub const DETECTION_DN_16BIT: f64 = 64.0;

/// One frame of the bracket.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameInfo {
    /// The file.
    pub file: PathBuf,
    /// Shutter time \[s\].
    pub time_s: f64,
    /// SHA-256 of the file's bytes that were decoded and merged, lower-case hex (what
    /// `result.json` records for the frame; not in `scatterfit merge --json`).
    #[serde(skip)]
    pub sha256: String,
    /// The JPEG quality the file was saved at, read from the header of the bytes decoded
    /// (`scatterfit_io::image_files::jpeg_quality`); `None` for other formats.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jpeg_quality: Option<f64>,
}

/// The merged bracket.
#[derive(Debug, Clone)]
pub struct HdrStage {
    /// Radiance and clipping mask.
    pub hdr: HdrImage,
    /// The response used (8-bit), `None` for a linear 16-bit merge or a given radiance map.
    pub response: Option<ResponseCurve>,
    /// Recovered, given, linear or merged (a radiance map from the manifest).
    pub response_kind: ResponseKind,
    /// RMS residual of the response recovery per channel (recovered responses only).
    pub rms: Vec<f64>,
    /// The frames, shortest first.
    pub frames: Vec<FrameInfo>,
    /// The radiance map file read instead of a bracket (the manifest's `camera.hdr`), with the
    /// SHA-256 of the bytes decoded; `None` for a merged bracket.
    pub radiance_file: Option<scatterfit_io::digest::ReadFile>,
    /// e.g. `1024×1024 RGB 8-bit`.
    pub image: String,
    /// Detection limit per channel [relative radiance]; NaN when unknown.
    pub detection_limit: Vec<f64>,
    /// Frames whose alpha channel was dropped.
    pub dropped_alpha: Vec<PathBuf>,
    /// Wall time reading \[s\].
    pub read_s: f64,
    /// Wall time recovering and merging \[s\].
    pub merge_s: f64,
    /// What was found and corrected of a real camera (black level, exposure times, flat).
    pub corrections: Corrections,
    /// The frames as read, shortest first, reduced to at most [`THUMBNAIL_SIDE`] pixels (8-bit
    /// RGB, point-sampled; 16-bit linear frames through the sRGB curve): what a report shows of the bracket without reading it again. Empty
    /// for a given radiance map.
    pub thumbnails: Vec<ImageBuf<u8>>,
}

/// Longest side of [`HdrStage::thumbnails`] \[px\].
pub const THUMBNAIL_SIDE: usize = 96;

/// `frame` point-sampled at the centres of a grid of at most [`THUMBNAIL_SIDE`] pixels, as 8-bit
/// RGB (16-bit samples, linear, through the sRGB curve; grey is repeated): cheap (a few thousand samples per
/// frame), enough to see the spot, clipping and misalignment.
fn thumbnail(frame: &CameraFrame) -> Option<ImageBuf<u8>> {
    let (w, h) = (frame.width(), frame.height());
    let step = w.max(h).div_ceil(THUMBNAIL_SIDE).max(1);
    let (tw, th) = (w.div_ceil(step), h.div_ceil(step));
    let mut data = Vec::with_capacity(tw * th * 3);
    for ty in 0..th {
        let y = (ty * step + step / 2).min(h - 1);
        for tx in 0..tw {
            let x = (tx * step + step / 2).min(w - 1);
            let px: [u8; 3] = match frame {
                CameraFrame::U8(b) => {
                    let p = b.pixel(x, y)?;
                    std::array::from_fn(|c| p[c.min(p.len() - 1)])
                }
                CameraFrame::U16(b) => {
                    // 16-bit frames are linear: encoded with the sRGB curve for display.
                    let p = b.pixel(x, y)?;
                    std::array::from_fn(|c| {
                        let v = f64::from(p[c.min(p.len() - 1)]) / f64::from(u16::MAX);
                        (scatterfit_optics::colour::srgb_encode(v) * 255.0).round() as u8
                    })
                }
            };
            data.extend_from_slice(&px);
        }
    }
    ImageBuf::new(tw, th, 3, data).ok()
}

/// Why a dark frame shows light, or `None`: the means of its 8 × 8 blocks (a hot pixel is diluted
/// 64-fold; a sensor's glow is smooth) against their median — a block brighter by more than 20 robust
/// standard deviations (1.4826 × the median absolute deviation) and by more than 8 codes in 8 bits
/// (2 % of full scale in 16) holds a lit region: the spot, a lamp. A dark frame's blocks differ by
/// its read noise over 8 pixels and its glow; the shortest frame of a bracket, given as the dark
/// frame, holds the spot at tens of codes.
fn lit_dark_frame(frame: &CameraFrame) -> Option<String> {
    const BLOCK: usize = 8;
    let (w, h) = (frame.width(), frame.height());
    let (bw, bh) = (w / BLOCK, h / BLOCK);
    if bw * bh < 16 {
        return None;
    }
    let (floor, value): (f64, Box<dyn Fn(usize, usize) -> f64>) = match frame {
        CameraFrame::U8(b) => (
            8.0,
            Box::new(move |x, y| {
                b.pixel(x, y).map_or(0.0, |p| {
                    p.iter().map(|&v| f64::from(v)).sum::<f64>() / p.len() as f64
                })
            }),
        ),
        CameraFrame::U16(b) => (
            0.02 * f64::from(u16::MAX),
            Box::new(move |x, y| {
                b.pixel(x, y).map_or(0.0, |p| {
                    p.iter().map(|&v| f64::from(v)).sum::<f64>() / p.len() as f64
                })
            }),
        ),
    };
    let mut means: Vec<(f64, usize, usize)> = Vec::with_capacity(bw * bh);
    for by in 0..bh {
        for bx in 0..bw {
            let mut s = 0.0;
            for y in by * BLOCK..(by + 1) * BLOCK {
                for x in bx * BLOCK..(bx + 1) * BLOCK {
                    s += value(x, y);
                }
            }
            means.push((s / (BLOCK * BLOCK) as f64, bx, by));
        }
    }
    let mut sorted: Vec<f64> = means.iter().map(|m| m.0).collect();
    let mid = sorted.len() / 2;
    let median = *sorted.select_nth_unstable_by(mid, f64::total_cmp).1;
    let mut dev: Vec<f64> = sorted.iter().map(|v| (v - median).abs()).collect();
    let sd = 1.4826 * *dev.select_nth_unstable_by(mid, f64::total_cmp).1;
    let (top, bx, by) = means.iter().copied().max_by(|a, b| a.0.total_cmp(&b.0))?;
    (top - median > floor.max(20.0 * sd)).then(|| {
        format!(
            "the dark frame shows light: the 8 × 8 block at ({}, {}) px averages {top:.1} against \
             a median of {median:.1} over the frame",
            bx * BLOCK,
            by * BLOCK
        )
    })
}

/// The bracket (and dark frame) read and checked, before any pixel work: the first half of
/// [`read_and_merge`], for a caller that reports on the frames or checks the merge's memory before
/// merging ([`FramesRead::decoded_bytes`], [`FramesRead::samples_per_frame`]).
#[derive(Debug, Clone)]
pub struct FramesRead {
    bracket: Bracket,
    dark: Option<CameraFrame>,
    flat: Option<(PathBuf, CameraFrame)>,
    raw: Option<RawInfo>,
    /// The frames, shortest first.
    pub frames: Vec<FrameInfo>,
    /// e.g. `1024×1024 RGB 8-bit`.
    pub image: String,
    /// Frames whose alpha channel was dropped.
    pub dropped_alpha: Vec<PathBuf>,
    /// Wall time reading \[s\].
    pub read_s: f64,
}

impl FramesRead {
    /// Samples (pixels × channels) in one frame, which the merged map has too.
    pub fn samples_per_frame(&self) -> u64 {
        let first = &self.bracket.frames()[0].frame;
        (first.width() * first.height() * first.channels()) as u64
    }

    /// Bytes the decoded frames hold.
    pub fn decoded_bytes(&self) -> u64 {
        let first = &self.bracket.frames()[0].frame;
        self.samples_per_frame()
            * u64::from(first.bit_depth() / 8)
            * self.bracket.frames().len() as u64
    }
}

/// The default number of sample pixels per channel for the response recovery of a bracket of
/// `frames` frames: 100, or Debevec & Malik's minimum ⌈256/(P − 1)⌉ when that is larger.
pub fn default_response_samples(frames: usize) -> usize {
    100.max(scatterfit_imaging::min_response_samples(frames))
}

/// Reads the bracket and merges it: [`read_frames`] then [`merge_frames`]. `on_frame_read` is
/// called once per decoded frame.
///
/// # Errors
/// As [`read_frames`] and [`merge_frames`].
pub fn read_and_merge(
    inputs: &HdrInputs,
    on_frame_read: &(dyn Fn(&Path) + Sync),
) -> Result<HdrStage> {
    merge_frames(read_frames(inputs, on_frame_read)?, inputs)
}

/// Reads the bracket (its decoded size checked against `inputs.memory_budget` first) and the dark
/// frame. `on_frame_read` is called once per decoded frame.
///
/// # Errors
/// [`PipelineError::Bracket`] for a bracket that cannot be read or is inconsistent;
/// [`PipelineError::DarkFrame`] / [`PipelineError::DarkFrameShape`] for a dark frame that cannot
/// be read or differs in shape from the frames.
pub fn read_frames(
    inputs: &HdrInputs,
    on_frame_read: &(dyn Fn(&Path) + Sync),
) -> Result<FramesRead> {
    let t0 = Instant::now();
    let budget = inputs
        .memory_budget
        .unwrap_or_else(scatterfit_io::budget::memory_budget_bytes);
    let bracket: Bracket = read_bracket_within(
        &inputs.images,
        inputs.exposures.as_deref(),
        budget,
        on_frame_read,
    )?;
    let dropped_alpha = bracket
        .frames()
        .iter()
        .filter(|f| f.dropped_alpha)
        .map(|f| f.path.clone())
        .collect();
    let dark = match &inputs.dark {
        Some(path) => {
            let d = read_camera_frame(path).map_err(PipelineError::DarkFrame)?;
            bracket
                .check_same_shape(&d.frame, path)
                .map_err(PipelineError::DarkFrameShape)?;
            if let Some(why) = lit_dark_frame(&d.frame) {
                return Err(PipelineError::Input(format!(
                    "{} (camera.dark): {why} — a dark frame is taken with the light off (or the \
                     lens capped) at the bracket's settings; is this a frame of the bracket?",
                    path.display()
                )));
            }
            Some(d.frame)
        }
        None => None,
    };
    let flat = match &inputs.flat {
        Some(path) => {
            let d = read_camera_frame(path).map_err(PipelineError::FlatFrame)?;
            bracket
                .check_same_shape(&d.frame, path)
                .map_err(PipelineError::FlatFrameShape)?;
            Some((path.clone(), d.frame))
        }
        None => None,
    };
    let raw = bracket.frames()[0].raw;
    let frames = bracket
        .frames()
        .iter()
        .map(|f| FrameInfo {
            file: f.path.clone(),
            time_s: f.time_s,
            sha256: f.sha256.clone(),
            jpeg_quality: f.jpeg_quality,
        })
        .collect();
    let image = bracket.describe();
    Ok(FramesRead {
        bracket,
        dark,
        flat,
        raw,
        frames,
        image,
        dropped_alpha,
        read_s: t0.elapsed().as_secs_f64(),
    })
}

/// An 8-bit frame's codes as relative exposure through the camera response: exp g(Z) per sample
/// (one table for every channel, or one per channel), code 0 as no light. A flat frame and a spot
/// image taken with the bracket's camera are linearised this way.
pub(crate) fn linearise_u8(frame: &ImageBuf<u8>, response: &ResponseCurve) -> Vec<f32> {
    let tables = response.tables();
    let ch = frame.channels();
    // exp g(z) per channel and code, once (the same values as per sample).
    let lin: Vec<[f32; LEVELS]> = (0..ch)
        .map(|c| {
            let g = &tables[if tables.len() == 1 { 0 } else { c }];
            std::array::from_fn(|z| if z == 0 { 0.0 } else { g[z].exp() as f32 })
        })
        .collect();
    let mut out = Vec::with_capacity(frame.data().len());
    for px in frame.data().chunks_exact(ch) {
        out.extend(px.iter().zip(&lin).map(|(&z, l)| l[usize::from(z)]));
    }
    out
}

/// Merges a bracket read by [`read_frames`]: 8-bit frames through the given response
/// (`inputs.response`) or one recovered from the frames (`inputs.samples`, `inputs.lambda`),
/// 16-bit and RAW frames as linear data (`inputs.saturation`, or the RAW file's white level) less
/// their black level; the dark frame subtracted; the exposure times estimated from the frames and,
/// when they differ (`inputs.exposure_correction`), used; the flat frame divided out; the detection
/// limit per channel. The frames' order is checked first
/// ([`scatterfit_imaging::check_bracket_order`]).
///
/// # Errors
/// [`PipelineError::ResponseCsv`] / [`PipelineError::Input`] for a bad response file or a response
/// given for 16-bit frames; [`PipelineError::Imaging`] when the frames are out of order, the
/// response cannot be recovered or the merge fails.
pub fn merge_frames(read: FramesRead, inputs: &HdrInputs) -> Result<HdrStage> {
    let FramesRead {
        bracket,
        dark,
        flat,
        raw,
        frames,
        image,
        dropped_alpha,
        read_s,
    } = read;
    let times = bracket.times_s();
    let t1 = Instant::now();
    let order_context = || {
        let names: Vec<String> = frames
            .iter()
            .enumerate()
            .map(|(k, f)| {
                format!(
                    "{k} = {}",
                    f.file.file_name().map_or_else(
                        || f.file.display().to_string(),
                        |n| n.to_string_lossy().into_owned()
                    )
                )
            })
            .collect();
        format!(
            "checking the bracket's order (frames by time: {})",
            names.join(", ")
        )
    };
    let mut corrections = Corrections::default();
    let thumbnails: Vec<ImageBuf<u8>> = bracket
        .frames()
        .iter()
        .filter_map(|f| thumbnail(&f.frame))
        .collect();
    let depth = bracket.frames()[0].frame.bit_depth();
    if depth == 8 && inputs.saturation_given {
        return Err(PipelineError::Input(format!(
            "camera.saturation = {} applies to 16-bit and RAW frames; these frames are 8-bit (they \
             clip at code 255 and their response is recovered): remove the key",
            inputs.saturation
        )));
    }
    let cx = MergeContext {
        times: &times,
        dark,
        flat: flat.as_ref(),
        inputs,
        order: &order_context,
    };
    let merged = if depth == 8 {
        let bufs: Vec<ImageBuf<u8>> = bracket
            .into_frames()
            .into_iter()
            .filter_map(|f| match f.frame {
                CameraFrame::U8(b) => Some(b),
                CameraFrame::U16(_) => None,
            })
            .collect();
        merge_8bit(bufs, cx, &mut corrections)?
    } else {
        let bufs: Vec<ImageBuf<u16>> = bracket
            .into_frames()
            .into_iter()
            .filter_map(|f| match f.frame {
                CameraFrame::U16(b) => Some(b),
                CameraFrame::U8(_) => None,
            })
            .collect();
        merge_linear(bufs, raw, cx, &mut corrections)?
    };
    let mut stage = HdrStage {
        hdr: merged.hdr,
        response: merged.response,
        response_kind: merged.kind,
        rms: merged.rms,
        frames,
        radiance_file: None,
        image,
        detection_limit: merged.detection_limit,
        dropped_alpha,
        read_s,
        merge_s: 0.0,
        corrections: Corrections::default(),
        thumbnails,
    };
    if let Some((path, f)) = &flat
        && corrections.flat.is_none()
    {
        return Err(PipelineError::Input(format!(
            "{}: the flat frame is {}-bit, the bracket {depth}-bit; take it with the same camera \
             settings",
            path.display(),
            f.bit_depth()
        )));
    }
    stage.corrections = corrections;
    stage.merge_s = t1.elapsed().as_secs_f64();
    Ok(stage)
}

/// Reads a response CSV into a curve with 256 levels.
///
/// # Errors
/// [`PipelineError::ResponseCsv`] or [`PipelineError::Input`] for a table of another size.
pub fn load_response(path: &Path) -> Result<ResponseCurve> {
    let table = read_response_csv(path)?;
    if table.levels() != LEVELS {
        return Err(PipelineError::Input(format!(
            "{}: {} rows, but a response for 8-bit frames lists g(z) for z = 0..255 (256 rows)",
            path.display(),
            table.levels()
        )));
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
    ResponseCurve::from_log_exposure(g).map_err(|source| PipelineError::Imaging {
        context: format!("camera response {}", path.display()),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thumbnails_keep_the_aspect_and_sample_block_centres() {
        // 8-bit, 1000 × 500, value = x / 4 in R, y / 2 in G, 7 in B.
        let (w, h) = (1000usize, 500usize);
        let data: Vec<u8> = (0..h)
            .flat_map(|y| (0..w).flat_map(move |x| [(x / 4) as u8, (y / 2) as u8, 7]))
            .collect();
        let frame = CameraFrame::U8(ImageBuf::new(w, h, 3, data).unwrap());
        let t = thumbnail(&frame).unwrap();
        // step = ceil(1000 / 96) = 11: 91 × 46 samples at the centres 5, 16, 27, …
        assert_eq!((t.width(), t.height(), t.channels()), (91, 46, 3));
        assert_eq!(t.pixel(0, 0).unwrap(), &[1, 2, 7]);
        assert_eq!(t.pixel(2, 3).unwrap(), &[(27 / 4) as u8, (38 / 2) as u8, 7]);
        // 16-bit linear grey: full scale → 255, half → sRGB 0.7354 → 188, zero → 0.
        let grey = |v: u16| {
            let f = CameraFrame::U16(ImageBuf::filled(4, 4, 1, v).unwrap());
            thumbnail(&f).unwrap().pixel(1, 1).unwrap().to_vec()
        };
        assert_eq!(grey(u16::MAX), [255, 255, 255]);
        assert_eq!(grey(32768), [188, 188, 188]);
        assert_eq!(grey(0), [0, 0, 0]);
    }
}
