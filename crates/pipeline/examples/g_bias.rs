//! What assuming g = 0 costs on anisotropic media, and what the g-aware `mc` model gives back
//! (BENCHMARKS.md, "The `mc` model over g"): MCML's profiles at g = 0.8 and 0.9
//! (`data/reference/mcml_profiles_g.csv`, σ′t = 1 mm⁻¹, pencil beam) as the camera's rings
//! (1–15 mm, the rig's span from the spot's edge to 300 px at 0.05 mm), adding-doubling's total
//! (`iad_totals_g.csv`) as the spectrophotometer's loss-free reading, measured with the proposed
//! method and `--model mc --albedo-model mc`: α′ inverted from Rd and σ′s fitted at an assumed g
//! (the family at that g, `scatterfit_optics::AtG`), once with g = 0 and once with the true g.
//!
//! ```text
//! cargo run -p scatterfit-pipeline --example g_bias
//! ```

use scatterfit_fit::{ChannelInput, FitOptions, Method, ProfileData, Ring, RingSelection, Spot};
use scatterfit_optics::{AtG, ModelFamily, ModelName};

fn main() {
    let mc = scatterfit_mc::family(ModelName::Mc).expect("mc tables");
    let mcml = include_str!("../../../data/reference/mcml_profiles_g.csv");
    let iad = include_str!("../../../data/reference/iad_totals_g.csv");
    println!("| g | η | α′ | assumed g | α′ from Rd | σ′s error | σa error |");
    println!("|---|---|---|---|---|---|---|");
    let mut summary: Vec<(f64, f64, f64)> = Vec::new();
    for g in [0.8, 0.9] {
        for eta in [1.0, 1.4, 2.0] {
            for ap in [0.5, 0.9, 0.99] {
                let rd = iad
                    .lines()
                    .filter(|l| !l.starts_with('#') && !l.starts_with('g'))
                    .map(|l| {
                        l.split(',')
                            .map(|x| x.parse().unwrap())
                            .collect::<Vec<f64>>()
                    })
                    .find(|v| (v[0], v[1], v[2]) == (g, eta, ap))
                    .map(|v| v[5])
                    .expect("adding-doubling row");
                let mut rings = Vec::new();
                for line in mcml.lines() {
                    if line.starts_with('#') || line.starts_with('g') {
                        continue;
                    }
                    let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
                    if (v[0], v[1], v[2]) != (g, eta, ap) {
                        continue;
                    }
                    let (lo, hi, value) = (v[6], v[7], v[8]);
                    // The ring's mean radius over its area.
                    let r = 2.0 / 3.0 * (hi.powi(3) - lo.powi(3)) / (hi * hi - lo * lo);
                    rings.push(Ring {
                        r_mm: r,
                        value,
                        stderr: f64::NAN,
                        count: 1,
                        detection_limit: 0.0,
                    });
                }
                let profile = ProfileData::new(rings).unwrap();
                for assumed in [0.0, g] {
                    let family = AtG::new(mc, assumed).unwrap();
                    let Ok(a) = family.albedo_from_rd(rd, eta, assumed) else {
                        println!("| {g} | {eta} | {ap} | {assumed} | Rd outside the tables |");
                        continue;
                    };
                    let mut opts = FitOptions::new(Method::Proposed);
                    opts.spot = Spot::Point;
                    opts.selection = RingSelection::new(1.0, 15.0, 1.0, 5e-3).unwrap();
                    let input = ChannelInput {
                        eta,
                        albedo_prime: Some(a),
                        rd_total: Some(rd),
                    };
                    let report =
                        scatterfit_fit::fit_channel(&profile, &input, &family, &opts).expect("fit");
                    let (sp, sa) = (ap, 1.0 - ap);
                    let e_sp = report.sigma_s_prime.value / sp - 1.0;
                    let e_sa = report.sigma_a.value / sa - 1.0;
                    summary.push((assumed, e_sp, e_sa));
                    println!(
                        "| {g} | {eta} | {ap} | {assumed} | {a:.5} | {:+.2} % | {:+.2} % |",
                        100.0 * e_sp,
                        100.0 * e_sa
                    );
                }
            }
        }
    }
    for assumed_zero in [true, false] {
        let mut sp: Vec<f64> = Vec::new();
        let mut sa: Vec<f64> = Vec::new();
        for &(a, e_sp, e_sa) in &summary {
            if (a == 0.0) == assumed_zero {
                sp.push(e_sp.abs());
                sa.push(e_sa.abs());
            }
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let worst = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
        println!(
            "assumed g {}: |σ′s error| median {:.2} %, worst {:.2} %; |σa error| median {:.2} %, worst {:.2} %",
            if assumed_zero { "0" } else { "= true g" },
            100.0 * median(&mut sp.clone()),
            100.0 * worst(&sp),
            100.0 * median(&mut sa.clone()),
            100.0 * worst(&sa)
        );
    }
}
