//! Every forward model against exact transport: MCML's independent radial profiles
//! (`data/reference/mcml_profiles.csv`, docs/physics.md §4.5; σ′t = 1 mm⁻¹, g = 0, 2·10⁶ photons per case).
//! For each (η, α′): the median and largest |relative difference| of the model's bin average from
//! MCML over r ∈ [1, 20] mean free paths (bins whose MCML relative noise, 1/√(N·2πr·dr·Rd), is below
//! 10 %; the last bin, which collects everything beyond 20 mm, is skipped) and the relative difference
//! of the total diffuse reflectance. Prints a Markdown table.
//!
//! Run: `cargo run --release -p scatterfit-mc --example forward_models_vs_mcml -- MCML_CSV [TABLE_DIR]`
//! (the `mc` model from the tables in TABLE_DIR, else the shipped set).

use scatterfit_mc::model::{McProfile, McTableSet};
use scatterfit_optics::{DiffusionModel, ModelFamily, OpticalProperties, ProfileModel};

/// One MCML case: η, α′, total Rd and the (r, Rd(r)) bins.
struct Case {
    eta: f64,
    albedo: f64,
    total: f64,
    bins: Vec<(f64, f64)>,
}

fn read_cases(text: &str) -> Vec<Case> {
    let mut cases: Vec<Case> = Vec::new();
    for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let f: Vec<f64> = line
            .split(',')
            .map(|x| x.parse().expect("number"))
            .collect();
        match cases.last_mut() {
            Some(c) if c.eta == f[0] && c.albedo == f[1] => c.bins.push((f[4], f[5])),
            _ => cases.push(Case {
                eta: f[0],
                albedo: f[1],
                total: f[2],
                bins: vec![(f[4], f[5])],
            }),
        }
    }
    for c in &mut cases {
        c.bins.pop(); // the last bin holds every photon beyond 20 mm
    }
    cases
}

/// The model's average over the annulus [r − 0.025, r + 0.025] (4-point Gauss–Legendre in r).
fn bin_average(m: &dyn ProfileModel, r: f64) -> f64 {
    const GL4: [(f64, f64); 4] = [
        (-0.861_136_311_594_053, 0.347_854_845_137_454),
        (-0.339_981_043_584_856, 0.652_145_154_862_546),
        (0.339_981_043_584_856, 0.652_145_154_862_546),
        (0.861_136_311_594_053, 0.347_854_845_137_454),
    ];
    let (a, b) = (r - 0.025, r + 0.025);
    let s: f64 = GL4
        .iter()
        .map(|&(x, w)| {
            let rr = 0.5 * (a + b) + 0.5 * (b - a) * x;
            w * 0.5 * (b - a) * 2.0 * std::f64::consts::PI * rr * m.rd(rr)
        })
        .sum();
    s / (std::f64::consts::PI * (b * b - a * a))
}

/// (median |Δ|, max |Δ|, bins) over r ∈ [1, 20] and the total's relative difference.
fn distance(m: &dyn ProfileModel, c: &Case) -> (f64, f64, usize, f64) {
    let mut d: Vec<f64> = c
        .bins
        .iter()
        .filter(|&&(r, v)| {
            (1.0..=20.0).contains(&r)
                && v > 0.0
                && 1.0 / (2e6 * 2.0 * std::f64::consts::PI * r * 0.05 * v).sqrt() < 0.1
        })
        .map(|&(r, v)| (bin_average(m, r) / v - 1.0).abs())
        .collect();
    d.sort_by(f64::total_cmp);
    let n = d.len();
    let med = if n == 0 { f64::NAN } else { d[n / 2] };
    let max = d.last().copied().unwrap_or(f64::NAN);
    (med, max, n, m.rd_total() / c.total - 1.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cases = read_cases(&std::fs::read_to_string(&args[1]).expect("read MCML csv"));
    let mc = match args.get(2) {
        Some(dir) => {
            let mut tables = Vec::new();
            for e in std::fs::read_dir(dir).expect("table dir") {
                let p = e.expect("entry").path();
                if p.extension().is_some_and(|x| x == "json") {
                    tables.push(scatterfit_mc::McTable::load(&p).expect("table"));
                }
            }
            McTableSet::new(tables).ok()
        }
        None => McTableSet::bundled().ok(),
    };
    println!("| η | α′ | model | median \\|Δ\\| r ∈ [1, 20] | max \\|Δ\\| | bins | total Rd Δ |");
    println!("|---|---|---|---|---|---|---|");
    for c in &cases {
        let p = OpticalProperties::new(c.albedo, 1.0 - c.albedo, c.eta).expect("props");
        let mut models: Vec<(String, Box<dyn ProfileModel>)> = DiffusionModel::ALL
            .iter()
            .map(|m| (m.name().to_string(), m.profile(&p).expect("model")))
            .collect();
        if let Some(set) = &mc
            && let Ok(m) = McProfile::new(set, &p)
        {
            models.push(("mc".to_owned(), Box::new(m)));
        }
        for (name, m) in &models {
            let (med, max, n, tot) = distance(m.as_ref(), c);
            println!(
                "| {} | {} | {name} | {:.1} % | {:.1} % | {n} | {:+.1} % |",
                c.eta,
                c.albedo,
                100.0 * med,
                100.0 * max,
                100.0 * tot
            );
        }
    }
}
