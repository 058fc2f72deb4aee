//! Published optical parameters used by the demo, the rig twin, the renderer and the end-to-end
//! tests: the one place the workspace keeps them ([`CHOI_2014`], [`CHOI_2014_EXISTING`],
//! [`JENSEN_2001`]; [`choi_2014_set`] finds a set of Choi et al. by name).

use crate::Method;

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

/// The existing method's parameters (σ′s and σa fitted together, Jensen et al. 2001's way) of three of
/// Choi, Lee & Chin's materials, as the paper quotes them in §4.3 for its Figure 5 ((a1)/(a3) pink
/// plastic, (b1)/(b3) blue coating, (c1)/(c3) brown leather) [mm⁻¹]. The text gives no η; these
/// carry Table 1's. Not in `data/reference/materials.csv`, which holds the paper's Table 1 (the
/// test checks their names and η against its rows and their values against the quoted sentences).
#[rustfmt::skip]
pub const CHOI_2014_EXISTING: [PublishedMaterial; 3] = [
    PublishedMaterial { name: "pink-plastic", source: "choi2014-existing", sigma_s_prime: [2.152, 1.522, 1.864], sigma_a: [1.152e-10, 0.4515, 0.007945], eta: CHOI_2014[0].eta },
    PublishedMaterial { name: "blue-coating", source: "choi2014-existing", sigma_s_prime: [1.128, 1.484, 1.923], sigma_a: [2.118, 1.857, 0.2809], eta: CHOI_2014[1].eta },
    PublishedMaterial { name: "brown-leather", source: "choi2014-existing", sigma_s_prime: [1.624, 1.222, 0.9038], sigma_a: [1.841, 2.529, 2.754], eta: CHOI_2014[2].eta },
];

/// One of Choi et al.'s published parameter sets: a material as one method measured it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PublishedSet {
    /// The parameters (name without the method).
    pub material: &'static PublishedMaterial,
    /// The method that gave them.
    pub method: Method,
}

impl PublishedSet {
    /// Where the numbers are printed, e.g. "Choi et al. 2014, Table 1".
    pub fn citation(&self) -> &'static str {
        match self.method {
            Method::Proposed => "Choi et al. 2014, Table 1",
            Method::Existing => "Choi et al. 2014, Figure 5 (existing method; η of Table 1)",
        }
    }

    /// The name [`choi_2014_set`] takes for this set: the material's, with `-existing` for the
    /// existing method's.
    pub fn key(&self) -> String {
        match self.method {
            Method::Proposed => self.material.name.to_owned(),
            Method::Existing => format!("{}-existing", self.material.name),
        }
    }
}

/// Choi et al.'s parameter sets by name: `pink-plastic` … `red-aluminum` (Table 1, the proposed
/// method) and `pink-plastic-existing`, `blue-coating-existing`, `brown-leather-existing`
/// ([`CHOI_2014_EXISTING`]). Case-insensitive; `_` and spaces count as `-`.
pub fn choi_2014_set(name: &str) -> Option<PublishedSet> {
    let key = name.trim().to_ascii_lowercase().replace(['_', ' '], "-");
    let (base, method, table) = match key.strip_suffix("-existing") {
        Some(base) => (base, Method::Existing, &CHOI_2014_EXISTING[..]),
        None => (key.as_str(), Method::Proposed, &CHOI_2014[..]),
    };
    table
        .iter()
        .find(|m| m.name == base)
        .map(|material| PublishedSet { material, method })
}

/// Every name [`choi_2014_set`] knows, Table 1's first.
pub fn choi_2014_sets() -> impl Iterator<Item = PublishedSet> {
    let proposed = CHOI_2014.iter().map(|material| PublishedSet {
        material,
        method: Method::Proposed,
    });
    let existing = CHOI_2014_EXISTING.iter().map(|material| PublishedSet {
        material,
        method: Method::Existing,
    });
    proposed.chain(existing)
}

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

    /// The existing method's sets: named after Table 1 materials with Table 1's η (a row of the
    /// reference CSV), and with the numbers of the paper's sentences in §4.3, quoted verbatim.
    #[test]
    fn existing_sets_match_the_paper_and_table_1() {
        const QUOTED: [&str; 3] = [
            "R: (2.152, 1.152e-10), G: (1.522, 0.4515), and B: (1.864, 0.007945)",
            "R: (1.128, 2.118), G: (1.484, 1.857), and B: (1.923, 0.2809)",
            "R: (1.624, 1.841), G: (1.222, 2.529), and B: (0.9038, 2.754)",
        ];
        let rows: Vec<Vec<&str>> = MATERIALS_CSV
            .lines()
            .filter(|l| l.contains(",choi2014,"))
            .map(|l| l.split(',').collect())
            .collect();
        assert_eq!(rows.len(), 7);
        for (m, quote) in CHOI_2014_EXISTING.iter().zip(QUOTED) {
            let row = rows
                .iter()
                .find(|r| r[0] == m.name)
                .unwrap_or_else(|| panic!("{} is not a Table 1 row", m.name));
            assert_eq!(m.eta, row[8].parse::<f64>().unwrap(), "{}", m.name);
            let numbers: Vec<f64> = quote
                .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-'))
                .filter(|t| t.chars().any(|c| c.is_ascii_digit()))
                .map(|t| t.parse().unwrap())
                .collect();
            assert_eq!(numbers.len(), 6, "{quote}");
            for c in 0..3 {
                assert_eq!(m.sigma_s_prime[c], numbers[2 * c], "{} σ′s", m.name);
                assert_eq!(m.sigma_a[c], numbers[2 * c + 1], "{} σa", m.name);
            }
        }
        // The lookup: Table 1 by the material's name, the existing method's with `-existing`.
        let p = choi_2014_set(" Pink_Plastic ").unwrap();
        assert_eq!((p.material, p.method), (&CHOI_2014[0], Method::Proposed));
        let e = choi_2014_set("brown-leather-existing").unwrap();
        assert_eq!(
            (e.material, e.method),
            (&CHOI_2014_EXISTING[2], Method::Existing)
        );
        assert_eq!(e.key(), "brown-leather-existing");
        assert!(e.citation().contains("Figure 5") && p.citation().contains("Table 1"));
        assert_eq!(
            choi_2014_set("nephrite-existing"),
            None,
            "not quoted in the paper"
        );
        assert_eq!(
            choi_2014_set("apple"),
            None,
            "Jensen et al.'s, not Choi et al.'s"
        );
        assert_eq!(choi_2014_sets().count(), 10);
        // Not rig-twin materials: `synth --material` takes Table 1's and Jensen et al.'s only.
        assert!(all().all(|m| m.source != "choi2014-existing"));
    }

    #[test]
    fn lookup_normalises_the_name() {
        assert_eq!(by_name("Pink Plastic").unwrap().name, "pink-plastic");
        assert_eq!(by_name(" WOOD_TILE ").unwrap().name, "wood-tile");
        assert_eq!(by_name("skin_1"), None);
        assert_eq!(by_name("unobtainium"), None);
    }
}
