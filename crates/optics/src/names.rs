//! The names a user chooses between: the forward model ([`ModelName`]), how α′ comes from the
//! spectrophotometer ([`AlbedoModel`]) and the fitting method ([`Method`]). One definition each: the
//! manifest (`[fit]`), `result.json`, the fit and the command line all use these. In files and on the
//! command line they are the strings of [`ModelName::name`] etc.; [`std::str::FromStr`] refuses
//! anything else with an [`OpticsError::UnknownName`] that lists the valid names.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::OpticsError;

/// The forward model of the radial profile Rd(r).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ModelName {
    /// The classical dipole, Jensen et al. 2001 (the paper's model): `dipole`.
    #[cfg_attr(
        feature = "clap",
        value(help = "The classical dipole, Jensen et al. 2001 (the paper's; approximate)")
    )]
    Dipole,
    /// d'Eon 2012, "A better dipole": `better-dipole`.
    #[cfg_attr(feature = "clap", value(help = "d'Eon 2012, \"A better dipole\""))]
    BetterDipole,
    /// Photon beam diffusion, Habel et al. 2013, as pbrt-v4 evaluates it: `pbd`.
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Photon beam diffusion, Habel et al. 2013, as pbrt-v4 evaluates it (slow: ~2 ms per evaluation)"
        )
    )]
    Pbd,
    /// Monte Carlo profile tables (exact transport): `mc`, the default — the diffusion models'
    /// bias reaches tens of percent at low α′ and high η (BENCHMARKS.md, "the bias study"), the
    /// tables' is within their noise, at the same cost per fit.
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Monte Carlo tables shipped with scatterfit (exact transport; the default). Henyey–Greenstein g 0–0.95 with --g or `[fit] g`; η 1.0–2.5; α′ 0.01–0.9999"
        )
    )]
    Mc,
}

impl ModelName {
    /// Every model, in the order of the docs.
    pub const ALL: [ModelName; 4] = [Self::Dipole, Self::BetterDipole, Self::Pbd, Self::Mc];

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Dipole => "dipole",
            Self::BetterDipole => "better-dipole",
            Self::Pbd => "pbd",
            Self::Mc => "mc",
        }
    }
}

/// How the reduced albedo α′ comes from the spectrophotometer's total diffuse reflectance Rd.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum AlbedoModel {
    /// The diffusion model's own total Rd(α′, η) inverted (the dipole's closed form for the paper,
    /// Choi et al. 2014 eq. 1, and for the `mc` profile model): `diffusion`.
    #[cfg_attr(
        feature = "clap",
        value(
            help = "The diffusion model's own total Rd(α′, η) inverted (the dipole's closed form: the paper)"
        )
    )]
    Diffusion,
    /// The Monte Carlo tables' total Rd(α′, η) inverted ("by the Monte Carlo method", exactly): `mc`.
    #[cfg_attr(
        feature = "clap",
        value(help = "The Monte Carlo tables' total inverted (exact transport)")
    )]
    Mc,
}

impl AlbedoModel {
    /// Both, in the order of the docs.
    pub const ALL: [AlbedoModel; 2] = [Self::Diffusion, Self::Mc];

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Diffusion => "diffusion",
            Self::Mc => "mc",
        }
    }

    /// The profile model's own physics, the default: `mc` for the `mc` model, else `diffusion`.
    pub fn default_for(model: ModelName) -> Self {
        match model {
            ModelName::Mc => Self::Mc,
            _ => Self::Diffusion,
        }
    }
}

/// Which unknowns the fit has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Method {
    /// Choi, Lee & Chin 2014: α′ from the spectrophotometer, unknowns σ′s and the scale k:
    /// `proposed`.
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Choi et al. 2014: α′ from the spectrophotometer, σ′s (and the profile's scale) fitted"
        )
    )]
    Proposed,
    /// Jensen et al. 2001: unknowns σ′s, σa and the scale k: `existing`.
    #[cfg_attr(
        feature = "clap",
        value(help = "Jensen et al. 2001: σ′s, σa (and the scale) fitted")
    )]
    Existing,
}

impl Method {
    /// Both, in the order of the docs.
    pub const ALL: [Method; 2] = [Self::Proposed, Self::Existing];

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Proposed => "proposed",
            Self::Existing => "existing",
        }
    }
}

/// Display, and FromStr against the `ALL` list with an error listing every valid name.
macro_rules! named {
    ($t:ty, $what:literal, $expected:literal) => {
        impl fmt::Display for $t {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }

        impl FromStr for $t {
            type Err = OpticsError;
            fn from_str(s: &str) -> Result<Self, OpticsError> {
                <$t>::ALL
                    .into_iter()
                    .find(|v| v.name() == s)
                    .ok_or_else(|| OpticsError::UnknownName {
                        what: $what,
                        given: s.to_owned(),
                        expected: $expected,
                    })
            }
        }
    };
}

named!(ModelName, "forward model", "dipole, better-dipole, pbd, mc");
named!(AlbedoModel, "albedo model", "diffusion, mc");
named!(Method, "fitting method", "proposed, existing");

#[cfg(test)]
mod tests {
    use super::*;

    /// Every name parses back to its value, displays as itself and is its serde string; anything
    /// else is refused with the valid names listed.
    #[test]
    fn names_round_trip() {
        fn check<T>(all: &[T], expected: &str)
        where
            T: Copy + fmt::Debug + PartialEq + fmt::Display + FromStr<Err = OpticsError>,
            T: Serialize + for<'de> Deserialize<'de>,
        {
            for &v in all {
                let s = v.to_string();
                assert_eq!(s.parse::<T>().unwrap(), v);
                assert_eq!(serde_json::to_string(&v).unwrap(), format!("\"{s}\""));
                assert_eq!(serde_json::from_str::<T>(&format!("\"{s}\"")).unwrap(), v);
            }
            let e = "Dipole ".parse::<T>().unwrap_err();
            assert!(matches!(e, OpticsError::UnknownName { .. }));
            assert!(e.to_string().contains(expected), "{e}");
            assert!(e.to_string().contains("\"Dipole \""), "{e}");
        }
        check(&ModelName::ALL, "dipole, better-dipole, pbd, mc");
        check(&AlbedoModel::ALL, "diffusion, mc");
        check(&Method::ALL, "proposed, existing");
        let names: Vec<_> = ModelName::ALL.iter().map(|m| m.name()).collect();
        assert_eq!(names, ["dipole", "better-dipole", "pbd", "mc"]);
        assert_eq!(Method::Existing.name(), "existing");
        assert_eq!(AlbedoModel::Mc.name(), "mc");
    }

    /// The defaults of the manifest's `[fit]`: the paper's method with exact transport, and each
    /// model's own physics for α′.
    #[test]
    fn defaults() {
        assert_eq!(ModelName::default(), ModelName::Mc);
        assert_eq!(Method::default(), Method::Proposed);
        assert_eq!(AlbedoModel::default_for(ModelName::Mc), AlbedoModel::Mc);
        for m in [ModelName::Dipole, ModelName::BetterDipole, ModelName::Pbd] {
            assert_eq!(AlbedoModel::default_for(m), AlbedoModel::Diffusion);
        }
    }
}

/// A fitted quantity, as results name it (`sigma_s_prime`, `sigma_a`, `scale`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Parameter {
    /// The reduced scattering coefficient σ′s \[mm⁻¹\]: `sigma_s_prime`.
    SigmaSPrime,
    /// The absorption coefficient σa \[mm⁻¹\]: `sigma_a`.
    SigmaA,
    /// The profile's scale k (measured = k · model): `scale`.
    Scale,
}

impl Parameter {
    /// The name used in files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::SigmaSPrime => "sigma_s_prime",
            Self::SigmaA => "sigma_a",
            Self::Scale => "scale",
        }
    }
}

impl std::fmt::Display for Parameter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
