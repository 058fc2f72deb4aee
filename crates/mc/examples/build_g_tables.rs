//! Builds the anisotropic (g ≠ 0) `mc` tables with the layout of
//! `common/g_tables_layout.rs` (albedo nodes over α′ 0.2–0.99995, strata at 64/(1 − g) and
//! 1024/(1 − g) interactions) and writes each in compact form as
//! `OUT/mc-white-eta<η>-g<g>.json` (η and g to two decimals). Tables already in OUT are skipped, so
//! an interrupted build resumes; each line of the log (stdout) gives the table, its build time,
//! interactions and the smoothing χ².
//!
//! ```text
//! cargo run --release -p scatterfit-mc --example build_g_tables -- --out DIR \
//!     [--photons P] [--seed S] [--g G,G,…] [--eta E,E,…] [--spacing reduced]
//! ```
//! Each table also gets low-albedo nodes down to α′ 0.01 from a short run of their own
//! (`scatterfit_mc::LowAlbedoRun`, 160 P photons). `--add-low-albedos` instead gives every table
//! already in OUT (of the `--g` listed, if given) that lacks them its low-albedo nodes (the shipped tables: seconds each), leaving
//! the rest of each file as it was. `--replace-low-albedos` does the same and also runs again the
//! low-albedo run of every table whose run traced fewer than 160 P photons (its low rows taken off
//! first, `McTable::without_low_albedos`); tables already at 160 P are skipped, so it resumes.
//!
//! `--spacing reduced` spaces the albedo nodes equally in √(1 − α′) instead of √(1 − a)
//! (`scatterfit_mc::AlbedoSpacing`), halving the last interval toward α′ → 1 at g = 0.9.
//! Defaults: P = 1e6 full-length photons (16 P and 4 P in the shorter strata), seed 1, and the
//! chosen grid in the order most needed first: g = 0.9 and 0.8 over the η grid, then g = 0.5,
//! 0.95, 0.7 (BENCHMARKS.md, "Anisotropic white tables", says why and what it costs). The η grid
//! for g ≠ 0 is 1.0, 1.1, …, 2.4 (0.1 apart; 15 tables), built 0.2 apart first (1.0, 1.2, …, 2.4,
//! then 1.1, 1.3, …, 2.3) so that a coarse set is complete early.

#[path = "common/g_tables_layout.rs"]
mod layout;

use scatterfit_mc::model::McTable;
use scatterfit_mc::white::simulate;

/// The g grid, most needed first.
const G_GRID: [f64; 5] = [0.9, 0.8, 0.5, 0.95, 0.7];

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| -> Option<&str> {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .map(String::as_str)
    };
    let list = |s: &str| -> Vec<f64> {
        s.split(',')
            .map(|x| x.trim().parse::<f64>().expect("a number"))
            .collect()
    };
    let Some(out) = value("--out").map(std::path::PathBuf::from) else {
        eprintln!(
            "usage: build_g_tables --out DIR [--photons P] [--seed S] [--g G,…] [--eta E,…] [--add-low-albedos | --replace-low-albedos]"
        );
        std::process::exit(2);
    };
    let photons = value("--photons").map_or(1e6, |p| p.parse::<f64>().expect("photons")) as u64;
    let seed: u64 = value("--seed").map_or(1, |s| s.parse().expect("seed"));
    let gs = value("--g").map_or(G_GRID.to_vec(), list);
    let reduced = match value("--spacing") {
        None => false,
        Some("reduced") => true,
        Some(other) => {
            eprintln!("--spacing {other}: the builder knows `reduced` (default: √(1 − a))");
            std::process::exit(2);
        }
    };
    let etas = value("--eta").map_or(
        (0..8)
            .map(|i| 1.0 + 0.2 * i as f64)
            .chain((0..7).map(|i| 1.1 + 0.2 * i as f64))
            .collect(),
        list,
    );
    std::fs::create_dir_all(&out).expect("output folder");
    let replace = args.iter().any(|a| a == "--replace-low-albedos");
    if replace || args.iter().any(|a| a == "--add-low-albedos") {
        add_low_albedos(&out, photons, value("--g").map(list), replace);
        return;
    }
    for &g in &gs {
        for &eta in &etas {
            let path = out.join(format!("mc-white-eta{eta:.2}-g{g:.2}.json"));
            if path.exists() {
                continue;
            }
            let mut spec = layout::g_spec(eta, g, photons);
            spec.seed = seed;
            if reduced {
                spec.albedo_spacing = scatterfit_mc::AlbedoSpacing::SqrtOneMinusReducedAlbedo;
            }
            let spec =
                layout::with_low_albedos(spec, layout::LOW_ALBEDO_PHOTONS_PER_PHOTON * photons);
            let t0 = std::time::Instant::now();
            let tally = simulate(&spec.white().expect("white spec"), &|_| {}).expect("simulate");
            let secs = t0.elapsed().as_secs_f64();
            let table = match McTable::from_tally(&spec, &tally) {
                Ok(t) => t.compact(),
                Err(e) => {
                    // Logged, and the next table built: a failed one is rebuilt (with more photons)
                    // on the next run, since its file is missing.
                    println!("FAILED g {g:.2} η {eta:.2} ({photons} photons): {e}");
                    continue;
                }
            };
            table.save(&path).expect("write");
            let chi = table.chi2_per_bin();
            println!(
                "{} g {g:.2} η {eta:.2}: {secs:.0} s wall, {:.3e} interactions, χ²/bin {:.2}–{:.2}, {} bytes",
                std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .map_or(0, |d| d.as_secs()),
                tally.interactions as f64,
                chi.iter().cloned().fold(f64::INFINITY, f64::min),
                chi.iter().cloned().fold(0.0, f64::max),
                std::fs::metadata(&path).map_or(0, |m| m.len())
            );
        }
    }
}

/// Gives every table in `dir` (of the g in `gs`, if given) without low-albedo nodes its nodes down
/// to α′ 0.01, with `LOW_ALBEDO_PHOTONS_PER_PHOTON` × `photons` in their run, and writes it back in
/// compact form (one line of log per table). With `replace`, a table whose low run traced fewer
/// photons than that has it taken off (`McTable::without_low_albedos`: the main run's rows as they
/// were) and run again; tables already at that count are skipped, so an interrupted run resumes.
fn add_low_albedos(dir: &std::path::Path, photons: u64, gs: Option<Vec<f64>>, replace: bool) {
    let low_photons = layout::LOW_ALBEDO_PHOTONS_PER_PHOTON * photons;
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .expect("table folder")
        .map(|e| e.expect("folder entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    paths.sort();
    for path in paths {
        let table = McTable::load(&path).expect("a table");
        let g = table.spec().g;
        let had = table.spec().low_albedos.as_ref().map(|l| l.photons);
        // g = 0 tables (crates/mc/tables) only when `--g 0` names them.
        if had.is_some_and(|p| !replace || p >= low_photons)
            || (g == 0.0 && !gs.as_ref().is_some_and(|gs| gs.contains(&0.0)))
            || gs
                .as_ref()
                .is_some_and(|gs| !gs.iter().any(|&x| (x - g).abs() < 1e-9))
        {
            continue;
        }
        let table = if had.is_some() {
            match table.without_low_albedos() {
                Ok(t) => t,
                Err(e) => {
                    println!("FAILED {}: {e}", path.display());
                    continue;
                }
            }
        } else {
            table
        };
        let t0 = std::time::Instant::now();
        let spec = layout::with_low_albedos(table.spec().clone(), low_photons);
        let low = spec.low_albedos.clone().expect("just set");
        let nodes = low.albedo_count;
        let table = match table.with_low_albedos(low) {
            Ok(t) => t.compact(),
            Err(e) => {
                println!("FAILED {}: {e}", path.display());
                continue;
            }
        };
        table.save(&path).expect("write");
        let chi = &table.chi2_per_bin()[..nodes];
        println!(
            "{} {}: {nodes} low-albedo nodes ({low_photons} photons{}) in {:.1} s, χ²/bin {:.2}–{:.2}",
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
            path.display(),
            had.map_or(String::new(), |p| format!(", replacing {p}")),
            t0.elapsed().as_secs_f64(),
            chi.iter().cloned().fold(f64::INFINITY, f64::min),
            chi.iter().cloned().fold(0.0, f64::max),
        );
    }
}
