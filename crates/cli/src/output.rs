//! Output of the subcommands: standard output through fallible writes, diagnostics on standard
//! error that never panic, and JSON to stdout or to a file (atomically).
//!
//! `println!` panics when its reader has gone ("failed printing to stdout: Broken pipe", exit 101,
//! for `scatterfit … | head`); every command prints through [`outln!`] and [`out!`] instead (the
//! crate denies `clippy::print_stdout` and `clippy::print_stderr`). A closed stdout
//! ([`io::ErrorKind::BrokenPipe`]) ends the printing quietly: what was still to be printed is
//! dropped, the command's files are written as usual and its exit code stands (0 on success), as
//! ripgrep does. Every other write error (a full disk behind a redirection) is an error. Standard
//! error goes through [`errln!`], which drops what cannot be written rather than panicking.
//!
//! Both pass their text through one helper, `scatterfit_io::escape::terminal`: sample names, file
//! names and messages quoting a file may hold escape sequences (ESC, an 8-bit CSI), carriage
//! returns or bidirectional overrides that a terminal would act on; they are shown as `\u{1b}`
//! instead (newlines and tabs are kept). JSON on stdout ([`print_json`], `scatterfit_io::escape::json`) has its C1 and
//! bidirectional controls written as `\u009b` escapes, which JSON readers decode to the same
//! string.

use std::fmt;
use std::io::{self, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Context;
use serde::Serialize;

/// Set once a write to stdout met a closed pipe; later writes are dropped.
static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);

/// True once the reader of stdout has gone.
pub fn stdout_closed() -> bool {
    STDOUT_CLOSED.load(Ordering::Relaxed)
}

/// Maps the outcome of a write to stdout: a closed pipe is remembered and is not an error.
fn stdout_outcome(r: io::Result<()>) -> anyhow::Result<()> {
    match r {
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => {
            STDOUT_CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        other => other.context("writing to standard output"),
    }
}

/// Writes formatted text to stdout (the body of [`out!`] and [`outln!`]).
///
/// # Errors
/// A write error other than a closed pipe.
pub fn write_stdout(args: fmt::Arguments<'_>) -> anyhow::Result<()> {
    if stdout_closed() {
        return Ok(());
    }
    let text = fmt::format(args);
    let text = scatterfit_io::escape::terminal(&text);
    stdout_outcome(io::stdout().lock().write_all(text.as_bytes()))
}

/// Writes bytes to stdout and flushes (an export printed whole).
///
/// # Errors
/// A write error other than a closed pipe.
pub fn write_stdout_bytes(bytes: &[u8]) -> anyhow::Result<()> {
    if stdout_closed() {
        return Ok(());
    }
    let mut out = io::stdout().lock();
    stdout_outcome(out.write_all(bytes).and_then(|()| out.flush()))
}

/// Flushes stdout (at the end of every command: text without a final newline is still buffered).
///
/// # Errors
/// A write error other than a closed pipe.
pub fn flush_stdout() -> anyhow::Result<()> {
    if stdout_closed() {
        return Ok(());
    }
    stdout_outcome(io::stdout().lock().flush())
}

/// Writes formatted text to stderr; what cannot be written (a closed stderr) is dropped.
pub fn write_stderr(args: fmt::Arguments<'_>) {
    let text = fmt::format(args);
    let _ = io::stderr()
        .lock()
        .write_all(scatterfit_io::escape::terminal(&text).as_bytes());
}

/// `print!` that returns `anyhow::Result<()>` instead of panicking: use as `out!(…)?`.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!($($arg)*))
    };
}

/// `println!` that returns `anyhow::Result<()>` instead of panicking: use as `outln!(…)?`.
macro_rules! outln {
    () => {
        $crate::output::write_stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` that never panics: diagnostics that cannot be written are dropped.
macro_rules! errln {
    () => {
        $crate::output::write_stderr(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::write_stderr(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {errln, out, outln};

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
    outln!("{}", scatterfit_io::escape::json(&text))
}
