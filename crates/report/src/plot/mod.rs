//! Figures for fit reports, shaped like Choi, Lee & Chin 2014: Figure 4 ("Fitting results": per RGB
//! channel the measured radial profile Rd(r) and the fitted curve, log scale) and Figure 6 (per
//! channel the sampled data, the existing method's curve and the proposed method's curve).
//!
//! A [`Figure`] is a row of [`Panel`]s (1×3 for RGB) that share their axes, so channels compare at a
//! glance. Each panel holds [`Series`]: measured rings (filled markers with one-sigma error bars),
//! excluded rings (hollow grey markers: inside the spot, below detection) and model curves (solid
//! or dashed). [`write_figure`] renders SVG and/or PNG with `plotters` into memory and writes each
//! file atomically; [`render_svg`] and [`render_png`] give the bytes without writing.
//!
//! The module by concept: the figure's data (this file); `axis` (plot-space axes, decade and
//! linear ticks, the figure's shared ranges); `series` (how each [`SeriesStyle`] is drawn,
//! clipping, legend samples); `layout` (title strip, panel headers with wrapped notes, the chart
//! frame and legend); `palette` (the neutral colours layout and series share); `backend` (SVG and
//! PNG backends, the embedded font, the PNG's text through `scatterfit_imaging::text`).
//!
//! Text: `plotters` runs without font-kit (no FreeType or fontconfig, which a fresh machine may lack);
//! the DejaVu Sans embedded in `scatterfit_imaging::text` is registered with plotters' `ab_glyph`
//! font table as `sans-serif`, so the SVG's text metrics match, and the PNG's glyphs are drawn by
//! that module's rasteriser.
//!
//! Log axes are drawn in log10 space with our own decade ticks (labels `10⁻⁴ … 10⁰`); values that
//! cannot be shown (non-finite, or ≤ 0 on a log axis) are skipped, and curves are clipped to the
//! plotting area by hand (plotters does not clip paths).

use std::path::Path;

use crate::error::{ReportError, Result};

mod axis;
mod backend;
mod layout;
mod palette;
mod series;
#[cfg(test)]
mod tests;

pub use backend::{render_png, render_svg};

/// One curve or point set drawn in a channel's panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text, e.g. "measured", "dipole fit (proposed)".
    pub label: String,
    /// (r \[mm\], value) pairs. Non-finite points, and points ≤ 0 on a log axis, are skipped.
    pub points: Vec<(f64, f64)>,
    /// One-sigma error per point (error bars), same length as `points`; only drawn for
    /// [`SeriesStyle::Measured`].
    pub errors: Option<Vec<f64>>,
    /// How the series is drawn.
    pub style: SeriesStyle,
    /// A colour of its own (else the panel's), e.g. to tell several curves of one panel apart.
    pub colour: Option<(u8, u8, u8)>,
}

/// How a [`Series`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesStyle {
    /// Measured rings: filled markers in the panel's colour, with error bars.
    Measured,
    /// Rings not fitted (inside the spot, below detection): hollow grey markers.
    Excluded,
    /// A model curve: solid line in the panel's colour.
    Line,
    /// A second model curve: dashed line in the panel's colour.
    DashedLine,
}

/// One channel's panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Panel title, e.g. "red".
    pub title: String,
    /// The channel's colour, used for its lines and markers (sRGB).
    pub colour: (u8, u8, u8),
    /// What the panel shows, drawn in order (later series on top).
    pub series: Vec<Series>,
    /// A line of text under the title, e.g. the fitted parameters; wrapped at ", " when too wide.
    pub note: Option<String>,
}

/// A row of panels sharing their axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Figure title, across the top.
    pub title: String,
    /// x axis label, e.g. "r \[mm\]".
    pub x_label: String,
    /// y axis label, e.g. "Rd(r) \[mm⁻²\]".
    pub y_label: String,
    /// The panels, side by side.
    pub panels: Vec<Panel>,
    /// Logarithmic y axis (decades spanning the data).
    pub log_y: bool,
    /// Logarithmic x axis.
    pub log_x: bool,
}

/// Writes the figure as SVG and/or PNG (either path may be `None`). Both are rendered in memory
/// first, then each file is written atomically (`scatterfit_io::atomic::write_atomic`).
///
/// # Errors
/// [`ReportError::ErrorCount`] for a series whose `errors` length differs from its `points` (nothing
/// is written), [`ReportError::Draw`] for a rendering failure, [`ReportError::WritePlot`] naming the
/// file that could not be written.
pub fn write_figure(fig: &Figure, svg: Option<&Path>, png: Option<&Path>) -> Result<()> {
    let svg_text = svg.map(|_| render_svg(fig)).transpose()?;
    let png_bytes = png.map(|_| render_png(fig)).transpose()?;
    let write = |path: &Path, bytes: &[u8]| {
        scatterfit_io::atomic::write_atomic(path, bytes).map_err(|source| ReportError::WritePlot {
            path: path.to_path_buf(),
            source,
        })
    };
    if let (Some(path), Some(text)) = (svg, svg_text) {
        write(path, text.as_bytes())?;
    }
    if let (Some(path), Some(bytes)) = (png, png_bytes) {
        write(path, &bytes)?;
    }
    Ok(())
}

/// Width of one panel \[px\].
const PANEL_WIDTH: u32 = 500;
/// Height of the figure \[px\].
const FIGURE_HEIGHT: u32 = 520;

/// Figure size \[px\]: one panel width per panel (at least one).
pub(crate) fn figure_size(fig: &Figure) -> (u32, u32) {
    let n = u32::try_from(fig.panels.len().max(1)).unwrap_or(u32::MAX / PANEL_WIDTH);
    (PANEL_WIDTH.saturating_mul(n), FIGURE_HEIGHT)
}
