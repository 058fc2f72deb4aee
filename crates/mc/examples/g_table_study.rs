//! Measurements behind the anisotropic (g ≠ 0) `mc` tables (BENCHMARKS.md, "Anisotropic white
//! tables"). Every comparison is in reduced units: ρ′ = σ′t r, α′ = σ′s/σ′t, R′(ρ′) = Rd(r)/σ′t².
//!
//! ```text
//! cargo run --release -p scatterfit-mc --example g_table_study -- cost ETA PHOTONS G...
//! cargo run --release -p scatterfit-mc --example g_table_study -- noise ETA G PHOTONS
//! cargo run --release -p scatterfit-mc --example g_table_study -- compare TABLE_A TABLE_B [TABLE_C]
//! ```
//! * `cost`: interactions per photon in each path-length stratum of a white run ([`g_spec`]'s layout)
//!   at each g, and the build's interactions per full-length photon.
//! * `noise`: two tables from independent seeds; the RMS of their relative difference / √2 over ρ′
//!   windows and the totals' difference (one table's model noise).
//! * `compare`: tables as JSON files (from `build_g_tables`). With two tables of one g: their noise as
//!   above. With three (g₀ < g_mid < g₁, one η): the error of interpolating in g (linear in g between
//!   g₀ and g₁ at fixed α′, ρ′, on ln R′) against the g_mid table, and of the totals (the same
//!   for a ratio to the g = 0 table, which does not depend on g). With three tables of one g at
//!   η₀ < η_mid < η₁: the error of interpolating in η likewise. With five (four g nodes, then a
//!   table between the middle two): the error of Catmull-Rom in g (pbrt's non-uniform weights) on
//!   ln R′ and on the totals. With one table: the size of the
//!   g-correction, R′_g/R′₀ − 1 against the shipped g = 0 table at the same η, by ρ′ window (RMS),
//!   and of the totals.

#[path = "common/g_tables_layout.rs"]
mod layout;

use layout::g_spec;
use scatterfit_mc::model::{McProfile, McTable, McTableSet};
use scatterfit_mc::white::{Stratum, WhiteSpec, simulate};
use scatterfit_optics::{OpticalProperties, ProfileModel};

const ALBEDOS: [f64; 8] = [0.3, 0.5, 0.7, 0.9, 0.97, 0.99, 0.999, 0.9999];
const WINDOWS: [(f64, f64); 6] = [
    (0.3, 1.0),
    (1.0, 3.0),
    (3.0, 10.0),
    (10.0, 20.0),
    (20.0, 35.0),
    (35.0, 50.0),
];

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let num = |i: usize| -> f64 { args[i].parse().expect("a number") };
    match args.get(1).map(String::as_str) {
        Some("cost") => {
            let eta = num(2);
            let photons = num(3) as u64;
            for i in 4..args.len() {
                cost(eta, num(i), photons);
            }
        }
        Some("noise") => {
            let (eta, g, photons) = (num(2), num(3), num(4) as u64);
            let mut sets = Vec::new();
            for seed in [11, 12] {
                let mut spec = g_spec(eta, g, photons);
                spec.seed = seed;
                let t0 = std::time::Instant::now();
                let t = McTable::build(&spec, &|_, _| {}).expect("table");
                println!("seed {seed}: {:.1} s", t0.elapsed().as_secs_f64());
                sets.push(McTableSet::new(vec![t]).expect("set"));
            }
            noise(&sets[0], &sets[1]);
        }
        Some("compare") => {
            let sets: Vec<McTableSet> = args[2..]
                .iter()
                .map(|p| {
                    let t = McTable::load(std::path::Path::new(p)).expect("table file");
                    McTableSet::new(vec![t]).expect("set")
                })
                .collect();
            if sets.len() == 1 {
                ratio(&sets[0]);
            } else if sets.len() == 2 {
                noise(&sets[0], &sets[1]);
            } else if sets.len() == 3 {
                interpolation(&sets[0], &sets[1], &sets[2]);
            } else {
                catmull_rom_in_g(&sets[..4], &sets[4]);
            }
        }
        _ => eprintln!("usage: g_table_study cost|noise|compare …"),
    }
}

/// Interactions per photon in each stratum of [`g_spec`]'s white run at (η, g), `photons` per stratum.
fn cost(eta: f64, g: f64, photons: u64) {
    let spec = g_spec(eta, g, photons).white().expect("white spec");
    let mut line = format!("η {eta} g {g}: interactions/photon by stratum");
    let mut per = Vec::new();
    for s in &spec.strata {
        // A run of this stratum alone (scores are irrelevant here, only the cost).
        let one = WhiteSpec {
            strata: vec![Stratum {
                photons,
                max_interactions: s.max_interactions,
            }],
            ..spec.clone()
        };
        let t0 = std::time::Instant::now();
        let tally = simulate(&one, &|_| {}).expect("white run");
        let n = tally.interactions as f64 / photons as f64;
        per.push(n);
        line += &format!(
            " | n < {}: {:.1} ({:.2} µs/photon)",
            s.max_interactions,
            n,
            1e6 * t0.elapsed().as_secs_f64() / photons as f64
        );
    }
    // The build's strata are 16:4:1 photons: interactions per full-length photon.
    let per_full = 16.0 * per[0] + 4.0 * per[1] + per[2];
    println!("{line} | build: {per_full:.0} interactions per full-length photon");
}

/// Model at reduced albedo α′, η, σ′t = 1.
fn model(set: &McTableSet, ap: f64) -> Option<McProfile> {
    let eta = set.eta_range().0;
    McProfile::new(set, &OpticalProperties::new(ap, 1.0 - ap, eta).ok()?).ok()
}

/// RMS relative difference / √2 of two sets over ρ′ windows, per α′.
fn noise(a: &McTableSet, b: &McTableSet) {
    for ap in ALBEDOS {
        let (Some(m1), Some(m2)) = (model(a, ap), model(b, ap)) else {
            println!("α′ {ap}: outside the tables");
            continue;
        };
        let mut line = format!(
            "α′ {ap:<7} data to ρ′ {:6.1} | Rd {:.5} Δ/√2 {:+.1e} |",
            m1.r_data_max_mm(),
            m1.rd_total(),
            (m2.rd_total() - m1.rd_total()) / 2f64.sqrt()
        );
        line += &windows(
            |rho| (m1.rd(rho), m2.rd(rho) / m1.rd(rho) - 1.0),
            2f64.sqrt(),
        );
        println!("{line}");
    }
}

/// RMS over ρ′ windows of `f(ρ′) = (value, relative error)` divided by `div`, where the value is
/// above 1e-6 of its value at ρ′ = 0.5; also the largest |error| over [1, 20).
fn windows(f: impl Fn(f64) -> (f64, f64), div: f64) -> String {
    let near = f(0.5).0;
    let mut out = String::new();
    let mut worst: f64 = 0.0;
    for (lo, hi) in WINDOWS {
        let (mut s2, mut n) = (0.0, 0);
        let mut rho = lo;
        while rho < hi {
            let (v, e) = f(rho);
            if v > 1e-6 * near {
                s2 += (e / div).powi(2);
                n += 1;
                if (1.0..20.0).contains(&rho) {
                    worst = worst.max((e / div).abs());
                }
            }
            rho *= 1.01;
        }
        if n > 0 {
            out += &format!(" [{lo},{hi}) {:.3}%", 100.0 * (s2 / n as f64).sqrt());
        } else {
            out += &format!(" [{lo},{hi}) –");
        }
    }
    out + &format!(" | max [1,20) {:.3}%", 100.0 * worst)
}

/// Interpolation error: `lo`, `mid`, `hi` differ in g (one η) or in η (one g).
fn interpolation(lo: &McTableSet, mid: &McTableSet, hi: &McTableSet) {
    let (g0, gm, g1) = (lo.g(), mid.g(), hi.g());
    let (e0, em, e1) = (lo.eta_range().0, mid.eta_range().0, hi.eta_range().0);
    let in_g = g0 != g1;
    let t = if in_g {
        (gm - g0) / (g1 - g0)
    } else {
        (em - e0) / (e1 - e0)
    };
    println!(
        "interpolating in {} at t = {t:.3}: g {g0}/{gm}/{g1}, η {e0}/{em}/{e1}",
        if in_g { "g" } else { "η" }
    );
    for ap in ALBEDOS {
        let (Some(m0), Some(mm), Some(m1)) = (model(lo, ap), model(mid, ap), model(hi, ap)) else {
            println!("α′ {ap}: outside the tables");
            continue;
        };
        // Direct: R′ interpolated linearly (in g or η) on ln R′.
        let direct = |rho: f64| {
            let v = (1.0 - t) * m0.rd(rho).ln() + t * m1.rd(rho).ln();
            (mm.rd(rho), v.exp() / mm.rd(rho) - 1.0)
        };
        let tot = (1.0 - t) * m0.rd_total() + t * m1.rd_total();
        let mut line = format!("α′ {ap:<7} total: {:+.1e} | profile:", tot - mm.rd_total());
        line += &windows(direct, 1.0);
        println!("{line}");
    }
}

/// Size of the correction R′_g/R′₀ − 1 of one table against the shipped g = 0 tables.
fn ratio(set: &McTableSet) {
    let zero = scatterfit_mc::McTableSet::bundled().expect("bundled tables");
    let eta = set.eta_range().0;
    println!("g {} against g = 0 at η {eta}: R′_g/R′₀ − 1", set.g());
    for ap in ALBEDOS {
        let Some(m) = model(set, ap) else {
            continue;
        };
        let z = McProfile::new(
            &zero,
            &OpticalProperties::new(ap, 1.0 - ap, eta).expect("props"),
        )
        .expect("g = 0 model");
        let mut line = format!(
            "α′ {ap:<7} total {:.5} vs {:.5} ({:+.2}%) |",
            m.rd_total(),
            z.rd_total(),
            100.0 * (m.rd_total() / z.rd_total() - 1.0)
        );
        line += &windows(|rho| (m.rd(rho), m.rd(rho) / z.rd(rho) - 1.0), 1.0);
        println!("{line}");
    }
}

/// Catmull-Rom in g over four tables (g₀ < g₁ < g₂ < g₃, one η) against a table at g₁ < g < g₂.
fn catmull_rom_in_g(nodes: &[McTableSet], mid: &McTableSet) {
    let x: Vec<f64> = nodes.iter().map(McTableSet::g).collect();
    let g = mid.g();
    // pbrt-v4 CatmullRomWeights for non-uniform nodes.
    let t = (g - x[1]) / (x[2] - x[1]);
    let (t2, t3) = (t * t, t * t * t);
    let mut w = [0.0, 2.0 * t3 - 3.0 * t2 + 1.0, -2.0 * t3 + 3.0 * t2, 0.0];
    let w0 = (t3 - 2.0 * t2 + t) * (x[2] - x[1]) / (x[2] - x[0]);
    w[0] = -w0;
    w[2] += w0;
    let w3 = (t3 - t2) * (x[2] - x[1]) / (x[3] - x[1]);
    w[1] -= w3;
    w[3] = w3;
    println!("Catmull-Rom in g over {x:?} at g = {g}: weights {w:?}");
    for ap in ALBEDOS {
        let ms: Option<Vec<McProfile>> = nodes.iter().map(|s| model(s, ap)).collect();
        let (Some(ms), Some(mm)) = (ms, model(mid, ap)) else {
            println!("α′ {ap}: outside the tables");
            continue;
        };
        let tot: f64 = ms.iter().zip(w).map(|(m, wk)| wk * m.rd_total()).sum();
        let cr = |rho: f64| {
            let v: f64 = ms.iter().zip(w).map(|(m, wk)| wk * m.rd(rho).ln()).sum();
            (mm.rd(rho), v.exp() / mm.rd(rho) - 1.0)
        };
        println!(
            "α′ {ap:<7} total: {:+.1e} | profile:{}",
            tot - mm.rd_total(),
            windows(cr, 1.0)
        );
    }
}
