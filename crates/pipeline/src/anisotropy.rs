//! The anisotropy g when it is not known exactly: a stated range of g propagated into
//! σ′s, σa and α′ as a separate uncertainty term ([`scatterfit_optics::Estimate::g`]) beside the
//! fit's and the spectrophotometer's.
//!
//! **Why a term.** The total diffuse reflectance at fixed reduced coefficients depends on g, so
//! α′ from the spectrophotometer does, and so does the profile's near field (the similarity
//! relation σ′s = σs(1 − g) holds only in the far field; Wyman, Patterson & Wilson 1989). A σa
//! computed at g = 0 for a material with g ≈ 0.85 is 5–25 % high (BENCHMARKS.md, "What assuming
//! g = 0 costs") — far outside a fit ± spectro error bar of a few tenths of a percent.
//!
//! **How.** The estimate is recomputed with the g-aware exact model — the `mc` tables over (η, g)
//! for the profile and for the α′ inversion (`scatterfit_mc::family(ModelName::Mc)` and
//! `albedo_family(AlbedoModel::Mc, …)` at each g through [`AtG`]) — at every g of the range the
//! tables answer: the tables' g nodes inside the range and the range's ends
//! ([`GPlan::points`]). Proposed method: α′(g′) from the reading's Rd, then σ′s fitted with it;
//! existing method: σ′s and σa both fitted at g′. The term is
//! - the largest |E(g′) − E(g₀)| over the points, where g₀ is the g the values are computed at
//!   (the given `[fit] g`, or 0 when neither g nor a range is stated); or
//! - for a range without a g: half the spread (max − min)/2, the values then being the middle
//!   (max + min)/2 of the estimates (when the value's model is `mc` with the `mc` α′; a g-blind
//!   diffusion dipole keeps its value, and its term is the largest deviation from the `mc`
//!   estimate at the g its fit used).
//!
//! This is a bound, not a standard deviation: a g anywhere in the range gives an estimate within
//! it (where the estimates change monotonically with g, as they do on the twins, BENCHMARKS.md
//! "The g term: coverage when g is not known"), so the total adds it linearly to the quadrature sum of the fit's and
//! the spectrophotometer's standard errors ([`scatterfit_optics::Estimate::total`]). The
//! diffusion dipoles do not depend on g; their g term is the sensitivity of the g-aware estimate,
//! which is what their user needs to know. Parts of the range the tables do not cover are not
//! evaluated (never extrapolated) and are named in the result ([`GPlan::not_covered`]).

use scatterfit_fit::{ChannelInput, FitOptions, FitReport, ProfileData, Start};
use scatterfit_io::manifest::GSetting;
use scatterfit_io::result_json::{GSource, GUncertainty};
use scatterfit_mc::McGridSet;
use scatterfit_optics::{AlbedoModel, AtG, Method, ModelName, Rgb};

use crate::error::{PipelineError, Result};
use crate::fit::{ChannelOutcome, FitSettings};
use crate::spectro::SpectroStage;

/// The range of g propagated when neither `[fit] g` nor `[fit] g_range` is stated: 0 (the
/// isotropic scattering the paper assumes) to 0.95 (the most forward-scattering of real
/// translucent materials — skin, marble, milk, wax, plastics are 0.7–0.95). An unstated g is an
/// unknown g; the values stay at g = 0 (what the paper's method and isotropic models assume), and
/// the term shows how far they could be off.
pub const DEFAULT_G_RANGE: [f64; 2] = [0.0, scatterfit_io::manifest::G_RANGE_MAX];

/// Two g closer than this are one point (a g typed as 0.8 is the node 0.8).
const SAME_G: f64 = 1e-9;

/// What is known about the material's g: the manifest's `[fit] g` and `[fit] g_range` (or the
/// commands' `--g`, `--g-range`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GPrior {
    /// A known or assumed g: the values are computed at it.
    pub g: Option<f64>,
    /// The range g lies in, `[lo, hi]` with 0 ≤ lo ≤ hi ≤ 0.95; with [`GPrior::fit`] the range
    /// searched.
    pub range: Option<[f64; 2]>,
    /// `g = "fit"`: g fitted per channel from the profile ([`crate::anisotropy_fit`]); where the
    /// data do not determine it, the range's term (the values the middle of the estimates).
    pub fit: bool,
}

impl GPrior {
    /// What a `[fit] g` (a number or `"fit"`) and a `[fit] g_range` say — the manifest's keys,
    /// or the commands' `--g` and `--g-range`, which take the same [`GSetting`].
    pub fn from_setting(g: Option<GSetting>, range: Option<[f64; 2]>) -> Self {
        Self {
            g: g.and_then(GSetting::value),
            range,
            fit: g.is_some_and(GSetting::is_fit),
        }
    }

    /// Where the knowledge came from: g alone is [`GSource::Given`], a range (with or without a g)
    /// [`GSource::Range`], neither [`GSource::DefaultRange`].
    pub fn source(&self) -> GSource {
        if self.fit {
            return GSource::Fit;
        }
        match (self.g, self.range) {
            (Some(_), None) => GSource::Given,
            (_, Some(_)) => GSource::Range,
            (None, None) => GSource::DefaultRange,
        }
    }

    /// The range propagated into the g term: the stated one, [`DEFAULT_G_RANGE`] when nothing is
    /// stated, `None` when g is given (known: no term).
    pub fn propagated_range(&self) -> Option<[f64; 2]> {
        match self.source() {
            GSource::Fit => self.range.or_else(|| {
                scatterfit_mc::bundled_grid()
                    .ok()
                    .and_then(default_search_range)
            }),
            GSource::Given => None,
            GSource::Range => self.range,
            GSource::DefaultRange => Some(DEFAULT_G_RANGE),
        }
    }

    /// True when the values are the middle of the estimates over the range (a range, no g).
    pub fn is_centred(&self) -> bool {
        self.g.is_none() && (self.range.is_some() || self.fit)
    }

    /// Checks the prior as the manifest does (for values from the command line or a program).
    ///
    /// # Errors
    /// [`PipelineError::Input`] naming the option: a range not in 0 ≤ lo ≤ hi ≤ 0.95, a g outside
    /// (−1, 1) or outside the range.
    pub fn check(&self) -> Result<()> {
        if self.fit && self.g.is_some() {
            return Err(PipelineError::Input(
                "g: give a number or \"fit\", not both".into(),
            ));
        }
        if let Some(g) = self.g
            && !(g.is_finite() && g > -1.0 && g < 1.0)
        {
            return Err(PipelineError::Input(format!(
                "g = {g}: the Henyey–Greenstein g must lie in (−1, 1)"
            )));
        }
        if let Some([lo, hi]) = self.range {
            let max = scatterfit_io::manifest::G_RANGE_MAX;
            if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo <= hi && hi <= max) {
                return Err(PipelineError::Input(format!(
                    "g range [{lo}, {hi}]: must be lo,hi with 0 ≤ lo ≤ hi ≤ {max}"
                )));
            }
            if let Some(g) = self.g
                && !(lo..=hi).contains(&g)
            {
                return Err(PipelineError::Input(format!(
                    "g = {g} lies outside the g range [{lo}, {hi}]: give a g inside it, or drop one"
                )));
            }
        }
        Ok(())
    }
}

/// Where the g term is evaluated, for one setting.
#[derive(Debug, Clone, PartialEq)]
pub struct GPlan {
    /// The range propagated.
    pub range: [f64; 2],
    /// The g at which the `mc` estimates are computed, increasing: the tables' nodes inside the
    /// range, the range's ends and the values' g, each where the tables cover it.
    pub points: Vec<f64>,
    /// The parts of the range the tables do not cover, in words (e.g. "0–0.8 (exclusive),
    /// 0.9–0.95 (exclusive of 0.9)"); `None` when all of it is covered.
    pub not_covered: Option<String>,
    /// The g the values are computed at; `None` when they are the middle of the estimates.
    pub reference: Option<f64>,
}

impl GPlan {
    /// The plan for `prior` on the bundled `mc` grid, the values computed at `g` (the settings'
    /// g); `None` when g is known.
    ///
    /// # Errors
    /// [`PipelineError::Input`] when the tables cover no g of the range.
    pub fn new(prior: &GPrior, g: f64) -> Result<Option<GPlan>> {
        let Some(range) = prior.propagated_range() else {
            return Ok(None);
        };
        let grid = scatterfit_mc::bundled_grid()?;
        Self::on_grid(grid, range, (!prior.is_centred()).then_some(g)).map(Some)
    }

    /// The plan for `range` on `grid`, the values at `reference` (`None`: the middle).
    ///
    /// # Errors
    /// As [`GPlan::new`].
    pub fn on_grid(grid: &McGridSet, range: [f64; 2], reference: Option<f64>) -> Result<GPlan> {
        let [lo, hi] = range;
        let mut points: Vec<f64> = grid
            .g_nodes()
            .into_iter()
            .filter(|&g| g >= lo - SAME_G && g <= hi + SAME_G)
            .chain([lo, hi])
            .chain(reference)
            .filter(|&g| grid.covers(g))
            .collect();
        points.sort_by(f64::total_cmp);
        points.dedup_by(|a, b| (*a - *b).abs() <= SAME_G);
        if points.is_empty() {
            return Err(PipelineError::Input(format!(
                "the g range {lo}–{hi}: the `mc` tables cover no g in it ({}); give a range that \
                 reaches one of them",
                grid.coverage()
            )));
        }
        Ok(GPlan {
            range,
            points,
            not_covered: not_covered(&grid.covered(), lo, hi),
            reference,
        })
    }

    /// The g the values' fit uses for a range without a g: the covered g nearest the range's
    /// middle (the middle itself where the tables answer there).
    pub fn nominal_g(grid: &McGridSet, range: [f64; 2]) -> Option<f64> {
        let mid = 0.5 * (range[0] + range[1]);
        if grid.covers(mid) {
            return Some(mid);
        }
        let plan = Self::on_grid(grid, range, None).ok()?;
        // Nearest point; on a tie the smaller g (closer to the isotropic default).
        plan.points
            .iter()
            .copied()
            .min_by(|a, b| (a - mid).abs().total_cmp(&(b - mid).abs()))
    }

    /// The result file's record of this plan.
    pub fn record(&self, prior: &GPrior) -> GUncertainty {
        GUncertainty {
            source: prior.source(),
            g: self.reference,
            range: Some(self.range),
            evaluated: self.points.clone(),
            not_covered: self.not_covered.clone(),
            fitted: None,
        }
    }
}

/// The record for a known g (no plan).
pub fn known_g_record(g: f64) -> GUncertainty {
    GUncertainty {
        source: GSource::Given,
        g: Some(g),
        range: None,
        evaluated: Vec::new(),
        not_covered: None,
        fitted: None,
    }
}

/// The parts of \[lo, hi\] outside the covered intervals, in words.
fn not_covered(covered: &[(f64, f64)], lo: f64, hi: f64) -> Option<String> {
    // Walk from lo: each covered interval that overlaps [lo, hi] leaves a gap before it.
    let mut gaps = Vec::new();
    let mut at = lo;
    let mut at_closed = false; // whether `at` itself is covered
    for &(a, b) in covered {
        if b < lo - SAME_G {
            continue;
        }
        if a > hi + SAME_G {
            break;
        }
        if a > at + SAME_G {
            gaps.push(gap(at, at_closed, a));
        }
        at = at.max(b);
        at_closed = true;
    }
    if hi > at + SAME_G || covered.is_empty() {
        gaps.push(if at_closed {
            format!("{at}–{hi} (exclusive of {at})")
        } else {
            format!("{at}–{hi}")
        });
    }
    (!gaps.is_empty()).then(|| gaps.join(", "))
}

fn gap(from: f64, from_covered: bool, to: f64) -> String {
    if from_covered {
        format!("{from}–{to} (exclusive)")
    } else {
        format!("{from}–{to} (exclusive of {to})")
    }
}

/// How α′ follows g in the term.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AlbedoAtG {
    /// Inverted from the reading's Rd at each g (a measurement with a spectrophotometer, or
    /// `fit --rd`).
    FromRd,
    /// Held at the given α′ (`fit --albedo` without `--rd`: the term then holds the profile's
    /// dependence on g only).
    Fixed,
}

/// One channel's g term.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GTerm {
    /// The term of σ′s \[mm⁻¹\].
    pub sigma_s_prime: f64,
    /// The term of σa \[mm⁻¹\].
    pub sigma_a: f64,
    /// The term of α′.
    pub albedo_prime: f64,
    /// The middle (max + min)/2 of σ′s, σa, α′ over the points: the values, for a range without a
    /// g when the value's model is the g-aware `mc` ([`GTerm::centre_applies`]).
    pub centre: [f64; 3],
    /// Whether [`GTerm::centre`] replaces the values.
    pub centre_applies: bool,
    /// The g the estimates were computed at (the plan's points where the fits succeeded).
    pub evaluated: Vec<f64>,
    /// What the user should know: points where the estimate could not be computed.
    pub note: Option<String>,
}

/// The `mc` estimate (σ′s, σa, α′) of one channel at g.
fn estimate_at(
    g: f64,
    data: &ProfileData,
    input: &ChannelInput,
    albedo_at_g: AlbedoAtG,
    opts: &FitOptions,
    proposed: bool,
) -> std::result::Result<[f64; 3], String> {
    let mc = scatterfit_mc::family(ModelName::Mc).map_err(|e| e.to_string())?;
    let mc_albedo =
        scatterfit_mc::albedo_family(AlbedoModel::Mc, ModelName::Mc).map_err(|e| e.to_string())?;
    let model = AtG::new(mc, g).map_err(|e| e.to_string())?;
    let mut input = *input;
    if proposed && albedo_at_g == AlbedoAtG::FromRd {
        let rd = input.rd_total.ok_or("no Rd")?;
        input.albedo_prime = Some(
            mc_albedo
                .albedo_from_rd(rd, input.eta, g)
                .map_err(|e| e.to_string())?,
        );
    }
    let r = scatterfit_fit::fit_channel(data, &input, &model, opts).map_err(|e| e.to_string())?;
    if !r.converged {
        return Err(format!("the fit failed ({})", r.termination));
    }
    Ok([r.sigma_s_prime.value, r.sigma_a.value, r.albedo_prime])
}

/// The g term of every fitted channel ([module docs](self)): `None` for a channel not fitted,
/// `Err` (why) where no term could be computed — the g the values are at could not be evaluated, or
/// no point could.
pub fn propagate_g(
    profiles: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    settings: &FitSettings,
    fits: &Rgb<ChannelOutcome>,
    plan: &GPlan,
    albedo_at_g: AlbedoAtG,
) -> Rgb<Option<std::result::Result<GTerm, String>>> {
    let opts = settings.options();
    let proposed = settings.method == Method::Proposed;
    let value_is_mc = settings.model == ModelName::Mc && settings.albedo_model == AlbedoModel::Mc;
    fits.as_ref()
        .zip(profiles.as_ref())
        .map_with_channel(|c, (outcome, data)| {
            let report = outcome.report().filter(|r| r.converged)?;
            let opts = match warm_start(&opts, report) {
                Ok(o) => o,
                Err(e) => return Some(Err(e)),
            };
            let input = ChannelInput {
                eta: spectro.eta,
                albedo_prime: spectro.albedo_prime[c],
                rd_total: Some(spectro.rd[c]),
            };
            let mut evaluated = Vec::new();
            let mut estimates = Vec::new();
            let mut failed = Vec::new();
            // Points whose tables do not reach the material's η, grouped by the tables' η range
            // (one clause for all of them, not one long message per g).
            let mut eta_gaps: Vec<((f64, f64), Vec<f64>)> = Vec::new();
            // Likewise the points whose tables hold no α′ with the reading's Rd, by the α′ range.
            let mut rd_gaps: Vec<(RdGapKey, Vec<f64>, Vec<f64>)> = Vec::new();
            for &g in &plan.points {
                if let Some(range) = eta_not_covered(g, input.eta) {
                    match eta_gaps.iter_mut().find(|(r, _)| *r == range) {
                        Some((_, gs)) => gs.push(g),
                        None => eta_gaps.push((range, vec![g])),
                    }
                    continue;
                }
                if proposed
                    && albedo_at_g == AlbedoAtG::FromRd
                    && let Some(rd) = input.rd_total
                    && let Some((key, total)) = rd_not_covered(g, rd, input.eta)
                {
                    match rd_gaps.iter_mut().find(|(k, _, _)| *k == key) {
                        Some((_, gs, totals)) => {
                            gs.push(g);
                            totals.push(total);
                        }
                        None => rd_gaps.push((key, vec![g], vec![total])),
                    }
                    continue;
                }
                match estimate_at(g, data, &input, albedo_at_g, &opts, proposed) {
                    Ok(e) => {
                        evaluated.push(g);
                        estimates.push(e);
                    }
                    Err(e) => failed.push(format!("g = {g}: {e}")),
                }
            }
            for ((above, end), gs, totals) in rd_gaps.into_iter().rev() {
                let (lo, hi) = totals
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| {
                        (a.min(t), b.max(t))
                    });
                let totals = if hi - lo > 5e-5 {
                    format!("{lo:.4}–{hi:.4}")
                } else {
                    format!("{lo:.4}")
                };
                failed.insert(
                    0,
                    format!(
                        "g = {}: Rd = {:.4} is {} the totals the `mc` tables hold there (at their {} \
                         α′, {end}: Rd {totals})",
                        list(&gs),
                        input.rd_total.unwrap_or(f64::NAN),
                        if above { "above" } else { "below" },
                        if above { "highest" } else { "lowest" },
                    ),
                );
            }
            for ((lo, hi), gs) in eta_gaps.into_iter().rev() {
                failed.insert(
                    0,
                    format!(
                        "g = {}: the `mc` tables there cover η {lo}–{hi}, not η = {:.4}",
                        list(&gs),
                        input.eta
                    ),
                );
            }
            let note = (!failed.is_empty()).then(|| {
                format!(
                    "the g term is evaluated at g = {} only ({})",
                    list(&evaluated),
                    failed.join("; ")
                )
            });
            // One point has no spread: a term of 0 there would read as "g does not matter".
            if estimates.len() == 1 && plan.points.len() > 1 {
                return Some(Err(format!(
                    "the g term could not be evaluated: only at g = {} ({})",
                    list(&evaluated),
                    failed.join("; ")
                )));
            }
            if estimates.is_empty() {
                return Some(Err(format!(
                    "the g term could not be evaluated: {}",
                    failed.join("; ")
                )));
            }
            let (min, max) = estimates.iter().fold(
                ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
                |(lo, hi), e| {
                    (
                        std::array::from_fn(|k| lo[k].min(e[k])),
                        std::array::from_fn(|k| hi[k].max(e[k])),
                    )
                },
            );
            let centre: [f64; 3] = std::array::from_fn(|k| 0.5 * (min[k] + max[k]));
            let term: [f64; 3] = match plan.reference {
                None if value_is_mc => std::array::from_fn(|k| 0.5 * (max[k] - min[k])),
                reference => {
                    // The largest deviation from the estimate at the values' g.
                    let g0 = reference.unwrap_or(settings.g);
                    let at = evaluated.iter().position(|&g| (g - g0).abs() <= SAME_G);
                    let Some(at) = at else {
                        return Some(Err(format!(
                            "the g term could not be evaluated at the values' g = {g0} ({})",
                            failed.join("; ")
                        )));
                    };
                    let e0 = estimates[at];
                    std::array::from_fn(|k| {
                        estimates
                            .iter()
                            .map(|e| (e[k] - e0[k]).abs())
                            .fold(0.0, f64::max)
                    })
                }
            };
            Some(Ok(GTerm {
                sigma_s_prime: term[0],
                sigma_a: term[1],
                albedo_prime: term[2],
                centre,
                centre_applies: plan.reference.is_none() && value_is_mc,
                evaluated,
                note,
            }))
        })
}

/// The η range of the bundled grid's tables at g when they do not reach `eta` (within the sets'
/// edge tolerance); `None` when they do, or when g itself is not covered (its estimate then fails
/// with its own message).
fn eta_not_covered(g: f64, eta: f64) -> Option<(f64, f64)> {
    let (lo, hi) = scatterfit_mc::bundled_grid().ok()?.eta_range_at(g).ok()?;
    let tol = scatterfit_mc::model::ETA_EDGE_TOLERANCE;
    (!(eta >= lo - tol && eta <= hi + tol)).then_some((lo, hi))
}

/// Which end of the tables' totals a reading lies beyond: (above the highest, that end's α′ in
/// words).
type RdGapKey = (bool, String);

/// When the reading's Rd lies outside the totals the bundled grid holds at g and η: which end
/// (with its α′) and the total there; `None` when Rd is inside, or when the grid cannot say (the
/// estimate then fails with its own message).
fn rd_not_covered(g: f64, rd: f64, eta: f64) -> Option<(RdGapKey, f64)> {
    let grid = scatterfit_mc::bundled_grid().ok()?;
    let (lo, hi) = grid.albedo_prime_range(g).ok()?;
    let (r_lo, r_hi) = (
        grid.rd_total(lo, eta, g).ok()?,
        grid.rd_total(hi, eta, g).ok()?,
    );
    if rd < r_lo {
        Some(((false, format!("{lo:.3}")), r_lo))
    } else if rd > r_hi {
        Some(((true, format!("{hi:.5}")), r_hi))
    } else {
        None
    }
}

fn list(v: &[f64]) -> String {
    v.iter()
        .map(|g| format!("{g}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The fit's options started from a converged fit's solution (σ′s, σa; the scale refitted): the
/// refits at other g begin where the main fit ended.
pub(crate) fn warm_start<E: std::fmt::Display>(
    opts: &std::result::Result<FitOptions, E>,
    report: &FitReport,
) -> std::result::Result<FitOptions, String> {
    let o = opts.as_ref().map_err(|e| e.to_string())?;
    Ok(FitOptions {
        start: Some(Start {
            sigma_s_prime: report.sigma_s_prime.value,
            sigma_a: Some(report.sigma_a.value),
            scale: None,
        }),
        ..*o
    })
}

/// The default search range for `g = "fit"` without a `g_range`: the widest interval of g the
/// grid covers (0–0.95 since the g 0.3/0.5/0.7 tables); `None` when it covers single nodes only.
pub fn default_search_range(grid: &McGridSet) -> Option<[f64; 2]> {
    grid.covered()
        .into_iter()
        .filter(|(a, b)| b > a)
        .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
        .map(|(a, b)| [a, b])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plan on the shipped grid (g 0–0.95, nodes 0, 0.15, 0.3, 0.5, 0.7, 0.8, 0.9, 0.95): the
    /// default range is evaluated at every node and nothing is left out; a range between nodes at
    /// its ends and the values' g; a range without a g has its nominal g at its middle. On a grid
    /// with a gap (the shipped one without its low nodes, as it was until 2026-11-27) the gap is
    /// named, a range inside it refused, and the nominal g is the covered point nearest the middle.
    #[test]
    fn plans_on_the_shipped_grid() {
        let grid = scatterfit_mc::bundled_grid().unwrap();
        let p = GPlan::on_grid(grid, DEFAULT_G_RANGE, Some(0.0)).unwrap();
        assert_eq!(p.points, [0.0, 0.15, 0.3, 0.5, 0.7, 0.8, 0.9, 0.95]);
        assert_eq!(p.not_covered, None);
        let p = GPlan::on_grid(grid, [0.82, 0.88], Some(0.85)).unwrap();
        assert_eq!(p.points, [0.82, 0.85, 0.88]);
        assert_eq!(p.not_covered, None);
        let p = GPlan::on_grid(grid, [0.4, 0.6], None).unwrap();
        assert_eq!(p.points, [0.4, 0.5, 0.6]);
        assert_eq!(GPlan::nominal_g(grid, [0.7, 0.95]), Some(0.825));
        assert_eq!(GPlan::nominal_g(grid, DEFAULT_G_RANGE), Some(0.475));
        let gapped = grid.with_nodes(|g| g == 0.0 || g >= 0.8).unwrap();
        let p = GPlan::on_grid(&gapped, DEFAULT_G_RANGE, Some(0.0)).unwrap();
        assert_eq!(p.points, [0.0, 0.8, 0.9, 0.95]);
        assert_eq!(p.not_covered.as_deref(), Some("0–0.8 (exclusive)"));
        let p = GPlan::on_grid(&gapped, [0.7, 0.95], None).unwrap();
        assert_eq!(p.points, [0.8, 0.9, 0.95]);
        assert_eq!(p.not_covered.as_deref(), Some("0.7–0.8 (exclusive of 0.8)"));
        assert!(GPlan::on_grid(&gapped, [0.3, 0.6], None).is_err());
        assert_eq!(GPlan::nominal_g(&gapped, DEFAULT_G_RANGE), Some(0.8));
        assert_eq!(GPlan::nominal_g(&gapped, [0.3, 0.6]), None);
        // A range that ends beyond the grid names the rest.
        let two = gapped.with_nodes(|g| g <= 0.9).unwrap();
        let p = GPlan::on_grid(&two, DEFAULT_G_RANGE, Some(0.0)).unwrap();
        assert_eq!(p.points, [0.0, 0.8, 0.9]);
        assert_eq!(
            p.not_covered.as_deref(),
            Some("0–0.8 (exclusive), 0.9–0.95 (exclusive of 0.9)")
        );
    }

    /// The prior's source and range: g alone is known, nothing stated is the default range.
    #[test]
    fn prior_source_and_checks() {
        let known = GPrior {
            g: Some(0.85),
            range: None,
            fit: false,
        };
        assert_eq!(known.source(), GSource::Given);
        assert_eq!(known.propagated_range(), None);
        let default = GPrior::default();
        assert_eq!(default.source(), GSource::DefaultRange);
        assert_eq!(default.propagated_range(), Some(DEFAULT_G_RANGE));
        assert!(!default.is_centred());
        let range = GPrior {
            g: None,
            range: Some([0.7, 0.95]),
            fit: false,
        };
        assert!(range.is_centred() && range.check().is_ok());
        // g = "fit" without a range searches the grid's widest covered interval, centred.
        let fit = GPrior {
            fit: true,
            ..GPrior::default()
        };
        assert_eq!(fit.source(), GSource::Fit);
        let grid = scatterfit_mc::bundled_grid().unwrap();
        assert_eq!(fit.propagated_range(), default_search_range(grid));
        assert!(fit.is_centred() && fit.check().is_ok());
        for bad in [
            GPrior {
                g: Some(0.5),
                range: Some([0.7, 0.9]),
                fit: false,
            },
            GPrior {
                g: None,
                range: Some([0.9, 0.7]),
                fit: false,
            },
            GPrior {
                g: None,
                range: Some([0.0, 0.99]),
                fit: false,
            },
            GPrior {
                g: Some(0.85),
                range: None,
                fit: true,
            },
        ] {
            assert!(bad.check().is_err(), "{bad:?}");
        }
    }
}
