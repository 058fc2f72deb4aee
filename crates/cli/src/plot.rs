//! TEMPORARY stand-in for the plotting module (being written on the `plots` branch); same API.
#![allow(dead_code)]

/// One curve or point set drawn in a channel's panel.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub errors: Option<Vec<f64>>,
    pub style: SeriesStyle,
}
/// How a series is drawn.
pub enum SeriesStyle {
    Measured,
    Excluded,
    Line,
    DashedLine,
}
/// A panel.
pub struct Panel {
    pub title: String,
    pub colour: (u8, u8, u8),
    pub series: Vec<Series>,
    pub note: Option<String>,
}
/// A figure.
pub struct Figure {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub panels: Vec<Panel>,
    pub log_y: bool,
    pub log_x: bool,
}
/// Writes the figure.
pub fn write_figure(
    fig: &Figure,
    svg: Option<&std::path::Path>,
    _png: Option<&std::path::Path>,
) -> anyhow::Result<()> {
    if let Some(p) = svg {
        scatterfit_io::atomic::write_atomic(
            p,
            format!("<svg><title>{}</title></svg>", fig.title).as_bytes(),
        )?;
    }
    Ok(())
}
