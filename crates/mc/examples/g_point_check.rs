//! The `mc` model over (η, g) at one material against a direct run of this crate's MCML engine
//! (`Simulation`, pencil beam, half-space; a different tracer from the white runs the tables come
//! from): mean relative difference ± standard error and χ²/bins per window of reduced radius
//! ρ′ = σ′t r, and the totals. For the channels whose error on the rig twin stays above the target
//! with g given: is it the model's or the twin's?
//!
//! ```text
//! cargo run --release -p scatterfit-mc --example g_point_check -- ALBEDO_PRIME ETA G PHOTONS [SEED]
//! ```
//! Reduced units: σ′t = 1 mm⁻¹, so r is in reduced mean free paths. With `G_TABLE=FILE` (a table
//! built by `build_g_tables`, at this η and g), that table's profile and total are printed too, for
//! a table not yet in the shipped grid (e.g. one with another albedo spacing). With `FINE=1`, narrower
//! windows over the far field (5–100 reduced mean free paths) too; with `ENGINE_CACHE=FILE`, the
//! engine's run is kept in FILE (JSON) and read back on the next call, so that versions of the model
//! can be compared with one costly run.

#[path = "common/windows.rs"]
mod windows;

use scatterfit_mc::{Beam, Layer, RadialGrid, Sample, Simulation, bundled_grid};
use scatterfit_optics::{OpticalProperties, ProfileModel};
use windows::windows;

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("a number"))
        .collect();
    let [a, eta, g, photons] = args[..4] else {
        panic!("usage: g_point_check ALBEDO_PRIME ETA G PHOTONS [SEED]")
    };
    let seed = args.get(4).map_or(1, |&s| s as u64);
    let edges: Vec<f64> = std::iter::once(0.0)
        .chain((0..=72).map(|i| 0.1 * 2000f64.powf(i as f64 / 72.0)))
        .collect();
    let grid = RadialGrid::from_edges(edges.clone()).expect("grid");
    let t0 = std::time::Instant::now();
    let half = Sample::slab(
        Layer::from_reduced(a, 1.0 - a, g, eta, f64::INFINITY).expect("layer"),
        1.0,
    )
    .expect("sample");
    // `ENGINE_CACHE=FILE`: the engine's run is read from FILE when it exists, else written there
    // (to compare several versions of the model with one costly run).
    let cache = std::env::var_os("ENGINE_CACHE").map(std::path::PathBuf::from);
    let cached = cache
        .as_ref()
        .and_then(|f| std::fs::read_to_string(f).ok())
        .map(|s| {
            serde_json::from_str::<scatterfit_mc::SimulationResult>(&s).expect("ENGINE_CACHE")
        });
    let d = cached.unwrap_or_else(|| {
        let d = Simulation::new(half, Beam::pencil(), grid, photons as u64, seed)
            .expect("simulation")
            .run();
        if let Some(f) = &cache {
            std::fs::write(f, serde_json::to_string(&d).expect("json")).expect("ENGINE_CACHE");
        }
        d
    });
    let bins = windows::engine_bins(&d, &edges);
    let p = OpticalProperties::new(a, 1.0 - a, eta)
        .and_then(|p| p.with_g(g))
        .expect("props");
    let m = bundled_grid().expect("grid").profile(&p).expect("model");
    println!(
        "α′ {a} η {eta} g {g}: engine total {:.5} ± {:.5}, model {:.5} (z {:+.1}) [{:.0} s]\n{}",
        d.rd_total.value,
        d.rd_total.stderr,
        m.rd_total(),
        (m.rd_total() - d.rd_total.value) / d.rd_total.stderr,
        t0.elapsed().as_secs_f64(),
        windows(&m, &bins).replace(" [", "\n  [")
    );
    // Narrower windows over the far field (where a fit with α′ given finds σ′s at α′ → 1).
    let fine: Vec<(f64, f64)> = [
        5.0, 7.5, 10.0, 15.0, 20.0, 25.0, 30.0, 40.0, 50.0, 65.0, 80.0, 100.0,
    ]
    .windows(2)
    .map(|w| (w[0], w[1]))
    .collect();
    let fine_wanted = std::env::var_os("FINE").is_some();
    if fine_wanted {
        println!(
            "fine:{}",
            windows::windows_in(&m, &bins, &fine).replace(" [", "\n  [")
        );
    }
    if let Some(file) = std::env::var_os("G_TABLE") {
        let table = scatterfit_mc::McTable::load(std::path::Path::new(&file)).expect("G_TABLE");
        let set = scatterfit_mc::McTableSet::new(vec![table]).expect("a set of one table");
        let t = scatterfit_mc::McProfile::new(&set, &p).expect("the table answers");
        println!(
            "G_TABLE {}: total {:.5} (z {:+.1})\n{}",
            file.to_string_lossy(),
            t.rd_total(),
            (t.rd_total() - d.rd_total.value) / d.rd_total.stderr,
            windows(&t, &bins).replace(" [", "\n  [")
        );
        if fine_wanted {
            println!(
                "fine:{}",
                windows::windows_in(&t, &bins, &fine).replace(" [", "\n  [")
            );
        }
    }
}
