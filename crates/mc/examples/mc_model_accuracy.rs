//! Accuracy of the `mc` forward model against MCML's independent profiles
//! (`reference/mcml_profiles.csv`, physics.md §4.5): builds (or loads from the cache) white Monte
//! Carlo tables at η = 1.0, 1.4, 2.0 and compares each MCML case, bin by bin and pooled in radial
//! windows, and the totals.
//!
//! Run: `cargo run --release -p scatterfit-mc --example mc_model_accuracy -- MCML_CSV PHOTONS [CACHE_DIR]`

use scatterfit_mc::model::{McProfile, McTableSet, McTableSpec};
use scatterfit_optics::{OpticalProperties, ProfileModel};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let csv = std::fs::read_to_string(&args[1]).expect("read MCML csv");
    let photons: u64 = args[2].parse().expect("photons");
    let dir = std::path::PathBuf::from(args.get(3).map_or("/tmp/mc-cache", |s| s.as_str()));
    let mut cases: Vec<(f64, f64, f64, Vec<(f64, f64)>)> = Vec::new();
    for line in csv.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let f: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let (eta, a, tot, r, v) = (f[0], f[1], f[2], f[4], f[5]);
        match cases.last_mut() {
            Some(c) if c.0 == eta && c.1 == a => c.3.push((r, v)),
            _ => cases.push((eta, a, tot, vec![(r, v)])),
        }
    }
    let t0 = std::time::Instant::now();
    let template = McTableSpec::new(1.0, 0.0, photons).unwrap();
    let mut sets = Vec::new();
    for eta in [1.0, 1.4, 2.0] {
        let set = McTableSet::load_or_build(&[eta], &template, &dir, &|_, _, _| {}).unwrap();
        let t = &set.tables()[0];
        let chi = t.chi2_per_bin();
        println!(
            "η {eta}: table ready at {:.1} s; smoothing χ²/bin min {:.2} median {:.2} max {:.2}",
            t0.elapsed().as_secs_f64(),
            chi.iter().cloned().fold(f64::INFINITY, f64::min),
            {
                let mut c = chi.to_vec();
                c.sort_by(f64::total_cmp);
                c[c.len() / 2]
            },
            chi.iter().cloned().fold(0.0, f64::max)
        );
        sets.push((eta, set));
    }
    let windows = [
        (0.1, 0.5),
        (0.5, 1.0),
        (1.0, 2.0),
        (2.0, 5.0),
        (5.0, 10.0),
        (10.0, 20.0),
    ];
    println!("case | total MCML / model (diff) | window: mean rel. diff ± s.e. (χ²/bins)");
    for (eta, a, tot, bins) in &cases {
        let set = &sets.iter().find(|s| s.0 == *eta).unwrap().1;
        let props = OpticalProperties::new(*a, 1.0 - a, *eta).unwrap();
        let m = McProfile::new(set, &props).unwrap();
        let mut line = format!(
            "η {eta} α′ {a}: Rd {tot:.5} / {:.5} ({:+.5}) |",
            m.rd_total(),
            m.rd_total() - tot
        );
        for (lo, hi) in windows {
            let (mut sw, mut swd, mut chi2, mut n) = (0.0, 0.0, 0.0, 0);
            for &(r, v) in &bins[..bins.len() - 1] {
                if r < lo || r >= hi || v <= 0.0 {
                    continue;
                }
                // Model averaged over the 0.05 mm annulus (4-point Gauss–Legendre in r).
                let (ra, rb) = (r - 0.025, r + 0.025);
                let gl = [
                    (-0.861136311594053, 0.347854845137454),
                    (-0.339981043584856, 0.652145154862546),
                    (0.339981043584856, 0.652145154862546),
                    (0.861136311594053, 0.347854845137454),
                ];
                let mut s = 0.0;
                for (x, w) in gl {
                    let rr = 0.5 * (ra + rb) + 0.5 * (rb - ra) * x;
                    s += w * 0.5 * (rb - ra) * 2.0 * std::f64::consts::PI * rr * m.rd(rr);
                }
                let model = s / (std::f64::consts::PI * (rb * rb - ra * ra));
                let rel = 1.0 / (2e6 * 2.0 * std::f64::consts::PI * r * 0.05 * v).sqrt();
                if rel > 0.3 {
                    continue;
                }
                let d = model / v - 1.0;
                let w = 1.0 / (rel * rel);
                sw += w;
                swd += w * d;
                chi2 += d * d * w;
                n += 1;
            }
            if n > 0 {
                line += &format!(
                    " [{lo},{hi}): {:+.4}±{:.4} ({:.1}/{n})",
                    swd / sw,
                    1.0 / sw.sqrt(),
                    chi2
                );
            }
        }
        println!("{line}");
    }
}
