//! Every citation in the repository resolves inside the repository.
//!
//! The code cites its physics as `docs/physics.md §N.M`, its reference data as files under `data/`,
//! and its own documents (`ARCHITECTURE.md`, `BENCHMARKS.md`, `CHANGELOG.md`, `RELIABILITY.md`,
//! `README.md`), often with a quoted section name. A reader of the published code must be able to
//! follow each one, so this test scans every `.rs`, `.md` and `.toml` file of the workspace (not
//! `target/` or hidden folders) and fails, listing them all, on
//! - a section number after `docs/physics.md` that is not a heading of that file (ranges such as
//!   `§4.2–4.4` and lists such as `§3, §10` check every number);
//! - the physics notes named without their folder, which is how the code cited the project's old
//!   reference sheet outside the repository;
//! - a `data/` path that is not a file;
//! - a quoted section name after one of the documents above that the document does not contain;
//! - any mention of the folder outside the repository the project started from, or of its two
//!   briefs (style and design), none of which a reader has.
//!
//! `scripts/fix_citations.sh` rewrites the old forms into these.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The workspace root (this crate is `crates/optics`).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every `.rs`, `.md` and `.toml` file under `dir`, skipping `target` and hidden folders.
fn source_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            if name != "target" && !name.starts_with('.') {
                source_files(&path, out);
            }
        } else if ["rs", "md", "toml"]
            .iter()
            .any(|ext| path.extension().is_some_and(|e| e == *ext))
        {
            out.push(path);
        }
    }
}

/// The section numbers that are headings of a Markdown file: `## 1. Title` → "1",
/// `### 4.3 Title` → "4.3".
fn headings(markdown: &str) -> BTreeSet<String> {
    markdown
        .lines()
        .filter(|l| l.starts_with('#'))
        .filter_map(|l| {
            let first = l.trim_start_matches('#').split_whitespace().next()?;
            let number = first.trim_end_matches('.');
            is_section_number(number).then(|| number.to_string())
        })
        .collect()
}

/// `1`, `4.3`, `10`: digits separated by single dots.
fn is_section_number(s: &str) -> bool {
    !s.is_empty()
        && s.split('.')
            .all(|p| !p.is_empty() && p.chars().all(|c| c.is_ascii_digit()))
}

/// The longest section number at the start of `s` (a sentence's final dot is not part of it).
fn leading_number(s: &str) -> Option<&str> {
    let end = s
        .char_indices()
        .find(|&(_, c)| !(c.is_ascii_digit() || c == '.'))
        .map_or(s.len(), |(i, _)| i);
    let n = s[..end].trim_end_matches('.');
    is_section_number(n).then_some(n)
}

/// The line number (1-based) of byte offset `at`.
fn line_of(text: &str, at: usize) -> usize {
    text[..at].matches('\n').count() + 1
}

/// Skips what may stand between a document's name and its section sign: a closing backtick,
/// spaces, a line break and the next line's comment marker (`///`, `//!`, `//`).
fn skip_to_section_sign(s: &str) -> &str {
    let mut rest = s.trim_start_matches('`');
    loop {
        let trimmed = rest.trim_start();
        let unmarked = trimmed
            .strip_prefix("///")
            .or_else(|| trimmed.strip_prefix("//!"))
            .or_else(|| trimmed.strip_prefix("//"))
            .unwrap_or(trimmed);
        if unmarked.len() == rest.len() {
            return rest;
        }
        rest = unmarked;
    }
}

/// The section numbers cited right after a mention of the physics notes: `§4.1`, `§4.2–4.4`,
/// `§3, §10`, `§2.1 and §3`.
fn cited_sections(after: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = skip_to_section_sign(after);
    while let Some(r) = rest.strip_prefix('§') {
        let r = r.trim_start();
        let Some(n) = leading_number(r) else { break };
        out.push(n.to_string());
        let mut r = &r[n.len()..];
        for dash in ['–', '-'] {
            if let Some(tail) = r.strip_prefix(dash)
                && let Some(m) = leading_number(tail)
            {
                out.push(m.to_string());
                r = &tail[m.len()..];
            }
        }
        rest = [", ", " and ", "; ", "/"]
            .iter()
            .find_map(|sep| r.strip_prefix(sep).filter(|t| t.starts_with('§')))
            .unwrap_or("");
    }
    out
}

/// A phrase in double quotes right after a document's name (`DOC.md, "x"`, `DOC.md "x"`,
/// `DOC.md ("x"`).
fn quoted_section(after: &str) -> Option<&str> {
    let rest = after
        .strip_prefix(", ")
        .or_else(|| after.strip_prefix(" ("))
        .or_else(|| after.strip_prefix(' '))?;
    let rest = rest.strip_prefix('"')?;
    let end = rest.find('"')?;
    let phrase = &rest[..end];
    (!phrase.is_empty() && !phrase.contains('\n')).then_some(phrase)
}

#[test]
fn every_citation_resolves_in_the_repository() {
    let root = root();
    let physics_notes = std::fs::read_to_string(root.join("docs/physics.md"))
        .expect("docs/physics.md, the physics notes the code cites");
    let sections = headings(&physics_notes);
    assert!(
        sections.contains("1.1") && sections.contains("10"),
        "{sections:?}"
    );

    // Spelled in pieces so that this file does not cite them itself.
    let notes_name = ["physics", ".md"].concat();
    let notes_path = ["docs/", &notes_name].concat();
    let outside = [
        ["shared", "/"].concat(),
        ["STYLE", ".md"].concat(),
        ["DESIGN", ".md"].concat(),
    ];
    let documents = [
        "ARCHITECTURE.md",
        "BENCHMARKS.md",
        "CHANGELOG.md",
        "RELIABILITY.md",
        "README.md",
    ];

    let mut files = Vec::new();
    source_files(&root, &mut files);
    assert!(
        files.len() > 50,
        "found only {} files under {}",
        files.len(),
        root.display()
    );
    let mut problems = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap_or_default();
        let name = file
            .strip_prefix(&root)
            .unwrap_or(file)
            .display()
            .to_string();
        let mut problem = |at: usize, what: String| {
            problems.push(format!("{name}:{}: {what}", line_of(&text, at)));
        };

        for (at, _) in text.match_indices(&notes_name) {
            let full = at >= 5 && text[..at].ends_with("docs/");
            if !full {
                problem(at, format!("cite the physics notes as `{notes_path}`"));
                continue;
            }
            for section in cited_sections(&text[at + notes_name.len()..]) {
                if !sections.contains(&section) {
                    problem(at, format!("{notes_path} has no §{section}"));
                }
            }
        }

        for needle in &outside {
            for (at, _) in text.match_indices(needle.as_str()) {
                problem(at, format!("`{needle}` is outside the repository"));
            }
        }

        for (at, _) in text.match_indices("data/") {
            if at > 0 && text[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
                continue; // `metadata/` and the like
            }
            let path: String = text[at..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || "_./-".contains(*c))
                .collect();
            let path = path.trim_end_matches('.');
            if path.contains('.') && !root.join(path).is_file() {
                problem(at, format!("{path} does not exist"));
            }
        }

        for doc in documents {
            for (at, _) in text.match_indices(doc) {
                let before = &text[..at];
                // The path in front of the name, if any (`data/reference/README.md`).
                let dir_start = before
                    .rfind(|c: char| !(c.is_ascii_alphanumeric() || "_./-".contains(c)))
                    .map_or(0, |i| {
                        i + before[i..].chars().next().map_or(1, char::len_utf8)
                    });
                let path = root.join(&text[dir_start..at + doc.len()]);
                if !path.is_file() {
                    problem(
                        at,
                        format!("{} does not exist", &text[dir_start..at + doc.len()]),
                    );
                    continue;
                }
                if let Some(phrase) = quoted_section(&text[at + doc.len()..]) {
                    let body = std::fs::read_to_string(&path)
                        .unwrap_or_default()
                        .to_lowercase();
                    if !body.contains(&phrase.to_lowercase()) {
                        problem(at, format!("{doc} has no \"{phrase}\""));
                    }
                }
            }
        }
    }
    assert!(
        problems.is_empty(),
        "{} citations do not resolve in the repository (scripts/fix_citations.sh fixes the old \
         forms):\n{}",
        problems.len(),
        problems.join("\n")
    );
}

/// The parser itself, on the forms the code uses.
#[test]
fn the_citation_forms_are_parsed() {
    assert_eq!(cited_sections(" §4.1) in mm"), ["4.1"]);
    assert_eq!(cited_sections("` §4.1)"), ["4.1"]);
    assert_eq!(cited_sections(" §4.2–4.4), the"), ["4.2", "4.4"]);
    assert_eq!(cited_sections(" §3, §10 item 2"), ["3", "10"]);
    assert_eq!(cited_sections(" §2.1 and §3"), ["2.1", "3"]);
    assert_eq!(cited_sections(" §5."), ["5"]);
    assert_eq!(cited_sections("\n/// §4.3, \"n=1.4\""), ["4.3"]);
    assert_eq!(cited_sections("'s reconstruction"), Vec::<String>::new());
    assert_eq!(quoted_section(", \"io: exports\")"), Some("io: exports"));
    assert_eq!(
        quoted_section(" (\"The measurement, as files\""),
        Some("The measurement, as files")
    );
    assert_eq!(quoted_section(" \"exports\""), Some("exports"));
    assert_eq!(quoted_section(" says"), None);
    let h = headings("# Title\n## 1. One\n### 1.1 Sub\n## 10. Ten\n#### Not numbered\n");
    assert_eq!(h.into_iter().collect::<Vec<_>>(), ["1", "1.1", "10"]);
}
