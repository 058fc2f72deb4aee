//! The `mc` model's tables shipped inside the crate, so that a measurement never waits for a
//! simulation: g = 0, η ∈ {1.0, 1.05, 1.1, 1.2, 1.3, …, 2.4, 2.5} (17 tables, 0.1 apart and 0.05 near 1,
//! where total internal reflection sets in; with 0.2 spacing Catmull-Rom in η was measured up to
//! 0.7 % off a table built at η = 1.33 itself, BENCHMARKS.md), each the default layout of
//! [`McTableSpec::new`] with
//! 2·10⁶ full-length photons (and 8·10⁶ / 3.2·10⁷ in the shorter strata), in compact form
//! ([`McTable::compact`]). Made by
//! `cargo run --release -p scatterfit-mc --example build_mc_tables -- crates/mc/tables 2e6 <η…>`.
//!
//! [`McTableSpec::new`]: crate::model::McTableSpec::new

use crate::error::{McError, Result};
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
}
