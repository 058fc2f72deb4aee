//! The memory budget: how much memory one command may allocate for the data it reads or makes.
//!
//! Sizes that follow from the input (an image's width × height, a bracket's frames) are checked
//! against it *before* anything is allocated, so that a corrupt header or a typo in a flag is a clear
//! error instead of an abort or a machine that starts to swap. The default is half of this
//! machine's memory ([`default_memory_budget_mib`], `MemTotal` of `/proc/meminfo`; where that
//! cannot be read, [`DEFAULT_MEMORY_BUDGET_MIB`]); set it with the environment variable
//! [`MEMORY_BUDGET_ENV`] (MiB), or with a command's `--max-memory-mib`.

/// The budget \[MiB\] where the machine's memory cannot be read: 8 GiB, a third of the project's
/// 24-GiB standard machine.
pub const DEFAULT_MEMORY_BUDGET_MIB: u64 = 8192;

/// The default budget \[MiB\]: half of the machine's memory (`MemTotal` in `/proc/meminfo`, the
/// kernel's figure for usable RAM), else [`DEFAULT_MEMORY_BUDGET_MIB`]. Half, because the decoded
/// data is not the only thing in memory (the OS, other users of a shared machine, the page cache
/// of the inputs).
pub fn default_memory_budget_mib() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| mem_total_kib(&t))
        .map_or(DEFAULT_MEMORY_BUDGET_MIB, |kib| (kib / 1024 / 2).max(1))
}

/// `MemTotal` \[KiB\] of the text of `/proc/meminfo`.
fn mem_total_kib(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemTotal:"))?;
    let mut words = line["MemTotal:".len()..].split_whitespace();
    let kib: u64 = words.next()?.parse().ok()?;
    (words.next() == Some("kB") && kib > 0).then_some(kib)
}

/// Environment variable that sets the budget in MiB, e.g. `SCATTERFIT_MAX_MEMORY_MIB=32768`.
pub const MEMORY_BUDGET_ENV: &str = "SCATTERFIT_MAX_MEMORY_MIB";

/// The budget in bytes: [`MEMORY_BUDGET_ENV`] when it holds a positive whole number of MiB, else
/// [`default_memory_budget_mib`].
pub fn memory_budget_bytes() -> u64 {
    std::env::var(MEMORY_BUDGET_ENV)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        .filter(|&mib| mib > 0)
        .unwrap_or_else(default_memory_budget_mib)
        .saturating_mul(1 << 20)
}

/// Bytes that something sized by the user's flags or inputs would need, above the budget: the
/// refusal names what needs them and how to raise the budget.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{what} needs {} of memory, more than the budget of {}; use fewer, or raise the budget with \
     --max-memory-mib (or {MEMORY_BUDGET_ENV}; default {} MiB, half of this machine's memory) if \
     this machine has the memory",
    describe_bytes(*needed),
    describe_bytes(*budget),
    default_memory_budget_mib()
)]
pub struct OverBudget {
    /// What needs the memory, e.g. `the table` or `tallying 200 radial and 0 angular bins`.
    pub what: String,
    /// Bytes needed.
    pub needed: u64,
    /// The budget \[bytes\].
    pub budget: u64,
}

/// Refuses `needed` bytes above `budget` ([`OverBudget`]), saying what needs them.
///
/// # Errors
/// The refusal.
pub fn check_memory(what: &str, needed: u64, budget: u64) -> Result<(), OverBudget> {
    if needed > budget {
        return Err(OverBudget {
            what: what.to_owned(),
            needed,
            budget,
        });
    }
    Ok(())
}

/// A byte count for messages: `512 MiB`, `3.2 GiB`, `1.5 TiB`.
pub fn describe_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["bytes", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes as f64;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} bytes")
    } else if v < 10.0 {
        format!("{v:.1} {}", UNITS[unit])
    } else {
        format!("{v:.0} {}", UNITS[unit])
    }
}

/// A duration for messages: `45 s`, `12 min`, `3.5 h`, `40 days`, `3e4 years`.
pub fn describe_seconds(s: f64) -> String {
    if !s.is_finite() {
        "forever".into()
    } else if s < 120.0 {
        format!("{s:.0} s")
    } else if s < 7200.0 {
        format!("{:.0} min", s / 60.0)
    } else if s < 3.0 * 86_400.0 {
        format!("{:.1} h", s / 3600.0)
    } else if s < 1000.0 * 86_400.0 {
        format!("{:.0} days", s / 86_400.0)
    } else {
        format!("{:.1e} years", s / (365.25 * 86_400.0))
    }
}

/// How to raise the budget, for messages.
pub fn how_to_raise() -> String {
    format!(
        "raise the memory budget with {MEMORY_BUDGET_ENV}=<MiB> (default {} MiB, half of this \
         machine's memory) if this machine has the memory",
        default_memory_budget_mib()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refusal_names_what_needs_the_memory_and_both_sizes() {
        assert_eq!(check_memory("the table", 1 << 20, 1 << 20), Ok(()));
        let e = check_memory("the table", 3 << 30, 512 << 20).unwrap_err();
        let text = e.to_string();
        assert!(
            text.starts_with("the table needs 3.0 GiB of memory, more than the budget of 512 MiB;"),
            "{text}"
        );
        assert!(text.contains("--max-memory-mib"), "{text}");
        assert!(text.contains(MEMORY_BUDGET_ENV), "{text}");
    }

    #[test]
    fn bytes_are_described_in_binary_units() {
        assert_eq!(describe_bytes(512), "512 bytes");
        assert_eq!(describe_bytes(3 << 29), "1.5 GiB");
        assert_eq!(describe_bytes(144 << 20), "144 MiB");
    }

    /// The default is half of `MemTotal`; a text without it (or in other units) gives none.
    #[test]
    fn the_default_budget_is_half_the_machines_memory() {
        let meminfo = "MemTotal:       24684084 kB\nMemFree:         1000 kB\n";
        assert_eq!(mem_total_kib(meminfo), Some(24_684_084));
        assert_eq!(mem_total_kib("MemFree: 5 kB\n"), None);
        assert_eq!(mem_total_kib("MemTotal: 5 MB\n"), None);
        if let Some(kib) = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|t| mem_total_kib(&t))
        {
            assert_eq!(default_memory_budget_mib(), kib / 2048);
            assert_ne!(default_memory_budget_mib(), DEFAULT_MEMORY_BUDGET_MIB);
        }
    }

    #[test]
    fn durations_read_well() {
        assert_eq!(describe_seconds(45.0), "45 s");
        assert_eq!(describe_seconds(720.0), "12 min");
        assert_eq!(describe_seconds(12_600.0), "3.5 h");
        assert_eq!(describe_seconds(f64::INFINITY), "forever");
    }
}
