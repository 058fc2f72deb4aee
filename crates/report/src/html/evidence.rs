//! The evidence a sample page shows besides the fit: the HDR radiance map in false colour with
//! the spot centre, the light spot, the fitted rings and the profile's cut-off drawn on it; the
//! recovered camera response; the bracket's frames as thumbnails; and a small rendering of the
//! measured material beside the spectrophotometer's colour.
//!
//! Pictures are PNG `data:` URIs inside the page (one file to open, print or send; nothing to go
//! missing when the folder is copied), kept small: the map at most [`MAP_SIDE`] pixels, the
//! thumbnails 96 (`scatterfit_pipeline::hdr::THUMBNAIL_SIDE`, made while the frames are in
//! memory), the swatch [`SWATCH_SIDE`]. Marks, labels and scales are SVG
//! vectors and text drawn over them, not pixels.

use std::fmt::Write as _;

use image::ImageEncoder as _;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use scatterfit_imaging::merge::CLIPPED_HIGH;
use scatterfit_pipeline::Measurement;
use scatterfit_pipeline::fit::ChannelOutcome;

use super::markup::{inline_svg, name, png_data_uri};
use crate::plot::{Figure, Panel, Series, SeriesStyle};

/// Longest side of the false-colour map \[px\].
pub(crate) const MAP_SIDE: usize = 320;
/// Side of the rendered swatch \[px\].
pub(crate) const SWATCH_SIDE: usize = 128;

/// Okabe & Ito's vermillion, bluish green and blue: the channels R, G, B in every figure of the
/// report, Figures 4 and 6 included (distinct for the common colour-vision deficiencies; the lines also
/// differ in dash and the legend names them).
pub const CHANNEL_COLOURS: [(u8, u8, u8); 3] = [(213, 94, 0), (0, 158, 115), (0, 114, 178)];

/// An 8-bit RGB buffer as PNG (fast compression: these are thumbnails).
pub(crate) fn encode_png(width: usize, height: usize, rgb: &[u8]) -> Option<Vec<u8>> {
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Sub)
        .write_image(
            rgb,
            u32::try_from(width).ok()?,
            u32::try_from(height).ok()?,
            image::ExtendedColorType::Rgb8,
        )
        .ok()?;
    Some(out)
}

/// Viridis (van der Walt & Smith, matplotlib 2015) at nine stops: perceptually uniform, readable
/// in grey and by colour-blind readers.
const VIRIDIS: [[f64; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

/// Viridis at `t` in [0, 1].
pub(crate) fn viridis(t: f64) -> [u8; 3] {
    let x = t.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as f64;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - k as f64;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    std::array::from_fn(|c| (a[c] + f * (b[c] - a[c])).round() as u8)
}

/// The rings the fits used, as (innermost inner radius, outermost outer radius) \[px\], over the
/// channels that were fitted.
fn fitted_span_px(m: &Measurement) -> Option<(f64, f64)> {
    let rings = &m.profile.profile.rings;
    let mut span: Option<(f64, f64)> = None;
    for f in m.fits.iter().filter_map(ChannelOutcome::report) {
        for ring in f.fitted.iter().filter_map(|r| rings.get(r.index)) {
            span = Some(match span {
                None => (ring.r_inner_px, ring.r_outer_px),
                Some((a, b)) => (a.min(ring.r_inner_px), b.max(ring.r_outer_px)),
            });
        }
    }
    span
}

/// The radiance map in false colour (log10 of the mean of the valid channels at each map
/// pixel's centre; viridis over the decades shown; white where every exposure clipped high), with the
/// centre, the spot, the fitted rings and the cut-off drawn over it as SVG, and its colour scale.
pub(crate) fn radiance_map(m: &Measurement, spot_radius_mm: Option<f64>) -> Option<String> {
    let hdr = &m.hdr.hdr;
    let (w, h, nc) = (
        hdr.radiance.width(),
        hdr.radiance.height(),
        hdr.radiance.channels(),
    );
    let step = w.max(h).div_ceil(MAP_SIDE).max(1);
    let (tw, th) = (w.div_ceil(step), h.div_ceil(step));
    // Per block, its centre pixel (point sampling: the map is smooth at this scale, and a
    // quarter-megapixel read instead of the whole frame keeps the page cheap): the mean radiance of
    // its valid channels, or its clip state.
    let mut values = vec![f64::NAN; tw * th];
    let mut high = vec![false; tw * th];
    let (data, clip) = (hdr.radiance.data(), hdr.clipped.data());
    for by in 0..th {
        let y = (by * step + step / 2).min(h - 1);
        for bx in 0..tw {
            let x = (bx * step + step / 2).min(w - 1);
            let i = (y * w + x) * nc;
            let (mut sum, mut n, mut hi) = (0.0f64, 0usize, false);
            for c in 0..nc {
                if clip[i + c] == 0 {
                    sum += f64::from(data[i + c]);
                    n += 1;
                } else if clip[i + c] & CLIPPED_HIGH != 0 {
                    hi = true;
                }
            }
            if n > 0 {
                values[by * tw + bx] = sum / n as f64;
            } else {
                high[by * tw + bx] = hi;
            }
        }
    }
    let top = values
        .iter()
        .copied()
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold(f64::NEG_INFINITY, f64::max);
    if !top.is_finite() {
        return None;
    }
    let hi_log = top.log10().ceil();
    let lo_log = hi_log - 6.0;
    let mut rgb = Vec::with_capacity(tw * th * 3);
    for (v, hi) in values.iter().zip(&high) {
        let px = if *hi {
            [255, 255, 255]
        } else if v.is_finite() && *v > 0.0 {
            viridis((v.log10() - lo_log) / (hi_log - lo_log))
        } else {
            [0, 0, 0]
        };
        rgb.extend_from_slice(&px);
    }
    let png = encode_png(tw, th, &rgb)?;
    // Overlay in image pixels scaled to the thumbnail.
    let s = 1.0 / step as f64;
    let [cx, cy] = m.profile.profile.center_px;
    let (cx, cy) = ((cx + 0.5) * s, (cy + 0.5) * s);
    let mmpp = m.profile.profile.mm_per_pixel;
    let r_max = m.profile.profile.rings.last().map_or(0.0, |r| r.r_outer_px);
    let bar_w = 70.0;
    let (vw, vh) = (tw as f64 + bar_w, th as f64);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{vw}\" height=\"{vh}\">\
         <image x=\"0\" y=\"0\" width=\"{tw}\" height=\"{th}\" href=\"{}\"/>\
         <clipPath id=\"map-clip\"><rect width=\"{tw}\" height=\"{th}\"/></clipPath>\
         <g clip-path=\"url(#map-clip)\">",
        png_data_uri(&png)
    );
    let circle = |svg: &mut String, r_px: f64, dash: &str, label: &str| {
        let r = r_px * s;
        if r > 0.5 {
            let _ = write!(
                svg,
                "<circle cx=\"{cx:.1}\" cy=\"{cy:.1}\" r=\"{r:.1}\" fill=\"none\" stroke=\"black\" \
                 stroke-width=\"2.6\" stroke-dasharray=\"{dash}\"/><circle cx=\"{cx:.1}\" \
                 cy=\"{cy:.1}\" r=\"{r:.1}\" fill=\"none\" stroke=\"white\" stroke-width=\"1.2\" \
                 stroke-dasharray=\"{dash}\"><title>{label}</title></circle>"
            );
        }
    };
    circle(&mut svg, r_max, "2 3", "profile cut-off r_max");
    if let Some((a, b)) = fitted_span_px(m) {
        circle(&mut svg, a, "", "innermost fitted ring");
        circle(&mut svg, b, "", "outermost fitted ring (fitted radius)");
    }
    if let Some(r) = spot_radius_mm.filter(|r| *r > 0.0) {
        circle(&mut svg, r / mmpp, "5 3", "the light spot (its radius)");
    }
    let _ = write!(
        svg,
        "<path d=\"M{:.1} {cy:.1}H{:.1}M{cx:.1} {:.1}V{:.1}\" stroke=\"black\" stroke-width=\"3\"/>\
         <path d=\"M{:.1} {cy:.1}H{:.1}M{cx:.1} {:.1}V{:.1}\" stroke=\"#E69F00\" stroke-width=\"1.4\">\
         <title>spot centre</title></path>",
        cx - 7.0,
        cx + 7.0,
        cy - 7.0,
        cy + 7.0,
        cx - 7.0,
        cx + 7.0,
        cy - 7.0,
        cy + 7.0
    );
    svg.push_str("</g>");
    // The colour scale: one block per decade, labelled.
    let x0 = tw as f64 + 10.0;
    let decades = (hi_log - lo_log) as usize;
    let bh = (vh - 20.0) / decades as f64;
    for k in 0..decades {
        let t0 = 1.0 - (k as f64 + 0.5) / decades as f64;
        let [r, g, b] = viridis(t0);
        let y = 10.0 + k as f64 * bh;
        let _ = write!(
            svg,
            "<rect x=\"{x0}\" y=\"{y:.1}\" width=\"14\" height=\"{bh:.1}\" fill=\"rgb({r},{g},{b})\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" font-family=\"sans-serif\">1e{}</text>",
            x0 + 18.0,
            y + 4.0,
            hi_log as i64 - k as i64
        );
    }
    let _ = write!(
        svg,
        "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" font-family=\"sans-serif\">1e{}</text></svg>",
        x0 + 18.0,
        vh - 6.0,
        lo_log as i64
    );
    let sampling = if step == 1 {
        "every image pixel".to_string()
    } else {
        format!("one image pixel of every {step}×{step} block")
    };
    let caption = format!(
        "The merged radiance map ({}) in false colour, log scale (relative radiance; white: \
         clipped in every exposure, black: below every exposure or no data), {sampling}. \
         Cross: the spot centre ({:.1}, {:.1}) px, {}. Solid circles: the innermost and outermost \
         ring the fits used ({}); dashed: the light spot; dotted: the profile's cut-off {:.0} px = {:.2} mm.",
        name(&m.hdr.image),
        m.profile.profile.center_px[0],
        m.profile.profile.center_px[1],
        name(&format!("{:?}", m.profile.center_source).to_lowercase()),
        fitted_span_px(m).map_or("none fitted".into(), |(a, b)| format!(
            "{a:.0}–{b:.0} px = {:.2}–{:.2} mm",
            a * mmpp,
            b * mmpp
        )),
        r_max,
        r_max * mmpp
    );
    Some(format!(
        "<figure>{}<figcaption>{caption}</figcaption></figure>",
        inline_svg(&svg, "false-colour radiance map")
    ))
}

/// The recovered (or given) camera response g(z) = ln X per channel as a figure; `None` for a
/// linear merge or a given radiance map.
pub(crate) fn response_figure(m: &Measurement) -> Option<Figure> {
    let response = m.hdr.response.as_ref()?;
    let n = response.channels();
    let series = (0..n.min(3))
        .map(|c| {
            let g = response
                .log_exposure(c)
                .map(|g| g.to_vec())
                .unwrap_or_default();
            Series {
                label: format!("{} (rms {})", ["R", "G", "B"][c], {
                    m.hdr
                        .rms
                        .get(c)
                        .map_or("—".into(), |v| scatterfit_io::result_table::sig4(*v))
                }),
                points: g.iter().enumerate().map(|(z, v)| (z as f64, *v)).collect(),
                errors: None,
                style: if c == 1 {
                    SeriesStyle::DashedLine
                } else {
                    SeriesStyle::Line
                },
                colour: Some(CHANNEL_COLOURS[c]),
            }
        })
        .collect();
    Some(Figure {
        title: format!("camera response ({})", m.hdr.response_kind),
        x_label: "pixel value z".into(),
        y_label: "g(z) = ln exposure".into(),
        panels: vec![Panel {
            title: "g(z) per channel".into(),
            colour: (80, 80, 80),
            series,
            note: None,
        }],
        log_y: false,
        log_x: false,
    })
}

/// The material rendered on `scatterfit-render`'s 10 mm sphere by the subsurface colour method
/// (Choi et al. 2014 §4.1; the studio's lights; one sample per pixel) at [`SWATCH_SIDE`] pixels, with
/// what it is; `None` when the parameters cannot be rendered.
pub(crate) fn swatch(coefficients: [(f64, f64); 3], eta: f64) -> Option<(Vec<u8>, String)> {
    use scatterfit_render::tonemap::{ToneMap, tone_map};
    use scatterfit_render::{
        Material, Method, RenderOptions, Shape, render, studio, studio_lights,
    };
    let material = Material::dipole(scatterfit_optics::Rgb::from_array(coefficients), eta).ok()?;
    // One sample per pixel and a coarse sphere: ~5 ms, a small part of a measurement.
    let scene = studio(Shape::Sphere.mesh(400).ok()?, studio_lights()).ok()?;
    let opts = RenderOptions {
        width: SWATCH_SIDE,
        height: SWATCH_SIDE,
        spp: 1,
        ..RenderOptions::default()
    };
    let rendered = render(&scene, &material, Method::Colour, &opts, &|_| {}).ok()?;
    let img = tone_map(&rendered.image, &ToneMap::default()).ok()?;
    let png = encode_png(img.width(), img.height(), img.data())?;
    Some((
        png,
        "a 10 mm sphere, subsurface colour method (§4.1), studio lights".into(),
    ))
}
