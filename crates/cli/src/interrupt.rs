//! Ctrl-C (SIGINT; also SIGTERM and SIGHUP, `ctrlc`'s `termination` feature, as a scheduler sends): the
//! temporary files of writes in flight are removed (`scatterfit_io::atomic::remove_in_flight`: one
//! registry for every writer, the Monte Carlo and synth caches included; it also stops later
//! writes), then the process exits with 130, the shell's code for an interrupted command. A result
//! file is either complete or absent; an interrupted run leaves no `.scatterfit-tmp-` file. (A run
//! killed without a chance to clean up — SIGKILL, a power cut — leaves its temporaries; the next run
//! that writes into that folder removes them once they are stale: `scatterfit_safefs::write`.)

use crate::output::errln;

/// Installs the handler (once, at start). Without one (another handler already installed, which
/// cannot happen in this binary) Ctrl-C keeps its default action.
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        let removed = scatterfit_io::atomic::remove_in_flight();
        if removed.is_empty() {
            errln!("\ninterrupted");
        } else {
            errln!(
                "\ninterrupted; removed {} unfinished temporary file(s)",
                removed.len()
            );
        }
        std::process::exit(130);
    });
}
