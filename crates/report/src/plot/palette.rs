//! The figure's neutral colours, shared by the layout (text, frame) and the series (excluded
//! rings, error bars); a panel's own colour comes with its [`super::Panel`].

use plotters::style::RGBColor;

/// Text: titles, notes, tick labels.
pub(super) const INK: RGBColor = RGBColor(20, 20, 20);
/// Rings not fitted and other secondary marks.
pub(super) const GREY: RGBColor = RGBColor(140, 140, 140);
