//! The g term of every fitted channel: the `mc` estimate recomputed at each g of the plan and
//! its spread ([module docs](super)).

use scatterfit_fit::{ChannelInput, FitOptions, FitReport, ProfileData, Start};
use scatterfit_optics::{AlbedoModel, AtG, Method, ModelName, Rgb};

use super::plan::{GPlan, SAME_G};
use super::record::{AlbedoAtG, GTerm};
use crate::fit::outcome::ChannelOutcome;
use crate::settings::FitPlan;
use crate::spectro::SpectroStage;

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

/// The g term of every fitted channel ([module docs](self)), each refit with the plan's options
/// started from the channel's own fit: `None` for a channel not
/// fitted, `Err` (why) where no term could be computed — the g the values are at could not be
/// evaluated, or no point could.
pub fn propagate_g(
    profiles: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    fit_plan: &FitPlan,
    fits: &Rgb<ChannelOutcome>,
    plan: &GPlan,
    albedo_at_g: AlbedoAtG,
) -> Rgb<Option<std::result::Result<GTerm, String>>> {
    let settings = &fit_plan.settings;
    let proposed = settings.method == Method::Proposed;
    let value_is_mc = settings.model == ModelName::Mc && settings.albedo_model == AlbedoModel::Mc;
    fits.as_ref()
        .zip(profiles.as_ref())
        .map_with_channel(|c, (outcome, data)| {
            let report = outcome.report().filter(|r| r.converged)?;
            let opts = warm_start(&fit_plan.options, report);
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
pub(crate) fn warm_start(opts: &FitOptions, report: &FitReport) -> FitOptions {
    FitOptions {
        start: Some(Start {
            sigma_s_prime: report.sigma_s_prime.value,
            sigma_a: Some(report.sigma_a.value),
            scale: None,
        }),
        ..*opts
    }
}
