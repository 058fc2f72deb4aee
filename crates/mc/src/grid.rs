//! Radial and angular tally grids.

use serde::{Deserialize, Serialize};

use crate::error::{Result, check};

/// Annuli [r_i, r_{i+1}) of the radial reflectance tally, in mm, starting at r = 0. Photons leaving
/// beyond the last edge count in the totals only.
///
/// Built only through the checked constructors; JSON holds the edges and is read back through
/// [`RadialGrid::from_edges`] (`#[serde(try_from)]`), which also recognises a uniform grid, so a grid
/// read back equals the one written. Two grids are equal when their edges are.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "RawGrid")]
pub struct RadialGrid {
    edges: Vec<f64>,
    /// Bin width when the grid is uniform (fast O(1) lookup), else 0.
    #[serde(skip)]
    uniform_dr: f64,
    /// 1 / `uniform_dr` (0 when not uniform).
    #[serde(skip)]
    inv_dr: f64,
}

/// The unchecked shape of [`RadialGrid`] in files.
#[derive(Deserialize)]
struct RawGrid {
    edges: Vec<f64>,
}

impl TryFrom<RawGrid> for RadialGrid {
    type Error = crate::McError;
    fn try_from(raw: RawGrid) -> Result<Self> {
        Self::from_edges(raw.edges)
    }
}

impl PartialEq for RadialGrid {
    /// Equal edges (the lookup fields are derived from them).
    fn eq(&self, other: &Self) -> bool {
        self.edges == other.edges
    }
}

impl RadialGrid {
    /// `bins` annuli of width `dr` \[mm\] (MCML's grid: `dr`, `nr`).
    ///
    /// # Errors
    /// `InvalidParameter` for dr not finite and > 0, or zero bins.
    pub fn uniform(dr: f64, bins: usize) -> Result<Self> {
        check(
            dr.is_finite() && dr > 0.0,
            "dr",
            dr,
            "the radial bin width must be finite and > 0 mm",
        )?;
        check(
            bins > 0,
            "bins",
            0.0,
            "the radial grid needs at least one bin",
        )?;
        let mut edges = Vec::new();
        edges
            .try_reserve_exact(bins.saturating_add(1))
            .map_err(|_| {
                crate::McError::Optics(scatterfit_optics::OpticsError::InvalidParameter {
                    name: "bins",
                    value: bins as f64,
                    reason: "too many radial bins to allocate; use fewer",
                })
            })?;
        edges.extend((0..=bins).map(|i| i as f64 * dr));
        Ok(Self {
            edges,
            uniform_dr: dr,
            inv_dr: 1.0 / dr,
        })
    }

    /// Annuli between the given edges \[mm\]: the first must be 0, the rest strictly increasing and finite.
    /// Edges that are exactly i·dr (as [`RadialGrid::uniform`] makes them) give a uniform grid.
    ///
    /// # Errors
    /// `InvalidParameter` when the edges break those rules or there are fewer than two.
    pub fn from_edges(edges: Vec<f64>) -> Result<Self> {
        check(
            edges.len() >= 2,
            "edges",
            edges.len() as f64,
            "need at least two edges",
        )?;
        check(
            edges[0] == 0.0,
            "edges[0]",
            edges[0],
            "the first edge must be 0 mm",
        )?;
        for w in edges.windows(2) {
            check(
                w[1].is_finite() && w[1] > w[0],
                "edges",
                w[1],
                "edges must be finite and strictly increasing",
            )?;
        }
        let dr = edges[1];
        let uniform = edges.iter().enumerate().all(|(i, &e)| e == i as f64 * dr);
        Ok(Self {
            edges,
            uniform_dr: if uniform { dr } else { 0.0 },
            inv_dr: if uniform { 1.0 / dr } else { 0.0 },
        })
    }

    /// `bins` annuli: [0, r_first) then logarithmically spaced up to `r_max` \[mm\].
    ///
    /// # Errors
    /// `InvalidParameter` unless 0 < r_first < r_max (finite) and bins ≥ 2.
    pub fn logarithmic(r_first: f64, r_max: f64, bins: usize) -> Result<Self> {
        check(
            r_first.is_finite() && r_first > 0.0 && r_max.is_finite() && r_max > r_first,
            "r_first",
            r_first,
            "need 0 < r_first < r_max",
        )?;
        check(bins >= 2, "bins", bins as f64, "need at least two bins")?;
        let q = (r_max / r_first).ln() / (bins - 1) as f64;
        let mut edges = vec![0.0];
        edges.extend((0..bins).map(|i| r_first * (q * i as f64).exp()));
        *edges.last_mut().expect("bins ≥ 2") = r_max;
        Self::from_edges(edges)
    }

    /// Bin edges \[mm\], one more than the number of bins.
    pub fn edges(&self) -> &[f64] {
        &self.edges
    }
    /// Number of annuli.
    pub fn bins(&self) -> usize {
        self.edges.len() - 1
    }
    /// Area π(r_{i+1}² − r_i²) of annulus `i` \[mm²\].
    pub fn area(&self, i: usize) -> f64 {
        std::f64::consts::PI * (self.edges[i + 1].powi(2) - self.edges[i].powi(2))
    }
    /// Area-weighted mean radius of annulus `i`, ⅔ (r₂³ − r₁³)/(r₂² − r₁²) \[mm\]: where a profile that is
    /// linear across the bin takes the bin's average value.
    pub fn center(&self, i: usize) -> f64 {
        let (a, b) = (self.edges[i], self.edges[i + 1]);
        2.0 / 3.0 * (b.powi(3) - a.powi(3)) / (b * b - a * a)
    }
    /// The annulus holding radius `r`, or `None` beyond the last edge.
    #[inline]
    pub(crate) fn find(&self, r: f64) -> Option<usize> {
        let nb = self.edges.len() - 1;
        if self.uniform_dr > 0.0 {
            let i = (r * self.inv_dr) as usize;
            // Guard the last edge against rounding in i·dr.
            if i < nb && r < self.edges[i + 1] {
                return Some(i);
            }
            if i < nb {
                return Some(i + 1).filter(|&j| j < nb);
            }
            return None;
        }
        let i = self.edges.partition_point(|&e| e <= r);
        (i >= 1 && i <= nb).then(|| i - 1)
    }

    /// Scaled copy: every edge times `factor`.
    ///
    /// # Errors
    /// `InvalidParameter` unless `factor` is finite and > 0 (and the scaled edges stay finite).
    pub fn scaled(&self, factor: f64) -> Result<Self> {
        check(
            factor.is_finite() && factor > 0.0,
            "factor",
            factor,
            "a grid is scaled by a finite factor > 0",
        )?;
        Self::from_edges(self.edges.iter().map(|e| e * factor).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_uniform_and_general_agree() {
        let u = RadialGrid::uniform(0.1, 50).unwrap();
        let g = RadialGrid::from_edges(u.edges().to_vec()).unwrap();
        for k in 0..6000 {
            let r = k as f64 * 0.000_997;
            assert_eq!(u.find(r), g.find(r), "r = {r}");
        }
        assert_eq!(u.find(5.0), None);
        assert_eq!(u.find(0.0), Some(0));
    }

    #[test]
    fn bad_grids_are_refused() {
        assert!(RadialGrid::uniform(0.0, 3).is_err());
        assert!(RadialGrid::uniform(0.1, 0).is_err());
        assert!(RadialGrid::from_edges(vec![0.0, 1.0, 1.0]).is_err());
        assert!(RadialGrid::from_edges(vec![0.1, 1.0]).is_err());
        assert!(RadialGrid::logarithmic(0.0, 1.0, 4).is_err());
    }

    /// A grid read back from JSON equals the one written and keeps its fast uniform lookup; bad
    /// edges in a file are refused by the same checks as the constructor.
    #[test]
    fn json_round_trip_goes_through_the_checks() {
        for grid in [
            RadialGrid::uniform(0.1, 200).unwrap(),
            RadialGrid::logarithmic(0.005, 200.0, 64).unwrap(),
        ] {
            let json = serde_json::to_string(&grid).unwrap();
            let back: RadialGrid = serde_json::from_str(&json).unwrap();
            assert_eq!(back, grid);
            assert_eq!(
                (back.uniform_dr, back.inv_dr),
                (grid.uniform_dr, grid.inv_dr)
            );
        }
        for bad in [
            r#"{"edges":[0.1,1.0]}"#,
            r#"{"edges":[0.0,1.0,1.0]}"#,
            r#"{"edges":[0.0]}"#,
            r#"{"edges":[0.0,-1.0]}"#,
        ] {
            assert!(serde_json::from_str::<RadialGrid>(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn centre_of_annulus() {
        let g = RadialGrid::from_edges(vec![0.0, 3.0]).unwrap();
        assert!((g.center(0) - 2.0).abs() < 1e-15);
    }
}
