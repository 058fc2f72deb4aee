//! The spectrophotometer CSV (ARCHITECTURE.md, "The measurement, as files"):
//!
//! ```text
//! # optional comment lines start with '#'
//! wavelength_nm,sci,sce          <- fractions 0..1
//! 400,0.0712,0.0301
//! ...
//! ```
//! or `wavelength_nm,sci_pct,sce_pct` with percentages 0..100. Other columns are ignored. Wavelengths
//! must increase strictly and cover 400–700 nm with steps of at most 10 nm (360–780 nm and 5 nm steps
//! are fine). SCI below SCE by more than [`SCI_BELOW_SCE_TOLERANCE`] is refused (swapped columns or a
//! faulty reading); within it, it is noise and is kept.
//!
//! The file may be UTF-8 (with or without BOM), UTF-16 with a BOM or Windows-1252, `,`-, `;`- or
//! tab-separated, with decimal commas where the separator is not a comma ([`crate::text`]).

use std::path::{Path, PathBuf};

use scatterfit_optics::spectro::SpectroReading;

use crate::csv_dialect::{CsvDialect, LineCounter};
use crate::text::{TextError, decode_text, read_text_file};

/// How far SCI may fall below SCE (absolute reflectance) before the reading is refused: about five
/// times the repeatability of a d/8 instrument such as the CM-600d (≈ 0.1 % reflectance).
pub const SCI_BELOW_SCE_TOLERANCE: f64 = 0.005;

/// A problem with a spectrophotometer CSV. Every variant names the file; most name the line and column.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SpectroCsvError {
    /// The file could not be read.
    #[error("{path}: cannot read the spectro CSV")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The bytes are not text we read (UTF-16 without BOM, a workbook, binary data, too large).
    #[error(transparent)]
    Text(TextError),
    /// The columns do not make a reading (`SpectroReading::new` refused them).
    #[error("{}: {source}", path.display())]
    Reading {
        /// The file.
        path: PathBuf,
        /// Why.
        source: scatterfit_optics::OpticsError,
    },
    /// The CSV structure is broken (unbalanced quotes, a row with too few fields, …).
    #[error("{path}: line {line}: {message}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// What the CSV reader reported.
        message: String,
    },
    /// A required column is missing from the header.
    #[error(
        "{path}: the header has no `{column}` column (found: {found}); expected \
         `wavelength_nm,sci,sce` (fractions 0..1) or `wavelength_nm,sci_pct,sce_pct` (percent)"
    )]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column looked for.
        column: &'static str,
        /// The header as found.
        found: String,
    },
    /// A cell that is not a finite number, or a reflectance outside its range.
    #[error("{path}: line {line}, column `{column}`: {value} {reason}")]
    BadValue {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// The column's name.
        column: String,
        /// The text of the cell, quoted for the message (`"…"`, shortened and escaped:
        /// [`crate::csv_dialect::cell_for_message`]).
        value: String,
        /// What is wrong with it and what is expected.
        reason: String,
    },
    /// Wavelengths not strictly increasing.
    #[error(
        "{path}: line {line}: wavelength {} nm does not follow {} nm; wavelengths must increase \
         strictly (sort the rows and remove duplicates)",
        crate::escape::number(*wavelength),
        crate::escape::number(*previous)
    )]
    Order {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// The offending wavelength.
        wavelength: f64,
        /// The wavelength before it.
        previous: f64,
    },
    /// The wavelengths do not cover 400–700 nm densely enough.
    #[error("{path}: {message}")]
    Coverage {
        /// The file.
        path: PathBuf,
        /// What is missing.
        message: String,
    },
    /// Percent columns (`sci_pct`, `sce_pct`) whose values are all at most 1: fractions, which
    /// read as percent would make every reflectance 100× too small (α′ far off).
    #[error(
        "{path}: every value in `{sci}` and `{sce}` is at most 1 (largest {max}): these are \
         fractions 0..1, not percent — name the columns `sci` and `sce`, or give percentages"
    )]
    FractionsInPercent {
        /// The file.
        path: PathBuf,
        /// The SCI column's name as found.
        sci: String,
        /// The SCE column's name as found.
        sce: String,
        /// The largest value in them.
        max: f64,
    },
    /// SCI below SCE beyond measurement noise.
    #[error(
        "{path}: line {line}: SCI {} is below SCE {} at {} nm by more than the noise tolerance \
         {}; SCI includes the specular component and cannot be smaller — are the columns swapped?",
        crate::escape::number(*sci),
        crate::escape::number(*sce),
        crate::escape::number(*wavelength),
        crate::escape::number(*tolerance)
    )]
    SciBelowSce {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// The wavelength \[nm\].
        wavelength: f64,
        /// SCI (fraction).
        sci: f64,
        /// SCE (fraction).
        sce: f64,
        /// The tolerance used.
        tolerance: f64,
    },
}

/// The most data rows a spectrophotometer CSV may have: one per wavelength, 1 nm apart over
/// 100–2500 nm is 2401; 10 000 leaves room and bounds the work a crafted file can ask for.
pub const MAX_SPECTRUM_ROWS: usize = 10_000;

/// Reads a spectrophotometer CSV.
///
/// # Errors
/// [`SpectroCsvError`] naming the file, line and column of the first problem.
pub fn read_spectro_csv(path: &Path) -> Result<SpectroReading, SpectroCsvError> {
    read_spectro_file(path).map(|(reading, _)| reading)
}

/// Reads a spectrophotometer CSV ([`read_spectro_csv`]) with the record of the file read: its path
/// and the SHA-256 of the bytes parsed.
///
/// # Errors
/// As [`read_spectro_csv`].
pub fn read_spectro_file(
    path: &Path,
) -> Result<(SpectroReading, crate::digest::ReadFile), SpectroCsvError> {
    let text = read_text_file(path).map_err(text_error)?;
    let reading = parse_spectro_csv(&text.text, path)?;
    Ok((
        reading,
        crate::digest::ReadFile {
            path: path.to_path_buf(),
            sha256: text.sha256,
        },
    ))
}

/// Parses the bytes of a spectrophotometer CSV (any accepted encoding, [`crate::text`]); `path` is
/// used in messages only.
///
/// # Errors
/// As [`read_spectro_csv`].
pub fn parse_spectro_bytes(bytes: &[u8], path: &Path) -> Result<SpectroReading, SpectroCsvError> {
    let text = decode_text(bytes, path).map_err(text_error)?;
    parse_spectro_csv(&text.text, path)
}

fn text_error(e: TextError) -> SpectroCsvError {
    match e {
        TextError::Io { path, source } => SpectroCsvError::Io { path, source },
        other => SpectroCsvError::Text(other),
    }
}

/// The message of a CSV error, with a hint when a row has more fields than the header.
pub(crate) fn csv_message(e: &csv::Error, dialect: &CsvDialect) -> String {
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } if len > expected_len => dialect.extra_fields_hint(*expected_len as usize, *len as usize),
        _ => e.to_string(),
    }
}

/// Parses the text of a spectrophotometer CSV; `path` is used in messages only.
///
/// # Errors
/// As [`read_spectro_csv`].
pub fn parse_spectro_csv(text: &str, path: &Path) -> Result<SpectroReading, SpectroCsvError> {
    let p = || path.to_owned();
    let dialect = CsvDialect::detect(text);
    let mut reader = dialect.reader_builder().from_reader(text.as_bytes());
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| SpectroCsvError::Malformed {
            path: p(),
            line: 1,
            message: csv_message(&e, &dialect),
        })?
        .iter()
        .map(|h| h.to_ascii_lowercase())
        .collect();
    let find = |name: &str| header.iter().position(|h| h == name);
    let found = crate::csv_dialect::header_for_message(
        header.iter().map(String::as_str),
        &["wavelength_nm", "sci", "sce", "sci_pct", "sce_pct"],
    );
    let wl_col = find("wavelength_nm").ok_or_else(|| SpectroCsvError::MissingColumn {
        path: p(),
        column: "wavelength_nm",
        found: found.clone(),
    })?;
    let (sci_col, sce_col, scale, sci_name, sce_name) = match (find("sci"), find("sce")) {
        (Some(i), Some(e)) => (i, e, 1.0, "sci", "sce"),
        _ => match (find("sci_pct"), find("sce_pct")) {
            (Some(i), Some(e)) => (i, e, 0.01, "sci_pct", "sce_pct"),
            (None, _) if find("sci").is_none() => {
                return Err(SpectroCsvError::MissingColumn {
                    path: p(),
                    column: "sci",
                    found,
                });
            }
            _ => {
                return Err(SpectroCsvError::MissingColumn {
                    path: p(),
                    column: "sce",
                    found,
                });
            }
        },
    };
    let max = if scale == 1.0 { "1" } else { "100" };

    let (mut wavelengths, mut sci, mut sce) = (Vec::new(), Vec::new(), Vec::new());
    let mut lines = LineCounter::new(text);
    for record in reader.records() {
        let record = record.map_err(|e| SpectroCsvError::Malformed {
            path: p(),
            line: lines.line(e.position()),
            message: csv_message(&e, &dialect),
        })?;
        let line = lines.line(record.position());
        if wavelengths.len() >= MAX_SPECTRUM_ROWS {
            return Err(SpectroCsvError::Malformed {
                path: p(),
                line,
                message: format!(
                    "more than {MAX_SPECTRUM_ROWS} rows; a reflectance spectrum has one row per \
                     wavelength (31 from 400 to 700 nm every 10 nm) — is this the right file?"
                ),
            });
        }
        let cell = |col: usize, name: &str| -> Result<f64, SpectroCsvError> {
            let text = record.get(col).unwrap_or("");
            let parsed = dialect.parse_f64(text);
            let bad = |reason: String| SpectroCsvError::BadValue {
                path: p(),
                line,
                column: name.to_owned(),
                value: crate::csv_dialect::cell_for_message(text),
                reason,
            };
            let v: f64 = parsed.ok_or_else(|| {
                bad(format!(
                    "is not a number (columns separated by {}{})",
                    dialect.delimiter_name(),
                    if dialect.decimal_comma {
                        ", decimal comma or point"
                    } else {
                        ", decimal point"
                    }
                ))
            })?;
            if !v.is_finite() {
                return Err(bad("is not a finite number".into()));
            }
            Ok(v)
        };
        let w = cell(wl_col, "wavelength_nm")?;
        if !(100.0..=2500.0).contains(&w) {
            return Err(SpectroCsvError::BadValue {
                path: p(),
                line,
                column: "wavelength_nm".into(),
                value: crate::csv_dialect::cell_for_message(record.get(wl_col).unwrap_or("")),
                reason: "is not a wavelength in nanometres (expected about 360–780)".into(),
            });
        }
        let reflectance = |col: usize, name: &str| -> Result<f64, SpectroCsvError> {
            let v = cell(col, name)?;
            if !(0.0..=1.0 / scale).contains(&v) {
                return Err(SpectroCsvError::BadValue {
                    path: p(),
                    line,
                    column: name.to_owned(),
                    value: crate::csv_dialect::cell_for_message(record.get(col).unwrap_or("")),
                    reason: format!(
                        "is outside 0..{max}{}",
                        if scale == 1.0 && v > 1.0 && v <= 100.0 {
                            "; percentages go in columns named sci_pct and sce_pct"
                        } else {
                            ""
                        }
                    ),
                });
            }
            Ok(v * scale)
        };
        let (i, e) = (
            reflectance(sci_col, sci_name)?,
            reflectance(sce_col, sce_name)?,
        );
        if let Some(&previous) = wavelengths.last()
            && w <= previous
        {
            return Err(SpectroCsvError::Order {
                path: p(),
                line,
                wavelength: w,
                previous,
            });
        }
        if i < e - SCI_BELOW_SCE_TOLERANCE {
            return Err(SpectroCsvError::SciBelowSce {
                path: p(),
                line,
                wavelength: w,
                sci: i,
                sce: e,
                tolerance: SCI_BELOW_SCE_TOLERANCE,
            });
        }
        wavelengths.push(w);
        sci.push(i);
        sce.push(e);
    }
    check_coverage(&wavelengths)
        .map_err(|message| SpectroCsvError::Coverage { path: p(), message })?;
    // Percent columns holding fractions: no reflectance reaches 1 %, where a real
    // sample's SCI (specular included) is several percent somewhere in 400–700 nm.
    let max = sci.iter().chain(&sce).copied().fold(0.0f64, f64::max) / scale;
    if scale != 1.0 && max <= 1.0 {
        return Err(SpectroCsvError::FractionsInPercent {
            path: p(),
            sci: sci_name.to_owned(),
            sce: sce_name.to_owned(),
            max,
        });
    }
    SpectroReading::new(wavelengths, sci, sce)
        .map_err(|source| SpectroCsvError::Reading { path: p(), source })
}

/// The wavelengths must reach 400 and 700 nm with no gap wider than 10 nm in between.
fn check_coverage(wavelengths: &[f64]) -> Result<(), String> {
    let (Some(&first), Some(&last)) = (wavelengths.first(), wavelengths.last()) else {
        return Err("no data rows; expected reflectances from 400 to 700 nm every 10 nm".into());
    };
    if first > 400.0 || last < 700.0 {
        return Err(format!(
            "{} wavelengths from {first} to {last} nm do not cover 400–700 nm, which the colour \
             computation needs; measure the full visible range (400–700 nm every 10 nm)",
            wavelengths.len()
        ));
    }
    for w in wavelengths.windows(2) {
        if w[1] > 400.0 && w[0] < 700.0 && w[1] - w[0] > 10.0 + 1e-9 {
            return Err(format!(
                "gap of {} nm between {} and {} nm; the colour computation needs a sample at least \
                 every 10 nm over 400–700 nm",
                w[1] - w[0],
                w[0],
                w[1]
            ));
        }
    }
    Ok(())
}

/// Writes a reading as a spectrophotometer CSV (`wavelength_nm,sci,sce`, fractions with 6
/// decimals, as instruments export them) atomically, with `comment` as `#` lines on top.
///
/// # Errors
/// [`SpectroCsvError::Io`] when the file cannot be written.
pub fn write_spectro_csv(
    path: &Path,
    reading: &SpectroReading,
    comment: &str,
) -> Result<(), SpectroCsvError> {
    use std::fmt::Write as _;
    let mut text = String::new();
    for line in comment.lines() {
        let _ = writeln!(text, "# {line}");
    }
    text.push_str("wavelength_nm,sci,sce\n");
    for ((w, sci), sce) in reading
        .wavelengths_nm()
        .iter()
        .zip(reading.sci())
        .zip(reading.sce())
    {
        let _ = writeln!(text, "{w},{sci:.6},{sce:.6}");
    }
    crate::atomic::write_atomic(path, text.as_bytes()).map_err(|source| SpectroCsvError::Io {
        path: path.to_owned(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn csv_with(rows: impl Fn(f64) -> String, header: &str) -> String {
        let mut s = format!("{header}\n");
        for i in 0..31 {
            let w = 400.0 + 10.0 * i as f64;
            s.push_str(&rows(w));
            s.push('\n');
        }
        s
    }

    fn good() -> String {
        csv_with(|w| format!("{w},0.55,0.51"), "wavelength_nm,sci,sce")
    }

    fn parse(text: &str) -> Result<SpectroReading, SpectroCsvError> {
        parse_spectro_csv(text, Path::new("sample/spectro.csv"))
    }

    fn err(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    /// A spectrum longer than any instrument writes (rows 0.01 nm apart) is refused at the row
    /// past the bound, not read and inverted whole.
    #[test]
    fn an_overlong_spectrum_is_refused() {
        let mut text = String::from("wavelength_nm,sci,sce\n");
        for i in 0..=MAX_SPECTRUM_ROWS {
            text.push_str(&format!("{},0.55,0.51\n", 400.0 + 0.01 * i as f64));
        }
        let e = err(&text);
        assert!(e.contains("more than 10000 rows"), "{e}");
    }

    #[test]
    fn reads_fractions_and_percent_and_comments() {
        let r = parse(&good()).unwrap();
        assert_eq!(r.wavelengths_nm().len(), 31);
        assert_eq!((r.sci()[3], r.sce()[3]), (0.55, 0.51));
        let pct = format!(
            "# CM-600d export\n{}",
            csv_with(|w| format!("{w}, 55 , 51"), "Wavelength_nm,SCI_pct,SCE_pct")
        );
        let r = parse(&pct).unwrap();
        assert!((r.sci()[0] - 0.55).abs() < 1e-15 && (r.sce()[30] - 0.51).abs() < 1e-15);
        let extra = csv_with(|w| format!("{w},0.55,0.51,x"), "wavelength_nm,sci,sce,note");
        assert!(parse(&extra).is_ok(), "extra columns are ignored");
    }

    #[test]
    fn missing_columns_are_named() {
        let e = err(&csv_with(|w| format!("{w},0.5"), "wavelength_nm,sci"));
        assert!(
            e.contains("sample/spectro.csv") && e.contains("`sce`"),
            "{e}"
        );
        let e = err(&csv_with(|w| format!("{w},0.5,0.5"), "lambda,sci,sce"));
        assert!(
            e.contains("`wavelength_nm`") && e.contains("found: lambda,sci,sce"),
            "{e}"
        );
    }

    #[test]
    fn non_numbers_and_nan_name_line_and_column() {
        let text = good().replace("430,0.55,0.51", "430,abc,0.51");
        let e = err(&text);
        assert!(
            e.contains("line 5")
                && e.contains("`sci`")
                && e.contains("\"abc\"")
                && e.contains("not a number"),
            "{e}"
        );
        let e = err(&good().replace("500,0.55,0.51", "500,0.55,NaN"));
        assert!(
            e.contains("line 12") && e.contains("`sce`") && e.contains("finite"),
            "{e}"
        );
    }

    #[test]
    fn out_of_range_reflectance_is_refused() {
        let e = err(&good().replace("410,0.55,0.51", "410,-0.01,0.51"));
        assert!(e.contains("line 3") && e.contains("outside 0..1"), "{e}");
        let e = err(&good().replace("410,0.55,0.51", "410,55,51"));
        assert!(
            e.contains("sci_pct"),
            "a percentage in a fraction column gets a hint: {e}"
        );
        let pct = csv_with(|w| format!("{w},101,50"), "wavelength_nm,sci_pct,sce_pct");
        assert!(err(&pct).contains("outside 0..100"));
        // Fractions in percent columns: refused, not read 100× too small.
        let fractions = csv_with(
            |w| format!("{w},0.55,0.51"),
            "wavelength_nm,sci_pct,sce_pct",
        );
        let e = err(&fractions);
        assert!(e.contains("fractions 0..1, not percent"), "{e}");
    }

    #[test]
    fn unsorted_and_duplicate_wavelengths_are_refused() {
        let e = err(&good()
            .replace("420,0.55,0.51", "405,0.55,0.51")
            .replace("410,0.55,0.51", "415,0.55,0.51"));
        assert!(e.contains("405 nm does not follow 415 nm"), "{e}");
        let e = err(&good().replace("420,0.55,0.51", "410,0.55,0.51"));
        assert!(e.contains("410 nm does not follow 410 nm"), "{e}");
    }

    #[test]
    fn insufficient_coverage_is_refused() {
        let short: String = good().lines().take(25).collect::<Vec<_>>().join("\n");
        assert!(err(&short).contains("do not cover 400–700"));
        let coarse = "wavelength_nm,sci,sce\n".to_owned()
            + &(0..16)
                .map(|i| format!("{},0.5,0.5\n", 400 + 20 * i))
                .collect::<String>();
        assert!(err(&coarse).contains("gap of 20 nm"));
        assert!(err("wavelength_nm,sci,sce\n").contains("no data rows"));
    }

    #[test]
    fn sci_below_sce_beyond_noise_is_refused_within_noise_kept() {
        let e = err(&good().replace("600,0.55,0.51", "600,0.50,0.51"));
        assert!(e.contains("600 nm") && e.contains("swapped"), "{e}");
        let r = parse(&good().replace("600,0.55,0.51", "600,0.508,0.51")).unwrap();
        assert!(r.sci()[20] < r.sce()[20]);
    }

    #[test]
    fn malformed_rows_and_missing_files_are_reported() {
        let e = err(&good().replace("450,0.55,0.51", "450,0.55"));
        assert!(e.contains("sample/spectro.csv"), "{e}");
        let e = read_spectro_csv(Path::new("/nonexistent/spectro.csv"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("/nonexistent/spectro.csv") && e.contains("cannot read"),
            "{e}"
        );
    }
}
