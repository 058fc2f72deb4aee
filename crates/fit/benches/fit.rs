//! Fit speed: one channel of a 300-ring profile (0.05 mm rings, a 1 mm spot convolved into the
//! model, rings from 1 mm out), as `scatterfit measure` fits it.

use scatterfit_fit::{ChannelInput, FitOptions, Method, PreparedFit, ProfileData, Ring, Spot};
use scatterfit_optics::dipole::Dipole;
use scatterfit_optics::{DiffusionModel, OpticalProperties};

fn main() {
    divan::main();
}

/// Pink plastic's red channel (Choi et al. 2014, Table 1) on 300 rings with ±1 % deterministic
/// ripple, as relative radiance.
fn profile() -> (ProfileData, ChannelInput) {
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
    (ProfileData::new(rings).unwrap(), input)
}

fn options(method: Method, disk: bool) -> FitOptions {
    let mut o = FitOptions::new(method);
    if !disk {
        o.spot = Spot::Point;
    }
    o
}

#[divan::bench(args = [true, false])]
fn proposed_solve(bencher: divan::Bencher, disk: bool) {
    let (p, input) = profile();
    let prepared = PreparedFit::new(
        &p,
        &input,
        &DiffusionModel::Dipole,
        &options(Method::Proposed, disk),
    )
    .unwrap();
    bencher.bench(|| divan::black_box(prepared.solve()));
}

#[divan::bench(args = [true, false])]
fn existing_solve(bencher: divan::Bencher, disk: bool) {
    let (p, input) = profile();
    let prepared = PreparedFit::new(
        &p,
        &input,
        &DiffusionModel::Dipole,
        &options(Method::Existing, disk),
    )
    .unwrap();
    bencher.bench(|| divan::black_box(prepared.solve()));
}

#[divan::bench]
fn prepare_with_spot_kernel(bencher: divan::Bencher) {
    let (p, input) = profile();
    let o = options(Method::Proposed, true);
    bencher.bench(|| {
        divan::black_box(PreparedFit::new(&p, &input, &DiffusionModel::Dipole, &o).unwrap())
    });
}
