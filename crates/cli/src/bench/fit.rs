//! `scatterfit bench fit`: the profile fit per channel and a whole sample's measurement.

use std::time::Instant;

use anyhow::Context;
use scatterfit_fit::{ChannelInput, FitOptions, Method, PreparedFit, Spot};
use scatterfit_optics::{Channel, DiffusionModel};
use scatterfit_pipeline::measure_sample;
use scatterfit_synth::materials::by_name;

use super::{Args, Figure};

/// One channel's fit on a 300-ring profile
/// (0.05 mm rings of a rig-twin sample's radial profile) — the proposed method with the spot
/// convolved (the default), with a point spot, and the existing method — as the median of many
/// runs on one thread; and a whole sample (13 × 1 MP exposures read, response recovered, merged,
/// profiled, three fits, result files and plots written) as the median of three runs.
pub fn figures(args: &Args) -> anyhow::Result<Vec<Figure>> {
    let temp = tempfile::tempdir()?;
    let dir = temp.path().join("wood-tile");
    let m = by_name("wood-tile").context("the built-in material")?;
    let material = crate::twin::Material {
        name: m.name.into(),
        sigma_s_prime: m.sigma_s_prime,
        sigma_a: m.sigma_a,
        eta: m.eta,
    };
    let cache = crate::common::cache_dir(None);
    let sample = crate::twin::synthesize(&material, 1, cache.as_deref(), true, args.quick)?;
    crate::twin::write_sample(&dir, &sample)?;
    let overrides = scatterfit_pipeline::Overrides::default();
    let mut totals = Vec::new();
    let mut last = None;
    for _ in 0..3 {
        let t0 = Instant::now();
        let meas = measure_sample(&dir, &overrides, &|_| {})?;
        scatterfit_report::write_measurement(&dir, &meas)?;
        totals.push(t0.elapsed().as_secs_f64());
        last = Some(meas);
    }
    totals.sort_by(f64::total_cmp);
    let meas = last.context("three runs")?;
    let data = meas.profile.channel_data(Channel::G)?;
    let rings = data.rings().len();
    let input = ChannelInput {
        eta: meas.spectro.eta,
        albedo_prime: meas.spectro.albedo_prime[Channel::G],
        rd_total: Some(meas.spectro.rd[Channel::G]),
    };
    let reps = if args.quick { 200 } else { 2_000 };
    let mut figures = Vec::new();
    let cases = [
        (
            "proposed, spot disk convolved (default)",
            Method::Proposed,
            true,
        ),
        ("proposed, point spot", Method::Proposed, false),
        (
            "existing (σ′s, σa), spot disk convolved",
            Method::Existing,
            true,
        ),
    ];
    for (label, method, disk) in cases {
        let mut opts = FitOptions::new(method);
        if !disk {
            opts.spot = Spot::Point;
        }
        let prepared = PreparedFit::new(&data, &input, &DiffusionModel::Dipole, &opts)?;
        let n = if method == Method::Existing {
            reps / 10
        } else {
            reps
        };
        let mut times: Vec<f64> = (0..n)
            .map(|_| {
                let t0 = Instant::now();
                std::hint::black_box(prepared.solve());
                t0.elapsed().as_secs_f64()
            })
            .collect();
        times.sort_by(f64::total_cmp);
        let used = prepared.selected().r_mm.len();
        figures.push(Figure {
            name: format!("fit one channel: {label}"),
            value: times[times.len() / 2] * 1e6,
            unit: "µs".into(),
            note: format!("median of {n}; {rings}-ring profile, {used} fitted; one thread"),
        });
    }
    let px = sample.truth.rig.width * sample.truth.rig.height;
    figures.push(Figure {
        name: "measure a whole sample (read, merge, profile, 3 fits, files, plots)".into(),
        value: totals[1],
        unit: "s".into(),
        note: format!(
            "median of 3; 13 × {:.1} MP 8-bit PNG; {} threads",
            px as f64 / 1e6,
            rayon::current_num_threads()
        ),
    });
    Ok(figures)
}
