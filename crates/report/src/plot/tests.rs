//! The plotting module's tests: axes, clipping, edge cases, and pixels of the rendered PNG.

use std::ops::Range;

use super::axis::{Axis, MAX_DECADES, figure_axes};
use super::layout::{LegendBox, TITLE_HEIGHT, legend_corner};
use super::series::clip_polyline;
use super::*;

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
    eprintln!("fig4 (SVG + PNG, 3 × 300 rings): {elapsed:?}");
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

/// The legend goes to the corner the data leave free: a rising curve (a camera response) moves it
/// to the upper left, a falling profile keeps it upper right, a curve rising at both ends sends it
/// down, and a segment crossing a corner with no point inside it still counts.
#[test]
fn the_legend_avoids_the_data() {
    use plotters::prelude::SeriesLabelPosition as P;
    let corner = |points: Vec<(f64, f64)>| {
        let fig = Figure {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            panels: vec![Panel {
                title: "p".into(),
                colour: RED,
                series: vec![series("a curve", points, SeriesStyle::Line)],
                note: None,
            }],
            log_y: false,
            log_x: false,
        };
        let (x, y) = figure_axes(&fig);
        let legend = LegendBox {
            width: 0.3,
            height: 0.15,
        };
        format!("{:?}", legend_corner(&fig, &fig.panels[0], &x, &y, legend))
    };
    let curve = |f: fn(f64) -> f64| (0..=100).map(|i| (f64::from(i), f(f64::from(i)))).collect();
    assert_eq!(corner(curve(|x| x)), format!("{:?}", P::UpperLeft));
    assert_eq!(corner(curve(|x| 100.0 - x)), format!("{:?}", P::UpperRight));
    assert_eq!(
        corner(curve(|x| (x - 50.0).powi(2) / 25.0)),
        format!("{:?}", P::LowerRight)
    );
    // Two points only: the segment from the lower left to the upper right crosses the upper right
    // corner's box between them.
    assert_eq!(
        corner(vec![(0.0, 0.0), (50.0, 10.0), (100.0, 100.0)]),
        format!("{:?}", P::UpperLeft)
    );
}
