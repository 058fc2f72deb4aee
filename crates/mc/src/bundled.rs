//! The `mc` model's tables shipped inside the crate, so that a measurement never waits for a
//! simulation: g = 0, η ∈ {1.0, 1.05, 1.1, 1.2, 1.3, …, 2.4, 2.5} (17 tables, 0.1 apart and 0.05 near 1,
//! where total internal reflection sets in; with 0.2 spacing Catmull-Rom in η was measured up to
//! 0.7 % off a table built at η = 1.33 itself, BENCHMARKS.md), each with the layout of
//! [`McTableSpec::shipped`] (128 albedo nodes, 4·10⁶ full-length photons and 1.6·10⁷ / 3.2·10⁷ in
//! the shorter strata, a seed per η; since 2026-11-29 one more node at a = 0.01 from a low-albedo
//! run of 6.4·10⁸ photons, [`crate::LowAlbedoRun`]), in compact form ([`McTable::compact`]). Made by
//! `cargo run --release -p scatterfit-mc --example build_mc_tables -- crates/mc/tables <η…>`
//! (rebuilt 2026-11-27 from 64 nodes and 2·10⁶ photons: CHANGELOG.md, "The g = 0 tables rebuilt").
//!
//! [`McTableSpec::shipped`]: crate::model::McTableSpec::shipped

use crate::error::{McError, Result};
use crate::grid_g::McGridSet;
use crate::model::{McTable, McTableSet};

/// The η of the shipped tables.
pub const BUNDLED_ETAS: [f64; 17] = [
    1.0, 1.05, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8, 1.9, 2.0, 2.1, 2.2, 2.3, 2.4, 2.5,
];

const BUNDLED_JSON: [&str; 17] = [
    include_str!("../tables/mc-white-eta1.00.json"),
    include_str!("../tables/mc-white-eta1.05.json"),
    include_str!("../tables/mc-white-eta1.10.json"),
    include_str!("../tables/mc-white-eta1.20.json"),
    include_str!("../tables/mc-white-eta1.30.json"),
    include_str!("../tables/mc-white-eta1.40.json"),
    include_str!("../tables/mc-white-eta1.50.json"),
    include_str!("../tables/mc-white-eta1.60.json"),
    include_str!("../tables/mc-white-eta1.70.json"),
    include_str!("../tables/mc-white-eta1.80.json"),
    include_str!("../tables/mc-white-eta1.90.json"),
    include_str!("../tables/mc-white-eta2.00.json"),
    include_str!("../tables/mc-white-eta2.10.json"),
    include_str!("../tables/mc-white-eta2.20.json"),
    include_str!("../tables/mc-white-eta2.30.json"),
    include_str!("../tables/mc-white-eta2.40.json"),
    // Added so that red aluminum (Choi et al. 2014, η = 2.4102) lies inside the set.
    include_str!("../tables/mc-white-eta2.50.json"),
];

/// One entry of [`BUNDLED_G`]: (η, g, the table's compact JSON from `../tables-g/`).
macro_rules! g_table {
    ($eta:literal, $g:literal, $eta_name:literal, $g_name:literal) => {
        (
            $eta,
            $g,
            include_str!(concat!(
                "../tables-g/mc-white-eta",
                $eta_name,
                "-g",
                $g_name,
                ".json"
            )),
        )
    };
}

/// The anisotropic tables shipped with the crate (`crates/mc/tables-g/`, README there): (η, g,
/// compact JSON). g = 0.15, 0.3, 0.5, 0.7 and 0.9 at η 1.0, 1.05, 1.1–1.8 (0.1 apart), 2.0–2.4 (0.2
/// apart) and 2.5; g = 0.8 and 0.95 at η 1.0, 1.05, 1.1, 1.2, 1.3, 1.4, 1.6–2.4 (0.2 apart) and 2.5
/// (g 0.95 had η 1.0, 1.4, 1.8, 2.4 until 2026-11-27: Catmull-Rom over 0.4–0.6 in η was up to 4.6 %
/// off in shape and 6.7·10⁻³ in the total, CHANGELOG.md "The g 0.95 node's η layout filled in");
/// Henyey–Greenstein, 10⁶ full-length photons each, albedo nodes over α′ 0.2–0.99995
/// (`examples/common/g_tables_layout.rs`), equally spaced in √(1 − α′) but at g = 0.95 (in √(1 − a)),
/// and below them nodes down to α′ 0.01 from a short run of their own (1.6·10⁸ photons stopped
/// after a few dozen interactions; [`crate::LowAlbedoRun`], added
/// 2026-11-29: 8 nodes, 79 at g = 0.95 where √(1 − a) spreads that range). 5.4 MB in all (the
/// g = 0 set: 1.5 MB).
#[rustfmt::skip]
pub const BUNDLED_G: [(f64, f64, &str); 94] = [
    g_table!(1.0, 0.15, "1.00", "0.15"),
    g_table!(1.05, 0.15, "1.05", "0.15"),
    g_table!(1.1, 0.15, "1.10", "0.15"),
    g_table!(1.2, 0.15, "1.20", "0.15"),
    g_table!(1.3, 0.15, "1.30", "0.15"),
    g_table!(1.4, 0.15, "1.40", "0.15"),
    g_table!(1.5, 0.15, "1.50", "0.15"),
    g_table!(1.6, 0.15, "1.60", "0.15"),
    g_table!(1.7, 0.15, "1.70", "0.15"),
    g_table!(1.8, 0.15, "1.80", "0.15"),
    g_table!(2.0, 0.15, "2.00", "0.15"),
    g_table!(2.2, 0.15, "2.20", "0.15"),
    g_table!(2.4, 0.15, "2.40", "0.15"),
    g_table!(2.5, 0.15, "2.50", "0.15"),
    g_table!(1.0, 0.3, "1.00", "0.30"),
    g_table!(1.05, 0.3, "1.05", "0.30"),
    g_table!(1.1, 0.3, "1.10", "0.30"),
    g_table!(1.2, 0.3, "1.20", "0.30"),
    g_table!(1.3, 0.3, "1.30", "0.30"),
    g_table!(1.4, 0.3, "1.40", "0.30"),
    g_table!(1.5, 0.3, "1.50", "0.30"),
    g_table!(1.6, 0.3, "1.60", "0.30"),
    g_table!(1.7, 0.3, "1.70", "0.30"),
    g_table!(1.8, 0.3, "1.80", "0.30"),
    g_table!(2.0, 0.3, "2.00", "0.30"),
    g_table!(2.2, 0.3, "2.20", "0.30"),
    g_table!(2.4, 0.3, "2.40", "0.30"),
    g_table!(2.5, 0.3, "2.50", "0.30"),
    g_table!(1.0, 0.5, "1.00", "0.50"),
    g_table!(1.05, 0.5, "1.05", "0.50"),
    g_table!(1.1, 0.5, "1.10", "0.50"),
    g_table!(1.2, 0.5, "1.20", "0.50"),
    g_table!(1.3, 0.5, "1.30", "0.50"),
    g_table!(1.4, 0.5, "1.40", "0.50"),
    g_table!(1.5, 0.5, "1.50", "0.50"),
    g_table!(1.6, 0.5, "1.60", "0.50"),
    g_table!(1.7, 0.5, "1.70", "0.50"),
    g_table!(1.8, 0.5, "1.80", "0.50"),
    g_table!(2.0, 0.5, "2.00", "0.50"),
    g_table!(2.2, 0.5, "2.20", "0.50"),
    g_table!(2.4, 0.5, "2.40", "0.50"),
    g_table!(2.5, 0.5, "2.50", "0.50"),
    g_table!(1.0, 0.7, "1.00", "0.70"),
    g_table!(1.05, 0.7, "1.05", "0.70"),
    g_table!(1.1, 0.7, "1.10", "0.70"),
    g_table!(1.2, 0.7, "1.20", "0.70"),
    g_table!(1.3, 0.7, "1.30", "0.70"),
    g_table!(1.4, 0.7, "1.40", "0.70"),
    g_table!(1.5, 0.7, "1.50", "0.70"),
    g_table!(1.6, 0.7, "1.60", "0.70"),
    g_table!(1.7, 0.7, "1.70", "0.70"),
    g_table!(1.8, 0.7, "1.80", "0.70"),
    g_table!(2.0, 0.7, "2.00", "0.70"),
    g_table!(2.2, 0.7, "2.20", "0.70"),
    g_table!(2.4, 0.7, "2.40", "0.70"),
    g_table!(2.5, 0.7, "2.50", "0.70"),
    g_table!(1.0, 0.8, "1.00", "0.80"),
    g_table!(1.05, 0.8, "1.05", "0.80"),
    g_table!(1.1, 0.8, "1.10", "0.80"),
    g_table!(1.2, 0.8, "1.20", "0.80"),
    g_table!(1.3, 0.8, "1.30", "0.80"),
    g_table!(1.4, 0.8, "1.40", "0.80"),
    g_table!(1.6, 0.8, "1.60", "0.80"),
    g_table!(1.8, 0.8, "1.80", "0.80"),
    g_table!(2.0, 0.8, "2.00", "0.80"),
    g_table!(2.2, 0.8, "2.20", "0.80"),
    g_table!(2.4, 0.8, "2.40", "0.80"),
    g_table!(2.5, 0.8, "2.50", "0.80"),
    g_table!(1.0, 0.9, "1.00", "0.90"),
    g_table!(1.05, 0.9, "1.05", "0.90"),
    g_table!(1.1, 0.9, "1.10", "0.90"),
    g_table!(1.2, 0.9, "1.20", "0.90"),
    g_table!(1.3, 0.9, "1.30", "0.90"),
    g_table!(1.4, 0.9, "1.40", "0.90"),
    g_table!(1.5, 0.9, "1.50", "0.90"),
    g_table!(1.6, 0.9, "1.60", "0.90"),
    g_table!(1.7, 0.9, "1.70", "0.90"),
    g_table!(1.8, 0.9, "1.80", "0.90"),
    g_table!(2.0, 0.9, "2.00", "0.90"),
    g_table!(2.2, 0.9, "2.20", "0.90"),
    g_table!(2.4, 0.9, "2.40", "0.90"),
    g_table!(2.5, 0.9, "2.50", "0.90"),
    g_table!(1.0, 0.95, "1.00", "0.95"),
    g_table!(1.05, 0.95, "1.05", "0.95"),
    g_table!(1.1, 0.95, "1.10", "0.95"),
    g_table!(1.2, 0.95, "1.20", "0.95"),
    g_table!(1.3, 0.95, "1.30", "0.95"),
    g_table!(1.4, 0.95, "1.40", "0.95"),
    g_table!(1.6, 0.95, "1.60", "0.95"),
    g_table!(1.8, 0.95, "1.80", "0.95"),
    g_table!(2.0, 0.95, "2.00", "0.95"),
    g_table!(2.2, 0.95, "2.20", "0.95"),
    g_table!(2.4, 0.95, "2.40", "0.95"),
    g_table!(2.5, 0.95, "2.50", "0.95"),
];

/// The largest g step the shipped grid interpolates across: 0.2 (between 0.3, 0.5 and 0.7; 0.15
/// between 0, 0.15 and 0.3; 0.1 and 0.05 above). Measured against tables built between the nodes
/// (CHANGELOG.md "The g tables rebuilt, and the whole g range", and "η 2.5 at g ≠ 0, a g 0.15
/// node"): ≤ 0.6 % RMS over 0.3–10 reduced mean free paths at α′ ≥ 0.5 (1–3 % at α′ 0.3, where the
/// profile is short), totals within 9·10⁻⁴.
pub const BUNDLED_MAX_G_STEP: f64 = 0.2 + 1e-9;

impl McGridSet {
    /// The shipped grid: the g = 0 set ([`McTableSet::bundled`]) and the anisotropic tables
    /// ([`BUNDLED_G`]), interpolated in g between nodes at most [`BUNDLED_MAX_G_STEP`] apart.
    ///
    /// # Errors
    /// `Format` if an embedded table does not parse (a build defect).
    pub fn bundled() -> Result<Self> {
        let mut sets = vec![McTableSet::bundled()?];
        let mut gs: Vec<f64> = BUNDLED_G.iter().map(|&(_, g, _)| g).collect();
        gs.dedup();
        for g in gs {
            let tables = BUNDLED_G
                .iter()
                .filter(|&&(_, tg, _)| tg == g)
                .map(|&(eta, g, json)| {
                    McTable::from_json(json).map_err(|message| McError::Format {
                        path: format!("<bundled mc table η = {eta}, g = {g}>").into(),
                        message,
                    })
                })
                .collect::<Result<Vec<_>>>()?;
            sets.push(McTableSet::new(tables)?);
        }
        Self::new(sets, BUNDLED_MAX_G_STEP)
    }
}

impl McTableSet {
    /// The shipped tables (g = 0, η from 1.0 to 2.5; module docs), parsed from the copies compiled
    /// into the crate (a few milliseconds: keep the set rather than calling this per evaluation).
    ///
    /// # Errors
    /// `Format` if an embedded table does not parse (a build defect).
    pub fn bundled() -> Result<Self> {
        let tables = BUNDLED_JSON
            .iter()
            .zip(BUNDLED_ETAS)
            .map(|(json, eta)| {
                McTable::from_json(json).map_err(|message| McError::Format {
                    path: format!("<bundled mc table η = {eta}>").into(),
                    message,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Self::new(tables)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every embedded table parses, sits at its η and has g = 0.
    #[test]
    fn bundled_tables_parse() {
        let set = McTableSet::bundled().unwrap();
        let etas: Vec<f64> = set.tables().iter().map(|t| t.spec().eta).collect();
        assert_eq!(etas, BUNDLED_ETAS);
        assert_eq!(set.g(), 0.0);
        assert_eq!(set.eta_range(), (1.0, 2.5));
    }

    /// Every embedded anisotropic table parses, sits at its (η, g) (the file name's), and the
    /// grid has the nodes g = 0, 0.15, 0.3, 0.5, 0.7, 0.8, 0.9, 0.95 with the η ranges of the README.
    #[test]
    fn bundled_grid_parses() {
        let grid = McGridSet::bundled().unwrap();
        assert_eq!(
            grid.g_nodes(),
            vec![0.0, 0.15, 0.3, 0.5, 0.7, 0.8, 0.9, 0.95]
        );
        for (set, n, top) in [
            (1, 14, 2.5),
            (2, 14, 2.5),
            (3, 14, 2.5),
            (4, 14, 2.5),
            (5, 12, 2.5),
            (6, 14, 2.5),
            (7, 12, 2.5),
        ] {
            let set = &grid.nodes()[set];
            assert_eq!(set.tables().len(), n);
            assert_eq!(set.eta_range(), (1.0, top));
        }
        for &(eta, g, json) in &BUNDLED_G {
            let t = McTable::from_json(json).unwrap();
            // (The η = 1.7 table was built at 1.0 + 7 × 0.1 = 1.7000000000000002.)
            assert!((t.spec().eta - eta).abs() < 1e-12 && t.spec().g == g);
        }
        assert_eq!(grid.nodes()[0], McTableSet::bundled().unwrap());
    }
}
