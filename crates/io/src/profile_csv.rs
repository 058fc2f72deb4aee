//! Radial profiles Rd(r) as CSV.
//!
//! Format (one row per ring, innermost first; radius at the ring's centre):
//! ```text
//! r_mm,r_px,value_r,stderr_r,count_r,value_g,stderr_g,count_g,value_b,stderr_b,count_b
//! 0.05,0.5,1523.2,12.1,8,…
//! ```
//! `value` is the mean radiance of the ring's valid pixels (relative units), `stderr` its standard
//! error, `count` the number of pixels averaged. A grey map has the single channel `y`. A ring with no
//! valid pixel has count 0 and empty value and stderr fields. An optional `limit_<c>` column holds the
//! bracket's detection limit (same units as `value`): a ring below it was not measured. Numbers are
//! written in Rust's shortest round-trip form.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::csv_dialect::{CsvDialect, LineCounter};
use crate::text::{TextError, decode_text, read_text_file};

/// What can go wrong reading or writing a profile CSV.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ProfileCsvError {
    /// The file could not be read.
    #[error("cannot read profile {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file could not be written (an existing file is left untouched).
    #[error("cannot write profile {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file is not text we read (UTF-16 without BOM, a workbook, binary data, too large).
    #[error(transparent)]
    Text(TextError),
    /// The table is malformed (header, a line, or inconsistent column lengths on write).
    #[error("{}: {detail}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What was wrong, with the line where there is one, and what to do.
        detail: String,
    },
}

/// One channel's columns of a radial profile.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileColumn {
    /// Channel name: `r`, `g`, `b`, or `y` for grey.
    pub name: String,
    /// Mean value per ring (NaN where the count is 0).
    pub value: Vec<f64>,
    /// Standard error of the mean per ring (NaN where undefined).
    pub stderr: Vec<f64>,
    /// Pixels averaged per ring.
    pub count: Vec<u64>,
    /// Detection limit per ring (empty when unknown; then no `limit_<c>` column).
    pub limit: Vec<f64>,
}

/// A radial profile: ring radii and per-channel columns.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileTable {
    /// Ring radius \[mm\].
    pub r_mm: Vec<f64>,
    /// Ring radius \[px\].
    pub r_px: Vec<f64>,
    /// One entry per channel.
    pub channels: Vec<ProfileColumn>,
}

fn number(text: &mut String, v: f64) {
    if v.is_finite() {
        let _ = write!(text, "{v}");
    }
}

/// Writes a profile atomically.
///
/// # Errors
/// [`ProfileCsvError::Invalid`] if the columns have different lengths or there is no channel;
/// [`ProfileCsvError::Write`] if the file cannot be written.
pub fn write_profile_csv(path: &Path, table: &ProfileTable) -> Result<(), ProfileCsvError> {
    let rings = table.r_mm.len();
    let consistent = !table.channels.is_empty()
        && table.r_px.len() == rings
        && table.channels.iter().all(|c| {
            c.value.len() == rings
                && c.stderr.len() == rings
                && c.count.len() == rings
                && (c.limit.is_empty() || c.limit.len() == rings)
        });
    if !consistent {
        return Err(ProfileCsvError::Invalid {
            path: path.to_path_buf(),
            detail: "profile columns have different lengths (or there is no channel)".into(),
        });
    }
    let mut text = String::with_capacity(rings * 32 * (2 + table.channels.len()));
    text.push_str("r_mm,r_px");
    for c in &table.channels {
        let _ = write!(text, ",value_{0},stderr_{0},count_{0}", c.name);
        if !c.limit.is_empty() {
            let _ = write!(text, ",limit_{}", c.name);
        }
    }
    text.push('\n');
    for i in 0..rings {
        number(&mut text, table.r_mm[i]);
        text.push(',');
        number(&mut text, table.r_px[i]);
        for c in &table.channels {
            text.push(',');
            number(&mut text, c.value[i]);
            text.push(',');
            number(&mut text, c.stderr[i]);
            let _ = write!(text, ",{}", c.count[i]);
            if !c.limit.is_empty() {
                text.push(',');
                number(&mut text, c.limit[i]);
            }
        }
        text.push('\n');
    }
    crate::atomic::write_atomic(path, text.as_bytes()).map_err(|source| ProfileCsvError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads a profile written by [`write_profile_csv`]. Empty value or stderr fields read as NaN.
///
/// # Errors
/// [`ProfileCsvError`] naming the file and line.
pub fn read_profile_csv(path: &Path) -> Result<ProfileTable, ProfileCsvError> {
    let text = read_text_file(path).map_err(text_error)?;
    parse_profile_csv(&text.text, path)
}

/// [`read_profile_csv`] on the bytes of a file (any accepted encoding, [`crate::text`]).
///
/// # Errors
/// As [`read_profile_csv`].
pub fn parse_profile_bytes(bytes: &[u8], path: &Path) -> Result<ProfileTable, ProfileCsvError> {
    let text = decode_text(bytes, path).map_err(text_error)?;
    parse_profile_csv(&text.text, path)
}

fn text_error(e: TextError) -> ProfileCsvError {
    match e {
        TextError::Io { path, source } => ProfileCsvError::Read { path, source },
        other => ProfileCsvError::Text(other),
    }
}

/// [`read_profile_csv`] on decoded text; `path` names it in messages.
///
/// # Errors
/// As [`read_profile_csv`].
pub fn parse_profile_csv(text: &str, path: &Path) -> Result<ProfileTable, ProfileCsvError> {
    let invalid = |detail: String| ProfileCsvError::Invalid {
        path: path.to_path_buf(),
        detail,
    };
    let dialect = CsvDialect::detect(text);
    let mut reader = dialect.reader_builder().from_reader(text.as_bytes());
    let headers = reader
        .headers()
        .map_err(|e| invalid(format!("unreadable header ({e})")))?
        .clone();
    let names: Vec<&str> = headers.iter().collect();
    let find = |n: &str| names.iter().position(|h| h.eq_ignore_ascii_case(n));
    let r_mm_col = find("r_mm").ok_or_else(|| {
        invalid(format!(
            "the header has no `r_mm` column (found `{}`)",
            crate::csv_dialect::header_for_message(
                names.iter().copied(),
                &["r_mm", "r_px", "value_r", "value_g", "value_b", "value_y"]
            )
        ))
    })?;
    let r_px_col = find("r_px");
    let mut channels = Vec::new();
    for h in &names {
        if let Some(name) = h.strip_prefix("value_") {
            let (Some(v), Some(s), Some(n)) = (
                find(h),
                find(&format!("stderr_{name}")),
                find(&format!("count_{name}")),
            ) else {
                let name = crate::escape::token(name);
                return Err(invalid(format!(
                    "channel `{name}` needs columns value_{name}, stderr_{name} and count_{name}"
                )));
            };
            channels.push((name.to_string(), v, s, n, find(&format!("limit_{name}"))));
        }
    }
    if channels.is_empty() {
        return Err(invalid(
            "no `value_<channel>` column; expected e.g. value_r,stderr_r,count_r".into(),
        ));
    }
    let mut table = ProfileTable {
        r_mm: Vec::new(),
        r_px: Vec::new(),
        channels: channels
            .iter()
            .map(|(name, ..)| ProfileColumn {
                name: name.clone(),
                value: vec![],
                stderr: vec![],
                count: vec![],
                limit: vec![],
            })
            .collect(),
    };
    let mut lines = LineCounter::new(text);
    for record in reader.records() {
        let record = record.map_err(|e| {
            invalid(format!(
                "line {}: malformed CSV: {}",
                lines.line(e.position()),
                crate::spectro::csv_message(&e, &dialect)
            ))
        })?;
        let line = lines.line(record.position());
        let float = |col: usize, allow_empty: bool| -> Result<f64, ProfileCsvError> {
            let field = record.get(col).unwrap_or("");
            if field.is_empty() && allow_empty {
                return Ok(f64::NAN);
            }
            // Non-finite values are written as empty fields, so `NaN` or `inf` text is refused.
            dialect
                .parse_f64(field)
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    invalid(format!(
                        "line {line}: `{}` = {} is not a finite number",
                        crate::escape::token(names[col]),
                        crate::csv_dialect::cell_for_message(field)
                    ))
                })
        };
        table.r_mm.push(float(r_mm_col, false)?);
        table.r_px.push(match r_px_col {
            Some(c) => float(c, true)?,
            None => f64::NAN,
        });
        for (column, (_, v, s, n, l)) in table.channels.iter_mut().zip(&channels) {
            column.value.push(float(*v, true)?);
            column.stderr.push(float(*s, true)?);
            if let Some(l) = l {
                column.limit.push(float(*l, true)?);
            }
            let field = record.get(*n).unwrap_or("");
            column.count.push(field.parse::<u64>().map_err(|_| {
                invalid(format!(
                    "line {line}: `{}` = {} is not a pixel count",
                    crate::escape::token(names[*n]),
                    crate::csv_dialect::cell_for_message(field)
                ))
            })?);
        }
    }
    Ok(table)
}
