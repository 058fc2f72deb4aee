//! The tracer at g ≠ 0 against independent references (issue 15): adding-doubling totals of
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
