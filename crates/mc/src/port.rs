//! The Monte Carlo twin of a spectrophotometer's port reading: uniform illumination over the lit
//! disc, collection over the concentric aperture, traced by the engine (no kernel, no profile), so
//! that the rig twin can make readings with the edge loss that the analytic correction
//! ([`scatterfit_optics::port`]) is then tested against.

use scatterfit_optics::port::Port;

use crate::beam::{Beam, BeamProfile};
use crate::engine::{McMean, Simulation};
use crate::error::Result;
use crate::grid::RadialGrid;
use crate::sample::Sample;

/// What a port reads of a sample, by Monte Carlo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct McPortReading {
    /// Diffuse reflectance leaving inside the aperture per unit incident power (excluding R_sp).
    pub collected: McMean,
    /// Total diffuse reflectance of the same run (everything that leaves the top face).
    pub rd_total: McMean,
    /// What the instrument, calibrated on a white standard, reads as a fraction of the true Rd:
    /// collected / (K(0)·Rd) with K(0) = min(a, b)²/a² ([`Port::white_kernel`]). Its standard error
    /// is the collected fraction's alone (the two are positively correlated, so this overstates it).
    pub reading_fraction: McMean,
    /// The reading itself, Rd·F = collected / K(0): what the instrument reports as Rd.
    pub rd_read: McMean,
}

/// Simulates `photons` photons into `sample` from a beam uniform over the port's lit disc (normal
/// incidence) and tallies what leaves inside its aperture (one radial bin [0, b]).
///
/// # Errors
/// As [`Simulation::new`] (zero photons; a non-absorbing half-space).
pub fn simulate_port_reading(
    sample: Sample,
    port: &Port,
    photons: u64,
    seed: u64,
) -> Result<McPortReading> {
    let beam = Beam::new(BeamProfile::Disk {
        radius: 0.5 * port.illuminated_mm(),
    })?;
    let b = 0.5 * port.aperture_mm();
    let grid = RadialGrid::from_edges(vec![0.0, b])?;
    let r = Simulation::new(sample, beam, grid, photons, seed)?.run();
    let area = r.grid.area(0);
    let collected = McMean {
        value: r.rd_profile[0].value * area,
        stderr: r.rd_profile[0].stderr * area,
    };
    let k0 = port.white_kernel();
    let rd = r.rd_total.value;
    Ok(McPortReading {
        collected,
        rd_total: r.rd_total,
        reading_fraction: McMean {
            value: collected.value / (k0 * rd),
            stderr: collected.stderr / (k0 * rd),
        },
        rd_read: McMean {
            value: collected.value / k0,
            stderr: collected.stderr / k0,
        },
    })
}
