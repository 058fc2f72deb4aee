//! The figure's layout: the title strip, one panel per channel side by side, each with its title
//! and note lines (wrapped at commas, every header as tall as the tallest so the plots line up),
//! the chart frame with its mesh and tick labels, the series and the legend.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axis::{Axis, figure_axes};
use super::palette::{GREY, INK};
use super::series::draw_series;
use super::{Figure, PANEL_WIDTH, Panel};
use crate::error::{ReportError, Result, draw_error};

/// Height of the figure title strip \[px\].
pub(super) const TITLE_HEIGHT: u32 = 40;
/// Font family under which the embedded font is registered.
pub(super) const FONT: &str = "sans-serif";

const TITLE_SIZE: f64 = 22.0;
const PANEL_TITLE_SIZE: f64 = 18.0;
const NOTE_SIZE: f64 = 14.0;
const AXIS_DESC_SIZE: f64 = 16.0;
const TICK_SIZE: f64 = 14.0;
const LEGEND_SIZE: f64 = 14.0;
const NOTE_LINE_HEIGHT: u32 = 18;
/// At most this many note lines per panel (the rest is cut with "…").
const NOTE_MAX_LINES: usize = 3;

fn font(size: f64) -> TextStyle<'static> {
    (FONT, size).into_font().color(&INK)
}

/// Wraps `note` at ", " / "; " boundaries so that each line fits `width` pixels.
fn wrap_note<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    note: &str,
    width: u32,
) -> Result<Vec<String>> {
    let style = font(NOTE_SIZE);
    let fits = |s: &str| -> Result<bool> {
        let (w, _) = area
            .estimate_text_size(s, &style)
            .map_err(|e| draw_error("measuring plot text", e))?;
        Ok(w <= width)
    };
    let mut chunks: Vec<String> = Vec::new();
    let mut rest = note.trim();
    while let Some(i) = rest.find([',', ';']) {
        chunks.push(rest[..=i].to_string());
        rest = rest[i + 1..].trim_start();
    }
    if !rest.is_empty() {
        chunks.push(rest.to_string());
    }
    let mut lines: Vec<String> = Vec::new();
    for chunk in chunks {
        match lines.last_mut() {
            Some(line) if fits(&format!("{line} {chunk}"))? => {
                line.push(' ');
                line.push_str(&chunk);
            }
            _ => lines.push(chunk),
        }
    }
    if lines.len() > NOTE_MAX_LINES {
        lines.truncate(NOTE_MAX_LINES);
        if let Some(last) = lines.last_mut() {
            last.push_str(" …");
        }
    }
    Ok(lines)
}

/// Draws `fig` on `root` (either backend): the series' error counts are checked before anything is
/// drawn, then the title strip and the panels side by side on shared axes.
pub(super) fn draw_figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    for (i, panel) in fig.panels.iter().enumerate() {
        for series in &panel.series {
            if let Some(errors) = &series.errors
                && errors.len() != series.points.len()
            {
                return Err(ReportError::ErrorCount {
                    panel: i + 1,
                    title: panel.title.clone(),
                    series: series.label.clone(),
                    errors: errors.len(),
                    points: series.points.len(),
                });
            }
        }
    }
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| draw_error("drawing the plot", e);
    root.fill(&WHITE).map_err(err)?;
    let (width, _) = root.dim_in_pixel();
    let (title_area, body) = root.split_vertically(TITLE_HEIGHT);
    title_area
        .draw(&Text::new(
            fig.title.clone(),
            (i32::try_from(width / 2).unwrap_or(0), 10),
            font(TITLE_SIZE).pos(Pos::new(HPos::Center, VPos::Top)),
        ))
        .map_err(err)?;

    let (x_axis, y_axis) = figure_axes(fig);
    if fig.panels.is_empty() {
        body.draw(&Text::new(
            "no panels to show",
            (i32::try_from(width / 2).unwrap_or(0), 100),
            font(NOTE_SIZE).pos(Pos::new(HPos::Center, VPos::Top)),
        ))
        .map_err(err)?;
        return Ok(());
    }
    let areas = body.split_evenly((1, fig.panels.len()));
    // Notes are wrapped per panel; every panel's header is as tall as the tallest, so the plots line up.
    let notes = fig
        .panels
        .iter()
        .map(|p| match &p.note {
            Some(n) if !n.trim().is_empty() => wrap_note(root, n, PANEL_WIDTH - 30),
            _ => Ok(Vec::new()),
        })
        .collect::<Result<Vec<_>>>()?;
    let note_lines = notes.iter().map(Vec::len).max().unwrap_or(0);
    let header = 34 + NOTE_LINE_HEIGHT * u32::try_from(note_lines).unwrap_or(0);
    for ((panel, area), note) in fig.panels.iter().zip(&areas).zip(&notes) {
        draw_panel(area, fig, panel, note, header, &x_axis, &y_axis)?;
    }
    Ok(())
}

/// One panel: its title and note lines in a header `header` px tall, then the chart with the mesh,
/// the series in order, the legend, and "no data to show" when nothing can be drawn.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
    panel: &Panel,
    note: &[String],
    header: u32,
    x_axis: &Axis,
    y_axis: &Axis,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| draw_error("drawing the plot", e);
    let (head, plot_area) = area.split_vertically(header);
    let (w, _) = head.dim_in_pixel();
    let centre = i32::try_from(w / 2).unwrap_or(0);
    head.draw(&Text::new(
        panel.title.clone(),
        (centre, 8),
        font(PANEL_TITLE_SIZE).pos(Pos::new(HPos::Center, VPos::Top)),
    ))
    .map_err(err)?;
    for (k, line) in note.iter().enumerate() {
        let y = 32 + NOTE_LINE_HEIGHT * u32::try_from(k).unwrap_or(0);
        head.draw(&Text::new(
            line.clone(),
            (centre, i32::try_from(y).unwrap_or(0)),
            font(NOTE_SIZE).pos(Pos::new(HPos::Center, VPos::Top)),
        ))
        .map_err(err)?;
    }

    let mut chart = ChartBuilder::on(&plot_area)
        .margin_left(6)
        .margin_right(18)
        .margin_top(6)
        .margin_bottom(6)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(x_axis.clone(), y_axis.clone())
        .map_err(err)?;
    let x_fmt = |v: &f64| x_axis.label(*v);
    let y_fmt = |v: &f64| y_axis.label(*v);
    chart
        .configure_mesh()
        .x_desc(fig.x_label.as_str())
        .y_desc(fig.y_label.as_str())
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(font(TICK_SIZE))
        .axis_desc_style(font(AXIS_DESC_SIZE))
        .bold_line_style(RGBColor(215, 215, 215))
        .light_line_style(RGBColor(238, 238, 238))
        .axis_style(RGBColor(90, 90, 90))
        .draw()
        .map_err(err)?;

    let x_px = f64::from(plot_area.dim_in_pixel().0.saturating_sub(96)).max(1.0);
    for series in &panel.series {
        draw_series(&mut chart, fig, panel.colour, series, x_axis, y_axis, x_px)?;
    }
    let labelled = panel.series.iter().any(|s| !s.label.is_empty());
    if labelled {
        let (pw, ph) = chart.plotting_area().dim_in_pixel();
        let legend = LegendBox::estimate(panel, (pw, ph));
        chart
            .configure_series_labels()
            .position(legend_corner(fig, panel, x_axis, y_axis, legend))
            .margin(8)
            .legend_area_size(26)
            .label_font(font(LEGEND_SIZE))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(190, 190, 190))
            .draw()
            .map_err(err)?;
    }
    if panel.series.iter().all(|s| {
        s.points
            .iter()
            .all(|&(x, y)| Axis::map(fig.log_x, x).is_none() || Axis::map(fig.log_y, y).is_none())
    }) {
        let (pw, ph) = plot_area.dim_in_pixel();
        plot_area
            .draw(&Text::new(
                "no data to show",
                (
                    i32::try_from(pw / 2).unwrap_or(0) + 30,
                    i32::try_from(ph / 2).unwrap_or(0),
                ),
                font(NOTE_SIZE)
                    .color(&GREY)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
            ))
            .map_err(err)?;
    }
    Ok(())
}

/// The legend's size as a fraction of the plotting area's width and height: a sample line and the
/// longest label at [`LEGEND_SIZE`] (about 0.42 of the size a character, as plotters draws the
/// embedded font), one 18 px row per labelled series, plus the margins (measured on the SVG: 240 ×
/// 62 px for three rows with a 34-character label).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct LegendBox {
    pub(super) width: f64,
    pub(super) height: f64,
}

impl LegendBox {
    fn estimate(panel: &Panel, (pw, ph): (u32, u32)) -> Self {
        let labels = panel.series.iter().filter(|s| !s.label.is_empty());
        let rows = labels.clone().count() as f64;
        let longest = labels.map(|s| s.label.chars().count()).max().unwrap_or(0) as f64;
        Self {
            width: (42.0 + 0.42 * LEGEND_SIZE * longest) / f64::from(pw.max(1)),
            height: (8.0 + 18.0 * rows) / f64::from(ph.max(1)),
        }
    }
}

/// The corner of the plotting area where the legend hides the fewest data: each series is sampled
/// along its points and the straight segments between them (20 samples a segment) in the axes'
/// plot space, and the corner whose legend box holds the fewest samples wins; ties go to the upper
/// right, then the upper left, lower right and lower left. So a rising curve (a camera response)
/// keeps its end visible, and the falling profiles of Figure 4 keep their legend upper right.
pub(super) fn legend_corner(
    fig: &Figure,
    panel: &Panel,
    x_axis: &Axis,
    y_axis: &Axis,
    legend: LegendBox,
) -> SeriesLabelPosition {
    let unit = |axis: &Axis, log: bool, v: f64| {
        Axis::map(log, v).map(|p| (p - axis.lo) / (axis.hi - axis.lo))
    };
    let mut samples: Vec<(f64, f64)> = Vec::new();
    for series in &panel.series {
        let points: Vec<(f64, f64)> = series
            .points
            .iter()
            .filter_map(|&(x, y)| Some((unit(x_axis, fig.log_x, x)?, unit(y_axis, fig.log_y, y)?)))
            .collect();
        samples.extend(points.first());
        for pair in points.windows(2) {
            let ((x0, y0), (x1, y1)) = (pair[0], pair[1]);
            samples.extend((1..=20).map(|k| {
                let t = f64::from(k) / 20.0;
                (x0 + t * (x1 - x0), y0 + t * (y1 - y0))
            }));
        }
    }
    // Unit square, y up; each corner's box with a margin of a legend row around it.
    let (w, h) = (legend.width + 0.02, legend.height + 0.03);
    let corners = [
        (
            SeriesLabelPosition::UpperRight,
            (1.0 - w, 1.0),
            (1.0 - h, 1.0),
        ),
        (SeriesLabelPosition::UpperLeft, (0.0, w), (1.0 - h, 1.0)),
        (SeriesLabelPosition::LowerRight, (1.0 - w, 1.0), (0.0, h)),
        (SeriesLabelPosition::LowerLeft, (0.0, w), (0.0, h)),
    ];
    let hidden = |(x0, x1): (f64, f64), (y0, y1): (f64, f64)| {
        samples
            .iter()
            .filter(|&&(x, y)| (x0..=x1).contains(&x) && (y0..=y1).contains(&y))
            .count()
    };
    let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
    for (corner, xs, ys) in corners {
        let n = hidden(xs, ys);
        if n < best.0 {
            best = (n, corner);
        }
    }
    best.1
}
