//! What the sample page costs beside the measurement (under 10 % of a sample's
//! measurement time). Ignored: a timing, run by hand on a sample folder of the full rig, e.g. one
//! of `scatterfit demo`'s:
//!
//! ```text
//! SCATTERFIT_BENCH_SAMPLE=/tmp/demo/wood-tile cargo test -p scatterfit-report --test suite \
//!     html_cost:: -- --ignored --nocapture
//! ```
//!
//! Prints the medians of 5 runs: `measure_sample` (which includes the bracket's thumbnails, made
//! while the frames are in memory), the page alone (`html::write_sample_page`: radiance map,
//! response figure, swatch render, the text, the atomic write; Figure 4's SVG is the one fit.svg
//! is written from, drawn once), and the whole `write_measurement`; BENCHMARKS.md records them.

use std::path::PathBuf;
use std::time::Instant;

use scatterfit_pipeline::{Overrides, measure_sample};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[test]
#[ignore = "a timing; run by hand with SCATTERFIT_BENCH_SAMPLE"]
fn sample_page_costs_under_a_tenth_of_the_measurement() {
    // Run by hand, so a missing folder is a failure that says what to set, not a silent pass.
    let dir = std::env::var_os("SCATTERFIT_BENCH_SAMPLE")
        .map(PathBuf::from)
        .expect(
            "set SCATTERFIT_BENCH_SAMPLE to a sample folder (one that `scatterfit demo` wrote)",
        );
    let out = tempfile::tempdir().unwrap();
    let runs = 5;
    let mut measure = Vec::new();
    let mut page = Vec::new();
    let mut all = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        let m = measure_sample(&dir, &Overrides::default(), &|_| {}).unwrap();
        measure.push(t.elapsed().as_secs_f64());
        let result = m.to_result(Some("profile.csv"));
        let fit_svg =
            scatterfit_report::render_svg(&scatterfit_report::fit_figure(&m, &result)).unwrap();
        let t = Instant::now();
        scatterfit_report::html::write_sample_page(
            out.path(),
            &m,
            &result,
            Some(fit_svg),
            None,
            &[],
        )
        .unwrap();
        page.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        scatterfit_report::write_measurement(out.path(), &m).unwrap();
        all.push(t.elapsed().as_secs_f64());
    }
    let (m, p, a) = (median(measure), median(page), median(all));
    let size = std::fs::metadata(out.path().join("report.html"))
        .unwrap()
        .len();
    println!(
        "{}: measure_sample {:.1} ms, report.html {:.1} ms ({:.1} % of the measurement; {} kB), \
         write_measurement (all files) {:.1} ms; medians of {runs}",
        dir.display(),
        m * 1e3,
        p * 1e3,
        100.0 * p / m,
        size / 1000,
        a * 1e3
    );
    assert!(
        p < 0.1 * m,
        "the page costs {:.1} % of the measurement",
        100.0 * p / m
    );
}
