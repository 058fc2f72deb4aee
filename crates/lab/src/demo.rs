//! The demo as a run (`scatterfit demo`): the seven materials of Choi, Lee & Chin (2014, Table 1)
//! as rig twins ([`materials`]), and once each is measured both ways, the files that say how well
//! the method did ([`write_demo`]: Table 1 and Table 2, the accuracy table against the twins'
//! truth, its JSON, and the index page that links every sample's report) and the one-line verdict
//! of the data checks ([`quality_line`]). Nothing here prints.

use std::path::{Path, PathBuf};

use scatterfit_io::result_json::MeasurementResult;
use scatterfit_optics::materials::CHOI_2014;
use scatterfit_synth::Truth;

use crate::accuracy::{MaterialRow, accuracy_rows};
use crate::twin_settings::Material;

/// Why the demo's files cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum DemoError {
    /// A table or page cannot be written.
    #[error(transparent)]
    Report(#[from] scatterfit_report::ReportError),
    /// The summary does not serialise (a defect).
    #[error("serialising the summary")]
    Json(#[from] serde_json::Error),
}

/// The demo's materials: the seven of Choi et al. 2014, Table 1.
pub fn materials() -> Vec<Material> {
    CHOI_2014.iter().map(Material::from).collect()
}

/// The files besides the samples' own, listed on the index page.
pub const DEMO_FILES: [&str; 6] = [
    "summary.md",
    "summary.csv",
    "compare.md",
    "compare.csv",
    "accuracy.md",
    "demo-summary.json",
];

/// What [`write_demo`] made.
#[derive(Debug)]
pub struct DemoFiles {
    /// Each material's values against the truth (`demo-summary.json`).
    pub rows: Vec<MaterialRow>,
    /// The accuracy table's Markdown (`accuracy.md`).
    pub accuracy: String,
    /// The proposed method's results, one per pair.
    pub proposed: Vec<MeasurementResult>,
    /// The index page.
    pub index: PathBuf,
}

impl DemoFiles {
    /// What `scatterfit demo` prints of the files it wrote into `out`: the accuracy table, the time
    /// spent synthesising (`synth_s`) and measuring (`measure_s`) \[s\], the files, the data
    /// checks' verdict ([`quality_line`]) and, last, the index page a person opens.
    pub fn text(&self, out: &Path, synth_s: f64, measure_s: f64) -> String {
        format!(
            "The method of Choi, Lee & Chin (2014) on Monte Carlo rig-twin samples of their seven \
             materials\n\
             (samples in {0}; the fitted model never made these data; truth in each truth.json)\n\n\
             {1}\n\
             time: {synth_s:.1} s synthesising (Monte Carlo, cached for the next run), \
             {measure_s:.1} s measuring 7 samples with both methods\n\
             files: {0}/<material>/result.json, report.html, fit.png, compare.png; {0}/summary.md \
             (Table 1), compare.md (Table 2), accuracy.md\n\
             quality: {2}\n\
             index: {3}\n",
            out.display(),
            self.accuracy,
            quality_line(&self.proposed),
            self.index.display()
        )
    }
}

/// Writes the demo's files into `out`: summary.csv/md (Table 1 of the proposed method),
/// compare.csv/md (Table 2), accuracy.md and demo-summary.json (every value against the twins'
/// `truths`, the paper's own fits beside them) and index.html (each pair's folder in `dirs`, the
/// samples in `failed` listed as such).
///
/// # Errors
/// A file cannot be written.
pub fn write_demo(
    out: &Path,
    pairs: &[(MeasurementResult, MeasurementResult)],
    papers: &[Option<MeasurementResult>],
    truths: &[Truth],
    dirs: &[PathBuf],
    failed: &[(PathBuf, String)],
) -> Result<DemoFiles, DemoError> {
    let rows = accuracy_rows(pairs, papers, truths);
    let proposed: Vec<MeasurementResult> = pairs.iter().map(|(_, p)| p.clone()).collect();
    let accuracy = crate::accuracy_markdown(&rows);
    scatterfit_report::write_table1(out, &proposed)?;
    scatterfit_report::write_table2(out, pairs)?;
    let json = serde_json::to_string_pretty(&rows)? + "\n";
    for (name, text) in [("accuracy.md", &accuracy), ("demo-summary.json", &json)] {
        scatterfit_report::tables::write_text(&out.join(name), text)?;
    }
    let index = scatterfit_report::html::write_results_index(
        out,
        "scatterfit demo: the seven materials of Choi, Lee & Chin (2014)",
        "Monte Carlo rig-twin samples of the paper's seven materials, measured with the proposed \
         method and the exact forward model (Monte Carlo tables); the paper's dipole fits are in \
         accuracy.md beside them; the truth is in each sample's truth.json, the errors against it in \
         accuracy.md. The sample's name opens its report: verdict, Table 1, Figures 4 and 6, the \
         evidence and the inputs.",
        &proposed,
        dirs,
        failed,
        &DEMO_FILES,
    )?;
    Ok(DemoFiles {
        rows,
        accuracy,
        proposed,
        index,
    })
}

/// The data checks' verdict on the proposed method's channels (RELIABILITY.md): `every channel
/// of the proposed method passes the data checks (ok)`, or each suspect sample with why.
pub fn quality_line(proposed: &[MeasurementResult]) -> String {
    let suspect: Vec<String> = proposed
        .iter()
        .filter(|r| !scatterfit_report::trusted(r))
        .map(|r| {
            format!(
                "{}: {}",
                scatterfit_io::escape::one_line(&r.name),
                scatterfit_report::suspect_text(r)
            )
        })
        .collect();
    if suspect.is_empty() {
        "every channel of the proposed method passes the data checks (ok)".into()
    } else {
        suspect.join("; ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_demos_materials_are_the_papers_seven() {
        let m = materials();
        assert_eq!(m.len(), 7);
        assert_eq!(m[0].name, "pink-plastic");
        assert_eq!(m[0].sigma_s_prime, CHOI_2014[0].sigma_s_prime);
        assert_eq!(m[6].eta, CHOI_2014[6].eta);
    }

    #[test]
    fn no_results_say_every_channel_passes_and_write_an_index() {
        assert_eq!(
            quality_line(&[]),
            "every channel of the proposed method passes the data checks (ok)"
        );
        let dir = tempfile::tempdir().unwrap();
        let failed = vec![(dir.path().join("sulfur"), "the bracket is dark".to_owned())];
        let files = write_demo(dir.path(), &[], &[], &[], &[], &failed).unwrap();
        assert!(files.rows.is_empty());
        for f in DEMO_FILES {
            assert!(dir.path().join(f).is_file(), "{f}");
        }
        let index = std::fs::read_to_string(&files.index).unwrap();
        assert!(index.contains("the bracket is dark"), "{index}");
    }
}
