//! The crate's error type: what stops a report or a figure from being written, with the file it
//! concerns.

use std::path::PathBuf;

use scatterfit_imaging::text::FontError;
use scatterfit_io::profile_csv::ProfileCsvError;
use scatterfit_io::result_json::ResultJsonError;

/// Everything that can stop a figure or a report from being written. Nothing is written for a
/// figure whose data are refused; a file that cannot be written leaves no partial file behind
/// (`scatterfit_io::atomic`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// A series gives a different number of error values than points.
    #[error(
        "plot panel {panel} (\"{title}\"), series \"{series}\": {errors} error values for {points} \
         points; give one error per point or none"
    )]
    ErrorCount {
        /// The panel, counted from 1.
        panel: usize,
        /// Its title.
        title: String,
        /// The series' label.
        series: String,
        /// Error values given.
        errors: usize,
        /// Points given.
        points: usize,
    },
    /// The plotting library (plotters) failed to draw, measure text or finish a figure.
    #[error("{stage}: {detail}")]
    Draw {
        /// What was being done ("drawing the plot", "rendering the PNG plot", …).
        stage: &'static str,
        /// plotters' message.
        detail: String,
    },
    /// The embedded font (`scatterfit_imaging::text`) could not be loaded: a broken build.
    #[error("the embedded plot font (DejaVu Sans) could not be loaded")]
    Font(#[source] FontError),
    /// The PNG encoder failed.
    #[error("encoding the plot as PNG")]
    EncodePng(#[source] image::ImageError),
    /// The output folder could not be created.
    #[error("creating {}", path.display())]
    CreateDir {
        /// The folder.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A plot file (SVG or PNG) could not be written.
    #[error("writing the plot {}", path.display())]
    WritePlot {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A table file (result.csv, result.md) could not be written.
    #[error("writing {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// result.json could not be written (the error names the file).
    #[error(transparent)]
    ResultJson(#[from] ResultJsonError),
    /// profile.csv could not be written (the error names the file).
    #[error(transparent)]
    ProfileCsv(#[from] ProfileCsvError),
    /// The result set's manifest (`result-files.json`) could not be removed or written.
    #[error(transparent)]
    ResultSet(#[from] scatterfit_io::result_set::ResultSetError),
}

/// `Result` with [`ReportError`].
pub type Result<T> = std::result::Result<T, ReportError>;

/// A plotters failure at `stage`, as a [`ReportError::Draw`].
pub(crate) fn draw_error(stage: &'static str, e: impl std::fmt::Display) -> ReportError {
    ReportError::Draw {
        stage,
        detail: e.to_string(),
    }
}

/// An error and its causes joined by ": ", after `text` (the context, or empty), skipping a cause
/// whose text is already there: many errors name their source in their own message, and the chain
/// printed whole would repeat it.
pub fn chain_text_after(mut text: String, err: &dyn std::error::Error) -> String {
    let mut next = Some(err);
    while let Some(cause) = next {
        let c = cause.to_string();
        if !text.contains(&c) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&c);
        }
        next = cause.source();
    }
    text
}

/// An error and its causes joined by ": ", a cause the text already holds left out
/// ([`chain_text_after`]); what `scatterfit` prints after `error: `.
pub fn error_text(err: &dyn std::error::Error) -> String {
    chain_text_after(String::new(), err)
}
