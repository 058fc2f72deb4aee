//! The Monte Carlo figures (`scatterfit bench mc`): Monte Carlo photon transport, photons per second.

use std::time::Instant;

use scatterfit_mc::{Beam, Layer, RadialGrid, Sample, Simulation};

use crate::{Figure, Result};

/// The two speed cases timed against MCML: (name, sample, photons at full size).
fn speed_cases(quick: bool) -> Result<Vec<(&'static str, Sample, u64, &'static str)>> {
    let k = if quick { 10 } else { 1 };
    Ok(vec![
        (
            "10 cm slab n=1.4 μa=0.1/cm μs=10/cm g=0",
            Sample::slab(Layer::new(0.01, 1.0, 0.0, 1.4, 100.0)?, 1.0)?,
            200_000 / k,
            "MCML (C, gcc -O3) ≈ 1.0e5 photons/s per core on the reference machine",
        ),
        (
            "standard slab (van de Hulst) g=0.75 τ=2",
            Sample::slab(Layer::new(1.0, 9.0, 0.75, 1.0, 0.2)?, 1.0)?,
            4_000_000 / k,
            "MCML (C, gcc -O3) ≈ 4e6 photons/s per core on the reference machine",
        ),
    ])
}

/// Photons/s of both speed cases on one thread and on all threads (grid 0.1 mm × 200, as MCML's
/// 0.01 cm × 200).
pub fn figures(quick: bool) -> Result<Vec<Figure>> {
    let mut figures = Vec::new();
    let all = rayon::current_num_threads();
    for (name, sample, photons, note) in speed_cases(quick)? {
        for threads in [1, all] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()?;
            let sim = Simulation::new(
                sample.clone(),
                Beam::pencil(),
                RadialGrid::uniform(0.1, 200)?,
                photons,
                1,
            )?;
            let start = Instant::now();
            let _ = pool.install(|| sim.run());
            let rate = photons as f64 / start.elapsed().as_secs_f64();
            figures.push(Figure {
                name: format!("mc {name}, {threads} thread(s)"),
                value: rate,
                unit: "photons/s".into(),
                note: format!("{photons} photons; {note}"),
            });
        }
    }
    Ok(figures)
}
