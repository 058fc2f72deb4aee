//! The spectrophotometer stage of Choi, Lee & Chin (2014, §3.2): a d/8 instrument's SCI and SCE
//! spectra (and optionally its L\*a\*b\*) → the refractive index η and, per linear-sRGB channel, the
//! diffuse reflectance Rd and the reduced albedo α′.
//!
//! - **η**: the specular reflectance is SCI − SCE (the light trap of a d/8 sphere removes the mirror
//!   reflection of the 8° viewing beam; docs/physics.md §5). Per wavelength and as a summary: the
//!   summary uses the luminance-weighted mean specular reflectance Σ W_Y(λ)(SCI − SCE)(λ) / Σ W_Y
//!   (D65, 2°), inverted through Schlick's approximation at 8° (the paper's method); the
//!   exact-Fresnel inversion is reported beside it. Per channel: the specular spectrum's linear
//!   sRGB, inverted the same way.
//! - **Colour**: the SCE spectrum (the diffuse part) → XYZ (ASTM E308, both observers) → L\*a\*b\* and
//!   linear sRGB (2°). A measured L\*a\*b\* replaces the spectrum for Rd when given.
//! - **α′**: per channel, the inverse of the dipole's total diffuse reflectance Rd(α′, η)
//!   ([`crate::dipole::albedo_from_rd`]; Choi et al. eq. (1) = Jensen et al. 2001 eq. 5).

use serde::Serialize;

use crate::colour::{self, Lab, Observer, Xyz};
use crate::dipole;
use crate::error::{OpticsError, Result};
use crate::fresnel::{self, D8_VIEWING_ANGLE_DEG};

/// A per-channel η spread above this is reported as significant dispersion. SCI − SCE repeatability of
/// about 0.1 % reflectance already moves η by ≈ 0.01 near η = 1.5, so smaller spreads are noise.
pub const DISPERSION_THRESHOLD: f64 = 0.02;

/// Summary specular reflectances below this give η < 1.22; docs/physics.md §5 caveat (1): on
/// semi-gloss or rough surfaces part of the specular lobe escapes the light trap, so SCI − SCE
/// underestimates R₀.
pub const LOW_SPECULAR_WARNING: f64 = 0.01;

/// Summary specular reflectances above this (η > 3) are not plausible for a dielectric.
pub const MAX_PLAUSIBLE_SPECULAR: f64 = 0.25;

/// One spectrophotometer reading: SCI and SCE reflectance spectra as fractions (0–1). Made through
/// [`SpectroReading::new`], so its three columns have one length, its wavelengths increase and its
/// reflectances are fractions.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectroReading {
    wavelengths_nm: Vec<f64>,
    sci: Vec<f64>,
    sce: Vec<f64>,
}

impl SpectroReading {
    /// A reading from its wavelengths \[nm\] and the SCI and SCE reflectances at them (fractions).
    ///
    /// # Errors
    /// [`OpticsError::Spectrum`] when the lengths differ, there are fewer than two wavelengths, a
    /// wavelength is not finite and > 0 or does not increase, or a reflectance is not in [0, 1].
    pub fn new(wavelengths_nm: Vec<f64>, sci: Vec<f64>, sce: Vec<f64>) -> Result<Self> {
        if sci.len() != wavelengths_nm.len() || sce.len() != wavelengths_nm.len() {
            return Err(OpticsError::Spectrum(format!(
                "{} wavelengths, {} SCI and {} SCE values; every wavelength needs both",
                wavelengths_nm.len(),
                sci.len(),
                sce.len()
            )));
        }
        if wavelengths_nm.len() < 2 {
            return Err(OpticsError::Spectrum(format!(
                "{} wavelength(s); a spectrum needs at least two",
                wavelengths_nm.len()
            )));
        }
        if let Some(w) = wavelengths_nm
            .iter()
            .find(|w| !(w.is_finite() && **w > 0.0))
        {
            return Err(OpticsError::Spectrum(format!(
                "wavelength {w} nm is not a positive number"
            )));
        }
        if let Some(pair) = wavelengths_nm.windows(2).find(|p| p[1] <= p[0]) {
            return Err(OpticsError::Spectrum(format!(
                "wavelengths must increase: {} nm follows {} nm",
                pair[1], pair[0]
            )));
        }
        for (name, values) in [("SCI", &sci), ("SCE", &sce)] {
            if let Some(v) = values.iter().find(|v| !(0.0..=1.0).contains(*v)) {
                return Err(OpticsError::Spectrum(format!(
                    "{name} reflectance {v:.4e} is not a fraction in [0, 1]"
                )));
            }
        }
        Ok(Self {
            wavelengths_nm,
            sci,
            sce,
        })
    }

    /// Wavelengths \[nm\], strictly increasing.
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelengths_nm
    }

    /// Specular component included reflectance (fraction) per wavelength.
    pub fn sci(&self) -> &[f64] {
        &self.sci
    }

    /// Specular component excluded reflectance (fraction) per wavelength.
    pub fn sce(&self) -> &[f64] {
        &self.sce
    }
}

/// Options of the spectrophotometer stage.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SpectroOptions {
    /// A measured L\*a\*b\* (D65) used for the colour instead of the SCE spectrum, and its observer.
    pub lab: Option<(Lab, Observer)>,
    /// A known η that replaces the one measured from SCI − SCE (e.g. for matte samples).
    pub eta: Option<f64>,
}

/// η at one wavelength.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpectralPoint {
    /// Wavelength \[nm\].
    pub wavelength_nm: f64,
    /// SCI (fraction).
    pub sci: f64,
    /// SCE (fraction).
    pub sce: f64,
    /// SCI − SCE.
    pub specular: f64,
    /// η from Schlick at 8°, `None` where SCI − SCE ≤ 0.
    pub eta: Option<f64>,
}

/// Where the summary η came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EtaSource {
    /// Measured: Schlick inversion of the luminance-weighted SCI − SCE.
    SchlickSciMinusSce,
    /// Given by the user.
    Given,
}

/// Where Rd per channel came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ColourSource {
    /// The SCE spectrum (2° observer).
    SceSpectrum,
    /// A measured L\*a\*b\* with the 2° observer.
    Lab2,
    /// A measured L\*a\*b\* with the 10° observer (Bradford-adapted to the 2° white).
    Lab10,
}

/// One linear-sRGB channel's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelResult {
    /// Diffuse reflectance Rd (linear sRGB, fraction).
    pub rd_total: f64,
    /// Reduced albedo α′, `None` when Rd is outside (0, 1] (see `problem`).
    pub albedo_prime: Option<f64>,
    /// η of this channel from the specular spectrum's linear sRGB (Schlick at 8°), if positive.
    pub eta_channel: Option<f64>,
    /// Why α′ could not be computed.
    pub problem: Option<String>,
}

/// The result of the spectrophotometer stage.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpectroAnalysis {
    /// Summary η used for α′.
    pub eta: f64,
    /// Where it came from.
    pub eta_source: EtaSource,
    /// The luminance-weighted mean SCI − SCE (400–700 nm, D65, 2°).
    pub specular_mean: f64,
    /// η from the same specular reflectance through the exact Fresnel equations at 8°.
    pub eta_exact_fresnel: Option<f64>,
    /// Whether the per-channel η spread exceeds [`DISPERSION_THRESHOLD`].
    pub dispersion_significant: bool,
    /// Per wavelength: SCI, SCE, SCI − SCE, η.
    pub spectral: Vec<SpectralPoint>,
    /// XYZ of the SCE spectrum, 2° observer (Y = 100).
    pub xyz_2deg: Xyz,
    /// L\*a\*b\* of the SCE spectrum, D65, 2°.
    pub lab_2deg: Lab,
    /// XYZ of the SCE spectrum, 10° observer (Y = 100).
    pub xyz_10deg: Xyz,
    /// L\*a\*b\* of the SCE spectrum, D65, 10°.
    pub lab_10deg: Lab,
    /// Where Rd came from.
    pub colour_source: ColourSource,
    /// Per channel R, G, B (linear sRGB); in JSON an object keyed `"r"`, `"g"`, `"b"` like every
    /// other result file of scatterfit.
    #[serde(serialize_with = "rgb_keyed")]
    pub channels: [ChannelResult; 3],
    /// Things the user should know (low specular, negative SCI − SCE at some wavelengths, …).
    pub warnings: Vec<String>,
}

/// Serialises three per-channel values as `{"r": …, "g": …, "b": …}`.
fn rgb_keyed<S: serde::Serializer, T: Serialize>(
    v: &[T; 3],
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut m = s.serialize_map(Some(3))?;
    for (k, x) in ["r", "g", "b"].iter().zip(v) {
        m.serialize_entry(k, x)?;
    }
    m.end()
}

impl SpectroAnalysis {
    /// True when every channel has an α′.
    pub fn complete(&self) -> bool {
        self.channels.iter().all(|c| c.albedo_prime.is_some())
    }
}

/// Runs the spectrophotometer stage on a reading.
///
/// # Errors
/// [`OpticsError::Spectrum`] for spectra that do not cover 400–700 nm; [`OpticsError::Specular`] when
/// no η was given and SCI − SCE is ≤ 0 or implausibly large on average;
/// [`OpticsError::InvalidParameter`] for a given η < 1. Channels whose Rd cannot be inverted are not
/// errors: they carry `albedo_prime: None` and a `problem`.
pub fn analyse(reading: &SpectroReading, options: &SpectroOptions) -> Result<SpectroAnalysis> {
    let wl = reading.wavelengths_nm();
    if reading.sci.len() != wl.len() || reading.sce.len() != wl.len() {
        return Err(OpticsError::Spectrum(format!(
            "{} wavelengths, {} SCI and {} SCE values",
            wl.len(),
            reading.sci.len(),
            reading.sce.len()
        )));
    }
    let specular: Vec<f64> = reading
        .sci
        .iter()
        .zip(&reading.sce)
        .map(|(i, e)| i - e)
        .collect();
    let mut warnings = Vec::new();

    // Specular reflectance per wavelength and its luminance-weighted mean.
    let spec_grid = colour::resample_to_weight_grid(wl, &specular)?;
    let spec_xyz = colour::weighted_sum(&spec_grid, Observer::TwoDegree);
    let specular_mean = spec_xyz.y / Observer::TwoDegree.d65_white().y;
    let spectral: Vec<SpectralPoint> = (0..wl.len())
        .map(|i| SpectralPoint {
            wavelength_nm: wl[i],
            sci: reading.sci[i],
            sce: reading.sce[i],
            specular: specular[i],
            eta: fresnel::eta_from_specular_schlick(specular[i], D8_VIEWING_ANGLE_DEG).ok(),
        })
        .collect();
    let in_range = |p: &&SpectralPoint| (400.0..=700.0).contains(&p.wavelength_nm);
    let non_positive: Vec<&SpectralPoint> = spectral
        .iter()
        .filter(in_range)
        .filter(|p| p.specular <= 0.0)
        .collect();
    if let Some(worst) = non_positive
        .iter()
        .min_by(|a, b| a.specular.total_cmp(&b.specular))
    {
        warnings.push(format!(
            "SCI − SCE ≤ 0 at {} of the wavelengths in 400–700 nm (lowest {:.5} at {} nm): η is \
             undefined there; within noise this means a very weak specular reflection",
            non_positive.len(),
            worst.specular,
            worst.wavelength_nm
        ));
    }

    // Summary η: measured (Schlick, the paper's method) unless given.
    let measured = fresnel::eta_from_specular_schlick(specular_mean, D8_VIEWING_ANGLE_DEG);
    let (eta, eta_source) = match options.eta {
        Some(given) => {
            crate::error::eta_at_least_one(given)?;
            (given, EtaSource::Given)
        }
        None => {
            if specular_mean <= 0.0 {
                return Err(OpticsError::Specular {
                    specular: specular_mean,
                    reason: "the sample shows no specular reflection on average over 400–700 nm \
                             (a matte surface, or the SCI and SCE columns swapped?); η cannot be \
                             measured this way — give it (e.g. --eta 1.5)",
                });
            }
            if specular_mean > MAX_PLAUSIBLE_SPECULAR {
                return Err(OpticsError::Specular {
                    specular: specular_mean,
                    reason: "more than 25 % specular reflection means η > 3, implausible for a \
                             dielectric (a metal, a mis-calibration, or percent values read as \
                             fractions?); check the reading or give η",
                });
            }
            (measured?, EtaSource::SchlickSciMinusSce)
        }
    };
    if eta_source == EtaSource::SchlickSciMinusSce && specular_mean < LOW_SPECULAR_WARNING {
        warnings.push(format!(
            "SCI − SCE is only {:.4} (η = {eta:.4}): on semi-gloss or rough surfaces part of the \
             specular lobe escapes the light trap, so η is likely underestimated",
            specular_mean
        ));
    }
    let eta_exact_fresnel =
        fresnel::eta_from_specular_exact(specular_mean, D8_VIEWING_ANGLE_DEG).ok();

    // Per-channel η from the specular spectrum's linear sRGB.
    let spec_rgb = colour::xyz_to_linear_srgb(spec_xyz);
    let eta_channel: Vec<Option<f64>> = spec_rgb
        .iter()
        .map(|&s| fresnel::eta_from_specular_schlick(s, D8_VIEWING_ANGLE_DEG).ok())
        .collect();
    let known: Vec<f64> = eta_channel.iter().flatten().copied().collect();
    let dispersion_significant = known.len() == 3
        && known.iter().copied().fold(f64::MIN, f64::max)
            - known.iter().copied().fold(f64::MAX, f64::min)
            > DISPERSION_THRESHOLD;
    if dispersion_significant {
        warnings.push(format!(
            "η differs between channels by more than {DISPERSION_THRESHOLD} (R {:.4}, G {:.4}, B {:.4}); \
             the summary η is used for α′, the per-channel values are reported",
            known[0], known[1], known[2]
        ));
    }

    // Colour of the diffuse part (SCE), both observers.
    let xyz_2deg = colour::spectrum_to_xyz(wl, &reading.sce, Observer::TwoDegree)?;
    let xyz_10deg = colour::spectrum_to_xyz(wl, &reading.sce, Observer::TenDegree)?;
    let lab_2deg = colour::xyz_to_lab(xyz_2deg, Observer::TwoDegree.d65_white());
    let lab_10deg = colour::xyz_to_lab(xyz_10deg, Observer::TenDegree.d65_white());
    let (rd, colour_source) = match options.lab {
        None => (
            colour::xyz_to_linear_srgb(xyz_2deg),
            ColourSource::SceSpectrum,
        ),
        Some((lab, observer)) => (
            colour::lab_to_linear_srgb(lab, observer),
            match observer {
                Observer::TwoDegree => ColourSource::Lab2,
                Observer::TenDegree => ColourSource::Lab10,
            },
        ),
    };

    let names = ["R", "G", "B"];
    let channels: [ChannelResult; 3] = std::array::from_fn(|c| {
        let (albedo_prime, problem) = match dipole::albedo_from_rd(rd[c], eta) {
            Ok(a) => (Some(a), None),
            Err(e) => (None, Some(format!("channel {}: {e}", names[c]))),
        };
        ChannelResult {
            rd_total: rd[c],
            albedo_prime,
            eta_channel: eta_channel[c],
            problem,
        }
    });

    Ok(SpectroAnalysis {
        eta,
        eta_source,
        specular_mean,
        eta_exact_fresnel,
        dispersion_significant,
        spectral,
        xyz_2deg,
        lab_2deg,
        xyz_10deg,
        lab_10deg,
        colour_source,
        channels,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> Vec<f64> {
        (0..31).map(|i| 400.0 + 10.0 * i as f64).collect()
    }

    /// A spectrally flat reading at 400–700 nm.
    fn flat(sci: f64, sce: f64) -> SpectroReading {
        SpectroReading::new(grid(), vec![sci; 31], vec![sce; 31]).unwrap()
    }

    /// A sample of η = 1.5 (flat R₀ = 0.04 at 8°) with a flat SCE of 0.5: η comes back, and α′ per
    /// channel inverts Rd = 0.5 at η = 1.5 (a grey: R = G = B up to the sRGB matrix's rounding).
    #[test]
    fn flat_specular_gives_eta_and_grey_albedo() {
        let wl = grid();
        let r0 = fresnel::fresnel_dielectric(8f64.to_radians().cos(), 1.5);
        let reading = SpectroReading::new(wl, vec![0.5 + r0; 31], vec![0.5; 31]).unwrap();
        let a = analyse(&reading, &SpectroOptions::default()).unwrap();
        // Schlick inversion of an exact-Fresnel specular: 1.5 to within Schlick's error at 8°.
        assert!((a.eta - 1.5).abs() < 2e-4, "{}", a.eta);
        assert!((a.eta_exact_fresnel.unwrap() - 1.5).abs() < 1e-9);
        assert!(!a.dispersion_significant);
        let want = dipole::albedo_from_rd(0.5, a.eta).unwrap();
        for ch in &a.channels {
            assert!((ch.rd_total - 0.5).abs() < 2e-4, "{}", ch.rd_total);
            assert!((ch.albedo_prime.unwrap() - want).abs() < 1e-4);
        }
        assert!(a.warnings.is_empty(), "{:?}", a.warnings);
        assert!(a.complete());
    }

    /// A given L*a*b* replaces the spectrum for Rd; 10° goes through Bradford.
    #[test]
    fn lab_overrides_spectrum_colour() {
        let reading = flat(0.54, 0.5);
        let lab = Lab {
            l: 60.0,
            a: 20.0,
            b: -30.0,
        };
        let opts = SpectroOptions {
            lab: Some((lab, Observer::TwoDegree)),
            eta: None,
        };
        let a = analyse(&reading, &opts).unwrap();
        assert_eq!(a.colour_source, ColourSource::Lab2);
        // docs/physics.md §6.2 with the ASTM 2° white.
        for (ch, want) in a.channels.iter().zip([0.319066, 0.241743, 0.561175]) {
            assert!((ch.rd_total - want).abs() < 2e-5);
        }
    }

    #[test]
    fn no_or_huge_specular_is_an_error_unless_eta_given() {
        let swapped = flat(0.5, 0.52);
        let err = analyse(&swapped, &SpectroOptions::default()).unwrap_err();
        assert!(err.to_string().contains("swapped"), "{err}");
        let given = SpectroOptions {
            eta: Some(1.4),
            ..Default::default()
        };
        let a = analyse(&swapped, &given).unwrap();
        assert_eq!(a.eta, 1.4);
        assert!(a.warnings.iter().any(|w| w.contains("≤ 0")));
        let metal = flat(0.9, 0.3);
        assert!(analyse(&metal, &SpectroOptions::default()).is_err());
    }

    /// A saturated colour outside the sRGB gamut gives a channel problem, not a clamped number.
    #[test]
    fn out_of_gamut_channel_is_reported() {
        let reading = flat(0.54, 0.5);
        // Very saturated green: linear sRGB red and blue < 0.
        let lab = Lab {
            l: 60.0,
            a: -90.0,
            b: 80.0,
        };
        let opts = SpectroOptions {
            lab: Some((lab, Observer::TwoDegree)),
            eta: None,
        };
        let a = analyse(&reading, &opts).unwrap();
        assert!(!a.complete());
        let bad = a
            .channels
            .iter()
            .find(|c| c.albedo_prime.is_none())
            .unwrap();
        assert!(bad.rd_total <= 0.0 && bad.problem.as_ref().unwrap().contains("channel"));
    }

    /// Low specular reflectance is flagged as a likely underestimate of η.
    #[test]
    fn low_specular_warns() {
        let reading = flat(0.505, 0.5);
        let a = analyse(&reading, &SpectroOptions::default()).unwrap();
        assert!(
            a.warnings.iter().any(|w| w.contains("underestimated")),
            "{:?}",
            a.warnings
        );
    }
}
