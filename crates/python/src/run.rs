//! Long work without blocking Python: the work runs on a scoped worker thread with the GIL
//! released, while the calling thread wakes every [`POLL`] to look for Ctrl-C
//! (`Python::check_signals`) and to hand the work's progress to a Python callback (the package's
//! progress bar). On Ctrl-C the work is asked to stop ([`Control::stopped`]), the worker is
//! joined, and `KeyboardInterrupt` is raised: control returns to the notebook within one poll plus
//! the time the work takes to notice.
//!
//! Written here rather than taken from a crate: PyO3 offers the pieces (`detach`,
//! `check_signals`) but no runner; the loop is a dozen lines.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use pyo3::prelude::*;

/// How often the calling thread looks for Ctrl-C and reports progress.
const POLL: Duration = Duration::from_millis(100);

/// What the work and its watcher share: a stop request and a progress count.
#[derive(Debug, Default)]
pub(crate) struct Control {
    stop: Arc<AtomicBool>,
    done: AtomicU64,
    /// Set by the worker when the work has returned; the watcher waits on it.
    finished: Mutex<bool>,
    wake: Condvar,
}

impl Control {
    /// True once the caller asked the work to stop (Ctrl-C).
    pub(crate) fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// The stop request as a flag the library's own loops read (`BatchRequest::stop_when`).
    pub(crate) fn stop_flag(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.stop)
    }

    /// The work's progress, in the units of the total given to [`run`].
    pub(crate) fn set_done(&self, done: u64) {
        self.done.store(done, Ordering::Relaxed);
    }

    /// One more unit done.
    pub(crate) fn add_done(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }
}

/// Runs `work` with the GIL released and Ctrl-C watched; `progress(done, total)` (a Python
/// callable, or `None`) is called from the calling thread as the work goes and once at its end.
///
/// # Errors
/// `KeyboardInterrupt` (or whatever the signal handler raised) after the work stopped; the
/// progress callback's own exception; a `RuntimeError` if the work panicked.
pub(crate) fn run<R: Send>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    total: u64,
    work: impl FnOnce(&Control) -> R + Send,
) -> PyResult<R> {
    let control = Control::default();
    let shared = &control;
    std::thread::scope(|scope| {
        let worker = scope.spawn(move || {
            let result = work(shared);
            *shared.finished.lock().unwrap_or_else(|p| p.into_inner()) = true;
            shared.wake.notify_all();
            result
        });
        let mut shown = u64::MAX;
        let mut report = || -> PyResult<()> {
            let done = control.done.load(Ordering::Relaxed);
            if let Some(callback) = progress
                && done != shown
            {
                shown = done;
                callback.call1((done, total))?;
            }
            Ok(())
        };
        loop {
            let over = py.detach(|| {
                let finished = shared.finished.lock().unwrap_or_else(|p| p.into_inner());
                let (finished, _) = shared
                    .wake
                    .wait_timeout_while(finished, POLL, |f| !*f)
                    .unwrap_or_else(|p| p.into_inner());
                *finished
            });
            if over {
                break;
            }
            if let Err(e) = py.check_signals().and_then(|()| report()) {
                control.stop.store(true, Ordering::Relaxed);
                // The worker notices the request between its steps; its result is dropped.
                let _ = py.detach(move || worker.join());
                return Err(e);
            }
        }
        let result = py.detach(move || worker.join()).map_err(|panic| {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".into());
            pyo3::exceptions::PyRuntimeError::new_err(format!(
                "scatterfit stopped on an internal error ({what}); please report it"
            ))
        })?;
        report()?;
        Ok(result)
    })
}
