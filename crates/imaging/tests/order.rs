//! The order check decides on evidence only: values at a frame's noise floor say nothing about
//! order (the darkest frames of Debevec's memorial sit on a film pedestal of codes 13–20 that
//! drifts by a code from frame to frame), while a reversed pair of frames with signal is refused.
//! The real memorial is checked in `crates/pipeline/tests/real_brackets.rs` (with the corpus).

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use scatterfit_imaging::{ImageBuf, ImagingError, bracket_signal, check_bracket_order};

/// A 200 × 200 grey bracket shaped like the memorial's shortest frames: 98 % of the pixels dark,
/// reading a pedestal `17 − j·drift` plus 2 codes of noise in frame j (the pedestal falls as the
/// time grows, as the memorial's does from 1/512 s to 1/256 s); 2 % bright, 30·Δt codes above it.
/// `bright[j]` = false: frame j's bright pixels are dark too (a frame without signal).
fn pedestal_bracket(times: &[f64], drift: f64, bright: &[bool], seed: u64) -> Vec<ImageBuf<u8>> {
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    let noise = Normal::new(0.0, 2.0).unwrap();
    let (w, h) = (200usize, 200usize);
    times
        .iter()
        .enumerate()
        .map(|(j, &t)| {
            let data = (0..w * h)
                .map(|i| {
                    let lit = i % 50 == 0 && bright[j];
                    let signal = if lit { 30.0 * t } else { 0.0 };
                    let v = 17.0 - drift * j as f64 + signal + noise.sample(&mut rng);
                    v.round().clamp(0.0, 255.0) as u8
                })
                .collect();
            ImageBuf::new(w, h, 1, data).unwrap()
        })
        .collect()
}

#[test]
fn pedestal_values_are_not_evidence_of_order() {
    let times = [1.0, 2.0, 4.0];
    let frames = pedestal_bracket(&times, 2.0, &[true; 3], 5);
    // The premise: over every unclipped value the longer frames read darker in sum (the old
    // check's statistic, z = Σ(y − x)/√Σ(y − x)², is far below −3: it refused such brackets).
    for j in 0..2 {
        let (a, b) = (frames[j].data(), frames[j + 1].data());
        let (mut s, mut s2) = (0.0f64, 0.0f64);
        for (&x, &y) in a.iter().zip(b) {
            let d = f64::from(y) - f64::from(x);
            s += d;
            s2 += d * d;
        }
        let z = s / s2.sqrt();
        assert!(z < -3.0, "frames {j}, {}: z = {z}", j + 1);
    }
    check_bracket_order(&frames, &times, u8::MAX).expect("the pedestal is no evidence");
    let signal = bracket_signal(&frames, &times, u8::MAX).unwrap();
    for fl in &signal.floor {
        assert!((14.0..=24.0).contains(&fl[0]), "floor {fl:?}");
    }
    assert!(signal.has_signal.iter().all(|&s| s), "{signal:?}");
    // The bright pixels are evidence: the same frames with their times reversed are refused.
    let reversed = [4.0, 2.0, 1.0];
    let err = check_bracket_order(&frames, &reversed, u8::MAX).unwrap_err();
    assert!(
        matches!(err, ImagingError::BracketOutOfOrder { .. }),
        "{err:?}"
    );
}

#[test]
fn a_frame_without_signal_is_found_and_passed_over() {
    let times = [0.5, 1.0, 2.0, 4.0];
    let mut frames = pedestal_bracket(&times, 0.0, &[true; 4], 6);
    // The shortest frame is black: no light reached code 1 (a lens cap, a far too short time).
    frames[0] = ImageBuf::filled(200, 200, 1, 0u8).unwrap();
    let signal = bracket_signal(&frames, &times, u8::MAX).unwrap();
    assert_eq!(
        signal.has_signal,
        vec![false, true, true, true],
        "{signal:?}"
    );
    check_bracket_order(&frames, &times, u8::MAX).expect("no evidence either way");
    // One frame listed twice is still refused.
    let mut twice = frames.clone();
    twice[2] = twice[1].clone();
    assert!(matches!(
        check_bracket_order(&twice, &times, u8::MAX),
        Err(ImagingError::BracketOutOfOrder { .. })
    ));
}
