//! A Slurm batch script for a sharded run (`scatterfit slurm`): a job array of N shards of a
//! command (`--shard $SLURM_ARRAY_TASK_ID/N`, each writing its partial file) and a combine job that
//! runs once every shard has succeeded (`sbatch --dependency=afterok`). No scheduler of our own:
//! the script is plain `sbatch`, and submitting it again redoes only the shards whose partial file
//! is missing. [`SlurmJob::script`] is the text; [`split_tokens`] takes the sharded command's own
//! arguments from the command line.

use std::path::PathBuf;

use crate::partial::Kind;

/// How the combined result equals the one-machine run's (said in the script's header).
fn same(command: Kind) -> &'static str {
    match command {
        Kind::Table => "byte for byte",
        Kind::Batch => "the same summary.csv, summary.md and index.html",
        Kind::Study => "the same rows in study.csv and study.md",
    }
}

/// Everything a script says: the sharded command and Slurm's side of the jobs. Paths should be
/// absolute (the jobs run on other nodes, from `cwd`).
#[derive(Debug, Clone)]
pub struct SlurmJob {
    /// What is sharded.
    pub command: Kind,
    /// The command's own arguments, without `--shard` (each array task adds its own).
    pub args: Vec<String>,
    /// Shards: the job array's size (tasks 1…N).
    pub array: u64,
    /// CPUs of each array task.
    pub cpus_per_task: u64,
    /// Time limit of each task (Slurm's format).
    pub time: Option<String>,
    /// Partition.
    pub partition: Option<String>,
    /// Other `#SBATCH` options for both jobs, verbatim.
    pub sbatch_options: Vec<String>,
    /// The folder the jobs run in.
    pub cwd: PathBuf,
    /// The scatterfit binary.
    pub exe: PathBuf,
    /// The folder of the partial files (the logs go into its `logs`).
    pub partial_dir: PathBuf,
    /// The Monte Carlo table cache the jobs share (`SCATTERFIT_CACHE`), if any.
    pub cache_dir: Option<PathBuf>,
    /// The combine job's `-o` (`.` when none).
    pub output: Option<String>,
    /// The run's fingerprint when known (the partial files' names then match only this run's).
    pub fingerprint: Option<String>,
    /// Where the script is written (named in its header).
    pub script: PathBuf,
}

/// Slurm's side of a script: `scatterfit slurm`'s own flags (their help is the field's text).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct SlurmSettings {
    /// Shards: the job array's size, 1 to 10 000 (tasks 1…N).
    #[cfg_attr(feature = "clap", arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=10_000)))]
    pub array: u64,
    /// Where to write the script (a `.sh` file; an existing one only with --force-script).
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "FILE", default_value = "scatterfit-slurm.sh")
    )]
    pub script: PathBuf,
    /// Replace an existing script file.
    #[cfg_attr(feature = "clap", arg(long))]
    pub force_script: bool,
    /// CPUs of each array task (`#SBATCH --cpus-per-task`; the task's threads), 1 to 1024.
    #[cfg_attr(feature = "clap", arg(long, value_name = "C", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=1024)))]
    pub cpus_per_task: u64,
    /// Time limit of each task (`#SBATCH --time`, Slurm's format, e.g. 2:00:00).
    #[cfg_attr(feature = "clap", arg(long, value_name = "TIME"))]
    pub time: Option<String>,
    /// Partition (`#SBATCH --partition`).
    #[cfg_attr(feature = "clap", arg(long, value_name = "NAME"))]
    pub partition: Option<String>,
    /// Another `#SBATCH` option for both jobs, verbatim (repeatable; e.g. --sbatch-option=--account=lab).
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "OPTION", allow_hyphen_values = true)
    )]
    pub sbatch_option: Vec<String>,
}

impl SlurmSettings {
    /// The job of `command` from its own command-line `tokens` (after `slurm <kind>`,
    /// [`split_tokens`]): the flags `output_flags` and `--cache-dir` are taken out, and `--json`
    /// and `--quiet`; the combine job's `-o` is `output` if given, else the last output flag's
    /// value; the Monte Carlo cache is `--cache-dir`, else `scatterfit_mc::cache::default_cache_dir`;
    /// paths are made absolute from `cwd`, where the jobs run.
    #[allow(clippy::too_many_arguments)]
    pub fn job(
        &self,
        command: Kind,
        tokens: &[String],
        output_flags: &[&str],
        output: Option<String>,
        partial_dir: &std::path::Path,
        fingerprint: Option<String>,
        exe: PathBuf,
        cwd: PathBuf,
    ) -> SlurmJob {
        let mut strip: Vec<&str> = output_flags.to_vec();
        strip.push("--cache-dir");
        let split = split_tokens(tokens, &strip, &["--json", "--quiet"]);
        let output = output.or_else(|| split.last(output_flags).map(str::to_owned));
        let given = split.last(&["--cache-dir"]).map(std::path::Path::new);
        let cache_dir = scatterfit_mc::cache::cache_dir_or_default(given);
        SlurmJob {
            command,
            args: split.kept,
            array: self.array,
            cpus_per_task: self.cpus_per_task,
            time: self.time.clone(),
            partition: self.partition.clone(),
            sbatch_options: self.sbatch_option.clone(),
            exe,
            partial_dir: cwd.join(partial_dir),
            cache_dir: cache_dir.map(|c| cwd.join(c)),
            output,
            fingerprint,
            script: self.script.clone(),
            cwd,
        }
    }
}

/// `s` quoted for a POSIX shell (left as it is when it holds only characters no shell treats
/// specially).
pub fn quote(s: &str) -> String {
    if !s.is_empty()
        && s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-_./=:,+@%".contains(&b))
    {
        s.to_owned()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// `scatterfit slurm`'s own flags that take a value: never passed on to the array tasks.
pub const OWN_WITH_VALUE: [&str; 6] = [
    "--array",
    "--script",
    "--cpus-per-task",
    "--time",
    "--partition",
    "--sbatch-option",
];

/// `scatterfit slurm`'s own switches: never passed on to the array tasks.
pub const OWN_SWITCHES: [&str; 1] = ["--force-script"];

/// A sharded command's tokens as given (after `slurm <kind>`), split ([`split_tokens`]).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SplitTokens {
    /// The tokens the array tasks run with.
    pub kept: Vec<String>,
    /// The flags taken out, in order, each with its value (empty for a switch).
    pub taken: Vec<(String, String)>,
}

impl SplitTokens {
    /// The value of the last of the flags `names` taken out.
    pub fn last(&self, names: &[&str]) -> Option<&str> {
        self.taken
            .iter()
            .rev()
            .find(|(n, _)| names.contains(&n.as_str()))
            .map(|(_, v)| v.as_str())
    }
}

/// Splits a command's `tokens` (after `slurm <kind>`) into those the array tasks run with and the
/// flags taken out: `scatterfit slurm`'s own ([`OWN_WITH_VALUE`], [`OWN_SWITCHES`]) and those in
/// `strip_with_value` (with their value: `--flag V`, `--flag=V`, `-oV`) and `strip_switches`.
/// Everything from a `--` on is kept as it is.
pub fn split_tokens(
    tokens: &[String],
    strip_with_value: &[&str],
    strip_switches: &[&str],
) -> SplitTokens {
    let mut split = SplitTokens::default();
    let mut i = 0;
    while i < tokens.len() {
        let t = &tokens[i];
        let (name, inline) = match t.split_once('=') {
            Some((n, v)) if n.starts_with("--") => (n.to_owned(), Some(v.to_owned())),
            _ if t.starts_with("-o") && t.len() > 2 && !t.starts_with("--") => {
                ("-o".to_owned(), Some(t[2..].to_owned()))
            }
            _ => (t.clone(), None),
        };
        if t == "--" {
            split.kept.extend(tokens[i..].iter().cloned());
            break;
        }
        let with_value =
            OWN_WITH_VALUE.contains(&name.as_str()) || strip_with_value.contains(&name.as_str());
        if with_value {
            let value = match inline {
                Some(v) => v,
                None => {
                    i += 1;
                    tokens.get(i).cloned().unwrap_or_default()
                }
            };
            split.taken.push((name, value));
        } else if OWN_SWITCHES.contains(&name.as_str()) || strip_switches.contains(&name.as_str()) {
            split.taken.push((name, String::new()));
        } else {
            split.kept.push(t.clone());
        }
        i += 1;
    }
    split
}

impl SlurmJob {
    /// The `logs` folder beside the partial files.
    pub fn logs(&self) -> PathBuf {
        self.partial_dir.join("logs")
    }

    /// The script's text: a bash script that submits the job array and the combine job.
    pub fn script(&self) -> String {
        let q = |p: &std::path::Path| quote(&p.to_string_lossy());
        let n = self.array;
        let name = self.command.name();
        let mut header = format!("#SBATCH --chdir={}\n", q(&self.cwd));
        if let Some(t) = &self.time {
            header.push_str(&format!("#SBATCH --time={}\n", quote(t)));
        }
        if let Some(p) = &self.partition {
            header.push_str(&format!("#SBATCH --partition={}\n", quote(p)));
        }
        for o in &self.sbatch_options {
            header.push_str(&format!("#SBATCH {o}\n"));
        }
        let mut env = String::from("export RAYON_NUM_THREADS=\"${SLURM_CPUS_PER_TASK:-1}\"\n");
        if let Some(c) = &self.cache_dir {
            env.push_str(&format!("export SCATTERFIT_CACHE={}\n", q(c)));
        }
        let exe = q(&self.exe);
        let cmd = self
            .args
            .iter()
            .map(|t| quote(t))
            .collect::<Vec<_>>()
            .join(" ");
        let pattern = format!(
            "{}/{name}-{}-*-of-{n:04}.json",
            q(&self.partial_dir),
            self.fingerprint.as_deref().unwrap_or("*")
        );
        let out_flag = self
            .output
            .as_deref()
            .map_or(String::from("-o ."), |o| format!("-o {}", quote(o)));
        let combine = format!("{exe} combine {pattern} {out_flag}");
        let logs = q(&self.logs());
        format!(
            r#"#!/bin/bash
# Written by `scatterfit slurm` (scatterfit {version}). Read it, then submit it from any login node:
#
#     bash {script}
#
# It submits two jobs:
#   1. a job array of {n} tasks: task K runs shard K/{n} of
#          scatterfit {name} {cmd}
#      and writes its partial file into {partials}
#   2. a combine job, held until every task has succeeded (--dependency=afterok):
#          scatterfit combine … {out_flag}
#      — the same result as the command on one machine ({same}).
# Submitting it again (a task failed, a node died) redoes only the shards whose partial file is
# missing: a task whose partial file is there and matches returns at once.
# Everything below must be on a file system every node sees: the binary, {cwd}, the partial
# files and logs ({partials}){cache_note}.
set -euo pipefail
mkdir -p {logs}

array=$(sbatch --parsable <<'SCATTERFIT_ARRAY'
#!/bin/bash
#SBATCH --job-name=scatterfit-{name}
#SBATCH --array=1-{n}
#SBATCH --cpus-per-task={cpus}
#SBATCH --output={logs}/{name}-%A-%a.out
{header}{env}exec {exe} {name} {cmd} --shard "${{SLURM_ARRAY_TASK_ID}}/{n}"
SCATTERFIT_ARRAY
)
array=${{array%%;*}}

combine=$(sbatch --parsable --dependency=afterok:"$array" <<'SCATTERFIT_COMBINE'
#!/bin/bash
#SBATCH --job-name=scatterfit-{name}-combine
#SBATCH --cpus-per-task=1
#SBATCH --output={logs}/{name}-combine-%j.out
{header}{env}exec {combine}
SCATTERFIT_COMBINE
)
combine=${{combine%%;*}}

echo "submitted: job array $array ({n} shards of scatterfit {name}), combine job $combine after it"
echo "logs: {logs}; squeue -j $array,$combine shows them"
"#,
            version = env!("CARGO_PKG_VERSION"),
            script = q(&self.script),
            partials = self.partial_dir.display(),
            same = same(self.command),
            cwd = self.cwd.display(),
            cache_note = self.cache_dir.as_deref().map_or(String::new(), |c| format!(
                ", and the table cache ({})",
                c.display()
            )),
            cpus = self.cpus_per_task,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitting() {
        let t: Vec<String> = [
            "--eta",
            "1.3",
            "--array",
            "8",
            "-o",
            "t.json",
            "--time=1:00",
            "--json",
            "--g",
            "0.9",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let split = split_tokens(&t, &["-o"], &["--json"]);
        assert_eq!(split.kept, ["--eta", "1.3", "--g", "0.9"]);
        assert_eq!(split.last(&["-o"]), Some("t.json"));
        assert_eq!(split.last(&["--array"]), Some("8"));
        assert_eq!(split.last(&["--time"]), Some("1:00"));
    }

    fn job() -> SlurmJob {
        SlurmJob {
            command: Kind::Table,
            args: vec![
                "--eta".into(),
                "1.3".into(),
                "--partial-dir".into(),
                "p q".into(),
            ],
            array: 8,
            cpus_per_task: 4,
            time: Some("2:00:00".into()),
            partition: None,
            sbatch_options: vec!["--account=lab".into()],
            cwd: PathBuf::from("/home/u/run"),
            exe: PathBuf::from("/opt/scatterfit"),
            partial_dir: PathBuf::from("/home/u/run/p q"),
            cache_dir: Some(PathBuf::from("/scratch/cache")),
            output: Some("t.json".into()),
            fingerprint: Some("0123456789abcdef".into()),
            script: PathBuf::from("run.sh"),
        }
    }

    #[test]
    fn quoting() {
        assert_eq!(quote("a b"), "'a b'");
        assert_eq!(quote("it's"), r"'it'\''s'");
        assert_eq!(quote("--eta=1.3"), "--eta=1.3");
        assert_eq!(quote(""), "''");
    }

    #[test]
    fn the_script_runs_each_shard_and_combines_them() {
        let s = job().script();
        assert!(s.starts_with("#!/bin/bash\n"), "{s}");
        // The array: 8 tasks of 4 CPUs, the shard from the task id, arguments quoted.
        assert!(
            s.contains("#SBATCH --array=1-8\n#SBATCH --cpus-per-task=4\n"),
            "{s}"
        );
        assert!(
            s.contains(
                "exec /opt/scatterfit table --eta 1.3 --partial-dir 'p q' --shard \
                 \"${SLURM_ARRAY_TASK_ID}/8\"\n"
            ),
            "{s}"
        );
        // Both jobs get the header and the cache.
        assert_eq!(s.matches("#SBATCH --chdir=/home/u/run\n").count(), 2, "{s}");
        assert_eq!(s.matches("#SBATCH --time=2:00:00\n").count(), 2, "{s}");
        assert_eq!(s.matches("#SBATCH --account=lab\n").count(), 2, "{s}");
        assert!(!s.contains("--partition"), "{s}");
        assert_eq!(
            s.matches("export SCATTERFIT_CACHE=/scratch/cache\n")
                .count(),
            2
        );
        // The combine job waits for the array and reads only this run's partial files.
        assert!(s.contains("--dependency=afterok:\"$array\""), "{s}");
        assert!(
            s.contains(
                "exec /opt/scatterfit combine '/home/u/run/p q'/table-0123456789abcdef-*-of-0008.json \
                 -o t.json\n"
            ),
            "{s}"
        );
        assert!(s.contains("mkdir -p '/home/u/run/p q/logs'\n"), "{s}");
        assert!(s.contains("(byte for byte)"), "{s}");
    }

    #[test]
    fn without_an_output_or_fingerprint_the_combine_job_takes_any_run_into_the_folder() {
        let s = SlurmJob {
            command: Kind::Batch,
            output: None,
            fingerprint: None,
            cache_dir: None,
            ..job()
        }
        .script();
        assert!(
            s.contains("combine '/home/u/run/p q'/batch-*-*-of-0008.json -o .\n"),
            "{s}"
        );
        assert!(!s.contains("SCATTERFIT_CACHE"), "{s}");
        assert!(!s.contains("table cache"), "{s}");
    }
}
