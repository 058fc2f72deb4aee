//! The diffusion forward models as [`ModelFamily`]s: the classical dipole
//! ([`crate::dipole::Dipole`], Jensen et al. 2001), the better dipole
//! ([`crate::better_dipole::BetterDipole`], d'Eon 2012) and photon beam diffusion ([`crate::pbd::Pbd`],
//! Habel et al. 2013 as pbrt-v4 evaluates it), each with its own total diffuse reflectance
//! Rd(α′, η, g) and its inverse α′(Rd, η, g) — the spectrophotometer's albedo "by the same physics".
//! The Monte Carlo tables are the fourth family, in the `mc` crate (`scatterfit_mc::McTableSet`).
//!
//! The traits themselves are [`crate::family`]'s, re-exported here.

pub use crate::family::{ModelFamily, ProfileModel, ProfileSample};

use crate::better_dipole::{self, BetterDipole};
use crate::diffusion::check_albedo;
use crate::dipole::{self, Dipole};
use crate::error::{Result, check_g, eta_at_least_one};
use crate::names::ModelName;
use crate::pbd::{self, Pbd};
use crate::properties::OpticalProperties;

/// The diffusion forward models (the `model =` / `--model` values except `mc`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum DiffusionModel {
    /// Classical dipole, Jensen et al. 2001 (the paper's model): `dipole`. Depends on σ′s only
    /// (g is ignored).
    Dipole,
    /// d'Eon 2012 "A better dipole" (docs/physics.md §3): `better-dipole`. Depends on σ′s only.
    BetterDipole,
    /// Photon beam diffusion, Habel et al. 2013, as pbrt-v4 evaluates it (docs/physics.md §2): `pbd`.
    /// Its single scattering uses σs = σ′s/(1 − g).
    Pbd,
}

impl DiffusionModel {
    /// Every diffusion model, in the order of the docs.
    pub const ALL: [DiffusionModel; 3] = [Self::Dipole, Self::BetterDipole, Self::Pbd];
}

impl From<DiffusionModel> for ModelName {
    fn from(m: DiffusionModel) -> Self {
        match m {
            DiffusionModel::Dipole => ModelName::Dipole,
            DiffusionModel::BetterDipole => ModelName::BetterDipole,
            DiffusionModel::Pbd => ModelName::Pbd,
        }
    }
}

impl ModelFamily for DiffusionModel {
    fn name(&self) -> ModelName {
        (*self).into()
    }

    fn profile(&self, props: &OpticalProperties) -> Result<Box<dyn ProfileModel>> {
        Ok(match self {
            Self::Dipole => Box::new(Dipole::new(props)),
            Self::BetterDipole => Box::new(BetterDipole::new(props)?),
            Self::Pbd => Box::new(Pbd::new(props)?),
        })
    }

    /// Builds the model on the stack (no heap allocation for the dipoles: this is the fit's hot
    /// path, ~47 µs per channel with the dipole).
    fn eval(&self, props: &OpticalProperties, radii_mm: &[f64], out: &mut [ProfileSample]) {
        match self {
            Self::Dipole => Dipole::new(props).profile_with_derivatives_into(radii_mm, out),
            Self::BetterDipole => match BetterDipole::new(props) {
                Ok(m) => ProfileModel::profile_with_derivatives_into(&m, radii_mm, out),
                Err(_) => out.fill(ProfileSample::NAN),
            },
            Self::Pbd => match Pbd::new(props) {
                Ok(m) => ProfileModel::profile_with_derivatives_into(&m, radii_mm, out),
                Err(_) => out.fill(ProfileSample::NAN),
            },
        }
    }

    /// Closed form for the dipoles (g ignored), quadrature for PBD.
    fn rd_total(&self, albedo_prime: f64, eta: f64, g: f64) -> Result<f64> {
        check_g(g)?;
        match self {
            Self::Dipole => {
                check_albedo(albedo_prime)?;
                eta_at_least_one(eta)?;
                Ok(dipole::rd_total(albedo_prime, eta))
            }
            Self::BetterDipole => better_dipole::rd_total(albedo_prime, eta),
            Self::Pbd => pbd::rd_total(albedo_prime, eta, g),
        }
    }

    fn albedo_from_rd(&self, rd: f64, eta: f64, g: f64) -> Result<f64> {
        check_g(g)?;
        match self {
            Self::Dipole => dipole::albedo_from_rd(rd, eta),
            Self::BetterDipole => better_dipole::albedo_from_rd(rd, eta),
            Self::Pbd => pbd::albedo_from_rd(rd, eta, g),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names: each diffusion model is its `ModelName` (the names of files and `--model`).
    #[test]
    fn names() {
        let names: Vec<&str> = DiffusionModel::ALL
            .iter()
            .map(|m| m.name().name())
            .collect();
        assert_eq!(names, ["dipole", "better-dipole", "pbd"]);
        for m in DiffusionModel::ALL {
            assert_eq!(ModelName::from(m), m.name());
        }
    }

    /// Through the family (the fit's `eval` and the boxed `profile`) the dipole gives exactly its
    /// own numbers: values and both derivatives at every radius, the total, and the inversion.
    #[test]
    fn dipole_through_trait_is_unchanged() {
        let p = OpticalProperties::new(1.2, 0.03, 1.4).unwrap();
        let d = Dipole::new(&p);
        let family: &dyn ModelFamily = &DiffusionModel::Dipole;
        let boxed = family.profile(&p).unwrap();
        let radii = [0.0, 0.1, 1.0, 5.0, 17.0];
        let mut via_eval = [ProfileSample::ZERO; 5];
        let mut via_box = [ProfileSample::ZERO; 5];
        family.eval(&p, &radii, &mut via_eval);
        boxed.profile_with_derivatives_into(&radii, &mut via_box);
        for (i, &r) in radii.iter().enumerate() {
            let want = d.rd_with_derivatives(r);
            for (what, got) in [("eval", via_eval[i]), ("profile", via_box[i])] {
                assert_eq!(got.rd, want.rd, "{what} Rd at r = {r}");
                assert_eq!(
                    got.d_sigma_s_prime, want.d_sigma_s_prime,
                    "{what} ∂/∂σ′s at r = {r}"
                );
                assert_eq!(got.d_sigma_a, want.d_sigma_a, "{what} ∂/∂σa at r = {r}");
            }
            assert_eq!(boxed.rd(r), d.rd(r));
            // The derivatives are not zero (a comparison of zeros would prove nothing).
            assert!(want.d_sigma_s_prime != 0.0 && want.d_sigma_a != 0.0);
        }
        assert_eq!(boxed.rd_total(), d.rd_total());
        assert_eq!(
            family.rd_total(0.9, 1.4, 0.0).unwrap(),
            dipole::rd_total(0.9, 1.4)
        );
        let rd = dipole::rd_total(0.9, 1.4);
        assert_eq!(
            family.albedo_from_rd(rd, 1.4, 0.0).unwrap(),
            dipole::albedo_from_rd(rd, 1.4).unwrap()
        );
    }

    /// The improved models through `eval` equal their own `rd_with_derivatives`; a parameter set
    /// outside a model's range fills NaN, and `profile` refuses it.
    #[test]
    fn eval_matches_models_and_fills_nan_outside() {
        let p = OpticalProperties::new(1.1, 0.05, 1.33).unwrap();
        let radii = [0.05, 0.5, 3.0];
        let mut out = [ProfileSample::ZERO; 3];
        DiffusionModel::BetterDipole.eval(&p, &radii, &mut out);
        let b = BetterDipole::new(&p).unwrap();
        for (o, &r) in out.iter().zip(&radii) {
            assert_eq!(*o, b.rd_with_derivatives(r));
        }
        DiffusionModel::Pbd.eval(&p, &radii, &mut out);
        let m = Pbd::new(&p).unwrap();
        for (o, &r) in out.iter().zip(&radii) {
            assert_eq!(*o, m.rd_with_derivatives(r));
        }
        let high = OpticalProperties::new(1.1, 0.05, 2.6).unwrap();
        for m in [DiffusionModel::BetterDipole, DiffusionModel::Pbd] {
            m.eval(&high, &radii, &mut out);
            assert!(out.iter().all(|s| s.rd.is_nan() && s.d_sigma_a.is_nan()));
            assert!(m.profile(&high).is_err());
        }
    }

    /// g: the dipoles ignore it (σ′s is all they know), PBD's single scattering uses σs = σ′s/(1 − g)
    /// (so the total moves), and a g outside (−1, 1) is refused by every model.
    #[test]
    fn g_reaches_pbd_only() {
        let (a, eta) = (0.9, 1.4);
        for m in [DiffusionModel::Dipole, DiffusionModel::BetterDipole] {
            assert_eq!(
                m.rd_total(a, eta, 0.0).unwrap(),
                m.rd_total(a, eta, 0.7).unwrap()
            );
        }
        let pbd0 = DiffusionModel::Pbd.rd_total(a, eta, 0.0).unwrap();
        let pbd7 = DiffusionModel::Pbd.rd_total(a, eta, 0.7).unwrap();
        assert_ne!(pbd0, pbd7);
        let p = OpticalProperties::new(a, 1.0 - a, eta)
            .unwrap()
            .with_g(0.7)
            .unwrap();
        assert_eq!(pbd7, DiffusionModel::Pbd.profile(&p).unwrap().rd_total());
        let back = DiffusionModel::Pbd.albedo_from_rd(pbd7, eta, 0.7).unwrap();
        assert!((back - a).abs() < 1e-9, "{back}");
        for m in DiffusionModel::ALL {
            assert!(m.rd_total(a, eta, 1.0).is_err());
            assert!(m.albedo_from_rd(0.3, eta, f64::NAN).is_err());
        }
    }
}
