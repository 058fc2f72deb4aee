//! The library calls the Python package wraps, timed from Rust — the reference its overhead is
//! measured against (`crates/python/examples/time_calls.py` times the same calls from Python):
//! `cargo run --release -p scatterfit-pipeline --example library_calls -- SAMPLE_DIR RESULT_DIR [N]`,
//! with SAMPLE_DIR a sample folder and RESULT_DIR the folder its result files were written to
//! (its `profile.csv` and `result.json` give the profile and η, α′ of the fit).
//!
//! Prints the median wall time of `measure_sample` on the folder (the measurement with its data
//! checks, which it makes once), of `to_result` (the result file's content from it, with the
//! verdicts) and of the two together, over N calls (default 11), and of `fit_profile` (proposed
//! method, exact transport, 1 mm spot) on its profile over 51.

use std::path::PathBuf;
use std::time::Instant;

use scatterfit_io::profile_csv::read_profile_csv;
use scatterfit_io::result_json::read_result_json;
use scatterfit_optics::{Method, ModelName, Rgb};
use scatterfit_pipeline::profile::channel_from_table;
use scatterfit_pipeline::profile_fit::{ProfileFitRequest, fit_profile};
use scatterfit_pipeline::{Overrides, measure_sample};

/// The median of `n` timed calls of `f` [s].
fn median_s(n: usize, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..n)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[n / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1).map(PathBuf::from);
    let (Some(sample), Some(results)) = (args.next(), args.next()) else {
        return Err("usage: library_calls SAMPLE_DIR RESULT_DIR [N]".into());
    };
    let n: usize = match args.next() {
        Some(n) => n.to_string_lossy().parse()?,
        None => 11,
    };
    let result = read_result_json(&results.join("result.json"))?;
    let table = read_profile_csv(&results.join("profile.csv"))?;
    let profile = Rgb::from_fn(|c| channel_from_table(&table, c.key())).transpose()?;
    let albedo = result
        .channels
        .clone()
        .map(|c| c.albedo_prime.map_or(f64::NAN, |a| a.value));
    let request = ProfileFitRequest {
        name: "profile".into(),
        profile_file: None,
        eta: result.eta,
        albedo_prime: Some(albedo),
        rd: None,
        method: Method::Proposed,
        model: ModelName::Mc,
        spot_diameter_mm: 1.0,
        r_min_mm: None,
        normalise_with_spectro: false,
        g_prior: Default::default(),
    };
    fit_profile(&profile, &request)?;
    let fit = median_s(51, || {
        fit_profile(&profile, &request).expect("fits");
    });
    println!("fit_profile: {:.3} ms (median of 51)", fit * 1e3);
    let overrides = Overrides::default();
    measure_sample(&sample, &overrides, &|_| {})?;
    let measure = median_s(n, || {
        measure_sample(&sample, &overrides, &|_| {}).expect("measures");
    });
    println!("measure_sample: {:.1} ms (median of {n})", measure * 1e3);
    // What a caller does next with a measurement: its result with the checks' verdicts (what
    // result.json holds, and what the Python package's `measure` returns).
    let m = measure_sample(&sample, &overrides, &|_| {})?;
    let result = median_s(n, || {
        std::hint::black_box(m.to_result(Some("profile.csv")));
    });
    println!(
        "Measurement::to_result: {:.2} ms (median of {n})",
        result * 1e3
    );
    let both = median_s(n, || {
        let m = measure_sample(&sample, &overrides, &|_| {}).expect("measures");
        std::hint::black_box(m.to_result(Some("profile.csv")));
    });
    println!(
        "measure_sample + to_result: {:.1} ms (median of {n})",
        both * 1e3
    );
    Ok(())
}
