//! Probe: evaluations and timing split of one proposed fit.
use scatterfit_fit::*;
use scatterfit_optics::{OpticalProperties, dipole::Dipole};
fn main() {
    let truth = OpticalProperties::new(1.893, 0.0496, 1.2886).unwrap();
    let d = Dipole::new(&truth);
    let rings = (0..300)
        .map(|i| {
            let r = (i as f64 + 0.5) * 0.05;
            let v = 3.0 * d.rd(r) * (1.0 + 0.01 * ((i * 7919 % 13) as f64 / 6.0 - 1.0));
            Ring {
                r_mm: r,
                value: v,
                stderr: 0.01 * v,
                count: 100,
                detection_limit: 0.0,
            }
        })
        .collect();
    let input = ChannelInput {
        eta: 1.2886,
        albedo_prime: Some(truth.albedo_prime()),
        rd_total: None,
    };
    let p = ProfileData::new(rings).unwrap();
    for m in [Method::Proposed, Method::Existing] {
        for disk in [false, true] {
            let mut o = FitOptions::new(m);
            if !disk {
                o.spot = Spot::Point;
            }
            let prep = PreparedFit::new(&p, &input, &DipoleModel, &o).unwrap();
            let r = prep.solve();
            let t0 = std::time::Instant::now();
            for _ in 0..200 {
                std::hint::black_box(prep.solve());
            }
            println!(
                "{m:?} disk {disk}: evals {} {} time {:.1} µs",
                r.evaluations,
                r.termination,
                t0.elapsed().as_secs_f64() / 200.0 * 1e6
            );
            let mut o2 = o;
            o2.start = Some(Start {
                sigma_s_prime: r.sigma_s_prime.value,
                sigma_a: Some(r.sigma_a.value),
                scale: Some(r.scale.value),
            });
            let prep2 = PreparedFit::new(&p, &input, &DipoleModel, &o2).unwrap();
            let r2 = prep2.solve();
            let t0 = std::time::Instant::now();
            for _ in 0..200 {
                std::hint::black_box(prep2.solve());
            }
            println!(
                "   from the solution: evals {} time {:.1} µs",
                r2.evaluations,
                t0.elapsed().as_secs_f64() / 200.0 * 1e6
            );
        }
    }
}
