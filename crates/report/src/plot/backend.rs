//! The backends: SVG text through plotters' SVG backend, PNG pixels through its bitmap backend with
//! our text rasteriser, and the embedded font both use.
//!
//! Text: `plotters` runs without font-kit (no FreeType or fontconfig, which a fresh machine may
//! lack). The DejaVu Sans embedded in `scatterfit_imaging::text` is registered with plotters'
//! `ab_glyph` font table as `sans-serif`, so plotters measures text (label and legend placement)
//! with the font the PNG shows and the SVG names. The PNG's glyphs are drawn by
//! [`GlyphTextBackend`], because plotters 0.3.7's own `ab_glyph` text drops each glyph's left side
//! bearing.

use std::sync::OnceLock;

use plotters::prelude::{BitMapBackend, DrawingBackend, IntoDrawingArea, SVGBackend};
use plotters::style::FontStyle;
use plotters::style::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingErrorKind,
};
use scatterfit_imaging::text::{DEJAVU_SANS, Font, FontError};

use super::layout::{FONT, draw_figure};
use super::{Figure, figure_size};
use crate::error::{self, ReportError, draw_error};

/// The most characters of one label drawn into a plot (longer ones end in `…`).
const MAX_DRAWN_CHARS: usize = 200;

/// The figure as SVG text.
///
/// # Errors
/// [`ReportError::ErrorCount`] for mismatched error bars, [`ReportError::Draw`] if plotters fails.
pub fn render_svg(fig: &Figure) -> error::Result<String> {
    register_font()?;
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, figure_size(fig)).into_drawing_area();
        draw_figure(&root, fig)?;
        root.present()
            .map_err(|e| draw_error("rendering the SVG plot", e))?;
    }
    // plotters escapes `<`, `>`, `&` and quotes but not the control characters XML forbids, which
    // a sample's name may hold: the document must stay well-formed for any name.
    Ok(scatterfit_io::escape::xml_chars(&text).into_owned())
}

/// The figure as PNG bytes (8-bit RGB).
///
/// # Errors
/// [`ReportError::ErrorCount`] for mismatched error bars, [`ReportError::Draw`] if plotters fails,
/// [`ReportError::EncodePng`] if the encoder does.
pub fn render_png(fig: &Figure) -> error::Result<Vec<u8>> {
    register_font()?;
    let (width, height) = figure_size(fig);
    let mut pixels = vec![0u8; width as usize * height as usize * 3];
    {
        let root = GlyphTextBackend::new(BitMapBackend::with_buffer(&mut pixels, (width, height)))?
            .into_drawing_area();
        draw_figure(&root, fig)?;
        root.present()
            .map_err(|e| draw_error("rendering the PNG plot", e))?;
    }
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &pixels,
        width,
        height,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(ReportError::EncodePng)?;
    Ok(bytes)
}

/// Registers the embedded font with plotters once per process.
fn register_font() -> error::Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, DEJAVU_SANS).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(ReportError::Font(FontError {
            reason: "plotters' font table refused it".into(),
        }))
    }
}

/// A bitmap backend whose text is rasterised by `scatterfit_imaging::text`, glyph by glyph at its
/// pen position, side bearing and kerning. plotters 0.3.7's `ab_glyph` text drops each glyph's left
/// side bearing, so letters crowd unevenly ("excluded" reads "exduded" at 14 px). Layout (text
/// extents, hence label and legend placement) stays plotters' own, which measures advances
/// correctly.
struct GlyphTextBackend<'a> {
    inner: BitMapBackend<'a>,
    font: &'static Font,
}

impl<'a> GlyphTextBackend<'a> {
    fn new(inner: BitMapBackend<'a>) -> error::Result<Self> {
        let font = Font::dejavu_sans().map_err(ReportError::Font)?;
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
        let colour = style.color();
        if colour.alpha == 0.0 {
            return Ok(());
        }
        // Bounded before layout: a label drawn from a file (a sample's name) could be megabytes,
        // and laying it out costs memory and time in proportion.
        let bounded;
        let text = if text.chars().count() > MAX_DRAWN_CHARS {
            bounded = format!(
                "{}…",
                text.chars().take(MAX_DRAWN_CHARS - 1).collect::<String>()
            );
            bounded.as_str()
        } else {
            text
        };
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
        let px = style.size() as f32;
        let baseline = (height as f32 + self.font.cap_height(px)) / 2.0;
        let mut coverage: Vec<(i32, i32, f32)> = Vec::new();
        self.font
            .layout(text, px)
            .coverage((0.0, baseline), |x, y, c| coverage.push((x, y, c)));
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
