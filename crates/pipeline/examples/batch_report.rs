//! Many sample folders measured in parallel, each one's result files and plots written into its
//! folder as soon as it is done (`result.json`, `result.csv`, `result.md`, `profile.csv`,
//! `fit.svg`, `fit.png`), and Table 1 printed for the batch:
//! `cargo run --release -p scatterfit-pipeline --example batch_report -- DIR...`
use std::path::PathBuf;

use scatterfit_io::result_table::table1_markdown;
use scatterfit_pipeline::{BatchRequest, Overrides, measure_batch_with};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dirs: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if dirs.is_empty() {
        return Err("usage: batch_report SAMPLE_DIR...".into());
    }
    let request = BatchRequest::new(dirs, Overrides::default());
    // Runs on a worker thread as each sample finishes: write its files there.
    let batch = measure_batch_with(
        request,
        &|dir, measured| {
            let m = measured.map_err(|e| e.to_string())?;
            scatterfit_report::write_measurement(dir, &m).map_err(|e| e.to_string())?;
            Ok::<_, String>(m.to_result(Some("profile.csv")))
        },
        &|_| {},
    )?;
    let mut results = Vec::new();
    for sample in batch.samples {
        match sample.outcome {
            Ok(r) => results.push(r),
            Err(e) => eprintln!("{}: {e}", sample.dir.display()),
        }
    }
    print!("{}", table1_markdown(&results));
    Ok(())
}
