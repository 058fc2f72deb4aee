//! Times the writing of one sample's report files (profile.csv, result.json, result.csv,
//! result.md, fit.svg, fit.png): the sample is measured once, then [`write_measurement`] runs 30
//! times into a temporary folder; prints the median, fastest and slowest (BENCHMARKS.md, "Report
//! files").
//!
//! Run: `cargo run --release -p scatterfit-report --example write_time -- SAMPLE_DIR`
//! (e.g. a folder of `scatterfit demo`'s output).

use std::path::PathBuf;
use std::time::Instant;

use scatterfit_pipeline::{Overrides, measure_sample};
use scatterfit_report::write_measurement;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(
        std::env::args_os()
            .nth(1)
            .ok_or("usage: write_time SAMPLE_DIR")?,
    );
    let m = measure_sample(&dir, &Overrides::default(), &|_| {})?;
    let out = std::env::temp_dir().join(format!("scatterfit-write-time-{}", std::process::id()));
    let mut ms = Vec::new();
    for _ in 0..30 {
        let t0 = Instant::now();
        write_measurement(&out, &m)?;
        ms.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    std::fs::remove_dir_all(&out)?;
    ms.sort_by(f64::total_cmp);
    println!(
        "write_measurement ({}, {} rings): median {:.1} ms, fastest {:.1}, slowest {:.1} (30 runs)",
        dir.display(),
        m.profile.profile.rings.len(),
        ms[15],
        ms[0],
        ms[29]
    );
    Ok(())
}
