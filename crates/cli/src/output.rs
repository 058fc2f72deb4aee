//! Shared output helpers for the subcommands: JSON to stdout or to a file (atomically).

use std::path::Path;

use anyhow::Context;
use serde::Serialize;

/// Serialises `value` as pretty JSON and writes it atomically to `path` (temporary file + rename).
pub fn write_json_file<T: Serialize>(path: &Path, value: &T) -> anyhow::Result<()> {
    let mut text = serde_json::to_string_pretty(value).context("serialising the result as JSON")?;
    text.push('\n');
    scatterfit_io::atomic::write_atomic(path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// Prints `value` as pretty JSON on stdout.
pub fn print_json<T: Serialize>(value: &T) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(value).context("serialising the result as JSON")?;
    println!("{text}");
    Ok(())
}
