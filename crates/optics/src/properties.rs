//! [`OpticalProperties`]: σ′s, σa and η of one material and one colour channel.

use serde::{Deserialize, Serialize};

use crate::error::{Result, eta_at_least_one, non_negative};

/// The optical properties of a homogeneous material in one colour channel.
///
/// Built only through [`OpticalProperties::new`] (or [`OpticalProperties::from_albedo`]); JSON is read
/// through the same check (`#[serde(try_from)]`), so every value of this type is valid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawProperties")]
pub struct OpticalProperties {
    /// Reduced scattering coefficient σ′s = σs(1 − g) [mm⁻¹].
    sigma_s_prime: f64,
    /// Absorption coefficient σa [mm⁻¹].
    sigma_a: f64,
    /// Relative refractive index η = n_material / n_air [1].
    eta: f64,
}

/// The unchecked shape of [`OpticalProperties`] in files.
#[derive(Deserialize)]
struct RawProperties {
    sigma_s_prime: f64,
    sigma_a: f64,
    eta: f64,
}

impl TryFrom<RawProperties> for OpticalProperties {
    type Error = crate::OpticsError;
    fn try_from(raw: RawProperties) -> Result<Self> {
        Self::new(raw.sigma_s_prime, raw.sigma_a, raw.eta)
    }
}

impl OpticalProperties {
    /// Checked constructor: σ′s > 0, σa ≥ 0, both finite, η ≥ 1.
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

    /// Relative refractive index η = n_material / n_air [1].
    pub fn eta(&self) -> f64 {
        self.eta
    }

    /// Reduced extinction coefficient σ′t = σa + σ′s [mm⁻¹].
    pub fn sigma_t_prime(&self) -> f64 {
        self.sigma_a + self.sigma_s_prime
    }

    /// Reduced albedo α′ = σ′s / σ′t [1].
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
        ] {
            assert!(
                serde_json::from_str::<OpticalProperties>(bad).is_err(),
                "{bad}"
            );
        }
    }
}
