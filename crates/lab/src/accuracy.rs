//! The demo's accuracy table: rig-twin samples measured by the proposed and the existing method
//! (with the measurement's forward model, exact transport by default) and by the paper's own fit
//! (the dipole, α′ from its total), each value beside the truth the twin was made with
//! (`truth.json`, [`Truth`]).

use scatterfit_io::result_json::MeasurementResult;
use scatterfit_optics::Channel;
use scatterfit_synth::Truth;
use serde::Serialize;

/// One channel of the demo's accuracy table: the truth, each method's value and its relative
/// error.
#[derive(Debug, Serialize)]
pub struct ChannelRow {
    /// "R", "G" or "B".
    pub channel: &'static str,
    /// The twin's σ′s \[mm⁻¹\].
    pub sigma_s_prime_true: f64,
    /// The twin's σa \[mm⁻¹\].
    pub sigma_a_true: f64,
    /// The twin's α′.
    pub albedo_prime_true: f64,
    /// The proposed method's σ′s \[mm⁻¹\].
    pub proposed_sigma_s_prime: Option<f64>,
    /// The proposed method's σa \[mm⁻¹\].
    pub proposed_sigma_a: Option<f64>,
    /// The proposed method's α′ (from the spectrophotometer).
    pub proposed_albedo_prime: Option<f64>,
    /// The existing method's σ′s \[mm⁻¹\].
    pub existing_sigma_s_prime: Option<f64>,
    /// The existing method's σa \[mm⁻¹\].
    pub existing_sigma_a: Option<f64>,
    /// Relative error of the proposed σ′s (found / true − 1).
    pub proposed_sigma_s_prime_error: Option<f64>,
    /// Relative error of the proposed σa.
    pub proposed_sigma_a_error: Option<f64>,
    /// Relative error of the existing σ′s.
    pub existing_sigma_s_prime_error: Option<f64>,
    /// Relative error of the existing σa.
    pub existing_sigma_a_error: Option<f64>,
    /// The paper's own fit (the dipole, α′ from the dipole's total, proposed method): σ′s
    /// \[mm⁻¹\].
    pub paper_sigma_s_prime: Option<f64>,
    /// σa of the paper's fit \[mm⁻¹\].
    pub paper_sigma_a: Option<f64>,
    /// Relative error of the paper's σ′s.
    pub paper_sigma_s_prime_error: Option<f64>,
    /// Relative error of the paper's σa.
    pub paper_sigma_a_error: Option<f64>,
}

/// One material of the demo's accuracy table.
#[derive(Debug, Serialize)]
pub struct MaterialRow {
    /// The material.
    pub name: String,
    /// The forward model of the measurement (the proposed and existing columns).
    pub model: String,
    /// The twin's η.
    pub eta_true: f64,
    /// η from the spectrophotometer.
    pub eta_found: f64,
    /// R, G, B.
    pub channels: Vec<ChannelRow>,
}

/// A result's value, without its terms (the table compares values with the truth).
fn value(e: Option<scatterfit_optics::Estimate>) -> Option<f64> {
    e.map(|e| e.value)
}

fn rel(found: Option<f64>, truth: f64) -> Option<f64> {
    found.map(|f| f / truth - 1.0)
}

/// The accuracy table's rows: each compared sample ((existing, proposed) results, and the paper's
/// fit where it ran) beside its rig twin's truth, matched by name; samples without a truth are
/// left out.
pub fn accuracy_rows(
    pairs: &[(MeasurementResult, MeasurementResult)],
    papers: &[Option<MeasurementResult>],
    truths: &[Truth],
) -> Vec<MaterialRow> {
    pairs
        .iter()
        .enumerate()
        .filter_map(|(i, (e, p))| {
            let t = truths.iter().find(|t| t.name == p.name)?;
            let x = papers.get(i).and_then(Option::as_ref);
            Some(MaterialRow {
                name: p.name.clone(),
                model: p.model.name().to_owned(),
                eta_true: t.eta,
                eta_found: p.eta,
                channels: Channel::ALL
                    .iter()
                    .map(|&c| {
                        let (tc, pc, ec) = (&t.channels[c.index()], &p.channels[c], &e.channels[c]);
                        ChannelRow {
                            channel: c.name(),
                            sigma_s_prime_true: tc.sigma_s_prime,
                            sigma_a_true: tc.sigma_a,
                            albedo_prime_true: tc.albedo_prime,
                            proposed_sigma_s_prime: value(pc.sigma_s_prime),
                            proposed_sigma_a: value(pc.sigma_a),
                            proposed_albedo_prime: value(pc.albedo_prime),
                            existing_sigma_s_prime: value(ec.sigma_s_prime),
                            existing_sigma_a: value(ec.sigma_a),
                            proposed_sigma_s_prime_error: rel(
                                value(pc.sigma_s_prime),
                                tc.sigma_s_prime,
                            ),
                            proposed_sigma_a_error: rel(value(pc.sigma_a), tc.sigma_a),
                            existing_sigma_s_prime_error: rel(
                                value(ec.sigma_s_prime),
                                tc.sigma_s_prime,
                            ),
                            existing_sigma_a_error: rel(value(ec.sigma_a), tc.sigma_a),
                            paper_sigma_s_prime: x.and_then(|x| value(x.channels[c].sigma_s_prime)),
                            paper_sigma_a: x.and_then(|x| value(x.channels[c].sigma_a)),
                            paper_sigma_s_prime_error: x.and_then(|x| {
                                rel(value(x.channels[c].sigma_s_prime), tc.sigma_s_prime)
                            }),
                            paper_sigma_a_error: x
                                .and_then(|x| rel(value(x.channels[c].sigma_a), tc.sigma_a)),
                        }
                    })
                    .collect(),
            })
        })
        .collect()
}
