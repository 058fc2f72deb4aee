//! Many samples measured in parallel: as many at once as the memory budget allows, every sample's
//! outcome kept (a failed sample never stops the others), a callback per finished sample.
//!
//! ```no_run
//! use std::path::PathBuf;
//!
//! use scatterfit_pipeline::batch::{BatchRequest, measure_batch};
//! use scatterfit_pipeline::{ModelName, Overrides};
//!
//! let dirs = vec![PathBuf::from("samples/pink-plastic"), PathBuf::from("samples/wood-tile")];
//! let request = BatchRequest::new(dirs, Overrides::default().model(ModelName::Mc)).jobs(2);
//! let outcome = measure_batch(request, &|_| {})?;
//! for sample in &outcome.samples {
//!     match &sample.outcome {
//!         Ok(m) => println!("{}: η = {:.4}", sample.dir.display(), m.eta().value),
//!         Err(e) => println!("{}: {e}", sample.dir.display()),
//!     }
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Each sample's manifest and inputs are resolved once, when the request is made
//! ([`BatchSample::new`], [`crate::sample_inputs`]): the job count is planned from them (the
//! frames' headers, [`crate::SampleInputs::peak_memory_bytes`]) and the measurement starts from
//! them ([`crate::measure_inputs`]). A caller that checks its outputs against a sample's inputs
//! before any work (as the command-line tool does) reads them from [`BatchSample::inputs`].

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::error::{PipelineError, Result};
use crate::measure::measure_inputs_until;
use crate::measurement::Measurement;
use crate::samples::{SampleInputs, sample_inputs};
use crate::settings::Overrides;

/// Why a batch could not run at all (a sample that fails is an outcome, not this).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BatchError {
    /// The worker threads could not be started.
    #[error("starting the worker threads: {0}")]
    ThreadPool(#[from] rayon::ThreadPoolBuildError),
}

/// One sample of a batch: its folder, its manifest and inputs as resolved once, and its options.
#[derive(Debug)]
pub struct BatchSample {
    /// The sample folder (or manifest file), as given.
    pub dir: PathBuf,
    /// Its manifest and input files, or why they cannot be read (the sample's outcome is then this
    /// error).
    pub inputs: Result<SampleInputs>,
    /// What overrides its manifest's `[fit]`.
    pub overrides: Overrides,
}

impl BatchSample {
    /// Resolves the sample in `dir` ([`sample_inputs`], with `overrides.allow_outside_paths`).
    pub fn new(dir: PathBuf, overrides: Overrides) -> Self {
        let inputs = sample_inputs(&dir, overrides.allow_outside_paths);
        Self {
            dir,
            inputs,
            overrides,
        }
    }
}

/// Samples to measure, and how many at once.
#[derive(Debug)]
pub struct BatchRequest {
    /// The samples, in the order their outcomes are returned.
    pub samples: Vec<BatchSample>,
    /// Samples measured at once; 0 for one per core. Fewer run when that many would not fit
    /// `memory_budget` ([`JobPlan`]).
    pub jobs: usize,
    /// The memory the samples measured at once may take \[bytes\] (default:
    /// `scatterfit_io::budget::memory_budget_bytes`: half the machine's memory, or `$SCATTERFIT_MAX_MEMORY_MIB`).
    pub memory_budget: u64,
    /// Once it reads true, the samples not yet started are not measured and the running ones stop
    /// before their next stage: their outcome is [`PipelineError::Interrupted`]. A caller's Ctrl-C.
    pub stop: Option<Arc<AtomicBool>>,
}

impl BatchRequest {
    /// Every folder of `dirs` with the same `overrides`, resolved now ([`BatchSample::new`]); one
    /// sample per core, the default memory budget.
    pub fn new(dirs: impl IntoIterator<Item = PathBuf>, overrides: Overrides) -> Self {
        Self::from_samples(
            dirs.into_iter()
                .map(|d| BatchSample::new(d, overrides))
                .collect(),
        )
    }

    /// Samples already resolved (each with its own overrides); one per core, the default memory
    /// budget.
    pub fn from_samples(samples: Vec<BatchSample>) -> Self {
        Self {
            samples,
            jobs: 0,
            memory_budget: scatterfit_io::budget::memory_budget_bytes(),
            stop: None,
        }
    }

    /// Stops starting samples once `flag` reads true ([`BatchRequest::stop`]).
    #[must_use]
    pub fn stop_when(self, flag: Arc<AtomicBool>) -> Self {
        Self {
            stop: Some(flag),
            ..self
        }
    }

    /// At most `jobs` samples at once (0: one per core).
    #[must_use]
    pub fn jobs(self, jobs: usize) -> Self {
        Self { jobs, ..self }
    }

    /// The memory budget \[bytes\].
    #[must_use]
    pub fn memory_budget(self, bytes: u64) -> Self {
        Self {
            memory_budget: bytes,
            ..self
        }
    }

    /// How many samples run at once: [`BatchRequest::jobs`] (one per core for 0), at most one per
    /// sample, fewer while that many of the largest samples would not fit the memory budget
    /// (checked from the frames' headers before any is read), never below one.
    pub fn plan(&self) -> JobPlan {
        let requested = if self.jobs == 0 {
            rayon::current_num_threads()
        } else {
            self.jobs
        }
        .clamp(1, self.samples.len().max(1));
        let mut sizes: Vec<u64> = self
            .samples
            .iter()
            .map(|s| s.inputs.as_ref().map_or(0, SampleInputs::peak_memory_bytes))
            .collect();
        sizes.sort_unstable_by(|a, b| b.cmp(a));
        let mut jobs = requested;
        while jobs > 1 && sizes.iter().take(jobs).sum::<u64>() > self.memory_budget {
            jobs -= 1;
        }
        JobPlan {
            requested,
            jobs,
            memory_needed: sizes.iter().take(requested).sum(),
            memory_budget: self.memory_budget,
        }
    }
}

/// How many samples a batch measures at once, and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct JobPlan {
    /// What was asked for (one per core for 0), at most one per sample.
    pub requested: usize,
    /// What runs: `requested`, or fewer when that many would not fit the budget.
    pub jobs: usize,
    /// The memory `requested` of the largest samples would take \[bytes\] (estimated).
    pub memory_needed: u64,
    /// The budget \[bytes\].
    pub memory_budget: u64,
}

impl JobPlan {
    /// True when fewer samples run at once than were asked for (a caller may say so).
    pub fn reduced(&self) -> bool {
        self.jobs < self.requested
    }
}

/// What a batch reports while it runs (from worker threads).
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub enum BatchEvent<'a> {
    /// Before any sample: the plan.
    Started(&'a JobPlan),
    /// A sample is done (its per-sample work, e.g. writing its results, has run).
    Finished {
        /// Its folder.
        dir: &'a Path,
        /// Samples done so far, this one included.
        finished: usize,
        /// Samples in the batch.
        total: usize,
    },
}

/// One sample's outcome, with its folder.
#[derive(Debug)]
pub struct SampleOutcome<T> {
    /// The folder, as given.
    pub dir: PathBuf,
    /// What the per-sample work returned (by default the measurement, or why there is none).
    pub outcome: T,
}

/// Every sample's outcome, in the request's order, and the plan they were run with.
#[derive(Debug)]
pub struct BatchOutcome<T = Result<Measurement>> {
    /// How many ran at once.
    pub plan: JobPlan,
    /// Per sample, in the order of the request.
    pub samples: Vec<SampleOutcome<T>>,
}

/// Measures every sample of `request` ([`measure_batch_with`] keeping each measurement).
///
/// # Errors
/// [`BatchError`] only when the worker threads cannot start; a sample that fails is its outcome.
pub fn measure_batch(
    request: BatchRequest,
    on_event: &(dyn Fn(BatchEvent<'_>) + Sync),
) -> std::result::Result<BatchOutcome, BatchError> {
    measure_batch_with(request, &|_, m| m, on_event)
}

/// Measures every sample of `request`, [`JobPlan::jobs`] at a time, and runs `work` on each
/// measurement as soon as it is done, on the worker thread (write its result files there, so a
/// batch never loses a finished sample); what `work` returns is the sample's outcome.
///
/// # Errors
/// [`BatchError`] only when the worker threads cannot start.
pub fn measure_batch_with<T: Send>(
    request: BatchRequest,
    work: &(dyn Fn(&Path, Result<Measurement>) -> T + Sync),
    on_event: &(dyn Fn(BatchEvent<'_>) + Sync),
) -> std::result::Result<BatchOutcome<T>, BatchError> {
    let stop = request.stop.clone();
    let stopped = || stop.as_ref().is_some_and(|s| s.load(Ordering::Relaxed));
    for_each_sample(
        request,
        &|sample| {
            let measured = if stopped() {
                Err(PipelineError::Interrupted)
            } else {
                // A sample already running stops before its next stage.
                sample.inputs.and_then(|inputs| {
                    measure_inputs_until(&inputs, &sample.overrides, &|_| {}, &stopped)
                })
            };
            work(&sample.dir, measured)
        },
        on_event,
    )
}

/// Runs `job` on every sample of `request` in a pool of [`BatchRequest::plan`]'s size; outcomes in
/// the request's order.
pub(crate) fn for_each_sample<T: Send>(
    request: BatchRequest,
    job: &(dyn Fn(BatchSample) -> T + Sync),
    on_event: &(dyn Fn(BatchEvent<'_>) + Sync),
) -> std::result::Result<BatchOutcome<T>, BatchError> {
    let plan = request.plan();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(plan.jobs)
        .build()?;
    on_event(BatchEvent::Started(&plan));
    let total = request.samples.len();
    let finished = AtomicUsize::new(0);
    let samples = pool.install(|| {
        request
            .samples
            .into_par_iter()
            .map(|sample| {
                let dir = sample.dir.clone();
                let outcome = job(sample);
                on_event(BatchEvent::Finished {
                    dir: &dir,
                    finished: finished.fetch_add(1, Ordering::Relaxed) + 1,
                    total,
                });
                SampleOutcome { dir, outcome }
            })
            .collect()
    });
    Ok(BatchOutcome { plan, samples })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plan: one job per sample at most, fewer while the largest samples would not fit the
    /// budget, never below one; a sample whose inputs cannot be read counts nothing.
    #[test]
    fn jobs_fit_the_memory_budget() {
        let dir = tempfile::tempdir().unwrap();
        let missing =
            |k: usize| BatchSample::new(dir.path().join(format!("none{k}")), Overrides::default());
        let request = BatchRequest::from_samples((0..3).map(missing).collect()).jobs(8);
        let plan = request.plan();
        assert_eq!((plan.requested, plan.jobs, plan.memory_needed), (3, 3, 0));
        assert!(!plan.reduced());
        let request = BatchRequest::from_samples(Vec::new()).jobs(0);
        assert_eq!(request.plan().jobs, 1);
    }

    /// A batch keeps every sample's outcome in order, reports each finished sample once, and a
    /// sample that cannot be read is an outcome, not a failed batch.
    #[test]
    fn a_stopped_batch_starts_no_sample() {
        let dir = tempfile::tempdir().unwrap();
        let dirs: Vec<PathBuf> = (0..3).map(|k| dir.path().join(format!("s{k}"))).collect();
        let stop = Arc::new(AtomicBool::new(true));
        let outcome = measure_batch(
            BatchRequest::new(dirs, Overrides::default()).stop_when(stop),
            &|_| {},
        )
        .unwrap();
        assert_eq!(outcome.samples.len(), 3);
        // Not the missing folders' input error: nothing was started.
        assert!(
            outcome
                .samples
                .iter()
                .all(|s| matches!(s.outcome, Err(PipelineError::Interrupted)))
        );
    }

    #[test]
    fn failures_are_outcomes_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let dirs: Vec<PathBuf> = (0..4).map(|k| dir.path().join(format!("s{k}"))).collect();
        let seen = std::sync::Mutex::new(Vec::new());
        let outcome = measure_batch(
            BatchRequest::new(dirs.clone(), Overrides::default()).jobs(2),
            &|e| {
                if let BatchEvent::Finished {
                    finished, total, ..
                } = e
                {
                    seen.lock().unwrap().push((finished, total));
                }
            },
        )
        .unwrap();
        let got: Vec<&PathBuf> = outcome.samples.iter().map(|s| &s.dir).collect();
        assert_eq!(got, dirs.iter().collect::<Vec<_>>());
        assert!(outcome.samples.iter().all(|s| s.outcome.is_err()));
        let mut seen = seen.into_inner().unwrap();
        seen.sort_unstable();
        assert_eq!(seen, [(1, 4), (2, 4), (3, 4), (4, 4)]);
    }
}
