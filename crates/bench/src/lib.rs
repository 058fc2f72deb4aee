//! The hot paths of scatterfit timed on this machine: the figures `scatterfit bench` prints and
//! BENCHMARKS.md records.
//!
//! One module per area (`optics`, `mc`, `imaging`, `render`), each a `figures(quick)` that builds
//! its problem, times it and returns [`Figure`]s; `quick` takes smaller problem sizes (the figures
//! are then not comparable with BENCHMARKS.md). [`fit::figures`] times the fit and a whole
//! measurement on a sample folder the caller wrote (the CLI's `bench fit` writes a rig-twin sample
//! as `synth` does).
//!
//! ```no_run
//! for f in scatterfit_bench::optics::figures(true)? {
//!     println!("{}: {:.3} {}", f.name, f.value, f.unit);
//! }
//! # Ok::<(), scatterfit_bench::BenchError>(())
//! ```

pub mod fit;
pub mod imaging;
pub mod mc;
pub mod optics;
pub mod render;

use serde::Serialize;

/// One measured figure.
#[derive(Debug, Clone, Serialize)]
pub struct Figure {
    /// What was measured, e.g. "dipole Rd(r) + derivatives, 300 radii".
    pub name: String,
    /// The measured value.
    pub value: f64,
    /// Its unit, e.g. "µs", "photons/s", "s".
    pub unit: String,
    /// Context: problem size, threads, the target (BENCHMARKS.md).
    pub note: String,
}

/// Why a benchmark could not run: the error of the crate whose set-up failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BenchError {
    /// The optics core refused the benchmark's parameters (a defect of the benchmark).
    #[error(transparent)]
    Optics(#[from] scatterfit_optics::OpticsError),
    /// The Monte Carlo engine refused the benchmark's sample or grid.
    #[error(transparent)]
    Mc(#[from] scatterfit_mc::McError),
    /// The image operations failed on the synthetic bracket.
    #[error(transparent)]
    Imaging(#[from] scatterfit_imaging::ImagingError),
    /// A frame of the synthetic bracket could not be written.
    #[error(transparent)]
    ImageFile(#[from] scatterfit_io::image_files::ImageFileError),
    /// The HDR stage failed on the synthetic bracket.
    #[error(transparent)]
    Pipeline(#[from] scatterfit_pipeline::PipelineError),
    /// The fit refused the benchmark's profile.
    #[error(transparent)]
    Fit(#[from] scatterfit_fit::FitError),
    /// The measurement's files could not be written.
    #[error(transparent)]
    Report(#[from] scatterfit_report::ReportError),
    /// The renderer failed on the benchmark's scene.
    #[error(transparent)]
    Render(#[from] scatterfit_render::RenderError),
    /// The thread pool of the one-thread figures could not be built.
    #[error("cannot build a thread pool: {0}")]
    Threads(#[from] rayon::ThreadPoolBuildError),
    /// A file or folder of the benchmark could not be made or written.
    #[error("{what}: {source}")]
    Io {
        /// What was being done, with the path.
        what: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

/// Result type of this crate.
pub type Result<T> = std::result::Result<T, BenchError>;
