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
use scatterfit_io::image_files::{CameraFrame, read_camera_frame};
use scatterfit_io::response_csv::read_response_csv;
use serde::Serialize;

use crate::error::{PipelineError, Result};

/// How the bracket became radiance (the name `result.json` records).
pub use scatterfit_io::result_json::ResponseKind;

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
    /// What to store for pixel-channels clipped in every exposure.
    pub clipped_fill: ClippedFill,
    /// 8-bit sample weighting.
    pub weighting: Weighting,
    /// Memory budget in bytes that the decoded frames are checked against before any is decoded;
    /// `None` for the environment's ([`scatterfit_io::budget::memory_budget_bytes`]).
    pub memory_budget: Option<u64>,
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
            clipped_fill: ClippedFill::Nan,
            weighting: Weighting::NoiseOptimal,
            memory_budget: None,
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
    /// Shutter time [s].
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
    /// Wall time reading [s].
    pub read_s: f64,
    /// Wall time recovering and merging [s].
    pub merge_s: f64,
}

/// The bracket (and dark frame) read and checked, before any pixel work: the first half of
/// [`read_and_merge`], for a caller that reports on the frames or checks the merge's memory before
/// merging ([`FramesRead::decoded_bytes`], [`FramesRead::samples_per_frame`]).
#[derive(Debug, Clone)]
pub struct FramesRead {
    bracket: Bracket,
    dark: Option<CameraFrame>,
    /// The frames, shortest first.
    pub frames: Vec<FrameInfo>,
    /// e.g. `1024×1024 RGB 8-bit`.
    pub image: String,
    /// Frames whose alpha channel was dropped.
    pub dropped_alpha: Vec<PathBuf>,
    /// Wall time reading [s].
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
        frames,
        image,
        dropped_alpha,
        read_s: t0.elapsed().as_secs_f64(),
    })
}

/// Merges a bracket read by [`read_frames`]: 8-bit frames through the given response
/// (`inputs.response`) or one recovered from the frames (`inputs.samples`, `inputs.lambda`),
/// 16-bit frames as linear data (`inputs.saturation`); the dark frame subtracted; the detection
/// limit per channel.
///
/// # Errors
/// [`PipelineError::ResponseCsv`] / [`PipelineError::Input`] for a bad response file or a response
/// given for 16-bit frames; [`PipelineError::Imaging`] when the response cannot be recovered or the
/// merge fails.
pub fn merge_frames(read: FramesRead, inputs: &HdrInputs) -> Result<HdrStage> {
    let FramesRead {
        bracket,
        dark,
        frames,
        image,
        dropped_alpha,
        read_s,
    } = read;
    let times = bracket.times_s();
    let t_max = times.iter().copied().fold(0.0f64, f64::max);
    let t1 = Instant::now();
    let imaging = |context: &str| {
        let context = context.to_string();
        move |source| PipelineError::Imaging { context, source }
    };
    let depth = bracket.frames()[0].frame.bit_depth();
    let mut stage = if depth == 8 {
        let bufs: Vec<ImageBuf<u8>> = bracket
            .into_frames()
            .into_iter()
            .filter_map(|f| match f.frame {
                CameraFrame::U8(b) => Some(b),
                CameraFrame::U16(_) => None,
            })
            .collect();
        let (response, kind, rms) = match &inputs.response {
            Some(path) => (load_response(path)?, ResponseKind::Given, Vec::new()),
            None => {
                let samples = inputs
                    .samples
                    .unwrap_or_else(|| default_response_samples(bufs.len()));
                let opts = CalibrateOptions::new(samples, inputs.lambda)
                    .map_err(imaging("the response recovery's options"))?;
                let cal = scatterfit_imaging::recover_response(&bufs, &times, &opts).map_err(
                    imaging("recovering the camera response (or give a known one: --response for merge, camera.response in sample.toml for measure)"),
                )?;
                let rms = cal.solutions.iter().map(|s| s.rms_residual).collect();
                (cal.response, ResponseKind::Recovered, rms)
            }
        };
        let dark = dark.and_then(|d| match d {
            CameraFrame::U8(b) => Some(b),
            CameraFrame::U16(_) => None,
        });
        let opts = MergeOptions {
            clipped_fill: inputs.clipped_fill,
            weighting: inputs.weighting,
        };
        let hdr = scatterfit_imaging::merge(&bufs, &times, &response, dark.as_ref(), &opts)
            .map_err(imaging("merging the bracket"))?;
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
        let dark = dark.and_then(|d| match d {
            CameraFrame::U16(b) => Some(b),
            CameraFrame::U8(_) => None,
        });
        let opts = LinearMergeOptions::new(inputs.saturation, inputs.clipped_fill)
            .map_err(imaging("the 16-bit merge's options"))?;
        let hdr = scatterfit_imaging::merge_linear_u16(&bufs, &times, dark.as_ref(), &opts)
            .map_err(imaging("merging the 16-bit bracket"))?;
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
        }
    };
    stage.merge_s = t1.elapsed().as_secs_f64();
    Ok(stage)
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
