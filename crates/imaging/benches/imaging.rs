//! Benchmarks of the in-memory imaging stage (targets: BENCHMARKS.md, "Summary"): the HDR merge of a 13-exposure
//! bracket of 24-megapixel 8-bit RGB frames, and the radial profile of a 24-megapixel radiance map.
//!
//! Run: `cargo bench -p scatterfit-imaging` (figures in BENCHMARKS.md, "imaging (in-memory)").

use std::sync::LazyLock;

use scatterfit_imaging::{
    CalibrateOptions, ImageBuf, MergeOptions, ProfileOptions, ResponseCurve, find_spot_center,
    merge, radial_profile, recover_response,
};

fn main() {
    divan::main();
}

/// 6000 × 4000 pixels = 24 MP.
const W: usize = 6000;
const H: usize = 4000;

fn times() -> Vec<f64> {
    (0..13)
        .map(|j| (1.0 / 600.0) * 1800f64.powf(j as f64 / 12.0))
        .collect()
}

/// A spot-like scene (radiance falling over ~6 decades from the centre) through a gamma-2.2 camera,
/// 13 exposures, 3 channels: 13 × 72 MB = 936 MB.
static BRACKET: LazyLock<Vec<ImageBuf<u8>>> = LazyLock::new(|| {
    times()
        .iter()
        .map(|t| {
            let mut data = vec![0u8; W * H * 3];
            for (i, px) in data.chunks_exact_mut(3).enumerate() {
                let (x, y) = ((i % W) as f64 - 3000.3, (i / W) as f64 - 2000.7);
                let r = (x * x + y * y).sqrt();
                let e = 1e3 * (-r / 150.0).exp() + 1e-3;
                for (c, v) in px.iter_mut().enumerate() {
                    let s = [1.0, 0.7, 0.4][c];
                    *v = (255.0 * (s * e * t).min(1.0).powf(1.0 / 2.2)).round() as u8;
                }
            }
            ImageBuf::new(W, H, 3, data).unwrap()
        })
        .collect()
});

static RESPONSE: LazyLock<ResponseCurve> = LazyLock::new(|| {
    let g = std::array::from_fn(|z| 2.2 * ((z.max(1) as f64) / 128.0).ln());
    ResponseCurve::from_log_exposure(vec![g; 3]).unwrap()
});

static RADIANCE: LazyLock<ImageBuf<f32>> = LazyLock::new(|| {
    let data = (0..W * H)
        .flat_map(|i| {
            let (x, y) = ((i % W) as f64 - 3000.3, (i / W) as f64 - 2000.7);
            let e = (1e3 * (-(x * x + y * y).sqrt() / 150.0).exp()) as f32;
            [e, 0.7 * e, 0.4 * e]
        })
        .collect();
    ImageBuf::new(W, H, 3, data).unwrap()
});

#[divan::bench(name = "merge: 13 × 24 MP 8-bit RGB, known response", sample_count = 5)]
fn merge_13x24mp(bencher: divan::Bencher) {
    let frames = &*BRACKET;
    let ts = times();
    let resp = &*RESPONSE;
    bencher.bench(|| merge(frames, &ts, resp, None, &MergeOptions::default()).unwrap());
}

#[divan::bench(
    name = "response recovery: 13 × 24 MP 8-bit RGB, 100 samples/channel",
    sample_count = 5
)]
fn recover_13x24mp(bencher: divan::Bencher) {
    let frames = &*BRACKET;
    let ts = times();
    bencher.bench(|| recover_response(frames, &ts, &CalibrateOptions::default()).unwrap());
}

#[divan::bench(
    name = "radial profile: 24 MP RGB radiance, r_max 300 px, 1 px rings",
    sample_count = 20
)]
fn profile_24mp(bencher: divan::Bencher) {
    let img = &*RADIANCE;
    bencher.bench(|| {
        radial_profile(img, [3000.3, 2000.7], None, 0.1, &ProfileOptions::default()).unwrap()
    });
}

#[divan::bench(name = "spot centre: 24 MP RGB radiance", sample_count = 5)]
fn center_24mp(bencher: divan::Bencher) {
    let img = &*RADIANCE;
    bencher.bench(|| find_spot_center(img, &Default::default()).unwrap());
}
