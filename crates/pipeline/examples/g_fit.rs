//! `[fit] g = "fit"` on rig twins: quick-rig twins (`RigSpec::quick`, or the paper's rig)
//! of materials simulated by the Monte Carlo engine at Henyey–Greenstein g = `G` (profile and
//! spectrophotometer reading), measured with `--model mc --albedo-model mc` and `g = "fit"`. Per
//! channel: the truth's α′ and g, the fitted g ± sd(g) (its fit and model parts, the shape signal
//! of Δg = 0.05), determined or why not, and σ′s, σa against the truth.
//!
//! ```text
//! nice -n 15 cargo run --release -p scatterfit-pipeline --example g_fit -- [G] [paper|quick] [MATERIAL,…] [SEED]
//! ```

use scatterfit_io::manifest::{FitSection, GSetting};
use scatterfit_lab::twin::{TwinFolder, write_twin_folder};
use scatterfit_optics::materials::by_name;
use scatterfit_optics::{AlbedoModel, Channel, ModelName};
use scatterfit_pipeline::{Overrides, measure_sample};
use scatterfit_synth::{RigSpec, synthesize};

fn main() {
    let arg = |k: usize| std::env::args().nth(k);
    let g: f64 = arg(1).map_or(0.9, |a| a.parse().expect("G"));
    let paper = arg(2).is_some_and(|a| a == "paper");
    let names: Vec<String> = arg(3).map_or_else(
        || vec!["wood-tile".into(), "skin1".into(), "nephrite".into()],
        |a| a.split(',').map(str::to_string).collect(),
    );
    let seed0: u64 = arg(4).map_or(7, |a| a.parse().expect("SEED"));
    let mut rig = if paper {
        RigSpec::paper()
    } else {
        RigSpec::quick()
    };
    rig.g = g;
    let dir = tempfile::tempdir().unwrap();
    println!(
        "| material | η | ch | α′ | truth g | fitted g ± sd | sd fit / spectro / model | shape of Δg 0.05 | determined | σ′s err | σa err | (σa ± total) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (k, name) in names.iter().enumerate() {
        let m = by_name(name).unwrap();
        let s = synthesize(
            m.name,
            m.sigma_s_prime,
            m.sigma_a,
            m.eta,
            &rig,
            seed0 + k as u64,
            None,
            &|_, _, _| {},
        )
        .unwrap();
        let folder = dir.path().join(m.name);
        let fit = FitSection {
            model: Some(ModelName::Mc),
            albedo_model: Some(AlbedoModel::Mc),
            g: Some(GSetting::Fit),
            ..Default::default()
        };
        write_twin_folder(&folder, &s, &TwinFolder::new(fit, "g_fit example")).unwrap();
        let t = std::time::Instant::now();
        let measured = measure_sample(&folder, &Overrides::default(), &|_| {}).unwrap();
        let fit_s = measured.timings.fit_s;
        eprintln!(
            "{name}: measured in {:.2} s (fit stage {:.3} s)",
            t.elapsed().as_secs_f64(),
            fit_s
        );
        let r = measured.to_result(None);
        let u = r.g_uncertainty.as_ref().unwrap();
        for (c, ch) in Channel::ALL.iter().enumerate() {
            let f = u.fitted.as_ref().and_then(|f| f[*ch].clone());
            let gf = measured.fits[*ch].fit().and_then(|f| f.g_fit.clone());
            let row = &r.channels[*ch];
            let err = |v: Option<f64>, truth: f64| {
                v.map_or("—".to_string(), |v| {
                    format!("{:+.2} %", 100.0 * (v / truth - 1.0))
                })
            };
            let (fitted, parts, shape, det) = match (&f, &gf) {
                (Some(f), Some(gf)) => (
                    match (f.g, f.g_stderr) {
                        (Some(g), Some(sd)) => format!("{g:.3} ± {sd:.3}"),
                        _ => format!("({:.3} ± {:.3}, not printed)", gf.g, gf.stderr),
                    },
                    format!(
                        "{:.3} / {:.3} / {:.3}",
                        gf.stderr_fit, gf.stderr_spectro, gf.stderr_model
                    ),
                    format!("{:.2} %", 100.0 * gf.shape_change),
                    if f.determined {
                        "yes".to_string()
                    } else {
                        format!("no: {}", f.reason.clone().unwrap_or_default())
                    },
                ),
                _ => ("—".into(), "—".into(), "—".into(), "no fit".into()),
            };
            if let Some(gf) = &gf
                && std::env::var_os("G_FIT_SCAN").is_some()
            {
                let min = gf.scan.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
                let scan: Vec<String> = gf
                    .scan
                    .iter()
                    .map(|(g, c)| format!("{g:.2}:{:.1}", c - min))
                    .collect();
                eprintln!("  {} χ² − min: {}", ch.name(), scan.join(" "));
            }
            let sa = row.sigma_a;
            println!(
                "| {name} | {} | {} | {:.4} | {g} | {fitted} | {parts} | {shape} | {det} | {} | {} | {} |",
                m.eta,
                ch.name(),
                m.albedo_prime()[c],
                err(row.sigma_s_prime.map(|e| e.value), m.sigma_s_prime[c]),
                err(row.sigma_a.map(|e| e.value), m.sigma_a[c]),
                sa.and_then(|e| e.total()).map_or("—".into(), |t| format!(
                    "± {:.2} %",
                    100.0 * t / m.sigma_a[c]
                )),
            );
        }
    }
}
