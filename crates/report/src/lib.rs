//! scatterfit-report: the reports and figures of a measurement.
//!
//! What `scatterfit measure` leaves in a sample's folder, for a Rust program that measured the
//! sample through `scatterfit-pipeline`:
//! - **result files** ([`write_measurement`]): `result.json` (every value, uncertainty and input
//!   file hash), `result.csv` and `result.md` (the row of Choi, Lee & Chin 2014's Table 1),
//!   `profile.csv` (the measured radial profile), the fit plot `fit.svg` / `fit.png`, and the
//!   sample page `report.html` ([`html`]: verdict, Table 1, Figures 4 and 6, the evidence, the
//!   inputs; one self-contained file);
//! - **the batch page** ([`html::write_index`]): `index.html`, one sortable row per sample;
//! - **figures** ([`fit_figure`]: the measured profile and the fitted model per RGB channel, the
//!   shape of the paper's Figure 4; [`compare_figure`]: measured, existing and proposed method, its
//!   Figure 6), drawn by [`write_figure`] as SVG and/or PNG;
//! - **the printed summary** ([`summary_text`]): η and per channel σ′s, σa with their
//!   uncertainties, α′, MSE; and the spectrophotometer stage's alone ([`spectro_text`],
//!   [`SpectroReport`]).
//!
//! Figures are data ([`Figure`] → [`Panel`]s → [`Series`]), so a program can plot its own
//! profiles the same way. Rendering needs no system fonts: plotters runs without font-kit and the
//! text comes from the DejaVu Sans embedded in `scatterfit_imaging::text`. Files are written
//! atomically (`scatterfit_io::atomic`); errors are [`ReportError`]s naming the file.
//!
//! ```no_run
//! use std::path::Path;
//!
//! use scatterfit_pipeline::{Overrides, measure_sample};
//!
//! // Measure a sample folder (sample.toml, the spectro file, the exposure bracket).
//! let m = measure_sample(Path::new("samples/pink-plastic"), &Overrides::default(), &|_| {})?;
//!
//! // Every result file, fit.png among them; then the summary `scatterfit measure` prints.
//! let written = scatterfit_report::write_measurement(Path::new("out/pink-plastic"), &m)?;
//! print!("{}", scatterfit_report::summary_text(&written.result));
//!
//! // Or the fit plot alone, as PNG.
//! let figure = scatterfit_report::fit_figure(&m, &written.result);
//! scatterfit_report::write_figure(&figure, None, Some(Path::new("pink-plastic-fit.png")))?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![forbid(unsafe_code)]

pub mod batch_set;
pub mod compare_set;
pub mod error;
pub mod figures;
pub mod html;
pub mod measurement;
pub mod plot;
pub mod spectro;
pub mod tables;

pub use error::{ReportError, Result};
pub use figures::{compare_figure, fit_figure};
pub use measurement::{
    WrittenReport, quality_line, summary_text, suspect_text, trusted, write_comparison,
    write_measurement, write_measurement_with,
};
pub use plot::{Figure, Panel, Series, SeriesStyle, render_png, render_svg, write_figure};
pub use spectro::{SpectroReport, spectro_text};
pub use tables::{write_table1, write_table2};
