//! The manifest's TOML syntax: parsing into the typed sections with the key and the line of a
//! mistake, which the checks in `mod.rs` then judge.

use super::*;

/// The top-level keys of a manifest: a TOML file whose top-level keys are all among these is
/// recognised as a manifest, and only then may a message quote a piece of it.
pub(super) const TOP_LEVEL_KEYS: [&str; 4] = ["name", "spectro", "camera", "fit"];

/// Parses manifest text, with messages that follow the content rule (RELIABILITY.md, "Inputs"):
/// line and column always; before the file is recognised as a manifest (it parses as TOML and its
/// top-level keys are ours) nothing of its content; after, single keys and values as short escaped
/// tokens. Never toml's snippet of the line.
pub(super) fn parse_toml(text: &str) -> Result<SampleManifest, String> {
    let at = |e: &toml::de::Error| {
        e.span()
            .map(|s| {
                let (line, column) = line_column(text, s.start);
                format!("line {line}, column {column}: ")
            })
            .unwrap_or_default()
    };
    let table: toml::Table = match toml::from_str(text) {
        Ok(t) => t,
        Err(e) => {
            let what =
                crate::escape::redact_quotes(e.message().trim(), |q| TOP_LEVEL_KEYS.contains(&q));
            return Err(format!(
                "{}not valid TOML ({what}); the file's content is not shown — is this a sample \
                 manifest?",
                at(&e)
            ));
        }
    };
    let recognised = table.keys().all(|k| TOP_LEVEL_KEYS.contains(&k.as_str()));
    match toml::from_str::<SampleManifest>(text) {
        Ok(m) => Ok(m),
        Err(e) if !recognised => Err(format!(
            "{}a top-level key that is not `name`, `[spectro]`, `[camera]` or `[fit]`: this is not \
             a scatterfit sample manifest (its content is not shown; `scatterfit synth` writes a \
             complete example)",
            at(&e)
        )),
        Err(e) => {
            let key = e
                .span()
                .and_then(|s| key_at(text, s.start))
                .map(|k| format!("`{k}`: "))
                .unwrap_or_default();
            Err(format!(
                "{}{key}{}",
                at(&e),
                crate::escape::shorten_quotes(e.message().trim())
            ))
        }
    }
}

/// 1-based line and column (in characters) of byte `offset` of `text`.
pub(super) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let mut start = offset;
    while !text.is_char_boundary(start) {
        start -= 1;
    }
    let before = &text[..start];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    (line, column)
}

/// The dotted key (`camera.mm_per_pixel`) of the line holding byte `offset`, as a short escaped
/// token: the last `[table]` header above it and the key before `=` on its line.
pub(super) fn key_at(text: &str, offset: usize) -> Option<String> {
    let (line, _) = line_column(text, offset);
    let lines: Vec<&str> = text.lines().collect();
    let here = lines.get(line - 1)?;
    let (key, _) = here.split_once('=')?;
    let key = key.trim().trim_matches('"');
    if key.is_empty() || key.starts_with('[') {
        return None;
    }
    let table = lines[..line - 1]
        .iter()
        .rev()
        .map(|l| l.trim())
        .find(|l| l.starts_with('[') && !l.starts_with("[["))
        // The name between the brackets (a comment may follow the header).
        .and_then(|l| l[1..].split_once(']').map(|(name, _)| name.trim()));
    Some(crate::escape::token(&match table {
        Some(t) => format!("{t}.{key}"),
        None => key.to_string(),
    }))
}
