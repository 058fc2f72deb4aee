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
    CalibrateOptions, ClippedFill, HdrImage, ImageBuf, LEVELS, LinearMergeOptions, MergeOptions,
    ResponseCurve, Weighting,
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

/// Exposure corrections estimated from the frames are applied automatically
/// ([`ExposureCorrection::Auto`]) when some frame's time is off by more than this (1 %): a good
/// shutter's scatter and the estimate's own (about 0.1 % on the twin) stay below it.
pub const EXPOSURE_AUTO_THRESHOLD: f64 = 0.01;

/// A frame whose estimated exposure differs from its nominal time by more than this (25 %) is
/// refused ([`scatterfit_imaging::ImagingError::ExposureMismatch`]): no shutter errs so much; the
/// file does not belong to its time.
pub const EXPOSURE_MISMATCH_LIMIT: f64 = 0.25;

/// Refuses an exposure estimate that moves a frame by more than [`EXPOSURE_MISMATCH_LIMIT`].
fn check_exposure(est: &ExposureEstimate, times: &[f64]) -> Result<()> {
    if let Some((frame, f)) = est
        .factor
        .iter()
        .enumerate()
        .find(|(_, f)| (*f - 1.0).abs() > EXPOSURE_MISMATCH_LIMIT)
    {
        return Err(PipelineError::Imaging {
            context: "estimating the exposures from the frames".into(),
            source: scatterfit_imaging::ImagingError::ExposureMismatch {
                frame,
                time_s: times[frame],
                factor: *f,
                limit: 100.0 * EXPOSURE_MISMATCH_LIMIT,
            },
        });
    }
    Ok(())
}

/// The black level of linear frames.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum BlackLevel {
    /// From a dark frame when given, else the RAW file's metadata, else the far corners
    /// ([`crate::camera::estimate_black_level`]).
    #[default]
    Auto,
    /// None (the frames are black-subtracted already).
    None,
    /// Given per channel \[DN\] (one value for all channels is repeated).
    Given(Vec<f64>),
}

/// What the HDR stage found and corrected of a real camera (issue 16).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Corrections {
    /// The black level subtracted from linear frames [DN per channel] and where it came from
    /// (`dark frame`, `metadata`, `given`, `far corners`); `None` when none was.
    pub black_level: Option<(Vec<f64>, &'static str)>,
    /// The exposure times estimated from the frames, and whether they replaced the nominal ones.
    pub exposure: Option<ExposureEstimate>,
    /// True when the estimated times were used.
    pub exposure_applied: bool,
    /// The flat frame divided out, with its smoothed fall-off (min and max of the divisor).
    pub flat: Option<(PathBuf, f64, f64)>,
    /// The codes 16-bit frames use and the saturation found ([`crate::checks::code_range`]; not
    /// written: the quality verdict reports what matters).
    #[serde(skip)]
    pub codes: Option<crate::checks::CodeRange>,
    /// The spot's centroid per frame ([`crate::checks::registration`]; not written).
    #[serde(skip)]
    pub registration: Option<crate::checks::Registration>,
}

/// The 8-bit code at which a pixel counts as detected in the longest exposure. Below it the tone
/// curve's toe, where the recovered response is least certain, and quantisation bias the merged
/// radiance: on the rig twin's steep profiles (α′ = 0.3–0.7, η = 2.4, exact forward model) a
/// threshold of code 5 left σ′s errors up to 5.6 %, code 15 up to 3 %, code 30 up to 1.5 % with no
/// loss elsewhere (BENCHMARKS.md, "the bias study"). Code 30 is about 200 photo-electrons on the
/// twin's camera (a signal-to-noise ratio near 14 per pixel).
pub const DETECTION_CODE: u8 = 30;

/// The 16-bit linear value at which a pixel counts as detected in the longest exposure.
pub const DETECTION_DN_16BIT: f64 = 64.0;

/// What to merge and how.
#[derive(Debug, Clone, PartialEq)]
pub struct HdrInputs {
    /// The frames (may be empty when `exposures` lists them).
    pub images: Vec<PathBuf>,
    /// `exposures.csv` (file,time_s), or `None` for EXIF times.
    pub exposures: Option<PathBuf>,
    /// A known response CSV (8-bit only).
    pub response: Option<PathBuf>,
    /// A dark frame.
    pub dark: Option<PathBuf>,
    /// Smoothness λ of the response recovery.
    pub lambda: f64,
    /// Sample pixels per channel for the response recovery; `None` for
    /// [`default_response_samples`] of the bracket's frame count (what `measure` uses).
    pub samples: Option<usize>,
    /// 16-bit saturation value.
    pub saturation: u16,
    /// True when `saturation` was stated (`camera.saturation`): it then overrides the clipping
    /// plateau found in the frames and a RAW file's white level; 8-bit frames are refused with it.
    pub saturation_given: bool,
    /// What to store for pixel-channels clipped in every exposure.
    pub clipped_fill: ClippedFill,
    /// 8-bit sample weighting.
    pub weighting: Weighting,
    /// Memory budget in bytes that the decoded frames are checked against before any is decoded;
    /// `None` for the environment's ([`scatterfit_io::budget::memory_budget_bytes`]).
    pub memory_budget: Option<u64>,
    /// The black level of linear frames (default auto).
    pub black_level: BlackLevel,
    /// Whether exposure times are estimated from the frames and used (default auto).
    pub exposure_correction: ExposureCorrection,
    /// A flat frame (vignetting), divided out of the radiance.
    pub flat: Option<PathBuf>,
}

impl HdrInputs {
    /// Defaults (λ = 10, the bracket's default sample count, 65535 saturation, NaN fill, noise-optimal weighting, the
    /// environment's memory budget) for a bracket listed in `exposures`.
    pub fn new(exposures: Option<PathBuf>, images: Vec<PathBuf>) -> Self {
        Self {
            images,
            exposures,
            response: None,
            dark: None,
            lambda: 10.0,
            samples: None,
            saturation: u16::MAX,
            saturation_given: false,
            clipped_fill: ClippedFill::Nan,
            weighting: Weighting::NoiseOptimal,
            memory_budget: None,
            black_level: BlackLevel::Auto,
            exposure_correction: ExposureCorrection::Auto,
            flat: None,
        }
    }

    /// Every input file named (for "is this output one of the inputs?" checks), frames listed in
    /// the exposures CSV included.
    ///
    /// # Errors
    /// [`PipelineError::Bracket`] when the exposures CSV cannot be read.
    pub fn input_files(&self) -> Result<Vec<PathBuf>> {
        let mut v = self.images.clone();
        v.extend(self.exposures.clone());
        v.extend(self.response.clone());
        v.extend(self.dark.clone());
        v.extend(self.flat.clone());
        if let Some(csv) = &self.exposures {
            v.extend(
                scatterfit_io::bracket::read_exposures_csv(csv)?
                    .into_iter()
                    .map(|e| e.path),
            );
        }
        Ok(v)
    }
}

/// One frame of the bracket.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameInfo {
    /// The file.
    pub file: PathBuf,
    /// Shutter time \[s\].
    pub time_s: f64,
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
            Some(d.frame)
        }
        None => None,
    };
    let flat = match &inputs.flat {
        Some(path) => {
            let d = read_camera_frame(path).map_err(PipelineError::DarkFrame)?;
            bracket
                .check_same_shape(&d.frame, path)
                .map_err(PipelineError::DarkFrameShape)?;
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
    let imaging = |context: &str| {
        let context = context.to_string();
        move |source| PipelineError::Imaging { context, source }
    };
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
    let depth = bracket.frames()[0].frame.bit_depth();
    if depth == 8 && inputs.saturation_given {
        return Err(PipelineError::Input(format!(
            "camera.saturation = {} applies to 16-bit and RAW frames; these frames are 8-bit (they \
             clip at code 255 and their response is recovered): remove the key",
            inputs.saturation
        )));
    }
    let mut stage = if depth == 8 {
        let bufs: Vec<ImageBuf<u8>> = bracket
            .into_frames()
            .into_iter()
            .filter_map(|f| match f.frame {
                CameraFrame::U8(b) => Some(b),
                CameraFrame::U16(_) => None,
            })
            .collect();
        scatterfit_imaging::check_bracket_order(&bufs, &times, u8::MAX)
            .map_err(imaging(&order_context()))?;
        corrections.registration = Some(crate::checks::registration(
            bufs.len(),
            bufs[0].width(),
            bufs[0].height(),
            bufs[0].channels(),
            &|j, i| f64::from(bufs[j].data()[i]) / 255.0,
        ));
        let samples = inputs
            .samples
            .unwrap_or_else(|| default_response_samples(bufs.len()));
        let recover = |t: &[f64]| -> Result<(ResponseCurve, Vec<f64>)> {
            let opts = CalibrateOptions::new(samples, inputs.lambda)
                .map_err(imaging("the response recovery's options"))?;
            let cal = scatterfit_imaging::recover_response(&bufs, t, &opts).map_err(
                imaging("recovering the camera response (or give a known one: --response for merge, camera.response in sample.toml for measure)"),
            )?;
            let rms = cal.solutions.iter().map(|s| s.rms_residual).collect();
            Ok((cal.response, rms))
        };
        let (mut response, kind, mut rms) = match &inputs.response {
            Some(path) => (load_response(path)?, ResponseKind::Given, Vec::new()),
            None => {
                let (r, rms) = recover(&times)?;
                (r, ResponseKind::Recovered, rms)
            }
        };
        // Exposure times from the frames: ratios of linearised codes in the well-exposed range.
        let mut times_used = times.clone();
        if inputs.exposure_correction != ExposureCorrection::Never {
            let recovered = kind == ResponseKind::Recovered;
            let ch = bufs[0].channels();
            let n = bufs[0].data().len();
            for round in 0..if recovered { 4 } else { 1 } {
                let lin: Vec<Vec<f64>> = response
                    .tables()
                    .iter()
                    .map(|g| g.iter().map(|v| v.exp()).collect())
                    .collect();
                let est = estimate_exposures(
                    &times_used,
                    n,
                    &|j, i| {
                        let z = bufs[j].data()[i];
                        (DETECTION_CODE..=230)
                            .contains(&z)
                            .then(|| lin[if lin.len() == 1 { 0 } else { i % ch }][usize::from(z)])
                    },
                    recovered,
                );
                let apply = inputs.exposure_correction == ExposureCorrection::Always
                    || (round == 0 && est.max_correction > EXPOSURE_AUTO_THRESHOLD)
                    || (round > 0 && corrections.exposure_applied);
                if round == 0 {
                    check_exposure(&est, &times)?;
                    corrections.exposure = Some(est.clone());
                }
                if !apply {
                    break;
                }
                corrections.exposure_applied = true;
                for (t, f) in times_used.iter_mut().zip(&est.factor) {
                    *t *= f;
                }
                if recovered {
                    (response, rms) = recover(&times_used)?;
                }
                if est.max_correction < 2e-4 {
                    break;
                }
            }
            if corrections.exposure_applied
                && let Some(e) = corrections.exposure.as_mut()
            {
                // Report the total correction against the nominal times.
                e.factor = times_used.iter().zip(&times).map(|(u, t)| u / t).collect();
                e.max_correction = e.factor.iter().map(|f| (f - 1.0).abs()).fold(0.0, f64::max);
            }
        }
        let dark = dark.and_then(|d| match d {
            CameraFrame::U8(b) => Some(b),
            CameraFrame::U16(_) => None,
        });
        let opts = MergeOptions {
            clipped_fill: inputs.clipped_fill,
            weighting: inputs.weighting,
        };
        let mut hdr =
            scatterfit_imaging::merge(&bufs, &times_used, &response, dark.as_ref(), &opts)
                .map_err(imaging("merging the bracket"))?;
        if let Some((path, CameraFrame::U8(f))) = &flat {
            let tables = response.tables();
            let ch = f.channels();
            let lin: Vec<f32> = f
                .data()
                .iter()
                .enumerate()
                .map(|(i, &z)| {
                    let g = &tables[if tables.len() == 1 { 0 } else { i % ch }];
                    if z == 0 {
                        0.0
                    } else {
                        g[usize::from(z)].exp() as f32
                    }
                })
                .collect();
            corrections.flat = Some(divide_flat(&mut hdr, path, f.width(), f.height(), ch, lin)?);
        }
        let t_max = times_used.iter().copied().fold(0.0f64, f64::max);
        let detection_limit = (0..hdr.radiance.channels())
            .map(|c| {
                let g = &response.tables()[if response.channels() == 1 { 0 } else { c }];
                g[usize::from(DETECTION_CODE)].exp() / t_max
            })
            .collect();
        HdrStage {
            hdr,
            response: Some(response),
            response_kind: kind,
            rms,
            frames,
            image,
            detection_limit,
            dropped_alpha,
            read_s,
            merge_s: 0.0,
            corrections: Corrections::default(),
        }
    } else {
        if let Some(path) = &inputs.response {
            return Err(PipelineError::Input(format!(
                "{}: a response curve applies to 8-bit frames; these frames are 16-bit and are \
                 merged as linear data — drop --response (or camera.response in the manifest)",
                path.display()
            )));
        }
        let bufs: Vec<ImageBuf<u16>> = bracket
            .into_frames()
            .into_iter()
            .filter_map(|f| match f.frame {
                CameraFrame::U16(b) => Some(b),
                CameraFrame::U8(_) => None,
            })
            .collect();
        let saturation = match raw {
            Some(r) if !inputs.saturation_given => {
                (r.levels.white.min(f64::from(u16::MAX)) as u16).max(2)
            }
            _ => inputs.saturation,
        };
        // The codes the frames use (8- or 12-bit data in 16-bit files; crate::checks); a stated
        // saturation is used as stated.
        let code_range = raw
            .is_none()
            .then(|| crate::checks::code_range(&bufs, saturation))
            .transpose()?
            .map(|c| {
                if inputs.saturation_given {
                    crate::checks::CodeRange {
                        saturation,
                        plateau_found: false,
                        ..c
                    }
                } else {
                    c
                }
            });
        let saturation = code_range.as_ref().map_or(saturation, |c| c.saturation);
        scatterfit_imaging::check_bracket_order(&bufs, &times, saturation)
            .map_err(imaging(&order_context()))?;
        corrections.registration = Some(crate::checks::registration(
            bufs.len(),
            bufs[0].width(),
            bufs[0].height(),
            bufs[0].channels(),
            &|j, i| f64::from(bufs[j].data()[i]) / f64::from(saturation),
        ));
        let dark = dark.and_then(|d| match d {
            CameraFrame::U16(b) => Some(b),
            CameraFrame::U8(_) => None,
        });
        let ch = bufs[0].channels();
        // The black level: a dark frame is subtracted pixel by pixel (as before); otherwise a level
        // per channel from the settings, the RAW metadata or the far corners.
        let black: Option<(Vec<f64>, &'static str)> = if dark.is_some() {
            None
        } else {
            match &inputs.black_level {
                BlackLevel::None => None,
                BlackLevel::Given(v) => Some((
                    (0..ch)
                        .map(|c| v[if v.len() == 1 { 0 } else { c.min(v.len() - 1) }])
                        .collect(),
                    "given",
                )),
                BlackLevel::Auto => match raw {
                    Some(r) => Some((r.levels.black[..ch.min(3)].to_vec(), "metadata")),
                    None => {
                        let refs: Vec<&ImageBuf<u16>> = bufs.iter().collect();
                        let est = estimate_black_level(&refs, &times, saturation);
                        est.level
                            .iter()
                            .any(|l| *l >= 1.0)
                            .then_some((est.level, "far corners"))
                    }
                },
            }
        };
        let black_of = |c: usize| black.as_ref().map_or(0.0, |(b, _)| b[c]);
        // Exposure times from the frames: ratios of the linear values in the well-exposed range.
        let mut times_used = times.clone();
        if inputs.exposure_correction != ExposureCorrection::Never {
            let n = bufs[0].data().len();
            let sat = f64::from(saturation);
            let est = estimate_exposures(
                &times,
                n,
                &|j, i| {
                    let b = black_of(i % ch);
                    let v = f64::from(bufs[j].data()[i]);
                    let d = dark.as_ref().map_or(b, |d| f64::from(d.data()[i]));
                    (v >= d + 0.02 * (sat - d) && v <= d + 0.8 * (sat - d)).then_some(v - d)
                },
                false,
            );
            check_exposure(&est, &times)?;
            let apply = inputs.exposure_correction == ExposureCorrection::Always
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
                inputs.clipped_fill,
            )
            .map_err(imaging("merging the linear bracket less its black level"))?,
            None => {
                let opts = LinearMergeOptions::new(saturation, inputs.clipped_fill)
                    .map_err(imaging("the 16-bit merge's options"))?;
                scatterfit_imaging::merge_linear_u16(&bufs, &times_used, dark.as_ref(), &opts)
                    .map_err(imaging("merging the 16-bit bracket"))?
            }
        };
        if let Some((path, CameraFrame::U16(f))) = &flat {
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
        HdrStage {
            hdr,
            response: None,
            response_kind: ResponseKind::Linear,
            rms: Vec::new(),
            frames,
            image,
            detection_limit,
            dropped_alpha,
            read_s,
            merge_s: 0.0,
            corrections: Corrections::default(),
        }
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

/// Divides the radiance by a flat frame's smoothed, median-normalised linear values
/// ([`flat_divisor`]); returns the file and the divisor's range.
fn divide_flat(
    hdr: &mut HdrImage,
    path: &Path,
    w: usize,
    h: usize,
    ch: usize,
    linear: Vec<f32>,
) -> Result<(PathBuf, f64, f64)> {
    let bad = || {
        PipelineError::Input(format!(
            "{}: the flat frame has no light (a frame of a uniform white target, exposed to \
             mid-range, is needed)",
            path.display()
        ))
    };
    let buf = ImageBuf::new(w, h, ch, linear).map_err(|_| bad())?;
    let div = flat_divisor(&buf).ok_or_else(bad)?;
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    let floor = 1e-3f32;
    let data: Vec<f32> = hdr
        .radiance
        .data()
        .iter()
        .zip(div.data())
        .map(|(&v, &d)| {
            lo = lo.min(f64::from(d));
            hi = hi.max(f64::from(d));
            v / d.max(floor)
        })
        .collect();
    if lo.is_nan() || lo <= 0.0 {
        return Err(bad());
    }
    hdr.radiance = ImageBuf::new(w, h, ch, data).map_err(|_| bad())?;
    Ok((path.to_path_buf(), lo, hi))
}

/// The fit's spot kernel from `camera.spot_image` ([`crate::camera::spot_from_image`]): the image
/// linearised as the bracket was (8-bit through the bracket's response; linear data less the
/// black level found for the bracket).
///
/// # Errors
/// [`PipelineError::Input`] naming the file and what is wrong with it.
pub fn spot_kernel_from_image(
    path: &Path,
    stage: &HdrStage,
    mm_per_pixel: f64,
) -> Result<scatterfit_fit::RadialSpot> {
    let bad = |what: String| {
        PipelineError::Input(format!(
            "{} (camera.spot_image): {what}; it is a photograph of the light spot on a thin \
             opaque white target (paper, a white tile) with the bracket's camera and scale",
            path.display()
        ))
    };
    let frame = read_camera_frame(path)
        .map_err(|e| bad(e.to_string()))?
        .frame;
    let linear: Vec<f32> = match (&frame, &stage.response) {
        (CameraFrame::U8(f), Some(r)) => {
            let tables = r.tables();
            let ch = f.channels();
            f.data()
                .iter()
                .enumerate()
                .map(|(i, &z)| {
                    let g = &tables[if tables.len() == 1 { 0 } else { i % ch }];
                    if z == 0 {
                        0.0
                    } else {
                        g[usize::from(z)].exp() as f32
                    }
                })
                .collect()
        }
        (CameraFrame::U8(f), None) => f.data().iter().map(|&z| f32::from(z)).collect(),
        (CameraFrame::U16(f), _) => {
            let ch = f.channels();
            let black = stage.corrections.black_level.as_ref();
            f.data()
                .iter()
                .enumerate()
                .map(|(i, &v)| {
                    (f64::from(v) - black.map_or(0.0, |(b, _)| b[(i % ch).min(b.len() - 1)])) as f32
                })
                .collect()
        }
    };
    let buf = ImageBuf::new(frame.width(), frame.height(), frame.channels(), linear)
        .map_err(|e| bad(e.to_string()))?;
    crate::camera::spot_from_image(&buf, mm_per_pixel).map_err(bad)
}

/// A radiance map read from a file (the manifest's `camera.hdr`): no bracket, no detection limit.
///
/// # Errors
/// [`PipelineError::Image`].
pub fn read_radiance_map(path: &Path) -> Result<HdrStage> {
    let t0 = Instant::now();
    let radiance = scatterfit_io::image_files::read_radiance(path)?;
    let (w, h, ch) = (radiance.width(), radiance.height(), radiance.channels());
    let clipped = ImageBuf::filled(w, h, ch, 0u8).map_err(|e| {
        PipelineError::Input(format!("{}: inconsistent image size ({e})", path.display()))
    })?;
    Ok(HdrStage {
        hdr: HdrImage {
            radiance,
            clipped,
            clipped_count: 0,
        },
        response: None,
        response_kind: ResponseKind::Merged,
        rms: Vec::new(),
        frames: Vec::new(),
        image: format!("{w}×{h} {}", if ch == 1 { "grey" } else { "RGB" }),
        detection_limit: vec![f64::NAN; ch],
        dropped_alpha: Vec::new(),
        read_s: t0.elapsed().as_secs_f64(),
        merge_s: 0.0,
        corrections: Corrections::default(),
    })
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
