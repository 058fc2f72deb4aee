//! What is known about g ([`GPrior`]) and where its term is evaluated ([`GPlan`]): the tables'
//! g nodes inside the range, the range's ends and the values' g, where the tables cover them.

use scatterfit_io::manifest::GSetting;
use scatterfit_io::result_json::{GSource, GUncertainty};
use scatterfit_mc::McGridSet;

use crate::error::{PipelineError, Result};

/// The range of g propagated when neither `[fit] g` nor `[fit] g_range` is stated: 0 (the
/// isotropic scattering the paper assumes) to 0.95 (the most forward-scattering of real
/// translucent materials — skin, marble, milk, wax, plastics are 0.7–0.95). An unstated g is an
/// unknown g; the values stay at g = 0 (what the paper's method and isotropic models assume), and
/// the term shows how far they could be off.
pub const DEFAULT_G_RANGE: [f64; 2] = [0.0, scatterfit_io::manifest::G_RANGE_MAX];

/// Two g closer than this are one point (a g typed as 0.8 is the node 0.8).
pub(crate) const SAME_G: f64 = 1e-9;

/// What is known about the material's g: the manifest's `[fit] g` and `[fit] g_range` (or the
/// commands' `--g`, `--g-range`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GPrior {
    /// A known or assumed g: the values are computed at it.
    pub g: Option<f64>,
    /// The range g lies in, `[lo, hi]` with 0 ≤ lo ≤ hi ≤ 0.95; with [`GPrior::fit`] the range
    /// searched.
    pub range: Option<[f64; 2]>,
    /// `g = "fit"`: g fitted per channel from the profile ([`crate::anisotropy::fit`]); where the
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
