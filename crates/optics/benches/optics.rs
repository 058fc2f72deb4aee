//! Optics hot paths: the dipole profile with derivatives (one LM iteration's model evaluation) and the
//! α′ inversion. Run: `cargo bench -p scatterfit-optics --bench optics`.

use divan::{Bencher, black_box};
use scatterfit_optics::dipole::{Dipole, albedo_from_rd, rd_total};
use scatterfit_optics::{DiffusionModel, ModelFamily, OpticalProperties};

fn main() {
    divan::main();
}

/// 300 radii, 0.1 mm apart: the paper's r ≤ 300 px at 0.1 mm/px.
fn radii() -> Vec<f64> {
    (1..=300).map(|i| 0.1 * i as f64).collect()
}

#[divan::bench(name = "dipole Rd(r) + derivatives, 300 radii")]
fn dipole_profile_with_derivatives(bencher: Bencher) {
    let radii = radii();
    let props = OpticalProperties::new(1.979, 0.0496, 1.2886).unwrap();
    bencher.bench_local(|| {
        let dipole = Dipole::new(black_box(&props));
        let mut acc = 0.0;
        for s in dipole.profile_with_derivatives(&radii) {
            acc += s.rd + s.d_sigma_s_prime + s.d_sigma_a;
        }
        black_box(acc)
    });
}

#[divan::bench(name = "dipole Rd(r) + derivatives, 300 radii, blocked")]
fn dipole_profile_with_derivatives_blocked(bencher: Bencher) {
    use scatterfit_optics::dipole::ProfileSample;
    let radii = radii();
    let props = OpticalProperties::new(1.979, 0.0496, 1.2886).unwrap();
    let mut out = vec![
        ProfileSample {
            rd: 0.0,
            d_sigma_s_prime: 0.0,
            d_sigma_a: 0.0
        };
        radii.len()
    ];
    bencher.bench_local(|| {
        let dipole = Dipole::new(black_box(&props));
        dipole.profile_with_derivatives_into(&radii, &mut out);
        black_box(&out);
    });
}

#[divan::bench(name = "dipole Rd(r), 300 radii")]
fn dipole_profile(bencher: Bencher) {
    let radii = radii();
    let props = OpticalProperties::new(1.979, 0.0496, 1.2886).unwrap();
    bencher.bench_local(|| {
        let dipole = Dipole::new(black_box(&props));
        black_box(radii.iter().map(|&r| dipole.rd(r)).sum::<f64>())
    });
}

#[divan::bench(name = "albedo inversion α′(Rd, η)", args = [0.05, 0.5, 0.95])]
fn albedo_inversion(bencher: Bencher, rd: f64) {
    bencher.bench_local(|| albedo_from_rd(black_box(rd), black_box(1.3)).unwrap());
}

#[divan::bench(name = "closed-form total Rd(α′, η)")]
fn total(bencher: Bencher) {
    bencher.bench_local(|| rd_total(black_box(0.97), black_box(1.3)));
}

/// Every forward model through `ModelFamily::eval` (what the fit calls): Rd(r) + both derivatives at
/// the 300 radii, model construction included (one Levenberg–Marquardt iteration's model work).
#[divan::bench(
    name = "model Rd(r) + derivatives, 300 radii",
    args = [DiffusionModel::Dipole, DiffusionModel::BetterDipole, DiffusionModel::Pbd]
)]
fn model_profile_with_derivatives(bencher: Bencher, model: DiffusionModel) {
    use scatterfit_optics::ProfileSample;
    let radii = radii();
    let props = OpticalProperties::new(1.979, 0.0496, 1.2886).unwrap();
    let mut out = vec![ProfileSample::ZERO; radii.len()];
    bencher.bench_local(|| {
        model.eval(black_box(&props), &radii, &mut out);
        black_box(&out);
    });
}

/// Every diffusion model's Rd(r) without derivatives at the 300 radii.
#[divan::bench(
    name = "model Rd(r), 300 radii",
    args = [DiffusionModel::Dipole, DiffusionModel::BetterDipole, DiffusionModel::Pbd]
)]
fn model_profile(bencher: Bencher, model: DiffusionModel) {
    let radii = radii();
    let props = OpticalProperties::new(1.979, 0.0496, 1.2886).unwrap();
    bencher.bench_local(|| {
        let m = model.profile(black_box(&props)).unwrap();
        black_box(radii.iter().map(|&r| m.rd(r)).sum::<f64>())
    });
}

/// Total Rd(α′, η, g = 0) per model (closed form for the dipoles, quadrature for PBD).
#[divan::bench(
    name = "model total Rd(α′, η)",
    args = [DiffusionModel::Dipole, DiffusionModel::BetterDipole, DiffusionModel::Pbd]
)]
fn model_total(bencher: Bencher, model: DiffusionModel) {
    bencher.bench_local(|| {
        model
            .rd_total(black_box(0.97), black_box(1.3), 0.0)
            .unwrap()
    });
}

/// α′(Rd = 0.5, η = 1.3) per model (bracketed root finding on the totals).
#[divan::bench(
    name = "model albedo inversion α′(0.5, 1.3)",
    args = [DiffusionModel::Dipole, DiffusionModel::BetterDipole, DiffusionModel::Pbd]
)]
fn model_inversion(bencher: Bencher, model: DiffusionModel) {
    bencher.bench_local(|| {
        model
            .albedo_from_rd(black_box(0.5), black_box(1.3), 0.0)
            .unwrap()
    });
}
