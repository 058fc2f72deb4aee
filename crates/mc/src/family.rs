//! The Monte Carlo tables as a forward model ([`scatterfit_optics::ModelFamily`] for
//! [`McTableSet`] and for the (η, g) grid [`McGridSet`]), and the one place where a model's name
//! becomes a model: [`family`] and [`albedo_family`].
//!
//! A [`McTableSet`] is made for one Henyey–Greenstein g; its tables are in the single-scattering
//! albedo a = σs/σt, so α′ = a(1 − g)/(1 − ag) and a = α′/(1 − g + gα′) (both the identity at
//! g = 0). Optical properties with another g are refused ([`OpticsError::AnisotropyMismatch`]),
//! never silently used with the tables' g. The `mc` family is the shipped grid ([`bundled_grid`]:
//! g = 0, and 0.8–0.9 interpolated), which honours each parameter set's own g and refuses a g it does
//! not cover ([`OpticsError::AnisotropyNotTabulated`]).

use std::sync::OnceLock;

use scatterfit_optics::{
    AlbedoModel, DiffusionModel, ModelFamily, ModelName, OpticalProperties, OpticsError,
    ProfileModel, ProfileSample,
};

use crate::error::{McError, Result};
use crate::grid_g::McGridSet;
use crate::model::{McProfile, McTableSet};

/// An [`McError`] from a table lookup as the optics vocabulary's error: a lookup fails with
/// [`McError::Optics`] (a value outside the tables or its domain), returned as it is.
fn lookup_error(e: McError) -> OpticsError {
    match e {
        McError::Optics(e) => e,
        _ => OpticsError::InvalidParameter {
            name: "mc tables",
            value: f64::NAN,
            reason: "the Monte Carlo tables cannot evaluate this parameter set",
        },
    }
}

impl McTableSet {
    /// Refuses a g other than the tables' (exact comparison: a table is made for one g).
    fn check_g(&self, g: f64) -> std::result::Result<(), OpticsError> {
        if g == self.g() {
            Ok(())
        } else {
            Err(OpticsError::AnisotropyMismatch {
                given: g,
                tables: self.g(),
            })
        }
    }
}

impl ModelFamily for McTableSet {
    fn name(&self) -> ModelName {
        ModelName::Mc
    }

    fn profile(
        &self,
        props: &OpticalProperties,
    ) -> std::result::Result<Box<dyn ProfileModel>, OpticsError> {
        self.check_g(props.g())?;
        Ok(Box::new(McProfile::new(self, props).map_err(lookup_error)?))
    }

    /// [`McProfile::new`] without boxing it.
    fn eval(&self, props: &OpticalProperties, radii_mm: &[f64], out: &mut [ProfileSample]) {
        match self
            .check_g(props.g())
            .ok()
            .and(McProfile::new(self, props).ok())
        {
            Some(m) => m.profile_with_derivatives_into(radii_mm, out),
            None => out.fill(ProfileSample::NAN),
        }
    }

    /// The tables' total at a = α′/(1 − g + gα′) ([`McTableSet::rd_total`]).
    fn rd_total(
        &self,
        albedo_prime: f64,
        eta: f64,
        g: f64,
    ) -> std::result::Result<f64, OpticsError> {
        self.check_g(g)?;
        let a = albedo_prime / (1.0 - g + g * albedo_prime);
        McTableSet::rd_total(self, a, eta).map_err(lookup_error)
    }

    /// α′ = a(1 − g)/(1 − ag) of the tables' inversion ([`McTableSet::albedo_from_rd_total`]).
    fn albedo_from_rd(&self, rd: f64, eta: f64, g: f64) -> std::result::Result<f64, OpticsError> {
        self.check_g(g)?;
        let a = self.albedo_from_rd_total(rd, eta).map_err(lookup_error)?;
        Ok(a * (1.0 - g) / (1.0 - a * g))
    }
}

impl ModelFamily for McGridSet {
    fn name(&self) -> ModelName {
        ModelName::Mc
    }

    /// The grid's model at `props.g()` ([`McGridSet::profile`]).
    fn profile(
        &self,
        props: &OpticalProperties,
    ) -> std::result::Result<Box<dyn ProfileModel>, OpticsError> {
        Ok(Box::new(
            McGridSet::profile(self, props).map_err(lookup_error)?,
        ))
    }

    /// [`McGridSet::profile`] without boxing it.
    fn eval(&self, props: &OpticalProperties, radii_mm: &[f64], out: &mut [ProfileSample]) {
        match McGridSet::profile(self, props) {
            Ok(m) => m.profile_with_derivatives_into(radii_mm, out),
            Err(_) => out.fill(ProfileSample::NAN),
        }
    }

    /// [`McGridSet::rd_total`].
    fn rd_total(
        &self,
        albedo_prime: f64,
        eta: f64,
        g: f64,
    ) -> std::result::Result<f64, OpticsError> {
        McGridSet::rd_total(self, albedo_prime, eta, g).map_err(lookup_error)
    }

    /// [`McGridSet::albedo_from_rd`].
    fn albedo_from_rd(&self, rd: f64, eta: f64, g: f64) -> std::result::Result<f64, OpticsError> {
        McGridSet::albedo_from_rd(self, rd, eta, g).map_err(lookup_error)
    }
}

/// The shipped (η, g) grid ([`McGridSet::bundled`]: g 0–0.95 at η 1.0–2.5),
/// parsed once per process.
///
/// # Errors
/// [`McError::BundledTables`] if the tables do not parse (a build defect).
pub fn bundled_grid() -> Result<&'static McGridSet> {
    static GRID: OnceLock<std::result::Result<McGridSet, String>> = OnceLock::new();
    GRID.get_or_init(|| McGridSet::bundled().map_err(|e| e.to_string()))
        .as_ref()
        .map_err(|message| McError::BundledTables(message.clone()))
}

/// The tables shipped with scatterfit ([`McTableSet::bundled`]), parsed once per process.
///
/// # Errors
/// [`McError::BundledTables`] if they do not parse (a build defect).
pub fn bundled_tables() -> Result<&'static McTableSet> {
    static SET: OnceLock<std::result::Result<McTableSet, String>> = OnceLock::new();
    SET.get_or_init(|| McTableSet::bundled().map_err(|e| e.to_string()))
        .as_ref()
        .map_err(|message| McError::BundledTables(message.clone()))
}

/// The forward model called `name`: the classical dipole (Jensen et al. 2001), the better dipole
/// (d'Eon 2012), photon beam diffusion (Habel et al. 2013) or the Monte Carlo tables shipped with
/// scatterfit over (η, g) ([`bundled_grid`]: g = 0 at η 1.0–2.5, exactly the g = 0 tables'
/// numbers; g up to 0.95 at η 1.0–2.5, linear in g between nodes; other g refused). The one place a
/// name becomes a model.
///
/// # Errors
/// [`McError::BundledTables`] when the Monte Carlo tables cannot be loaded.
pub fn family(name: ModelName) -> Result<&'static dyn ModelFamily> {
    static DIPOLE: DiffusionModel = DiffusionModel::Dipole;
    static BETTER_DIPOLE: DiffusionModel = DiffusionModel::BetterDipole;
    static PBD: DiffusionModel = DiffusionModel::Pbd;
    Ok(match name {
        ModelName::Dipole => &DIPOLE,
        ModelName::BetterDipole => &BETTER_DIPOLE,
        ModelName::Pbd => &PBD,
        ModelName::Mc => bundled_grid()?,
    })
}

/// The model whose total Rd(α′, η) is inverted for the spectrophotometer's α′: for
/// [`AlbedoModel::Mc`] the Monte Carlo tables' total; for [`AlbedoModel::Diffusion`] the profile
/// model's own total, and the classical dipole's closed form (the paper's eq. 1) when the profile
/// model is `mc`.
///
/// # Errors
/// As [`family`].
pub fn albedo_family(albedo: AlbedoModel, model: ModelName) -> Result<&'static dyn ModelFamily> {
    match (albedo, model) {
        (AlbedoModel::Mc, _) => family(ModelName::Mc),
        (AlbedoModel::Diffusion, ModelName::Mc) => family(ModelName::Dipole),
        (AlbedoModel::Diffusion, m) => family(m),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{McTable, McTableSpec};

    /// Every name gives the family of that name; the albedo rule picks the tables, the dipole for
    /// `diffusion` with the `mc` profile, else the profile model itself.
    #[test]
    fn names_give_their_families() {
        for name in ModelName::ALL {
            assert_eq!(family(name).unwrap().name(), name);
            assert_eq!(
                albedo_family(AlbedoModel::Mc, name).unwrap().name(),
                ModelName::Mc
            );
            let diffusion = albedo_family(AlbedoModel::Diffusion, name).unwrap().name();
            let want = if name == ModelName::Mc {
                ModelName::Dipole
            } else {
                name
            };
            assert_eq!(diffusion, want);
        }
        // Parsed once: the same set every time.
        assert!(std::ptr::eq(
            bundled_tables().unwrap(),
            bundled_tables().unwrap()
        ));
    }

    /// Through the family the tables give exactly `McProfile`'s numbers and the set's totals; a g
    /// other than the tables' is refused (profile, totals, inversion) and fills NaN in `eval`;
    /// parameters outside the tables are `OutOfTable` with the tables' own message.
    #[test]
    fn family_matches_tables_and_refuses_other_g() {
        let set = bundled_tables().unwrap();
        let p = OpticalProperties::new(1.3, 0.04, 1.37).unwrap();
        let m = McProfile::new(set, &p).unwrap();
        let radii = [0.02, 0.4, 2.0, 9.0];
        let mut out = [ProfileSample::ZERO; 4];
        set.eval(&p, &radii, &mut out);
        let boxed = ModelFamily::profile(set, &p).unwrap();
        for (o, &r) in out.iter().zip(&radii) {
            assert_eq!(*o, m.rd_with_derivatives(r));
            assert_eq!(boxed.rd(r), m.rd(r));
        }
        assert_eq!(boxed.rd_total(), m.rd_total());
        let a = p.albedo_prime();
        let rd = ModelFamily::rd_total(set, a, 1.37, 0.0).unwrap();
        assert_eq!(rd, set.rd_total(a, 1.37).unwrap());
        assert_eq!(
            ModelFamily::albedo_from_rd(set, rd, 1.37, 0.0).unwrap(),
            set.albedo_from_rd_total(rd, 1.37).unwrap()
        );
        let aniso = p.with_g(0.3).unwrap();
        let e = ModelFamily::profile(set, &aniso).err().unwrap();
        assert!(matches!(e, OpticsError::AnisotropyMismatch { .. }), "{e}");
        assert!(e.to_string().contains("g = 0.3"), "{e}");
        set.eval(&aniso, &radii, &mut out);
        assert!(out.iter().all(|s| s.rd.is_nan()));
        assert!(ModelFamily::rd_total(set, a, 1.37, 0.3).is_err());
        assert!(ModelFamily::albedo_from_rd(set, rd, 1.37, 0.3).is_err());
        let e = ModelFamily::albedo_from_rd(set, 0.999, 1.37, 0.0).unwrap_err();
        assert!(matches!(
            e,
            OpticsError::OutOfTable {
                name: "rd_total",
                ..
            }
        ));
        let mc_message = set
            .albedo_from_rd_total(0.999, 1.37)
            .unwrap_err()
            .to_string();
        assert_eq!(e.to_string(), mc_message);
    }

    /// A set made for g ≠ 0 takes α′ and g and maps them onto its single-scattering albedo: the
    /// family's total at α′ is the set's total at a = α′/(1 − g + gα′), and the inversion returns α′.
    #[test]
    fn anisotropic_set_maps_reduced_albedo() {
        let g = 0.5;
        let mut spec = McTableSpec::with_strata(1.3, g, vec![30_000, 6_000], vec![64]).unwrap();
        spec.albedo_count = 8;
        spec.albedo_min = 0.7;
        spec.albedo_max = 0.99;
        spec.radial_bins = 120;
        spec.rho_max = 60.0;
        let set = McTableSet::new(vec![McTable::build(&spec, &|_, _| {}).unwrap()]).unwrap();
        let alpha = 0.8;
        let a = alpha / (1.0 - g + g * alpha);
        let rd = ModelFamily::rd_total(&set, alpha, 1.3, g).unwrap();
        assert_eq!(rd, set.rd_total(a, 1.3).unwrap());
        let back = ModelFamily::albedo_from_rd(&set, rd, 1.3, g).unwrap();
        assert!((back - alpha).abs() < 1e-9, "{back}");
        let p = OpticalProperties::from_albedo(1.0, alpha, 1.3)
            .unwrap()
            .with_g(g)
            .unwrap();
        assert!((ModelFamily::profile(&set, &p).unwrap().rd_total() - rd).abs() < 1e-12);
        assert!(ModelFamily::rd_total(&set, alpha, 1.3, 0.0).is_err());
    }
}
