//! [`OpticalProperties`]: σ′s, σa and η of one material and one colour channel.

use serde::{Deserialize, Serialize};

use crate::error::{Result, eta_at_least_one, non_negative};

/// The optical properties of a homogeneous material in one colour channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OpticalProperties {
    /// Reduced scattering coefficient σ′s = σs(1 − g) [mm⁻¹].
    pub sigma_s_prime: f64,
    /// Absorption coefficient σa [mm⁻¹].
    pub sigma_a: f64,
    /// Relative refractive index η = n_material / n_air [1].
    pub eta: f64,
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
