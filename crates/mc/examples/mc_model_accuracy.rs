//! Accuracy of the `mc` forward model (the shipped tables, or those in TABLE_DIR):
//! 1. against MCML's independent profiles (`data/reference/mcml_profiles.csv`, docs/physics.md §4.5) at its
//!    15 (η, α′) points (η = 1.0, 1.4, 2.0 are table nodes; α′ 0.3 … 0.999 lie between albedo nodes):
//!    weighted mean relative difference ± standard error (MCML noise 1/√(N·2πr·dr·Rd)) and χ²/bins
//!    in radial windows, and the totals;
//! 2. against direct simulations with this crate's MCML engine (`Simulation`: per-albedo photons with
//!    implicit capture and roulette, a different tracer from the white one) at η between the tables
//!    and α′ between albedo nodes, σ′t = 1 mm⁻¹, on a logarithmic radial grid.
//!
//! Run: `cargo run --release -p scatterfit-mc --example mc_model_accuracy -- MCML_CSV DIRECT_PHOTONS [TABLE_DIR]`

use scatterfit_mc::model::{McProfile, McTable, McTableSet};
use scatterfit_mc::{Beam, Layer, RadialGrid, Sample, Simulation};
use scatterfit_optics::{OpticalProperties, ProfileModel};

#[path = "common/windows.rs"]
mod windows;

use windows::windows;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let csv = std::fs::read_to_string(&args[1]).expect("read MCML csv");
    let direct_photons: u64 = args[2].parse::<f64>().expect("photons") as u64;
    let set = match args.get(3) {
        Some(dir) => {
            let mut tables = Vec::new();
            for e in std::fs::read_dir(dir).expect("table dir") {
                let p = e.expect("entry").path();
                if p.extension().is_some_and(|x| x == "json") {
                    tables.push(McTable::load(&p).expect("table"));
                }
            }
            McTableSet::new(tables).expect("set")
        }
        None => McTableSet::bundled().expect("bundled tables"),
    };
    // 1. MCML.
    let mut cases: Vec<(f64, f64, f64)> = Vec::new();
    let mut bins: Vec<Vec<(f64, f64, f64, f64)>> = Vec::new();
    for line in csv.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let f: Vec<f64> = line
            .split(',')
            .map(|x| x.parse().expect("number"))
            .collect();
        if cases.last().is_none_or(|c| c.0 != f[0] || c.1 != f[1]) {
            cases.push((f[0], f[1], f[2]));
            bins.push(Vec::new());
        }
        let (r, v) = (f[4], f[5]);
        let rel = 1.0 / (2e6 * 2.0 * std::f64::consts::PI * r * 0.05 * v).sqrt();
        bins.last_mut()
            .expect("a case")
            .push((r - 0.025, r + 0.025, v, rel));
    }
    println!(
        "## against MCML (mean model/MCML − 1 ± s.e. (χ²/bins) per window of r in mean free paths)"
    );
    for ((eta, a, total), b) in cases.iter().zip(&mut bins) {
        b.pop(); // overflow bin
        let p = OpticalProperties::new(*a, 1.0 - a, *eta).expect("props");
        let m = McProfile::new(&set, &p).expect("model");
        println!(
            "η {eta} α′ {a}: total {total:.5} / model {:.5} ({:+.5}) |{}",
            m.rd_total(),
            m.rd_total() - total,
            windows(&m, b)
        );
    }
    // 2. Direct simulations between tables and albedo nodes.
    println!("## against direct MCML-engine runs ({direct_photons} photons each)");
    let edges: Vec<f64> = std::iter::once(0.0)
        .chain((0..=60).map(|i| 0.1 * 500f64.powf(i as f64 / 60.0)))
        .collect();
    let grid = RadialGrid::from_edges(edges.clone()).expect("grid");
    for (eta, a, seed) in [
        (1.3, 0.5, 1u64),
        (1.3, 0.95, 2),
        (1.5, 0.8, 3),
        (1.5, 0.995, 4),
        (1.7, 0.9, 5),
        (1.33, 0.9995, 6),
        (2.3, 0.98, 7),
    ] {
        let t0 = std::time::Instant::now();
        let half = Sample::slab(
            Layer::from_reduced(a, 1.0 - a, 0.0, eta, f64::INFINITY).expect("layer"),
            1.0,
        )
        .expect("sample");
        let d = Simulation::new(half, Beam::pencil(), grid.clone(), direct_photons, seed)
            .expect("simulation")
            .run();
        let b = windows::engine_bins(&d, &edges);
        let p = OpticalProperties::new(a, 1.0 - a, eta).expect("props");
        let m = McProfile::new(&set, &p).expect("model");
        println!(
            "η {eta} α′ {a}: total {:.5}±{:.5} / model {:.5} ({:+.5}) [{:.0} s] |{}",
            d.rd_total.value,
            d.rd_total.stderr,
            m.rd_total(),
            m.rd_total() - d.rd_total.value,
            t0.elapsed().as_secs_f64(),
            windows(&m, &b)
        );
    }
}
