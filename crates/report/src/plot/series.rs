//! How each [`SeriesStyle`] is drawn: markers (filled with error bars, or hollow grey), solid and
//! dashed curves clipped to the frame by hand (plotters does not clip paths), and each series'
//! sample in the legend.

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::axis::Axis;
use super::palette::GREY;
use super::{Figure, Series, SeriesStyle};
use crate::error::{Result, draw_error};

/// Draws one series into a panel's chart (in the panel's colour unless the series has its own) and
/// gives it a legend entry when it has a label.
pub(super) fn draw_series<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<Axis, Axis>>,
    fig: &Figure,
    panel_colour: (u8, u8, u8),
    series: &Series,
    x_axis: &Axis,
    y_axis: &Axis,
    x_px: f64,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| draw_error("drawing the plot", e);
    let (r, g, b) = series.colour.unwrap_or(panel_colour);
    let colour = RGBColor(r, g, b);
    // Measured markers in a lighter tint of the channel colour, so that a model curve drawn in
    // the full colour stays visible on top of 300 dense rings and the scatter shows around it.
    let marker_colour = tint(colour, 0.45);
    // Plot-space points with their index (for the error bars); None where not drawable.
    let mapped: Vec<Option<(f64, f64)>> = series
        .points
        .iter()
        .map(|&(x, y)| Some((Axis::map(fig.log_x, x)?, Axis::map(fig.log_y, y)?)))
        .collect();
    let visible = |p: &(f64, f64)| x_axis.contains(p.0) && y_axis.contains(p.1);
    let anno =
        match series.style {
            SeriesStyle::Measured | SeriesStyle::Excluded => {
                let n_visible = mapped.iter().flatten().filter(|p| visible(p)).count();
                // Markers shrink as rings crowd (300 rings in ~400 px), between 1.5 and 3.5 px.
                let radius = (0.45 * x_px / n_visible.max(1) as f64).clamp(1.5, 3.5);
                let radius_px = radius.round() as i32;
                if series.style == SeriesStyle::Measured {
                    if let Some(errors) = &series.errors {
                        // Caps only while they do not merge into a band.
                        let cap = if n_visible <= 60 { 3 } else { 0 };
                        let bars: Vec<(f64, f64, f64)> = mapped
                            .iter()
                            .zip(&series.points)
                            .zip(errors)
                            .filter_map(|((m, &(_, y)), &e)| {
                                let p = (*m)?;
                                let (lo, hi) = error_bar(fig.log_y, y, e, y_axis)?;
                                visible(&p).then_some((p.0, lo, hi))
                            })
                            .collect();
                        // (plotters' ErrorBar needs its `errorbar` feature, not enabled here.)
                        let style = marker_colour.stroke_width(1);
                        chart
                            .draw_series(bars.iter().map(|&(x, lo, hi)| {
                                PathElement::new(vec![(x, lo), (x, hi)], style)
                            }))
                            .map_err(err)?;
                        if cap > 0 {
                            chart
                                .draw_series(bars.iter().flat_map(|&(x, lo, hi)| {
                                    [lo, hi].map(|y| {
                                        EmptyElement::at((x, y))
                                            + PathElement::new(vec![(-cap, 0), (cap, 0)], style)
                                    })
                                }))
                                .map_err(err)?;
                        }
                    }
                    let style = marker_colour.filled();
                    chart
                        .draw_series(
                            mapped
                                .iter()
                                .flatten()
                                .filter(|p| visible(p))
                                .map(|&p| Circle::new(p, radius_px, style)),
                        )
                        .map_err(err)?
                } else {
                    let style = GREY.stroke_width(1);
                    chart
                        .draw_series(
                            mapped
                                .iter()
                                .flatten()
                                .filter(|p| visible(p))
                                .map(|&p| Circle::new(p, radius_px, style)),
                        )
                        .map_err(err)?
                }
            }
            SeriesStyle::Line | SeriesStyle::DashedLine => {
                let runs = clip_polyline(&mapped, x_axis, y_axis);
                let style = colour.stroke_width(2);
                if series.style == SeriesStyle::Line {
                    chart
                        .draw_series(runs.into_iter().map(|run| PathElement::new(run, style)))
                        .map_err(err)?
                } else {
                    chart
                        .draw_series(
                            runs.into_iter()
                                .flat_map(|run| DashedLineSeries::new(run, 9, 6, style)),
                        )
                        .map_err(err)?
                }
            }
        };
    if series.label.is_empty() {
        return Ok(());
    }
    // The legend's sample of the series; (x, y) is the left middle of the sample area.
    let anno = anno.label(series.label.clone());
    match series.style {
        SeriesStyle::Measured => anno.legend(move |(x, y)| {
            EmptyElement::at((x + 9, y))
                + PathElement::new(vec![(0, -7), (0, 7)], marker_colour.stroke_width(1))
                + Circle::new((0, 0), 3, marker_colour.filled())
        }),
        SeriesStyle::Excluded => anno.legend(|(x, y)| {
            EmptyElement::at((x + 9, y)) + Circle::new((0, 0), 3, GREY.stroke_width(1))
        }),
        SeriesStyle::Line => anno.legend(move |(x, y)| {
            PathElement::new(vec![(x - 2, y), (x + 20, y)], colour.stroke_width(2))
        }),
        SeriesStyle::DashedLine => anno.legend(move |(x, y)| {
            DashedPathElement::new(vec![(x - 2, y), (x + 20, y)], 6, 4, colour.stroke_width(2))
        }),
    };
    Ok(())
}

/// `c` moved the fraction `f` of the way towards white.
fn tint(c: RGBColor, f: f64) -> RGBColor {
    let t = |v: u8| (f64::from(v) + f * (255.0 - f64::from(v))).round() as u8;
    RGBColor(t(c.0), t(c.1), t(c.2))
}

/// The plot-space ends (lower, upper) of a one-sigma bar around `y`, clamped to the axis: on a log
/// axis a lower end y − σ ≤ 0 is drawn to the bottom of the axis. None when there is nothing to draw.
fn error_bar(log: bool, y: f64, sigma: f64, axis: &Axis) -> Option<(f64, f64)> {
    let sigma = sigma.abs();
    if !sigma.is_finite() || sigma == 0.0 {
        return None;
    }
    let hi = Axis::map(log, y + sigma)?;
    let lo = Axis::map(log, y - sigma).unwrap_or(axis.lo);
    Some((axis.clamp(lo), axis.clamp(hi)))
}

/// Splits a curve into runs of drawable points (a point that cannot be shown breaks the curve) and
/// clips each segment to the plotting rectangle (Liang–Barsky), so curves never leave their panel.
pub(super) fn clip_polyline(
    points: &[Option<(f64, f64)>],
    x: &Axis,
    y: &Axis,
) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    for pair in points.windows(2) {
        let clipped = match (pair[0], pair[1]) {
            (Some(p), Some(q)) => clip_segment(p, q, x, y),
            _ => None,
        };
        match clipped {
            Some((a, b)) => {
                if current.last() != Some(&a) {
                    if current.len() >= 2 {
                        runs.push(std::mem::take(&mut current));
                    }
                    current.clear();
                    current.push(a);
                }
                current.push(b);
            }
            None => {
                if current.len() >= 2 {
                    runs.push(std::mem::take(&mut current));
                }
                current.clear();
            }
        }
    }
    if current.len() >= 2 {
        runs.push(current);
    }
    runs
}

/// The part of segment p→q inside the axes' rectangle (Liang & Barsky 1984), if any. An end that
/// lies inside is returned unchanged, so consecutive segments join exactly.
fn clip_segment(
    p: (f64, f64),
    q: (f64, f64),
    x: &Axis,
    y: &Axis,
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let mut t0: f64 = 0.0;
    let mut t1: f64 = 1.0;
    for (pk, qk) in [
        (-dx, p.0 - x.lo),
        (dx, x.hi - p.0),
        (-dy, p.1 - y.lo),
        (dy, y.hi - p.1),
    ] {
        if pk == 0.0 {
            if qk < 0.0 {
                return None;
            }
        } else {
            let t = qk / pk;
            if pk < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    let at = |t: f64| (p.0 + t * dx, p.1 + t * dy);
    let a = if t0 == 0.0 { p } else { at(t0) };
    let b = if t1 == 1.0 { q } else { at(t1) };
    Some((a, b))
}
