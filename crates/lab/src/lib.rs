//! The research tools above the measurement: what the project uses to check the method, not what
//! a lab needs to measure a sample.
//!
//! - [`twin`]: a rig twin (a [`scatterfit_synth::SyntheticSample`]) written as a sample folder, the
//!   one writer `scatterfit synth`, the demo, the study and the tests share, and
//!   [`twin_settings`], what a twin is made of (material, rig, port) from a user's settings;
//! - [`study`]: the bias study over α′, η and g (`scatterfit study`), its rows and tables, and
//!   [`study_figure`], its figure, and [`study_run`], the study as a run (its settings, fits,
//!   shards' parts and files);
//! - [`accuracy`]: the demo's table of each measured value against the twin's truth, and
//!   [`accuracy_markdown()`], its Markdown, and [`demo`], the demo's materials and files;
//! - [`partial`]: the partial files of a sharded run (`--shard K/N`) and their checks, and
//!   [`slurm`], the Slurm script of such a run (`scatterfit slurm`).
//!
//! The layers below ([`scatterfit_pipeline`], [`scatterfit_report`], `scatterfit-render`) know
//! nothing of the twin; this crate joins the two (ARCHITECTURE.md, "Workspace layout").

pub mod accuracy;
pub mod accuracy_markdown;
pub mod demo;
pub mod partial;
pub mod slurm;
pub mod study;
pub mod study_figure;
pub mod study_run;
pub mod twin;
pub mod twin_settings;

pub use accuracy_markdown::accuracy_markdown;
