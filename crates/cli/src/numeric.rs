//! Numeric flags shared by the subcommands: counts written as people write them (`1e6`), and the
//! budgets (memory, Monte Carlo work) that sizes derived from the flags are checked against before
//! anything is allocated or traced.

/// Help text of `--max-memory-mib`.
pub const MAX_MEMORY_HELP: &str = "Memory budget [MiB, ≥ 1] for what the other flags and the \
     inputs size (tallies, tables, rings, images); checked before anything is allocated. Default: \
     $SCATTERFIT_MAX_MEMORY_MIB, else half of this machine's memory (MemTotal of /proc/meminfo)";

/// Help text of `--max-interactions`.
pub const MAX_INTERACTIONS_HELP: &str = "Work budget: the most photon interactions (scattering \
     events, all photons together) the run may be expected to take, estimated before it starts from \
     σs, σa, g, η and the thickness; a count (default 1e12: about 7 h on 2 cores at 2e7 \
     interactions/s per thread). Raise it to allow longer runs";

/// The memory budget of a command that sizes its work from its flags and inputs
/// (`--max-memory-mib`: `merge`, `profile`, `render`, `simulate`, `table`).
#[derive(Debug, Clone, clap::Args)]
pub struct MemoryArgs {
    #[arg(long, value_parser = parse_mib, help = MAX_MEMORY_HELP)]
    pub max_memory_mib: Option<u64>,
}

impl MemoryArgs {
    /// The budget \[bytes\] ([`memory_budget`]).
    pub fn budget(&self) -> u64 {
        memory_budget(self.max_memory_mib)
    }
}

/// The Monte Carlo work budget (`--max-interactions`: `simulate`, `table`).
#[derive(Debug, Clone, clap::Args)]
pub struct WorkArgs {
    #[arg(long, default_value = "1e12", value_parser = parse_count, help = MAX_INTERACTIONS_HELP)]
    pub max_interactions: u64,
}

/// Refuses a flag's value unless `ok`, with the flag, the value and `rule` (the valid range, its
/// unit and why), e.g. `--ring-width-px 0: must be > 0 px …`.
///
/// # Errors
/// The refusal (exit 2).
pub fn ensure(
    ok: bool,
    flag: &str,
    value: impl std::fmt::Display,
    rule: &str,
) -> anyhow::Result<()> {
    if ok {
        Ok(())
    } else {
        let text = value.to_string();
        let value = text.parse::<f64>().map_or(text, show);
        anyhow::bail!("{flag} {value}: {rule}")
    }
}

/// A number for messages: at most 6 significant digits, in scientific notation beyond ordinary
/// magnitudes (`1e-300`, not three hundred zeros; `0.3`, not `0.30000000000000004`):
/// `scatterfit_io::escape::number`.
pub fn show(v: f64) -> String {
    scatterfit_io::escape::number(v)
}

/// Parses a count: `1000000`, `1e6`, `2.5e5` or `1_000_000`; a whole number ≥ 0 that fits in u64
/// (decimal notation must be exact: at most 2⁵³ when written with an exponent or a point).
///
/// # Errors
/// A message for clap naming what was wrong.
pub fn parse_count(text: &str) -> Result<u64, String> {
    let t = text.trim().replace('_', "");
    if let Ok(n) = t.parse::<u64>() {
        return Ok(n);
    }
    let v: f64 = t
        .parse()
        .map_err(|_| format!("`{text}` is not a count (write e.g. 1000000 or 1e6)"))?;
    if !v.is_finite() || v < 0.0 {
        return Err(format!("`{text}` is not a count ≥ 0"));
    }
    if v.fract() != 0.0 {
        return Err(format!("`{text}` is not a whole number"));
    }
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2⁵³
    if v > EXACT {
        return Err(format!(
            "`{text}` is too large for a count in floating-point notation (at most 2⁵³ ≈ 9.0e15); \
             write the digits"
        ));
    }
    Ok(v as u64)
}

/// A memory budget in MiB (`--max-memory-mib`): a count ≥ 1.
///
/// # Errors
/// As [`parse_count`], or 0.
pub fn parse_mib(text: &str) -> Result<u64, String> {
    match parse_count(text)? {
        0 => Err("a memory budget of 0 MiB allows nothing; give at least 1".into()),
        n => Ok(n),
    }
}

/// [`parse_count`] for sizes held in `usize`.
///
/// # Errors
/// As [`parse_count`], or a count that does not fit this machine's `usize`.
pub fn parse_size(text: &str) -> Result<usize, String> {
    let n = parse_count(text)?;
    usize::try_from(n).map_err(|_| format!("`{text}` is too large"))
}

/// Parses a decimal number (for clap), refusing NaN and infinities up front.
///
/// # Errors
/// A message for clap.
pub fn parse_finite(text: &str) -> Result<f64, String> {
    let v: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("`{text}` is not a finite number"))
    }
}

/// The memory budget \[bytes\]: the flag's MiB, else [`scatterfit_io::budget::MEMORY_BUDGET_ENV`], else
/// half of the machine's memory (`scatterfit_io::budget::default_memory_budget_mib`).
pub fn memory_budget(flag_mib: Option<u64>) -> u64 {
    flag_mib.map_or_else(scatterfit_io::budget::memory_budget_bytes, |m| {
        m.saturating_mul(1 << 20)
    })
}

/// Refuses `needed` bytes above `budget`, saying what needs them and how to raise the budget
/// ([`scatterfit_io::budget::check_memory`]).
///
/// # Errors
/// The refusal.
pub fn check_memory(what: &str, needed: u64, budget: u64) -> anyhow::Result<()> {
    Ok(scatterfit_io::budget::check_memory(what, needed, budget)?)
}

pub use scatterfit_io::budget::describe_seconds;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_accept_scientific_notation() {
        assert_eq!(parse_count("1e6"), Ok(1_000_000));
        assert_eq!(parse_count("2.5e5"), Ok(250_000));
        assert_eq!(parse_count("1_000_000"), Ok(1_000_000));
        assert_eq!(parse_count("18446744073709551615"), Ok(u64::MAX));
        assert!(parse_count("1.5").unwrap_err().contains("whole"));
        assert!(parse_count("-3").is_err());
        assert!(parse_count("1e300").unwrap_err().contains("too large"));
        assert!(parse_count("NaN").is_err());
        assert!(parse_count("many").unwrap_err().contains("1e6"));
    }

    #[test]
    fn numbers_in_messages_stay_short() {
        assert_eq!(show(1e-300), "1e-300");
        assert_eq!(show(1e13), "1e13");
        assert_eq!(show(300.0), "300");
        assert_eq!(show(0.5), "0.5");
        let err = ensure(false, "--ring-width-px", 1e-300, "rule").unwrap_err();
        assert_eq!(err.to_string(), "--ring-width-px 1e-300: rule");
    }
}
