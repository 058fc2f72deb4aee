//! Builds the `mc` model's g = 0 tables for a list of η with the shipped layout
//! ([`McTableSpec::shipped`]: 128 albedos, 4·10⁶ full-length photons, a seed per η) and writes each
//! in compact form (no raw profiles) as `OUT_DIR/mc-white-eta<η>.json`, the files
//! `McTableSet::bundled` embeds. Prints build time, interactions and the smoothing χ² per table.
//!
//! Run: `cargo run --release -p scatterfit-mc --example build_mc_tables -- OUT_DIR ETA...`
//! (the shipped set: η 1.0, 1.05, 1.1, 1.2, …, 2.5; 2–8 min per table on two cores).

use scatterfit_mc::model::{McTable, McTableSpec};
use scatterfit_mc::white::simulate;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((out, etas)) = args.split_first() else {
        eprintln!("usage: build_mc_tables OUT_DIR ETA...");
        std::process::exit(2);
    };
    let out = std::path::PathBuf::from(out);
    std::fs::create_dir_all(&out).expect("output folder");
    for eta in etas.iter().map(|s| s.parse::<f64>().expect("η")) {
        let spec = McTableSpec::shipped(eta).expect("spec");
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
