//! The tracer at g ≠ 0 against independent references: adding-doubling totals of
//! anisotropic half-spaces (`data/reference/iad_totals_g.csv`, iadpython 0.5.3) for the engine and for
//! the white run behind the `mc` tables, and MCML's own radial profiles and totals at g = 0.5–0.95
//! (`data/reference/mcml_profiles_g.csv`, original MCML C code). Fixed seeds; tolerances in standard
//! errors, the references' own uncertainty added (adding-doubling: twice the difference between its
//! two quadratures; MCML: its Monte Carlo noise).

use scatterfit_mc::white::{WhiteSpec, simulate};
use scatterfit_mc::{Beam, Layer, RadialGrid, Sample, Simulation};

/// One adding-doubling row: (g, η, α′) → (Rd, quadrature uncertainty).
struct AdRow {
    g: f64,
    eta: f64,
    albedo_prime: f64,
    rd: f64,
    rd_err: f64,
}

fn adding_doubling() -> Vec<AdRow> {
    include_str!("../../../data/reference/iad_totals_g.csv")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('g'))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            AdRow {
                g: v[0],
                eta: v[1],
                albedo_prime: v[2],
                rd: v[5],
                rd_err: 2.0 * (v[5] - v[7]).abs(),
            }
        })
        .collect()
}

fn find(rows: &[AdRow], g: f64, eta: f64, ap: f64) -> &AdRow {
    rows.iter()
        .find(|r| r.g == g && r.eta == eta && r.albedo_prime == ap)
        .expect("reference row")
}

/// A half-space at σ′t = 1 mm⁻¹ with reduced albedo α′ and asymmetry g.
fn half_space(g: f64, eta: f64, ap: f64) -> Sample {
    let layer = Layer::new(1.0 - ap, ap / (1.0 - g), g, eta, f64::INFINITY).unwrap();
    Sample::new(vec![layer], 1.0, 1.0).unwrap()
}

/// The engine's total diffuse reflectance of anisotropic half-spaces against adding-doubling within
/// 4 s.e. (⊕ the quadrature uncertainty), over g 0.5–0.95, η 1–2 and α′ 0.5–0.99 (photons chosen
/// for about 10⁷ interactions per case).
#[test]
fn engine_totals_match_adding_doubling() {
    let rows = adding_doubling();
    let cases = [
        (0.9, 1.4, 0.5, 120_000),
        (0.9, 1.4, 0.9, 25_000),
        (0.95, 1.0, 0.9, 15_000),
        (0.8, 2.0, 0.5, 60_000),
        (0.5, 2.0, 0.99, 12_000),
        (0.8, 1.0, 0.99, 6_000),
    ];
    for (g, eta, ap, photons) in cases {
        let r = Simulation::new(
            half_space(g, eta, ap),
            Beam::pencil(),
            RadialGrid::uniform(1.0, 4).unwrap(),
            photons,
            17,
        )
        .unwrap()
        .run();
        let want = find(&rows, g, eta, ap);
        eprintln!(
            "engine g {g} η {eta} α′ {ap}: {:.5} ± {:.5} vs {:.6}",
            r.rd_total.value, r.rd_total.stderr, want.rd
        );
        let tol = 4.0 * (r.rd_total.stderr.powi(2) + want.rd_err.powi(2)).sqrt();
        assert!(
            (r.rd_total.value - want.rd).abs() < tol,
            "g {g} η {eta} α′ {ap}: Rd {:.5} ± {:.5}, adding-doubling {:.6}",
            r.rd_total.value,
            r.rd_total.stderr,
            want.rd
        );
    }
}

/// The white run (one run for every albedo, the `mc` tables' engine) at g = 0.9, η = 1.4, strata as
/// the g ≠ 0 tables use them (bounds 64/(1 − g), 1024/(1 − g)): its totals at a(α′) for α′ = 0.5, 0.9,
/// 0.99 against adding-doubling within 4 s.e. ⊕ the quadrature uncertainty.
#[test]
fn white_run_totals_match_adding_doubling() {
    let rows = adding_doubling();
    for (g, eta) in [(0.9, 1.4), (0.5, 2.0)] {
        let aps = [0.5, 0.9, 0.99];
        let albedos: Vec<f64> = aps.iter().map(|&ap| ap / (1.0 - g + g * ap)).collect();
        let scale = 1.0 / (1.0 - g);
        let bounds = [(64.0 * scale) as u64, (1024.0 * scale) as u64];
        let spec = WhiteSpec::new(
            eta,
            g,
            albedos,
            vec![0.0, 1.0, 10.0],
            &[64_000, 8_000, 1_500],
            &bounds,
            5,
        )
        .unwrap();
        let tally = simulate(&spec, &|_| {}).unwrap();
        for (k, &ap) in aps.iter().enumerate() {
            let want = find(&rows, g, eta, ap);
            let se = tally.rd_total_stderr[k];
            eprintln!(
                "white g {g} η {eta} α′ {ap}: {:.5} ± {se:.5} vs {:.6}",
                tally.rd_total[k], want.rd
            );
            let tol = 4.0 * (se * se + want.rd_err.powi(2)).sqrt();
            assert!(
                (tally.rd_total[k] - want.rd).abs() < tol,
                "white g {g} η {eta} α′ {ap}: {:.5} ± {se:.5}, adding-doubling {:.6}",
                tally.rd_total[k],
                want.rd
            );
        }
    }
}

/// MCML's reflected weight per radial window for one case: (window edges [mm], Σ Rd·area over the
/// window's bins, MCML's photons, MCML's total Rd).
fn mcml_windows(g: f64, eta: f64, ap: f64, windows: &[f64]) -> (Vec<f64>, u64, f64) {
    let mut w = vec![0.0; windows.len() - 1];
    let (mut photons, mut total) = (0, 0.0);
    for line in include_str!("../../../data/reference/mcml_profiles_g.csv").lines() {
        if line.starts_with('#') || line.starts_with('g') {
            continue;
        }
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        if (v[0], v[1], v[2]) != (g, eta, ap) {
            continue;
        }
        photons = v[3] as u64;
        total = v[4];
        let (lo, hi, rd) = (v[6], v[7], v[8]);
        let area = std::f64::consts::PI * (hi * hi - lo * lo);
        if let Some(k) =
            (0..w.len()).find(|&k| lo >= windows[k] - 1e-9 && hi <= windows[k + 1] + 1e-9)
        {
            w[k] += rd * area;
        }
    }
    assert!(photons > 0, "no MCML profile for g {g} η {eta} α′ {ap}");
    (w, photons, total)
}

/// The engine's reflected fraction per radial window (0–0.5–1–2–5–10–19.75 mm at σ′t = 1 mm⁻¹) and
/// its total against MCML's at g = 0.5–0.95. Both codes score the same estimator (implicit capture,
/// the same roulette), so MCML's standard error is ours × √(N_ours/N_MCML); windows with more than
/// 20 % relative error are skipped. Within 4 combined standard errors.
#[test]
fn engine_profiles_match_mcml() {
    let windows = [0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 19.75];
    let cases = [
        (0.9, 1.4, 0.5, 100_000),
        (0.9, 1.4, 0.9, 20_000),
        (0.9, 1.0, 0.9, 20_000),
        (0.95, 1.4, 0.9, 10_000),
        (0.8, 2.0, 0.9, 20_000),
        (0.5, 1.4, 0.99, 8_000),
        (0.5, 1.0, 0.5, 100_000),
    ];
    for (g, eta, ap, photons) in cases {
        let (mcml, n_mcml, mcml_total) = mcml_windows(g, eta, ap, &windows);
        let r = Simulation::new(
            half_space(g, eta, ap),
            Beam::pencil(),
            RadialGrid::from_edges(windows.to_vec()).unwrap(),
            photons,
            23,
        )
        .unwrap()
        .run();
        let scale = (photons as f64 / n_mcml as f64).sqrt();
        for k in 0..windows.len() - 1 {
            let area = r.grid.area(k);
            let (ours, se) = (r.rd_profile[k].value * area, r.rd_profile[k].stderr * area);
            let se_all = se * (1.0 + scale * scale).sqrt();
            if ours <= 0.0 || se_all > 0.2 * ours {
                continue;
            }
            eprintln!(
                "g {g} η {eta} α′ {ap} [{}, {}) mm: ours {ours:.5} ± {se:.5}, MCML {:.5}",
                windows[k],
                windows[k + 1],
                mcml[k]
            );
            assert!(
                (ours - mcml[k]).abs() < 4.0 * se_all,
                "g {g} η {eta} α′ {ap} window {k}: {ours} ± {se_all} vs MCML {}",
                mcml[k]
            );
        }
        let se_t = r.rd_total.stderr * (1.0 + scale * scale).sqrt();
        assert!(
            (r.rd_total.value - mcml_total).abs() < 4.0 * se_t,
            "g {g} η {eta} α′ {ap}: total {:?} vs MCML {mcml_total}",
            r.rd_total
        );
    }
}
