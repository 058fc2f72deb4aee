//! One interface for the radial-profile forward models, so that the fit, the study and `measure` can
//! take any of them: the classical dipole ([`crate::dipole::Dipole`], Jensen et al. 2001), the better
//! dipole ([`crate::better_dipole::BetterDipole`], d'Eon 2012), photon beam diffusion
//! ([`crate::pbd::Pbd`], Habel et al. 2013 as pbrt-v4 evaluates it) and, in the `mc` crate, the Monte
//! Carlo tables (`scatterfit_mc::McProfile`).
//!
//! [`DiffusionModel`] names the three diffusion models and gives each one's total diffuse reflectance
//! Rd(α′, η) and its inverse α′(Rd, η) — the spectrophotometer's albedo "by the same physics".

use std::fmt;
use std::str::FromStr;

pub use crate::dipole::ProfileSample;
use crate::error::{OpticsError, Result};
use crate::properties::OpticalProperties;
use crate::{better_dipole, dipole, pbd};

/// A radially resolved diffuse reflectance model Rd(r) of a half-space for one set of optical
/// properties (built per parameter set, like [`crate::dipole::Dipole::new`]).
pub trait ProfileModel {
    /// Rd(r) [mm⁻²] at radius `r_mm` ≥ 0 [mm] from the point of incidence.
    fn rd(&self, r_mm: f64) -> f64;
    /// Rd and its partial derivatives ∂Rd/∂σ′s, ∂Rd/∂σa at every radius of `radii_mm`, written to
    /// `out` (the shorter of the two sets the count). Derivatives are analytic (never finite
    /// differences). The hot path of the fit: one call per Levenberg–Marquardt iteration.
    fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]);
    /// Total diffuse reflectance ∫₀^∞ 2πr Rd(r) dr [1] (excluding the specular reflection).
    fn rd_total(&self) -> f64;
}

impl ProfileModel for dipole::Dipole {
    fn rd(&self, r_mm: f64) -> f64 {
        dipole::Dipole::rd(self, r_mm)
    }
    fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]) {
        dipole::Dipole::profile_with_derivatives_into(self, radii_mm, out);
    }
    fn rd_total(&self) -> f64 {
        dipole::Dipole::rd_total(self)
    }
}

/// The diffusion forward models by name (the `model =` / `--model` values except `mc`, which lives in
/// the `mc` crate).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum DiffusionModel {
    /// Classical dipole, Jensen et al. 2001 (the paper's model): `dipole`.
    Dipole,
    /// d'Eon 2012 "A better dipole" (physics.md §3): `better-dipole`.
    BetterDipole,
    /// Photon beam diffusion, Habel et al. 2013, as pbrt-v4 evaluates it (physics.md §2), g = 0:
    /// `pbd`.
    Pbd,
}

impl DiffusionModel {
    /// Every diffusion model, in the order of the docs.
    pub const ALL: [DiffusionModel; 3] = [Self::Dipole, Self::BetterDipole, Self::Pbd];

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Dipole => "dipole",
            Self::BetterDipole => "better-dipole",
            Self::Pbd => "pbd",
        }
    }

    /// The model for `props`.
    ///
    /// # Errors
    /// `InvalidParameter` where the model does not cover η (better dipole and PBD: η ≤ 2.5).
    pub fn profile(self, props: &OpticalProperties) -> Result<AnyDiffusion> {
        Ok(match self {
            Self::Dipole => AnyDiffusion::Dipole(dipole::Dipole::new(props)),
            Self::BetterDipole => {
                AnyDiffusion::BetterDipole(better_dipole::BetterDipole::new(props)?)
            }
            Self::Pbd => AnyDiffusion::Pbd(Box::new(pbd::Pbd::new(props)?)),
        })
    }

    /// Total diffuse reflectance Rd(α′, η) of this model (closed form for the dipoles, quadrature for
    /// PBD).
    ///
    /// # Errors
    /// `InvalidParameter` for α′ outside [0, 1] or η outside the model's range.
    pub fn rd_total(self, albedo_prime: f64, eta: f64) -> Result<f64> {
        match self {
            Self::Dipole => {
                better_dipole::check_albedo(albedo_prime)?;
                crate::error::eta_at_least_one(eta)?;
                Ok(dipole::rd_total(albedo_prime, eta))
            }
            Self::BetterDipole => better_dipole::rd_total(albedo_prime, eta),
            Self::Pbd => pbd::rd_total(albedo_prime, eta),
        }
    }

    /// The reduced albedo α′ whose total diffuse reflectance is `rd` at η (the inverse of
    /// [`DiffusionModel::rd_total`], monotonic for every model).
    ///
    /// # Errors
    /// `RdOutOfRange`/`RdOutOfModelRange` for an Rd the model cannot produce, `InvalidParameter` for
    /// η outside the model's range.
    pub fn albedo_from_rd(self, rd: f64, eta: f64) -> Result<f64> {
        match self {
            Self::Dipole => dipole::albedo_from_rd(rd, eta),
            Self::BetterDipole => better_dipole::albedo_from_rd(rd, eta),
            Self::Pbd => pbd::albedo_from_rd(rd, eta),
        }
    }
}

impl fmt::Display for DiffusionModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for DiffusionModel {
    type Err = OpticsError;
    fn from_str(s: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| OpticsError::UnknownModel(s.to_owned()))
    }
}

/// One of the diffusion models, built for one parameter set ([`DiffusionModel::profile`]).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum AnyDiffusion {
    /// Classical dipole.
    Dipole(dipole::Dipole),
    /// Better dipole.
    BetterDipole(better_dipole::BetterDipole),
    /// Photon beam diffusion (boxed: it holds its 100 depth samples).
    Pbd(Box<pbd::Pbd>),
}

impl ProfileModel for AnyDiffusion {
    fn rd(&self, r_mm: f64) -> f64 {
        match self {
            Self::Dipole(m) => ProfileModel::rd(m, r_mm),
            Self::BetterDipole(m) => ProfileModel::rd(m, r_mm),
            Self::Pbd(m) => ProfileModel::rd(m.as_ref(), r_mm),
        }
    }
    fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]) {
        match self {
            Self::Dipole(m) => m.profile_with_derivatives_into(radii_mm, out),
            Self::BetterDipole(m) => ProfileModel::profile_with_derivatives_into(m, radii_mm, out),
            Self::Pbd(m) => ProfileModel::profile_with_derivatives_into(m.as_ref(), radii_mm, out),
        }
    }
    fn rd_total(&self) -> f64 {
        match self {
            Self::Dipole(m) => ProfileModel::rd_total(m),
            Self::BetterDipole(m) => ProfileModel::rd_total(m),
            Self::Pbd(m) => ProfileModel::rd_total(m.as_ref()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_is_refused() {
        for m in DiffusionModel::ALL {
            assert_eq!(m.name().parse::<DiffusionModel>().unwrap(), m);
        }
        let e = "dipol".parse::<DiffusionModel>().unwrap_err().to_string();
        assert!(e.contains("dipole, better-dipole, pbd"), "{e}");
    }

    /// The trait delegates to the dipole's own methods: same numbers.
    #[test]
    fn dipole_through_trait_is_unchanged() {
        let p = OpticalProperties::new(1.2, 0.03, 1.4).unwrap();
        let d = dipole::Dipole::new(&p);
        let any = DiffusionModel::Dipole.profile(&p).unwrap();
        let radii = [0.1, 1.0, 5.0];
        let mut out = [ProfileSample {
            rd: 0.0,
            d_sigma_s_prime: 0.0,
            d_sigma_a: 0.0,
        }; 3];
        any.profile_with_derivatives_into(&radii, &mut out);
        for (r, o) in radii.iter().zip(&out) {
            assert_eq!(any.rd(*r), d.rd(*r));
            assert_eq!(o.rd, d.rd_with_derivatives(*r).rd);
        }
        assert_eq!(any.rd_total(), d.rd_total());
        assert_eq!(
            DiffusionModel::Dipole.rd_total(0.9, 1.4).unwrap(),
            dipole::rd_total(0.9, 1.4)
        );
    }
}
