//! Escaping for the HTML pages, and the small pieces every page shares (head, style, base64 data
//! URIs).
//!
//! Every text that comes from a file or a path (a sample's name, a file name, a check's message,
//! the options as given) goes through [`text`] (may hold line breaks) or [`name`] (one line)
//! before it reaches the page. Both reuse `scatterfit_io::escape`: controls and the
//! bidirectional overrides are shown as `\u{…}` (a name cannot reorder or hide what follows it),
//! then `&`, `<`, `>`, `"` and `'` become entities (`xml_text`), so the result is safe in element
//! content and in a quoted attribute alike.

use scatterfit_io::escape::{one_line, terminal, xml_text};

/// A one-line value from a file (a name, a path) for HTML text or a quoted attribute: line breaks,
/// tabs, controls and bidirectional overrides as `\u{…}`, the five special characters as entities.
pub fn name(s: &str) -> String {
    xml_text(&one_line(s))
}

/// A message or a block from a file for HTML text (`<pre>` or a paragraph): controls and
/// bidirectional overrides as `\u{…}` (line breaks and tabs kept), the five special characters as
/// entities.
pub fn text(s: &str) -> String {
    xml_text(&terminal(s))
}

/// A link target made from a relative path: each segment percent-encoded (RFC 3986 unreserved
/// characters kept), so that no path can become `javascript:` or leave the attribute.
pub fn href(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    for (i, seg) in path.split('/').enumerate() {
        if i > 0 {
            out.push('/');
        }
        for b in seg.bytes() {
            if b.is_ascii_alphanumeric() || matches!(b, b'-' | b'.' | b'_' | b'~') {
                out.push(char::from(b));
            } else {
                out.push_str(&format!("%{b:02X}"));
            }
        }
    }
    // A first segment with a colon would be a scheme; percent-encoding made it `%3A`.
    out
}

const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 (RFC 4648 §4, padded).
pub fn base64(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(char::from(B64[((n >> (18 - 6 * k)) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A PNG as a `data:` URI.
pub fn png_data_uri(png: &[u8]) -> String {
    format!("data:image/png;base64,{}", base64(png))
}

/// The colours of the pages: the Okabe & Ito (2008) palette, distinguishable with the common
/// colour-vision deficiencies, and each verdict also spelt out in words.
pub(crate) const STYLE: &str = r#"
:root { --ok:#009E73; --suspect:#E69F00; --failed:#D55E00; --note:#56B4E9; --ink:#1a1a1a; --muted:#555; --rule:#ccc; }
* { box-sizing: border-box; }
body { font: 15px/1.45 system-ui, -apple-system, "Segoe UI", "DejaVu Sans", sans-serif; color: var(--ink); margin: 0 auto; max-width: 1240px; padding: 1rem 1.5rem 3rem; background: #fff; }
h1 { font-size: 1.6rem; margin: .2rem 0 .4rem; }
h2 { font-size: 1.2rem; margin: 1.8rem 0 .5rem; border-bottom: 1px solid var(--rule); padding-bottom: .2rem; }
h3 { font-size: 1rem; margin: 1rem 0 .3rem; }
p.meta, .muted { color: var(--muted); }
table { border-collapse: collapse; margin: .4rem 0; }
th, td { border: 1px solid var(--rule); padding: .25rem .55rem; text-align: left; vertical-align: top; }
th { background: #f3f3f3; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
.err { color: var(--muted); font-size: .85em; white-space: nowrap; }
.verdict { display: inline-block; padding: .05rem .5rem; border-radius: .7rem; font-weight: 600; border: 2px solid; }
.verdict.ok { border-color: var(--ok); color: #005a42; }
.verdict.suspect { border-color: var(--suspect); color: #7a5200; background: #fff6e0; }
.verdict.failed { border-color: var(--failed); color: #8a3200; background: #fdebe0; }
.verdict.note { border-color: var(--note); color: #1d5d80; }
.verdict.ok::before { content: "\2713\00a0"; }
.verdict.suspect::before { content: "!\00a0"; }
.verdict.failed::before { content: "\2717\00a0"; }
ul.reasons { margin: .2rem 0 .6rem; padding-left: 1.2rem; }
figure { margin: .6rem 0 1rem; }
figure svg, figure img { max-width: 100%; height: auto; display: block; }
figcaption { color: var(--muted); font-size: .9em; margin-top: .3rem; }
.row { display: flex; flex-wrap: wrap; gap: 1rem; align-items: flex-start; }
.thumbs { display: flex; flex-wrap: wrap; gap: .4rem; }
.thumbs figure { margin: 0; width: 96px; }
.thumbs img { width: 96px; image-rendering: pixelated; border: 1px solid var(--rule); }
.thumbs figcaption { font-size: .75em; margin: 0; }
.swatch { width: 160px; height: 160px; border: 1px solid var(--rule); }
figure.swatchbox { width: 200px; }
.scroll { overflow-x: auto; }
td.rgbv { min-width: 13rem; font-size: .9em; }
.nowrap { white-space: nowrap; }
.why { display: block; font-size: .85em; color: var(--muted); margin-top: .2rem; }
body.wide { max-width: none; }
td.sample { min-width: 11rem; }
#samples-table { font-size: .92em; }
td.links { white-space: nowrap; }
td.sample .path { font-size: .75em; }
pre { background: #f6f6f6; padding: .5rem; overflow-x: auto; font-size: .85em; white-space: pre-wrap; word-break: break-all; }
code, .path { font-family: "DejaVu Sans Mono", monospace; font-size: .9em; word-break: break-all; }
th.sortable { cursor: pointer; user-select: none; }
th.sortable::after { content: " \2195"; color: var(--muted); }
th[aria-sort="ascending"]::after { content: " \2191"; }
th[aria-sort="descending"]::after { content: " \2193"; }
nav a { margin-right: 1rem; }
@media print { body { max-width: none; padding: 0; } nav { display: none; } h2 { break-after: avoid; } figure, table { break-inside: avoid; } }
"#;

/// The page's start: doctype, `<head>` with the title (escaped here) and the style.
pub(crate) fn head(title: &str) -> String {
    head_with(title, "")
}

/// [`head`] with a class on `<body>` (`wide`: no maximum width, for the index's table).
pub(crate) fn head_with(title: &str, body_class: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <meta name=\"generator\" content=\"scatterfit {}\">\n<title>{}</title>\n<style>{STYLE}</style>\n\
         </head>\n<body class=\"{}\">\n",
        env!("CARGO_PKG_VERSION"),
        name(title),
        name(body_class)
    )
}

/// A verdict badge: the word in a coloured outline (the word carries the meaning, the colour
/// repeats it).
pub(crate) fn badge(verdict: &str) -> String {
    let class = match verdict {
        "ok" | "suspect" | "failed" => verdict,
        _ => "note",
    };
    format!("<span class=\"verdict {class}\">{}</span>", name(verdict))
}

/// An inline SVG made by plotters (or by hand) for an HTML body: the XML declaration dropped, a
/// `viewBox` added from its `width` and `height` so that it scales with the page, and a role and
/// label for screen readers.
pub(crate) fn inline_svg(svg: &str, label: &str) -> String {
    let body = svg
        .trim_start()
        .strip_prefix("<?xml")
        .and_then(|s| s.find("?>").map(|k| &s[k + 2..]))
        .unwrap_or(svg)
        .trim_start();
    let Some(rest) = body.strip_prefix("<svg") else {
        return String::new();
    };
    let attr = |key: &str| -> Option<&str> {
        let open = &rest[..rest.find('>')?];
        let k = open.find(&format!("{key}=\""))? + key.len() + 2;
        let end = open[k..].find('"')?;
        Some(&open[k..k + end])
    };
    let view_box = match (attr("viewBox"), attr("width"), attr("height")) {
        (Some(_), _, _) => String::new(),
        (None, Some(w), Some(h)) => format!(" viewBox=\"0 0 {w} {h}\""),
        _ => String::new(),
    };
    // The drawing's text came from files too (a sample's name in a title): XML's escaping made it
    // markup-safe; the controls XML allows (CR, C1) and the bidirectional overrides go here.
    let rest: String = rest
        .chars()
        .map(|c| {
            if c == '\r' || is_hidden_control(c) {
                '\u{fffd}'
            } else {
                c
            }
        })
        .collect();
    format!(
        "<svg role=\"img\" aria-label=\"{}\"{view_box}{rest}",
        name(label)
    )
}

/// C1 controls and the bidirectional overrides and isolates: allowed in XML, acted on (not shown)
/// by text layout.
fn is_hidden_control(c: char) -> bool {
    matches!(c, '\u{7f}'..='\u{9f}' | '\u{61c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}'
        | '\u{2066}'..='\u{2069}')
}
