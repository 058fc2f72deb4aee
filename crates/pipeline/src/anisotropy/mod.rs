//! The anisotropy g when it is not known exactly: a stated range of g propagated into
//! σ′s, σa and α′ as a separate uncertainty term ([`scatterfit_optics::Estimate::g`]) beside the
//! fit's and the spectrophotometer's.
//!
//! **Why a term.** The total diffuse reflectance at fixed reduced coefficients depends on g, so
//! α′ from the spectrophotometer does, and so does the profile's near field (the similarity
//! relation σ′s = σs(1 − g) holds only in the far field; Wyman, Patterson & Wilson 1989). A σa
//! computed at g = 0 for a material with g ≈ 0.85 is 5–25 % high (BENCHMARKS.md, "What assuming
//! g = 0 costs") — far outside a fit ± spectro error bar of a few tenths of a percent.
//!
//! **How.** The estimate is recomputed with the g-aware exact model — the `mc` tables over (η, g)
//! for the profile and for the α′ inversion (`scatterfit_mc::family(ModelName::Mc)` and
//! `albedo_family(AlbedoModel::Mc, …)` at each g through [`AtG`](scatterfit_optics::AtG)) — at every g of the range the
//! tables answer: the tables' g nodes inside the range and the range's ends
//! ([`GPlan::points`]). Proposed method: α′(g′) from the reading's Rd, then σ′s fitted with it;
//! existing method: σ′s and σa both fitted at g′. The term is
//! - the largest |E(g′) − E(g₀)| over the points, where g₀ is the g the values are computed at
//!   (the given `[fit] g`, or 0 when neither g nor a range is stated); or
//! - for a range without a g: half the spread (max − min)/2, the values then being the middle
//!   (max + min)/2 of the estimates (when the value's model is `mc` with the `mc` α′; a g-blind
//!   diffusion dipole keeps its value, and its term is the largest deviation from the `mc`
//!   estimate at the g its fit used).
//!
//! This is a bound, not a standard deviation: a g anywhere in the range gives an estimate within
//! it (where the estimates change monotonically with g, as they do on the twins, BENCHMARKS.md
//! "The g term: coverage when g is not known"), so the total adds it linearly to the quadrature sum of the fit's and
//! the spectrophotometer's standard errors ([`scatterfit_optics::Estimate::total`]). The
//! diffusion dipoles do not depend on g; their g term is the sensitivity of the g-aware estimate,
//! which is what their user needs to know. Parts of the range the tables do not cover are not
//! evaluated (never extrapolated) and are named in the result ([`GPlan::not_covered`]).
//!
//! [`with_g_term`] gives the fitted channels their term (and their fit of g). The parts: [`plan`] (what is known about g, where the term is evaluated), [`term`] (the term
//! itself), [`fit`] (`g = "fit"`: g fitted from the profile) and [`record`] (what they give a
//! fitted channel: its term, its fit of g).

pub mod fit;
pub mod plan;
pub mod record;
pub mod term;

pub use fit::{
    ALBEDO_DETERMINED_MAX, G_DETERMINED_SD, MODEL_SHAPE_NOISE, SCAN_FINE_FROM, SCAN_STEP,
    SCAN_STEP_COARSE, fit_g, fit_g_channels, scan_points,
};
pub use plan::{DEFAULT_G_RANGE, GPlan, GPrior, default_search_range, known_g_record};
pub use record::{AlbedoAtG, GFit, GTerm};
pub use term::propagate_g;

use scatterfit_fit::ProfileData;
use scatterfit_optics::Rgb;

use crate::fit::outcome::ChannelOutcome;
use crate::settings::FitPlan;
use crate::spectro::SpectroStage;

/// The outcomes with the g term of the plan's g prior ([`crate::anisotropy`]; 0 when g is known),
/// its refits made with the plan's options. A g plan that cannot be made (the tables cover no g of
/// the range) leaves the terms unknown, with the reason in each channel's note.
pub fn with_g_term(
    profiles: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    plan: &FitPlan,
    fits: Rgb<ChannelOutcome>,
    albedo_at_g: AlbedoAtG,
) -> Rgb<ChannelOutcome> {
    let settings = &plan.settings;
    match GPlan::new(&settings.g_prior, settings.g) {
        Ok(None) => fits.map(|f| f.with_g(None)),
        Ok(Some(g_plan)) if settings.g_prior.fit => {
            let fitted = fit_g_channels(profiles, spectro, plan, &fits, g_plan.range, albedo_at_g);
            let terms = propagate_g(profiles, spectro, plan, &fits, &g_plan, albedo_at_g);
            fits.zip(fitted)
                .zip(terms)
                .map(|((f, g), t)| f.with_g_fit(g, t))
        }
        Ok(Some(g_plan)) => {
            let terms = propagate_g(profiles, spectro, plan, &fits, &g_plan, albedo_at_g);
            fits.zip(terms).map(|(f, t)| f.with_g(t))
        }
        Err(e) => fits.map(|f| f.with_g(Some(Err(e.to_string())))),
    }
}
