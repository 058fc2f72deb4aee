//! Numeric flags shared by the subcommands (their value parsers are `scatterfit_io::flags`), and the
//! budgets (memory, Monte Carlo work) that sizes derived from the flags are checked against before
//! anything is allocated or traced.

/// Help text of `--max-memory-mib`.
pub const MAX_MEMORY_HELP: &str = "Memory budget [MiB, ≥ 1] for what the other flags and the \
     inputs size (tallies, tables, rings, images); checked before anything is allocated. Default: \
     $SCATTERFIT_MAX_MEMORY_MIB, else half of this machine's memory (MemTotal of /proc/meminfo)";

pub use scatterfit_pipeline::monte_carlo::MAX_INTERACTIONS_HELP;

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

pub use scatterfit_io::flags::{parse_count, parse_finite, parse_mib, parse_size};

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
