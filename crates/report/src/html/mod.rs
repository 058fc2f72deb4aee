//! The HTML report: `report.html`, one page per sample ([`write_sample_page`], written by
//! [`crate::write_measurement`]), and `index.html`, one page per batch ([`write_index`]).
//!
//! Self-contained pages: no network and no file besides the page is needed to read them. Figures
//! are inline SVG (the same drawings as fit.svg and compare.svg; their text is text, searchable
//! and copyable); pictures (the radiance map, the bracket's thumbnails, the rendered swatch) are
//! small PNG `data:` URIs, so that a page survives being mailed or copied alone — the choice of a
//! report a lab signs and sends, at a cost of tens of kilobytes. The index's sorting is a few lines
//! of inline JavaScript; without it the table is still complete. Printable (a print style drops
//! the navigation and keeps figures and tables whole).
//!
//! Colours: the Okabe & Ito palette for verdicts and channels and viridis for the radiance map,
//! all readable with the common colour-vision deficiencies; every verdict is also a word.
//!
//! Every value that comes from a file or a path is escaped (`markup::name`, `markup::text`, which
//! reuse `scatterfit_io::escape`); links are percent-encoded relative paths (`markup::href`).
//! Every read of the result's fields is in `view` (one place to adapt when the result's shape
//! changes).
//!
//! Modules: `view` (the view model), `markup` (escaping, page head and style, data URIs),
//! `sample` and `index` (the two pages), `evidence` (radiance map, response, thumbnails, swatch).

use std::path::{Path, PathBuf};

use scatterfit_io::result_json::MeasurementResult;
use scatterfit_pipeline::Measurement;

use crate::error::{ReportError, Result};

mod evidence;
mod index;
pub mod markup;
mod sample;
#[cfg(test)]
mod tests;
mod view;

pub use evidence::CHANNEL_COLOURS;
pub use index::{IndexEntry, IndexPage};
pub use sample::SampleExtras;

/// The sample page's file name.
pub const SAMPLE_PAGE: &str = "report.html";
/// The batch page's file name.
pub const INDEX_PAGE: &str = "index.html";

/// The sample page of `result` with `extras` (figures and pictures), as HTML text.
pub fn sample_html(result: &MeasurementResult, extras: &SampleExtras) -> String {
    sample::sample_page(&view::ResultView::new(result), extras)
}

/// The pictures and figures of a measurement's page besides Figure 4 and Figure 6 (given as SVG
/// text): the radiance map with its marks, the response, the bracket's thumbnails, the swatch.
pub fn sample_extras(
    m: &Measurement,
    result: &MeasurementResult,
    fit_svg: Option<String>,
    compare_svg: Option<String>,
) -> SampleExtras {
    let view = view::ResultView::new(result);
    let mut extras = sample::extras_for(m, &view, fit_svg, compare_svg);
    extras.thumbnails = m
        .hdr
        .thumbnails
        .iter()
        .zip(&m.hdr.frames)
        .filter_map(|(t, f)| {
            let png = evidence::encode_png(t.width(), t.height(), t.data())?;
            let file = f.file.file_name()?.to_string_lossy().into_owned();
            Some((file, f.time_s, png))
        })
        .collect();
    extras
}

/// Writes `report.html` for `m` (whose result is `result`) into `dir`, atomically, with Figure 4
/// (`fit_svg`), Figure 6 when `compare_svg` is given, and links to `files` (names beside it).
///
/// # Errors
/// [`ReportError::Write`] naming the page.
pub fn write_sample_page(
    dir: &Path,
    m: &Measurement,
    result: &MeasurementResult,
    fit_svg: Option<String>,
    compare_svg: Option<String>,
    files: &[&str],
) -> Result<PathBuf> {
    let mut extras = sample_extras(m, result, fit_svg, compare_svg);
    extras.files = files.iter().map(|f| (*f).to_string()).collect();
    let path = dir.join(SAMPLE_PAGE);
    write(&path, &sample_html(result, &extras))?;
    Ok(path)
}

/// The index page, as HTML text.
pub fn index_html(page: &IndexPage<'_>) -> String {
    index::index_page(page)
}

/// Writes `index.html` into `dir`, atomically.
///
/// # Errors
/// [`ReportError::Write`] naming the page.
pub fn write_index(dir: &Path, page: &IndexPage<'_>) -> Result<PathBuf> {
    let path = dir.join(INDEX_PAGE);
    write(&path, &index_html(page))?;
    Ok(path)
}

/// Writes `index.html` into `dir` for a command over many samples: one row per result (its folder
/// from `folders`, linked to its report.html when there is one, and to its compare.svg, Figure 6,
/// when there is one), the samples of `failures` with their message, and links to `files` (names
/// in `dir`). Returns its path.
///
/// # Errors
/// [`ReportError::Write`] naming the page.
pub fn write_results_index(
    dir: &Path,
    title: &str,
    intro: &str,
    results: &[MeasurementResult],
    folders: &[PathBuf],
    failures: &[(PathBuf, String)],
    files: &[&str],
) -> Result<PathBuf> {
    let samples = results
        .iter()
        .zip(folders)
        .map(|(result, d)| {
            let page = d.join(SAMPLE_PAGE);
            let compare = d.join("compare.svg");
            IndexEntry {
                result,
                folder: d.display().to_string(),
                page: page.exists().then(|| link_from(dir, &page)),
                links: if compare.exists() {
                    vec![("Figure 6".into(), link_from(dir, &compare))]
                } else {
                    Vec::new()
                },
            }
        })
        .collect();
    let page = IndexPage {
        title: title.into(),
        intro: intro.into(),
        samples,
        failures: failures
            .iter()
            .map(|(d, why)| (d.display().to_string(), why.clone()))
            .collect(),
        files: files.iter().map(|f| (*f).to_string()).collect(),
    };
    write_index(dir, &page)
}

/// The path of `target` as a link from a page in `page_dir`: relative when both resolve on this
/// machine (so that the folder can be moved whole), else `target` as given; `/`-separated, not yet
/// percent-encoded (the pages do that).
pub fn link_from(page_dir: &Path, target: &Path) -> String {
    let rel = (|| {
        let from = std::fs::canonicalize(page_dir).ok()?;
        let parent = target.parent().filter(|p| !p.as_os_str().is_empty());
        let to_dir = std::fs::canonicalize(parent.unwrap_or(Path::new("."))).ok()?;
        let file = target.file_name()?;
        let from: Vec<_> = from.components().collect();
        let to: Vec<_> = to_dir.components().collect();
        let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
        let mut parts: Vec<String> = vec!["..".into(); from.len() - common];
        parts.extend(
            to[common..]
                .iter()
                .map(|c| c.as_os_str().to_string_lossy().into_owned()),
        );
        parts.push(file.to_string_lossy().into_owned());
        Some(parts.join("/"))
    })();
    rel.unwrap_or_else(|| target.to_string_lossy().replace('\\', "/"))
}

fn write(path: &Path, html: &str) -> Result<()> {
    scatterfit_io::atomic::write_atomic(path, html.as_bytes()).map_err(|source| {
        ReportError::Write {
            path: path.to_path_buf(),
            source,
        }
    })
}
