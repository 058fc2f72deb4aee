//! Photons per second of the engine on the cases timed against MCML (BENCHMARKS.md, "Monte Carlo:
//! speed against MCML"), one thread unless told otherwise:
//!
//! ```text
//! cargo run --release -p scatterfit-mc --example mcml_speed -- CASE PHOTONS [THREADS]
//! ```
//! CASE: `iso` (10 cm slab, n 1.4, μa 0.1/cm, μs 10/cm, g 0), `g09` (the same slab with μs 100/cm,
//! g 0.9: the same reduced coefficients, ten times the interactions), `std` (the standard slab, μa
//! 10/cm, μs 90/cm, g 0.75, n 1, d 0.02 cm). Radial grid 0.01 cm × 200, pencil beam, as the MCML
//! input files in BENCHMARKS.md. Prints photons/s (wall) and interactions per photon; time the CPU
//! with `/usr/bin/time` when the machine is shared.

use std::time::Instant;

use scatterfit_mc::{Beam, Layer, RadialGrid, Sample, Simulation};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map(String::as_str).unwrap_or("iso");
    let photons: u64 = args
        .get(2)
        .map(|s| s.parse::<f64>().expect("PHOTONS: a number") as u64)
        .unwrap_or(100_000);
    let threads: usize = args
        .get(3)
        .map(|s| s.parse().expect("THREADS"))
        .unwrap_or(1);
    // mm and mm⁻¹: μ [cm⁻¹] / 10, d [cm] × 10.
    let layer = match case {
        "iso" => Layer::new(0.01, 1.0, 0.0, 1.4, 100.0),
        "g09" => Layer::new(0.01, 10.0, 0.9, 1.4, 100.0),
        "std" => Layer::new(1.0, 9.0, 0.75, 1.0, 0.2),
        other => panic!("unknown case {other}: iso, g09 or std"),
    }
    .expect("valid layer");
    let sample = Sample::slab(layer, 1.0).expect("valid sample");
    let grid = RadialGrid::uniform(0.1, 200).expect("valid grid");
    let sim = Simulation::new(sample, Beam::pencil(), grid, photons, 1).expect("valid simulation");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let t = Instant::now();
    let r = pool.install(|| sim.run());
    let secs = t.elapsed().as_secs_f64();
    println!(
        "{case}: {photons} photons, {threads} thread(s): {secs:.3} s wall, {:.4e} photons/s, \
         {:.1} interactions/photon, Rd {:.5} ± {:.5}, A {:.5}",
        photons as f64 / secs,
        r.interactions as f64 / photons as f64,
        r.rd_total.value,
        r.rd_total.stderr,
        r.absorbed.value
    );
}
