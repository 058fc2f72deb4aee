//! The spectrophotometer's uncertainty, propagated to η, α′, σ′s and σa by central differences
//! (`SpectroStage::uncertainty`, `fit::propagate_spectro`), checked against brute force: many
//! readings scaled by 1 + εz (z standard normal, fixed seed), each analysed and fitted from
//! scratch; the spread of what comes out must match the propagated standard errors. The sample
//! standard deviation of N draws has a relative standard error of 1/√(2(N − 1)); the tolerance is
//! four of those (plus 2 % for the first-order propagation's own error at ε = 0.5 %).

use std::path::Path;

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rand_xoshiro::Xoshiro256PlusPlus;
use scatterfit_fit::{ProfileData, Ring};
use scatterfit_optics::OpticalProperties;
use scatterfit_optics::dipole::Dipole;
use scatterfit_optics::spectro::{SpectroOptions, SpectroReading, analyse};
use scatterfit_optics::{AlbedoModel, Channel, DiffusionModel, Method, ModelName, Rgb};
use scatterfit_pipeline::fit::{fit_stage, propagate_spectro};
use scatterfit_pipeline::spectro::{SpectroStage, from_analysis};
use scatterfit_pipeline::{FitPlan, FitSettings};

const EPS: f64 = 0.005;
const DRAWS: usize = 400;

/// A smooth, coloured SCE spectrum (reddish, α′ ≈ 0.99 / 0.97 / 0.9 in R, G, B at η ≈ 1.4) with a
/// specular part of 0.03, scaled by `f`.
fn reading(f: f64) -> SpectroReading {
    let wl: Vec<f64> = (0..31).map(|i| 400.0 + 10.0 * f64::from(i)).collect();
    let sce: Vec<f64> = wl
        .iter()
        .map(|w| f * (0.18 + 0.42 / (1.0 + (-(w - 560.0) / 25.0).exp())))
        .collect();
    let sci: Vec<f64> = sce.iter().map(|s| s + f * 0.03).collect();
    SpectroReading::new(wl, sci, sce).unwrap()
}

fn stage(f: f64, repeatability: f64) -> SpectroStage {
    let analysis = analyse(&reading(f), &SpectroOptions::default()).unwrap();
    from_analysis(
        analysis,
        Path::new("test.csv"),
        repeatability,
        &DiffusionModel::Dipole,
    )
}

/// Sample standard deviation.
fn sd(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

fn tolerance() -> f64 {
    4.0 / (2.0 * (DRAWS as f64 - 1.0)).sqrt() + 0.02
}

fn draws() -> Vec<f64> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(20261122);
    let normal = Normal::new(0.0, 1.0).unwrap();
    (0..DRAWS)
        .map(|_| 1.0 + EPS * normal.sample(&mut rng))
        .collect()
}

#[test]
fn eta_and_albedo_errors_match_repeated_readings() {
    let nominal = stage(1.0, EPS);
    let u = &nominal.uncertainty;
    let (mut etas, mut albedos) = (Vec::new(), vec![Vec::new(); 3]);
    for f in draws() {
        let s = stage(f, 0.0);
        etas.push(s.eta);
        for (list, a) in albedos.iter_mut().zip(s.albedo_prime) {
            list.push(a.unwrap());
        }
    }
    let want = u.eta_stderr.unwrap();
    let got = sd(&etas);
    assert!(
        (got / want - 1.0).abs() < tolerance(),
        "η: spread {got:.3e} vs propagated {want:.3e}"
    );
    for (c, list) in albedos.iter().enumerate() {
        let want = u.albedo_prime_stderr[Channel::ALL[c]].unwrap();
        let got = sd(list);
        assert!(
            (got / want - 1.0).abs() < tolerance(),
            "α′ channel {c}: spread {got:.3e} vs propagated {want:.3e}"
        );
    }
    // A given η carries no uncertainty of its own; ε = 0 propagates nothing.
    let zero = stage(1.0, 0.0);
    assert_eq!(zero.uncertainty.eta_stderr, Some(0.0));
    assert!(
        zero.uncertainty
            .albedo_prime_stderr
            .iter()
            .all(|a| *a == Some(0.0))
    );
}

/// A profile of 240 rings (0.05 mm apart from 1 mm out) made from the dipole at the channel's α′
/// and η (the profile is held fixed: only the reading varies, which is what the propagation is
/// about), with 1 % ring errors.
fn profiles(s: &SpectroStage) -> Rgb<ProfileData> {
    Rgb::from_fn(|c| {
        let a = s.albedo_prime[c].unwrap();
        let sp = 1.5;
        let d = Dipole::new(&OpticalProperties::new(sp, sp * (1.0 / a - 1.0), s.eta).unwrap());
        let rings = (0..240)
            .map(|i| {
                let r = 1.0 + 0.05 * f64::from(i);
                let v = 100.0 * d.rd(r);
                Ring {
                    r_mm: r,
                    value: v,
                    stderr: 0.01 * v,
                    count: 100,
                    detection_limit: 0.0,
                }
            })
            .collect();
        ProfileData::new(rings).unwrap()
    })
}

#[test]
fn sigma_errors_match_refits_of_repeated_readings() {
    let settings = FitSettings {
        method: Method::Proposed,
        model: ModelName::Dipole,
        albedo_model: AlbedoModel::Diffusion,
        spot_radius_mm: 0.5,
        spot: scatterfit_pipeline::SpotShape::Disk,
        r_min_mm: Some(1.0),
        normalise_with_spectro: false,
        g: 0.0,
        g_prior: Default::default(),
    };
    let nominal = stage(1.0, EPS);
    let data = profiles(&nominal);
    let plan = FitPlan::new(settings).unwrap();
    let fits = fit_stage(&data, &nominal, &plan);
    let errors = propagate_spectro(&data, &nominal, &plan, &fits);
    let (mut sp, mut sa) = (vec![Vec::new(); 3], vec![Vec::new(); 3]);
    for f in draws() {
        let s = stage(f, 0.0);
        for (c, outcome) in fit_stage(&data, &s, &plan).iter().enumerate() {
            let r = outcome.report().unwrap();
            assert!(r.converged);
            sp[c].push(r.sigma_s_prime.value);
            sa[c].push(r.sigma_a.value);
        }
    }
    for c in 0..3 {
        let e = errors[Channel::ALL[c]].unwrap();
        for (name, want, got) in [
            ("σ′s", e.sigma_s_prime, sd(&sp[c])),
            ("σa", e.sigma_a, sd(&sa[c])),
        ] {
            assert!(want > 0.0, "{name} channel {c}");
            assert!(
                (got / want - 1.0).abs() < tolerance(),
                "{name} channel {c}: spread {got:.3e} vs propagated {want:.3e}"
            );
        }
    }
}
