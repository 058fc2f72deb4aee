//! Text on pixel buffers: one line laid out glyph by glyph and rasterised with `ab_glyph`, from the
//! embedded DejaVu Sans.
//!
//! This is the workspace's only glyph rasteriser and the only copy of the font: the report crate's
//! PNG plots and the renderer's figure captions both draw through it, so a fresh machine with no
//! system fonts (no FreeType, no fontconfig) still gets readable labels.
//!
//! A line is laid out on its baseline from pen position 0: each glyph sits at the pen, its outline
//! keeps its own left side bearing, the pen moves by the glyph's advance plus the kerning of the
//! pair. (plotters 0.3.7's own `ab_glyph` text drops the side bearing, so letters crowd unevenly:
//! "excluded" reads "exduded" at 14 px; that is why its PNG backend draws text through here.) The
//! rasterised line comes out as coverage per pixel ([`Line::coverage`]), for a caller that blends
//! itself (a plotting backend, rotated text), or is blended straight into an 8-bit buffer
//! ([`Line::draw`]).
//!
//! ```
//! use scatterfit_imaging::ImageBuf;
//! use scatterfit_imaging::text::Font;
//!
//! let font = Font::dejavu_sans()?;
//! let line = font.layout("σ′s = 1.98 mm⁻¹", 17.0);
//! let mut image = ImageBuf::new(200, 30, 3, vec![255u8; 200 * 30 * 3])?;
//! // Centred, the line box's top at y = 4.
//! line.draw(&mut image, (100.0 - line.width() / 2.0, 4.0 + font.ascent(17.0)), [20, 20, 20]);
//! assert!(image.data().iter().any(|&v| v < 128));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::sync::OnceLock;

use ab_glyph::{Font as _, FontRef, GlyphId, PxScale, ScaleFont, point};

use crate::ImageBuf;

/// DejaVu Sans (Bitstream Vera licence; `assets/DejaVuSans-LICENSE.txt` beside the font file): the
/// TrueType bytes, compiled in once for the whole workspace. Exposed for libraries that register a
/// font by its bytes (plotters' `register_font` for the SVG plots' text metrics).
pub static DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Font bytes that are not a TrueType/OpenType font `ab_glyph` can read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the font could not be read as TrueType/OpenType: {reason}")]
pub struct FontError {
    /// What the font parser said.
    pub reason: String,
}

/// A font to draw text with (a parsed TrueType/OpenType face; cheap to clone).
#[derive(Debug, Clone)]
pub struct Font {
    face: FontRef<'static>,
}

impl Font {
    /// Parses TrueType/OpenType bytes that live for the whole program (e.g. `include_bytes!`).
    ///
    /// # Errors
    /// [`FontError`] if the bytes are not a font.
    pub fn from_static(bytes: &'static [u8]) -> Result<Self, FontError> {
        FontRef::try_from_slice(bytes)
            .map(|face| Self { face })
            .map_err(|e| FontError {
                reason: e.to_string(),
            })
    }

    /// The embedded DejaVu Sans ([`DEJAVU_SANS`]), parsed once per process.
    ///
    /// # Errors
    /// [`FontError`] if the embedded bytes do not parse (a broken build, never user input).
    pub fn dejavu_sans() -> Result<&'static Self, FontError> {
        static FONT: OnceLock<Result<Font, FontError>> = OnceLock::new();
        FONT.get_or_init(|| Self::from_static(DEJAVU_SANS))
            .as_ref()
            .map_err(Clone::clone)
    }

    /// Lays out `text` as one line at `px` pixels per em: the pen starts at 0 and moves by each
    /// glyph's advance and the kerning between neighbours. Characters the font lacks show its
    /// missing-glyph box; line breaks are not interpreted.
    pub fn layout(&self, text: &str, px: f32) -> Line<'_> {
        let scale = PxScale::from(px);
        let scaled = self.face.as_scaled(scale);
        let mut glyphs = Vec::with_capacity(text.len());
        let mut pen = 0.0f32;
        let mut previous = None;
        for c in text.chars() {
            let id = scaled.glyph_id(c);
            if let Some(p) = previous {
                pen += scaled.kern(p, id);
            }
            glyphs.push(PlacedGlyph { id, pen });
            pen += scaled.h_advance(id);
            previous = Some(id);
        }
        Line {
            face: &self.face,
            scale,
            glyphs,
            width: pen,
        }
    }

    /// Height of the font's ascender above the baseline at `px` \[px\].
    pub fn ascent(&self, px: f32) -> f32 {
        self.face.as_scaled(PxScale::from(px)).ascent()
    }

    /// Distance from one baseline to the next at `px` \[px\]: ascent − descent + line gap.
    pub fn line_height(&self, px: f32) -> f32 {
        let scaled = self.face.as_scaled(PxScale::from(px));
        scaled.height() + scaled.line_gap()
    }

    /// Height of a capital letter above the baseline at `px` \[px\]: the top of "H"'s pixel bounds
    /// (whole pixels), or 0.63 of the font height for a font without an "H" outline.
    pub fn cap_height(&self, px: f32) -> f32 {
        let scaled = self.face.as_scaled(PxScale::from(px));
        scaled
            .outline_glyph(scaled.scaled_glyph('H'))
            .map_or(0.63 * scaled.height(), |g| -g.px_bounds().min.y)
    }
}

/// A glyph of a [`Line`] and its pen position \[px from the line's start\].
#[derive(Debug, Clone, Copy)]
struct PlacedGlyph {
    id: GlyphId,
    pen: f32,
}

/// One line of text laid out by [`Font::layout`], ready to rasterise anywhere.
#[derive(Debug, Clone)]
pub struct Line<'f> {
    face: &'f FontRef<'static>,
    scale: PxScale,
    glyphs: Vec<PlacedGlyph>,
    width: f32,
}

impl Line<'_> {
    /// The advance width of the whole line \[px\]: where the pen stops after the last glyph.
    pub fn width(&self) -> f32 {
        self.width
    }

    /// Rasterises the line with its pen starting at `origin` (x, baseline y) \[px\] and calls
    /// `pixel(x, y, coverage)` for every pixel a glyph touches, glyph after glyph, coverage in
    /// 0…1 (anti-aliased; clamp before blending, `ab_glyph` may overshoot slightly). Pixels may lie
    /// outside any image: the caller clips.
    pub fn coverage(&self, origin: (f32, f32), mut pixel: impl FnMut(i32, i32, f32)) {
        for g in &self.glyphs {
            let glyph =
                g.id.with_scale_and_position(self.scale, point(origin.0 + g.pen, origin.1));
            if let Some(outline) = self.face.outline_glyph(glyph) {
                let bounds = outline.px_bounds();
                let (x0, y0) = (bounds.min.x as i32, bounds.min.y as i32);
                outline.draw(|x, y, c| pixel(x0 + x as i32, y0 + y as i32, c));
            }
        }
    }

    /// Draws the line into `image` with its pen starting at `origin` (x, baseline y) \[px\] in the
    /// colour `ink`: each touched pixel becomes `(1 − c)·pixel + c·ink`, rounded, per channel in
    /// the buffer's own (sRGB) values, as text renderers blend. The first three channels are
    /// blended (the first only, for a grey image); pixels outside the image are skipped.
    pub fn draw(&self, image: &mut ImageBuf<u8>, origin: (f32, f32), ink: [u8; 3]) {
        let (width, height, channels) = (image.width(), image.height(), image.channels());
        let inked = channels.min(3);
        let data = image.data_mut();
        self.coverage(origin, |x, y, c| {
            let (Ok(x), Ok(y)) = (usize::try_from(x), usize::try_from(y)) else {
                return;
            };
            if x >= width || y >= height {
                return;
            }
            let i = (y * width + x) * channels;
            let c = c.clamp(0.0, 1.0);
            for (d, &k) in data[i..i + inked].iter_mut().zip(&ink) {
                *d = (f32::from(*d) * (1.0 - c) + f32::from(k) * c).round() as u8;
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn white(w: usize, h: usize) -> ImageBuf<u8> {
        ImageBuf::new(w, h, 3, vec![255; w * h * 3]).unwrap()
    }

    /// Columns holding any ink, left to right.
    fn inked_columns(img: &ImageBuf<u8>) -> Vec<usize> {
        (0..img.width())
            .filter(|&x| (0..img.height()).any(|y| img.pixel(x, y).unwrap()[0] < 200))
            .collect()
    }

    #[test]
    fn the_embedded_font_parses_once_and_has_latin_greek_and_superscripts() {
        let font = Font::dejavu_sans().unwrap();
        assert!(std::ptr::eq(font, Font::dejavu_sans().unwrap()));
        let face = font.face.clone();
        // σ, ′, ⁻, ¹, α, η and the decade labels' superscripts all have glyphs (id 0 is "missing").
        for c in "σ′⁻¹²³⁴⁵⁶⁷⁸⁹⁰αη…—±µ".chars() {
            assert_ne!(face.glyph_id(c), GlyphId(0), "{c:?} missing");
        }
    }

    /// DejaVu Sans' own tables (read with a 40-line script from the TTF, not through `ab_glyph`):
    /// hhea ascender 1901, descender −483, line gap 0; hmtx 'l' advance 569, 'H' left side bearing
    /// 201; glyf 'H' yMax 1493. `PxScale` is the pixel height of ascender − descender, so at 2384 px
    /// one font unit is one pixel.
    const UNIT_PX: f32 = 2384.0;

    #[test]
    fn metrics_are_dejavu_sans() {
        let font = Font::dejavu_sans().unwrap();
        assert!((font.ascent(UNIT_PX) - 1901.0).abs() < 0.01);
        assert!((font.line_height(UNIT_PX) - 2384.0).abs() < 0.01);
        assert!((font.cap_height(UNIT_PX) - 1493.0).abs() <= 1.0);
    }

    #[test]
    fn width_is_the_sum_of_advances_and_kerning() {
        let font = Font::dejavu_sans().unwrap();
        assert!((font.layout("l", UNIT_PX).width() - 569.0).abs() < 0.01);
        assert!((font.layout("ll", UNIT_PX).width() - 2.0 * 569.0).abs() < 0.01);
        assert_eq!(font.layout("", 14.0).width(), 0.0);
        // "AV" is a kerning pair: tighter than the two advances apart.
        let apart = font.layout("A", 100.0).width() + font.layout("V", 100.0).width();
        assert!(font.layout("AV", 100.0).width() < apart - 1.0);
    }

    #[test]
    fn glyphs_keep_their_left_side_bearing() {
        // At a tenth of a unit per pixel, 'H' is inked from 20.1 px right of the pen: with the pen at
        // 10, the first inked column is 30 (plotters' ab_glyph path, which drops the bearing, put it
        // at 10). A second 'H' starts one advance (154 px) and one bearing later.
        let font = Font::dejavu_sans().unwrap();
        let mut img = white(360, 260);
        font.layout("HH", UNIT_PX / 10.0)
            .draw(&mut img, (10.0, 200.0), [0, 0, 0]);
        let cols = inked_columns(&img);
        assert_eq!(cols.first(), Some(&30), "ink columns {cols:?}");
        assert!(
            cols.contains(&(30 + 154)) && !cols.contains(&(30 + 153)),
            "{cols:?}"
        );
    }

    #[test]
    fn draw_blends_clips_and_coverage_agrees() {
        let font = Font::dejavu_sans().unwrap();
        let line = font.layout("Hg", 20.0);
        // Half off the left and bottom edges: no panic, some ink inside.
        let mut img = white(12, 12);
        line.draw(&mut img, (-6.0, 8.0), [0, 0, 255]);
        assert!(img.data().chunks(3).any(|p| p[0] < 128 && p[2] == 255));
        // Every covered pixel inside the image was blended, and only those.
        let mut covered = vec![0f32; 12 * 12];
        line.coverage((-6.0, 8.0), |x, y, c| {
            if (0..12).contains(&x) && (0..12).contains(&y) {
                covered[(y * 12 + x) as usize] += c;
            }
        });
        for (p, c) in img.data().chunks(3).zip(&covered) {
            assert_eq!(p[0] < 255, c.clamp(0.0, 1.0) * 255.0 > 0.5, "{p:?} vs {c}");
        }
        // A grey image takes the first ink value.
        let mut grey = ImageBuf::new(40, 20, 1, vec![0u8; 800]).unwrap();
        font.layout("H", 14.0)
            .draw(&mut grey, (2.0, 15.0), [255, 0, 0]);
        assert!(grey.data().iter().any(|&v| v > 200));
    }

    #[test]
    fn bad_font_bytes_are_an_error() {
        let e = Font::from_static(b"not a font").unwrap_err();
        assert!(e.to_string().contains("TrueType"), "{e}");
    }
}
