//! Axes in plot space: log10 of the value on a log axis, the value itself on a linear one; decade
//! ticks with superscript labels (`10⁻⁴`), "nice" linear steps, and the ranges a figure's panels
//! share.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};

use super::{Figure, Series, SeriesStyle};

/// At most this many decades on a log axis: wider data keep the top decades.
pub(super) const MAX_DECADES: f64 = 24.0;

/// One axis in plot space: log10 of the value on a log axis, the value itself otherwise.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Axis {
    pub(super) log: bool,
    /// Plot-space range.
    pub(super) lo: f64,
    pub(super) hi: f64,
    /// Distance between ticks on a linear axis.
    pub(super) step: f64,
    /// Labelled ticks (plot space).
    pub(super) ticks: Vec<f64>,
    /// Minor grid lines (plot space).
    pub(super) minor: Vec<f64>,
}

impl Axis {
    /// The plot-space coordinate of `v`, if it can be shown on this kind of axis.
    pub(super) fn map(log: bool, v: f64) -> Option<f64> {
        if !v.is_finite() {
            None
        } else if log {
            (v > 0.0).then(|| v.log10())
        } else {
            Some(v)
        }
    }

    pub(super) fn contains(&self, p: f64) -> bool {
        p >= self.lo && p <= self.hi
    }

    pub(super) fn clamp(&self, p: f64) -> f64 {
        p.clamp(self.lo, self.hi)
    }

    /// A log axis showing the data's plot-space extent [lo, hi] (log10 values) with a margin of 4 %
    /// of the span (at least 0.05 decade) either side, so no marker sits on the frame. An end within
    /// 0.35 decade of a whole decade is moved out to it; data inside less than about a decade get
    /// the whole decades around them, so the axis always carries at least two decade ticks. At most
    /// `MAX_DECADES` are shown (the top ones).
    pub(super) fn log(lo: f64, hi: f64) -> Self {
        // Data spanning more than MAX_DECADES keep their top decades.
        let lo = lo.max(hi - MAX_DECADES);
        let margin = (0.04 * (hi - lo)).max(0.05);
        let (mut bottom, mut top) = (lo - margin, hi + margin);
        if top.floor() - bottom.ceil() < 1.0 {
            bottom = bottom.floor();
            top = top.ceil();
        } else {
            if bottom - bottom.floor() < 0.35 {
                bottom = bottom.floor();
            }
            if top.ceil() - top < 0.35 {
                top = top.ceil();
            }
        }
        if top - bottom > MAX_DECADES {
            bottom = top - MAX_DECADES;
        }
        // At most ~10 labels; grid lines on every decade, and at 2…9 × 10^k when few decades.
        let (first, last) = (bottom.ceil(), top.floor());
        let step = ((last - first + 1.0) / 10.0).ceil().max(1.0);
        let ticks = decade_range(first, last)
            .filter(|d| d.rem_euclid(step) < 0.5)
            .collect();
        let mut minor: Vec<f64> = decade_range(first, last).collect();
        if top - bottom <= 5.0 {
            for d in decade_range(bottom.floor(), top.ceil() - 1.0) {
                minor.extend(
                    (2..10)
                        .map(|m| d + f64::from(m).log10())
                        .filter(|p| (bottom..=top).contains(p)),
                );
            }
        }
        Self {
            log: true,
            lo: bottom,
            hi: top,
            step: 1.0,
            ticks,
            minor,
        }
    }

    /// A linear axis showing the data's extent [min, max]: from 0 when the data are not negative
    /// (radii start at the spot centre), else from 4 % of the span below `min`, to 4 % above `max`;
    /// ticks at multiples of a "nice" step (1, 2, 5 × 10^k).
    pub(super) fn linear(min: f64, max: f64) -> Self {
        let base = min.min(0.0);
        let span = if max > base { max - base } else { 1.0 };
        let lo = if min < 0.0 { min - 0.04 * span } else { 0.0 };
        let hi = if max > base {
            max + 0.04 * span
        } else {
            base + 1.0
        };
        let step = nice_step((hi - lo) / 6.0);
        let (first, last) = ((lo / step - 1e-9).ceil(), (hi / step + 1e-9).floor());
        let ticks = (0..=((last - first) as i64).max(-1))
            .map(|k| (first + k as f64) * step)
            .collect();
        Self {
            log: false,
            lo,
            hi,
            step,
            ticks,
            minor: Vec::new(),
        }
    }

    /// Tick label for plot-space value `p`.
    pub(super) fn label(&self, p: f64) -> String {
        if self.log {
            format!("10{}", superscript(p.round() as i64))
        } else {
            let decimals = (-self.step.log10().floor()).max(0.0) as usize;
            let text = format!("{p:.decimals$}");
            // Never print "-0" or "-0.0".
            if text
                .trim_start_matches('-')
                .chars()
                .all(|c| c == '0' || c == '.')
            {
                text.trim_start_matches('-').to_string()
            } else {
                text
            }
        }
    }
}

/// The axis as a plotters coordinate: linear in plot space, labelled ticks as bold mesh lines and
/// the minor grid as light ones (plotters' own log coordinate picks its ticks itself).
impl Ranged for Axis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let t = (value - self.lo) / (self.hi - self.lo);
        let t = if t.is_finite() {
            t.clamp(-1.0, 2.0)
        } else {
            0.5
        };
        limit.0 + (t * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// Whole decades from `bottom` to `top` inclusive (both integers in f64).
fn decade_range(bottom: f64, top: f64) -> impl Iterator<Item = f64> {
    let n = (top - bottom).round().max(-1.0) as i64;
    (0..=n).map(move |k| bottom + k as f64)
}

/// The smallest of 1, 2, 5 × 10^k that is ≥ `raw` (raw > 0).
fn nice_step(raw: f64) -> f64 {
    let raw = if raw.is_finite() && raw > 0.0 {
        raw
    } else {
        1.0
    };
    let magnitude = 10f64.powf(raw.log10().floor());
    let f = raw / magnitude;
    let m = if f <= 1.0 {
        1.0
    } else if f <= 2.0 {
        2.0
    } else if f <= 5.0 {
        5.0
    } else {
        10.0
    };
    m * magnitude
}

/// `k` in Unicode superscript digits ("⁻⁴").
fn superscript(k: i64) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if k < 0 {
        s.push('⁻');
    }
    for c in k.unsigned_abs().to_string().chars() {
        s.push(DIGITS[c.to_digit(10).unwrap_or(0) as usize]);
    }
    s
}

/// Min and max of an iterator of plot-space values, if any.
fn extent(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

pub(super) fn is_marker(style: SeriesStyle) -> bool {
    matches!(style, SeriesStyle::Measured | SeriesStyle::Excluded)
}

/// The shared axes of a figure: x from 0 (log: over the data's decades) to just past the largest
/// radius; y over the marker data (values and upper error bars), widened by at most one
/// decade (log) for model curves reaching beyond; the curves alone when there are no markers.
pub(super) fn figure_axes(fig: &Figure) -> (Axis, Axis) {
    let all = || fig.panels.iter().flat_map(|p| p.series.iter());
    let shown = |s: &Series| -> Vec<(f64, f64)> {
        s.points
            .iter()
            .filter_map(|&(x, y)| Some((Axis::map(fig.log_x, x)?, Axis::map(fig.log_y, y)?)))
            .collect()
    };

    let xs = extent(all().flat_map(|s| shown(s).into_iter().map(|p| p.0)));
    let x_axis = match (fig.log_x, xs) {
        (true, Some((lo, hi))) => Axis::log(lo, hi),
        (true, None) => Axis::log(-1.0, 1.0),
        (false, Some((lo, hi))) => Axis::linear(lo, hi),
        (false, None) => Axis::linear(0.0, 1.0),
    };

    let marker_ys = extent(all().filter(|s| is_marker(s.style)).flat_map(|s| {
        let upper: Vec<f64> = match (&s.errors, s.style) {
            (Some(errors), SeriesStyle::Measured) => s
                .points
                .iter()
                .zip(errors)
                .filter(|((x, y), _)| {
                    Axis::map(fig.log_x, *x).is_some() && Axis::map(fig.log_y, *y).is_some()
                })
                .filter_map(|((_, y), e)| Axis::map(fig.log_y, y + e.abs()))
                .collect(),
            _ => Vec::new(),
        };
        shown(s).into_iter().map(|p| p.1).chain(upper)
    }));
    let line_ys = extent(
        all()
            .filter(|s| !is_marker(s.style))
            .flat_map(|s| shown(s).into_iter().map(|p| p.1)),
    );
    let widen = if fig.log_y { 1.0 } else { f64::INFINITY };
    let ys = match (marker_ys, line_ys) {
        (Some((lo, hi)), Some((llo, lhi))) => {
            Some((lo.min(llo.max(lo - widen)), hi.max(lhi.min(hi + widen))))
        }
        (m, l) => m.or(l),
    };
    let y_axis = match (fig.log_y, ys) {
        (true, Some((lo, hi))) => Axis::log(lo, hi),
        (true, None) => Axis::log(-3.0, 0.0),
        (false, Some((lo, hi))) => Axis::linear(lo, hi),
        (false, None) => Axis::linear(0.0, 1.0),
    };
    (x_axis, y_axis)
}
