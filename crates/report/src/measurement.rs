//! Writing and printing a measurement: result.json, result.csv and result.md (Table 1's shape),
//! profile.csv, the fit plot (fit.svg, fit.png; Figure 4's shape) and the sample page report.html. The CLI's `measure`, `batch`,
//! `compare` and `demo` write through here.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use scatterfit_io::quality::Verdict;
use scatterfit_io::result_json::{MeasurementResult, write_result_json};
use scatterfit_io::result_table::{
    errors_note, port_note, sig4, sigma_cells, table1_csv, table1_markdown,
};
use scatterfit_pipeline::{Compared, Measurement};

use crate::error::{ReportError, Result};

/// What [`write_measurement`] wrote.
#[derive(Debug, Clone)]
pub struct WrittenReport {
    /// The measurement's result, as written to result.json.
    pub result: MeasurementResult,
    /// The files written, in order: profile.csv, result.json, result.csv, result.md, fit.svg,
    /// fit.png, report.html and last the set's manifest, result-files.json (`scatterfit_io::result_set`).
    pub files: Vec<PathBuf>,
}

/// Writes every result file of `m` into `dir` (created if missing): profile.csv, result.json,
/// result.csv, result.md, fit.svg, fit.png and the sample page report.html (`crate::html`), then
/// result-files.json, which lists them with their hashes (a folder without it holds an incomplete
/// set). Each file is written atomically; files of an earlier run are replaced.
///
/// # Errors
/// The first file that cannot be written, named in the error: [`ReportError::CreateDir`],
/// [`ReportError::ProfileCsv`], [`ReportError::ResultJson`], [`ReportError::Write`],
/// [`ReportError::WritePlot`].
pub fn write_measurement(dir: &Path, m: &Measurement) -> Result<WrittenReport> {
    write_measurement_with(dir, m, None)
}

/// [`write_measurement`], and when `existing` (the same sample fitted by the existing method) is
/// given, the sample page also shows Figure 6 (existing and proposed).
///
/// # Errors
/// As [`write_measurement`].
pub fn write_measurement_with(
    dir: &Path,
    m: &Measurement,
    existing: Option<&Measurement>,
) -> Result<WrittenReport> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::CreateDir {
        path: dir.to_path_buf(),
        source,
    })?;
    // The set manifest goes first and comes back last: a folder without one is incomplete
    // (`scatterfit_io::result_set`).
    scatterfit_io::result_set::begin(dir)?;
    let mut written = Vec::new();
    let profile = dir.join("profile.csv");
    scatterfit_io::profile_csv::write_profile_csv(&profile, &m.profile.to_table())?;
    written.push(profile);
    let result = m.to_result(Some("profile.csv"));
    let json = dir.join("result.json");
    write_result_json(&json, &result)?;
    written.push(json);
    for (name, text) in [
        ("result.csv", table1_csv(std::slice::from_ref(&result))),
        ("result.md", table1_markdown(std::slice::from_ref(&result))),
    ] {
        let p = dir.join(name);
        scatterfit_io::atomic::write_atomic(&p, text.as_bytes()).map_err(|source| {
            ReportError::Write {
                path: p.clone(),
                source,
            }
        })?;
        written.push(p);
    }
    // The fit figure is drawn once: fit.svg and the page's Figure 4 are the same text.
    let (svg, png) = (dir.join("fit.svg"), dir.join("fit.png"));
    let figure = crate::figures::fit_figure(m, &result);
    let fit_svg = crate::plot::render_svg(&figure)?;
    scatterfit_io::atomic::write_atomic(&svg, fit_svg.as_bytes()).map_err(|source| {
        ReportError::WritePlot {
            path: svg.clone(),
            source,
        }
    })?;
    crate::plot::write_figure(&figure, None, Some(&png))?;
    written.extend([svg, png]);
    let compare_svg = existing
        .map(|e| crate::plot::render_svg(&crate::figures::compare_figure(e, m, &result.name)))
        .transpose()?;
    let beside: Vec<String> = written
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    let beside: Vec<&str> = beside.iter().map(String::as_str).collect();
    written.push(crate::html::write_sample_page(
        dir,
        m,
        &result,
        Some(fit_svg),
        compare_svg,
        &beside,
    )?);
    let names: Vec<String> = written
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    scatterfit_io::result_set::finish(dir, &names, &result.name, &m.manifest.dir)?;
    written.push(dir.join(scatterfit_io::result_set::SET_FILE));
    Ok(WrittenReport {
        result,
        files: written,
    })
}

/// `quality: R ok · G suspect · B ok` (the data checks' verdict per channel), `None` for a result
/// without verdicts (written before the checks, or by a command that makes none).
pub fn quality_line(r: &MeasurementResult) -> Option<String> {
    let cells: Vec<String> = r
        .channels
        .iter_channels()
        .filter_map(|(ch, c)| {
            c.quality
                .as_ref()
                .map(|q| format!("{} {}", ch.name(), q.verdict))
        })
        .collect();
    (!cells.is_empty()).then(|| format!("quality: {}", cells.join(" · ")))
}

/// Writes one sample's comparison into its folder `dir`: the plot shaped like the paper's Figure 6
/// (`compare.svg`, `compare.png`) and, with `write_results`, the proposed measurement's result files
/// as [`write_measurement_with`] writes them (its report.html with Figure 6). Returns what could not
/// be written, one message each (`writing the results: …`, `writing the plot: …`, with their
/// causes): a sample whose files failed is still compared.
pub fn write_comparison(dir: &Path, c: &Compared, write_results: bool) -> Vec<String> {
    let mut problems = Vec::new();
    if write_results && let Err(e) = write_measurement_with(dir, &c.proposed, Some(&c.existing)) {
        problems.push(format!("writing the results: {}", chain_text(&e)));
    }
    let name = c.proposed.manifest.display_name();
    let fig = crate::compare_figure(&c.existing, &c.proposed, &name);
    let (svg, png) = (dir.join("compare.svg"), dir.join("compare.png"));
    if let Err(e) = crate::write_figure(&fig, Some(&svg), Some(&png)) {
        problems.push(format!("writing the plot: {}", chain_text(&e)));
    }
    problems
}

/// An error and its causes joined by ": ".
fn chain_text(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    text
}

/// True when no channel of `r` has a data-check verdict other than `ok` (results without verdicts
/// count as trusted: the checks did not run).
pub fn trusted(r: &MeasurementResult) -> bool {
    r.channels
        .iter()
        .all(|c| c.quality.as_ref().is_none_or(|q| q.verdict == Verdict::Ok))
}

/// The suspect channels of `r` and why, one line (`G suspect: …; B suspect: …`); empty when
/// [`trusted`].
pub fn suspect_text(r: &MeasurementResult) -> String {
    r.channels
        .iter_channels()
        .filter_map(|(ch, c)| {
            let q = c.quality.as_ref()?;
            (q.verdict != Verdict::Ok).then(|| {
                format!(
                    "{} {}: {}",
                    ch.name(),
                    q.verdict,
                    scatterfit_io::escape::one_line(&q.summary())
                )
            })
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// A human summary of one result, as `scatterfit measure` prints it: η (and the g assumed, when the
/// result records it) and, per channel,
/// σ′s ± error, σa ± error, α′, MSE, fit time and rings used, the data checks' findings and
/// their verdict per channel ([`quality_line`]).
pub fn summary_text(r: &MeasurementResult) -> String {
    let mut t = String::new();
    let eta = match r.eta_stderr {
        Some(e) => format!("{:.4} ± {}", r.eta, sig4(e)),
        None => format!("{:.4}", r.eta),
    };
    // The Henyey–Greenstein g the models were evaluated at, when the result records it;
    // how g entered the error bars follows the table (errors_note).
    let g = match (&r.g_uncertainty, r.inputs.options.g) {
        (Some(u), _) if u.source == scatterfit_io::result_json::GSource::Given => {
            format!(", g = {} given", u.g.unwrap_or(0.0))
        }
        (Some(u), _) if u.source == scatterfit_io::result_json::GSource::Fit => {
            let fitted = u.fitted.as_ref().map_or(String::new(), |f| {
                let parts: Vec<String> = f
                    .iter_channels()
                    .filter_map(|(c, f)| {
                        f.as_ref().map(|f| match (f.g, f.g_stderr) {
                            (Some(g), Some(sd)) => format!("{} {g:.3} ± {sd:.3}", c.name()),
                            _ => format!("{} not determined", c.name()),
                        })
                    })
                    .collect();
                format!(": {}", parts.join(", "))
            });
            let within = u
                .range
                .map_or(String::new(), |[lo, hi]| format!(" in {lo}–{hi}"));
            format!(", g fitted{within}{fitted}")
        }
        (Some(u), _) => match (u.g, u.range) {
            (Some(g), Some([lo, hi])) => format!(", values at g = {g} (g in {lo}–{hi}: ± g)"),
            (None, Some([lo, hi])) => format!(", g in {lo}–{hi} (± g)"),
            _ => String::new(),
        },
        (None, Some(g)) => format!(", g = {g} assumed"),
        (None, None) => String::new(),
    };
    let _ = writeln!(
        t,
        "{}: η = {eta} ({}), method {}, model {}{g}",
        scatterfit_io::escape::one_line(&r.name),
        r.eta_source.map_or("", |s| s.name()),
        r.method,
        r.model
    );
    let _ = writeln!(
        t,
        "  ch  {:<40} {:<42} {:<8} {:<10} {:>9} {:>6}",
        "σ′s [mm⁻¹]", "σa [mm⁻¹]", "α′", "MSE", "fit [µs]", "rings"
    );
    for (ch, c) in r.channels.iter_channels() {
        let name = ch.name();
        let [sp, sa] = sigma_cells(c);
        let _ = writeln!(
            t,
            "  {name}   {sp:<40} {sa:<42} {:<8} {:<10} {:>9.1} {:>6}",
            c.albedo_prime
                .map_or("—".into(), |a| format!("{:.5}", a.value)),
            c.mse.map_or("—".into(), sig4),
            c.fit_time_s * 1e6,
            c.rings_used
        );
        // A note a reason already quotes (the g term's, in `g_term_incomplete`) is not repeated.
        if let Some(p) = &c.problem
            && !c
                .quality
                .iter()
                .flat_map(|q| &q.reasons)
                .any(|r| r.message.contains(p.as_str()))
        {
            let _ = writeln!(t, "      note: {}", scatterfit_io::escape::one_line(p));
        }
        for reason in c.quality.iter().flat_map(|q| &q.reasons) {
            let _ = writeln!(
                t,
                "      {}: {}",
                reason.severity,
                scatterfit_io::escape::one_line(&reason.message)
            );
        }
    }
    if let Some(line) = quality_line(r) {
        let _ = writeln!(t, "  {line}");
    }
    for line in errors_note(std::slice::from_ref(r)).lines() {
        let _ = writeln!(t, "  {line}");
    }
    if r.spectro_port.is_some() {
        let _ = write!(t, "  {}", port_note(std::slice::from_ref(r)));
    }
    t
}
