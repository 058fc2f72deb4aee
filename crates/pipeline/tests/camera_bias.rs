//! Diagnosis: the merged radiance of a *flat field* of known rate through each tone
//! curve and noise level of the sweep, merged with the camera's true response, so that neither the
//! response recovery nor the profile is involved. Prints the bias per expected code of the longest
//! frame.

use rand::SeedableRng;
use rand_distr::{Distribution, Normal, Poisson};
use rand_xoshiro::Xoshiro256PlusPlus;
use scatterfit_imaging::{ImageBuf, MergeOptions, ResponseCurve, merge};
use scatterfit_synth::rig::{CameraModel, RigSpec, ToneCurve};

/// The true response: each code's midpoint of linear signal (as the camera test's
/// `CAMERA_TRUE_RESPONSE`).
fn true_response(camera: &CameraModel) -> ResponseCurve {
    let g = camera.true_log_response();
    ResponseCurve::from_log_exposure(vec![g]).unwrap()
}

fn electrons(mean: f64, read: f64, rng: &mut Xoshiro256PlusPlus) -> f64 {
    let shot = if mean <= 0.0 {
        0.0
    } else if mean < 1000.0 {
        Poisson::new(mean).unwrap().sample(rng)
    } else {
        Normal::new(mean, mean.sqrt()).unwrap().sample(rng)
    };
    shot + Normal::new(0.0, read).unwrap().sample(rng)
}

#[test]
#[ignore = "a diagnosis that prints a table; run with --ignored --nocapture"]
fn flat_field_bias_by_code() {
    let rig = RigSpec::quick();
    let times = rig.times_s.clone();
    let t_max = *times.last().unwrap();
    let n = 200_000;
    for curve in [
        ToneCurve::Linear,
        ToneCurve::Gamma22,
        ToneCurve::Srgb,
        ToneCurve::Log,
        ToneCurve::SCurve,
    ] {
        for read in [3.0, 15.0] {
            let camera = CameraModel {
                curve,
                read_noise_e: read,
                ..CameraModel::default()
            };
            let response = true_response(&camera);
            let x_of = |z: u8| {
                if z == 0 {
                    0.0
                } else {
                    response.tables()[0][z as usize].exp()
                }
            };
            let mut line = format!("{:>8} {read:>2} e⁻:", curve.name());
            for code in [20u8, 30, 40, 60, 80] {
                // The rate [e⁻/s] whose longest frame expects this code.
                let s = (0..200_000)
                    .map(|k| k as f64 / 200_000.0)
                    .find(|&s| 255.0 * camera.tone(s) >= f64::from(code))
                    .unwrap();
                let rate = s * camera.full_well_e / t_max;
                let mut rng = Xoshiro256PlusPlus::seed_from_u64(u64::from(code) + 7);
                let frames: Vec<ImageBuf<u8>> = times
                    .iter()
                    .map(|t| {
                        let d: Vec<u8> = (0..n)
                            .map(|_| camera.code(electrons(rate * t, read, &mut rng)))
                            .collect();
                        ImageBuf::new(n, 1, 1, d).unwrap()
                    })
                    .collect();
                let hdr =
                    merge(&frames, &times, &response, None, &MergeOptions::default()).unwrap();
                // The merge's gauge: X in units of the full well (the true response's), per second.
                let truth = rate / camera.full_well_e;
                let mean = hdr
                    .radiance
                    .data()
                    .iter()
                    .map(|&v| if v.is_finite() { f64::from(v) } else { 0.0 })
                    .sum::<f64>()
                    / n as f64;
                // The longest frame alone: E[X(Z)]/(rate t_max).
                let last = frames.last().unwrap().data();
                let x_last = last.iter().map(|&z| x_of(z)).sum::<f64>() / n as f64;
                line.push_str(&format!(
                    "  z{code}: merge {:+.2} % last {:+.2} %",
                    100.0 * (mean / truth - 1.0),
                    100.0 * (x_last / (truth * t_max) - 1.0)
                ));
            }
            eprintln!("{line}");
        }
    }
}
