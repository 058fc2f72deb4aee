//! Photon-transport speed on the two cases timed against MCML (BENCHMARKS.md, "Summary") (run: `cargo bench -p scatterfit-mc`).
//!
//! 1. "10 cm slab": μa = 0.1/cm, μs = 10/cm, g = 0, n = 1.4, d = 10 cm (in mm: σa = 0.01, σs = 1,
//!    d = 100), radial grid 0.1 mm × 200 — MCML: ~1.0e5 photons/s on one core.
//! 2. "standard slab": μa = 10/cm, μs = 90/cm, g = 0.75, n = 1, d = 0.02 cm — MCML: ~4e6 photons/s.
//!
//! Each iteration traces a fixed number of photons on a one-thread rayon pool; divan reports the
//! throughput in items (photons) per second.

use scatterfit_mc::{Beam, Layer, RadialGrid, Sample, Simulation};

fn main() {
    divan::main();
}

fn simulation(thick: bool, photons: u64) -> Simulation {
    let layer = if thick {
        Layer::new(0.01, 1.0, 0.0, 1.4, 100.0)
    } else {
        Layer::new(1.0, 9.0, 0.75, 1.0, 0.2)
    }
    .expect("valid layer");
    let sample = Sample::slab(layer, 1.0).expect("valid sample");
    let grid = RadialGrid::uniform(0.1, 200).expect("valid grid");
    Simulation::new(sample, Beam::pencil(), grid, photons, 1).expect("valid simulation")
}

fn one_thread() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool")
}

/// 10 cm slab, n = 1.4, α = 0.99, g = 0: 20 000 photons per iteration, one thread.
#[divan::bench(sample_count = 10, sample_size = 1)]
fn slab_10cm_n1_4_one_thread(b: divan::Bencher) {
    let sim = simulation(true, 20_000);
    let pool = one_thread();
    b.counter(divan::counter::ItemsCount::new(20_000usize))
        .bench_local(|| pool.install(|| sim.run()));
}

/// Standard slab (van de Hulst): 500 000 photons per iteration, one thread.
#[divan::bench(sample_count = 10, sample_size = 1)]
fn standard_slab_one_thread(b: divan::Bencher) {
    let sim = simulation(false, 500_000);
    let pool = one_thread();
    b.counter(divan::counter::ItemsCount::new(500_000usize))
        .bench_local(|| pool.install(|| sim.run()));
}

/// Standard slab on all cores (rayon's default pool).
#[divan::bench(sample_count = 10, sample_size = 1)]
fn standard_slab_all_threads(b: divan::Bencher) {
    let sim = simulation(false, 1_000_000);
    b.counter(divan::counter::ItemsCount::new(1_000_000usize))
        .bench_local(|| sim.run());
}

/// The `mc` forward model: Rd(r) + both derivatives at 300 radii (0.1…30 mm) through the
/// `ProfileModel` trait, model construction included (η between two tables, α′ between nodes) —
/// one Levenberg–Marquardt iteration's model work. Uses a small table built once (the evaluation
/// cost does not depend on the photon count).
#[divan::bench(sample_count = 100)]
fn mc_model_profile_with_derivatives_300_radii(b: divan::Bencher) {
    use scatterfit_mc::model::{McProfile, McTable, McTableSet, McTableSpec};
    use scatterfit_optics::{OpticalProperties, ProfileModel, ProfileSample};
    let tables = [1.2, 1.4]
        .iter()
        .map(|&eta| {
            let spec = McTableSpec::with_strata(eta, 0.0, vec![40_000, 8_000], vec![64]).unwrap();
            McTable::build(&spec, &|_, _| {}).unwrap()
        })
        .collect();
    let set = McTableSet::new(tables).unwrap();
    let radii: Vec<f64> = (1..=300).map(|i| 0.1 * i as f64).collect();
    let props = OpticalProperties::new(1.979, 0.0496, 1.2886).unwrap();
    let mut out = vec![
        ProfileSample {
            rd: 0.0,
            d_sigma_s_prime: 0.0,
            d_sigma_a: 0.0
        };
        radii.len()
    ];
    b.bench_local(|| {
        let m = McProfile::new(&set, divan::black_box(&props)).unwrap();
        m.profile_with_derivatives_into(&radii, &mut out);
        divan::black_box(&out);
    });
}

/// Parsing the 16 shipped `mc` tables (`McTableSet::bundled`), done once per process.
#[divan::bench(sample_count = 20)]
fn mc_bundled_set_parse() -> scatterfit_mc::McTableSet {
    scatterfit_mc::McTableSet::bundled().unwrap()
}

/// α′ from a total Rd by Monte Carlo between tables (η = 1.33): bisection on the interpolated totals.
#[divan::bench(sample_count = 100)]
fn mc_albedo_from_rd_total(b: divan::Bencher) {
    let set = scatterfit_mc::McTableSet::bundled().unwrap();
    b.bench_local(|| {
        set.albedo_from_rd_total(divan::black_box(0.5), divan::black_box(1.33))
            .unwrap()
    });
}
