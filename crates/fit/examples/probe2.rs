//! Probe: one proposed fit, repeated (for callgrind).
use scatterfit_fit::*;
use scatterfit_optics::{OpticalProperties, dipole::Dipole};
fn main() {
    let disk = std::env::args().nth(1).is_some();
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
    let mut o = FitOptions::new(Method::Proposed);
    if !disk {
        o.spot = Spot::Point;
    }
    let prep = PreparedFit::new(&p, &input, &DipoleModel, &o).unwrap();
    for _ in 0..100 {
        std::hint::black_box(prep.solve());
    }
}
