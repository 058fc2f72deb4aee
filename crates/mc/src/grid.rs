//! Radial and angular tally grids.

use serde::{Deserialize, Serialize};

use crate::error::{Result, check};

/// Annuli [r_i, r_{i+1}) of the radial reflectance tally, in mm, starting at r = 0. Photons leaving
/// beyond the last edge count in the totals only.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RadialGrid {
    edges: Vec<f64>,
    /// Bin width when the grid is uniform (fast O(1) lookup), else 0.
    #[serde(skip)]
    uniform_dr: f64,
    /// 1 / `uniform_dr` (0 when not uniform).
    #[serde(skip)]
    inv_dr: f64,
}

impl RadialGrid {
    /// `bins` annuli of width `dr` [mm] (MCML's grid: `dr`, `nr`).
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
        Ok(Self {
            edges: (0..=bins).map(|i| i as f64 * dr).collect(),
            uniform_dr: dr,
            inv_dr: 1.0 / dr,
        })
    }

    /// Annuli between the given edges [mm]: the first must be 0, the rest strictly increasing and finite.
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
        Ok(Self {
            edges,
            uniform_dr: 0.0,
            inv_dr: 0.0,
        })
    }

    /// `bins` annuli: [0, r_first) then logarithmically spaced up to `r_max` [mm].
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

    /// Bin edges [mm], one more than the number of bins.
    pub fn edges(&self) -> &[f64] {
        &self.edges
    }
    /// Number of annuli.
    pub fn bins(&self) -> usize {
        self.edges.len() - 1
    }
    /// Area π(r_{i+1}² − r_i²) of annulus `i` [mm²].
    pub fn area(&self, i: usize) -> f64 {
        std::f64::consts::PI * (self.edges[i + 1].powi(2) - self.edges[i].powi(2))
    }
    /// Area-weighted mean radius of annulus `i`, ⅔ (r₂³ − r₁³)/(r₂² − r₁²) [mm]: where a profile that is
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

    /// Scaled copy: every edge times `factor` (> 0).
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            edges: self.edges.iter().map(|e| e * factor).collect(),
            uniform_dr: self.uniform_dr * factor,
            inv_dr: self.inv_dr / factor,
        }
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

    #[test]
    fn centre_of_annulus() {
        let g = RadialGrid::from_edges(vec![0.0, 3.0]).unwrap();
        assert!((g.center(0) - 2.0).abs() < 1e-15);
    }
}
