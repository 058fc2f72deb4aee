//! Monte Carlo photon transport with MCML's physics, the profile tables built from it (the `mc`
//! forward model: [`McTable`], [`McTableSet`], [`McProfile`], over g [`McGridSet`]), and the one place where a model's
//! name becomes a model ([`family()`], [`albedo_family()`]).
//!
//! The engine follows Wang, Jacques & Zheng 1995 (MCML; the algorithm is summarised in
//! `docs/physics.md` §4.1) in millimetres: a collimated beam enters a stack of plane-parallel
//! layers (a slab, or a half-space when the last layer is infinitely thick); photons take
//! exponentially distributed steps, lose weight σa/σt at each interaction (implicit capture),
//! scatter with the Henyey–Greenstein phase function, are reflected or transmitted at the faces with
//! the Fresnel probability, and are ended by Russian roulette (threshold 10⁻⁴, chance 0.1). The
//! specular reflection at entry is reported separately.
//!
//! Tallies: Rd(r) [mm⁻²] on a radial grid with per-bin standard errors from per-photon second
//! moments, total Rd, Tt and absorbed A, and optionally Rd by exit angle.
//!
//! Determinism: photons run in chunks of [`CHUNK_PHOTONS`], each with its own xoshiro256++ stream
//! derived from (seed, chunk index); chunk tallies are summed in chunk order, so a seed gives the
//! same result bit for bit on any number of threads. Memory does not grow with the photon count.
//!
//! ```
//! use scatterfit_mc::{Beam, Layer, RadialGrid, Sample, Simulation};
//! // The standard slab (docs/physics.md §4.2): σa = 1, σs = 9 mm⁻¹, g = 0.75, n = 1, d = 0.2 mm.
//! let slab = Sample::slab(Layer::new(1.0, 9.0, 0.75, 1.0, 0.2)?, 1.0)?;
//! let sim = Simulation::new(slab, Beam::pencil(), RadialGrid::uniform(0.1, 20)?, 10_000, 1)?;
//! let result = sim.run();
//! assert!((result.rd_total.value - 0.0974).abs() < 5.0 * result.rd_total.stderr + 1e-3);
//! # Ok::<(), scatterfit_mc::McError>(())
//! ```

#![forbid(unsafe_code)]

mod beam;
pub mod bundled;
pub mod cache;
mod engine;
mod error;
pub mod exact;
pub mod family;
mod fresnel;
mod grid;
pub mod grid_g;
pub mod model;
mod phase;
pub mod port;
pub mod report;
mod rng;
mod sample;
pub mod shard;
pub mod smooth;
pub mod spec;
pub mod white;

pub use beam::{Beam, BeamProfile};
pub use engine::{
    CHUNK_PHOTONS, CostEstimate, McMean, REFERENCE_INTERACTIONS_PER_SECOND, ROULETTE_CHANCE,
    ROULETTE_THRESHOLD, Simulation, SimulationResult,
};
pub use error::{McError, Result};
pub use family::{albedo_family, bundled_grid, bundled_tables, family};
pub use fresnel::{FresnelSample, fresnel_mcml};
pub use grid::RadialGrid;
pub use grid_g::{McGridProfile, McGridSet};
pub use model::{McProfile, McTable, McTableSet};
pub use phase::{hg_cdf_cos, hg_pdf_cos, sample_hg_cos};
pub use report::{SimulationReport, TableSummary};
pub use sample::{Layer, Sample};
pub use shard::{Shard, ShardError};
pub use spec::{AlbedoSpacing, LowAlbedoRun, McTableSpec};
