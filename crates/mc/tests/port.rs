//! The spectrophotometer port: the analytic reading (`scatterfit_optics::port`, the
//! two-disc kernel integrated against a pencil-beam profile) against the engine's direct twin of the
//! reading (uniform illumination over the lit disc, collection over the aperture) — two different
//! computations of the same number; fixed seeds, tolerances in standard errors.

use scatterfit_mc::port::simulate_port_reading;
use scatterfit_mc::{Beam, Layer, RadialGrid, Sample, Simulation};
use scatterfit_optics::port::Port;

/// A half-space with millimetre-scale lateral spread (σ′t = 1 mm⁻¹, α′ = 0.99, η 1.4; g as given).
fn half_space(g: f64) -> Sample {
    let (sigma_s_prime, sigma_a) = (0.99, 0.01);
    let layer = Layer::new(sigma_a, sigma_s_prime / (1.0 - g), g, 1.4, f64::INFINITY).unwrap();
    Sample::new(vec![layer], 1.0, 1.0).unwrap()
}

/// Two common d/8 ports (8 mm lit over 14 mm and over 8 mm): the disc-beam twin's collected fraction
/// equals the kernel integral of a pencil-beam profile (0.05 mm bins to the port's reach; the
/// profile as a step function) within 4 combined standard errors plus 0.2 % for the binning, and
/// the edge loss is real (reading fraction well below 1).
#[test]
fn twin_matches_kernel_integral() {
    for (g, ill, ap) in [(0.0, 14.0, 8.0), (0.0, 8.0, 8.0), (0.8, 14.0, 8.0)] {
        let port = Port::new(ill, ap).unwrap();
        let photons = if g == 0.0 { 200_000 } else { 60_000 };
        let twin = simulate_port_reading(half_space(g), &port, photons, 7).unwrap();
        let reach = 0.5 * (ill + ap);
        let bins = (reach / 0.05).ceil() as usize;
        let pencil = Simulation::new(
            half_space(g),
            Beam::pencil(),
            RadialGrid::uniform(0.05, bins).unwrap(),
            photons,
            8,
        )
        .unwrap()
        .run();
        let rd = |r: f64| {
            let i = ((r / 0.05) as usize).min(bins - 1);
            pencil.rd_profile[i].value
        };
        let analytic = port.reading(&rd, pencil.rd_total.value);
        // The kernel-weighted sum's standard error: bins are independent to first order.
        let se_analytic = (0..bins)
            .map(|i| {
                let r = pencil.grid.center(i);
                (pencil.rd_profile[i].stderr * pencil.grid.area(i) * port.kernel(r)).powi(2)
            })
            .sum::<f64>()
            .sqrt();
        let se = (twin.collected.stderr.powi(2) + se_analytic.powi(2)).sqrt();
        let diff = analytic.collected - twin.collected.value;
        eprintln!(
            "g {g}, lit {ill} / aperture {ap} mm: reading fraction twin {:.4} ± {:.4}, kernel {:.4}",
            twin.reading_fraction.value, twin.reading_fraction.stderr, analytic.reading_fraction
        );
        assert!(
            diff.abs() < 4.0 * se + 2e-3 * twin.collected.value,
            "g {g}, {ill}/{ap} mm: kernel {:.5} vs twin {:.5} ± {se:.5}",
            analytic.collected,
            twin.collected.value
        );
        assert!(
            twin.reading_fraction.value < 0.97,
            "{ill}/{ap}: reading {:?}",
            twin.reading_fraction
        );
        // The twin's total is the pencil beam's (translation invariance), within 4 s.e.
        let dse = (twin.rd_total.stderr.powi(2) + pencil.rd_total.stderr.powi(2)).sqrt();
        assert!((twin.rd_total.value - pencil.rd_total.value).abs() < 4.0 * dse);
    }
}
