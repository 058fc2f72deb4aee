//! The fit figures (`scatterfit bench fit`): the profile fit per channel and a whole sample's
//! measurement, on a sample folder the caller wrote (the CLI writes a rig-twin sample).

use std::path::Path;
use std::time::Instant;

use scatterfit_fit::{ChannelInput, FitOptions, Method, PreparedFit, Spot};
use scatterfit_optics::{Channel, DiffusionModel};
use scatterfit_pipeline::measure_sample;

use crate::{Figure, Result};

/// One channel's fit on the sample's profile (G; a rig-twin sample's is 300 rings of 0.05 mm) —
/// the proposed method with the spot convolved (the default), with a point spot, and the existing
/// method — as the median of many runs on one thread; and the whole sample in `dir` (its `pixels`
/// per frame read, response recovered, merged, profiled, three fits, result files and plots
/// written) as the median of three runs.
pub fn figures(dir: &Path, pixels: usize, quick: bool) -> Result<Vec<Figure>> {
    let overrides = scatterfit_pipeline::Overrides::default();
    let measure = || -> Result<(f64, scatterfit_pipeline::Measurement)> {
        let t0 = Instant::now();
        let meas = measure_sample(dir, &overrides, &|_| {})?;
        scatterfit_report::write_measurement(dir, &meas)?;
        Ok((t0.elapsed().as_secs_f64(), meas))
    };
    let (t, mut meas) = measure()?;
    let mut totals = vec![t];
    for _ in 0..2 {
        let (t, m) = measure()?;
        totals.push(t);
        meas = m;
    }
    totals.sort_by(f64::total_cmp);
    let data = meas.profile.channel_data(Channel::G)?;
    let rings = data.rings().len();
    let input = ChannelInput {
        eta: meas.spectro.eta,
        albedo_prime: meas.spectro.albedo_prime[Channel::G],
        rd_total: Some(meas.spectro.rd[Channel::G]),
    };
    let reps = if quick { 200 } else { 2_000 };
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
    figures.push(Figure {
        name: "measure a whole sample (read, merge, profile, 3 fits, files, plots)".into(),
        value: totals[1],
        unit: "s".into(),
        note: format!(
            "median of 3; 13 × {:.1} MP 8-bit PNG; {} threads",
            pixels as f64 / 1e6,
            rayon::current_num_threads()
        ),
    });
    Ok(figures)
}
