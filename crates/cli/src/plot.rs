//! Figures for fit reports, shaped like Choi, Lee & Chin 2014: Figure 4 ("Fitting results": per RGB
//! channel the measured radial profile Rd(r) and the fitted curve, log scale) and Figure 6 (per
//! channel the sampled data, the existing method's curve and the proposed method's curve).
//!
//! A [`Figure`] is a row of [`Panel`]s (1×3 for RGB) that share their axes, so channels compare at a
//! glance. Each panel holds [`Series`]: measured rings (filled markers with one-sigma error bars),
//! excluded rings (hollow grey markers: inside the spot, below detection) and model curves (solid
//! or dashed). [`write_figure`] renders SVG and/or PNG with `plotters` into memory and writes each
//! file atomically.
//!
//! Text: `plotters` runs without font-kit (no FreeType or fontconfig, which a fresh machine may lack);
//! DejaVu Sans is compiled into the binary and registered with plotters' `ab_glyph` font table as
//! `sans-serif`, so the PNG always shows its labels and the SVG's text metrics match.
//!
//! Log axes are drawn in log10 space with our own decade ticks (labels `10⁻⁴ … 10⁰`); values that
//! cannot be shown (non-finite, or ≤ 0 on a log axis) are skipped, and curves are clipped to the
//! plotting area by hand (plotters does not clip paths).

use std::path::Path;
use std::sync::OnceLock;

use anyhow::{Context, Result, anyhow, bail, ensure};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// One curve or point set drawn in a channel's panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text, e.g. "measured", "dipole fit (proposed)".
    pub label: String,
    /// (r [mm], value) pairs. Non-finite points, and points ≤ 0 on a log axis, are skipped.
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
    /// x axis label, e.g. "r [mm]".
    pub x_label: String,
    /// y axis label, e.g. "Rd(r) [mm⁻²]".
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
/// A series whose `errors` length differs from its `points`, a rendering failure, or an I/O error
/// naming the file.
pub fn write_figure(fig: &Figure, svg: Option<&Path>, png: Option<&Path>) -> Result<()> {
    let svg_text = svg.map(|_| render_svg(fig)).transpose()?;
    let png_bytes = png.map(|_| render_png(fig)).transpose()?;
    if let (Some(path), Some(text)) = (svg, svg_text) {
        scatterfit_io::atomic::write_atomic(path, text.as_bytes())
            .with_context(|| format!("writing the plot {}", path.display()))?;
    }
    if let (Some(path), Some(bytes)) = (png, png_bytes) {
        scatterfit_io::atomic::write_atomic(path, &bytes)
            .with_context(|| format!("writing the plot {}", path.display()))?;
    }
    Ok(())
}

/// Width of one panel [px].
const PANEL_WIDTH: u32 = 500;
/// Height of the figure [px].
const FIGURE_HEIGHT: u32 = 520;
/// Height of the figure title strip [px].
const TITLE_HEIGHT: u32 = 40;
/// Font family under which the embedded font is registered.
const FONT: &str = "sans-serif";
/// DejaVu Sans (Bitstream Vera licence, assets/DejaVuSans-LICENSE.txt).
static DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

const TITLE_SIZE: f64 = 22.0;
const PANEL_TITLE_SIZE: f64 = 18.0;
const NOTE_SIZE: f64 = 14.0;
const AXIS_DESC_SIZE: f64 = 16.0;
const TICK_SIZE: f64 = 14.0;
const LEGEND_SIZE: f64 = 14.0;
const NOTE_LINE_HEIGHT: u32 = 18;
/// At most this many note lines per panel (the rest is cut with "…").
const NOTE_MAX_LINES: usize = 3;
/// At most this many decades on a log axis: wider data keep the top decades.
const MAX_DECADES: f64 = 24.0;

const INK: RGBColor = RGBColor(20, 20, 20);
const GREY: RGBColor = RGBColor(140, 140, 140);

/// Figure size [px]: one panel width per panel (at least one).
pub(crate) fn figure_size(fig: &Figure) -> (u32, u32) {
    let n = u32::try_from(fig.panels.len().max(1)).unwrap_or(u32::MAX / PANEL_WIDTH);
    (PANEL_WIDTH.saturating_mul(n), FIGURE_HEIGHT)
}

/// The figure as SVG text.
pub(crate) fn render_svg(fig: &Figure) -> Result<String> {
    register_font()?;
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, figure_size(fig)).into_drawing_area();
        draw_figure(&root, fig)?;
        root.present()
            .map_err(|e| anyhow!("rendering the SVG plot: {e}"))?;
    }
    // plotters escapes `<`, `>`, `&` and quotes but not the control characters XML forbids, which
    // a sample's name may hold: the document must stay well-formed for any name.
    Ok(scatterfit_io::escape::xml_chars(&text).into_owned())
}

/// The figure as PNG bytes (8-bit RGB).
pub(crate) fn render_png(fig: &Figure) -> Result<Vec<u8>> {
    register_font()?;
    let (width, height) = figure_size(fig);
    let mut pixels = vec![0u8; width as usize * height as usize * 3];
    {
        let root = glyph_text::GlyphTextBackend::new(BitMapBackend::with_buffer(
            &mut pixels,
            (width, height),
        ))?
        .into_drawing_area();
        draw_figure(&root, fig)?;
        root.present()
            .map_err(|e| anyhow!("rendering the PNG plot: {e}"))?;
    }
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &pixels,
        width,
        height,
        image::ExtendedColorType::Rgb8,
    )
    .context("encoding the plot as PNG")?;
    Ok(bytes)
}

/// The PNG backend's text renderer (a module of its own: plotters' `Color` and the backend's
/// `BackendStyle` traits both name `stroke_width`).
mod glyph_text {
    use anyhow::{Result, anyhow};
    use plotters::prelude::{BitMapBackend, DrawingBackend};
    use plotters::style::text_anchor::{HPos, VPos};
    use plotters_backend::{
        BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingErrorKind,
    };

    use super::DEJAVU_SANS;

    /// A bitmap backend whose text is rasterised here with `ab_glyph`, glyph by glyph at its pen
    /// position, side bearing and kerning. plotters 0.3.7's `ab_glyph` text drops each glyph's left side
    /// bearing, so letters crowd unevenly ("excluded" reads "exduded" at 14 px). Layout (text extents,
    /// hence label and legend placement) stays plotters' own, which measures advances correctly.
    pub(super) struct GlyphTextBackend<'a> {
        inner: BitMapBackend<'a>,
        font: ab_glyph::FontRef<'static>,
    }

    impl<'a> GlyphTextBackend<'a> {
        pub(super) fn new(inner: BitMapBackend<'a>) -> Result<Self> {
            let font = ab_glyph::FontRef::try_from_slice(DEJAVU_SANS).map_err(|e| {
                anyhow!("the embedded plot font (DejaVu Sans) could not be loaded: {e}")
            })?;
            Ok(Self { inner, font })
        }
    }

    impl<'a> DrawingBackend for GlyphTextBackend<'a> {
        type ErrorType = <BitMapBackend<'a> as DrawingBackend>::ErrorType;

        fn get_size(&self) -> (u32, u32) {
            self.inner.get_size()
        }
        fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
            self.inner.ensure_prepared()
        }
        fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
            self.inner.present()
        }
        fn draw_pixel(
            &mut self,
            point: BackendCoord,
            color: BackendColor,
        ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
            self.inner.draw_pixel(point, color)
        }
        fn draw_line<S: BackendStyle>(
            &mut self,
            from: BackendCoord,
            to: BackendCoord,
            style: &S,
        ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
            self.inner.draw_line(from, to, style)
        }
        fn draw_rect<S: BackendStyle>(
            &mut self,
            upper_left: BackendCoord,
            bottom_right: BackendCoord,
            style: &S,
            fill: bool,
        ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
            self.inner.draw_rect(upper_left, bottom_right, style, fill)
        }
        fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
            &mut self,
            path: I,
            style: &S,
        ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
            self.inner.draw_path(path, style)
        }
        fn draw_circle<S: BackendStyle>(
            &mut self,
            center: BackendCoord,
            radius: u32,
            style: &S,
            fill: bool,
        ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
            self.inner.draw_circle(center, radius, style, fill)
        }
        fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
            &mut self,
            vert: I,
            style: &S,
        ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
            self.inner.fill_polygon(vert, style)
        }
        fn blit_bitmap(
            &mut self,
            pos: BackendCoord,
            size: (u32, u32),
            src: &[u8],
        ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
            self.inner.blit_bitmap(pos, size, src)
        }

        /// Text in the box plotters laid out (anchor and rotation as plotters' default `draw_text`),
        /// with capital letters centred vertically in it.
        fn draw_text<S: BackendTextStyle>(
            &mut self,
            text: &str,
            style: &S,
            pos: BackendCoord,
        ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
            use ab_glyph::{Font, ScaleFont};

            let colour = style.color();
            if colour.alpha == 0.0 {
                return Ok(());
            }
            let ((min_x, min_y), (max_x, max_y)) = style
                .layout_box(text)
                .map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
            let (width, height) = (max_x - min_x, max_y - min_y);
            let dx = match style.anchor().h_pos {
                HPos::Left => 0,
                HPos::Right => -width,
                HPos::Center => -width / 2,
            };
            let dy = match style.anchor().v_pos {
                VPos::Top => 0,
                VPos::Center => -height / 2,
                VPos::Bottom => -height,
            };
            let transform = style.transform();
            let font = self.font.clone();
            let scaled = font.as_scaled(style.size() as f32);
            let cap_height = scaled
                .outline_glyph(scaled.scaled_glyph('H'))
                .map_or(0.63 * scaled.height(), |g| -g.px_bounds().min.y);
            let baseline = (height as f32 + cap_height) / 2.0;
            let mut coverage: Vec<(i32, i32, f32)> = Vec::new();
            let mut pen = 0.0f32;
            let mut previous = None;
            for c in text.chars() {
                let id = scaled.glyph_id(c);
                if let Some(p) = previous {
                    pen += scaled.kern(p, id);
                }
                let glyph =
                    id.with_scale_and_position(scaled.scale(), ab_glyph::point(pen, baseline));
                if let Some(outline) = font.outline_glyph(glyph) {
                    let bounds = outline.px_bounds();
                    let (x0, y0) = (bounds.min.x as i32, bounds.min.y as i32);
                    outline.draw(|x, y, c| coverage.push((x0 + x as i32, y0 + y as i32, c)));
                }
                pen += scaled.h_advance(id);
                previous = Some(id);
            }
            for (x, y, c) in coverage {
                let (x, y) = transform.transform(x + dx - min_x, y + dy - min_y);
                let alpha = colour.alpha * f64::from(c.clamp(0.0, 1.0));
                self.inner.draw_pixel(
                    (pos.0 + x, pos.1 + y),
                    BackendColor {
                        alpha,
                        rgb: colour.rgb,
                    },
                )?;
            }
            Ok(())
        }
    }
}

/// Registers the embedded font with plotters once per process.
fn register_font() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, DEJAVU_SANS).is_ok()
    });
    ensure!(
        ok,
        "the embedded plot font (DejaVu Sans) could not be loaded"
    );
    Ok(())
}

/// One axis in plot space: log10 of the value on a log axis, the value itself otherwise.
#[derive(Debug, Clone, PartialEq)]
struct Axis {
    log: bool,
    /// Plot-space range.
    lo: f64,
    hi: f64,
    /// Distance between ticks on a linear axis.
    step: f64,
    /// Labelled ticks (plot space).
    ticks: Vec<f64>,
    /// Minor grid lines (plot space).
    minor: Vec<f64>,
}

impl Axis {
    /// The plot-space coordinate of `v`, if it can be shown on this kind of axis.
    fn map(log: bool, v: f64) -> Option<f64> {
        if !v.is_finite() {
            None
        } else if log {
            (v > 0.0).then(|| v.log10())
        } else {
            Some(v)
        }
    }

    fn contains(&self, p: f64) -> bool {
        p >= self.lo && p <= self.hi
    }

    fn clamp(&self, p: f64) -> f64 {
        p.clamp(self.lo, self.hi)
    }

    /// A log axis showing the data's plot-space extent [lo, hi] (log10 values) with a margin of 4 %
    /// of the span (at least 0.05 decade) either side, so no marker sits on the frame. An end within
    /// 0.35 decade of a whole decade is moved out to it; data inside less than about a decade get
    /// the whole decades around them, so the axis always carries at least two decade ticks. At most
    /// `MAX_DECADES` are shown (the top ones).
    fn log(lo: f64, hi: f64) -> Self {
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
    fn linear(min: f64, max: f64) -> Self {
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
    fn label(&self, p: f64) -> String {
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

fn is_marker(style: SeriesStyle) -> bool {
    matches!(style, SeriesStyle::Measured | SeriesStyle::Excluded)
}

/// The shared axes of a figure: x from 0 (log: over the data's decades) to just past the largest
/// radius; y over the marker data (values and upper error bars), widened by at most one
/// decade (log) for model curves reaching beyond; the curves alone when there are no markers.
fn figure_axes(fig: &Figure) -> (Axis, Axis) {
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
            .map_err(|e| anyhow!("measuring plot text: {e}"))?;
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

fn draw_figure<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, fig: &Figure) -> Result<()>
where
    DB::ErrorType: 'static,
{
    for (i, panel) in fig.panels.iter().enumerate() {
        for series in &panel.series {
            if let Some(errors) = &series.errors
                && errors.len() != series.points.len()
            {
                bail!(
                    "plot panel {} (\"{}\"), series \"{}\": {} error values for {} points; give one \
                     error per point or none",
                    i + 1,
                    panel.title,
                    series.label,
                    errors.len(),
                    series.points.len()
                );
            }
        }
    }
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("drawing the plot: {e}");
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
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("drawing the plot: {e}");
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
    let mut labelled = false;
    for series in &panel.series {
        let (r, g, b) = series.colour.unwrap_or(panel.colour);
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
        let anno = match series.style {
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
            continue;
        }
        labelled = true;
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
    }
    if labelled {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
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
fn clip_polyline(points: &[Option<(f64, f64)>], x: &Axis, y: &Axis) -> Vec<Vec<(f64, f64)>> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::ops::Range;

    const RED: (u8, u8, u8) = (200, 30, 30);
    const GREEN: (u8, u8, u8) = (30, 150, 40);
    const BLUE: (u8, u8, u8) = (30, 60, 210);

    /// Deterministic standard normal deviates (SplitMix64 + Box–Muller), so the tests need no RNG crate.
    struct Normal(u64);
    impl Normal {
        fn uniform(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }
        fn sample(&mut self) -> f64 {
            let (u, v) = (self.uniform(), self.uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    fn series(label: &str, points: Vec<(f64, f64)>, style: SeriesStyle) -> Series {
        Series {
            label: label.into(),
            points,
            errors: None,
            style,
            colour: None,
        }
    }

    /// A synthetic three-panel figure: exponential profiles with error bars, excluded rings and a curve.
    fn synthetic() -> Figure {
        let panel = |title: &str, colour, k: f64| {
            let r: Vec<f64> = (0..60).map(|i| 0.1 + 0.25 * f64::from(i)).collect();
            let measured: Vec<(f64, f64)> = r
                .iter()
                .filter(|&&r| r >= 1.0)
                .map(|&r| (r, (-k * r).exp()))
                .collect();
            Panel {
                title: title.into(),
                colour,
                series: vec![
                    series(
                        "excluded",
                        r.iter()
                            .filter(|&&r| r < 1.0)
                            .map(|&r| (r, (-k * r).exp()))
                            .collect(),
                        SeriesStyle::Excluded,
                    ),
                    Series {
                        errors: Some(measured.iter().map(|p| 0.05 * p.1).collect()),
                        ..series("measured", measured, SeriesStyle::Measured)
                    },
                    series(
                        "fit",
                        r.iter().map(|&r| (r, (-k * r).exp())).collect(),
                        SeriesStyle::Line,
                    ),
                ],
                // Long enough to wrap onto a second line.
                note: Some(format!(
                    "k = {k} mm⁻¹, σ′s = 1.98 ± 0.01 mm⁻¹, σa = 0.00079 ± 0.00002 mm⁻¹, α′ = 0.9996, \
                     MSE 0.8"
                )),
            }
        };
        Figure {
            title: "Synthetic profile".into(),
            x_label: "r [mm]".into(),
            y_label: "Rd(r) [mm⁻²]".into(),
            panels: vec![
                panel("red", RED, 0.5),
                panel("green", GREEN, 0.8),
                panel("blue", BLUE, 1.1),
            ],
            log_y: true,
            log_x: false,
        }
    }

    fn decode(bytes: &[u8]) -> image::RgbImage {
        image::load_from_memory_with_format(bytes, image::ImageFormat::Png)
            .expect("the PNG decodes")
            .to_rgb8()
    }

    /// Dark (text-coloured) pixels in a rectangle; the background is white and the grid light grey.
    fn ink(img: &image::RgbImage, x: Range<u32>, y: Range<u32>) -> usize {
        y.flat_map(|j| x.clone().map(move |i| (i, j)))
            .filter(|&(i, j)| img.get_pixel(i, j).0.iter().all(|&c| c < 110))
            .count()
    }

    #[test]
    fn writes_svg_and_png_with_visible_text() {
        let dir = tempfile::tempdir().unwrap();
        let out = examples_dir(&dir);
        let (svg, png) = (out.join("synthetic.svg"), out.join("synthetic.png"));
        write_figure(&synthetic(), Some(&svg), Some(&png)).unwrap();

        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.len() > 10_000, "SVG only {} bytes", text.len());
        for needle in [
            "Synthetic profile",
            "r [mm]",
            "Rd(r) [mm⁻²]",
            "σ′s = 1.98 ± 0.01 mm⁻¹",
        ] {
            assert!(text.contains(needle), "SVG lacks {needle:?}");
        }
        assert!(text.contains("10⁻"), "SVG lacks decade tick labels");

        let bytes = std::fs::read(&png).unwrap();
        assert!(bytes.len() > 10_000, "PNG only {} bytes", bytes.len());
        let img = decode(&bytes);
        assert_eq!(img.dimensions(), (1500, 520));
        // Title strip (centred), x-axis description (bottom of each panel) and the rotated y-axis
        // description (left edge of the first panel) all carry glyph pixels. Nothing else is drawn in
        // these places: no data, grid lines are light grey.
        assert!(ink(&img, 600..900, 0..TITLE_HEIGHT) > 150, "no title text");
        assert!(ink(&img, 250..330, 495..520) > 40, "no x-axis label text");
        assert!(ink(&img, 0..24, 200..400) > 60, "no y-axis label text");
    }

    #[test]
    fn text_detector_sees_an_empty_title_as_empty() {
        // The ink test above must be able to fail: with no title, the title strip has no dark pixels.
        let fig = Figure {
            title: String::new(),
            ..synthetic()
        };
        let img = decode(&render_png(&fig).unwrap());
        assert_eq!(ink(&img, 0..1500, 0..TITLE_HEIGHT), 0);
    }

    #[test]
    fn axes_span_the_data_with_a_margin_and_decade_ticks() {
        let fig = synthetic();
        let (x, y) = figure_axes(&fig);
        // x from 0 to just past the largest radius 14.85 mm, ticks every 5 mm.
        assert_eq!(x.lo, 0.0);
        assert!(x.hi > 14.85 && x.hi < 16.0, "x to {}", x.hi);
        assert_eq!(x.ticks, [0.0, 5.0, 10.0, 15.0]);
        // y: data from exp(-1.1·14.85) = 8.0e-8 to exp(-0.05)·1.05 (upper error bar) = 0.9988.
        let (lo, hi) = (
            (-1.1f64 * 14.85).exp().log10(),
            ((-0.05f64).exp() * 1.05).log10(),
        );
        assert!(
            y.lo < lo - 0.1 && y.lo > lo - 1.0,
            "y from {} for data {lo}",
            y.lo
        );
        assert!(
            y.hi > hi + 0.1 && y.hi < hi + 1.0,
            "y to {} for data {hi}",
            y.hi
        );
        assert_eq!(y.ticks, [-7.0, -6.0, -5.0, -4.0, -3.0, -2.0, -1.0, 0.0]);
        assert_eq!(y.label(-4.0), "10⁻⁴");
        assert_eq!(y.label(0.0), "10⁰");
        // A single value gets the decades around it; 30 decades keep the top 24, labelled every 3rd.
        let one = Axis::log(-2.0, -2.0);
        assert_eq!(
            (one.lo, one.hi, one.ticks.clone()),
            (-3.0, -1.0, vec![-3.0, -2.0, -1.0])
        );
        let wide = Axis::log(-300.0, 300.0);
        assert!(
            wide.hi >= 300.0 && wide.hi - wide.lo <= MAX_DECADES,
            "{}..{}",
            wide.lo,
            wide.hi
        );
        assert!(
            wide.ticks.len() <= 10 && wide.ticks.contains(&300.0),
            "{:?}",
            wide.ticks
        );
    }

    #[test]
    fn curves_extend_the_log_range_by_at_most_one_decade() {
        let fig = Figure {
            panels: vec![Panel {
                title: "r".into(),
                colour: RED,
                series: vec![
                    series("m", vec![(1.0, 1e-2), (2.0, 1e-3)], SeriesStyle::Measured),
                    series("f", vec![(0.0, 1e3), (5.0, 1e-12)], SeriesStyle::Line),
                ],
                note: None,
            }],
            ..synthetic()
        };
        // Markers span 10⁻³…10⁻², the curve 10⁻¹²…10³: the axis reaches one decade further each
        // way (10⁻⁴…10⁻¹) plus its margin, not the curve's 15 decades.
        let (_, y) = figure_axes(&fig);
        assert!(y.lo < -4.0 && y.lo > -4.5, "y from {}", y.lo);
        assert!(y.hi > -1.0 && y.hi < -0.5, "y to {}", y.hi);
    }

    #[test]
    fn clipping_keeps_curves_inside_and_joins_inner_segments() {
        let frame = |log, lo, hi| Axis {
            log,
            lo,
            hi,
            step: 1.0,
            ticks: Vec::new(),
            minor: Vec::new(),
        };
        let (x, y) = (frame(false, 0.0, 10.0), frame(true, -3.0, 0.0));
        let pts = [
            Some((0.0, 1.0)),
            Some((2.0, -1.0)),
            Some((4.0, -2.0)),
            None,
            Some((6.0, -2.0)),
            Some((8.0, -5.0)),
        ];
        let runs = clip_polyline(&pts, &x, &y);
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0], vec![(1.0, 0.0), (2.0, -1.0), (4.0, -2.0)]);
        assert_eq!(runs[1], vec![(6.0, -2.0), (6.0 + 2.0 / 3.0, -3.0)]);
    }

    /// Where a test writes figures: `$SCATTERFIT_PLOT_EXAMPLES` when set (to look at them), else `dir`.
    fn examples_dir(dir: &tempfile::TempDir) -> std::path::PathBuf {
        std::env::var_os("SCATTERFIT_PLOT_EXAMPLES")
            .map_or_else(|| dir.path().to_path_buf(), std::path::PathBuf::from)
    }

    #[test]
    fn edge_cases_render_without_panicking() {
        let dir = tempfile::tempdir().unwrap();
        let out = examples_dir(&dir);
        let nan = f64::NAN;
        let twelve_decades: Vec<(f64, f64)> =
            (0..=12).map(|i| (f64::from(i), 10f64.powi(-i))).collect();
        let cases: Vec<(&str, Vec<Series>)> = vec![
            ("empty", vec![series("m", vec![], SeriesStyle::Measured)]),
            ("no series", vec![]),
            (
                "all excluded",
                vec![series(
                    "x",
                    vec![(0.1, 1.0), (0.2, 0.5)],
                    SeriesStyle::Excluded,
                )],
            ),
            (
                "single point",
                vec![series("m", vec![(3.0, 0.01)], SeriesStyle::Measured)],
            ),
            (
                "point at 1",
                vec![series("m", vec![(0.0, 1.0)], SeriesStyle::Measured)],
            ),
            (
                "NaN",
                vec![
                    Series {
                        errors: Some(vec![nan, 0.1, f64::INFINITY]),
                        ..series(
                            "m",
                            vec![(nan, 1.0), (1.0, nan), (2.0, 0.3)],
                            SeriesStyle::Measured,
                        )
                    },
                    series(
                        "f",
                        vec![(0.0, nan), (1.0, 0.5), (2.0, nan), (3.0, 0.1)],
                        SeriesStyle::Line,
                    ),
                ],
            ),
            (
                "12 decades",
                vec![
                    series("m", twelve_decades.clone(), SeriesStyle::Measured),
                    series("f", twelve_decades, SeriesStyle::DashedLine),
                ],
            ),
            (
                "non-positive",
                vec![
                    Series {
                        errors: Some(vec![1.0, 1.0, 5.0]),
                        ..series(
                            "m",
                            vec![(1.0, 0.0), (2.0, -1.0), (3.0, 2.0)],
                            SeriesStyle::Measured,
                        )
                    },
                    series("f", vec![(0.0, -1.0), (1.0, 0.0)], SeriesStyle::Line),
                ],
            ),
            (
                "huge span",
                vec![series(
                    "m",
                    vec![(1.0, 1e-300), (2.0, 1e300)],
                    SeriesStyle::Measured,
                )],
            ),
        ];
        for (name, list) in cases {
            for (log_x, log_y) in [(false, true), (true, true), (false, false)] {
                let fig = Figure {
                    title: name.into(),
                    panels: vec![Panel {
                        title: name.into(),
                        colour: GREEN,
                        series: list.clone(),
                        note: None,
                    }],
                    log_x,
                    log_y,
                    ..synthetic()
                };
                let stem = format!("edge-{}-{log_x}-{log_y}", name.replace(' ', "_"));
                let (svg, png) = (
                    out.join(format!("{stem}.svg")),
                    out.join(format!("{stem}.png")),
                );
                write_figure(&fig, Some(&svg), Some(&png))
                    .unwrap_or_else(|e| panic!("{name} (log x {log_x}, log y {log_y}): {e:#}"));
                assert!(decode(&std::fs::read(&png).unwrap()).width() == 500);
            }
        }
        let none = Figure {
            panels: vec![],
            ..synthetic()
        };
        write_figure(
            &none,
            Some(&dir.path().join("n.svg")),
            Some(&dir.path().join("n.png")),
        )
        .unwrap();
    }

    #[test]
    fn mismatched_errors_are_an_error_and_nothing_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let mut fig = synthetic();
        fig.panels[1].series[1].errors = Some(vec![0.1]);
        let svg = dir.path().join("bad.svg");
        let e = write_figure(&fig, Some(&svg), None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("green") && e.contains("measured") && e.contains("1 error values"),
            "{e}"
        );
        assert!(!svg.exists());
    }

    /// Figure 4 and Figure 6 of Choi et al. 2014 from dipole profiles (Jensen et al. 2001) with 1 %
    /// scatter on 0.05 mm rings out to 15 mm, rings under 1 mm excluded. Written to
    /// `$SCATTERFIT_PLOT_EXAMPLES` when set (to look at them), else to a temporary folder.
    #[test]
    fn realistic_fit_figures() {
        use scatterfit_optics::OpticalProperties;
        use scatterfit_optics::dipole::Dipole;

        let dir = tempfile::tempdir().unwrap();
        let out = examples_dir(&dir);
        let eta = 1.29;
        // (name, colour, σ′s, σa) [mm⁻¹]
        let channels = [
            ("red", RED, 1.98, 0.02),
            ("green", GREEN, 1.90, 0.05),
            ("blue", BLUE, 1.86, 0.09),
        ];
        let mut noise = Normal(7);
        let rings: Vec<f64> = (0..300).map(|i| 0.025 + 0.05 * f64::from(i)).collect();
        let curve_r: Vec<f64> = (0..=600).map(|i| 0.025 * f64::from(i)).collect();
        let mut fig4 = Vec::new();
        let mut fig6 = Vec::new();
        for (name, colour, sp, sa) in channels {
            let truth = Dipole::new(&OpticalProperties::new(sp, sa, eta).unwrap());
            let existing = Dipole::new(&OpticalProperties::new(0.8 * sp, 1.6 * sa, eta).unwrap());
            let data: Vec<(f64, f64, f64)> = rings
                .iter()
                .map(|&r| {
                    let v = truth.rd(r);
                    (r, v * (1.0 + 0.01 * noise.sample()), 0.01 * v)
                })
                .collect();
            let pick = |keep: bool| -> (Vec<(f64, f64)>, Vec<f64>) {
                data.iter()
                    .filter(|d| (d.0 >= 1.0) == keep)
                    .map(|&(r, v, e)| ((r, v), e))
                    .unzip()
            };
            let (fitted, errors) = pick(true);
            let (inside, _) = pick(false);
            let curve = |d: &Dipole| curve_r.iter().map(|&r| (r, d.rd(r))).collect::<Vec<_>>();
            let measured = Series {
                label: "measured (1σ)".into(),
                points: fitted,
                errors: Some(errors),
                style: SeriesStyle::Measured,
                colour: None,
            };
            fig4.push(Panel {
                title: name.into(),
                colour,
                series: vec![
                    series("not fitted (spot)", inside, SeriesStyle::Excluded),
                    measured.clone(),
                    series("dipole fit", curve(&truth), SeriesStyle::Line),
                ],
                note: Some(format!(
                    "σ′s = {sp:.2} ± 0.01 mm⁻¹, σa = {sa:.4} mm⁻¹, η = {eta}, MSE 0.98"
                )),
            });
            fig6.push(Panel {
                title: name.into(),
                colour,
                series: vec![
                    Series {
                        label: "sampled data".into(),
                        ..measured
                    },
                    series(
                        "existing (σ′s, σa)",
                        curve(&existing),
                        SeriesStyle::DashedLine,
                    ),
                    series("proposed (σ′s)", curve(&truth), SeriesStyle::Line),
                ],
                note: None,
            });
        }
        let figure = |title: &str, panels| Figure {
            title: title.into(),
            x_label: "r [mm]".into(),
            y_label: "Rd(r) [mm⁻²]".into(),
            panels,
            log_y: true,
            log_x: false,
        };
        let fig4 = figure(
            "pink plastic: fitting results (dipole, proposed method)",
            fig4,
        );
        let fig6 = figure(
            "pink plastic: sampled data, existing and proposed method",
            fig6,
        );
        let start = std::time::Instant::now();
        write_figure(
            &fig4,
            Some(&out.join("fig4.svg")),
            Some(&out.join("fig4.png")),
        )
        .unwrap();
        let elapsed = start.elapsed();
        write_figure(
            &fig6,
            Some(&out.join("fig6.svg")),
            Some(&out.join("fig6.png")),
        )
        .unwrap();
        crate::output::errln!("fig4 (SVG + PNG, 3 × 300 rings): {elapsed:?}");
        let img = decode(&std::fs::read(out.join("fig4.png")).unwrap());
        // Rd spans ~10⁰ down to ~10⁻⁸ at 15 mm (blue, σtr = 0.74 mm⁻¹): the axis covers it all.
        let (_, y) = figure_axes(&fig4);
        assert!(y.hi >= 0.0 && y.lo <= -7.0, "y decades {}..{}", y.lo, y.hi);
        // Each panel shows its channel colour (markers and curve).
        let count = |c: (u8, u8, u8)| img.pixels().filter(|p| p.0 == [c.0, c.1, c.2]).count();
        for c in [RED, GREEN, BLUE] {
            assert!(count(c) > 500, "colour {c:?} on {} pixels", count(c));
        }
    }
}
