//! Tests of the HTML writer: escaping of every field that comes from a file (names, paths,
//! messages, options), links, base64, and the pages' shape. The hostile strings are the ones a
//! sample folder can carry: markup, quotes, `&`, line breaks, terminal and bidirectional controls.

use scatterfit_io::result_json::MeasurementResult;

use super::markup::{base64, href, inline_svg, name, text};
use super::{IndexEntry, IndexPage, SampleExtras, index_html, sample_html};

/// A name or message written to break out of its element, its attribute, or the page.
const HOSTILE: &str =
    "<script>alert(\"x\")</script> & 'q' \"d\"\nline2\r\t\u{1b}[31m\u{7}\u{202e}evil\u{9b}";

/// Characters that must never reach a page raw: C0 controls but tab, LF and CR; DEL; C1; the
/// bidirectional overrides and isolates.
fn is_forbidden(c: char) -> bool {
    matches!(c,
        '\u{0}'..='\u{8}' | '\u{b}' | '\u{c}' | '\u{e}'..='\u{1f}' | '\u{7f}'..='\u{9f}'
        | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// Checks what holds for any page whatever went into it: no forbidden character, no `<script`
/// but the page's own (`scripts` of them), every `<` opening a tag, a comment or the doctype.
fn check_page(page: &str, scripts: usize) {
    if let Some(c) = page.chars().find(|c| is_forbidden(*c)) {
        panic!("forbidden character U+{:04X} in the page", u32::from(c));
    }
    assert_eq!(
        page.matches("<script").count(),
        scripts,
        "scripts in:\n{page}"
    );
    for (i, _) in page.match_indices('<') {
        let next = page[i + 1..].chars().next().unwrap_or(' ');
        assert!(
            next.is_ascii_alphabetic() || next == '/' || next == '!',
            "a raw `<` at byte {i}: {}",
            &page[i.saturating_sub(40)..(i + 40).min(page.len())]
        );
    }
    assert!(
        !page.contains("alert(\"x\")"),
        "raw hostile text in the page"
    );
    assert!(!page.contains("'q'"), "a raw quote from a file in the page");
}

fn hostile_result() -> MeasurementResult {
    let channel = |verdict: &str| {
        serde_json::json!({
            "status": if verdict == "failed" { "failed" } else { "ok" },
            "sigma_s_prime": 1.25, "sigma_s_prime_stderr": 0.01, "sigma_s_prime_stderr_spectro": 0.02,
            "sigma_a": 0.0125, "sigma_a_stderr": 0.001,
            "albedo_prime": 0.99, "rd_total": 0.5, "mse": 0.1,
            "problem": HOSTILE,
            "quality": { "verdict": verdict, "reasons": [
                { "kind": "poor_fit", "severity": verdict, "message": HOSTILE } ] }
        })
    };
    let file = serde_json::json!({
        "name": HOSTILE, "eta": 1.3, "eta_source": "spectro", "method": "proposed",
        "model": "dipole", "albedo_model": "diffusion",
        "channels": { "r": channel("ok"), "g": channel("suspect"), "b": channel("failed") },
        "inputs": {
            "sample_dir": HOSTILE,
            "manifest": { "path": HOSTILE, "sha256": HOSTILE },
            "frames": [ { "path": format!("frames/{HOSTILE}.png"), "sha256": "00" } ],
            "options": { "note": HOSTILE }
        },
        "version": HOSTILE
    });
    // A file of the first schema (flat error keys), read as every consumer reads one.
    scatterfit_io::result_json::parse_result_json(&file.to_string(), std::path::Path::new("r.json"))
        .expect("a result")
}

#[test]
fn name_escapes_markup_quotes_ampersands_and_controls() {
    let e = name(HOSTILE);
    assert!(e.starts_with("&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; &amp; &apos;q&apos;"));
    // Line breaks, tabs and controls are shown, never acted on.
    assert!(
        e.contains("\\u{a}line2\\u{d}\\u{9}\\u{1b}[31m\\u{7}\\u{202e}evil\\u{9b}"),
        "{e}"
    );
    assert!(!e.chars().any(|c| c.is_control() || is_forbidden(c)));
}

#[test]
fn text_keeps_line_breaks_and_escapes_the_rest() {
    let e = text("a < b & c\n\"d\"\u{1b}");
    assert_eq!(e, "a &lt; b &amp; c\n&quot;d&quot;\\u{1b}");
}

#[test]
fn href_cannot_become_a_scheme_or_leave_its_attribute() {
    assert_eq!(href("javascript:alert(1)"), "javascript%3Aalert%281%29");
    assert_eq!(href("my sample/report.html"), "my%20sample/report.html");
    assert_eq!(href("a\"b/<c>"), "a%22b/%3Cc%3E");
    assert_eq!(href("é"), "%C3%A9");
}

#[test]
fn base64_matches_rfc_4648_test_vectors() {
    // RFC 4648 §10.
    for (plain, coded) in [
        ("", ""),
        ("f", "Zg=="),
        ("fo", "Zm8="),
        ("foo", "Zm9v"),
        ("foob", "Zm9vYg=="),
        ("fooba", "Zm9vYmE="),
        ("foobar", "Zm9vYmFy"),
    ] {
        assert_eq!(base64(plain.as_bytes()), coded, "{plain}");
    }
}

#[test]
fn inline_svg_drops_the_declaration_and_scales() {
    let svg = "<?xml version=\"1.0\"?>\n<svg width=\"300\" height=\"100\" xmlns=\"http://www.w3.org/2000/svg\"><rect/></svg>";
    let s = inline_svg(svg, "a \"label\"");
    assert!(s.starts_with("<svg role=\"img\" aria-label=\"a &quot;label&quot;\" viewBox=\"0 0 300 100\" width=\"300\""), "{s}");
    assert!(!s.contains("<?xml"));
    assert_eq!(inline_svg("not svg", "x"), "");
    // Controls XML allows but text layout acts on are replaced.
    let s = inline_svg("<svg><text>a\u{9b}b\u{202e}c</text></svg>", "x");
    assert!(s.ends_with("<text>a\u{fffd}b\u{fffd}c</text></svg>"), "{s}");
}

#[test]
fn sample_page_escapes_every_field_from_a_file() {
    let r = hostile_result();
    let svg = format!(
        "<svg width=\"10\" height=\"10\"><text>{}</text></svg>",
        scatterfit_io::escape::xml_text(HOSTILE)
    );
    let extras = SampleExtras {
        fit_svg: Some(svg.clone()),
        compare_svg: Some(svg),
        response_svg: None,
        thumbnails: vec![(HOSTILE.into(), 0.01, vec![1, 2, 3])],
        files: vec![HOSTILE.into(), "result.json".into()],
        swatch: Some((vec![0], HOSTILE.into())),
        ..SampleExtras::default()
    };
    let page = sample_html(&r, &extras);
    check_page(&page, 0);
    // The hostile name is shown, escaped, in the title and the heading.
    let shown = name(HOSTILE);
    assert!(page.contains(&format!("<title>{shown} — scatterfit report</title>")));
    assert!(page.contains(&format!("<h1>{shown}</h1>")));
    // The per-channel verdicts and the reason's message.
    for v in ["ok", "suspect", "failed"] {
        assert!(
            page.contains(&format!("<span class=\"verdict {v}\">{v}</span>")),
            "{v}"
        );
    }
    assert!(page.contains(&text(HOSTILE)));
    // The uncertainty terms of σ′s: fit and spectro.
    assert!(page.contains("<td class=\"num\">1.250</td><td class=\"num err\">0.01000</td><td class=\"num err\">0.02000</td>"), "{page}");
    // A link from a file name is percent-encoded.
    assert!(page.contains("<a href=\"%3Cscript%3Ealert"));
}

#[test]
fn index_escapes_names_folders_links_and_failure_messages() {
    let r = hostile_result();
    let page = IndexPage {
        title: HOSTILE.into(),
        intro: HOSTILE.into(),
        samples: vec![IndexEntry {
            result: &r,
            folder: HOSTILE.into(),
            page: Some(format!("{HOSTILE}/report.html")),
            links: vec![(HOSTILE.into(), "javascript:alert(1)".into())],
        }],
        failures: vec![(HOSTILE.into(), HOSTILE.into())],
        files: vec![HOSTILE.into()],
    };
    let html = index_html(&page);
    check_page(&html, 1);
    assert!(!html.contains("href=\"javascript:"));
    assert!(html.contains("javascript%3Aalert%281%29"));
    // One click to the sample's page and to its evidence.
    assert!(
        html.contains("/report.html\">report</a><br><a href=\"%3Cscript%3E"),
        "{html}"
    );
    assert!(html.contains("/report.html#evidence\">evidence</a>"));
    // One row, its verdict (the worst channel's) and its sort key.
    assert_eq!(
        html.matches("<tr><td class=\"sample\" data-sort=").count(),
        1
    );
    assert!(html.contains("<td data-sort=\"2\"><span class=\"verdict failed\">failed</span></td>"));
    assert!(html.contains("1 could not be measured"));
}

#[test]
fn index_sort_keys_are_numbers() {
    let r = hostile_result();
    let page = IndexPage {
        title: "t".into(),
        samples: vec![IndexEntry {
            result: &r,
            folder: "f".into(),
            page: None,
            links: Vec::new(),
        }],
        ..IndexPage::default()
    };
    let html = index_html(&page);
    // η and σ′s as exact numbers for the sort, four significant figures shown.
    assert!(html.contains("data-sort=\"1.3e0\">1.300</td>"), "{html}");
    assert!(html.contains("data-sort=\"1.25e0\">1.250<br><span class=\"err\">± "));
}

#[test]
fn sample_page_sections_come_in_a_readers_order() {
    let r = hostile_result();
    let svg = "<svg width=\"10\" height=\"10\"></svg>".to_string();
    let extras = SampleExtras {
        fit_svg: Some(svg.clone()),
        compare_svg: Some(svg),
        ..SampleExtras::default()
    };
    let page = sample_html(&r, &extras);
    let at = |id: &str| {
        page.find(&format!("<section id=\"{id}\""))
            .unwrap_or_else(|| panic!("no section {id}"))
    };
    let order = ["verdict", "table1", "fig4", "fig6", "evidence", "inputs"].map(at);
    assert!(order.windows(2).all(|w| w[0] < w[1]), "{order:?}");
    // Without the existing method's fit there is no Figure 6, nor a link to it.
    let page = sample_html(&r, &SampleExtras::default());
    assert!(!page.contains("id=\"fig6\"") && !page.contains("href=\"#fig6\""));
}

#[test]
fn spectro_colour_is_srgb_of_the_channels_rd() {
    // IEC 61966-2-1: linear 0.5 → 1.055 · 0.5^(1/2.4) − 0.055 = 0.7354 → code 188 (0xbc).
    assert_eq!(super::view::srgb8(0.5), 188);
    assert_eq!(super::view::srgb8(0.0), 0);
    assert_eq!(super::view::srgb8(1.5), 255);
    let page = sample_html(&hostile_result(), &SampleExtras::default());
    assert!(page.contains("background:rgb(188,188,188)") && page.contains("sRGB #bcbcbc"));
}

#[test]
fn the_sample_page_is_a_result_file_the_outputs_check_protects() {
    // pipeline::outputs guards (links, inputs, other samples' results) the files it lists.
    assert!(scatterfit_pipeline::outputs::RESULT_FILES.contains(&super::SAMPLE_PAGE));
}

/// Table 1 shows α′'s fit term (behind a spectrophotometer port, `albedo_prime_stderr_fit`) in a
/// column of its own, and every row keeps as many cells as the header; without it, no column.
#[test]
fn table_1_shows_the_albedo_fit_term_when_there_is_one() {
    let table = |page: &str| -> String {
        let start = page.find("<section id=\"table1\"").expect("Table 1");
        let end = start + page[start..].find("</table>").expect("its end");
        page[start..end].to_string()
    };
    let mut r = hostile_result();
    let without = table(&sample_html(&r, &SampleExtras::default()));
    assert_eq!(without.matches("<th>± fit</th>").count(), 2, "{without}");
    r.channels.r.albedo_prime.as_mut().expect("α′").fit = Some(1.2345e-5);
    let with = table(&sample_html(&r, &SampleExtras::default()));
    assert_eq!(with.matches("<th>± fit</th>").count(), 3, "{with}");
    assert!(
        with.contains("1.234e-5") || with.contains("1.235e-5"),
        "{with}"
    );
    // Header: channel, 4 + 4 + 4 value/term columns, Rd; each row the same 14 cells.
    for row in with.split("<tr><th>").skip(1).filter(|r| r.contains("num")) {
        let cells = row.matches("<td").count() + 1;
        assert_eq!(cells, 14, "{row}");
    }
}
