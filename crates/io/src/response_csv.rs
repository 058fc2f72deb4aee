//! Camera response curves as CSV.
//!
//! Format (one row per pixel value z = 0, 1, …, levels − 1, in order):
//! ```text
//! z,g_r,g_g,g_b
//! 0,-5.83,-5.91,-6.02
//! …
//! ```
//! `g(z)` is the natural logarithm of the exposure E·Δt that produces pixel value z (Debevec & Malik
//! 1997, eq. 2), in the gauge g(128) = 0 for 8-bit data. A grey camera writes `z,g` (`g_y` is read
//! too). Values are written in Rust's shortest round-trip form, so a write–read cycle is exact.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::csv_dialect::{CsvDialect, LineCounter};
use crate::text::{TextError, decode_text, read_text_file};

/// Most rows a response table may have: one per code value of a 16-bit camera.
pub const MAX_LEVELS: usize = 1 << 16;

/// What can go wrong reading or writing a response CSV.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ResponseCsvError {
    /// The file could not be read.
    #[error("cannot read camera response {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file could not be written (an existing file is left untouched).
    #[error("cannot write camera response {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file is not text we read (UTF-16 without BOM, a workbook, binary data, too large).
    #[error(transparent)]
    Text(TextError),
    /// The header is not `z,g_r,g_g,g_b` or `z,g`.
    #[error(
        "{}: the header must be `z,g_r,g_g,g_b` (RGB) or `z,g` (grey), found `{found}`; \
         g(z) is the natural log of exposure for pixel value z",
        path.display()
    )]
    Header {
        /// The file.
        path: PathBuf,
        /// The header found.
        found: String,
    },
    /// A data line is wrong.
    #[error("{}, line {line}: {detail}", path.display())]
    Line {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// What was wrong and what to do.
        detail: String,
    },
    /// The table is not usable as a response (too few rows, wrong channel count on write).
    #[error("{}: {detail}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What was wrong.
        detail: String,
    },
}

/// A camera response: for each channel, g(z) = ln(E·Δt) for every pixel value z.
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseTable {
    /// `g[c][z]` for channel c (R, G, B or the single grey channel) and pixel value z.
    pub g: Vec<Vec<f64>>,
}

impl ResponseTable {
    /// Number of pixel values (256 for 8-bit).
    pub fn levels(&self) -> usize {
        self.g.first().map_or(0, Vec::len)
    }

    /// Number of channels (1 or 3).
    pub fn channels(&self) -> usize {
        self.g.len()
    }
}

fn channel_columns(channels: usize) -> Option<&'static [&'static str]> {
    match channels {
        1 => Some(&["g"]),
        3 => Some(&["g_r", "g_g", "g_b"]),
        _ => None,
    }
}

/// Writes a response atomically as `z,g_r,g_g,g_b` (or `z,g`).
///
/// # Errors
/// [`ResponseCsvError::Invalid`] for a channel count other than 1 or 3, channels of unequal length
/// or non-finite values; [`ResponseCsvError::Write`] if the file cannot be written.
pub fn write_response_csv(path: &Path, response: &ResponseTable) -> Result<(), ResponseCsvError> {
    let invalid = |detail: String| ResponseCsvError::Invalid {
        path: path.to_path_buf(),
        detail,
    };
    let columns = channel_columns(response.channels()).ok_or_else(|| {
        invalid(format!(
            "a response has 1 or 3 channels, not {}",
            response.channels()
        ))
    })?;
    let levels = response.levels();
    if response.g.iter().any(|c| c.len() != levels) || levels < 2 {
        return Err(invalid(
            "every channel needs the same number (≥ 2) of values".into(),
        ));
    }
    if let Some((c, z)) = (0..levels)
        .flat_map(|z| (0..response.channels()).map(move |c| (c, z)))
        .find(|&(c, z)| !response.g[c][z].is_finite())
    {
        return Err(invalid(format!(
            "{}({z}) is {}; a response must be finite",
            columns[c], response.g[c][z]
        )));
    }
    let mut text = String::with_capacity(levels * 64);
    text.push('z');
    for name in columns {
        text.push(',');
        text.push_str(name);
    }
    text.push('\n');
    for z in 0..levels {
        let _ = write!(text, "{z}");
        for channel in &response.g {
            let _ = write!(text, ",{}", channel[z]);
        }
        text.push('\n');
    }
    crate::atomic::write_atomic(path, text.as_bytes()).map_err(|source| ResponseCsvError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads a response CSV written by [`write_response_csv`] (or by hand in that format): rows
/// z = 0, 1, … in order, finite values.
///
/// # Errors
/// [`ResponseCsvError`] naming the file and line.
pub fn read_response_csv(path: &Path) -> Result<ResponseTable, ResponseCsvError> {
    let text = read_text_file(path).map_err(text_error)?;
    parse_response_csv(&text.text, path)
}

/// [`read_response_csv`] on the bytes of a file (any accepted encoding, [`crate::text`]); `path`
/// names it in messages.
///
/// # Errors
/// As [`read_response_csv`].
pub fn parse_response_bytes(bytes: &[u8], path: &Path) -> Result<ResponseTable, ResponseCsvError> {
    let text = decode_text(bytes, path).map_err(text_error)?;
    parse_response_csv(&text.text, path)
}

fn text_error(e: TextError) -> ResponseCsvError {
    match e {
        TextError::Io { path, source } => ResponseCsvError::Read { path, source },
        other => ResponseCsvError::Text(other),
    }
}

/// [`read_response_csv`] on decoded text.
///
/// # Errors
/// As [`read_response_csv`].
pub fn parse_response_csv(text: &str, path: &Path) -> Result<ResponseTable, ResponseCsvError> {
    let dialect = CsvDialect::detect(text);
    let mut reader = dialect
        .reader_builder()
        .flexible(true)
        .from_reader(text.as_bytes());
    let header_err = |found: String| ResponseCsvError::Header {
        path: path.to_path_buf(),
        found,
    };
    let headers = reader
        .headers()
        .map_err(|e| header_err(format!("unreadable ({e})")))?
        .clone();
    let names: Vec<String> = headers.iter().map(str::to_ascii_lowercase).collect();
    let find = |n: &str| names.iter().position(|h| h == n);
    let shown = || {
        crate::csv_dialect::header_for_message(
            names.iter().map(String::as_str),
            &["z", "g", "g_y", "g_r", "g_g", "g_b"],
        )
    };
    let z_col = find("z").ok_or_else(|| header_err(shown()))?;
    let value_cols: Vec<usize> = match (
        find("g_r"),
        find("g_g"),
        find("g_b"),
        find("g").or(find("g_y")),
    ) {
        (Some(r), Some(g), Some(b), _) => vec![r, g, b],
        (None, None, None, Some(y)) => vec![y],
        _ => return Err(header_err(shown())),
    };
    let mut g = vec![Vec::new(); value_cols.len()];
    let mut lines = LineCounter::new(text);
    for record in reader.records() {
        let line_err = |line: u64, detail: String| ResponseCsvError::Line {
            path: path.to_path_buf(),
            line,
            detail,
        };
        let record = record
            .map_err(|e| line_err(lines.line(e.position()), format!("malformed CSV: {e}")))?;
        let line = lines.line(record.position());
        if record.len() > headers.len() {
            return Err(line_err(
                line,
                dialect.extra_fields_hint(headers.len(), record.len()),
            ));
        }
        let expected_z = g[0].len();
        if expected_z >= MAX_LEVELS {
            return Err(line_err(
                line,
                format!(
                    "more than {MAX_LEVELS} rows; a response has one row per code value (256 for \
                     8-bit, at most 65536 for 16-bit data)"
                ),
            ));
        }
        let z = record.get(z_col).unwrap_or("");
        if z.parse::<usize>().ok() != Some(expected_z) {
            return Err(line_err(
                line,
                format!(
                    "z = {z:?} but the rows must list z = 0, 1, 2, … in order (expected {expected_z})"
                ),
            ));
        }
        for (c, &col) in value_cols.iter().enumerate() {
            let field = record.get(col).unwrap_or("");
            let value = dialect
                .parse_f64(field)
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    line_err(
                        line,
                        format!(
                            "`{}` = {} is not a finite number",
                            crate::escape::token(&names[col]),
                            crate::csv_dialect::cell_for_message(field)
                        ),
                    )
                })?;
            g[c].push(value);
        }
    }
    if g[0].len() < 2 {
        return Err(ResponseCsvError::Invalid {
            path: path.to_path_buf(),
            detail: format!(
                "only {} rows; a response lists g(z) for every pixel value (256 rows for 8-bit)",
                g[0].len()
            ),
        });
    }
    Ok(ResponseTable { g })
}
