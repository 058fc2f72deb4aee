//! Stage 3½: the spectrophotometer port's edge loss, corrected from the measurement
//! itself.
//!
//! A d/8 instrument lights a disc and measures through a concentric aperture; light that enters
//! inside the lit disc and leaves beyond the aperture is lost, so it reads F·Rd with F < 1 for a
//! material whose light travels millimetres (`scatterfit_optics::port`, docs/physics.md §12).
//! The fit gives the length scale: starting from the reading, each round fits the channel, takes F
//! of the fitted material through the same port from the fit's forward model
//! ([`Port::reading_of`]), sets Rd = Rd_read / F, inverts α′ again with the albedo model, and refits,
//! until Rd moves by less than 10⁻⁶ relatively (a fixed point: F depends on σ′t, which α′ moves
//! only slightly, so it converges in a few rounds). The correction is only as exact as the forward
//! model: with `--model mc` the profile is exact transport's; with a diffusion model it carries
//! that model's near-source error.

use scatterfit_fit::{ChannelInput, ProfileData};
use scatterfit_optics::port::Port;
use scatterfit_optics::{Channel, ModelFamily, OpticalProperties, Rgb};
use serde::Serialize;

use crate::settings::FitPlan;
use crate::spectro::SpectroStage;

mod fit_term;

pub use fit_term::propagate_fit_through_port;

/// Rounds before giving up on a channel (it converges in 3–10 on the rig twin).
const MAX_ROUNDS: usize = 60;

/// Relative change of Rd between rounds that ends the iteration.
const TOLERANCE: f64 = 1e-6;

/// What the port correction did, per channel.
#[derive(Debug, Clone, Serialize)]
pub struct PortCorrection {
    /// Diameter of the lit disc \[mm\].
    pub illuminated_mm: f64,
    /// Diameter of the measured aperture \[mm\].
    pub aperture_mm: f64,
    /// The stage as read, before the correction (a refit with another model starts again here).
    #[serde(skip)]
    pub read: SpectroStage,
    /// F per channel: the fraction of the true Rd the instrument read (`None` where the channel
    /// could not be fitted, and its Rd was left as read).
    pub reading_fraction: Rgb<Option<f64>>,
    /// Rounds of fit → F → α′ per channel (beyond `MAX_ROUNDS` = 60 the iteration did not settle
    /// and the rest are the bracketed solve's fits).
    pub rounds: Rgb<usize>,
    /// Why a channel was left uncorrected.
    pub problems: Rgb<Option<String>>,
    /// Per corrected channel, the fixed point again with F taken from the fitted σ′s × (1 ∓ s),
    /// s its relative standard error from the profile's noise: how the fit's error moves the
    /// corrected Rd ([`propagate_fit_through_port`] turns it into the fit terms).
    #[serde(skip)]
    pub fit_pm: Rgb<Option<FitThroughPort>>,
}

/// A channel's corrected Rd when the fit's σ′s is one standard error low and high (see
/// [`PortCorrection::fit_pm`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitThroughPort {
    /// The factors on the fitted σ′s (and σa, α′ fixed) that F was taken at: 1 ∓ s.
    pub scale: [f64; 2],
    /// The corrected Rd of the reading at each.
    pub rd: [f64; 2],
}

/// The port of the manifest's `spectro.aperture_mm` / `spectro.illuminated_mm` (`None` when no
/// aperture is given: the reading is then taken as loss-free).
///
/// # Errors
/// A diameter the port refuses (the manifest checks both before).
pub fn port_of(
    aperture_mm: Option<f64>,
    illuminated_mm: Option<f64>,
) -> crate::error::Result<Option<Port>> {
    let Some(aperture) = aperture_mm else {
        return Ok(None);
    };
    Port::new(illuminated_mm.unwrap_or(aperture), aperture)
        .map(Some)
        .map_err(|e| crate::error::PipelineError::Input(format!("the spectrophotometer port: {e}")))
}

/// Corrects the stage's Rd (hence α′ and its uncertainty) for the port's edge loss, by iterating
/// fit ↔ F per channel (module docs). Returns the corrected stage and what was done; a channel
/// that cannot be fitted keeps its reading, with the reason.
///
/// The reading's uncertainty goes through the same fixed point: the readings × (1 ∓ ε) at η∓
/// (`SpectroUncertainty::rd_pm`, `eta_pm`) are corrected too, and their corrected Rd become the
/// stage's perturbed readings, from which α′'s standard error and the refits of the spectro term
/// follow. This matters: F falls as α′ rises (the light spreads further), so the corrected Rd
/// moves more than the reading — by A = (d ln Rd/d ln(1 − α′)) / (d ln(Rd·F)/d ln(1 − α′)),
/// 2–4 for an 8 mm port at α′ ≥ 0.996 (BENCHMARKS.md, "The port's conditioning") — and a bar
/// computed from the corrected Rd as if it were a loss-free reading would be that much too small.
pub fn correct_port(
    data: &Rgb<ProfileData>,
    read: &SpectroStage,
    plan: &FitPlan,
    port: Port,
) -> (SpectroStage, PortCorrection) {
    let (model, albedo): (&dyn ModelFamily, &dyn ModelFamily) = (&plan.model, &plan.albedo);
    let mut fraction = Rgb::from_fn(|_| None);
    let mut rounds = Rgb::from_fn(|_| 0);
    let mut problems: Rgb<Option<String>> = Rgb::from_fn(|_| None);
    let mut rd = read.rd;
    let mut rd_pm: Rgb<Option<[f64; 2]>> = Rgb::default();
    let mut fit_pm: Rgb<Option<FitThroughPort>> = Rgb::default();
    let mut warnings = Vec::new();
    let u = &read.uncertainty;
    for ch in Channel::ALL {
        let point = FixedPoint {
            data: &data[ch],
            opts: &plan.options,
            model,
            albedo,
            port,
        };
        match point.solve(read.rd[ch], read.eta, 1.0) {
            Ok(solved) => {
                rd[ch] = solved.rd;
                fraction[ch] = Some(solved.reading_fraction);
                rounds[ch] = solved.rounds;
                let s = solved.sigma_s_prime_rel_stderr;
                if s.is_finite() && s > 0.0 && s < 0.5 {
                    let scale = [1.0 - s, 1.0 + s];
                    let pm: Result<Vec<f64>, (usize, String)> = scale
                        .iter()
                        .map(|&k| point.solve(read.rd[ch], read.eta, k).map(|s| s.rd))
                        .collect();
                    match pm {
                        Ok(pm) => {
                            fit_pm[ch] = Some(FitThroughPort {
                                scale,
                                rd: [pm[0], pm[1]],
                            });
                        }
                        Err((_, e)) => warnings.push(format!(
                            "channel {}: the port correction with the fitted σ′s ± its standard \
                             error failed ({e}), so the fit's error is not carried through the \
                             port's F and the fit terms understate it",
                            ch.name()
                        )),
                    }
                }
                if u.repeatability > 0.0 {
                    let pm: Result<Vec<f64>, (usize, String)> = (0..2)
                        .map(|k| point.solve(u.rd_pm[ch][k], u.eta_pm[k], 1.0).map(|s| s.rd))
                        .collect();
                    // Without the perturbed fixed points the stage keeps ε on the corrected Rd,
                    // which understates the bar (see above); the warning says so.
                    match pm {
                        Ok(pm) => rd_pm[ch] = Some([pm[0], pm[1]]),
                        Err((_, e)) => warnings.push(format!(
                            "channel {}: the port correction of the reading ± its repeatability \
                             failed ({e}), so its spectro uncertainty is the loss-free one's, \
                             which understates it",
                            ch.name()
                        )),
                    }
                }
            }
            Err((round, e)) => {
                rounds[ch] = round;
                problems[ch] = Some(e);
            }
        }
    }
    let mut corrected = read.with_corrected_rd(rd, rd_pm, albedo);
    corrected.warnings.extend(warnings);
    let correction = PortCorrection {
        illuminated_mm: port.illuminated_mm(),
        aperture_mm: port.aperture_mm(),
        read: read.clone(),
        reading_fraction: fraction,
        rounds,
        problems,
        fit_pm,
    };
    (corrected, correction)
}

/// One channel's fit ↔ F iteration (see [`correct_port`]).
struct FixedPoint<'a> {
    data: &'a ProfileData,
    opts: &'a scatterfit_fit::FitOptions,
    model: &'a dyn ModelFamily,
    albedo: &'a dyn ModelFamily,
    port: Port,
}

/// A converged [`FixedPoint`].
struct Solved {
    /// The corrected Rd, reading / F.
    rd: f64,
    /// F of the last round's fit.
    reading_fraction: f64,
    /// Rounds taken.
    rounds: usize,
    /// The last round's fit: σ′s's standard error over its value (the profile's noise).
    sigma_s_prime_rel_stderr: f64,
}

impl FixedPoint<'_> {
    /// The corrected Rd of a reading `rd_read` at η = `eta`, F taken at the fitted σ′s and σa ×
    /// `scale` (1: the fit as it is; 1 ∓ s: a fit one standard error off, α′ unchanged); on
    /// failure the round it stopped in and why.
    ///
    /// The fixed point first (fast: 3–10 fits); where it does not settle — at α′ → 1 behind a
    /// port much smaller than the lit disc, F changes faster with Rd than Rd itself and the
    /// iteration cycles, or a round's step leaves the albedo model's range — the same equation
    /// Rd(α′)·F(α′) = reading is solved on a bracket ([`FixedPoint::bracketed`]).
    fn solve(&self, rd_read: f64, eta: f64, scale: f64) -> Result<Solved, (usize, String)> {
        self.iterate(rd_read, eta, scale)
            .or_else(|_| self.bracketed(rd_read, eta, scale))
    }

    /// The port's reading of the material that the profile gives at α′: the fit at α′ (with the
    /// albedo model's Rd(α′) as the total), its σ′s and σa × `scale`, and F of that material
    /// through the port. Returns (Rd(α′), F, the fit's relative σ′s standard error).
    fn reading_at(
        &self,
        albedo_prime: f64,
        eta: f64,
        scale: f64,
    ) -> Result<(f64, f64, f64), String> {
        let rd = self
            .albedo
            .rd_total(albedo_prime, eta, 0.0)
            .map_err(|e| e.to_string())?;
        let input = ChannelInput {
            eta,
            albedo_prime: Some(albedo_prime),
            rd_total: Some(rd),
        };
        let report = match scatterfit_fit::fit_channel(self.data, &input, self.model, self.opts) {
            Ok(r) if r.converged => r,
            Ok(_) => {
                return Err(format!(
                    "the fit at α′ = {albedo_prime:.6} did not converge"
                ));
            }
            Err(e) => return Err(e.to_string()),
        };
        let f = OpticalProperties::new(
            scale * report.sigma_s_prime.value,
            scale * report.sigma_a.value,
            eta,
        )
        .and_then(|p| self.model.profile(&p))
        .map(|m| self.port.reading_of(&*m).reading_fraction)
        .map_err(|e| e.to_string())?;
        if !(f.is_finite() && f > 0.0 && f <= 1.0 + 1e-9) {
            return Err(format!("the port's reading fraction {f} is not in (0, 1]"));
        }
        Ok((
            rd,
            f.min(1.0),
            report.sigma_s_prime.stderr / report.sigma_s_prime.value,
        ))
    }

    /// The port equation Rd(α′)·F(α′) = reading solved for α′ on a bracket, by the Illinois
    /// method (`scatterfit_optics::roots`) in x = ln(1 − α′), where Rd and F are smooth up to the
    /// albedo model's last α′. The bracket: the α′ of the reading taken as loss-free (F ≤ 1, so the
    /// port reads at most the reading there) and the largest α′ the albedo model inverts (a
    /// bound of the search, not a failure). Where even that α′ reads less than the reading there
    /// is no solution in the model's range, and the error says so with the numbers.
    fn bracketed(&self, rd_read: f64, eta: f64, scale: f64) -> Result<Solved, (usize, String)> {
        let fail = |e: String| (MAX_ROUNDS, e);
        let a_lo = self
            .albedo
            .albedo_from_rd(rd_read, eta, 0.0)
            .map_err(|e| fail(format!("α′ from Rd = {rd_read:.4}: {e}")))?;
        // The largest α′ the albedo model evaluates (the tables end at 0.9999, the diffusion
        // models go on).
        let a_hi = (3..=7)
            .rev()
            .map(|k| 1.0 - 10f64.powi(-k))
            .find(|&a| a > a_lo && self.albedo.rd_total(a, eta, 0.0).is_ok())
            .ok_or_else(|| {
                fail(format!(
                    "the reading's α′ ({a_lo:.6}) is already at the end of the {} albedo \
                     model's range",
                    self.albedo.name()
                ))
            })?;
        let evaluations = std::cell::Cell::new(0usize);
        let residual = |x: f64| -> f64 {
            evaluations.set(evaluations.get() + 1);
            self.reading_at(1.0 - x.exp(), eta, scale)
                .map_or(f64::NAN, |(rd, f, _)| rd * f - rd_read)
        };
        let (x_lo, x_hi) = ((1.0 - a_lo).ln(), (1.0 - a_hi).ln());
        let h_hi = residual(x_hi);
        if !h_hi.is_finite() {
            return Err(fail(format!(
                "the port correction could not be evaluated at α′ = {a_hi} (the fit or the \
                 port's F failed there)"
            )));
        }
        if h_hi < 0.0 {
            return Err(fail(format!(
                "no material the {} model describes reads Rd = {rd_read:.4} through this port: \
                 at α′ up to {a_hi} (the albedo model's range) the port reads at most {:.4}; \
                 check spectro.aperture_mm and spectro.illuminated_mm against the instrument, \
                 and the reading",
                self.model.name(),
                h_hi + rd_read
            )));
        }
        let x = scatterfit_optics::roots::bracketed_root(residual, x_lo, x_hi, 1e-10).ok_or_else(
            || {
                fail(format!(
                    "the port correction found no root between α′ {a_lo:.6} and {a_hi} (the \
                     port's reading is not continuous in α′ there)"
                ))
            },
        )?;
        let albedo_prime = 1.0 - x.exp();
        let (rd, f, s) = self.reading_at(albedo_prime, eta, scale).map_err(fail)?;
        Ok(Solved {
            rd,
            reading_fraction: f,
            rounds: MAX_ROUNDS + evaluations.get(),
            sigma_s_prime_rel_stderr: s,
        })
    }

    /// The fixed-point iteration of [`FixedPoint::solve`].
    fn iterate(&self, rd_read: f64, eta: f64, scale: f64) -> Result<Solved, (usize, String)> {
        let (model, albedo) = (self.model, self.albedo);
        let mut rd_c = rd_read;
        let mut target = rd_read;
        let mut albedo_prime = albedo
            .albedo_from_rd(rd_c, eta, 0.0)
            .map_err(|e| (0, format!("α′ from Rd = {rd_c:.4}: {e}")))?;
        for round in 1..=MAX_ROUNDS {
            let fail = |e: String| (round, e);
            let input = ChannelInput {
                eta,
                albedo_prime: Some(albedo_prime),
                rd_total: Some(rd_c),
            };
            let report = match scatterfit_fit::fit_channel(self.data, &input, model, self.opts) {
                Ok(r) if r.converged => r,
                Ok(_) => return Err(fail("the fit did not converge".into())),
                Err(e) => return Err(fail(e.to_string())),
            };
            let f = OpticalProperties::new(
                scale * report.sigma_s_prime.value,
                scale * report.sigma_a.value,
                eta,
            )
            .and_then(|p| model.profile(&p))
            .map(|m| self.port.reading_of(&*m).reading_fraction)
            .map_err(|e| fail(e.to_string()))?;
            if !(f.is_finite() && f > 0.0 && f <= 1.0 + 1e-9) {
                return Err(fail(format!(
                    "the port's reading fraction {f} is not in (0, 1]"
                )));
            }
            let f = f.min(1.0);
            target = rd_read / f;
            if ((target - rd_c) / rd_c).abs() < TOLERANCE {
                return Ok(Solved {
                    rd: rd_c,
                    reading_fraction: f,
                    rounds: round,
                    sigma_s_prime_rel_stderr: report.sigma_s_prime.stderr
                        / report.sigma_s_prime.value,
                });
            }
            // Step towards the target, halving the step while its Rd lies beyond what the albedo
            // model can invert (an early round's F, from a fit at a too-low α′, can overshoot;
            // damped, the next rounds approach the fixed point from inside the model's range).
            let mut step = target - rd_c;
            let mut next = None;
            for _ in 0..40 {
                if let Ok(a) = albedo.albedo_from_rd(rd_c + step, eta, 0.0) {
                    next = Some((rd_c + step, a));
                    break;
                }
                step *= 0.5;
            }
            let Some((rd_next, a_next)) = next else {
                return Err(fail(format!(
                    "the corrected Rd ({target:.4}) lies beyond what the {} albedo model can \
                     invert at η = {eta:.4}",
                    albedo.name(),
                )));
            };
            rd_c = rd_next;
            albedo_prime = a_next;
        }
        Err((
            MAX_ROUNDS,
            format!(
                "not converged in {MAX_ROUNDS} rounds (Rd {rd_c:.4}, the port's F asks for \
                 {target:.4}: beyond the albedo model's range?)"
            ),
        ))
    }
}

/// The measured reflectance spectrum corrected for the port's edge loss: Rd(λ) / F(λ), with F
/// interpolated linearly in wavelength between the channels' reading fractions at the wavelengths
/// where the exports take each channel (R 611, G 549, B 464 nm,
/// `scatterfit_io::export::CHANNEL_WAVELENGTHS`) and held beyond them. An approximation: F depends
/// on the transport at each wavelength, which the fit knows at the three channels only; F follows
/// the mean free path, which varies slowly across a channel's band for the materials measured.
/// `None` when a channel has no F (the spectrum is then left as read, as is that channel's Rd).
pub fn correct_spectrum(
    spectrum: &scatterfit_io::result_json::RdSpectrum,
    reading_fraction: &Rgb<Option<f64>>,
) -> Option<scatterfit_io::result_json::RdSpectrum> {
    let f = reading_fraction.transpose()?;
    // (wavelength, F) in increasing wavelength: B, G, R.
    let wl = scatterfit_io::export::CHANNEL_WAVELENGTHS;
    let nodes = [(wl[2], f.b), (wl[1], f.g), (wl[0], f.r)];
    let f_at = |lambda: f64| {
        if lambda <= nodes[0].0 {
            return nodes[0].1;
        }
        for w in nodes.windows(2) {
            let ((l0, f0), (l1, f1)) = (w[0], w[1]);
            if lambda <= l1 {
                return f0 + (f1 - f0) * (lambda - l0) / (l1 - l0);
            }
        }
        nodes[2].1
    };
    Some(scatterfit_io::result_json::RdSpectrum {
        wavelength_nm: spectrum.wavelength_nm.clone(),
        rd: spectrum
            .wavelength_nm
            .iter()
            .zip(&spectrum.rd)
            .map(|(&l, &rd)| rd / f_at(l))
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rd(λ)/F(λ) with F linear between (464, F_B), (549, F_G), (611, F_R) and held beyond: values
    /// worked by hand; no spectrum without every channel's F.
    #[test]
    fn the_spectrum_is_divided_by_the_interpolated_fraction() {
        let spectrum = scatterfit_io::result_json::RdSpectrum {
            wavelength_nm: vec![400.0, 464.0, 500.0, 549.0, 611.0, 700.0],
            rd: vec![0.5; 6],
        };
        let f = Rgb {
            r: Some(0.8),
            g: Some(0.9),
            b: Some(0.95),
        };
        let got = correct_spectrum(&spectrum, &f).unwrap();
        // At 500 nm: F = 0.95 − 0.05 · 36/85 = 0.928823…
        let want = [
            0.5 / 0.95,
            0.5 / 0.95,
            0.5 / 0.928_823_529_4,
            0.5 / 0.9,
            0.5 / 0.8,
            0.5 / 0.8,
        ];
        for (g, w) in got.rd.iter().zip(want) {
            assert!((g - w).abs() < 1e-9, "{g} vs {w}");
        }
        assert_eq!(got.wavelength_nm, spectrum.wavelength_nm);
        let missing = Rgb { g: None, ..f };
        assert!(correct_spectrum(&spectrum, &missing).is_none());
    }
}
