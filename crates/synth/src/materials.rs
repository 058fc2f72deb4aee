//! Published optical parameters used by the demo and the end-to-end tests.

/// A material's published parameters per linear-sRGB channel (R, G, B).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PublishedMaterial {
    /// Short name.
    pub name: &'static str,
    /// Reduced scattering coefficient σ′s per channel [mm⁻¹].
    pub sigma_s_prime: [f64; 3],
    /// Absorption coefficient σa per channel [mm⁻¹].
    pub sigma_a: [f64; 3],
    /// Relative refractive index η.
    pub eta: f64,
}

impl PublishedMaterial {
    /// Reduced albedo α′ = σ′s/(σ′s + σa) per channel.
    pub fn albedo_prime(&self) -> [f64; 3] {
        std::array::from_fn(|c| self.sigma_s_prime[c] / (self.sigma_s_prime[c] + self.sigma_a[c]))
    }
}

/// The seven materials of Choi, Lee & Chin (2014), Table 1 (σ′s and σa in mm⁻¹, one η per
/// material); also in `shared/reference/materials.csv`.
#[rustfmt::skip]
pub const CHOI_2014: [PublishedMaterial; 7] = [
    PublishedMaterial { name: "pink-plastic", sigma_s_prime: [1.979, 1.893, 1.992], sigma_a: [0.000792, 0.049600, 0.022700], eta: 1.2886 },
    PublishedMaterial { name: "blue-coating", sigma_s_prime: [1.189, 1.742, 1.865], sigma_a: [1.189000, 0.090597, 0.016372], eta: 1.9432 },
    PublishedMaterial { name: "brown-leather", sigma_s_prime: [1.659, 1.383, 1.113], sigma_a: [0.116993, 0.272607, 0.428075], eta: 1.2391 },
    PublishedMaterial { name: "nephrite", sigma_s_prime: [1.439, 1.565, 1.414], sigma_a: [0.066138, 0.053121, 0.046018], eta: 1.0777 },
    PublishedMaterial { name: "wood-tile", sigma_s_prime: [2.35, 2.33, 1.461], sigma_a: [0.017508, 0.065100, 0.138360], eta: 1.3108 },
    PublishedMaterial { name: "sulfur", sigma_s_prime: [1.896, 1.954, 1.622], sigma_a: [0.002359, 0.004151, 0.073041], eta: 1.1159 },
    PublishedMaterial { name: "red-aluminum", sigma_s_prime: [1.89, 1.171, 0.7498], sigma_a: [0.018700, 0.768300, 0.558000], eta: 2.4102 },
];
