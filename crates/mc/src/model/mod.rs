//! The `mc` forward model: Rd(r; σ′s, σa) of a half-space from Monte Carlo tables, smooth in the
//! albedo and the radius, with analytic derivatives of the interpolant.
//!
//! * [`McTable`] — one (η, g): a white Monte Carlo run ([`crate::white`]) scored at a grid of
//!   single-scattering albedos aₖ (σt = 1), each row smoothed by [`crate::smooth::fit_row`] into
//!   ln R̂(ρ; aₖ) = Sₖ(ln ρ) − κ₀(aₖ)ρ, plus the Monte Carlo total Rd(aₖ). Cached on disk as JSON
//!   ([`crate::cache`]: the folder is [`crate::cache::default_cache_dir`]); `scatterfit table` builds
//!   one for any η and g, and the tables shipped in the crate ([`crate::bundled`]) are such tables.
//! * [`McTableSet`] — tables for several η (same g and layout); interpolates in η.
//! * [`McProfile`] — the model for one set of optical properties, implementing
//!   [`scatterfit_optics::ProfileModel`]; the set is the `mc` [`scatterfit_optics::ModelFamily`]
//!   (the [`family`](mod@crate::family) module).
//!
//! Similarity (pbrt's `TabulatedBSSRDF::Sr`, docs/physics.md §2.3): with σs = σ′s/(1 − g), σt = σa + σs and
//! a = σs/σt, Rd(r) = σt² R̂(σt r; a) exactly (same η, g). For g = 0, σt = σ′t and a = α′.
//!
//! Interpolation: between albedos, cubic Hermite on the spline coefficients less ln a (so on
//! S − ln a, after the analytic κ₀(a)ρ is taken out: C¹ in a) in x = −√(1 − a) + 0.03·ln a, and on
//! ln(Rd/a) for the totals in x = −√(1 − a); ln a added back after. At low albedo light leaves mostly
//! after one scattering, so R̂ ∝ a to first order (the single-scattering term of the collision
//! expansion Rd = Σₙ aⁿRₙ) and ln R̂ bends like ln a, which a cubic in √(1 − a) cannot follow across
//! the first nodes: on ln Rd itself the totals between the g ≠ 0 tables' first two nodes (α′ 0.01
//! and 0.035) were 7–10 % below adding-doubling's at α′ 0.02 and 1–2 % above at 0.05; toward a → 1,
//! ln a ≈ −(1 − a) is smooth in √(1 − a) and changes little (BENCHMARKS.md, "Low albedo at g ≠ 0").
//! Beyond a few mean free paths the light has scattered n > 1 times, R̂ ∝ aⁿ, and S − ln a still
//! bends like (n − 1) ln a: the log term of the profile's abscissa, which dominates below a ≈ 0.06
//! and is negligible toward a → 1 (`table::albedo_abscissa`), took the profile at α′ 0.02 (g 0.5,
//! η 1.3) over 2–5 and 5–10 mean free paths from −3.2 and −7.9 % to +1.2 and −0.2 % of a direct
//! engine run — Catmull-Rom
//! derivatives inside (pbrt's `CatmullRomWeights`), the parabola through the three end nodes at the
//! first and last node (`Ends`); between η nodes,
//! Catmull-Rom in η on the same coefficients (linear with two tables); in ρ, the cubic B-spline itself
//! (C²). Derivatives ∂Rd/∂σ′s, ∂Rd/∂σa are those of this interpolant: through σt (the σt² factor and
//! ρ = σt r) and through a (the albedo weights' derivatives and dκ₀/da) — never finite differences.
//!
//! The module by concept: `table` ([`McTable`] and its file format), `weights` (the
//! interpolation weights), `set` ([`McTableSet`], the interpolation in η), `profile`
//! ([`McProfile`]); the table's specification is [`crate::spec`].

mod profile;
mod set;
mod table;
#[cfg(test)]
mod testing;
mod weights;

pub use crate::spec::{AlbedoSpacing, LowAlbedoRun, McTableSpec};
pub use profile::{FAR_FIELD_JOIN, FAR_FIELD_JOIN_REDUCED, McProfile};
pub(crate) use set::invert_increasing_total;
pub use set::{ETA_EDGE_TOLERANCE, McTableSet};
pub use table::{MC_TABLE_VERSION, McTable, RawProfiles};
