//! Text that came from a file or a path, made safe for where it goes: a terminal, a Markdown table,
//! a CSV cell a spreadsheet will open, an SVG's XML, an error message. And numbers for messages.
//!
//! The rules (RELIABILITY.md, "Names reaching the terminal"):
//!
//! | where | what is escaped | how |
//! |---|---|---|
//! | a terminal ([`terminal`]: everything the CLI prints; [`json`]: JSON it prints, as `\u009b` escapes) | C0 controls but newline and tab (ESC starts every terminal escape sequence; CR rewrites a line), DEL, C1 controls (U+0080–U+009F: U+009B is an 8-bit CSI), the bidirectional overrides and isolates (U+202A–U+202E, U+2066–U+2069, U+200E, U+200F, U+061C: they reorder what is shown) | `\u{1b}` |
//! | one value in a line ([`one_line`]: a sample name, a file name) | the above, and newline and tab | `\u{a}` |
//! | quoted content of a file ([`token`]) | as [`one_line`], shortened to [`MAX_TOKEN_CHARS`] characters | `…` |
//! | a Markdown table cell ([`markdown_cell`]) | `\|`, `\`, `<`, `>`, `&` (raw HTML), line breaks, controls | `\|`, `&lt;` |
//! | a CSV cell ([`csv_cell`]) | a leading `=`, `+`, `-`, `@`, tab or CR (a spreadsheet formula) unless the cell is a number; quotes, separators, line breaks | `'=…`, RFC 4180 quoting |
//! | XML text or an attribute ([`xml_text`]) | `&`, `<`, `>`, `"`, `'`; characters XML 1.0 forbids (C0 but tab, LF, CR; U+FFFE, U+FFFF) | entities; U+FFFD |

use std::borrow::Cow;
use std::fmt::Write as _;

/// Most characters of a file's content quoted in a message ([`token`]).
pub const MAX_TOKEN_CHARS: usize = 40;

/// True for a character a terminal may act on rather than show (newline and tab excepted).
fn is_terminal_control(c: char) -> bool {
    matches!(c,
        '\u{0}'..='\u{8}' | '\u{b}'..='\u{1f}' | '\u{7f}'..='\u{9f}'
        | '\u{61c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

fn escaped(c: char) -> String {
    format!("\\u{{{:x}}}", u32::from(c))
}

/// `text` with every character a terminal would act on (an escape sequence, a carriage return, a
/// bidirectional override) written as `\u{…}`; newlines and tabs are kept. What the command-line
/// tool applies to everything it prints.
pub fn terminal(text: &str) -> Cow<'_, str> {
    if !text.chars().any(is_terminal_control) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if is_terminal_control(c) {
            out.push_str(&escaped(c));
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// JSON text with the characters a terminal acts on that JSON leaves raw (C1 controls, DEL,
/// bidirectional controls; C0 is already escaped by serde_json) written as `\uXXXX` escapes: the
/// same JSON value, safe to print.
pub fn json(json: &str) -> Cow<'_, str> {
    // DEL, C1 and the bidirectional controls: the terminal controls that are not C0.
    let bad = |c: char| (is_terminal_control(c) && !c.is_ascii_control()) || c == '\u{7f}';
    if !json.chars().any(bad) {
        return Cow::Borrowed(json);
    }
    let mut out = String::with_capacity(json.len() + 16);
    for c in json.chars() {
        if bad(c) {
            let _ = write!(out, "\\u{:04x}", u32::from(c));
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// [`terminal`], and newlines and tabs escaped too: one value that must stay on its line (a sample
/// name, a file name in a list).
pub fn one_line(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if is_terminal_control(c) || c == '\n' || c == '\t' {
            out.push_str(&escaped(c));
        } else {
            out.push(c);
        }
    }
    out
}

/// A piece of a file's content as a message may quote it: [`one_line`], at most
/// [`MAX_TOKEN_CHARS`] characters (then `…`).
pub fn token(text: &str) -> String {
    let short: String = text.chars().take(MAX_TOKEN_CHARS).collect();
    let mut out = one_line(&short);
    if text.chars().nth(MAX_TOKEN_CHARS).is_some() {
        out.push('…');
    }
    out
}

/// A message of another library (a parser's) with every quoted segment — `` `…` `` or `"…"` — made a
/// [`token`]: shortened and escaped.
pub fn shorten_quotes(message: &str) -> String {
    map_quotes(message, token)
}

/// A message of another library with its quoted segments removed unless `keep` accepts them
/// (replaced by `…`): for a file not yet recognised as the kind expected, whose content a message
/// may not show. Punctuation-only segments (`` `=` ``, `` `]` ``) are kept.
pub fn redact_quotes(message: &str, keep: impl Fn(&str) -> bool) -> String {
    map_quotes(message, |q| {
        if keep(q) || (!q.is_empty() && q.chars().all(|c| c.is_ascii_punctuation())) {
            one_line(q)
        } else {
            "…".into()
        }
    })
}

fn map_quotes(message: &str, mut f: impl FnMut(&str) -> String) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(start) = rest.find(['`', '"']) {
        let quote = rest[start..].chars().next().unwrap_or('`');
        out.push_str(&terminal(&rest[..start]));
        let after = &rest[start + 1..];
        // A `"…"` segment may hold escaped quotes (`\"`), as serde's messages write them.
        let end = if quote == '"' {
            let mut i = 0;
            let bytes = after.as_bytes();
            let mut found = None;
            while i < bytes.len() {
                match bytes[i] {
                    b'\\' => i += 2,
                    b'"' => {
                        found = Some(i);
                        break;
                    }
                    _ => i += 1,
                }
            }
            found
        } else {
            after.find('`')
        };
        match end {
            Some(e) => {
                out.push(quote);
                out.push_str(&f(&after[..e]));
                out.push(quote);
                rest = &after[e + 1..];
            }
            None => {
                out.push(quote);
                out.push_str(&f(after));
                rest = "";
            }
        }
    }
    out.push_str(&terminal(rest));
    out
}

/// A number for a message: at most 6 significant digits (`0.123457`, `1.5e300`, `-2.5e-7`), `NaN`,
/// `inf`. A value read from a file is shown this way, never with its 300 digits.
pub fn number(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    let exp = a.log10().floor() as i32;
    let text = if (-4..6).contains(&exp) {
        let decimals = (5 - exp).max(0) as usize;
        trim_zeros(format!("{v:.decimals$}"))
    } else {
        let s = format!("{v:.5e}");
        match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim_zeros(m.to_string())),
            None => s,
        }
    };
    // Rounding may carry into a new digit (999999.5 → 1000000): still ≤ 6 significant digits.
    text
}

fn trim_zeros(s: String) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A cell of a Markdown table: `|` and `\` escaped, raw HTML defused (`<`, `>`, `&` as entities),
/// line breaks and controls escaped ([`one_line`]).
pub fn markdown_cell(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in one_line(text).chars() {
        match c {
            '|' => out.push_str("\\|"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            _ => out.push(c),
        }
    }
    out
}

/// A CSV cell (RFC 4180) a spreadsheet can open safely: text starting with `=`, `+`, `-`, `@`, a tab
/// or a carriage return is a formula to Excel, LibreOffice and Google Sheets (`=HYPERLINK(…)`,
/// `=cmd|…`), so it gets a leading `'` (OWASP's advice), unless the whole cell is a number (`-0.5`);
/// a cell holding `,`, `;`, `"`, a line break or leading/trailing spaces is quoted, with `"` doubled;
/// line breaks become spaces.
pub fn csv_cell(text: &str) -> String {
    let mut cell = text.replace(['\n', '\r'], " ");
    let formula =
        text.starts_with(['=', '+', '-', '@', '\t', '\r']) && text.parse::<f64>().is_err();
    if formula {
        cell.insert(0, '\'');
    }
    let cell = terminal(&cell).into_owned();
    if cell.contains([',', ';', '"', '\t']) || cell.starts_with(' ') || cell.ends_with(' ') {
        format!("\"{}\"", cell.replace('"', "\"\""))
    } else {
        cell
    }
}

/// Text for XML (an SVG's `<text>` or an attribute value): the five special characters as entities,
/// and characters XML 1.0 forbids (C0 controls but tab, newline and CR; U+FFFE, U+FFFF) replaced by
/// U+FFFD, so that the document stays well-formed for any name.
pub fn xml_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(c),
            c if xml_forbidden(c) => out.push('\u{fffd}'),
            _ => out.push(c),
        }
    }
    out
}

/// `text` with the characters XML 1.0 forbids (C0 controls but tab, newline and CR; U+FFFE,
/// U+FFFF) replaced by U+FFFD: for text handed to an XML writer that escapes `&`, `<`, `>`, `"`
/// and `'` itself (plotters' SVG backend), or for a finished document.
pub fn xml_chars(text: &str) -> Cow<'_, str> {
    if !text.chars().any(xml_forbidden) {
        return Cow::Borrowed(text);
    }
    Cow::Owned(
        text.chars()
            .map(|c| if xml_forbidden(c) { '\u{fffd}' } else { c })
            .collect(),
    )
}

/// A character XML 1.0 does not allow in a document.
fn xml_forbidden(c: char) -> bool {
    matches!(c, '\u{0}'..='\u{8}' | '\u{b}' | '\u{c}' | '\u{e}'..='\u{1f}' | '\u{fffe}' | '\u{ffff}')
}

/// A list of names for a message, each a [`token`], joined by `, `.
pub fn tokens<'a>(items: impl IntoIterator<Item = &'a str>) -> String {
    let mut out = String::new();
    for (i, t) in items.into_iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        let _ = write!(out, "{}", token(t));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// JSON made safe for a terminal is still the same JSON value.
    #[test]
    fn json_keeps_its_value() {
        let name = "a\u{9b}2J\u{202e}b\u{1b}[31m\u{7f}";
        let text = serde_json::to_string(&serde_json::json!({ "name": name })).unwrap();
        let safe = json(&text);
        assert!(
            !safe.contains(['\u{9b}', '\u{202e}', '\u{1b}', '\u{7f}']),
            "{safe}"
        );
        let back: serde_json::Value = serde_json::from_str(&safe).unwrap();
        assert_eq!(back["name"], name);
    }

    /// Hostile names of our own (beyond the first ones found): an ANSI colour and title-setting sequence,
    /// an 8-bit CSI, a carriage return that would overwrite "failed" with "ok", a right-to-left
    /// override that reorders a file name, a NUL, DEL.
    #[test]
    fn terminal_controls_are_shown_not_acted_on() {
        let hostile = "a\u{1b}[31mred\u{1b}]0;title\u{7}\rok\u{9b}2J\u{202e}gnp.exe\0\u{7f}";
        let t = terminal(hostile);
        assert!(!t.chars().any(is_terminal_control), "{t}");
        assert_eq!(
            t,
            "a\\u{1b}[31mred\\u{1b}]0;title\\u{7}\\u{d}ok\\u{9b}2J\\u{202e}gnp.exe\\u{0}\\u{7f}"
        );
        assert_eq!(
            terminal("line\n\tnext, grün °C µ"),
            "line\n\tnext, grün °C µ"
        );
        assert_eq!(one_line("a\nb\tc"), "a\\u{a}b\\u{9}c");
    }

    #[test]
    fn tokens_are_short() {
        let long = "x".repeat(100);
        assert_eq!(token(&long), format!("{}…", "x".repeat(40)));
        assert_eq!(token("abc"), "abc");
        assert_eq!(
            shorten_quotes(&format!("unknown variant `{long}`, expected `dipole`")),
            format!("unknown variant `{}…`, expected `dipole`", "x".repeat(40))
        );
        assert_eq!(
            shorten_quotes(r#"invalid type: string "a\"b\u001b", expected f64"#),
            r#"invalid type: string "a\"b\u001b", expected f64"#
        );
        assert_eq!(
            redact_quotes(
                "unknown field `token`, expected one of `name`, `spectro`; expected `=`",
                |q| q == "name" || q == "spectro"
            ),
            "unknown field `…`, expected one of `name`, `spectro`; expected `=`"
        );
        assert_eq!(
            redact_quotes("value \"root:$6$x\"", |_| false),
            "value \"…\""
        );
    }

    #[test]
    fn numbers_have_at_most_six_significant_digits() {
        for (v, s) in [
            (1e300, "1e300"),
            (1.234_567_89e300, "1.23457e300"),
            (-2.5e-7, "-2.5e-7"),
            (0.123_456_789, "0.123457"),
            (1.979, "1.979"),
            (1_234_567.0, "1.23457e6"),
            (999_999.0, "999999"),
            (0.0, "0"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
            (f64::MAX, "1.79769e308"),
            (5e-324, "4.94066e-324"),
            (100.0, "100"),
        ] {
            assert_eq!(number(v), s, "{v:e}");
            let digits = s
                .split('e')
                .next()
                .unwrap()
                .chars()
                .filter(char::is_ascii_digit)
                .collect::<String>();
            assert!(digits.trim_start_matches('0').len() <= 6, "{s}");
        }
    }

    #[test]
    fn markdown_cells_cannot_break_the_table_or_inject_html() {
        assert_eq!(
            markdown_cell("a|b<script>alert(1)</script>&\nrow"),
            "a\\|b&lt;script&gt;alert(1)&lt;/script&gt;&amp;\\u{a}row"
        );
    }

    /// Formula injection: every leading character a spreadsheet treats as a formula, and cells that
    /// need quoting; numbers stay numbers.
    #[test]
    fn csv_cells_are_not_formulas() {
        for (raw, cell) in [
            (
                "=HYPERLINK(\"http://x\",\"y\")",
                "\"'=HYPERLINK(\"\"http://x\"\",\"\"y\"\")\"",
            ),
            ("+1+cmd|' /C calc'!A0", "'+1+cmd|' /C calc'!A0"),
            ("-2+3", "'-2+3"),
            ("@SUM(A1)", "'@SUM(A1)"),
            ("\t=1", "\"'\t=1\""),
            ("\r=1", "' =1"),
            ("-0.5", "-0.5"),
            ("+1e3", "+1e3"),
            ("wood, oak", "\"wood, oak\""),
            ("a\nb", "a b"),
            ("plain", "plain"),
        ] {
            assert_eq!(csv_cell(raw), cell, "{raw:?}");
        }
    }

    #[test]
    fn xml_text_is_well_formed_for_any_name() {
        let hostile = "</text><script>&\"'\u{1}\u{1b}\u{fffe}é";
        let x = xml_text(hostile);
        assert_eq!(
            x,
            "&lt;/text&gt;&lt;script&gt;&amp;&quot;&apos;\u{fffd}\u{fffd}\u{fffd}é"
        );
    }
}
