//! Exposure brackets: the camera frames of one scene at several shutter times, with those times.
//!
//! Times come from an `exposures.csv` (header `file,time_s`; a file path relative to the CSV's
//! folder; a time in seconds, as a decimal `0.0016667` or a fraction `1/600`) or, when no CSV is
//! given, from each file's EXIF `ExposureTime`. Frames are decoded in parallel (rayon).
//!
//! [`read_bracket`] refuses, naming the file and line: fewer than 2 images, an unreadable file, a
//! missing or non-positive time, two images with the same time, the same file twice, and frames whose
//! size, channel count or bit depth differ from the first frame's. The frames come back sorted by
//! exposure time, shortest first.

use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::csv_dialect::{CsvDialect, LineCounter};
use crate::image_files::{CameraFrame, ImageFileError, decode_camera_frame, describe_shape};
use crate::text::{TextError, decode_text, read_text_file};

mod exposures;

pub use exposures::{
    ExposureEntry, MAX_FRAMES, exif_exposure_time, parse_exposures_bytes, parse_exposures_csv,
    read_exposures_csv,
};

/// The shutter times accepted \[s\]: 1 µs (beyond the fastest electronic shutters, 1/32000 s) to a
/// day (beyond any bulb exposure of a lit sample).
pub const SHUTTER_RANGE_S: (f64, f64) = (1e-6, 86_400.0);

/// True for a time within [`SHUTTER_RANGE_S`].
pub fn is_shutter_time(t: f64) -> bool {
    (SHUTTER_RANGE_S.0..=SHUTTER_RANGE_S.1).contains(&t)
}

/// What can go wrong reading a bracket. Every variant names the file (and line) at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BracketError {
    /// A frame (or dark frame) could not be read or decoded.
    #[error(transparent)]
    Image(#[from] ImageFileError),
    /// The exposures CSV could not be read.
    #[error("cannot read exposure times from {}: {source}", path.display())]
    ExposuresRead {
        /// The CSV file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The exposures CSV is not text we read (UTF-16 without BOM, a workbook, binary, too large).
    #[error(transparent)]
    ExposuresText(TextError),
    /// The exposures CSV lacks the `file` or `time_s` column.
    #[error(
        "{}: the header must name the columns `file` and `time_s` (found: {found}); \
         write e.g. `file,time_s` then one line per image such as `img_01.png,1/600`",
        path.display()
    )]
    ExposuresHeader {
        /// The CSV file.
        path: PathBuf,
        /// The header as found.
        found: String,
    },
    /// A line of the exposures CSV is malformed.
    #[error("{}, line {line}: {detail}", path.display())]
    ExposuresLine {
        /// The CSV file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// What was wrong and what to do.
        detail: String,
    },
    /// An exposure time is zero, negative or not finite.
    #[error(
        "{where_}: exposure time {} s is not positive; every frame needs its shutter time in \
         seconds (> 0)",
        crate::escape::number(*time_s)
    )]
    NonPositiveTime {
        /// Where the time came from (`exposures.csv, line 3` or `img.jpg (EXIF ExposureTime)`).
        where_: String,
        /// The value found.
        time_s: f64,
    },
    /// An exposure time no shutter takes (outside [`SHUTTER_RANGE_S`]): a unit or typing mistake.
    #[error(
        "{where_}: exposure time {} s is not a shutter time (cameras take {} s to {} s); write \
         each frame's time in seconds, e.g. 1/600 or 0.0016667 — times in milliseconds or \
         microseconds, or a mangled exponent, would be off by that factor",
        crate::escape::number(*time_s),
        crate::escape::number(SHUTTER_RANGE_S.0),
        crate::escape::number(SHUTTER_RANGE_S.1)
    )]
    ImplausibleTime {
        /// Where the time came from.
        where_: String,
        /// The value found.
        time_s: f64,
    },
    /// No exposure time for an image.
    #[error("{}: no exposure time: {detail}", image.display())]
    MissingTime {
        /// The image.
        image: PathBuf,
        /// Why, and what to do.
        detail: String,
    },
    /// Two images have the same exposure time (a bracket needs distinct times).
    #[error(
        "{} and {} have the same exposure time {} s; a bracket needs a different shutter time \
         for every frame (remove the duplicate or correct its time)",
        first.display(),
        second.display(),
        crate::escape::number(*time_s)
    )]
    DuplicateTime {
        /// The first image.
        first: PathBuf,
        /// The second image.
        second: PathBuf,
        /// Their common time.
        time_s: f64,
    },
    /// The same file is listed twice.
    #[error("{} is listed twice; list every frame once", path.display())]
    DuplicateImage {
        /// The file.
        path: PathBuf,
    },
    /// Fewer than two images.
    #[error(
        "an exposure bracket needs at least 2 images, got {count}; give the frames on the command \
         line or list them in exposures.csv"
    )]
    TooFewImages {
        /// How many were given.
        count: usize,
    },
    /// The decoded bracket would not fit the memory budget ([`crate::budget`]).
    #[error(
        "the {frames} frames of this bracket ({shape}) need about {} once decoded, more than the \
         memory budget of {}; {}",
        crate::budget::describe_bytes(*needed),
        crate::budget::describe_bytes(*budget),
        crate::budget::how_to_raise()
    )]
    TooLarge {
        /// Number of frames.
        frames: usize,
        /// The first frame's header, e.g. `6000×4000 Rgb8`.
        shape: String,
        /// Bytes needed.
        needed: u64,
        /// The budget.
        budget: u64,
    },
    /// A frame's size, channel count or bit depth differs from the first frame's.
    #[error(
        "{} is {found} but {} is {expected}; all frames of a bracket (and its dark and flat frames) \
         must have the same size, channels and bit depth",
        path.display(),
        first.display()
    )]
    ShapeMismatch {
        /// The frame that differs.
        path: PathBuf,
        /// Its shape, e.g. `640×480 RGB 8-bit`.
        found: String,
        /// The reference frame.
        first: PathBuf,
        /// The reference shape.
        expected: String,
    },
}

/// One frame of a bracket.
#[derive(Debug, Clone, PartialEq)]
pub struct BracketFrame {
    /// The file it came from.
    pub path: PathBuf,
    /// Shutter time Δt \[s\].
    pub time_s: f64,
    /// The pixels, at the file's bit depth.
    pub frame: CameraFrame,
    /// True if the file's alpha channel was dropped.
    pub dropped_alpha: bool,
    /// A camera RAW file's metadata (levels, exposure time); `None` for other files.
    pub raw: Option<crate::image_files::RawInfo>,
    /// SHA-256 of the file's bytes that were decoded into `frame`, lower-case hex
    /// ([`crate::digest::sha256_hex`]).
    pub sha256: String,
    /// The JPEG quality the file was saved at, from its header
    /// ([`crate::image_files::jpeg_quality`]); `None` for other formats.
    pub jpeg_quality: Option<f64>,
}

/// A validated exposure bracket: at least two frames of one shape and bit depth, with distinct
/// positive times, sorted by time (shortest first). Made by [`read_bracket`] or [`Bracket::new`],
/// which check all that; the frames are read through [`Bracket::frames`].
#[derive(Debug, Clone, PartialEq)]
pub struct Bracket {
    frames: Vec<BracketFrame>,
}

impl Bracket {
    /// A bracket from decoded frames, sorted by time.
    ///
    /// # Errors
    /// [`BracketError::TooFewImages`] for fewer than two frames, [`BracketError::NonPositiveTime`]
    /// for a time that is not finite and > 0, [`BracketError::ShapeMismatch`] for frames of
    /// different size, channels or bit depth, [`BracketError::DuplicateTime`] for two equal times.
    pub fn new(mut frames: Vec<BracketFrame>) -> Result<Self, BracketError> {
        if frames.len() < 2 {
            return Err(BracketError::TooFewImages {
                count: frames.len(),
            });
        }
        if let Some(f) = frames
            .iter()
            .find(|f| !(f.time_s.is_finite() && f.time_s > 0.0))
        {
            return Err(BracketError::NonPositiveTime {
                where_: f.path.display().to_string(),
                time_s: f.time_s,
            });
        }
        if let Some(f) = frames.iter().find(|f| !is_shutter_time(f.time_s)) {
            return Err(BracketError::ImplausibleTime {
                where_: f.path.display().to_string(),
                time_s: f.time_s,
            });
        }
        for f in &frames[1..] {
            check_shape(&frames[0].frame, &frames[0].path, &f.frame, &f.path)?;
        }
        let times: Vec<(PathBuf, f64)> =
            frames.iter().map(|f| (f.path.clone(), f.time_s)).collect();
        check_distinct_times(&times)?;
        frames.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        Ok(Self { frames })
    }

    /// The frames, shortest exposure first.
    pub fn frames(&self) -> &[BracketFrame] {
        &self.frames
    }

    /// The frames, shortest exposure first, taken out of the bracket.
    pub fn into_frames(self) -> Vec<BracketFrame> {
        self.frames
    }

    /// Shutter times Δt \[s\], in frame order.
    pub fn times_s(&self) -> Vec<f64> {
        self.frames.iter().map(|f| f.time_s).collect()
    }

    /// The common shape of the frames, e.g. `6000×4000 RGB 8-bit`.
    pub fn describe(&self) -> String {
        self.frames[0].frame.describe()
    }

    /// Checks that `frame` (e.g. a dark frame read from `path`) has the bracket's size, channel count
    /// and bit depth.
    ///
    /// # Errors
    /// [`BracketError::ShapeMismatch`] naming both files.
    pub fn check_same_shape(&self, frame: &CameraFrame, path: &Path) -> Result<(), BracketError> {
        check_shape(&self.frames[0].frame, &self.frames[0].path, frame, path)
    }
}

fn check_shape(
    first: &CameraFrame,
    first_path: &Path,
    frame: &CameraFrame,
    path: &Path,
) -> Result<(), BracketError> {
    let same = first.width() == frame.width()
        && first.height() == frame.height()
        && first.channels() == frame.channels()
        && first.bit_depth() == frame.bit_depth();
    if same {
        Ok(())
    } else {
        Err(BracketError::ShapeMismatch {
            path: path.to_path_buf(),
            found: frame.describe(),
            first: first_path.to_path_buf(),
            expected: describe_shape(
                first.width(),
                first.height(),
                first.channels(),
                first.bit_depth(),
            ),
        })
    }
}

/// Where a frame's exposure time comes from.
#[derive(Debug, Clone, PartialEq)]
enum TimeOf {
    Known { time_s: f64, where_: String },
    Exif,
}

/// Reads an exposure bracket.
///
/// - `images` non-empty, `exposures` given: the times of those images are looked up in the CSV
///   (every image must be listed; extra CSV lines are ignored).
/// - `images` empty, `exposures` given: every file listed in the CSV is read.
/// - `exposures` absent: times come from each file's EXIF `ExposureTime`.
///
/// Frames are decoded in parallel on rayon's pool; `on_frame_read` is called (from any thread)
/// after each frame is decoded, e.g. to advance a progress bar.
///
/// # Errors
/// Any [`BracketError`]; the first failing file (in the order given) is reported.
pub fn read_bracket(
    images: &[PathBuf],
    exposures: Option<&Path>,
    on_frame_read: &(dyn Fn(&Path) + Sync),
) -> Result<Bracket, BracketError> {
    read_bracket_within(
        images,
        exposures,
        crate::budget::memory_budget_bytes(),
        on_frame_read,
    )
}

/// [`read_bracket`] within a memory budget \[bytes\] (a command's `--max-memory-mib`) instead of the
/// environment's: the frames' decoded size, read from their headers, is checked against it before
/// any frame is decoded.
///
/// # Errors
/// As [`read_bracket`].
pub fn read_bracket_within(
    images: &[PathBuf],
    exposures: Option<&Path>,
    budget: u64,
    on_frame_read: &(dyn Fn(&Path) + Sync),
) -> Result<Bracket, BracketError> {
    let plan: Vec<(PathBuf, TimeOf)> = match exposures {
        Some(csv) => {
            let entries = read_exposures_csv(csv)?;
            if images.is_empty() {
                entries
                    .into_iter()
                    .map(|e| {
                        let where_ = format!("{}, line {}", csv.display(), e.line);
                        (
                            e.path,
                            TimeOf::Known {
                                time_s: e.time_s,
                                where_,
                            },
                        )
                    })
                    .collect()
            } else {
                let mut by_key: HashMap<PathBuf, &ExposureEntry> = HashMap::new();
                for e in &entries {
                    by_key.entry(path_key(&e.path)).or_insert(e);
                }
                images
                    .iter()
                    .map(|image| {
                        let entry = by_key.get(&path_key(image)).ok_or_else(|| {
                            BracketError::MissingTime {
                                image: image.clone(),
                                detail: format!(
                                    "it is not listed in {}; add a line `{},<seconds>`",
                                    csv.display(),
                                    image.file_name().map_or_else(
                                        || image.display().to_string(),
                                        |n| n.to_string_lossy().into_owned()
                                    )
                                ),
                            }
                        })?;
                        let where_ = format!("{}, line {}", csv.display(), entry.line);
                        Ok((
                            image.clone(),
                            TimeOf::Known {
                                time_s: entry.time_s,
                                where_,
                            },
                        ))
                    })
                    .collect::<Result<_, BracketError>>()?
            }
        }
        None => images.iter().map(|p| (p.clone(), TimeOf::Exif)).collect(),
    };
    if plan.len() < 2 {
        return Err(BracketError::TooFewImages { count: plan.len() });
    }
    let mut seen: HashMap<PathBuf, ()> = HashMap::new();
    for (path, _) in &plan {
        if seen.insert(path_key(path), ()).is_some() {
            return Err(BracketError::DuplicateImage { path: path.clone() });
        }
    }
    // Times known up front are checked before the (slow) decoding.
    let known: Vec<(PathBuf, f64)> = plan
        .iter()
        .filter_map(|(p, t)| match t {
            TimeOf::Known { time_s, .. } => Some((p.clone(), *time_s)),
            TimeOf::Exif => None,
        })
        .collect();
    check_distinct_times(&known)?;
    check_bracket_budget(&plan, budget)?;

    let decoded: Vec<Result<BracketFrame, BracketError>> = plan
        .par_iter()
        .map(|(path, time)| {
            let bytes = crate::image_files::read_image_bytes(path, budget)?;
            let decoded = decode_camera_frame(&bytes, path)?;
            let time_s = match (time, decoded.raw.and_then(|r| r.exposure_time_s)) {
                (TimeOf::Known { time_s, .. }, _) => *time_s,
                (TimeOf::Exif, Some(t)) if t.is_finite() && t > 0.0 => t,
                (TimeOf::Exif, _) => exif_exposure_time(&bytes, path)?,
            };
            let sha256 = crate::digest::sha256_hex(&bytes);
            let jpeg_quality = crate::image_files::jpeg_quality(&bytes);
            drop(bytes);
            on_frame_read(path);
            Ok(BracketFrame {
                path: path.clone(),
                time_s,
                frame: decoded.frame,
                dropped_alpha: decoded.dropped_alpha,
                raw: decoded.raw,
                sha256,
                jpeg_quality,
            })
        })
        .collect();
    let frames: Vec<BracketFrame> = decoded.into_iter().collect::<Result<_, _>>()?;
    Bracket::new(frames)
}

/// The decoded size \[bytes\] of the frames `paths`, from their headers (not their pixels): the sum,
/// the largest frame and the first frame's shape. Headers that cannot be read count 0 (the decoder
/// reports them).
pub fn decoded_size<'a>(paths: impl IntoIterator<Item = &'a Path>) -> (u64, u64, String) {
    use image::ImageDecoder;
    let mut total = 0u64;
    let mut largest = 0u64;
    let mut shape = String::new();
    for path in paths {
        // A regular file only: `ImageReader::open` on a FIFO would block for ever.
        let Ok(reader) = scatterfit_safefs::read::open_regular(path).and_then(|(f, _)| {
            image::ImageReader::new(std::io::BufReader::new(f)).with_guessed_format()
        }) else {
            continue;
        };
        let Ok(decoder) = reader.into_decoder() else {
            continue;
        };
        let (w, h) = decoder.dimensions();
        let bytes = u64::from(w)
            .saturating_mul(u64::from(h))
            .saturating_mul(u64::from(decoder.color_type().bytes_per_pixel()));
        if shape.is_empty() {
            shape = format!("{w}×{h} {:?}", decoder.color_type());
        }
        total = total.saturating_add(bytes);
        largest = largest.max(bytes);
    }
    (total, largest, shape)
}

/// The frames a bracket would read: the `images` given, else those listed in `exposures`.
///
/// # Errors
/// The exposures CSV's errors.
pub fn planned_frames(
    images: &[PathBuf],
    exposures: Option<&Path>,
) -> Result<Vec<PathBuf>, BracketError> {
    match exposures {
        Some(csv) if images.is_empty() => Ok(read_exposures_csv(csv)?
            .into_iter()
            .map(|e| e.path)
            .collect()),
        _ => Ok(images.to_vec()),
    }
}

/// Reads the frames' headers (not their pixels) and refuses a bracket whose decoded frames would
/// not fit `budget` bytes: all frames at once, plus one transient copy (alpha dropped) per decoding
/// thread. A header that cannot be read is left for the decoder to report.
fn check_bracket_budget(plan: &[(PathBuf, TimeOf)], budget: u64) -> Result<(), BracketError> {
    let (total, largest, shape) = decoded_size(plan.iter().map(|(p, _)| p.as_path()));
    let threads = rayon::current_num_threads() as u64;
    let needed = total.saturating_add(largest.saturating_mul(threads));
    if needed > budget {
        return Err(BracketError::TooLarge {
            frames: plan.len(),
            shape,
            needed,
            budget,
        });
    }
    Ok(())
}

/// Two times closer than one part in 10⁶ count as the same shutter speed.
fn check_distinct_times(times: &[(PathBuf, f64)]) -> Result<(), BracketError> {
    let mut sorted: Vec<&(PathBuf, f64)> = times.iter().collect();
    sorted.sort_by(|a, b| a.1.total_cmp(&b.1));
    for pair in sorted.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if (b.1 - a.1).abs() <= 1e-6 * b.1.abs() {
            // Report in the order the user gave them.
            let (first, second) =
                if times.iter().position(|t| t.0 == a.0) < times.iter().position(|t| t.0 == b.0) {
                    (a, b)
                } else {
                    (b, a)
                };
            return Err(BracketError::DuplicateTime {
                first: first.0.clone(),
                second: second.0.clone(),
                time_s: a.1,
            });
        }
    }
    Ok(())
}

/// A key under which two spellings of one existing file compare equal.
fn path_key(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.components().collect())
}

/// Writes an `exposures.csv` (`file,time_s`; file names as given, relative to the CSV's folder)
/// atomically. Times are written in Rust's shortest round-trip form, so they read back exactly.
///
/// # Errors
/// The I/O error, with the path.
pub fn write_exposures_csv(path: &Path, entries: &[(String, f64)]) -> std::io::Result<()> {
    let mut text = String::from("file,time_s\n");
    for (file, t) in entries {
        text.push_str(&format!("{file},{t}\n"));
    }
    crate::atomic::write_atomic(path, text.as_bytes())
        .map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", path.display())))
}

#[cfg(test)]
mod tests {
    use super::exposures::parse_time;
    use super::*;

    /// Times off by 10^±300 (a mangled exponent, a unit mistake far past milliseconds) are
    /// refused as no shutter time, naming the line and the unit to use, not merged into an
    /// all-black or all-white radiance map with advice about the exposures.
    #[test]
    fn times_no_shutter_takes_are_refused() {
        for t in ["1e300", "1e-300", "2e5"] {
            let text = format!("file,time_s\na.png,{t}\nb.png,0.01\n");
            let e = parse_exposures_csv(&text, Path::new("s/exposures.csv")).unwrap_err();
            assert!(
                matches!(e, BracketError::ImplausibleTime { .. }),
                "{t}: {e}"
            );
            let m = e.to_string();
            assert!(
                m.contains("line 2") && m.contains("not a shutter time") && m.len() < 400,
                "{m}"
            );
        }
        let ok = "file,time_s\na.png,1/32000\nb.png,30\n";
        assert_eq!(
            parse_exposures_csv(ok, Path::new("e.csv")).unwrap().len(),
            2
        );
    }

    #[test]
    fn times_parse_as_decimals_and_fractions() {
        let d = CsvDialect::detect("file,time_s");
        assert_eq!(parse_time("0.5", &d), Some(0.5));
        assert_eq!(parse_time("1/600", &d), Some(1.0 / 600.0));
        assert_eq!(parse_time("2e-3", &d), Some(2e-3));
        assert_eq!(parse_time("1/0", &d), None);
        assert_eq!(parse_time("fast", &d), None);
        assert_eq!(parse_time("0,5", &d), None);
        let semicolon = CsvDialect::detect("file;time_s");
        assert_eq!(parse_time("0,5", &semicolon), Some(0.5));
        assert_eq!(parse_time("1/2,5", &semicolon), Some(0.4));
    }

    #[test]
    fn equal_times_are_refused_naming_both_files() {
        let times = vec![
            (PathBuf::from("a.png"), 0.01),
            (PathBuf::from("b.png"), 0.02),
            (PathBuf::from("c.png"), 0.01),
        ];
        match check_distinct_times(&times) {
            Err(BracketError::DuplicateTime { first, second, .. }) => {
                assert_eq!(
                    (first, second),
                    (PathBuf::from("a.png"), PathBuf::from("c.png"))
                );
            }
            other => panic!("expected DuplicateTime, got {other:?}"),
        }
    }
}
