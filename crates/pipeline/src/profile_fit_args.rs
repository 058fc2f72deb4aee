//! The flags of a fit of a profile a user already has (`scatterfit fit`): η, α′ or the
//! spectrophotometer's Rd per channel, the method, the forward model, the light spot, the
//! innermost radius, the normalisation and what is known of g — turned into a
//! [`ProfileFitRequest`] for the profile file.

use std::path::Path;

#[cfg(feature = "clap")]
use scatterfit_io::flags::{parse_finite, parse_g, parse_g_range, parse_rgb};
use scatterfit_io::manifest::GSetting;
use scatterfit_optics::{Method, ModelName, Rgb};

use crate::anisotropy::GPrior;
use crate::profile_fit::ProfileFitRequest;

/// `scatterfit fit`'s flags but the profile and the outputs (their help is the field's text).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct ProfileFitArgs {
    /// Relative refractive index η, in [1, 3].
    #[cfg_attr(feature = "clap", arg(long, value_parser = parse_finite))]
    pub eta: f64,
    /// Reduced albedo α′ per channel R,G,B, each in (0, 1] (the proposed method needs it or --rd).
    #[cfg_attr(feature = "clap", arg(long, value_name = "R,G,B", value_parser = parse_rgb))]
    pub albedo: Option<[f64; 3]>,
    /// The spectrophotometer's total diffuse reflectance Rd per channel R,G,B, each in (0, 1].
    /// Without --albedo, α′ is inverted from it through --model at --eta and g; with --albedo,
    /// the two must agree through that model within 0.01 in Rd. Default: the model's Rd of the
    /// given α′.
    #[cfg_attr(feature = "clap", arg(long, value_name = "R,G,B", value_parser = parse_rgb))]
    pub rd: Option<[f64; 3]>,
    /// The fitting method.
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = Method::Proposed))]
    pub method: Method,
    /// The forward model (mc, exact transport, by default; dipole is the paper's).
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = ModelName::Mc))]
    pub model: ModelName,
    /// Diameter of the light spot \[mm\], in (0, 20]; the model is convolved with it.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 1.0, value_name = "MM", value_parser = parse_finite))]
    pub spot_diameter_mm: f64,
    /// Innermost fitted radius \[mm\], in [0, 1000) (default: the spot diameter).
    #[cfg_attr(feature = "clap", arg(long, value_name = "MM", value_parser = parse_finite))]
    pub r_min_mm: Option<f64>,
    /// Proposed method: fix the profile's scale by the spectrophotometer's Rd.
    #[cfg_attr(feature = "clap", arg(long))]
    pub normalise_with_spectro: bool,
    /// The material's Henyey–Greenstein g, known or assumed, in (−1, 1): the model is evaluated at
    /// it (as the manifest's `[fit] g`). Alone, g is known and its error term is 0. Or `fit`
    /// (needs --model mc): g fitted per channel from the profile within --g-range (default: what
    /// the `mc` tables cover at η, 0–0.95), printed with its standard error where the data
    /// determine it (sd(g) ≤ 0.05, the minimum inside the range); elsewhere "not determined" and
    /// the range's ± g term.
    #[cfg_attr(feature = "clap", arg(long, value_name = "G|fit", value_parser = parse_g))]
    pub g: Option<GSetting>,
    /// The range LO,HI (0 ≤ LO ≤ HI ≤ 0.95) the material's g lies in (as `[fit] g_range`),
    /// propagated into σ′s, σa and α′ as a separate "± g" term from the g-aware `mc` model; with
    /// --g the values are at that g, without it the middle of the estimates over the range.
    /// Neither --g nor --g-range: the values at g = 0 and the term over 0–0.95 (g not stated is g
    /// not known). With --albedo and no --rd, α′ is held fixed over the range (the term is then the
    /// profile's part only); give --rd to have α′ follow g.
    #[cfg_attr(feature = "clap", arg(long, value_name = "LO,HI", value_parser = parse_g_range))]
    pub g_range: Option<[f64; 2]>,
}

impl ProfileFitArgs {
    /// The fit of the profile in `profile` (its stem names the result; "profile" without one).
    pub fn request(&self, profile: &Path) -> ProfileFitRequest {
        ProfileFitRequest {
            name: profile
                .file_stem()
                .map_or_else(|| "profile".into(), |s| s.to_string_lossy().into_owned()),
            profile_file: Some(profile.to_string_lossy().into_owned()),
            eta: self.eta,
            albedo_prime: self.albedo.map(Rgb::from_array),
            rd: self.rd.map(Rgb::from_array),
            method: self.method,
            model: self.model,
            spot_diameter_mm: self.spot_diameter_mm,
            r_min_mm: self.r_min_mm,
            normalise_with_spectro: self.normalise_with_spectro,
            g_prior: GPrior::from_setting(self.g, self.g_range),
        }
    }
}
