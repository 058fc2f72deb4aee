//! [`OpticalProperties`]: σ′s, σa, η (and the Henyey–Greenstein g) of one material and one colour
//! channel.

use serde::{Deserialize, Serialize};

use crate::error::{Result, check_g, eta_at_least_one, non_negative};

/// The optical properties of a homogeneous material in one colour channel.
///
/// Built only through [`OpticalProperties::new`] (or [`OpticalProperties::from_albedo`], and
/// [`OpticalProperties::with_g`]); JSON is read through the same checks (`#[serde(try_from)]`), so
/// every value of this type is valid.
///
/// g is the Henyey–Greenstein asymmetry of the phase function, 0 (isotropic) unless set. The
/// measurement gives σ′s = σs(1 − g) only; the diffusion dipoles depend on σ′s alone and ignore g,
/// photon beam diffusion's single scattering and the Monte Carlo tables use σs = σ′s/(1 − g). JSON
/// without `g` reads as g = 0, and g = 0 is not written (files stay as they were before g existed).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawProperties")]
pub struct OpticalProperties {
    /// Reduced scattering coefficient σ′s = σs(1 − g) [mm⁻¹].
    sigma_s_prime: f64,
    /// Absorption coefficient σa [mm⁻¹].
    sigma_a: f64,
    /// Relative refractive index η = n_material / n_air [1].
    eta: f64,
    /// Henyey–Greenstein asymmetry g ∈ (−1, 1) [1].
    #[serde(skip_serializing_if = "is_isotropic")]
    g: f64,
}

fn is_isotropic(g: &f64) -> bool {
    *g == 0.0
}

/// The unchecked shape of [`OpticalProperties`] in files.
#[derive(Deserialize)]
struct RawProperties {
    sigma_s_prime: f64,
    sigma_a: f64,
    eta: f64,
    #[serde(default)]
    g: f64,
}

impl TryFrom<RawProperties> for OpticalProperties {
    type Error = crate::OpticsError;
    fn try_from(raw: RawProperties) -> Result<Self> {
        Self::new(raw.sigma_s_prime, raw.sigma_a, raw.eta)?.with_g(raw.g)
    }
}

impl OpticalProperties {
    /// Checked constructor: σ′s > 0, σa ≥ 0, both finite, η ≥ 1; g = 0.
    ///
    /// # Errors
    /// [`crate::OpticsError::InvalidParameter`] naming the offending quantity.
    pub fn new(sigma_s_prime: f64, sigma_a: f64, eta: f64) -> Result<Self> {
        non_negative("sigma_s_prime [mm^-1]", sigma_s_prime)?;
        if sigma_s_prime == 0.0 {
            return Err(crate::OpticsError::InvalidParameter {
                name: "sigma_s_prime [mm^-1]",
                value: sigma_s_prime,
                reason: "must be > 0 (a diffusion model needs scattering)",
            });
        }
        non_negative("sigma_a [mm^-1]", sigma_a)?;
        eta_at_least_one(eta)?;
        Ok(Self {
            sigma_s_prime,
            sigma_a,
            eta,
            g: 0.0,
        })
    }

    /// The same properties with Henyey–Greenstein asymmetry `g` (σ′s, σa and η unchanged: σs =
    /// σ′s/(1 − g) changes with g).
    ///
    /// # Errors
    /// [`crate::OpticsError::InvalidParameter`] for g outside (−1, 1) or not finite.
    pub fn with_g(self, g: f64) -> Result<Self> {
        Ok(Self {
            g: check_g(g)?,
            ..self
        })
    }

    /// Reduced scattering coefficient σ′s = σs(1 − g) [mm⁻¹].
    pub fn sigma_s_prime(&self) -> f64 {
        self.sigma_s_prime
    }

    /// Absorption coefficient σa [mm⁻¹].
    pub fn sigma_a(&self) -> f64 {
        self.sigma_a
    }

    /// Relative refractive index η = n_material / n_air \[1\].
    pub fn eta(&self) -> f64 {
        self.eta
    }

    /// Henyey–Greenstein asymmetry g \[1\] (0 unless set by [`OpticalProperties::with_g`]).
    pub fn g(&self) -> f64 {
        self.g
    }

    /// Scattering coefficient σs = σ′s/(1 − g) [mm⁻¹] (the similarity relation; Wyman, Patterson &
    /// Wilson 1989).
    pub fn sigma_s(&self) -> f64 {
        self.sigma_s_prime / (1.0 - self.g)
    }

    /// Reduced extinction coefficient σ′t = σa + σ′s [mm⁻¹].
    pub fn sigma_t_prime(&self) -> f64 {
        self.sigma_a + self.sigma_s_prime
    }

    /// Reduced albedo α′ = σ′s / σ′t \[1\].
    pub fn albedo_prime(&self) -> f64 {
        self.sigma_s_prime / self.sigma_t_prime()
    }

    /// Effective transport coefficient σtr = √(3 σa σ′t) [mm⁻¹] (Jensen et al. 2001, §2.2).
    pub fn sigma_tr(&self) -> f64 {
        (3.0 * self.sigma_a * self.sigma_t_prime()).sqrt()
    }

    /// The properties with σa from the paper's constraint σa = σ′s/α′ − σ′s
    /// (Choi, Lee & Chin 2014, eq. (2)), given σ′s, the reduced albedo α′ ∈ (0, 1] and η.
    ///
    /// # Errors
    /// As [`OpticalProperties::new`], or α′ outside (0, 1].
    pub fn from_albedo(sigma_s_prime: f64, albedo_prime: f64, eta: f64) -> Result<Self> {
        if !(albedo_prime > 0.0 && albedo_prime <= 1.0) {
            return Err(crate::OpticsError::InvalidParameter {
                name: "albedo_prime",
                value: albedo_prime,
                reason: "the reduced albedo must lie in (0, 1]",
            });
        }
        Self::new(
            sigma_s_prime,
            sigma_s_prime / albedo_prime - sigma_s_prime,
            eta,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// JSON goes through the checked constructor: a valid value round-trips, an invalid one is refused.
    #[test]
    fn deserialisation_is_checked() {
        let p = OpticalProperties::new(1.2, 0.03, 1.4).unwrap();
        let json = serde_json::to_string(&p).unwrap();
        assert_eq!(serde_json::from_str::<OpticalProperties>(&json).unwrap(), p);
        for bad in [
            r#"{"sigma_s_prime":-1,"sigma_a":0.1,"eta":1.3}"#,
            r#"{"sigma_s_prime":1,"sigma_a":-0.1,"eta":1.3}"#,
            r#"{"sigma_s_prime":1,"sigma_a":0.1,"eta":0.5}"#,
            r#"{"sigma_s_prime":1,"sigma_a":0.1,"eta":1.3,"g":1}"#,
        ] {
            assert!(
                serde_json::from_str::<OpticalProperties>(bad).is_err(),
                "{bad}"
            );
        }
    }

    /// g defaults to 0 (old files read), is written only when set, round-trips, and is checked.
    #[test]
    fn g_is_optional_checked_and_round_trips() {
        let p = OpticalProperties::new(1.2, 0.03, 1.4).unwrap();
        assert_eq!(p.g(), 0.0);
        assert_eq!(p.sigma_s(), 1.2);
        let json = serde_json::to_string(&p).unwrap();
        assert_eq!(json, r#"{"sigma_s_prime":1.2,"sigma_a":0.03,"eta":1.4}"#);
        let q = p.with_g(0.5).unwrap();
        assert_eq!((q.g(), q.sigma_s_prime(), q.sigma_s()), (0.5, 1.2, 2.4));
        let json = serde_json::to_string(&q).unwrap();
        assert!(json.contains(r#""g":0.5"#), "{json}");
        assert_eq!(serde_json::from_str::<OpticalProperties>(&json).unwrap(), q);
        for bad in [1.0, -1.0, f64::NAN, 2.0] {
            assert!(p.with_g(bad).is_err(), "{bad}");
        }
        assert_eq!(p.with_g(-0.3).unwrap().g(), -0.3);
    }
}
