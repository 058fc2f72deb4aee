//! The bracket's exposure times: `exposures.csv` (file,time_s; any CSV dialect and text encoding)
//! and the EXIF ExposureTime of a frame.

use super::*;

/// The most frames a bracket may have (`exposures.csv` lines, `camera.images`): real brackets
/// have 3–20, and each frame is decoded whole, so thousands would be refused only after hours.
pub const MAX_FRAMES: usize = 64;

/// One exposure-time entry of an `exposures.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct ExposureEntry {
    /// The image, resolved against the CSV's folder.
    pub path: PathBuf,
    /// The image as the CSV names it (what the input path policy checks).
    pub named: PathBuf,
    /// Shutter time Δt \[s\].
    pub time_s: f64,
    /// 1-based line in the CSV.
    pub line: u64,
}

/// Reads an `exposures.csv` (header `file,time_s`, other columns ignored). Relative paths are
/// resolved against the CSV's folder; a time may be a decimal or a fraction (`1/600`).
///
/// # Errors
/// [`BracketError::ExposuresRead`], [`BracketError::ExposuresHeader`], [`BracketError::ExposuresLine`]
/// (empty file name, unparsable time, short line) and [`BracketError::NonPositiveTime`], each naming
/// the CSV and the line.
pub fn read_exposures_csv(path: &Path) -> Result<Vec<ExposureEntry>, BracketError> {
    let text = read_text_file(path).map_err(|e| exposures_text_error(e, path))?;
    parse_exposures_csv(&text.text, path)
}

/// [`read_exposures_csv`] on the bytes of the file (any accepted encoding, [`crate::text`]); `path`
/// names it in messages and relative image paths are resolved against its folder.
///
/// # Errors
/// As [`read_exposures_csv`].
pub fn parse_exposures_bytes(
    bytes: &[u8],
    path: &Path,
) -> Result<Vec<ExposureEntry>, BracketError> {
    let text = decode_text(bytes, path).map_err(|e| exposures_text_error(e, path))?;
    parse_exposures_csv(&text.text, path)
}

pub(super) fn exposures_text_error(e: TextError, path: &Path) -> BracketError {
    match e {
        TextError::Io { source, .. } => BracketError::ExposuresRead {
            path: path.to_path_buf(),
            source,
        },
        other => BracketError::ExposuresText(other),
    }
}

/// [`read_exposures_csv`] on decoded text.
///
/// # Errors
/// As [`read_exposures_csv`].
pub fn parse_exposures_csv(text: &str, path: &Path) -> Result<Vec<ExposureEntry>, BracketError> {
    let base = path.parent().unwrap_or(Path::new(""));
    let dialect = CsvDialect::detect(text);
    let mut reader = dialect
        .reader_builder()
        .flexible(true)
        .from_reader(text.as_bytes());
    let header_err = |found: String| BracketError::ExposuresHeader {
        path: path.to_path_buf(),
        found,
    };
    let headers = reader
        .headers()
        .map_err(|e| header_err(format!("unreadable header: {e}")))?
        .clone();
    let column = |name: &str| headers.iter().position(|h| h.eq_ignore_ascii_case(name));
    let (Some(file_col), Some(time_col)) = (column("file"), column("time_s")) else {
        return Err(header_err(if headers.is_empty() {
            "an empty file".into()
        } else {
            crate::csv_dialect::header_for_message(headers.iter(), &["file", "time_s"])
        }));
    };
    let mut entries = Vec::new();
    let mut lines = LineCounter::new(text);
    for record in reader.records() {
        let line_err = |line: u64, detail: String| BracketError::ExposuresLine {
            path: path.to_path_buf(),
            line,
            detail,
        };
        let record = record.map_err(|e| {
            let line = lines.line(e.position());
            line_err(line, format!("malformed CSV: {e}"))
        })?;
        let line = lines.line(record.position());
        if record.iter().all(str::is_empty) {
            continue;
        }
        if entries.len() >= MAX_FRAMES {
            return Err(line_err(
                line,
                format!(
                    "more than {MAX_FRAMES} frames; a bracket needs a dozen or so (each frame is \
                     decoded whole) — is this the right file?"
                ),
            ));
        }
        if record.len() > headers.len() {
            return Err(line_err(
                line,
                dialect.extra_fields_hint(headers.len(), record.len()),
            ));
        }
        let file = record.get(file_col).unwrap_or("");
        if file.is_empty() {
            return Err(line_err(
                line,
                "the `file` field is empty; name the image file".into(),
            ));
        }
        let Some(time_text) = record.get(time_col).filter(|t| !t.is_empty()) else {
            return Err(line_err(
                line,
                format!(
                    "no `time_s` for {}; give its shutter time in seconds, e.g. 0.01 or 1/100",
                    crate::escape::token(file)
                ),
            ));
        };
        let time_s = parse_time(time_text, &dialect).ok_or_else(|| {
            line_err(
                line,
                format!(
                    "`time_s` = {} for {} is not a number; write seconds as a decimal \
                     (0.0016667) or a fraction (1/600)",
                    crate::csv_dialect::cell_for_message(time_text),
                    crate::escape::token(file)
                ),
            )
        })?;
        if !(time_s > 0.0 && time_s.is_finite()) {
            return Err(BracketError::NonPositiveTime {
                where_: format!(
                    "{}, line {line} ({})",
                    path.display(),
                    crate::escape::token(file)
                ),
                time_s,
            });
        }
        if !is_shutter_time(time_s) {
            return Err(BracketError::ImplausibleTime {
                where_: format!(
                    "{}, line {line} ({})",
                    path.display(),
                    crate::escape::token(file)
                ),
                time_s,
            });
        }
        entries.push(ExposureEntry {
            path: base.join(file),
            named: PathBuf::from(file),
            time_s,
            line,
        });
    }
    Ok(entries)
}

/// Parses `0.01`, `1e-3` or `1/600` seconds (`0,01` where the dialect has decimal commas).
pub(super) fn parse_time(text: &str, dialect: &CsvDialect) -> Option<f64> {
    match text.split_once('/') {
        Some((num, den)) => {
            let (num, den) = (dialect.parse_f64(num)?, dialect.parse_f64(den)?);
            (den != 0.0).then(|| num / den)
        }
        None => dialect.parse_f64(text),
    }
}

/// The EXIF `ExposureTime` \[s\] of an image file's bytes (JPEG, TIFF, PNG `eXIf`, HEIF, WebP).
///
/// # Errors
/// [`BracketError::MissingTime`] if the file has no EXIF data or no usable `ExposureTime`;
/// [`BracketError::NonPositiveTime`] if it is zero.
pub fn exif_exposure_time(bytes: &[u8], path: &Path) -> Result<f64, BracketError> {
    let missing = |why: String| BracketError::MissingTime {
        image: path.to_path_buf(),
        detail: format!(
            "{why}; give the shutter times in an exposures.csv (header `file,time_s`) with \
             --exposures"
        ),
    };
    let exif = exif::Reader::new()
        .read_from_container(&mut Cursor::new(bytes))
        .map_err(|e| missing(format!("no readable EXIF data ({e})")))?;
    let field = exif
        .get_field(exif::Tag::ExposureTime, exif::In::PRIMARY)
        .ok_or_else(|| missing("the EXIF data has no ExposureTime".into()))?;
    let time_s = match &field.value {
        exif::Value::Rational(v) if !v.is_empty() && v[0].denom != 0 => v[0].to_f64(),
        exif::Value::Rational(v) if !v.is_empty() => {
            return Err(missing(format!(
                "EXIF ExposureTime {}/0 has a zero denominator",
                v[0].num
            )));
        }
        other => {
            return Err(missing(format!(
                "EXIF ExposureTime has an unexpected type ({other:?})"
            )));
        }
    };
    if !(time_s > 0.0 && time_s.is_finite()) {
        return Err(BracketError::NonPositiveTime {
            where_: format!("{} (EXIF ExposureTime)", path.display()),
            time_s,
        });
    }
    if !is_shutter_time(time_s) {
        return Err(BracketError::ImplausibleTime {
            where_: format!("{} (EXIF ExposureTime)", path.display()),
            time_s,
        });
    }
    Ok(time_s)
}
