//! Figures: panels side by side with captions under them (the shape of the paper's Figure 5), as
//! 8-bit sRGB with text, or as a linear grid (no text) for EXR.
//!
//! Captions are drawn by `scatterfit_imaging::text` (the workspace's one glyph rasteriser) in the
//! DejaVu Sans embedded there, so they render on a machine with no system fonts.

use scatterfit_imaging::ImageBuf;
use scatterfit_imaging::text::Font;

use crate::error::{RenderError, Result, invalid};

/// One panel: an 8-bit sRGB image (3 channels) and its caption lines.
#[derive(Debug, Clone)]
pub struct Panel {
    /// The picture (RGB, 8-bit sRGB).
    pub image: ImageBuf<u8>,
    /// Caption lines, drawn centred under the picture.
    pub caption: Vec<String>,
}

/// Layout and colours of a figure.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureStyle {
    /// Panels per row.
    pub columns: usize,
    /// Space around and between panels \[px\].
    pub gap: usize,
    /// Caption text height \[px\].
    pub text_px: f32,
    /// Background (sRGB 8-bit).
    pub background: [u8; 3],
    /// Text colour (sRGB 8-bit).
    pub ink: [u8; 3],
    /// Optional title line drawn above the panels.
    pub title: Option<String>,
}

impl Default for FigureStyle {
    fn default() -> Self {
        Self {
            columns: 4,
            gap: 12,
            text_px: 17.0,
            background: [24, 24, 24],
            ink: [230, 230, 230],
            title: None,
        }
    }
}

/// Composes panels (all the same size) into a grid with captions in the embedded DejaVu Sans.
///
/// # Errors
/// [`RenderError::InvalidOption`] for no panel, zero columns, or panels of different sizes or
/// channel counts other than 3; [`RenderError::Font`] if the embedded font does not load (a broken
/// build).
pub fn compose(panels: &[Panel], style: &FigureStyle) -> Result<ImageBuf<u8>> {
    let font = Font::dejavu_sans().map_err(|e| RenderError::Font(e.reason))?;
    let first = panels
        .first()
        .ok_or_else(|| invalid("panels", 0, "need at least one"))?;
    let (pw, ph) = (first.image.width(), first.image.height());
    if style.columns == 0 {
        return Err(invalid("columns", 0, "need at least one"));
    }
    if panels
        .iter()
        .any(|p| p.image.width() != pw || p.image.height() != ph || p.image.channels() != 3)
    {
        return Err(invalid(
            "panels",
            panels.len(),
            "must all be RGB images of the same size",
        ));
    }
    let line_h = font.line_height(style.text_px).ceil() as usize + 2;
    let lines = panels.iter().map(|p| p.caption.len()).max().unwrap_or(0);
    let cols = style.columns.min(panels.len());
    let rows = panels.len().div_ceil(cols);
    let g = style.gap;
    let title_h = if style.title.is_some() {
        line_h + g / 2
    } else {
        0
    };
    let cell_h = ph + lines * line_h + g / 2;
    let w = cols * pw + (cols + 1) * g;
    let h = title_h + rows * cell_h + (rows + 1) * g;
    let mut canvas = ImageBuf::new(w, h, 3, style.background.repeat(w * h))?;
    if let Some(title) = &style.title {
        centred_text(
            &mut canvas,
            font,
            style.text_px,
            title,
            w as f32 / 2.0,
            g as f32,
            style.ink,
        );
    }
    for (k, p) in panels.iter().enumerate() {
        let (col, row) = (k % cols, k / cols);
        let x0 = g + col * (pw + g);
        let y0 = title_h + g + row * (cell_h + g);
        for y in 0..ph {
            let src = &p.image.data()[y * pw * 3..(y + 1) * pw * 3];
            let dst = ((y0 + y) * w + x0) * 3;
            canvas.data_mut()[dst..dst + pw * 3].copy_from_slice(src);
        }
        for (i, line) in p.caption.iter().enumerate() {
            let cx = x0 as f32 + pw as f32 / 2.0;
            let ty = (y0 + ph + g / 2 + i * line_h) as f32;
            centred_text(&mut canvas, font, style.text_px, line, cx, ty, style.ink);
        }
    }
    Ok(canvas)
}

/// Linear panels (1 or 3 channels, same size) side by side with `gap` pixels of 0 between them, in
/// rows of `columns` — the EXR counterpart of [`compose`], without text.
///
/// # Errors
/// [`RenderError::InvalidOption`] for no panel, zero columns or mismatched panels.
pub fn compose_linear(
    panels: &[&ImageBuf<f32>],
    columns: usize,
    gap: usize,
) -> Result<ImageBuf<f32>> {
    let first = panels
        .first()
        .ok_or_else(|| invalid("panels", 0, "need at least one"))?;
    let (pw, ph, ch) = (first.width(), first.height(), first.channels());
    if columns == 0
        || panels
            .iter()
            .any(|p| p.width() != pw || p.height() != ph || p.channels() != ch)
    {
        return Err(invalid(
            "panels",
            panels.len(),
            "must have the same size and channels, with at least one column",
        ));
    }
    let cols = columns.min(panels.len());
    let rows = panels.len().div_ceil(cols);
    let w = cols * pw + (cols - 1) * gap;
    let h = rows * ph + (rows - 1) * gap;
    let mut data = vec![0f32; w * h * ch];
    for (k, p) in panels.iter().enumerate() {
        let (x0, y0) = ((k % cols) * (pw + gap), (k / cols) * (ph + gap));
        for y in 0..ph {
            let src = &p.data()[y * pw * ch..(y + 1) * pw * ch];
            let dst = ((y0 + y) * w + x0) * ch;
            data[dst..dst + pw * ch].copy_from_slice(src);
        }
    }
    Ok(ImageBuf::new(w, h, ch, data)?)
}

/// Draws `text` centred on `cx` (never starting left of the image), its line box starting at `top`.
fn centred_text(
    canvas: &mut ImageBuf<u8>,
    font: &Font,
    px: f32,
    text: &str,
    cx: f32,
    top: f32,
    ink: [u8; 3],
) {
    let line = font.layout(text, px);
    let x0 = (cx - line.width() / 2.0).max(0.0);
    line.draw(canvas, (x0, top + font.ascent(px)), ink);
}
