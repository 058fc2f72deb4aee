//! Spot centre and radial profile on analytic, radially symmetric images.

use rand::{RngExt, SeedableRng};
use rand_distr::Normal;
use rand_xoshiro::Xoshiro256PlusPlus;
use scatterfit_imaging::{
    CenterOptions, ImageBuf, ImagingError, ProfileOptions, SpotCenter, find_spot_center,
    radial_profile,
};

/// A spot-like profile: a 1-mm-ish core (Gaussian, σ = 6 px) on a diffusion-like tail e^(−r/25)/(1 + r/10).
fn spot(r: f64) -> f64 {
    1000.0 * (-(r * r) / (2.0 * 36.0)).exp() + 100.0 * (-r / 25.0).exp() / (1.0 + r / 10.0)
}

/// Renders `f(r)` per channel scaled by `scales`, centre (cx, cy), point-sampled at pixel centres.
fn render(
    w: usize,
    h: usize,
    cx: f64,
    cy: f64,
    scales: &[f64],
    f: impl Fn(f64) -> f64,
) -> ImageBuf<f32> {
    let mut data = Vec::with_capacity(w * h * scales.len());
    for y in 0..h {
        for x in 0..w {
            let r = ((x as f64 - cx).powi(2) + (y as f64 - cy).powi(2)).sqrt();
            for s in scales {
                data.push((s * f(r)) as f32);
            }
        }
    }
    ImageBuf::new(w, h, scales.len(), data).unwrap()
}

/// Noisy spot image: 3 % multiplicative and 0.05 additive Gaussian noise, the core clipped (NaN,
/// as a merge leaves pixels saturated in every exposure) where the spot exceeds 600, and a 3 × 3
/// dust speck 5× brighter than the core at (60, 400).
fn noisy_spot(cx: f64, cy: f64, seed: u64) -> ImageBuf<f32> {
    let mut img = render(640, 480, cx, cy, &[1.0, 0.8, 0.5], spot);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mult = Normal::new(0.0, 0.03).unwrap();
    let add = Normal::new(0.0, 0.05).unwrap();
    let w = img.width();
    for (i, v) in img.data_mut().iter_mut().enumerate() {
        let (x, y) = ((i / 3) % w, (i / 3) / w);
        let r = ((x as f64 - cx).powi(2) + (y as f64 - cy).powi(2)).sqrt();
        if spot(r) > 600.0 {
            *v = f32::NAN;
            continue;
        }
        let e: f64 = rng.sample(mult);
        let a: f64 = rng.sample(add);
        *v = (f64::from(*v) * (1.0 + e) + a) as f32;
        if (59..62).contains(&x) && (399..402).contains(&y) {
            *v = 5000.0;
        }
    }
    img
}

/// The centre of a noisy spot with a clipped (NaN) core and a bright dust speck is found within
/// 0.05 px (the target) for several noise seeds and non-integer centres.
#[test]
fn center_within_005_px_on_noisy_clipped_spot_with_speck() {
    for (seed, cx, cy) in [
        (1, 301.37, 248.81),
        (2, 300.5, 240.25),
        (3, 410.93, 120.08),
        (4, 180.11, 333.6),
    ] {
        let img = noisy_spot(cx, cy, seed);
        let c = find_spot_center(&img, &CenterOptions::default()).unwrap();
        let err = ((c.x() - cx).powi(2) + (c.y() - cy).powi(2)).sqrt();
        eprintln!(
            "seed {seed}: error {err:.4} px, {} spot px",
            c.spot_pixels()
        );
        assert!(
            err < 0.05,
            "seed {seed}: found ({:.3}, {:.3}), true ({cx}, {cy}), error {err:.4} px",
            c.x(),
            c.y()
        );
    }
}

/// Without clipping or noise, the centroid is essentially exact (symmetry), for a clipped core
/// with finite values (the merge's lower-bound fill) as well.
#[test]
fn center_exact_on_clean_and_flat_topped_spots() {
    let (cx, cy) = (200.3, 150.7);
    let img = render(400, 300, cx, cy, &[1.0], spot);
    let c = find_spot_center(&img, &CenterOptions::default()).unwrap();
    assert!(
        (c.x() - cx).abs() < 0.01 && (c.y() - cy).abs() < 0.01,
        "({}, {})",
        c.x(),
        c.y()
    );
    let flat = render(400, 300, cx, cy, &[1.0], |r| spot(r).min(400.0));
    let c = find_spot_center(&flat, &CenterOptions::default()).unwrap();
    assert!(
        (c.x() - cx).abs() < 0.01 && (c.y() - cy).abs() < 0.01,
        "({}, {})",
        c.x(),
        c.y()
    );
}

#[test]
fn center_refuses_bad_input() {
    let dark = ImageBuf::filled(10, 10, 1, 0.0f32).unwrap();
    assert!(matches!(
        find_spot_center(&dark, &CenterOptions::default()),
        Err(ImagingError::NoSpot { .. })
    ));
    let img = render(50, 40, 20.0, 20.0, &[1.0], spot);
    for bad in [1.5, 0.0, f64::NAN] {
        assert!(matches!(
            CenterOptions::new(bad),
            Err(ImagingError::InvalidOption { .. })
        ));
    }
    assert!(SpotCenter::given(&img, 49.4, 39.5).is_ok());
    assert!(matches!(
        SpotCenter::given(&img, 50.0, 2.0),
        Err(ImagingError::CenterOutside { .. })
    ));
    assert!(SpotCenter::given(&img, f64::NAN, 2.0).is_err());
}

/// A radially symmetric analytic image, off-centre at a non-integer centre: every ring's mean equals
/// f at the ring's reported radius (the mean pixel distance) to 2·10⁻³ relative (the remaining
/// difference is f's curvature over the ring's width, f''·Var(r)/2 with Var(r) ≈ w²/12), in every
/// channel with its own scale; rings that leave the image (the centre is 40 px from the left edge)
/// still match.
#[test]
fn profile_matches_analytic_function() {
    let (cx, cy) = (40.37, 95.62);
    let scales = [1.0, 0.5, 0.25];
    let f = |r: f64| 100.0 * (-r / 25.0).exp() / (1.0 + r / 10.0);
    let img = render(260, 200, cx, cy, &scales, f);
    let opts = ProfileOptions::new(1.0, 150.0).unwrap();
    let prof = radial_profile(&img, [cx, cy], None, 0.1, &opts).unwrap();
    assert_eq!(prof.rings.len(), 150);
    for (k, ring) in prof.rings.iter().enumerate().skip(2) {
        for (c, s) in scales.iter().enumerate() {
            let rc = &ring.channels[c];
            let expected = s * f(ring.r_px);
            let rel = (rc.mean - expected).abs() / expected;
            assert!(
                rel < 2e-3,
                "ring {k} channel {c}: mean {} vs f(r = {:.3}) = {expected}",
                rc.mean,
                ring.r_px
            );
        }
        assert!(ring.r_px >= ring.r_inner_px && ring.r_px < ring.r_outer_px);
    }
    // Radius in mm.
    assert!((prof.r_mm(10).unwrap() - prof.rings[10].r_px * 0.1).abs() < 1e-12);
    // Counts: all pixels with r < r_max, counted independently.
    let brute = (0..200)
        .flat_map(|y| (0..260).map(move |x| (x, y)))
        .filter(|&(x, y)| ((x as f64 - cx).powi(2) + (y as f64 - cy).powi(2)).sqrt() < 150.0)
        .count();
    let total: usize = prof.rings.iter().map(|r| r.channels[0].count).sum();
    assert_eq!(total, brute);
    // A ring inside the image has about 2πr·w pixels; one leaving it (r = 100 > 40 px to the edge) fewer.
    let n20 = prof.rings[20].channels[0].count as f64;
    assert!(
        (n20 / (2.0 * std::f64::consts::PI * 20.5) - 1.0).abs() < 0.1,
        "ring 20: {n20} pixels"
    );
    let n100 = prof.rings[100].channels[0].count as f64;
    assert!(
        n100 < 0.7 * 2.0 * std::f64::consts::PI * 100.5,
        "ring 100 leaves the image: {n100}"
    );
}

/// The standard error is s/√n: on a constant image with Gaussian noise σ = 0.01, s ≈ σ in every
/// ring with n ≥ 200 (to 15 %, the sampling spread of s for n = 200 is ~5 %); masked and NaN
/// pixels are excluded.
#[test]
fn profile_standard_error_and_exclusions() {
    let (w, h) = (200, 200);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(42);
    let noise = Normal::new(0.0, 0.01).unwrap();
    let data: Vec<f32> = (0..w * h)
        .map(|_| (1.0 + rng.sample(noise)) as f32)
        .collect();
    let mut img = ImageBuf::new(w, h, 1, data).unwrap();
    let prof = radial_profile(&img, [100.2, 99.9], None, 1.0, &ProfileOptions::default()).unwrap();
    for ring in prof.rings.iter().filter(|r| r.channels[0].count >= 200) {
        let rc = ring.channels[0];
        let s = rc.std_err * (rc.count as f64).sqrt();
        assert!(
            (s / 0.01 - 1.0).abs() < 0.15,
            "ring r = {}: s = {s}",
            ring.r_px
        );
        assert!((rc.mean - 1.0).abs() < 5.0 * rc.std_err);
    }
    // Exclusions: NaN on the right half, mask on the top half of the rest.
    for y in 0..h {
        for x in 0..w {
            if x > 100 {
                img.data_mut()[y * w + x] = f32::NAN;
            }
        }
    }
    let mask_data: Vec<u8> = (0..w * h).map(|i| u8::from(i / w < 50)).collect();
    let mask = ImageBuf::new(w, h, 1, mask_data).unwrap();
    let opts = ProfileOptions::new(2.0, 40.0).unwrap();
    let prof = radial_profile(&img, [80.0, 100.0], Some(&mask), 1.0, &opts).unwrap();
    let expected = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            x <= 100 && y >= 50 && ((x as f64 - 80.0).powi(2) + (y as f64 - 100.0).powi(2)) < 1600.0
        })
        .count();
    assert_eq!(
        prof.rings
            .iter()
            .map(|r| r.channels[0].count)
            .sum::<usize>(),
        expected
    );
}

#[test]
fn profile_refuses_bad_input() {
    let img = ImageBuf::filled(20, 20, 1, 1.0f32).unwrap();
    let ok = ProfileOptions::default();
    assert!(radial_profile(&img, [10.0, 10.0], None, 0.0, &ok).is_err());
    assert!(radial_profile(&img, [f64::NAN, 10.0], None, 0.1, &ok).is_err());
    // Ring options are refused when made: a bad width, and a width that asks for an
    // impossible number of rings ("capacity overflow" once) or a radius of 1e13 px.
    for (width, r_max) in [(-1.0, 300.0), (1e-300, 300.0), (1.0, 1e13), (f64::NAN, 1.0)] {
        assert!(
            matches!(
                ProfileOptions::new(width, r_max),
                Err(ImagingError::InvalidOption { .. })
            ),
            "{width} {r_max}"
        );
    }
    assert_eq!(ProfileOptions::new(1.0, 1e6).unwrap().rings(), 1_000_000);
    let mask = ImageBuf::filled(20, 21, 1, 0u8).unwrap();
    assert!(matches!(
        radial_profile(&img, [10.0, 10.0], Some(&mask), 0.1, &ok),
        Err(ImagingError::ShapeMismatch { .. })
    ));
}

/// A uniform frame (or a gently vignetted one, a flat frame's look) has no spot: it is refused as
/// such, not given "a centre" in the middle of the frame. The noisy spot of the tests above still
/// has one.
#[test]
fn a_uniform_image_has_no_spot() {
    let grey = ImageBuf::filled(64, 48, 3, 0.4f32).unwrap();
    let vignetted = render(640, 480, 320.0, 240.0, &[1.0, 0.9, 0.8], |r| {
        1.0 - 0.4 * (r / 400.0).powi(2)
    });
    for img in [&grey, &vignetted] {
        let e = find_spot_center(img, &CenterOptions::default()).unwrap_err();
        assert!(
            matches!(e, ImagingError::NoSpot { .. }) && e.to_string().contains("uniform"),
            "{e}"
        );
    }
    find_spot_center(&noisy_spot(300.2, 240.7, 9), &CenterOptions::default()).unwrap();
}
