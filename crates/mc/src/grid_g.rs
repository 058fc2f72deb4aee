//! The `mc` forward model over (η, g): one [`McTableSet`] per Henyey–Greenstein g (each
//! interpolating in η, [`crate::model`]), and an interpolation in g between neighbouring sets.
//!
//! **Reduced units.** Tables of different g are in their own single-scattering albedo a = σs/σt
//! and σt = σa + σ′s/(1 − g); [`McProfile::new`] maps (σ′s, σa) onto each (similarity, pbrt's
//! `TabulatedBSSRDF::Sr`, docs/physics.md §2.3). At fixed (σ′s, σa) every node therefore answers at
//! the same σ′t = σa + σ′s and α′ = σ′s/σ′t, so interpolating ln Rd(r) in g at fixed r is
//! interpolating ln R′(ρ′; α′) = ln(Rd/σ′t²) in g at fixed reduced radius ρ′ = σ′t r and reduced
//! albedo α′ — the comparison in which Rd changes least with g (the similarity relation σ′s =
//! σs(1 − g) holds in the far field; Wyman, Patterson & Wilson 1989).
//!
//! **Interpolation in g.** Linear in g on ln Rd(r) (the profile) and on Rd (the total), between the
//! two bracketing nodes, and only where they are at most [`McGridSet::max_step`] apart; a g within
//! [`G_NODE_TOLERANCE`] of a node is that node's set, unchanged (so g = 0 gives exactly the g = 0
//! tables' numbers). The shipped nodes are 0, 0.15, 0.3, 0.5, 0.7, 0.8, 0.9, 0.95 (`max_step` 0.2), so
//! every g in 0–0.95 is answered and nothing beyond is extrapolated. Measured (BENCHMARKS.md, "The
//! `mc` model over g" and "The g tables rebuilt, and the whole g range"; `examples/g_model_check.rs`):
//! at g = 0.85 (η 1.4) the interpolant is within 0.2–0.4 % of a table built there over 1–10 mean
//! free paths at α′ ≥ 0.9; halfway between the low nodes (g 0.15, 0.4, 0.6, η 1.4) within 0.6 % RMS
//! over 0.3–10 mean free paths at α′ ≥ 0.5 of 10⁶-photon tables built there (1–5 % at α′ 0.3 in
//! the short profile's far windows); totals within 7.1·10⁻⁴ (g 0.15) and 1.6·10⁻⁴ (0.4, 0.6) of
//! adding-doubling's. Before the low nodes, interpolating across 0–0.8 was 1–6 % off MCML at
//! g = 0.5, so a grid with such a gap (wider than `max_step`) refuses the g inside it with
//! [`McError::Optics`] (`OpticsError::AnisotropyNotTabulated`).
//!
//! Derivatives: Rd = Rd_lo^(1−t) Rd_hi^t, so ∂Rd/∂θ = Rd [(1 − t) ∂Rd_lo/∂θ / Rd_lo + t ∂Rd_hi/∂θ /
//! Rd_hi] for θ = σ′s, σa (t depends on g only) — the derivatives of the interpolant, exactly.

use scatterfit_optics::{OpticalProperties, ProfileModel, ProfileSample};

use crate::error::{McError, Result, check};
use crate::model::{McProfile, McTableSet};

/// How close a g must be to a node to be that node (a g typed as 0.8 parses to the node exactly;
/// this absorbs arithmetic on it).
pub const G_NODE_TOLERANCE: f64 = 1e-9;

/// Single-scattering albedo a with reduced albedo α′ at asymmetry g: a = α′/(1 − g + gα′).
pub fn albedo_from_reduced(albedo_prime: f64, g: f64) -> f64 {
    albedo_prime / (1.0 - g + g * albedo_prime)
}

/// Reduced albedo α′ with single-scattering albedo a at asymmetry g: α′ = a(1 − g)/(1 − ag).
pub fn reduced_from_albedo(a: f64, g: f64) -> f64 {
    a * (1.0 - g) / (1.0 - a * g)
}

/// Where a g falls on the grid.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Place {
    /// At node `k`.
    Node(usize),
    /// Between nodes `k` and `k + 1`, fraction `t` of the way.
    Between(usize, f64),
}

/// `mc` tables over (η, g): one [`McTableSet`] per g node (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct McGridSet {
    nodes: Vec<McTableSet>,
    max_step: f64,
}

impl McGridSet {
    /// A grid from one set per g (sorted here by g), interpolating in g only between neighbouring
    /// nodes at most `max_step` apart (0: only the nodes themselves).
    ///
    /// # Errors
    /// `InvalidParameter` for no sets, two sets at one g, or a negative or non-finite `max_step`.
    pub fn new(mut nodes: Vec<McTableSet>, max_step: f64) -> Result<Self> {
        check(
            !nodes.is_empty(),
            "sets",
            0.0,
            "need at least one table set",
        )?;
        check(
            max_step.is_finite() && max_step >= 0.0,
            "max_step",
            max_step,
            "the largest g step to interpolate across must be finite and ≥ 0",
        )?;
        nodes.sort_by(|a, b| a.g().total_cmp(&b.g()));
        for w in nodes.windows(2) {
            check(
                w[1].g() - w[0].g() > G_NODE_TOLERANCE,
                "g",
                w[1].g(),
                "two table sets at one g",
            )?;
        }
        Ok(Self { nodes, max_step })
    }

    /// The sets, by increasing g.
    pub fn nodes(&self) -> &[McTableSet] {
        &self.nodes
    }

    /// The grid of the nodes whose g `keep` accepts, with the same `max_step` (a grid with fewer
    /// nodes: to measure what a node adds, or to hold code to a grid with a gap).
    ///
    /// # Errors
    /// `InvalidParameter` when no node is kept.
    pub fn with_nodes(&self, keep: impl Fn(f64) -> bool) -> Result<Self> {
        Self::new(
            self.nodes.iter().filter(|s| keep(s.g())).cloned().collect(),
            self.max_step,
        )
    }

    /// The g of the nodes.
    pub fn g_nodes(&self) -> Vec<f64> {
        self.nodes.iter().map(McTableSet::g).collect()
    }

    /// The largest distance in g between two nodes that is interpolated across.
    pub fn max_step(&self) -> f64 {
        self.max_step
    }

    /// The g values and η ranges the grid covers, in words (for error messages), e.g.
    /// "g 0–0.95 (tables at 0, 0.15, …, 0.95, linear in g between; η 1–2.5)".
    pub fn coverage(&self) -> String {
        let mut parts = Vec::new();
        for (k, end) in self.runs() {
            let lo = self.nodes[k..=end]
                .iter()
                .map(|s| s.eta_range().0)
                .fold(f64::NEG_INFINITY, f64::max);
            let hi = self.nodes[k..=end]
                .iter()
                .map(|s| s.eta_range().1)
                .fold(f64::INFINITY, f64::min);
            if end == k {
                parts.push(format!("g = {} (η {lo}–{hi})", self.nodes[k].g()));
            } else {
                let nodes: Vec<String> = self.nodes[k..=end]
                    .iter()
                    .map(|s| s.g().to_string())
                    .collect();
                parts.push(format!(
                    "g {}–{} (tables at {}, linear in g between; η {lo}–{hi})",
                    self.nodes[k].g(),
                    self.nodes[end].g(),
                    nodes.join(", ")
                ));
            }
        }
        parts.join("; ")
    }

    /// The g the grid answers, as closed intervals by increasing g: a run of nodes each within
    /// [`McGridSet::max_step`] of the next is one interval, a lone node a point (`lo == hi`).
    /// Within each interval every g is a node or interpolated between two; outside all of them
    /// [`McGridSet::profile`] refuses with `AnisotropyNotTabulated` (never extrapolates).
    pub fn covered(&self) -> Vec<(f64, f64)> {
        self.runs()
            .into_iter()
            .map(|(k, end)| (self.nodes[k].g(), self.nodes[end].g()))
            .collect()
    }

    /// The runs of nodes each within `max_step` of the next, as (first, last) node indices: each
    /// run is one interval of g the grid answers.
    fn runs(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        let mut k = 0;
        while k < self.nodes.len() {
            let mut end = k;
            while end + 1 < self.nodes.len()
                && self.nodes[end + 1].g() - self.nodes[end].g() <= self.max_step
            {
                end += 1;
            }
            out.push((k, end));
            k = end + 1;
        }
        out
    }

    /// True when the grid answers at `g` (a node, or between two nodes at most `max_step` apart).
    pub fn covers(&self, g: f64) -> bool {
        self.place(g).is_ok()
    }

    fn not_tabulated(&self, g: f64) -> McError {
        McError::Optics(scatterfit_optics::OpticsError::AnisotropyNotTabulated {
            given: g,
            tabulated: self.coverage(),
        })
    }

    fn place(&self, g: f64) -> Result<Place> {
        if !g.is_finite() {
            return Err(self.not_tabulated(g));
        }
        let gs = self.g_nodes();
        if let Some(k) = gs.iter().position(|&n| (g - n).abs() <= G_NODE_TOLERANCE) {
            return Ok(Place::Node(k));
        }
        let k = gs.partition_point(|&n| n < g);
        if k == 0 || k == gs.len() || gs[k] - gs[k - 1] > self.max_step {
            return Err(self.not_tabulated(g));
        }
        Ok(Place::Between(k - 1, (g - gs[k - 1]) / (gs[k] - gs[k - 1])))
    }

    /// The node sets and weights for g: one (set, 1) at a node, two between.
    fn weights(&self, g: f64) -> Result<Vec<(&McTableSet, f64)>> {
        Ok(match self.place(g)? {
            Place::Node(k) => vec![(&self.nodes[k], 1.0)],
            Place::Between(k, t) => vec![(&self.nodes[k], 1.0 - t), (&self.nodes[k + 1], t)],
        })
    }

    /// The η range the grid answers at g: the intersection of the bracketing nodes' ranges.
    ///
    /// # Errors
    /// `AnisotropyNotTabulated` for a g the grid does not cover.
    pub fn eta_range_at(&self, g: f64) -> Result<(f64, f64)> {
        Ok(self
            .weights(g)?
            .iter()
            .map(|(set, _)| set.eta_range())
            .fold((f64::NEG_INFINITY, f64::INFINITY), |(lo, hi), (a, b)| {
                (lo.max(a), hi.min(b))
            }))
    }

    /// Checks that every node g needs has tables at η (with the sets' edge tolerance,
    /// [`crate::model::ETA_EDGE_TOLERANCE`]), so that a query beyond a g node's η range is refused
    /// naming the node and its range rather than as a bare table bound.
    fn check_eta(&self, eta: f64, g: f64) -> Result<()> {
        for (set, _) in self.weights(g)? {
            let (min, max) = set.eta_range();
            let tol = crate::model::ETA_EDGE_TOLERANCE;
            if eta.is_finite() && !(eta >= min - tol && eta <= max + tol) {
                return Err(McError::Optics(
                    scatterfit_optics::OpticsError::EtaNotTabulatedAtG {
                        eta,
                        g,
                        node: set.g(),
                        min,
                        max,
                        tabulated: self.coverage(),
                    },
                ));
            }
        }
        Ok(())
    }

    /// The model for `props` at its own g ([`OpticalProperties::g`]).
    ///
    /// # Errors
    /// `AnisotropyNotTabulated` for a g the grid does not cover; `EtaNotTabulatedAtG` for η
    /// outside the tables of a node g needs; `OutOfTable` for α′ outside a node's tables.
    pub fn profile(&self, props: &OpticalProperties) -> Result<McGridProfile> {
        self.check_eta(props.eta(), props.g())?;
        Ok(match self.place(props.g())? {
            Place::Node(k) => McGridProfile::Node(self.node_profile(k, props)?),
            Place::Between(k, t) => {
                let lo = self.node_profile(k, props)?;
                let hi = self.node_profile(k + 1, props)?;
                let rd_total = (1.0 - t) * lo.rd_total() + t * hi.rd_total();
                McGridProfile::Between {
                    lo,
                    hi,
                    t,
                    rd_total,
                }
            }
        })
    }

    /// Node `k`'s model for `props`, continued beyond the node's radial range by the g = 0 node's
    /// shape when the node's g is not 0 and the g = 0 node answers at these σ′s, σa and η
    /// ([`McProfile::with_far_field`]).
    fn node_profile(&self, k: usize, props: &OpticalProperties) -> Result<McProfile> {
        let own = McProfile::new(&self.nodes[k], props)?;
        let isotropic = &self.nodes[0];
        if k == 0 || isotropic.g().abs() > G_NODE_TOLERANCE {
            return Ok(own);
        }
        Ok(match McProfile::far_field_donor(isotropic, props) {
            Ok(donor) => own.with_far_field(donor),
            Err(_) => own,
        })
    }

    /// Total diffuse reflectance (excluding R_sp) at reduced albedo α′, η and g: each node's total
    /// at its single-scattering albedo a = α′/(1 − g + gα′) ([`McTableSet::rd_total`]), linear in g
    /// between two nodes.
    ///
    /// # Errors
    /// As [`McGridSet::profile`].
    pub fn rd_total(&self, albedo_prime: f64, eta: f64, g: f64) -> Result<f64> {
        self.check_eta(eta, g)?;
        total_of(&self.weights(g)?, albedo_prime, eta)
    }

    /// The α′ range a g is tabulated over (the intersection of the bracketing nodes').
    ///
    /// # Errors
    /// `AnisotropyNotTabulated` for a g the grid does not cover.
    pub fn albedo_prime_range(&self, g: f64) -> Result<(f64, f64)> {
        let mut range = (f64::NEG_INFINITY, f64::INFINITY);
        for (set, _) in self.weights(g)? {
            let a = set.tables()[0].albedos();
            range.0 = range.0.max(reduced_from_albedo(a[0], set.g()));
            range.1 = range.1.min(reduced_from_albedo(a[a.len() - 1], set.g()));
        }
        Ok(range)
    }

    /// The reduced albedo α′ whose total ([`McGridSet::rd_total`]) at η and g is `rd`. At a node,
    /// that set's inversion ([`McTableSet::albedo_from_rd_total`]) mapped to α′; between nodes,
    /// bisection in √(1 − α′) on the interpolated total (increasing in α′: each node's is, and the
    /// weights do not depend on α′) to 1e-14.
    ///
    /// # Errors
    /// `OutOfTable` (`rd_total`) for an Rd outside the totals at the ends of the α′ range, else as
    /// [`McGridSet::rd_total`].
    pub fn albedo_from_rd(&self, rd: f64, eta: f64, g: f64) -> Result<f64> {
        self.check_eta(eta, g)?;
        if let Place::Node(k) = self.place(g)? {
            let set = &self.nodes[k];
            let a = set.albedo_from_rd_total(rd, eta)?;
            return Ok(reduced_from_albedo(a, set.g()));
        }
        let (lo, hi) = self.albedo_prime_range(g)?;
        // The nodes and weights once, not per bisection step (η is checked above).
        let weights = self.weights(g)?;
        crate::model::invert_increasing_total(rd, lo, hi, |ap| total_of(&weights, ap, eta))
    }
}

/// The total at α′ and η of the nodes `weights` (linear in g between them; [`McGridSet::rd_total`]).
fn total_of(weights: &[(&McTableSet, f64)], albedo_prime: f64, eta: f64) -> Result<f64> {
    let mut sum = 0.0;
    for &(set, w) in weights {
        sum += w * set.rd_total(albedo_from_reduced(albedo_prime, set.g()), eta)?;
    }
    Ok(sum)
}

/// The grid's model for one parameter set: a node's [`McProfile`], or two interpolated in g.
// Made once per residual evaluation of a fit and dropped after it: the variants differ by a
// McProfile (about 200 bytes on the stack); boxing one would add a heap allocation per evaluation.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum McGridProfile {
    /// At a node of the grid.
    Node(McProfile),
    /// Between two nodes: Rd = Rd_lo^(1−t) Rd_hi^t, total (1 − t) Rd_lo + t Rd_hi.
    Between {
        /// The lower node's model.
        lo: McProfile,
        /// The upper node's model.
        hi: McProfile,
        /// Fraction of the way from the lower to the upper node's g.
        t: f64,
        /// The interpolated total.
        rd_total: f64,
    },
}

impl McGridProfile {
    /// Rd(r) with its derivatives in σ′s and σa (of the interpolant; module docs).
    #[inline]
    pub fn rd_with_derivatives(&self, r_mm: f64) -> ProfileSample {
        match self {
            Self::Node(m) => m.rd_with_derivatives(r_mm),
            Self::Between { lo, hi, t, .. } => {
                let (a, b) = (lo.rd_with_derivatives(r_mm), hi.rd_with_derivatives(r_mm));
                if !(a.rd > 0.0 && b.rd > 0.0) {
                    return ProfileSample::ZERO;
                }
                let rd = (a.rd.ln() * (1.0 - t) + b.rd.ln() * t).exp();
                let mix = |da: f64, db: f64| rd * ((1.0 - t) * da / a.rd + t * db / b.rd);
                ProfileSample {
                    rd,
                    d_sigma_s_prime: mix(a.d_sigma_s_prime, b.d_sigma_s_prime),
                    d_sigma_a: mix(a.d_sigma_a, b.d_sigma_a),
                }
            }
        }
    }
}

impl ProfileModel for McGridProfile {
    fn rd(&self, r_mm: f64) -> f64 {
        match self {
            Self::Node(m) => m.rd(r_mm),
            Self::Between { lo, hi, t, .. } => {
                (lo.rd(r_mm).ln() * (1.0 - t) + hi.rd(r_mm).ln() * t).exp()
            }
        }
    }

    fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]) {
        for (r, o) in radii_mm.iter().zip(out.iter_mut()) {
            *o = self.rd_with_derivatives(*r);
        }
    }

    fn rd_total(&self) -> f64 {
        match self {
            Self::Node(m) => m.rd_total(),
            Self::Between { rd_total, .. } => *rd_total,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `model`'s analytic ∂Rd/∂σ′s and ∂Rd/∂σa at (`sp`, `sa`) and radius `r` against central
    /// differences with relative steps `h` (σ′s, σa), within `rel` of the difference (+ 10⁻⁷ Rd);
    /// `what` prefixes the failure message.
    fn assert_derivatives(
        model: &dyn Fn(f64, f64) -> McGridProfile,
        sp: f64,
        sa: f64,
        r: f64,
        h: [f64; 2],
        rel: f64,
        what: &str,
    ) {
        let got = model(sp, sa).rd_with_derivatives(r);
        let (h_sp, h_sa) = (h[0] * sp, h[1] * sa);
        let fd_sp = (model(sp + h_sp, sa).rd(r) - model(sp - h_sp, sa).rd(r)) / (2.0 * h_sp);
        let fd_sa = (model(sp, sa + h_sa).rd(r) - model(sp, sa - h_sa).rd(r)) / (2.0 * h_sa);
        let tol = |fd: f64| rel * fd.abs() + 1e-7 * got.rd;
        assert!(
            (got.d_sigma_s_prime - fd_sp).abs() <= tol(fd_sp),
            "{what}∂/∂σ′s r = {r}: {} vs {fd_sp}",
            got.d_sigma_s_prime
        );
        assert!(
            (got.d_sigma_a - fd_sa).abs() <= tol(fd_sa),
            "{what}∂/∂σa r = {r}: {} vs {fd_sa}",
            got.d_sigma_a
        );
    }

    /// Between g nodes the derivatives are those of the interpolant: they agree with central
    /// differences of the model itself (g = 0.85, between the shipped 0.8 and 0.9 sets, at η between
    /// tables); at a node the model is that node's `McProfile`, unchanged.
    #[test]
    fn derivatives_between_g_nodes_match_finite_differences() {
        let grid = McGridSet::bundled().unwrap();
        for (sp, sa, eta, g) in [(1.0, 0.05, 1.45, 0.85), (2.0, 0.4, 1.33, 0.82)] {
            let model = |sp: f64, sa: f64| {
                let p = OpticalProperties::new(sp, sa, eta)
                    .unwrap()
                    .with_g(g)
                    .unwrap();
                grid.profile(&p).unwrap()
            };
            let m = model(sp, sa);
            assert!(matches!(m, McGridProfile::Between { .. }));
            for r in [0.02, 0.3, 1.0, 4.0, 12.0] {
                assert_derivatives(&model, sp, sa, r, [1e-6, 1e-6], 1e-5, "");
                let got = m.rd_with_derivatives(r);
                assert!((got.rd / m.rd(r) - 1.0).abs() < 1e-14);
            }
        }
        let p = OpticalProperties::new(1.0, 0.05, 1.45)
            .unwrap()
            .with_g(0.8)
            .unwrap();
        let k = grid.g_nodes().iter().position(|&g| g == 0.8).unwrap();
        let node = McProfile::new(&grid.nodes()[k], &p)
            .unwrap()
            .with_far_field(McProfile::far_field_donor(&grid.nodes()[0], &p).unwrap());
        assert_eq!(grid.profile(&p).unwrap(), McGridProfile::Node(node));
    }

    /// Beyond a g ≠ 0 node's radial range the profile is the g = 0 node's shape
    /// ([`McProfile::with_far_field`]): continuous at the join (the two sides within 10⁻⁹), its
    /// derivatives those of the continued model (central differences, also across the join's
    /// dependence on σt), and equal there to a constant times the g = 0 model. At g = 0.95 and
    /// σ′s = 3 mm⁻¹ the node's tables end at 8.3 mm (500/σt), the join at 6.7 mm (0.8 of that);
    /// at g = 0.8 they end at 33 mm and the join is at 25 reduced mean free paths, 8.3 mm, moving
    /// with σ′t instead of σt (the derivatives check both). Also above the
    /// g = 0 tables' last albedo (α′ 0.9999), where the donor holds its shape and decays at the true
    /// albedo: continuous in α′ across that node.
    #[test]
    fn the_far_field_beyond_a_g_node_follows_the_isotropic_shape() {
        let grid = McGridSet::bundled().unwrap();
        let (sp, eta) = (3.0, 1.4);
        let model = |sp: f64, sa: f64, g: f64| {
            let p = OpticalProperties::new(sp, sa, eta)
                .unwrap()
                .with_g(g)
                .unwrap();
            grid.profile(&p).unwrap()
        };
        for (g, albedo) in [(0.95, 0.9998), (0.95, 0.99993), (0.8, 0.9998)] {
            let sa = sp * (1.0 / albedo - 1.0);
            let m = model(sp, sa, g);
            // The nearer of the two joins, written out (`McProfile::far_field_join`).
            let join = f64::min(
                crate::model::FAR_FIELD_JOIN * 500.0 / (sa + sp / (1.0 - g)),
                crate::model::FAR_FIELD_JOIN_REDUCED / (sp + sa),
            );
            let (below, above) = (m.rd(join * (1.0 - 1e-12)), m.rd(join * (1.0 + 1e-12)));
            assert!((above / below - 1.0).abs() < 1e-9, "{below} vs {above}");
            if albedo < 0.9999 {
                let iso = model(sp, sa, 0.0);
                let c = m.rd(10.0) / iso.rd(10.0);
                for r in [9.0, 15.0, 25.0, 40.0] {
                    assert!((m.rd(r) / iso.rd(r) / c - 1.0).abs() < 1e-12, "r = {r}");
                }
            }
            for r in [3.0, 6.0, 8.0, 20.0] {
                // (σa is 10⁻⁴σ′s here: its step is relatively larger, the tolerance too.)
                let at_g = |sp: f64, sa: f64| model(sp, sa, g);
                let what = format!("α′ {albedo} ");
                assert_derivatives(&at_g, sp, sa, r, [1e-6, 1e-4], 1e-4, &what);
            }
        }
        // Across the g = 0 tables' last albedo node (α′ 0.9999) the continued profile is continuous.
        let at = |albedo: f64| model(sp, sp * (1.0 / albedo - 1.0), 0.95).rd(20.0);
        let (lo, hi) = (at(0.9999 - 1e-10), at(0.9999 + 1e-10));
        assert!((hi / lo - 1.0).abs() < 1e-6, "{lo} vs {hi}");
    }

    /// A node whose tables stop short of η is refused by name: on a grid of the shipped g = 0 set
    /// and the g = 0.8 set cut at η 2.0, η 2.2 answers at g = 0, and at g 0.5 and 0.8 (both need
    /// the 0.8 node) the profile, the total and the α′ inversion each refuse with
    /// `EtaNotTabulatedAtG`, naming the node, its η range and what to do; `eta_range_at` says the
    /// same range, and η within the sets' edge tolerance of 2.0 still answers.
    #[test]
    fn a_node_that_stops_short_of_eta_is_named() {
        let grid = McGridSet::bundled().unwrap();
        let node = |g: f64| {
            let k = grid.g_nodes().iter().position(|&n| n == g).unwrap();
            grid.nodes()[k].clone()
        };
        let cut = McTableSet::new(
            node(0.8)
                .tables()
                .iter()
                .filter(|t| t.spec().eta <= 2.0 + 1e-9)
                .cloned()
                .collect(),
        )
        .unwrap();
        let grid = McGridSet::new(vec![node(0.0), cut], 0.8).unwrap();
        let props = |eta: f64, g: f64| {
            OpticalProperties::new(1.0, 0.01, eta)
                .unwrap()
                .with_g(g)
                .unwrap()
        };
        assert!(grid.profile(&props(2.2, 0.0)).is_ok());
        assert!(grid.rd_total(0.99, 2.2, 0.0).is_ok());
        assert_eq!(grid.eta_range_at(0.5).unwrap(), (1.0, 2.0));
        assert!(grid.profile(&props(2.0 + 0.004, 0.8)).is_ok());
        for g in [0.5, 0.8] {
            let errors = [
                grid.profile(&props(2.2, g)).err().unwrap(),
                grid.rd_total(0.99, 2.2, g).unwrap_err(),
                grid.albedo_from_rd(0.3, 2.2, g).unwrap_err(),
            ];
            for e in errors {
                assert!(
                    matches!(
                        e,
                        McError::Optics(scatterfit_optics::OpticsError::EtaNotTabulatedAtG { node, max, .. }) if node == 0.8 && max == 2.0
                    ),
                    "{e}"
                );
                let text = e.to_string();
                for want in ["η = 2.2000", "g = 0.8 cover η 1–2", "--model dipole"] {
                    assert!(text.contains(want), "{text} lacks {want}");
                }
            }
        }
    }

    /// The weights: a node within the tolerance is that node; between nodes at most `max_step`
    /// apart, the fraction of the way; elsewhere `AnisotropyNotTabulated` with the coverage.
    #[test]
    fn places_on_the_grid() {
        let grid = McGridSet::bundled().unwrap();
        assert_eq!(grid.g_nodes(), [0.0, 0.15, 0.3, 0.5, 0.7, 0.8, 0.9, 0.95]);
        assert_eq!(grid.place(0.8 + 1e-12).unwrap(), Place::Node(5));
        match grid.place(0.825).unwrap() {
            Place::Between(5, t) => assert!((t - 0.25).abs() < 1e-12),
            p => panic!("{p:?}"),
        }
        match grid.place(0.4).unwrap() {
            Place::Between(2, t) => assert!((t - 0.5).abs() < 1e-12),
            p => panic!("{p:?}"),
        }
        for g in [-0.1, 0.96, f64::NAN] {
            assert!(matches!(
                grid.place(g),
                Err(McError::Optics(
                    scatterfit_optics::OpticsError::AnisotropyNotTabulated { .. }
                ))
            ));
        }
        assert_eq!(grid.covered(), [(0.0, 0.95)]);
        assert!(grid.covers(0.0) && grid.covers(0.5) && grid.covers(0.93) && !grid.covers(0.97));
        assert_eq!(
            grid.coverage(),
            "g 0–0.95 (tables at 0, 0.15, 0.3, 0.5, 0.7, 0.8, 0.9, 0.95, linear in g between; η 1–2.5)"
        );
        // A grid with a gap names each run.
        let gapped = grid.with_nodes(|g| g == 0.0 || g >= 0.8).unwrap();
        assert_eq!(gapped.covered(), [(0.0, 0.0), (0.8, 0.95)]);
        assert!(!gapped.covers(0.5));
        assert_eq!(
            gapped.coverage(),
            "g = 0 (η 1–2.5); g 0.8–0.95 (tables at 0.8, 0.9, 0.95, linear in g between; η 1–2.5)"
        );
    }
}
