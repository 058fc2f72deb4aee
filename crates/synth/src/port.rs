//! The twin's spectrophotometer port: a reading made through a d/8 instrument's port
//! instead of the loss-free total. Per channel the engine lights a disc uniformly and tallies what
//! leaves inside the concentric aperture (`scatterfit_mc::port::simulate_port_reading`: no kernel,
//! no profile), so the pipeline's correction (`scatterfit_optics::port`, which integrates a fitted
//! model's profile) is tested on readings it did not make.

use scatterfit_mc::port::simulate_port_reading;
use scatterfit_mc::{Layer, Sample};
use scatterfit_optics::port::Port;
use serde::{Deserialize, Serialize};

use crate::{SynthError, SyntheticSample, lab10_of};

/// What the twin's port did (`truth.json`'s `port`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PortTruth {
    /// Diameter of the lit disc \[mm\].
    pub illuminated_mm: f64,
    /// Diameter of the measured aperture \[mm\].
    pub aperture_mm: f64,
    /// F per channel R, G, B: the fraction of the true Rd the calibrated instrument read.
    pub reading_fraction: [f64; 3],
    /// Its Monte Carlo standard error.
    pub reading_fraction_stderr: [f64; 3],
    /// The reading per channel, F·Rd (what spectro.csv now holds, through the spectral basis).
    pub rd_read: [f64; 3],
    /// Photons traced per channel.
    pub photons: [u64; 3],
}

impl SyntheticSample {
    /// The same sample with its spectrophotometer reading made through `port`: per channel, a
    /// half-space of the truth's σ′s, σa, g and η lit uniformly over the port's disc and read over
    /// its aperture with as many photons as the twin's own reading took, the reading F·Rd turned
    /// into SCI/SCE spectra as the loss-free one was ([`crate::spectro::reading_for`]), and the
    /// L\*a\*b\* from it. The truth keeps the loss-free totals and gains [`PortTruth`].
    ///
    /// # Errors
    /// [`SynthError::Mc`] when the engine refuses the optics; [`SynthError::OutOfGamut`] when the
    /// reading's colour cannot be made.
    pub fn read_through_port(mut self, port: &Port) -> Result<Self, SynthError> {
        let t = &self.truth;
        let mut truth = PortTruth {
            illuminated_mm: port.illuminated_mm(),
            aperture_mm: port.aperture_mm(),
            reading_fraction: [0.0; 3],
            reading_fraction_stderr: [0.0; 3],
            rd_read: [0.0; 3],
            photons: [0; 3],
        };
        for (c, ch) in t.channels.iter().enumerate() {
            let layer =
                Layer::from_reduced(ch.sigma_s_prime, ch.sigma_a, t.g, t.eta, f64::INFINITY)?;
            let sample = Sample::new(vec![layer], 1.0, 1.0)?;
            let photons = ch.photons.max(1);
            // A stream of its own: the twin's profiles use seed·3 + c.
            let seed = t.seed.wrapping_mul(3).wrapping_add(c as u64) ^ 0x005e_ed0f_0a11_u64;
            let r = simulate_port_reading(sample, port, photons, seed)?;
            truth.reading_fraction[c] = r.reading_fraction.value;
            truth.reading_fraction_stderr[c] = r.reading_fraction.stderr;
            truth.rd_read[c] = r.rd_read.value;
            truth.photons[c] = photons;
        }
        self.reading = crate::spectro::reading_for(truth.rd_read, t.eta)?;
        self.lab10 = lab10_of(&self.reading)?;
        self.truth.port = Some(truth);
        Ok(self)
    }
}
