//! `scatterfit demo`: the whole method on data the fitted model did not make. The rig twin
//! (`scatterfit-synth`, Monte Carlo) synthesises the seven materials of Choi, Lee & Chin (2014,
//! Table 1) as sample folders — spectro reading, 13-exposure bracket, manifest, truth — then every
//! folder is measured with the proposed method and compared with the existing one, and the
//! recovered σ′s, σa and η are printed beside the truth with their errors. Each folder gets its
//! report.html; the last line printed is the path of index.html, the page that lists them.
//!
//! The demo owns its output folder: it writes a `.scatterfit-demo` marker there and refuses a
//! folder holding anything else unless `--force`. Monte Carlo profiles are cached (the second run
//! takes seconds).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use scatterfit_lab::demo::{materials, write_demo};

use scatterfit_pipeline::outputs::claim_folder;

use crate::common::CacheArgs;
use crate::output::{errln, out};
use crate::twin::{synthesize, write_sample};

/// Arguments of `scatterfit demo`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder for the synthetic samples and the summaries (created; the demo's own: a
    /// `.scatterfit-demo` marker is written there, and a folder holding anything else is refused
    /// unless --force; a previous demo's files are replaced).
    #[arg(
        short = 'o',
        long = "output-dir",
        alias = "out-dir",
        default_value = "scatterfit-demo",
        value_name = "DIR"
    )]
    pub output_dir: PathBuf,
    /// Seed of the rig twin, 0 to 2⁶⁴ − 1.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[command(flatten)]
    pub jobs: crate::common::JobsArgs,
    /// Small fast samples (256 × 256 px at 0.1 mm/px, a tenth of the photons): a quick look, not the
    /// accuracy of the full rig.
    #[arg(long)]
    pub quick: bool,
    /// Use a folder that holds other files than a previous demo's.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub cache: CacheArgs,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bars.
    #[arg(long)]
    pub quiet: bool,
}

/// Runs `scatterfit demo`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let t0 = Instant::now();
    crate::common::check_output_dir(&args.output_dir, "-o")?;
    claim_folder(
        &args.output_dir,
        ".scatterfit-demo",
        "demo",
        " to write there",
        args.force,
    )?;
    let quiet = args.quiet || args.json;
    let cache = args.cache.dir();
    if !quiet {
        errln!(
            "synthesising the 7 materials of Choi et al. 2014 with the Monte Carlo rig twin (cached in {})",
            cache
                .as_deref()
                .map_or("no cache".into(), |p| p.display().to_string())
        );
    }
    let mut dirs = Vec::new();
    let mut truths = Vec::new();
    for material in materials() {
        let sample = synthesize(&material, args.seed, cache.as_deref(), quiet, args.quick)?;
        let dir = args.output_dir.join(&material.name);
        write_sample(&dir, &sample)?;
        dirs.push(dir);
        truths.push(sample.truth);
    }
    let synth_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let crate::runner::Comparison {
        pairs,
        dirs: pair_dirs,
        papers,
        failed,
    } = crate::runner::compare_dirs(
        &dirs,
        &scatterfit_pipeline::Overrides::default(),
        args.jobs.count(),
        quiet,
        true,
        true,
    )?;
    let measure_s = t1.elapsed().as_secs_f64();
    let out = &args.output_dir;
    let files = write_demo(out, &pairs, &papers, &truths, &pair_dirs, &failed)?;
    if args.json {
        crate::output::print_json(&files.rows)?;
    } else {
        out!("{}", files.text(out, synth_s, measure_s))?;
    }
    Ok(crate::common::list_failures("failed", &failed))
}
