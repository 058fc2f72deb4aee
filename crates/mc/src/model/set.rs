//! [`McTableSet`]: tables of one g and layout at several η, interpolated in η; the total Rd and its
//! inverse in the albedo.

use std::path::Path;

use super::table::McTable;
use super::weights::catmull_rom_weights;
use crate::error::{Result, check};
use crate::spec::McTableSpec;

/// How far beyond the first or last table's η a lookup may go; it then uses that table. A measured
/// η carries ~10⁻⁴ of Schlick's and the reading's error, and Rd changes with η by less than 0.2 %
/// over 0.005 (the tables' totals between η = 2.3 and 2.4), well inside the measurement's error.
pub const ETA_EDGE_TOLERANCE: f64 = 0.005;

/// Monte Carlo tables for several η with the same g and layout; interpolates in η.
#[derive(Debug, Clone, PartialEq)]
pub struct McTableSet {
    pub(super) tables: Vec<McTable>,
}

impl McTableSet {
    /// A set from tables (sorted here by η). All must share g and the albedo and radial layout.
    ///
    /// # Errors
    /// `InvalidParameter` for an empty list, mixed g or layouts, or two tables at one η.
    pub fn new(mut tables: Vec<McTable>) -> Result<Self> {
        check(!tables.is_empty(), "tables", 0.0, "need at least one table")?;
        tables.sort_by(|a, b| a.spec.eta.total_cmp(&b.spec.eta));
        let first = &tables[0];
        for t in &tables[1..] {
            check(
                t.spec.g == first.spec.g,
                "g",
                t.spec.g,
                "every table of a set must have one g",
            )?;
            check(
                t.albedos == first.albedos && t.knots == first.knots,
                "eta",
                t.spec.eta,
                "every table of a set must have the same albedo nodes and knots",
            )?;
        }
        for w in tables.windows(2) {
            check(
                w[1].spec.eta > w[0].spec.eta,
                "eta",
                w[1].spec.eta,
                "two tables at one η",
            )?;
        }
        Ok(Self { tables })
    }

    /// The tables for `etas` (each from `template` with its η), from the cache folder `dir` where a
    /// matching file is there, else simulated and saved there. `progress(table, done, total)`.
    ///
    /// # Errors
    /// As [`McTable::load_or_build`] and [`McTableSet::new`].
    pub fn load_or_build(
        etas: &[f64],
        template: &McTableSpec,
        dir: &Path,
        progress: &(dyn Fn(usize, u64, u64) + Sync),
    ) -> Result<Self> {
        let mut tables = Vec::with_capacity(etas.len());
        for (i, &eta) in etas.iter().enumerate() {
            let spec = McTableSpec {
                eta,
                ..template.clone()
            };
            let (t, _, _) = McTable::load_or_build(&spec, dir, &|d, n| progress(i, d, n))?;
            tables.push(t);
        }
        Self::new(tables)
    }

    /// The tables, by increasing η.
    pub fn tables(&self) -> &[McTable] {
        &self.tables
    }

    /// The η range covered.
    pub fn eta_range(&self) -> (f64, f64) {
        (
            self.tables[0].spec.eta,
            self.tables[self.tables.len() - 1].spec.eta,
        )
    }

    /// The Henyey–Greenstein g of every table.
    pub fn g(&self) -> f64 {
        self.tables[0].spec.g
    }

    /// Catmull-Rom weights of η over the tables (the single table itself when there is one and η is
    /// its own).
    pub(super) fn eta_weights(&self, eta: f64) -> Result<(usize, [f64; 4])> {
        let (lo, hi) = self.eta_range();
        let n = self.tables.len();
        if n == 1 {
            return if (eta - lo).abs() <= 1e-9 {
                Ok((0, [0.0, 1.0, 0.0, 0.0]))
            } else {
                Err(crate::error::out_of_table("eta", eta, lo, hi))
            };
        }
        if !(eta >= lo - ETA_EDGE_TOLERANCE && eta <= hi + ETA_EDGE_TOLERANCE) {
            return Err(crate::error::out_of_table("eta", eta, lo, hi));
        }
        // Within the tolerance beyond an end, the end table (a measured η of 2.4002 for a material
        // of 2.4 must not fail).
        let eta = eta.clamp(lo, hi);
        Ok(catmull_rom_weights(n, |k| self.tables[k].spec.eta, eta))
    }

    /// Total diffuse reflectance Rd(a, η) (excluding R_sp) by Monte Carlo: cubic Hermite in √(1 − a)
    /// on ln Rd over the albedo nodes ([`McTable::rd_total`]), then Catmull-Rom in η on ln Rd over the tables (on the default η grid
    /// within 0.2 % of adding-doubling between tables, BENCHMARKS.md). a is the single-scattering
    /// albedo (α′ for g = 0; for g ≠ 0, α′ = a(1 − g)/(1 − ag)).
    ///
    /// # Errors
    /// `OutOfTable` for a or η outside the tables.
    pub fn rd_total(&self, a: f64, eta: f64) -> Result<f64> {
        let (j, we) = self.eta_weights(eta)?;
        let mut ln_sum = 0.0;
        for (q, &w) in we.iter().enumerate() {
            if w != 0.0 {
                ln_sum += w * self.tables[j + q - 1].rd_total(a)?.ln();
            }
        }
        Ok(ln_sum.exp())
    }

    /// The albedo a (α′ for g = 0) whose Monte Carlo total diffuse reflectance at η is `rd`: the
    /// inverse of [`McTableSet::rd_total`] (increasing in a; checked at every node when a table is
    /// built), by bisection in √(1 − a) to 1e-14, so the round trip is exact to ~1e-12 in Rd.
    ///
    /// # Errors
    /// `OutOfTable` when `rd` lies outside [Rd(a_min), Rd(a_max)] at this η, or η outside the tables.
    pub fn albedo_from_rd_total(&self, rd: f64, eta: f64) -> Result<f64> {
        let a = &self.tables[0].albedos;
        invert_increasing_total(rd, a[0], a[a.len() - 1], |a| self.rd_total(a, eta))
    }
}

/// The albedo in [lo, hi] at which an increasing total diffuse reflectance `total` equals `rd`:
/// bisection in u = √(1 − a), where the Monte Carlo totals are smooth up to a = 1, to 1e-14 in u
/// (so the round trip is exact to ~1e-12 in Rd). Written by hand: the totals are fallible table
/// lookups (`?` inside the loop), and a bracketed bisection in this variable is all they need.
///
/// # Errors
/// `OutOfTable` (`rd_total`) for an `rd` outside [total(lo), total(hi)]; the lookups' own errors.
pub(crate) fn invert_increasing_total(
    rd: f64,
    lo: f64,
    hi: f64,
    total: impl Fn(f64) -> Result<f64>,
) -> Result<f64> {
    let (r_lo, r_hi) = (total(lo)?, total(hi)?);
    if !(rd >= r_lo && rd <= r_hi) {
        return Err(crate::error::out_of_table("rd_total", rd, r_lo, r_hi));
    }
    let (mut u_lo, mut u_hi) = ((1.0 - hi).sqrt(), (1.0 - lo).sqrt());
    for _ in 0..200 {
        let u = 0.5 * (u_lo + u_hi);
        if u <= u_lo || u >= u_hi || u_hi - u_lo < 1e-14 {
            break;
        }
        if total(1.0 - u * u)? >= rd {
            u_lo = u;
        } else {
            u_hi = u;
        }
    }
    let u = 0.5 * (u_lo + u_hi);
    Ok((1.0 - u * u).clamp(lo, hi))
}

#[cfg(test)]
mod tests {
    use crate::model::testing::small_set;

    /// α′ from the Monte Carlo total inverts the total at any η of the set (round trip 1e-12), and an
    /// Rd outside the tabulated range is refused.
    #[test]
    fn albedo_from_total_round_trips_across_eta() {
        let set = small_set(&[1.0, 1.4]);
        for eta in [1.0, 1.17, 1.4] {
            for a in [0.31, 0.5, 0.8, 0.95, 0.989] {
                let rd = set.rd_total(a, eta).unwrap();
                let back = set.albedo_from_rd_total(rd, eta).unwrap();
                assert!(
                    (set.rd_total(back, eta).unwrap() - rd).abs() < 1e-12,
                    "η {eta} a {a}"
                );
                assert!((back - a).abs() < 1e-9);
            }
            assert!(set.albedo_from_rd_total(0.99, eta).is_err());
            assert!(set.albedo_from_rd_total(0.001, eta).is_err());
        }
    }
}
