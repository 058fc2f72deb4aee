//! scatterfit-optics: the pure physics of scatterfit. No files, no threads, no CLI.
//!
//! Glossary (graphics notation, millimetres; biomedical optics writes μ where we write σ):
//!
//! | symbol | name in code | meaning | unit |
//! |---|---|---|---|
//! | σa | `sigma_a` | absorption coefficient | mm⁻¹ |
//! | σ′s | `sigma_s_prime` | reduced scattering coefficient σs(1−g) | mm⁻¹ |
//! | σ′t | `sigma_t_prime` | σa + σ′s | mm⁻¹ |
//! | α′ | `albedo_prime` | reduced albedo σ′s/σ′t | 1 |
//! | σtr | `sigma_tr` | effective transport coefficient √(3σaσ′t) | mm⁻¹ |
//! | η | `eta` | relative refractive index (material / air) | 1 |
//! | Fdr | `f_dr` | diffuse Fresnel reflectance | 1 |
//! | Rd(r) | `rd_profile` | radially resolved diffuse reflectance | mm⁻² |
//! | Rd | `rd_total` | total diffuse reflectance ∫2πr Rd(r) dr | 1 |
//!
//! Modules: [`fresnel`] (exact Fresnel, Schlick, η from a d/8 specular reflectance, pbrt's Fresnel
//! moments), [`dipole`] (Jensen et al. 2001 classical dipole, its total reflectance and the α′
//! inversion), [`better_dipole`] (d'Eon 2012), [`pbd`] (photon beam diffusion, Habel et al. 2013 as
//! pbrt-v4 evaluates it), [`model`] (the diffusion models as [`ModelFamily`]s, [`DiffusionModel`]),
//! [`colour`] (spectra → CIE XYZ → L\*a\*b\* / linear sRGB), [`spectro`] (the spectrophotometer
//! stage).
//!
//! The vocabulary the crates above share: [`Channel`] and [`Rgb`] (a value per linear-sRGB
//! channel, by name), [`ModelName`], [`AlbedoModel`] and [`Method`] (what a user chooses), and the
//! forward-model traits [`ProfileModel`] (Rd(r) of one parameter set) and [`ModelFamily`] (a named
//! model: profiles, its total Rd(α′, η, g) and the α′ inversion), and [`Estimate`] (a measured value
//! with the standard errors of its independent sources: fit, spectrophotometer, g).

pub mod better_dipole;
pub mod colour;
pub mod dipole;
pub mod estimate;
pub mod family;
pub mod fresnel;
pub mod materials;
pub mod model;
pub mod names;
pub mod pbd;
pub mod port;
pub mod rgb;
pub mod spectro;
pub mod termination;

mod diffusion;
mod dual;
mod error;
pub mod numerics;
mod properties;

/// The root finder's old path.
pub use numerics::roots;

pub use error::{OpticsError, Result};
pub use estimate::Estimate;
pub use family::{AtG, ModelFamily, ProfileModel, ProfileSample};
pub use model::DiffusionModel;
pub use names::{AlbedoModel, Method, ModelName, Parameter};
pub use properties::OpticalProperties;
pub use rgb::{Channel, Rgb};
pub use termination::Termination;
