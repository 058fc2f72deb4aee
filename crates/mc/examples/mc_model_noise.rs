//! Statistical error of the `mc` model: two tables from independent seeds at one η and photon count;
//! the relative difference of their smoothed models, divided by √2, estimates one table's error.
//! Prints its RMS over ρ windows for several albedos, the ρ range each row's data covers, and the
//! build time. Run: `cargo run --release -p scatterfit-mc --example mc_model_noise -- ETA PHOTONS`
use scatterfit_mc::model::{McProfile, McTable, McTableSet, McTableSpec};
use scatterfit_optics::{OpticalProperties, ProfileModel};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let eta: f64 = args[1].parse().unwrap();
    let photons: u64 = args[2].parse().unwrap();
    let mut sets = Vec::new();
    for seed in [11, 12] {
        let mut spec = match std::env::var("STRATA") {
            // STRATA="p0,p1,p2/b0,b1": photons per stratum / bounds.
            Ok(v) => {
                let (p, b) = v.split_once('/').unwrap();
                let p = p
                    .split(',')
                    .map(|x| x.parse::<f64>().unwrap() as u64)
                    .collect();
                let b = b
                    .split(',')
                    .filter(|x| !x.is_empty())
                    .map(|x| x.parse().unwrap())
                    .collect();
                McTableSpec::with_strata(eta, 0.0, p, b).unwrap()
            }
            Err(_) => McTableSpec::new(eta, 0.0, photons).unwrap(),
        };
        spec.seed = seed;
        let t0 = std::time::Instant::now();
        let tally = scatterfit_mc::white::simulate(&spec.white().unwrap(), &|_| {}).unwrap();
        let t = McTable::from_tally(&spec, &tally).unwrap();
        println!(
            "seed {seed}: built in {:.1} s, {:.3e} interactions",
            t0.elapsed().as_secs_f64(),
            tally.interactions as f64
        );
        sets.push(McTableSet::new(vec![t]).unwrap());
    }
    let windows = [
        (0.3, 1.0),
        (1.0, 3.0),
        (3.0, 10.0),
        (10.0, 20.0),
        (20.0, 35.0),
        (35.0, 50.0),
    ];
    for a in [0.3, 0.6, 0.9, 0.97, 0.99, 0.997, 0.999, 0.9997, 0.9999] {
        let p = OpticalProperties::new(a, 1.0 - a, eta).unwrap();
        let (m1, m2) = (
            McProfile::new(&sets[0], &p).unwrap(),
            McProfile::new(&sets[1], &p).unwrap(),
        );
        let near = m1.rd(0.5);
        let mut line = format!(
            "α′ {a:<7} data to ρ {:5.1} | Rd {:.5} Δ {:+.5} |",
            m1.r_data_max_mm(),
            m1.rd_total(),
            m2.rd_total() - m1.rd_total()
        );
        for (lo, hi) in windows {
            let (mut s2, mut n) = (0.0, 0);
            let mut rho = lo;
            while rho < hi {
                let (v1, v2) = (m1.rd(rho), m2.rd(rho));
                if v1 > 1e-6 * near {
                    s2 += ((v2 / v1 - 1.0) / 2f64.sqrt()).powi(2);
                    n += 1;
                }
                rho *= 1.01;
            }
            if n > 0 {
                line += &format!(" [{lo},{hi}) {:.4}%", 100.0 * (s2 / n as f64).sqrt());
            } else {
                line += &format!(" [{lo},{hi}) <1e-6");
            }
        }
        println!("{line}");
    }
}
