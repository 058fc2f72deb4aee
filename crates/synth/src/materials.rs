//! Published optical parameters used by the demo, the rig twin and the end-to-end tests.

/// A material's published parameters per linear-sRGB channel (R, G, B).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PublishedMaterial {
    /// Short name (lower case, hyphenated), as `scatterfit synth --material` takes it.
    pub name: &'static str,
    /// Where the numbers come from.
    pub source: &'static str,
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
/// material); also in `data/reference/materials.csv`.
#[rustfmt::skip]
pub const CHOI_2014: [PublishedMaterial; 7] = [
    PublishedMaterial { name: "pink-plastic", source: "choi2014", sigma_s_prime: [1.979, 1.893, 1.992], sigma_a: [0.000792, 0.049600, 0.022700], eta: 1.2886 },
    PublishedMaterial { name: "blue-coating", source: "choi2014", sigma_s_prime: [1.189, 1.742, 1.865], sigma_a: [1.189000, 0.090597, 0.016372], eta: 1.9432 },
    PublishedMaterial { name: "brown-leather", source: "choi2014", sigma_s_prime: [1.659, 1.383, 1.113], sigma_a: [0.116993, 0.272607, 0.428075], eta: 1.2391 },
    PublishedMaterial { name: "nephrite", source: "choi2014", sigma_s_prime: [1.439, 1.565, 1.414], sigma_a: [0.066138, 0.053121, 0.046018], eta: 1.0777 },
    PublishedMaterial { name: "wood-tile", source: "choi2014", sigma_s_prime: [2.35, 2.33, 1.461], sigma_a: [0.017508, 0.065100, 0.138360], eta: 1.3108 },
    PublishedMaterial { name: "sulfur", source: "choi2014", sigma_s_prime: [1.896, 1.954, 1.622], sigma_a: [0.002359, 0.004151, 0.073041], eta: 1.1159 },
    PublishedMaterial { name: "red-aluminum", source: "choi2014", sigma_s_prime: [1.89, 1.171, 0.7498], sigma_a: [0.018700, 0.768300, 0.558000], eta: 2.4102 },
];

/// Jensen, Marschner, Levoy & Hanrahan (2001), measured materials as pbrt-v3/v4 carry them
/// (docs/physics.md §1.5; `data/reference/materials.csv`). pbrt stores no η; we use 1.3, the index
/// Jensen et al. are believed to have measured with (docs/physics.md §1.5: unverified).
#[rustfmt::skip]
pub const JENSEN_2001: [PublishedMaterial; 11] = [
    PublishedMaterial { name: "apple", source: "jensen2001", sigma_s_prime: [2.29, 2.39, 1.97], sigma_a: [0.0030, 0.0034, 0.046], eta: 1.3 },
    PublishedMaterial { name: "chicken1", source: "jensen2001", sigma_s_prime: [0.15, 0.21, 0.38], sigma_a: [0.015, 0.077, 0.19], eta: 1.3 },
    PublishedMaterial { name: "chicken2", source: "jensen2001", sigma_s_prime: [0.19, 0.25, 0.32], sigma_a: [0.018, 0.088, 0.20], eta: 1.3 },
    PublishedMaterial { name: "cream", source: "jensen2001", sigma_s_prime: [7.38, 5.47, 3.15], sigma_a: [0.0002, 0.0028, 0.0163], eta: 1.3 },
    PublishedMaterial { name: "ketchup", source: "jensen2001", sigma_s_prime: [0.18, 0.07, 0.03], sigma_a: [0.061, 0.97, 1.45], eta: 1.3 },
    PublishedMaterial { name: "marble", source: "jensen2001", sigma_s_prime: [2.19, 2.62, 3.00], sigma_a: [0.0021, 0.0041, 0.0071], eta: 1.3 },
    PublishedMaterial { name: "potato", source: "jensen2001", sigma_s_prime: [0.68, 0.70, 0.55], sigma_a: [0.0024, 0.0090, 0.12], eta: 1.3 },
    PublishedMaterial { name: "skimmilk", source: "jensen2001", sigma_s_prime: [0.70, 1.22, 1.90], sigma_a: [0.0014, 0.0025, 0.0142], eta: 1.3 },
    PublishedMaterial { name: "skin1", source: "jensen2001", sigma_s_prime: [0.74, 0.88, 1.01], sigma_a: [0.032, 0.17, 0.48], eta: 1.3 },
    PublishedMaterial { name: "skin2", source: "jensen2001", sigma_s_prime: [1.09, 1.59, 1.79], sigma_a: [0.013, 0.070, 0.145], eta: 1.3 },
    PublishedMaterial { name: "wholemilk", source: "jensen2001", sigma_s_prime: [2.55, 3.21, 3.77], sigma_a: [0.0011, 0.0024, 0.014], eta: 1.3 },
];

/// Every built-in material.
pub fn all() -> impl Iterator<Item = &'static PublishedMaterial> {
    CHOI_2014.iter().chain(JENSEN_2001.iter())
}

/// The built-in material of this name (case-insensitive; `_` and spaces count as `-`).
pub fn by_name(name: &str) -> Option<&'static PublishedMaterial> {
    let key = name.trim().to_ascii_lowercase().replace(['_', ' '], "-");
    all().find(|m| m.name == key)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The published tables as `data/reference/materials.csv` has them (copied from Choi et al.
    /// 2014, Table 1, and from pbrt's `MeasuredSS` for Jensen et al. 2001; `data/reference/README.md`).
    const MATERIALS_CSV: &str = include_str!("../../../data/reference/materials.csv");

    /// Every row of `data/reference/materials.csv` is a built-in material with the same source,
    /// σ′s, σa and η (an empty η is Jensen et al.'s 1.3), and every built-in material is a row.
    #[test]
    fn tables_match_the_reference_csv() {
        let mut lines = MATERIALS_CSV
            .lines()
            .filter(|l| !l.trim().is_empty() && !l.starts_with('#'));
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(
            header,
            [
                "name",
                "source",
                "sigma_s_prime_r",
                "sigma_s_prime_g",
                "sigma_s_prime_b",
                "sigma_a_r",
                "sigma_a_g",
                "sigma_a_b",
                "eta"
            ]
        );
        let mut names = Vec::new();
        for line in lines {
            let f: Vec<&str> = line.split(',').collect();
            assert_eq!(f.len(), header.len(), "{line}");
            let num = |k: usize| -> f64 { f[k].parse().unwrap_or_else(|_| panic!("{line}")) };
            let m = by_name(f[0]).unwrap_or_else(|| panic!("{} is not built in", f[0]));
            assert_eq!(m.name, f[0]);
            assert_eq!(m.source, f[1], "{line}");
            assert_eq!(m.sigma_s_prime, [num(2), num(3), num(4)], "{line}");
            assert_eq!(m.sigma_a, [num(5), num(6), num(7)], "{line}");
            let eta = if f[8].is_empty() { 1.3 } else { num(8) };
            assert_eq!(m.eta, eta, "{line}");
            names.push(f[0]);
        }
        let built_in: Vec<&str> = all().map(|m| m.name).collect();
        assert_eq!(names, built_in, "same materials, same order");
        assert_eq!(CHOI_2014.len(), 7, "Choi et al. 2014, Table 1");
    }

    #[test]
    fn lookup_normalises_the_name() {
        assert_eq!(by_name("Pink Plastic").unwrap().name, "pink-plastic");
        assert_eq!(by_name(" WOOD_TILE ").unwrap().name, "wood-tile");
        assert_eq!(by_name("skin_1"), None);
        assert_eq!(by_name("unobtainium"), None);
    }
}
