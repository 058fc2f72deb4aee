//! Builds the `mc` model's tables for a list of η (g = 0, the default layout) and writes each in
//! compact form (no raw profiles) as `OUT_DIR/mc-white-eta<η>.json`, the files `McTableSet::bundled`
//! embeds. Prints build time, interactions and the smoothing χ² per table.
//!
//! Run: `cargo run --release -p scatterfit-mc --example build_mc_tables -- OUT_DIR PHOTONS ETA...`
//! (PHOTONS is the full-length stratum; the shorter strata get 4× and 16× as many).

use scatterfit_mc::model::{McTable, McTableSpec};
use scatterfit_mc::white::simulate;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = std::path::PathBuf::from(&args[1]);
    let photons: u64 = args[2].parse::<f64>().expect("photons") as u64;
    std::fs::create_dir_all(&out).expect("output folder");
    for eta in args[3..].iter().map(|s| s.parse::<f64>().expect("η")) {
        let spec = McTableSpec::new(eta, 0.0, photons).expect("spec");
        let t0 = std::time::Instant::now();
        let tally = simulate(&spec.white().expect("white spec"), &|_| {}).expect("simulate");
        let secs = t0.elapsed().as_secs_f64();
        let table = McTable::from_tally(&spec, &tally)
            .expect("smooth")
            .compact();
        let path = out.join(format!("mc-white-eta{eta:.2}.json"));
        table.save(&path).expect("write");
        let chi = table.chi2_per_bin();
        println!(
            "η {eta:.2}: {secs:.1} s wall, {:.3e} interactions, smoothing χ²/bin {:.2}–{:.2}, {} bytes",
            tally.interactions as f64,
            chi.iter().cloned().fold(f64::INFINITY, f64::min),
            chi.iter().cloned().fold(0.0, f64::max),
            std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0)
        );
    }
}
