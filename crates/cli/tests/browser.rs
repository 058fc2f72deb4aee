//! The HTML report in a real browser: `scatterfit demo --quick` writes its index.html and a
//! report.html per sample; headless Chromium opens the index and one sample page, and the test
//! checks that
//! - the pages load without a console error (`--enable-logging=stderr`: no `Uncaught`, no
//!   `ERROR:CONSOLE`, no failed resource);
//! - the index's JavaScript ran (its sort headers are made by the script, and it marks the body
//!   `data-ready="1"`) and it lists the seven materials with links to their pages;
//! - every figure of the sample page (Figure 4, Figure 6, the radiance map, the response curve, the
//!   swatch, the thumbnails) has drawn content: in a full-page screenshot, the figure's box (found
//!   by the browser's layout, `getBoundingClientRect` in a wrapper page that frames the report at
//!   the screenshot's width) holds many pixels of more than one colour.
//!
//! The page also prints (`--print-to-pdf`: a PDF of more than 100 kB).
//!
//! The screenshots and the PDF are kept as artefacts: `$SCATTERFIT_ARTEFACTS/browser/` (default
//! `target/ci-artefacts/browser/`); the test prints the folder.
//!
//! The browser is `$SCATTERFIT_CHROMIUM`, else `chromium` on the PATH (Debian's package; `.ci/run`
//! installs it). Without one `cargo test` reports the test as ignored, saying why (the `peers`
//! binary is its own harness: `tests/common/peer.rs`), unless `SCATTERFIT_REQUIRE_CHROMIUM=1` (set
//! by `.ci/run`), which makes its absence a failure.

use crate::common;

use common::peer::Peer;
use common::{run_cached, temp_dir, workspace_root};

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use libtest_mimic::Trial;

/// The screenshot's width [CSS px]; the wrapper frames the report at the same width, so the boxes
/// it measures are where the screenshot has them.
const WIDTH: u32 = 1280;

/// The browser, or why there is none.
fn chromium() -> Result<PathBuf, String> {
    let candidates: Vec<PathBuf> = match std::env::var_os("SCATTERFIT_CHROMIUM") {
        Some(p) => vec![PathBuf::from(p)],
        None => std::env::var_os("PATH")
            .map(|path| {
                std::env::split_paths(&path)
                    .flat_map(|d| ["chromium", "chromium-browser"].map(|n| d.join(n)))
                    .collect()
            })
            .unwrap_or_default(),
    };
    candidates.into_iter().find(|p| p.is_file()).ok_or_else(|| {
        "no Chromium (install Debian's `chromium`: apt-get install -y --no-install-recommends \
         chromium, or set SCATTERFIT_CHROMIUM)"
            .to_string()
    })
}

/// The tests, named `browser::…` in the `peers` binary.
pub fn trials() -> Vec<Trial> {
    let chromium = Peer::new("browser", chromium, "SCATTERFIT_REQUIRE_CHROMIUM");
    vec![chromium.trial(
        "demo_pages_load_and_draw_in_chromium",
        demo_pages_load_and_draw_in_chromium,
    )]
}

/// Where the screenshots go (created).
fn artefacts() -> PathBuf {
    let base = std::env::var_os("SCATTERFIT_ARTEFACTS")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("target").join("ci-artefacts"));
    let dir = base.join("browser");
    std::fs::create_dir_all(&dir).expect("the artefacts folder");
    dir
}

/// Runs headless Chromium on `url` with `args`; returns (stdout, stderr). `profile` keeps its
/// profile out of $HOME.
fn browse(chrome: &Path, profile: &Path, args: &[&str], url: &str) -> (String, String) {
    let out = Command::new(chrome)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--hide-scrollbars",
            "--force-device-scale-factor=1",
            "--allow-file-access-from-files",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(args)
        .arg(url)
        .env("HOME", profile)
        .output()
        .expect("run chromium");
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (text(&out.stdout), text(&out.stderr))
}

fn file_url(p: &Path) -> String {
    format!("file://{}", p.display())
}

/// Console errors in Chromium's log.
fn console_errors(stderr: &str) -> Vec<&str> {
    stderr
        .lines()
        .filter(|l| {
            l.contains("Uncaught")
                || l.contains("ERROR:CONSOLE")
                || (l.contains("CONSOLE") && l.contains("Failed to load"))
                || l.contains("net::ERR_")
        })
        .collect()
}

/// A box on the page [CSS px].
#[derive(Debug)]
struct Box {
    what: String,
    x: f64,
    y: f64,
    w: f64,
    h: f64,
}

/// The wrapper page: frames `page` at the screenshot's width and writes the page's height and
/// every figure's box into its own DOM (read with --dump-dom).
fn measure_boxes(chrome: &Path, profile: &Path, dir: &Path, page: &Path) -> (u32, Vec<Box>) {
    let wrapper = dir.join("measure-boxes.html");
    std::fs::write(
        &wrapper,
        format!(
            "<!DOCTYPE html><html><body style=\"margin:0\"><iframe id=\"f\" src=\"{}\" \
             style=\"border:0;width:{WIDTH}px;height:30000px\" scrolling=\"no\"></iframe>\
             <pre id=\"out\"></pre><script>document.getElementById('f').onload=function(){{\
             var d=this.contentDocument,o=[];o.push('height '+Math.ceil(d.body.getBoundingClientRect().bottom+16));\
             d.querySelectorAll('figure svg, figure img, figure .swatch').forEach(function(e,i){{\
             var r=e.getBoundingClientRect();o.push('box '+(e.getAttribute('aria-label')||\
             e.getAttribute('alt')||e.className||e.tagName)+'|'+r.left+'|'+r.top+'|'+r.width+'|'+r.height);}});\
             document.getElementById('out').textContent=o.join('\\n');}};</script></body></html>",
            file_url(page)
        ),
    )
    .unwrap();
    let (dom, _) = browse(
        chrome,
        profile,
        &[&format!("--window-size={WIDTH},1000"), "--dump-dom"],
        &file_url(&wrapper),
    );
    let out = dom
        .split("<pre id=\"out\">")
        .nth(1)
        .and_then(|s| s.split("</pre>").next())
        .unwrap_or_else(|| panic!("the wrapper wrote nothing:\n{dom}"));
    let mut height = 0;
    let mut boxes = Vec::new();
    for line in out.lines() {
        if let Some(h) = line.strip_prefix("height ") {
            height = h.trim().parse().unwrap();
        } else if let Some(b) = line.strip_prefix("box ") {
            let f: Vec<&str> = b.split('|').collect();
            let n = |k: usize| f[k].parse::<f64>().unwrap();
            boxes.push(Box {
                what: f[0].replace("&amp;", "&"),
                x: n(1),
                y: n(2),
                w: n(3),
                h: n(4),
            });
        }
    }
    (height, boxes)
}

/// The index's η column (its `data-sort` values) as loaded, after one click on its header and
/// after a second: clicks made by a wrapper page that frames the index.
fn sorted_by_clicks(chrome: &Path, profile: &Path, dir: &Path, index: &Path) -> [Vec<f64>; 3] {
    let wrapper = dir.join("sort-check.html");
    std::fs::write(
        &wrapper,
        format!(
            "<!DOCTYPE html><html><body><iframe id=\"f\" src=\"{}\" style=\"width:1200px;\
             height:800px\"></iframe><pre id=\"out\"></pre><script>\
             document.getElementById('f').onload=function(){{var d=this.contentDocument,o=[];\
             var t=d.getElementById('samples-table'),th=t.tHead.rows[0].cells[3];\
             function col(){{return Array.prototype.map.call(t.tBodies[0].rows,function(r){{\
             return r.cells[3].getAttribute('data-sort');}}).join(' ');}}\
             o.push(col());th.click();o.push(col());th.click();o.push(col());\
             document.getElementById('out').textContent=o.join('\\n');}};</script></body></html>",
            file_url(index)
        ),
    )
    .unwrap();
    let (dom, _) = browse(chrome, profile, &["--dump-dom"], &file_url(&wrapper));
    let out = dom
        .split("<pre id=\"out\">")
        .nth(1)
        .and_then(|s| s.split("</pre>").next())
        .unwrap_or_else(|| panic!("the sort wrapper wrote nothing:\n{dom}"));
    let cols: Vec<Vec<f64>> = out
        .lines()
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(cols.len(), 3, "{out}");
    [cols[0].clone(), cols[1].clone(), cols[2].clone()]
}

/// Screenshot of `page` (full height) into `png`.
fn screenshot(chrome: &Path, profile: &Path, page: &Path, height: u32, png: &Path) -> String {
    let (_, stderr) = browse(
        chrome,
        profile,
        &[
            &format!("--window-size={WIDTH},{height}"),
            &format!("--screenshot={}", png.display()),
        ],
        &file_url(page),
    );
    assert!(png.exists(), "no screenshot {}:\n{stderr}", png.display());
    stderr
}

/// Pixels in the box that differ from its most common colour, and the box's pixel count.
fn drawn_pixels(img: &image::RgbaImage, b: &Box) -> (usize, usize) {
    let mut counts = std::collections::HashMap::new();
    let (x0, y0) = (b.x.max(0.0) as u32, b.y.max(0.0) as u32);
    let x1 = ((b.x + b.w) as u32).min(img.width());
    let y1 = ((b.y + b.h) as u32).min(img.height());
    let mut total = 0;
    for y in y0..y1 {
        for x in x0..x1 {
            *counts.entry(img.get_pixel(x, y).0).or_insert(0usize) += 1;
            total += 1;
        }
    }
    let top = counts.values().copied().max().unwrap_or(0);
    (total - top, total)
}

fn demo_pages_load_and_draw_in_chromium(chrome: &Path) {
    let temp = temp_dir();
    let run = run_cached(
        temp.path(),
        &["demo", "--quick", "-o", "demo", "--quiet", "-j", "2"],
    );
    assert_eq!(run.code, 0, "{}\n{}", run.stdout, run.stderr);
    let demo = temp.path().join("demo");
    let index = demo.join("index.html");
    let last = run.stdout.lines().last().unwrap_or_default();
    assert_eq!(
        last,
        format!("index: {}", Path::new("demo/index.html").display())
    );
    let sample = demo.join("wood-tile").join("report.html");
    assert!(sample.exists(), "no {}", sample.display());
    let out = artefacts();
    let profile = temp.path().join("chromium-profile");
    let _ = writeln!(
        std::io::stderr(),
        "browser test: screenshots in {}",
        out.display()
    );

    // The index: loads without errors, its script ran, seven rows linked to their pages.
    let (dom, stderr) = browse(chrome, &profile, &["--dump-dom"], &file_url(&index));
    let errors = console_errors(&stderr);
    assert!(errors.is_empty(), "index.html: {errors:#?}");
    assert!(
        dom.contains("data-ready=\"1\""),
        "the index's script did not run:\n{dom}"
    );
    assert!(dom.contains("<th class=\"sortable\""), "no sort headers");
    assert_eq!(dom.matches("/report.html\">report</a>").count(), 7, "{dom}");
    // Sorting by η: a click sorts ascending, a second descending.
    let [loaded, once, twice] = sorted_by_clicks(chrome, &profile, temp.path(), &index);
    assert_eq!(loaded.len(), 7);
    let mut up = loaded.clone();
    up.sort_by(f64::total_cmp);
    assert_eq!(once, up, "one click");
    up.reverse();
    assert_eq!(twice, up, "two clicks");
    let (h, _) = measure_boxes(chrome, &profile, temp.path(), &index);
    let stderr = screenshot(chrome, &profile, &index, h.max(400), &out.join("index.png"));
    assert!(console_errors(&stderr).is_empty(), "{stderr}");

    // The sample page: no errors, every figure drawn.
    let (height, boxes) = measure_boxes(chrome, &profile, temp.path(), &sample);
    assert!(height > 1000, "page height {height}");
    let png = out.join("wood-tile-report.png");
    let stderr = screenshot(chrome, &profile, &sample, height, &png);
    let errors = console_errors(&stderr);
    assert!(errors.is_empty(), "report.html: {errors:#?}");
    let img = image::open(&png).unwrap().to_rgba8();
    assert_eq!(img.width(), WIDTH);
    let names: Vec<&str> = boxes.iter().map(|b| b.what.as_str()).collect();
    let _ = writeln!(
        std::io::stderr(),
        "browser test: {} pictures and figures on the sample page, {height} px tall: {names:?}",
        boxes.len()
    );
    for want in [
        "Figure 4",
        "Figure 6",
        "false-colour radiance map",
        "camera response",
        "rendered swatch",
    ] {
        assert!(names.contains(&want), "no {want} among {names:?}");
    }
    // Printable: Chromium prints the page to a PDF (kept with the screenshots).
    let pdf = out.join("wood-tile-report.pdf");
    let _ = std::fs::remove_file(&pdf);
    let (_, stderr) = browse(
        chrome,
        &profile,
        &[
            &format!("--print-to-pdf={}", pdf.display()),
            "--no-pdf-header-footer",
        ],
        &file_url(&sample),
    );
    let bytes = std::fs::read(&pdf).unwrap_or_else(|e| panic!("no PDF ({e}):\n{stderr}"));
    assert!(bytes.starts_with(b"%PDF"), "not a PDF");
    assert!(bytes.len() > 100_000, "a {} byte PDF", bytes.len());
    let _ = writeln!(
        std::io::stderr(),
        "browser test: printed to {} ({} bytes)",
        pdf.display(),
        bytes.len()
    );
    for b in &boxes {
        let (drawn, total) = drawn_pixels(&img, b);
        assert!(total > 1000, "{b:?}: a box of {total} px");
        // A flat box (a spectro swatch is one colour by design) is exempt; every picture and
        // figure has at least 2 % of its pixels off its background.
        if b.what != "swatch" {
            assert!(
                drawn * 50 > total,
                "{}: {drawn} of {total} px drawn",
                b.what
            );
        }
    }
}
