//! Does the reported uncertainty cover the truth when g is not known? Quick-rig twins
//! (`RigSpec::quick`, fixed seeds) of six materials simulated by the Monte Carlo engine at each
//! Henyey–Greenstein g of the list (profile and spectrophotometer reading), written with a manifest
//! that does **not** state g, measured with `--model mc --albedo-model mc` as a user who does not
//! know g would: the values at g = 0 and the g term over the default range 0–0.95
//! (`scatterfit_pipeline::anisotropy`); then refitted with `[fit] g_range = [0, 0.95]` (the values
//! the middle of the estimates over the range). Per g: the median |error| of σ′s and σa against
//! the truth, and the fraction of channel values (σ′s and σa) with |value − truth| ≤ the total
//! uncertainty ((fit ⊕ spectro) + g, `Estimate::total`), beside the fraction ≤ fit ⊕ spectro
//! alone and ≤ fit ⊕ spectro ⊕ g (the g term in quadrature).
//!
//! ```text
//! nice -n 15 cargo run --release -p scatterfit-pipeline --example g_coverage [G,G,…] [MATERIAL,…]
//! ```

use scatterfit_io::manifest::FitSection;
use scatterfit_io::result_json::ChannelResult;
use scatterfit_lab::twin::{TwinFolder, write_twin_folder};
use scatterfit_optics::materials::by_name;
use scatterfit_optics::{AlbedoModel, Channel, Estimate, ModelName};
use scatterfit_pipeline::FitSettings;
use scatterfit_pipeline::anisotropy::GPrior;
use scatterfit_pipeline::{Overrides, measure_sample};
use scatterfit_synth::{RigSpec, synthesize};

/// One channel value against its truth.
struct Point {
    err: f64,
    /// The reported total, (fit ⊕ spectro) + g (`Estimate::total`).
    total: Option<f64>,
    without_g: Option<f64>,
    /// fit ⊕ spectro ⊕ g (the g term in quadrature, for comparison).
    quadrature: Option<f64>,
}

fn points(c: &ChannelResult, truth: [f64; 2]) -> Vec<Point> {
    [c.sigma_s_prime, c.sigma_a]
        .into_iter()
        .zip(truth)
        .filter_map(|(e, t)| {
            let e = e?;
            Some(Point {
                err: e.value / t - 1.0,
                total: e.total().map(|s| s / t),
                without_g: Estimate { g: None, ..e }.total().map(|s| s / t),
                quadrature: Estimate { g: None, ..e }
                    .total()
                    .map(|s| s.hypot(e.g.unwrap_or(0.0)) / t),
            })
        })
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn covered(p: &[Point], bar: impl Fn(&Point) -> Option<f64>) -> String {
    let inside = p
        .iter()
        .filter(|p| bar(p).is_some_and(|b| p.err.abs() <= b))
        .count();
    format!(
        "{inside}/{} ({:.0} %)",
        p.len(),
        100.0 * inside as f64 / p.len() as f64
    )
}

fn main() {
    let gs: Vec<f64> = std::env::args()
        .nth(1)
        .map_or(vec![0.0, 0.5, 0.8, 0.9], |a| {
            a.split(',').map(|g| g.parse().expect("G")).collect()
        });
    let materials: Vec<String> = std::env::args().nth(2).map_or_else(
        || {
            [
                "wood-tile",
                "nephrite",
                "brown-leather",
                "skin1",
                "skin2",
                "blue-coating",
            ]
            .map(String::from)
            .to_vec()
        },
        |a| a.split(',').map(String::from).collect(),
    );
    let dir = tempfile::tempdir().unwrap();
    println!(
        "| twin g | channels | median abs err σ′s / σa, values at g = 0 | covered by fit ⊕ spectro | \
         covered by (fit ⊕ spectro) + g | by fit ⊕ spectro ⊕ g | g_range 0–0.95: median abs err σ′s / σa | \
         covered + g | covered ⊕ g |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for &g in &gs {
        let mut rig = RigSpec::quick();
        rig.g = g;
        let (mut at0, mut mid) = (Vec::new(), Vec::new());
        let (mut e0, mut em) = ((Vec::new(), Vec::new()), (Vec::new(), Vec::new()));
        for (k, name) in materials.iter().enumerate() {
            let m = by_name(name).unwrap();
            let t = std::time::Instant::now();
            let s = synthesize(
                m.name,
                m.sigma_s_prime,
                m.sigma_a,
                m.eta,
                &rig,
                7 + k as u64,
                None,
                &|_, _, _| {},
            )
            .unwrap();
            let folder = dir.path().join(format!("{}-g{g}", m.name));
            // The user chose the exact model but does not know g: no g, no range.
            let fit = FitSection {
                model: Some(ModelName::Mc),
                albedo_model: Some(AlbedoModel::Mc),
                ..Default::default()
            };
            write_twin_folder(&folder, &s, &TwinFolder::new(fit, "g_coverage example")).unwrap();
            let t_synth = t.elapsed().as_secs_f64();
            let t = std::time::Instant::now();
            let measured = measure_sample(&folder, &Overrides::default(), &|_| {}).unwrap();
            let t_measure = t.elapsed().as_secs_f64();
            let ranged = measured
                .refit_with(FitSettings {
                    g: 0.8,
                    g_prior: GPrior {
                        g: None,
                        range: Some([0.0, 0.95]),
                        fit: false,
                    },
                    ..measured.settings
                })
                .unwrap();
            let (r0, rm) = (measured.to_result(None), ranged.to_result(None));
            for (c, ch) in Channel::ALL.iter().enumerate() {
                let truth = [m.sigma_s_prime[c], m.sigma_a[c]];
                let (a, b) = (&r0.channels[*ch], &rm.channels[*ch]);
                let (pa, pb) = (points(a, truth), points(b, truth));
                eprintln!(
                    "g {g} {name} {} α′ {:.4}: at 0 σ′s {:+.2} % σa {:+.2} % (total {:.2} / {:.2} %, g term {:?} / {:?}); \
                     range σ′s {:+.2} % σa {:+.2} % (total {:.2} / {:.2} %){}",
                    ch.name(),
                    m.albedo_prime()[c],
                    100.0 * pa.first().map_or(f64::NAN, |p| p.err),
                    100.0 * pa.get(1).map_or(f64::NAN, |p| p.err),
                    100.0 * pa.first().and_then(|p| p.total).unwrap_or(f64::NAN),
                    100.0 * pa.get(1).and_then(|p| p.total).unwrap_or(f64::NAN),
                    a.sigma_s_prime.and_then(|e| e.g),
                    a.sigma_a.and_then(|e| e.g),
                    100.0 * pb.first().map_or(f64::NAN, |p| p.err),
                    100.0 * pb.get(1).map_or(f64::NAN, |p| p.err),
                    100.0 * pb.first().and_then(|p| p.total).unwrap_or(f64::NAN),
                    100.0 * pb.get(1).and_then(|p| p.total).unwrap_or(f64::NAN),
                    a.problem
                        .as_ref()
                        .map_or(String::new(), |p| format!(" [{p}]"))
                );
                if let [sp, sa] = pa.as_slice() {
                    e0.0.push(sp.err.abs());
                    e0.1.push(sa.err.abs());
                }
                if let [sp, sa] = pb.as_slice() {
                    em.0.push(sp.err.abs());
                    em.1.push(sa.err.abs());
                }
                at0.extend(pa);
                mid.extend(pb);
            }
            eprintln!(
                "g {g} {name}: synthesised in {t_synth:.1} s, measured in {t_measure:.2} s \
                 (g term included)"
            );
        }
        println!(
            "| {g} | {} | {:.1} % / {:.1} % | {} | {} | {} | {:.1} % / {:.1} % | {} | {} |",
            e0.0.len(),
            100.0 * median(e0.0),
            100.0 * median(e0.1),
            covered(&at0, |p| p.without_g),
            covered(&at0, |p| p.total),
            covered(&at0, |p| p.quadrature),
            100.0 * median(em.0),
            100.0 * median(em.1),
            covered(&mid, |p| p.total),
            covered(&mid, |p| p.quadrature),
        );
    }
}
