//! scatterfit-render: a CPU validation renderer that shows measured parameters on an object, by the
//! two methods of Choi, Lee & Chin 2014 (§4.1–4.3, Figure 5), and reproduces the measurement's own
//! geometry to compare rendered and measured reflectance profiles (§4.4, Figure 6, Table 2).
//!
//! # Glossary
//! - **Subsurface colour method** ([`colour`], §4.1, eqs. 3–5): the colour of a layer of thickness
//!   d (found by ray casting along the light) after Groenhuis et al. 1983, times a shading model with
//!   diffuse, translucent and anisotropic specular terms.
//! - **Texture-space dipole method** ([`texture_space`], §4.2, eq. 6): the dipole BSSRDF integrated
//!   over irradiance sampled on the surface, evaluated hierarchically (Jensen & Buhler 2002).
//! - **Profile model** ([`Material`]): the forward model Rd(r) per channel, a
//!   `scatterfit_optics::ProfileModel` from any `ModelFamily` (the classical dipole, the better
//!   dipole, photon beam diffusion, the Monte Carlo tables), without touching the renderer.
//! - **Radiance** in relative units: an irradiance of 1 on a white Lambertian surface facing the
//!   light gives 1/π. Linear sRGB, D65; [`tonemap`] makes an 8-bit sRGB picture of it.
//!
//! Units: mm and mm⁻¹. Geometry and physics in f64, pixels in f32. The renderer does no file IO:
//! meshes come in as vertex and index arrays, images go out as [`scatterfit_imaging::ImageBuf`].
//! The request layer above it does, through `scatterfit_io`: [`params`] (parameters from a
//! result.json or a published set, the material through `scatterfit_mc::family`), [`measured`]
//! (the measured profile a validation compares with), [`setup`] (a mesh file or built-in shape,
//! the lights) and [`request`] (`scatterfit render`'s figure and validation as typed requests, the
//! files they write). Parallel over image rows with rayon; every random stream is
//! keyed by (seed, pixel or sample row), so a render is identical for a seed on any thread count.

#![forbid(unsafe_code)]

pub mod bvh;
pub mod colour;
pub mod error;
pub mod figure;
pub mod measured;
pub mod mesh;
pub mod params;
pub mod profile;
pub mod render;
pub mod request;
mod rng;
pub mod scene;
pub mod scenes;
pub mod settings;
pub mod setup;
pub mod texture_space;
pub mod tonemap;
pub mod validation;

pub use error::{RenderError, Result};
pub use mesh::Mesh;
pub use params::ParameterSet;
pub use profile::{Material, RdTable};
pub use render::{Method, RenderOptions, RenderStats, Rendered, Timings, render};
pub use request::{FigureRequest, Methods, ProfileRequest, RenderEvent, Summary};
pub use scene::{Camera, Light, Projection, Scene};
pub use scenes::{Shape, studio, studio_lights};
pub use setup::{LightRig, MeshSource, StudioScene};
