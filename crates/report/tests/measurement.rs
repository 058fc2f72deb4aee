//! A Rust program's whole report: a Monte Carlo rig-twin sample (quick rig, fixed seed) measured
//! through `scatterfit-pipeline`, then its files written through this crate. Checks what a user
//! would open: every file exists, result.json reads back through io's checked reader and agrees
//! with the summary, fit.png is a 3-panel picture in the channels' colours, compare.png draws both
//! methods, and a folder that cannot be created is an error naming it.

use std::path::Path;

use scatterfit_io::result_json::parse_result_json;
use scatterfit_io::sample_folder::{SampleFiles, write_sample_folder};
use scatterfit_optics::materials::by_name;
use scatterfit_pipeline::Method;
use scatterfit_pipeline::{Measurement, Overrides, measure_sample};
use scatterfit_report::{
    ReportError, compare_figure, fit_figure, render_png, summary_text, write_figure,
    write_measurement,
};
use scatterfit_synth::{RigSpec, synthesize};

/// Wood tile on the quick rig, seed 3, written as a sample folder and measured.
fn measured(dir: &Path) -> Measurement {
    let m = by_name("wood-tile").unwrap();
    let rig = RigSpec::quick();
    let s = synthesize(
        m.name,
        m.sigma_s_prime,
        m.sigma_a,
        m.eta,
        &rig,
        3,
        None,
        &|_, _, _| {},
    )
    .unwrap();
    write_sample_folder(
        dir,
        &SampleFiles {
            name: m.name,
            reading: &s.reading,
            lab10: None,
            frames: &s.bracket.frames,
            times_s: &s.bracket.times_s,
            mm_per_pixel: rig.mm_per_pixel,
            spot_diameter_mm: 2.0 * rig.spot_radius_mm,
            truth_json: None,
            provenance: "test",
            fit: Default::default(),
        },
    )
    .unwrap();
    measure_sample(dir, &Overrides::default(), &|_| {}).unwrap()
}

fn decode(path: &Path) -> image::RgbImage {
    image::open(path).unwrap().to_rgb8()
}

/// Pixels of exactly this colour (a channel's curve is drawn in its full colour).
fn count(img: &image::RgbImage, c: [u8; 3]) -> usize {
    img.pixels().filter(|p| p.0 == c).count()
}

/// The channel colours of `figures.rs` (R, G, B).
const COLOURS: [[u8; 3]; 3] = [[213, 94, 0], [0, 158, 115], [0, 114, 178]];

#[test]
fn a_measured_sample_gets_its_report_files() {
    let temp = tempfile::tempdir().unwrap();
    let sample = temp.path().join("wood-tile");
    let m = measured(&sample);
    let out = temp.path().join("report").join("wood-tile");

    let written = write_measurement(&out, &m).unwrap();
    let names: Vec<String> = written
        .files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "profile.csv",
            "result.json",
            "result.csv",
            "result.md",
            "fit.svg",
            "fit.png",
            "report.html",
            "result-files.json"
        ]
    );
    for f in &written.files {
        assert!(f.starts_with(&out), "{} outside the folder", f.display());
        assert!(std::fs::metadata(f).unwrap().len() > 100, "{}", f.display());
    }

    // result.json reads back through io's checked reader, and the summary prints its values.
    let json = out.join("result.json");
    let back = parse_result_json(&std::fs::read_to_string(&json).unwrap(), &json).unwrap();
    assert_eq!(back.name, "wood-tile");
    let summary = summary_text(&written.result);
    assert!(summary.starts_with("wood-tile: η = "), "{summary}");
    let md = std::fs::read_to_string(out.join("result.md")).unwrap();
    // The g the models assumed: the manifest has none, so the values are at 0, g is
    // taken as unknown over the default range, and both say so — the term in every channel.
    assert_eq!(back.inputs.options.g, Some(0.0));
    assert!(
        summary.contains(", values at g = 0 (g in 0–0.95: ± g)"),
        "{summary}"
    );
    assert!(
        summary.contains("not stated, so taken as unknown in 0–0.95"),
        "{summary}"
    );
    let g = back.g_uncertainty.as_ref().unwrap();
    assert_eq!(g.range, Some([0.0, 0.95]));
    for ch in back.channels.iter() {
        assert!(ch.sigma_a.and_then(|e| e.g).unwrap() > 0.0);
    }
    assert!(md.contains("± g"), "{md}");
    for ch in back.channels.iter() {
        let sp = ch
            .sigma_s_prime
            .expect("every channel of the wood tile fits")
            .value;
        assert!(
            summary.contains(&scatterfit_io::result_table::sig4(sp)),
            "σ′s {sp} not in\n{summary}"
        );
    }
    assert!(md.contains("wood-tile"), "{md}");

    // fit.png: three 500 × 520 panels, each channel's fitted curve in its colour.
    let img = decode(&out.join("fit.png"));
    assert_eq!(img.dimensions(), (1500, 520));
    for c in COLOURS {
        assert!(
            count(&img, c) > 300,
            "colour {c:?} on {} pixels",
            count(&img, c)
        );
    }
    let svg = std::fs::read_to_string(out.join("fit.svg")).unwrap();
    assert!(
        svg.contains("wood-tile — radial profile and exact-transport (mc) fit"),
        "SVG title"
    );

    // report.html: self-contained (no external reference), Figure 4 inline with its title as
    // text, the radiance map, one thumbnail per frame, the swatch beside the spectro colour.
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(page.contains("<h1>wood-tile</h1>"));
    assert!(
        page.contains("wood-tile — radial profile and exact-transport (mc) fit"),
        "Figure 4"
    );
    assert!(!page.contains("src=\"http") && !page.contains("href=\"http"));
    assert!(page.contains("aria-label=\"false-colour radiance map\""));
    assert_eq!(
        page.matches("<img alt=\"frame ").count(),
        m.hdr.frames.len(),
        "one thumbnail per frame"
    );
    assert!(page.contains("alt=\"rendered swatch\""));
    assert!(page.contains("spectrophotometer: Rd as sRGB #"));
    assert!(page.contains("camera response"));
    assert!(!page.contains("id=\"fig6\""), "no Figure 6 from one method");

    // The same picture in memory, and the Figure 6 comparison of both methods.
    let fig = fit_figure(&m, &written.result);
    assert_eq!(
        render_png(&fig).unwrap(),
        std::fs::read(out.join("fit.png")).unwrap()
    );
    let existing = m.refit(Method::Existing).unwrap();
    let compare = compare_figure(&existing, &m, "wood-tile");
    let labels: Vec<&str> = compare.panels[1]
        .series
        .iter()
        .map(|s| s.label.as_str())
        .collect();
    assert!(
        labels.contains(&"existing (σ′s, σa fitted)")
            && labels.contains(&"proposed (α′ from spectro)"),
        "{labels:?}"
    );
    let png = temp.path().join("compare.png");
    write_figure(&compare, None, Some(&png)).unwrap();
    assert_eq!(decode(&png).dimensions(), (1500, 520));
    // With the existing method's fit, the page shows Figure 6 too.
    let both = temp.path().join("both");
    scatterfit_report::write_measurement_with(&both, &m, Some(&existing)).unwrap();
    let page = std::fs::read_to_string(both.join("report.html")).unwrap();
    assert!(
        page.contains("id=\"fig6\"") && page.contains("measured profile, existing and proposed")
    );

    // Written again: replaced in place, same picture.
    let again = write_measurement(&out, &m).unwrap();
    assert_eq!(again.files, written.files);
    assert_eq!(decode(&out.join("fit.png")), img);

    // A folder under a file cannot be created: the error names it, nothing is written.
    let blocked = temp.path().join("a-file");
    std::fs::write(&blocked, "x").unwrap();
    let target = blocked.join("out");
    let e = write_measurement(&target, &m).unwrap_err();
    assert!(matches!(e, ReportError::CreateDir { .. }), "{e:?}");
    assert!(e.to_string().contains(&*target.to_string_lossy()), "{e}");
}
