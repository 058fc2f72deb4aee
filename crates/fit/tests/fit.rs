//! Tests of the profile fit: the Jacobian against finite differences, recovery of known parameters
//! from automatic and from bad starts, the cost of ignoring the light spot, detection limits, flat
//! directions, and the proposed method on MCML's independent profiles.

use scatterfit_fit::{
    ChannelInput, FitError, FitOptions, Method, ProfileData, Ring, RingSelection, Spot, Start,
    fit_channel,
};
use scatterfit_optics::dipole::Dipole;
use scatterfit_optics::{DiffusionModel, OpticalProperties};

/// Disk average of the dipole over a uniform spot of radius `a` centred `r` away, by brute-force
/// midpoint quadrature in polar coordinates around the spot centre — independent of the fit
/// crate's arc-length kernel.
fn dipole_disk(d: &Dipole, r: f64, a: f64) -> f64 {
    let (nr, nphi) = (120, 240);
    let mut sum = 0.0;
    for i in 0..nr {
        let rho = a * (i as f64 + 0.5) / nr as f64;
        for j in 0..nphi {
            let phi = std::f64::consts::PI * (j as f64 + 0.5) / nphi as f64;
            let dist = (r * r + rho * rho - 2.0 * r * rho * phi.cos())
                .max(0.0)
                .sqrt();
            sum += d.rd(dist) * rho;
        }
    }
    2.0 * sum * (a / nr as f64) * (std::f64::consts::PI / nphi as f64)
        / (std::f64::consts::PI * a * a)
}

/// A noise-free profile of `values` on 1-px rings of `mm_per_px`, 1 % relative errors.
fn profile(r: &[f64], values: &[f64]) -> ProfileData {
    ProfileData::new(
        r.iter()
            .zip(values)
            .map(|(&r_mm, &v)| Ring {
                r_mm,
                value: v,
                stderr: 0.01 * v,
                count: 100,
                detection_limit: 0.0,
            })
            .collect(),
    )
    .unwrap()
}

fn radii(mm_per_px: f64, rings: usize) -> Vec<f64> {
    (0..rings).map(|i| (i as f64 + 0.5) * mm_per_px).collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// Materials of Choi et al. 2014 Table 1 (one channel each) spanning the paper's range.
const CASES: [(f64, f64, f64); 5] = [
    (1.979, 0.000792, 1.2886), // pink plastic R
    (1.742, 0.090597, 1.9432), // blue coating G
    (1.113, 0.428075, 1.2391), // brown leather B
    (1.439, 0.066138, 1.0777), // nephrite R
    (0.7498, 0.558, 2.4102),   // red aluminum B
];

/// Noise-free data from the spot-convolved dipole (brute force): the proposed and the existing
/// method both recover the parameters from the automatic start.
#[test]
fn recovers_known_parameters_with_the_spot() {
    let r = radii(0.05, 300);
    for (sp, sa, eta) in CASES {
        let truth = OpticalProperties::new(sp, sa, eta).unwrap();
        let d = Dipole::new(&truth);
        let y: Vec<f64> = r.iter().map(|&r| 7.0 * dipole_disk(&d, r, 0.5)).collect();
        let data = profile(&r, &y);
        let input = ChannelInput {
            eta,
            albedo_prime: Some(truth.albedo_prime()),
            rd_total: Some(d.rd_total()),
        };
        for method in [Method::Proposed, Method::Existing] {
            let rep = fit_channel(
                &data,
                &input,
                &DiffusionModel::Dipole,
                &FitOptions::new(method),
            )
            .unwrap();
            assert!(rep.converged, "{method:?} {sp}: {}", rep.termination);
            assert!(
                rel(rep.sigma_s_prime.value, sp) < 2e-3,
                "{method:?} σ′s {} vs {sp}",
                rep.sigma_s_prime.value
            );
            // σa of a nearly transparent channel is constrained only loosely by the existing method.
            let tol = if method == Method::Existing && sa < 0.01 {
                0.05
            } else {
                5e-3
            };
            assert!(
                rel(rep.sigma_a.value, sa) < tol,
                "{method:?} σa {} vs {sa}",
                rep.sigma_a.value
            );
            assert!(rel(rep.scale.value, 7.0) < 5e-3, "k {}", rep.scale.value);
            assert!(rep.rings_inside_spot == 20, "1 mm of 0.05 mm rings");
        }
        // Normalised with the spectrophotometer: k from the flux, σ′s alone.
        let mut opts = FitOptions::new(Method::Proposed);
        opts.normalise_with_spectro = true;
        let rep = fit_channel(&data, &input, &DiffusionModel::Dipole, &opts).unwrap();
        assert!(rep.converged && rel(rep.sigma_s_prime.value, sp) < 2e-3);
        assert!(rel(rep.scale.value, 7.0) < 5e-3);
    }
}

/// Starts off by 10× either way (σ′s, σa and k) converge to the same solution.
#[test]
fn converges_from_starts_off_by_ten() {
    let r = radii(0.05, 300);
    for (sp, sa, eta) in CASES {
        let truth = OpticalProperties::new(sp, sa, eta).unwrap();
        let d = Dipole::new(&truth);
        let y: Vec<f64> = r.iter().map(|&r| 3.0 * d.rd(r)).collect();
        let data = profile(&r, &y);
        let input = ChannelInput {
            eta,
            albedo_prime: Some(truth.albedo_prime()),
            rd_total: None,
        };
        for method in [Method::Proposed, Method::Existing] {
            for f in [0.1, 10.0] {
                let mut opts = FitOptions::new(method);
                opts.spot = Spot::Point;
                opts.start = Some(Start {
                    sigma_s_prime: sp * f,
                    sigma_a: Some(sa * f),
                    scale: Some(3.0 / f),
                });
                let rep = fit_channel(&data, &input, &DiffusionModel::Dipole, &opts).unwrap();
                assert!(rep.converged, "{method:?} ×{f} {sp}: {}", rep.termination);
                assert!(
                    rel(rep.sigma_s_prime.value, sp) < 1e-4,
                    "{method:?} ×{f}: σ′s {} vs {sp}",
                    rep.sigma_s_prime.value
                );
                assert!(
                    rel(rep.sigma_a.value, sa) < 2e-3,
                    "{method:?} ×{f}: σa {} vs {sa}",
                    rep.sigma_a.value
                );
            }
        }
    }
}

/// The analytic Jacobian the solver uses agrees with central finite differences of the residuals,
/// for every method, with and without the spot convolution (checked through the public fit: the
/// standard errors come from the Jacobian, so compare them with errors from a finite-difference
/// Jacobian of the weighted residuals built here).
#[test]
fn standard_errors_match_a_finite_difference_jacobian() {
    let r = radii(0.1, 150);
    let (sp, sa, eta) = (1.2, 0.05, 1.4);
    let truth = OpticalProperties::new(sp, sa, eta).unwrap();
    let d = Dipole::new(&truth);
    // Deterministic ±2 % "noise" so χ² is not zero (the errors are scaled by it when > 1).
    let y: Vec<f64> = r
        .iter()
        .enumerate()
        .map(|(i, &r)| 4.0 * d.rd(r) * (1.0 + 0.02 * ((i * 7919 % 13) as f64 / 6.0 - 1.0)))
        .collect();
    let data = profile(&r, &y);
    let input = ChannelInput {
        eta,
        albedo_prime: Some(truth.albedo_prime()),
        rd_total: None,
    };
    let mut opts = FitOptions::new(Method::Existing);
    opts.spot = Spot::Point;
    let rep = fit_channel(&data, &input, &DiffusionModel::Dipole, &opts).unwrap();
    assert!(rep.converged);
    // Residuals of x = (ln σ′s, ln σa, ln k) built from Dipole::rd, differentiated numerically.
    let used: Vec<usize> = rep.fitted.iter().map(|f| f.index).collect();
    let resid = |x: [f64; 3]| -> Vec<f64> {
        let p = OpticalProperties::new(x[0].exp(), x[1].exp(), eta).unwrap();
        let dd = Dipole::new(&p);
        used.iter()
            .map(|&i| (x[2] + dd.rd(r[i]).ln() - y[i].ln()) / 0.01)
            .collect()
    };
    let x = [
        rep.sigma_s_prime.value.ln(),
        rep.sigma_a.value.ln(),
        rep.scale.value.ln(),
    ];
    let mut jtj = [[0.0; 3]; 3];
    let cols: Vec<Vec<f64>> = (0..3)
        .map(|a| {
            let (mut xp, mut xm) = (x, x);
            xp[a] += 1e-6;
            xm[a] -= 1e-6;
            resid(xp)
                .iter()
                .zip(resid(xm))
                .map(|(p, m)| (p - m) / 2e-6)
                .collect()
        })
        .collect();
    for a in 0..3 {
        for b in 0..3 {
            jtj[a][b] = cols[a].iter().zip(&cols[b]).map(|(u, v)| u * v).sum();
        }
    }
    let chi2: f64 = resid(x).iter().map(|e| e * e).sum::<f64>() / (used.len() - 3) as f64;
    // Invert the 3×3 by cofactors.
    let m = jtj;
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let inv00 = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det;
    let inv11 = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
    let s = chi2.max(1.0);
    let sd_sp = rep.sigma_s_prime.value * (inv00 * s).sqrt();
    let sd_sa = rep.sigma_a.value * (inv11 * s).sqrt();
    assert!(
        rel(rep.sigma_s_prime.stderr, sd_sp) < 1e-4,
        "{} vs {sd_sp}",
        rep.sigma_s_prime.stderr
    );
    assert!(
        rel(rep.sigma_a.stderr, sd_sa) < 1e-4,
        "{} vs {sd_sa}",
        rep.sigma_a.stderr
    );
    assert!(rel(rep.chi2_reduced, chi2) < 1e-6);
}

/// What ignoring the spot costs: on data from a 1 mm spot, a point-source model fitted from one
/// spot diameter out misses σ′s by several per cent where the disk model is exact. Measured here
/// and stated, not hidden.
#[test]
fn ignoring_the_spot_biases_sigma_s() {
    let r = radii(0.05, 300);
    let mut worst_point: f64 = 0.0;
    for (sp, sa, eta) in CASES {
        let truth = OpticalProperties::new(sp, sa, eta).unwrap();
        let d = Dipole::new(&truth);
        let y: Vec<f64> = r.iter().map(|&r| dipole_disk(&d, r, 0.5)).collect();
        let data = profile(&r, &y);
        let input = ChannelInput {
            eta,
            albedo_prime: Some(truth.albedo_prime()),
            rd_total: None,
        };
        let disk = fit_channel(
            &data,
            &input,
            &DiffusionModel::Dipole,
            &FitOptions::new(Method::Proposed),
        )
        .unwrap();
        let mut opts = FitOptions::new(Method::Proposed);
        opts.spot = Spot::Point;
        let point = fit_channel(&data, &input, &DiffusionModel::Dipole, &opts).unwrap();
        assert!(rel(disk.sigma_s_prime.value, sp) < 2e-3);
        worst_point = worst_point.max(rel(point.sigma_s_prime.value, sp));
    }
    assert!(
        worst_point > 0.02,
        "a point model on a 1 mm spot should visibly bias σ′s (got {worst_point})"
    );
}

/// Rings under the detection limit are excluded and counted. Emulate the far field of an absorbing
/// channel where the bracket reads its noise floor (a constant at the limit) instead of the signal:
/// fitted as values, those rings bias σa; excluded, the fit is exact.
#[test]
fn rings_below_detection_are_excluded_not_fitted() {
    let r = radii(0.05, 300);
    let (sp, sa, eta) = (1.113, 0.428075, 1.2391);
    let truth = OpticalProperties::new(sp, sa, eta).unwrap();
    let d = Dipole::new(&truth);
    let limit = 1e-4 * dipole_disk(&d, 1.0, 0.5);
    let rings: Vec<Ring> = r
        .iter()
        .map(|&rr| {
            let v = dipole_disk(&d, rr, 0.5);
            let measured = if v < limit { 0.5 * limit } else { v };
            Ring {
                r_mm: rr,
                value: measured,
                stderr: 0.01 * measured,
                count: 100,
                detection_limit: limit,
            }
        })
        .collect();
    let data = ProfileData::new(rings).unwrap();
    let input = ChannelInput {
        eta,
        albedo_prime: None,
        rd_total: None,
    };
    let opts = FitOptions::new(Method::Existing);
    let rep = fit_channel(&data, &input, &DiffusionModel::Dipole, &opts).unwrap();
    assert!(
        rep.rings_below_detection > 50,
        "{}",
        rep.rings_below_detection
    );
    assert!(rel(rep.sigma_a.value, sa) < 5e-3, "{}", rep.sigma_a.value);
    let mut blind = opts;
    blind.selection = blind.selection.with_detection_factor(0.0).unwrap();
    let biased = fit_channel(&data, &input, &DiffusionModel::Dipole, &blind).unwrap();
    assert_eq!(biased.rings_below_detection, 0);
    assert!(
        rel(biased.sigma_a.value, sa) > 0.05,
        "fitting the noise floor should bias σa: {}",
        biased.sigma_a.value
    );
}

/// A profile with signal only inside the spot cannot be fitted: a typed error that says so.
#[test]
fn signal_only_inside_the_spot_is_refused() {
    let r = radii(0.05, 300);
    let truth = OpticalProperties::new(1.0, 2.0, 1.3).unwrap();
    let d = Dipole::new(&truth);
    let rings: Vec<Ring> = r
        .iter()
        .map(|&rr| Ring {
            r_mm: rr,
            value: d.rd(rr),
            stderr: 0.01 * d.rd(rr),
            count: 100,
            detection_limit: d.rd(0.9),
        })
        .collect();
    let err = fit_channel(
        &ProfileData::new(rings).unwrap(),
        &ChannelInput {
            eta: 1.3,
            albedo_prime: Some(1.0 / 3.0),
            rd_total: None,
        },
        &DiffusionModel::Dipole,
        &FitOptions::new(Method::Proposed),
    )
    .unwrap_err();
    assert!(matches!(err, FitError::TooFewRings { .. }), "{err}");
    assert!(err.to_string().contains("inside the light spot"), "{err}");
}

/// A flat direction: in the far field the dipole's shape depends on σtr alone, so a profile
/// measured only there (here 8–10 mm) cannot separate σ′s from σa. The existing method reports
/// them unconstrained instead of printing numbers with small error bars.
#[test]
fn a_flat_direction_is_reported_unconstrained() {
    let r: Vec<f64> = (0..40).map(|i| 8.0 + 0.05 * i as f64).collect();
    let truth = OpticalProperties::new(1.5, 0.05, 1.3).unwrap();
    let d = Dipole::new(&truth);
    let y: Vec<f64> = r.iter().map(|&r| d.rd(r)).collect();
    let mut opts = FitOptions::new(Method::Existing);
    opts.spot = Spot::Point;
    let rep = fit_channel(
        &profile(&r, &y),
        &ChannelInput {
            eta: 1.3,
            albedo_prime: None,
            rd_total: None,
        },
        &DiffusionModel::Dipole,
        &opts,
    )
    .unwrap();
    assert!(!rep.is_measurement());
    assert!(
        !rep.unconstrained.is_empty(),
        "σ′s/σa separated from 2 mm of far field? {:?} ± {:?}",
        rep.sigma_s_prime,
        rep.sigma_a
    );
}

/// MCML's independent profiles (docs/physics.md §4.5, `data/reference/mcml_profiles.csv`): the
/// paper's proposed method with the dipole, given the exact α′, on exact transport where diffusion
/// should hold best (α′ ≥ 0.99, η ≤ 1.4), fitted from one mean free path to 15 mean free paths. The
/// fit converges to the right neighbourhood, but the dipole's shape is not exact transport's: σ′s
/// is biased low by 7–14 % (BENCHMARKS.md, "The dipole on exact transport"), within the 20 % band
/// reported for the paper's method at these albedos, and the misfit shows in χ².
#[test]
fn proposed_method_on_mcml_profiles() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/reference/mcml_profiles.csv"
    );
    let text = std::fs::read_to_string(path).unwrap();
    for (eta, alpha) in [(1.0, 0.99), (1.0, 0.999), (1.4, 0.99), (1.4, 0.999)] {
        let rows: Vec<(f64, f64)> = text
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("eta"))
            .filter_map(|l| {
                let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
                (f[0] == eta && f[1] == alpha).then_some((f[4], f[5]))
            })
            .collect();
        assert_eq!(rows.len(), 400);
        // Skip the last bin (it collects everything beyond 20 mm); Poisson-like bin errors.
        let rings: Vec<Ring> = rows[..rows.len() - 1]
            .iter()
            .map(|&(r, v)| {
                let n = 2e6 * 2.0 * std::f64::consts::PI * r * 0.05 * v;
                Ring {
                    r_mm: r,
                    value: v,
                    stderr: v / n.max(1.0).sqrt(),
                    count: 100,
                    detection_limit: 0.0,
                }
            })
            .collect();
        let mut opts = FitOptions::new(Method::Proposed);
        opts.spot = Spot::Point;
        opts.selection =
            RingSelection::new(1.0, 15.0, 1.0, RingSelection::DEFAULT_ERROR_FLOOR).unwrap();
        let rep = fit_channel(
            &ProfileData::new(rings).unwrap(),
            &ChannelInput {
                eta,
                albedo_prime: Some(alpha),
                rd_total: None,
            },
            &DiffusionModel::Dipole,
            &opts,
        )
        .unwrap();
        assert!(rep.converged, "{}", rep.termination);
        assert!(
            rep.chi2_reduced > 2.0,
            "the dipole's misfit on exact transport"
        );
        let err = rel(rep.sigma_s_prime.value, alpha);
        assert!(
            err < 0.2,
            "η {eta} α′ {alpha}: σ′s {} vs {alpha} ({:.1} %)",
            rep.sigma_s_prime.value,
            100.0 * err
        );
    }
}
