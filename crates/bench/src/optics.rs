//! The optics figures (`scatterfit bench optics`): the optics core on one thread.

use std::hint::black_box;
use std::time::Instant;

use scatterfit_optics::OpticalProperties;
use scatterfit_optics::dipole::{Dipole, ProfileSample, albedo_from_rd};

use crate::{Figure, Result};

/// The dipole profile with derivatives (300 radii) and the α′ inversion, timed over many
/// repetitions.
pub fn figures(quick: bool) -> Result<Vec<Figure>> {
    let reps = if quick { 2_000 } else { 50_000 };
    let radii: Vec<f64> = (1..=300).map(|i| 0.1 * i as f64).collect();
    let props = OpticalProperties::new(1.979, 0.0496, 1.2886)?;
    let mut out = vec![
        ProfileSample {
            rd: 0.0,
            d_sigma_s_prime: 0.0,
            d_sigma_a: 0.0
        };
        radii.len()
    ];
    let start = Instant::now();
    for _ in 0..reps {
        Dipole::new(black_box(&props)).profile_with_derivatives_into(black_box(&radii), &mut out);
        black_box(&out);
    }
    let profile_us = start.elapsed().as_secs_f64() * 1e6 / reps as f64;

    let rds: Vec<f64> = (1..=99).map(|i| i as f64 / 100.0).collect();
    let start = Instant::now();
    for _ in 0..reps / 50 {
        for &rd in &rds {
            black_box(albedo_from_rd(black_box(rd), 1.3)?);
        }
    }
    let inversion_us = start.elapsed().as_secs_f64() * 1e6 / ((reps / 50) * rds.len()) as f64;
    Ok(vec![
        Figure {
            name: "dipole Rd(r) + derivatives, 300 radii".into(),
            value: profile_us,
            unit: "µs".into(),
            note: "one thread; BENCHMARKS.md has the figures of the reference machine".into(),
        },
        Figure {
            name: "α′ inversion (Rd = 0.01…0.99, η = 1.3)".into(),
            value: inversion_us,
            unit: "µs".into(),
            note: "one thread, mean over Rd".into(),
        },
    ])
}
