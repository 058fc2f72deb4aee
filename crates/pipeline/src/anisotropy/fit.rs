//! Fitting the anisotropy g from the profile (`[fit] g = "fit"`): a one-dimensional
//! profile likelihood over g per channel, and the rule that decides whether the data determine g.
//!
//! **The profile likelihood** (Press et al., *Numerical Recipes*, 3rd ed., §15.6.4–15.6.5;
//! Bevington & Robinson, *Data Reduction and Error Analysis*, 3rd ed., §8.2). For each g on a scan
//! of the searched range the channel is fitted with the g-aware `mc` model at that g — proposed
//! method: α′(g) inverted from the reading's Rd with the `mc` tables at g, then σ′s and the scale k
//! fitted; existing method: σ′s, σa and k fitted — giving χ²(g) = min over the other unknowns of
//! Σ ((ln y_i − ln(k·R(r_i; σ′s, σa, g)))/σ_i)². Its minimum is the joint least-squares fit of
//! (g, the rest):
//!
//! - ĝ: the vertex of the parabola through the scan's smallest χ² and its two neighbours,
//!   χ²(g) ≈ a (g − ĝ)² + χ²_min;
//! - sd_fit(g) = √(s/a), Δχ² = 1 at one standard deviation, s = max(1, χ²_min/(n − p − 1)) — the
//!   reduced χ² inflates it when the model misfits, never deflates it (as the fit's own errors,
//!   `scatterfit_fit`);
//! - the values at ĝ come from the fit at ĝ; their g term is how far they move over ĝ ± sd(g)
//!   (first-order propagation along the profile path);
//! - corr(σ′s, g) = b·sd_fit(g)/√(sd(σ′s | g)² + b² sd_fit(g)²), with b = dσ̂′s/dg the slope of the
//!   profile path: for a quadratic χ² surface the conditional minimum σ̂′s(g) is the regression line
//!   of σ′s on g, so Cov(σ′s, g) = b Var(g) and Var(σ′s) = Var(σ′s | g) + b² Var(g).
//!
//! **The model's part of sd(g).** Camera noise alone pins g to ±0.001 (BENCHMARKS.md, "Can g be
//! fitted from the rig's profile?"); what limits g is the model's own shape error. A change of g by
//! Δg = 0.05 changes the refitted profile's shape by an RMS S (measured here, per channel, from the
//! fits at ĝ ± 0.05); a smooth shape error δ of the model projects onto it as at most
//! |Δg| = 0.05·δ/S. δ is measured from the data: the RMS of the fit's log residuals at ĝ beyond the
//! rings' own noise, √(max(0, rms² − mean σ_ln²)), and never less than [`MODEL_SHAPE_NOISE`] (the
//! `mc` tables' noise budget, 0.3 %): sd_model(g) = 0.05·δ/S. (With δ fixed at 0.3 % the rig twin at
//! g = 0.8 had four channels "determined" 2–4 sd(g) from the truth; with the measured misfit none
//! is: BENCHMARKS.md.)
//!
//! **The spectrophotometer's part.** α′(g) comes from the reading's Rd, so an error in the reading
//! moves the minimum: the scan is repeated with the reading (η and Rd together, as
//! [`crate::fit::propagate_spectro`]) at −1 and +1 standard deviation, and sd_spectro(g) is half
//! the distance between the two minima. sd(g) = √(sd_fit² + sd_model² + sd_spectro²).
//!
//! **The rule** ([`G_DETERMINED_SD`], [`ALBEDO_DETERMINED_MAX`]): g is determined when the
//! minimum lies inside the searched range (at least one scan step from either end of the g the
//! tables answer at this η), χ²'s curvature there is positive, the fit at ĝ converged, α′ < 0.98,
//! and sd(g) ≤ 0.05. The α′ bound is the Fisher study's verdict (determined for α′ ≲ 0.95, not
//! for α′ ≥ 0.98 at η = 1.4): there the true shape signal S is 0.2–0.4 %, the model's noise, but
//! S measured on the data is inflated by the two g nodes' independent table noise, so sd_model
//! alone would not refuse it (rig twins: BENCHMARKS.md).
//! Where g is not determined it is not printed, and the channel gets the searched range's "± g"
//! term ([`crate::anisotropy`]), as `g_range` alone gives.

use scatterfit_fit::{ChannelInput, FitOptions, FitReport, ProfileData};
use scatterfit_mc::McGridSet;
use scatterfit_optics::{AlbedoModel, AtG, Method, ModelName, Rgb};

use super::record::{AlbedoAtG, GFit};
use super::term::warm_start;
use crate::fit::outcome::ChannelOutcome;
use crate::settings::FitPlan;
use crate::spectro::SpectroStage;

/// The largest sd(g) at which g counts as determined: the Fisher study's threshold (BENCHMARKS.md,
/// "Can g be fitted from the rig's profile?"), a quarter of the 0.7–0.95 real materials span.
pub const G_DETERMINED_SD: f64 = 0.05;

/// The reduced albedo from which g counts as not determined whatever the fit's curvature says:
/// there a change of g by 0.05 changes the refitted profile's shape by only 0.2–0.4 % RMS (the
/// Fisher study, BENCHMARKS.md "Can g be fitted from the rig's profile?", with the tables' noise
/// separated by a second seed) — the model's own noise — while the shape signal measured on the
/// data there is inflated by the noise of the two g nodes' tables (on rig twins at g = 0.9 it
/// read 1.2–1.4 % at α′ 0.993–0.999 and put ĝ 0.92–0.94; BENCHMARKS.md, the twin table).
pub const ALBEDO_DETERMINED_MAX: f64 = 0.98;

/// The smallest relative shape error δ (RMS over the profile) assumed for the model: the tables'
/// noise budget, and
/// the interpolant's error in g against a table built at g = 0.85 (0.2–0.4 %; BENCHMARKS.md,
/// "The `mc` model over g").
pub const MODEL_SHAPE_NOISE: f64 = 0.003;

/// The scan's step in g from [`SCAN_FINE_FROM`] up (the nodes of the tables and the range's ends
/// are added).
pub const SCAN_STEP: f64 = 0.01;

/// The scan's step in g below [`SCAN_FINE_FROM`]: the profile's shape changes with g more slowly
/// there (at g 0.5 the reduced profile is within 1–6 % of g = 0's over 0.5–10 mean free paths,
/// at 0.9 within 8–60 %; BENCHMARKS.md "The `mc` model over g"), the minimum is refined by a
/// parabola through its neighbours, and a sample's scan stays a few hundred fits.
pub const SCAN_STEP_COARSE: f64 = 0.05;

/// Where the scan's fine step starts.
pub const SCAN_FINE_FROM: f64 = 0.7;

/// The Δg whose shape change is the signal (the Fisher study's).
const SHAPE_DG: f64 = 0.05;

/// The scan's points in `range`: steps of [`SCAN_STEP_COARSE`] below [`SCAN_FINE_FROM`] and of
/// [`SCAN_STEP`] from it, the grid's nodes inside and the ends, each where the grid covers it (η is
/// checked when the model is evaluated).
pub fn scan_points(grid: &McGridSet, range: [f64; 2]) -> Vec<f64> {
    let [lo, hi] = range;
    let steps = |a: f64, b: f64, step: f64| -> Vec<f64> {
        if b < a {
            return Vec::new();
        }
        let n = ((b - a) / step + 1e-9).floor() as usize;
        (0..=n).map(|k| a + k as f64 * step).collect()
    };
    let fine_from = SCAN_FINE_FROM.clamp(lo, hi);
    let mut points: Vec<f64> = steps(lo, fine_from, SCAN_STEP_COARSE)
        .into_iter()
        .chain(steps(fine_from, hi, SCAN_STEP))
        .chain(grid.g_nodes().into_iter().filter(|&g| g >= lo && g <= hi))
        .chain([lo, hi])
        .map(|g| (g * 1e9).round() / 1e9)
        .filter(|&g| g <= hi + 1e-12 && grid.covers(g))
        .collect();
    points.sort_by(f64::total_cmp);
    points.dedup_by(|a, b| (*a - *b).abs() <= 1e-9);
    points
}

/// What one channel's fit at one g needs.
pub struct ChannelAtG<'a> {
    /// The profile.
    pub data: &'a ProfileData,
    /// η, the reading's α′ and Rd.
    pub input: ChannelInput,
    /// How α′ follows g.
    pub albedo_at_g: AlbedoAtG,
    /// The fit's options (a start near the solution).
    pub opts: FitOptions,
    /// Proposed (α′ from Rd) or existing.
    pub proposed: bool,
}

impl ChannelAtG<'_> {
    /// The channel fitted with the `mc` model at g (α′ from the reading at g for the proposed
    /// method).
    ///
    /// # Errors
    /// Why not, in words: g or η outside the tables, the fit failed or did not converge.
    pub fn fit(&self, g: f64) -> Result<FitReport, String> {
        let mc = scatterfit_mc::family(ModelName::Mc).map_err(|e| e.to_string())?;
        let model = AtG::new(mc, g).map_err(|e| e.to_string())?;
        let mut input = self.input;
        if self.proposed && self.albedo_at_g == AlbedoAtG::FromRd {
            let albedo = scatterfit_mc::albedo_family(AlbedoModel::Mc, ModelName::Mc)
                .map_err(|e| e.to_string())?;
            let rd = input.rd_total.ok_or("no Rd")?;
            input.albedo_prime = Some(
                albedo
                    .albedo_from_rd(rd, input.eta, g)
                    .map_err(|e| e.to_string())?,
            );
        }
        let r = scatterfit_fit::fit_channel(self.data, &input, &model, &self.opts)
            .map_err(|e| e.to_string())?;
        if !r.converged {
            return Err(format!("the fit did not converge ({})", r.termination));
        }
        Ok(r)
    }
}

/// χ² of a report (the reduced χ² times the degrees of freedom).
fn chi2(r: &FitReport) -> f64 {
    r.chi2_reduced * dof(r) as f64
}

fn dof(r: &FitReport) -> usize {
    r.rings_used.saturating_sub(r.parameters.len()).max(1)
}

/// RMS of ln(a/b) over the fitted rings of two fits of one profile.
fn shape_rms(a: &FitReport, b: &FitReport) -> f64 {
    let n = a.fitted.len().min(b.fitted.len());
    if n == 0 {
        return f64::NAN;
    }
    let s: f64 = a
        .fitted
        .iter()
        .zip(&b.fitted)
        .map(|(x, y)| (x.model / y.model).ln().powi(2))
        .sum();
    (s / n as f64).sqrt()
}

/// The vertex and curvature a of the parabola through three points (χ² = a(g − ĝ)² + c).
fn parabola(p: [(f64, f64); 3]) -> Option<(f64, f64)> {
    let [(x0, y0), (x1, y1), (x2, y2)] = p;
    let d01 = (y1 - y0) / (x1 - x0);
    let d12 = (y2 - y1) / (x2 - x1);
    let a = (d12 - d01) / (x2 - x0);
    if !(a.is_finite() && a > 0.0) {
        return None;
    }
    // y' = d01 + a (2x − x0 − x1) = 0
    let vertex = 0.5 * (x0 + x1) - d01 / (2.0 * a);
    Some((vertex, a))
}

/// The g of χ²'s smallest value over `points` (the parabola's vertex through it and its
/// neighbours; the end point itself at an end): where a perturbed reading puts the minimum.
fn scan_minimum(channel: &ChannelAtG<'_>, points: &[f64]) -> Option<f64> {
    let scan: Vec<(f64, f64)> = points
        .iter()
        .filter_map(|&g| channel.fit(g).ok().map(|r| (g, chi2(&r))))
        .collect();
    let i = (0..scan.len()).min_by(|&a, &b| scan[a].1.total_cmp(&scan[b].1))?;
    if i == 0 || i + 1 == scan.len() {
        return Some(scan[i].0);
    }
    Some(
        parabola([scan[i - 1], scan[i], scan[i + 1]])
            .map_or(scan[i].0, |(v, _)| v.clamp(scan[i - 1].0, scan[i + 1].0)),
    )
}

/// The profile likelihood over `points` for one channel ([module docs](self)); `perturbed`: the
/// channel with the spectrophotometer's reading at −1 and +1 standard deviation (empty when the
/// reading does not enter, or has no error), whose minima give sd(g)'s spectrophotometer part.
pub fn fit_g(
    channel: &ChannelAtG<'_>,
    points: &[f64],
    perturbed: &[ChannelAtG<'_>],
) -> Result<GFit, String> {
    // The scan: runs of g the tables answered, with no failed point between.
    let mut scan: Vec<(f64, FitReport)> = Vec::new();
    let mut run_of: Vec<usize> = Vec::new();
    let mut run = 0;
    let mut failed = Vec::new();
    for &g in points {
        match channel.fit(g) {
            Ok(r) => {
                scan.push((g, r));
                run_of.push(run);
            }
            Err(e) => {
                if !scan.is_empty() {
                    run += 1;
                }
                failed.push(format!("g = {g}: {e}"));
            }
        }
    }
    if scan.len() < 3 {
        return Err(format!(
            "too few g the `mc` tables answer in the searched range ({})",
            if failed.is_empty() {
                "fewer than 3 scan points".into()
            } else {
                failed.join("; ")
            }
        ));
    }
    let chi: Vec<f64> = scan.iter().map(|(_, r)| chi2(r)).collect();
    let i = (0..scan.len())
        .min_by(|&a, &b| chi[a].total_cmp(&chi[b]))
        .unwrap_or(0);
    let (run_start, run_end) = (
        run_of.iter().position(|&k| k == run_of[i]).unwrap_or(0),
        run_of.iter().rposition(|&k| k == run_of[i]).unwrap_or(0),
    );
    let searched = [scan[run_start].0, scan[run_end].0];
    let mut fit = GFit {
        g: scan[i].0,
        stderr: f64::NAN,
        stderr_fit: f64::NAN,
        stderr_model: f64::NAN,
        stderr_spectro: f64::NAN,
        corr_sigma_s_prime: f64::NAN,
        shape_change: f64::NAN,
        searched,
        scan: scan.iter().zip(&chi).map(|((g, _), c)| (*g, *c)).collect(),
        determined: false,
        reason: None,
        report: None,
        term: None,
    };
    if i == run_start || i == run_end {
        fit.reason = Some(format!(
            "χ² is smallest at the end of the searched range, g = {}: the data prefer a g the \
             range or the tables (at this η) do not reach",
            scan[i].0
        ));
        return Ok(fit);
    }
    let p = |k: usize| (scan[k].0, chi[k]);
    let Some((vertex, a)) = parabola([p(i - 1), p(i), p(i + 1)]) else {
        fit.reason = Some("χ²(g) has no positive curvature at its minimum".into());
        return Ok(fit);
    };
    let g_hat = vertex.clamp(scan[i - 1].0, scan[i + 1].0);
    let at = match channel.fit(g_hat) {
        Ok(r) => r,
        Err(e) => {
            fit.reason = Some(format!("the fit at the minimum g = {g_hat:.3} failed: {e}"));
            return Ok(fit);
        }
    };
    // sd from the curvature: Δχ² = 1 ↔ a·sd² = 1, inflated by the reduced χ² (g one more unknown).
    let chi2_reduced = (chi2(&at) / dof(&at).saturating_sub(1).max(1) as f64).max(1.0);
    let sd_fit = (chi2_reduced / a).sqrt();
    // The shape signal: the refitted profiles at ĝ ± 0.05 (inside the searched range), scaled to
    // Δg = 0.05.
    let (lo, hi) = (searched[0], searched[1]);
    let mut signals = Vec::new();
    for side in [-SHAPE_DG, SHAPE_DG] {
        let g = (g_hat + side).clamp(lo, hi);
        let dg = (g - g_hat).abs();
        if dg < 0.5 * SCAN_STEP {
            continue;
        }
        if let Ok(r) = channel.fit(g) {
            signals.push(shape_rms(&at, &r) * SHAPE_DG / dg);
        }
    }
    let shape = if signals.is_empty() {
        f64::NAN
    } else {
        signals.iter().sum::<f64>() / signals.len() as f64
    };
    // δ: the model's noise, or the misfit the data show beyond the rings' own noise if larger.
    let noise2 = at
        .fitted
        .iter()
        .map(|f| f.sigma_ln * f.sigma_ln)
        .sum::<f64>()
        / at.fitted.len().max(1) as f64;
    let misfit = (at.rms_log_residual.powi(2) - noise2).max(0.0).sqrt();
    let delta = MODEL_SHAPE_NOISE.max(misfit);
    let sd_model = SHAPE_DG * delta / shape;
    // The reading's part: half the distance between the minima at the reading ∓ its error.
    let sd_spectro = match perturbed {
        [lo_reading, hi_reading] => match (
            scan_minimum(lo_reading, points),
            scan_minimum(hi_reading, points),
        ) {
            (Some(a), Some(b)) => 0.5 * (b - a).abs(),
            _ => f64::NAN,
        },
        _ => 0.0,
    };
    let sd = sd_fit.hypot(sd_model).hypot(sd_spectro);
    // corr(σ′s, g) along the profile path.
    let (g0, g1) = (scan[i - 1].0, scan[i + 1].0);
    let slope = (scan[i + 1].1.sigma_s_prime.value - scan[i - 1].1.sigma_s_prime.value) / (g1 - g0);
    let sd_sp = at.sigma_s_prime.stderr;
    let corr = slope * sd_fit / (sd_sp * sd_sp + slope * slope * sd_fit * sd_fit).sqrt();
    // The values' g term: how far they move over ĝ ± sd(g).
    let value = |r: &FitReport| [r.sigma_s_prime.value, r.sigma_a.value, r.albedo_prime];
    let v0 = value(&at);
    let mut term = [0.0f64; 3];
    for side in [-sd, sd] {
        let g = (g_hat + side).clamp(lo, hi);
        if (g - g_hat).abs() < 1e-6 {
            continue;
        }
        if let Ok(r) = channel.fit(g) {
            let v = value(&r);
            for k in 0..3 {
                term[k] = term[k].max((v[k] - v0[k]).abs());
            }
        }
    }
    fit.g = g_hat;
    fit.stderr = sd;
    fit.stderr_fit = sd_fit;
    fit.stderr_model = sd_model;
    fit.stderr_spectro = sd_spectro;
    fit.corr_sigma_s_prime = corr;
    fit.shape_change = shape;
    fit.term = Some(term);
    let albedo = at.albedo_prime;
    fit.reason = if albedo >= ALBEDO_DETERMINED_MAX {
        Some(format!(
            "α′ = {albedo:.4} ≥ {ALBEDO_DETERMINED_MAX}: there a change of g alters the profile's \
             shape by less than the model's own noise (0.2–0.4 % RMS for Δg = 0.05), so χ²(g) \
             follows the tables' noise, not g"
        ))
    } else if !sd.is_finite() {
        Some("sd(g) could not be computed (a scan at the minimum or at the perturbed readings failed)".into())
    } else if sd > G_DETERMINED_SD {
        Some(format!(
            "sd(g) = {sd:.3} > {G_DETERMINED_SD} (the fit's part {sd_fit:.3}; the \
             spectrophotometer's {sd_spectro:.3}; the model's {sd_model:.3}: Δg = 0.05 changes \
             the profile's shape by {:.2} % RMS against the model's {:.2} % misfit)",
            100.0 * shape,
            100.0 * delta
        ))
    } else {
        None
    };
    fit.determined = fit.reason.is_none();
    fit.report = Some(at);
    Ok(fit)
}

/// The fit of g of every fitted channel over `range` (`None` for a channel not fitted; `Err` why
/// not, when the scan could not run).
pub fn fit_g_channels(
    profiles: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    plan: &FitPlan,
    fits: &Rgb<ChannelOutcome>,
    range: [f64; 2],
    albedo_at_g: AlbedoAtG,
) -> Rgb<Option<Result<GFit, String>>> {
    let grid = scatterfit_mc::bundled_grid();
    fits.as_ref()
        .zip(profiles.as_ref())
        .map_with_channel(|c, (outcome, data)| {
            let report = outcome.report().filter(|r| r.converged)?;
            let opts = warm_start(&plan.options, report);
            let grid = match &grid {
                Ok(g) => *g,
                Err(e) => return Some(Err(e.to_string())),
            };
            let proposed = plan.settings.method == Method::Proposed;
            let at = |eta: f64, rd: f64| ChannelAtG {
                data,
                input: ChannelInput {
                    eta,
                    albedo_prime: spectro.albedo_prime[c],
                    rd_total: Some(rd),
                },
                albedo_at_g,
                opts,
                proposed,
            };
            let channel = at(spectro.eta, spectro.rd[c]);
            // The reading at ∓ its error (η and Rd together, as `propagate_spectro`): it moves
            // α′(g) and so the minimum (the existing method reads η only).
            let u = &spectro.uncertainty;
            let perturbed: Vec<ChannelAtG<'_>> = if u.repeatability > 0.0 {
                (0..2)
                    .map(|k| {
                        let rd = if proposed && albedo_at_g == AlbedoAtG::FromRd {
                            u.rd_pm[c][k]
                        } else {
                            spectro.rd[c]
                        };
                        at(u.eta_pm[k], rd)
                    })
                    .collect()
            } else {
                Vec::new()
            };
            Some(fit_g(&channel, &scan_points(grid, range), &perturbed))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::anisotropy::plan::default_search_range;

    /// The parabola's vertex and curvature from three points of a known parabola, unevenly spaced.
    #[test]
    fn parabola_through_three_points() {
        let f = |x: f64| 40.0 * (x - 0.873).powi(2) + 5.0;
        let (v, a) = parabola([(0.85, f(0.85)), (0.86, f(0.86)), (0.9, f(0.9))]).unwrap();
        assert!(
            (v - 0.873).abs() < 1e-12 && (a - 40.0).abs() < 1e-9,
            "{v} {a}"
        );
        assert!(parabola([(0.0, 1.0), (1.0, 0.0), (2.0, -1.0)]).is_none());
    }

    /// The default range and the scan on the shipped grid: the widest covered interval, steps of
    /// 0.05 below 0.7 and 0.01 from it with the nodes and ends, nothing the grid does not cover.
    #[test]
    fn range_and_scan_on_the_shipped_grid() {
        let grid = scatterfit_mc::bundled_grid().unwrap();
        let [lo, hi] = default_search_range(grid).unwrap();
        assert!(lo >= 0.0 && hi > lo && grid.covers(lo) && grid.covers(hi));
        for range in [[0.7, 0.93], [0.12, 0.93], [0.0, 0.95], [0.2, 0.6]] {
            let points = scan_points(grid, range);
            assert!(
                points
                    .iter()
                    .all(|&g| grid.covers(g) && (range[0]..=range[1]).contains(&g)),
                "{range:?}: {points:?}"
            );
            assert!(
                points.windows(2).all(|w| {
                    let step = if w[0] >= SCAN_FINE_FROM - 1e-9 {
                        SCAN_STEP
                    } else {
                        SCAN_STEP_COARSE
                    };
                    w[1] - w[0] <= step + 1e-9 || !grid.covers(0.5 * (w[0] + w[1]))
                }),
                "{range:?}: {points:?}"
            );
            assert!(points.contains(&range[0]) && points.contains(&range[1]));
        }
    }
}
