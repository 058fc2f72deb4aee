//! [`McProfile`]: the `mc` model of one set of optical properties, Rd(r) = σt² R̂(σt r; a) from a
//! [`McTableSet`], with its far-field continuation and analytic derivatives
//! ([`scatterfit_optics::ProfileModel`]).

use scatterfit_optics::{OpticalProperties, ProfileModel, ProfileSample};

use super::set::McTableSet;
use crate::error::Result;
use crate::smooth::{Knots, kappa0};

/// The `mc` forward model for one set of optical properties: the table set's interpolant at (a, η)
/// collapsed into one spline in u = ln ρ with its a-derivative, and the similarity scaling.
#[derive(Debug, Clone, PartialEq)]
pub struct McProfile {
    props: OpticalProperties,
    knots: Knots,
    /// S's coefficients at (a, η), and their derivatives in a.
    coefs: Vec<f64>,
    dcoefs: Vec<f64>,
    /// σt, a, κ₀(a), dκ₀/da.
    sigma_t: f64,
    kappa: f64,
    dkappa: f64,
    /// ∂σt/∂σ′s, ∂a/∂σ′s, ∂a/∂σa (∂σt/∂σa = 1).
    dst_dsp: f64,
    da_dsp: f64,
    da_dsa: f64,
    /// Smallest optical radius of the spline (below it Rd is held constant).
    rho_floor: f64,
    /// Outer radius of the Monte Carlo data at this albedo [mm].
    r_data_max: f64,
    /// The tables' outer radial edge [mean free paths 1/σt of the set's g].
    rho_max: f64,
    rd_total: f64,
    /// Beyond a g ≠ 0 set's radial range, the g = 0 model's shape ([`McProfile::with_far_field`]).
    far: Option<Box<FarField>>,
}

/// Where a g ≠ 0 set's profile hands over to the g = 0 model's shape, as a fraction of the set's
/// outer radial edge (`McTableSpec::rho_max`, in its own mean free paths 1/σt): inside the data,
/// clear of the last bins the smoother's end condition shapes.
pub const FAR_FIELD_JOIN: f64 = 0.8;

/// Where a g ≠ 0 set's profile hands over to the g = 0 model's shape at the latest, in reduced mean
/// free paths 1/σ′t: the g ≠ 0 tables' own far field is reliable only to about there at α′ → 1
/// (their photons need 1/(1 − g) times the interactions of g = 0 to get as far, and the smoother
/// bends the noisy rows). Measured at g 0.8, η 1.0, α′ 0.9999 against a direct engine run
/// (`g_point_check`, 2·10⁷ photons): the set's own profile is within 0.1 % to 20 reduced mean free
/// paths, then +0.7 … −1.9 % to 50 and −2 … −4 % beyond; continued from 25 it is within 0.7 % to
/// 100 (from 20: +0.9 … +1.5 %, the g = 0 shape not yet the g = 0.8 one there; from 30: within
/// 1.0 %); against MCML (`data/reference/mcml_far_field_g.csv`) within 0.4 % from 10 to 97.5, where
/// the node's own profile was 2.6 % low at 40–60. CHANGELOG.md, "The far field's join at 25
/// reduced mean free paths".
pub const FAR_FIELD_JOIN_REDUCED: f64 = 25.0;

/// The continuation of a [`McProfile`] beyond its set's radial range (see
/// [`McProfile::with_far_field`]): Rd(r) = c·Rd₀(r) for r > r_join, with c = Rd(r_join)/Rd₀(r_join).
#[derive(Debug, Clone, PartialEq)]
struct FarField {
    /// The g = 0 model at the same σ′s, σa and η.
    donor: McProfile,
    /// The join radius [mm].
    r_join: f64,
    /// ln c and its derivatives in σ′s and σa (the join radius moves with σt: included).
    ln_c: f64,
    d_ln_c: [f64; 2],
}

impl McProfile {
    /// The model for `props` (its η, and the set's g) from `set`.
    ///
    /// # Errors
    /// `OutOfTable` when η or the albedo a = σs/σt is outside the tables.
    pub fn new(set: &McTableSet, props: &OpticalProperties) -> Result<Self> {
        Self::build(set, props, false)
    }

    /// [`McProfile::new`], or with `beyond_top` for an albedo above the set's last node: the
    /// smoothed shape S (module docs) held at that node and the exact decay e^{−κ₀(a)ρ} at the true
    /// albedo — the far-field donor of [`McProfile::with_far_field`], where the g = 0 set (nodes
    /// to α′ 0.9999) must answer for g ≠ 0 sets that reach α′ 0.99995. Continuous at the node;
    /// above it the shape's own change with a (which the decay dominates there) is left out.
    fn build(set: &McTableSet, props: &OpticalProperties, beyond_top: bool) -> Result<Self> {
        let g = set.g();
        let sigma_s = props.sigma_s_prime() / (1.0 - g);
        let sigma_t = props.sigma_a() + sigma_s;
        let a = sigma_s / sigma_t;
        let eta = props.eta();
        let (j, we) = set.eta_weights(eta)?;
        let t0 = &set.tables[0];
        let top = t0.albedos[t0.albedos.len() - 1];
        let (i, wa, dwa) = if beyond_top && a > top {
            let (i, wa, _) = t0.albedo_weights(top)?;
            (i, wa, [0.0; 4])
        } else {
            t0.albedo_weights(a)?
        };
        let m = t0.knots.len();
        let (mut coefs, mut dcoefs) = (vec![0.0; m], vec![0.0; m]);
        let mut rho_data = 0.0;
        for (q, &w_eta) in we.iter().enumerate() {
            if w_eta == 0.0 {
                continue;
            }
            let t = &set.tables[j + q - 1];
            for k in 0..4 {
                if wa[k] == 0.0 && dwa[k] == 0.0 {
                    continue;
                }
                let row = t.row(i + k - 1);
                // The row's S less ln a of its node (module docs, "Interpolation"): a constant on every
                // coefficient, since the B-splines sum to 1.
                let ln_node = t0.albedos[i + k - 1].ln();
                let (w, dw) = (w_eta * wa[k], w_eta * dwa[k]);
                for ((c, d), &b) in coefs.iter_mut().zip(dcoefs.iter_mut()).zip(row) {
                    *c += w * (b - ln_node);
                    *d += dw * (b - ln_node);
                }
                rho_data += w * t.rho_data_max[i + k - 1];
            }
        }
        // ln a back (the η and albedo weights sum to 1, their a-derivatives to 0); held at the
        // last node above it, as the shape is.
        let (ln_a, dln_a) = if beyond_top && a > top {
            (top.ln(), 0.0)
        } else {
            (a.ln(), 1.0 / a)
        };
        for (c, d) in coefs.iter_mut().zip(dcoefs.iter_mut()) {
            *c += ln_a;
            *d += dln_a;
        }
        let (kappa, dkappa) = kappa0(a, g);
        let st2 = sigma_t * sigma_t;
        Ok(Self {
            props: *props,
            knots: t0.knots,
            coefs,
            dcoefs,
            sigma_t,
            kappa,
            dkappa,
            dst_dsp: 1.0 / (1.0 - g),
            da_dsp: props.sigma_a() / ((1.0 - g) * st2),
            da_dsa: -sigma_s / st2,
            rho_floor: t0.spec.rho_min,
            r_data_max: rho_data / sigma_t,
            rho_max: t0.spec.rho_max,
            rd_total: set.rd_total(a.min(top), eta)?,
            far: None,
        })
    }

    /// The far-field donor for [`McProfile::with_far_field`]: the g = 0 set's model at `props`,
    /// answering above the set's last albedo node too (its shape held there, the decay exact).
    ///
    /// # Errors
    /// As [`McProfile::new`] below the set's albedo range or outside its η range.
    pub fn far_field_donor(set: &McTableSet, props: &OpticalProperties) -> Result<Self> {
        Self::build(set, props, true)
    }

    /// The same model continued beyond its set's radial range by `donor`'s shape — the g = 0 set's
    /// model at the same σ′s, σa and η: Rd(r) = c·Rd₀(r) for r beyond r_join — the nearer of
    /// [`FAR_FIELD_JOIN`]·ρ_max/σt and [`FAR_FIELD_JOIN_REDUCED`]/σ′t
    /// ([`McProfile::far_field_join`]) — c making Rd continuous there.
    ///
    /// Why: every table spans ρ = σt·r up to ρ_max = 500 of its *own* mean free paths, which at
    /// g = 0.9 and 0.95 is only 50 and 25 reduced ones (σ′t r) — 8 mm at σ′s = 3 mm⁻¹ for g 0.95,
    /// inside the paper rig's 25 mm field, where at α′ → 1 the light still travels tens of
    /// millimetres. Beyond, the smoother's extrapolation (a power law times e^{−κ₀ρ}) was 10–50 %
    /// off (CHANGELOG.md, "The far field beyond the g tables' radius"). The far field follows
    /// similarity (in reduced units it is the same at every g: Wyman, Patterson & Wilson 1989;
    /// d'Eon 2012 §4 for the diffusion asymptote), and the g = 0 set's tables reach 500 reduced mean
    /// free paths, so its shape carries the profile on; the join's factor c keeps the g ≠ 0 set's
    /// own amplitude (which the near field sets). And where a g ≠ 0 set's data do reach, they are
    /// reliable only to about 25 reduced mean free paths at α′ → 1 ([`FAR_FIELD_JOIN_REDUCED`]): a
    /// fit that weights the far field read σ′s 2–2.5 % low at g 0.8, α′ 0.9999 from the set's own
    /// far field (CHANGELOG.md, "The far field's join at 25 reduced mean free paths"). The total
    /// is the set's own (tallied, not the profile's integral). Unchanged where the donor does not
    /// answer.
    #[must_use]
    pub fn with_far_field(mut self, donor: McProfile) -> Self {
        let (r_join, dr_join) = self.far_field_join();
        if !(r_join.is_finite() && r_join > 0.0) || donor.sigma_t <= 0.0 {
            return self;
        }
        let (own, d) = (
            self.rd_with_derivatives(r_join),
            donor.rd_with_derivatives(r_join),
        );
        if !(own.rd > 0.0 && d.rd > 0.0) {
            return self;
        }
        // ∂ln Rd/∂r at the join, of each (σt ∂ln R̂/∂ρ − nothing else: Rd = σt² R̂(σt r)).
        let slope = |m: &McProfile| m.sigma_t * m.ln_rhat(m.sigma_t * r_join).1;
        let dr = slope(&self) - slope(&donor);
        let d_ln_c = [
            own.d_sigma_s_prime / own.rd - d.d_sigma_s_prime / d.rd + dr * dr_join[0],
            own.d_sigma_a / own.rd - d.d_sigma_a / d.rd + dr * dr_join[1],
        ];
        self.far = Some(Box::new(FarField {
            ln_c: own.rd.ln() - d.rd.ln(),
            d_ln_c,
            r_join,
            donor,
        }));
        self
    }

    /// Where [`McProfile::with_far_field`] joins \[mm\] — the nearer of the reduced radius
    /// [`FAR_FIELD_JOIN_REDUCED`]/σ′t and [`FAR_FIELD_JOIN`]·ρ_max/σt (the set's own range) — with
    /// its derivatives in σ′s and σa (the join moves with the coefficients).
    pub fn far_field_join(&self) -> (f64, [f64; 2]) {
        let own_range = FAR_FIELD_JOIN * self.rho_max / self.sigma_t;
        let sigma_t_reduced = self.props.sigma_s_prime() + self.props.sigma_a();
        let reduced = FAR_FIELD_JOIN_REDUCED / sigma_t_reduced;
        if reduced < own_range {
            // r = J′/σ′t with σ′t = σ′s + σa.
            (reduced, [-reduced / sigma_t_reduced; 2])
        } else {
            // r = J ρ_max/σt with ∂σt/∂σ′s = 1/(1 − g), ∂σt/∂σa = 1.
            let per_sigma_t = -own_range / self.sigma_t;
            (own_range, [per_sigma_t * self.dst_dsp, per_sigma_t])
        }
    }

    /// The optical properties of this model.
    pub fn properties(&self) -> &OpticalProperties {
        &self.props
    }

    /// Outer radius of the Monte Carlo data behind the model at this albedo \[mm\] (interpolated like
    /// the model): beyond it Rd(r) is the smoother's extrapolation.
    pub fn r_data_max_mm(&self) -> f64 {
        self.r_data_max
    }

    /// ln R̂, ∂ln R̂/∂ρ, ∂ln R̂/∂a at optical radius ρ.
    #[inline]
    fn ln_rhat(&self, rho: f64) -> (f64, f64, f64) {
        let (rho, floor) = if rho < self.rho_floor {
            (self.rho_floor, true)
        } else {
            (rho, false)
        };
        let b = self.knots.basis(rho.ln());
        let c = &self.coefs[b.first..b.first + 4];
        let dc = &self.dcoefs[b.first..b.first + 4];
        let mut s = 0.0;
        let mut s_u = 0.0;
        let mut s_a = 0.0;
        for p in 0..4 {
            s += b.w[p] * c[p];
            s_u += b.dw[p] * c[p];
            s_a += b.w[p] * dc[p];
        }
        let d_rho = if floor { 0.0 } else { s_u / rho - self.kappa };
        (s - self.kappa * rho, d_rho, s_a - self.dkappa * rho)
    }

    /// Rd(r) with its derivatives in σ′s and σa.
    #[inline]
    pub fn rd_with_derivatives(&self, r_mm: f64) -> ProfileSample {
        if let Some(f) = self.far.as_deref().filter(|f| r_mm > f.r_join) {
            let d = f.donor.rd_with_derivatives(r_mm);
            let c = f.ln_c.exp();
            let rd = c * d.rd;
            return ProfileSample {
                rd,
                d_sigma_s_prime: c * d.d_sigma_s_prime + rd * f.d_ln_c[0],
                d_sigma_a: c * d.d_sigma_a + rd * f.d_ln_c[1],
            };
        }
        let st = self.sigma_t;
        let (l, l_rho, l_a) = self.ln_rhat(st * r_mm);
        let rd = st * st * l.exp();
        // ∂Rd/∂σt at fixed a = Rd (2/σt + r ∂ln R̂/∂ρ); ∂Rd/∂a at fixed σt = Rd ∂ln R̂/∂a.
        let d_st = rd * (2.0 / st + r_mm * l_rho);
        let d_a = rd * l_a;
        ProfileSample {
            rd,
            d_sigma_s_prime: d_st * self.dst_dsp + d_a * self.da_dsp,
            d_sigma_a: d_st + d_a * self.da_dsa,
        }
    }
}

impl ProfileModel for McProfile {
    fn rd(&self, r_mm: f64) -> f64 {
        if let Some(f) = self.far.as_deref().filter(|f| r_mm > f.r_join) {
            return f.ln_c.exp() * f.donor.rd(r_mm);
        }
        let st = self.sigma_t;
        st * st * self.ln_rhat(st * r_mm).0.exp()
    }

    fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]) {
        for (r, o) in radii_mm.iter().zip(out.iter_mut()) {
            *o = self.rd_with_derivatives(*r);
        }
    }

    /// The Monte Carlo total at this albedo and η (interpolated like the profile; not the integral
    /// of the smoothed profile, which misses the part beyond the table's last radius).
    fn rd_total(&self) -> f64 {
        self.rd_total
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::McError;
    use crate::model::table::McTable;
    use crate::model::testing::{small_set, small_spec_g};

    /// The model's analytic derivatives (of the interpolant: albedo weights, κ₀(a), the spline in
    /// ln ρ, similarity) agree with central differences of the model itself, between albedo nodes,
    /// between η tables, and for g ≠ 0 the chain through σs = σ′s/(1 − g).
    #[test]
    fn derivatives_match_finite_differences() {
        let set = small_set(&[1.0, 1.2, 1.5]);
        let set_g = McTableSet::new(
            [1.2, 1.5]
                .iter()
                .map(|&e| McTable::build(&small_spec_g(e, 0.5), &|_, _| {}).unwrap())
                .collect(),
        )
        .unwrap();
        for (sp, sa, eta, set) in [
            (1.0, 0.05, 1.0, &set),
            (2.0, 0.4, 1.33, &set),
            (0.7, 0.02, 1.5, &set),
            (1.3, 0.3, 1.2, &set),
            (1.0, 0.1, 1.4, &set_g),
        ] {
            let model = |sp: f64, sa: f64| {
                McProfile::new(set, &OpticalProperties::new(sp, sa, eta).unwrap()).unwrap()
            };
            let m = model(sp, sa);
            for r in [0.02, 0.3, 1.0, 4.0, 12.0] {
                let got = m.rd_with_derivatives(r);
                let (h_sp, h_sa) = (1e-6 * sp, 1e-6 * sa);
                let fd_sp =
                    (model(sp + h_sp, sa).rd(r) - model(sp - h_sp, sa).rd(r)) / (2.0 * h_sp);
                let fd_sa =
                    (model(sp, sa + h_sa).rd(r) - model(sp, sa - h_sa).rd(r)) / (2.0 * h_sa);
                let tol = |fd: f64| 1e-5 * fd.abs() + 1e-7 * got.rd;
                assert!(
                    (got.d_sigma_s_prime - fd_sp).abs() <= tol(fd_sp),
                    "∂/∂σ′s r = {r} ({sp}, {sa}, {eta}): {} vs {fd_sp}",
                    got.d_sigma_s_prime
                );
                assert!(
                    (got.d_sigma_a - fd_sa).abs() <= tol(fd_sa),
                    "∂/∂σa r = {r} ({sp}, {sa}, {eta}): {} vs {fd_sa}",
                    got.d_sigma_a
                );
                assert_eq!(got.rd, m.rd(r));
            }
        }
    }

    /// Similarity: doubling σ′s and σa halves every length, so Rd(r/2) = 4 Rd(r); at a node η the
    /// set returns that table's own values; between η tables, totals lie between their neighbours;
    /// out-of-range albedo and η are errors naming the coordinate.
    #[test]
    fn similarity_nodes_and_ranges() {
        let set = small_set(&[1.0, 1.4]);
        let p1 = OpticalProperties::new(1.0, 0.1, 1.4).unwrap();
        let p2 = OpticalProperties::new(2.0, 0.2, 1.4).unwrap();
        let (m1, m2) = (
            McProfile::new(&set, &p1).unwrap(),
            McProfile::new(&set, &p2).unwrap(),
        );
        for r in [0.1, 1.0, 5.0] {
            assert!((m2.rd(r / 2.0) / (4.0 * m1.rd(r)) - 1.0).abs() < 1e-12);
        }
        let only = McTableSet::new(vec![set.tables()[1].clone()]).unwrap();
        assert_eq!(McProfile::new(&only, &p1).unwrap().rd(1.0), m1.rd(1.0));
        let a = 0.9;
        let (lo, hi) = (set.rd_total(a, 1.0).unwrap(), set.rd_total(a, 1.4).unwrap());
        let mid = set.rd_total(a, 1.2).unwrap();
        assert!(mid < lo && mid > hi, "{lo} {mid} {hi}");
        let e = McProfile::new(&set, &OpticalProperties::new(1.0, 10.0, 1.2).unwrap());
        assert!(matches!(
            e,
            Err(McError::Optics(
                scatterfit_optics::OpticsError::OutOfTable {
                    name: "albedo (σs/σt)",
                    ..
                }
            ))
        ));
        let e = McProfile::new(&set, &OpticalProperties::new(1.0, 0.1, 1.6).unwrap());
        assert!(matches!(
            e,
            Err(McError::Optics(
                scatterfit_optics::OpticsError::OutOfTable { name: "eta", .. }
            ))
        ));
        assert!(McProfile::new(&only, &OpticalProperties::new(1.0, 0.1, 1.41).unwrap()).is_err());
    }

    /// g ≠ 0: the white table is in the single-scattering albedo a at σt = 1, and McProfile maps
    /// (σ′s, σa, g) onto it; its total agrees with the MCML engine run on the same layer
    /// (`Layer::from_reduced`, σs = σ′s/(1 − g)) within 4 combined standard errors + 0.003 (the small
    /// table's interpolation).
    #[test]
    fn anisotropic_total_matches_engine() {
        let (g, eta, sp, sa) = (0.5, 1.3, 1.0, 0.05);
        let t = McTable::build(&small_spec_g(eta, g), &|_, _| {}).unwrap();
        let set = McTableSet::new(vec![t]).unwrap();
        let m = McProfile::new(&set, &OpticalProperties::new(sp, sa, eta).unwrap()).unwrap();
        let half = crate::Sample::slab(
            crate::Layer::from_reduced(sp, sa, g, eta, f64::INFINITY).unwrap(),
            1.0,
        )
        .unwrap();
        let grid = crate::RadialGrid::uniform(1.0, 10).unwrap();
        let d = crate::Simulation::new(half, crate::Beam::pencil(), grid, 40_000, 9)
            .unwrap()
            .run();
        let a = (sp / (1.0 - g)) / (sa + sp / (1.0 - g));
        let (_, se) = set.tables()[0].totals();
        let k = set.tables()[0].albedos().partition_point(|&x| x < a);
        let tol = 4.0 * (d.rd_total.stderr.powi(2) + se[k].powi(2)).sqrt() + 0.003;
        assert!(
            (m.rd_total() - d.rd_total.value).abs() <= tol,
            "{} vs engine {:?}",
            m.rd_total(),
            d.rd_total
        );
    }
}
