//! Quick speed probe (not a benchmark): photons/s for the two cases on the current pool.
use scatterfit_mc::*;
fn main() {
    let n: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(200_000);
    // 10 cm slab, n = 1.4, μa = 0.1/cm, μs = 10/cm, g = 0 → mm: 0.01, 1.0; grid 0.1 mm × 200.
    let thick = Sample::slab(Layer::new(0.01, 1.0, 0.0, 1.4, 100.0).unwrap(), 1.0).unwrap();
    let std_slab = Sample::slab(Layer::new(1.0, 9.0, 0.75, 1.0, 0.2).unwrap(), 1.0).unwrap();
    for (name, s, k) in [("thick", thick, 1u64), ("standard", std_slab, 20)] {
        let sim = Simulation::new(
            s,
            Beam::pencil(),
            RadialGrid::uniform(0.1, 200).unwrap(),
            n * k / 4,
            1,
        )
        .unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let t = std::time::Instant::now();
        let r = pool.install(|| sim.run());
        let dt = t.elapsed().as_secs_f64();
        println!(
            "{name}: {:.3e} photons/s (1 thread); Rd {:.5}±{:.5} Tt {:.5}±{:.5} A {:.5} cons {:.6}±{:.6}",
            sim.photons() as f64 / dt,
            r.rd_total.value,
            r.rd_total.stderr,
            r.transmittance.value,
            r.transmittance.stderr,
            r.absorbed.value,
            r.conservation.value,
            r.conservation.stderr
        );
    }
}
