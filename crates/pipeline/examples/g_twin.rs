//! The whole measurement on rig-twin samples that scatter forward: quick-rig twins
//! (`RigSpec::quick`, fixed seeds) of three materials simulated by the Monte Carlo engine at
//! Henyey–Greenstein g = 0.8 or `G` (profile and spectrophotometer reading), measured with `--model mc
//! --albedo-model mc` and the manifest's `[fit] g = 0.8`, and refitted from the same frames and
//! reading assuming g = 0 (`Measurement::refit_with`). Relative errors against the truth.
//!
//! Also printed (stderr), per channel: the twin's Monte Carlo total reflectance (its
//! spectrophotometer reading) ± its standard error against the `mc` model's total at the truth,
//! and the σa error that the reading's noise alone makes through the α′ inversion — what separates
//! the twin's noise from the method's error at α′ → 1.
//!
//! ```text
//! nice -n 19 cargo run -p scatterfit-pipeline --example g_twin [G] [paper|quick] [MATERIAL,…] [PHOTONS×]
//! ```
//!
//! A material named `range-etaX` (for example `range-eta1.0`, `range-eta2.4`) spans the
//! range of α′ the `mc` model over g is meant for, at η = X: R at α′ 0.3 (σ′s 1 mm⁻¹), G at α′ 0.99 (σ′s 1.5 mm⁻¹), B at α′ 0.9999
//! (σ′s 3 mm⁻¹, so that its light, which travels 1/σtr ≈ 19 mm, stays inside the paper rig's field).
//!
//! `PHOTONS×` multiplies the twin's photon budget (its Monte Carlo noise falls as 1/√×): a channel
//! whose error falls with it was limited by the twin, not by the method.

use scatterfit_io::manifest::FitSection;
use scatterfit_io::sample_folder::{SampleFiles, write_sample_folder};
use scatterfit_optics::materials::by_name;
use scatterfit_optics::{AlbedoModel, Channel, ModelName};
use scatterfit_pipeline::FitSettings;
use scatterfit_pipeline::{Overrides, measure_sample};
use scatterfit_synth::{RigSpec, synthesize};

fn main() {
    // The twin's g (default 0.8; 0 gives the quick rig's own error at g = 0 as a baseline).
    let g: f64 = std::env::args()
        .nth(1)
        .map_or(0.8, |a| a.parse().expect("G"));
    let dir = tempfile::tempdir().unwrap();
    // `paper` as the second argument: the paper's rig (ten times the photons, 1 MP frames).
    let paper = std::env::args().nth(2).is_some_and(|a| a == "paper");
    // (the seeds are 7, 8, … in the order the materials are given)
    let mut rig = if paper {
        RigSpec::paper()
    } else {
        RigSpec::quick()
    };
    rig.g = g;
    if let Some(x) = std::env::args().nth(4) {
        let x: f64 = x.parse().expect("PHOTONS×");
        rig.steps_budget *= x;
        rig.max_photons = (rig.max_photons as f64 * x) as u64;
        rig.min_photons = (rig.min_photons as f64 * x) as u64;
    }
    println!("| material | ch | α′ | σ′s: g = 0 assumed | g = {g} | σa: g = 0 assumed | g = {g} |");
    println!("|---|---|---|---|---|---|---|");
    // Materials as the third argument, comma-separated (default: wood-tile, sulfur, skin2).
    let names: Vec<String> = std::env::args().nth(3).map_or_else(
        || vec!["wood-tile".into(), "sulfur".into(), "skin2".into()],
        |a| a.split(',').map(str::to_string).collect(),
    );
    for (k, name) in names.iter().enumerate() {
        let m = match name.strip_prefix("range-eta") {
            Some(eta) => range_material(name, eta.parse().expect("range-etaX: X is η")),
            None => *by_name(name).unwrap(),
        };
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
        eprintln!("{name}: synthesised in {:.0} s", t.elapsed().as_secs_f64());
        let grid = scatterfit_mc::bundled_grid().unwrap();
        for (c, ct) in s.truth.channels.iter().enumerate() {
            let (Ok(model), Ok(back)) = (
                grid.rd_total(ct.albedo_prime, m.eta, g),
                grid.albedo_from_rd(ct.rd_total, m.eta, g),
            ) else {
                eprintln!(
                    "  {c}: α′ {:.5}, twin Rd {:.5} ± {:.5}: beyond the tables at g = {g}",
                    ct.albedo_prime, ct.rd_total, ct.rd_total_stderr
                );
                continue;
            };
            eprintln!(
                "  {c}: α′ {:.5}, twin Rd {:.5} ± {:.5}, model Rd {:.5} (z {:+.1}), α′ from twin Rd {:.5} → σa {:+.2} %",
                ct.albedo_prime,
                ct.rd_total,
                ct.rd_total_stderr,
                model,
                (ct.rd_total - model) / ct.rd_total_stderr,
                back,
                100.0 * ((1.0 / back - 1.0) / (1.0 / ct.albedo_prime - 1.0) - 1.0)
            );
        }
        let folder = dir.path().join(m.name);
        write_sample_folder(
            &folder,
            &SampleFiles {
                name: m.name,
                reading: &s.reading,
                lab10: None,
                frames: &s.bracket.frames,
                times_s: &s.bracket.times_s,
                mm_per_pixel: rig.mm_per_pixel,
                spot_diameter_mm: 2.0 * rig.spot_radius_mm,
                truth_json: None,
                provenance: "g_twin example",
                fit: FitSection {
                    model: Some(ModelName::Mc),
                    albedo_model: Some(AlbedoModel::Mc),
                    g: Some(scatterfit_io::manifest::GSetting::Value(g)),
                    ..Default::default()
                },
            },
        )
        .unwrap();
        // A surface without a specular part (η = 1) gives no η to measure: a user gives it.
        let overrides = Overrides {
            eta: (m.eta < 1.001).then_some(m.eta),
            ..Overrides::default()
        };
        let at_g = measure_sample(&folder, &overrides, &|_| {}).unwrap();
        let at_0 = at_g
            .refit_with(FitSettings {
                g: 0.0,
                ..at_g.settings
            })
            .unwrap();
        let (r0, rg) = (at_0.to_result(None), at_g.to_result(None));
        for (c, ch) in Channel::ALL.iter().enumerate() {
            let err = |v: Option<f64>, truth: f64| {
                v.map_or("—".to_string(), |v| {
                    format!("{:+.2} %", 100.0 * (v / truth - 1.0))
                })
            };
            let (a, b) = (&r0.channels[*ch], &rg.channels[*ch]);
            println!(
                "| {name} | {} | {:.4} | {} | {} | {} | {} |",
                ch.name(),
                m.albedo_prime()[c],
                err(a.sigma_s_prime.map(|e| e.value), m.sigma_s_prime[c]),
                err(b.sigma_s_prime.map(|e| e.value), m.sigma_s_prime[c]),
                err(a.sigma_a.map(|e| e.value), m.sigma_a[c]),
                err(b.sigma_a.map(|e| e.value), m.sigma_a[c]),
            );
        }
    }
}

/// The α′ range the g-aware model is meant for, at one η (module docs): α′ 0.3, 0.99 and 0.9999.
fn range_material(name: &str, eta: f64) -> scatterfit_optics::materials::PublishedMaterial {
    let sigma_s_prime = [1.0, 1.5, 3.0];
    let albedo = [0.3, 0.99, 0.9999];
    scatterfit_optics::materials::PublishedMaterial {
        name: Box::leak(name.to_string().into_boxed_str()),
        source: "the α′ range of the g-aware model (0.3–0.9999)",
        sigma_s_prime,
        sigma_a: std::array::from_fn(|c| sigma_s_prime[c] * (1.0 / albedo[c] - 1.0)),
        eta,
    }
}
