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
//! Units: mm and mm⁻¹. Geometry and physics in f64, pixels in f32. No file IO here: meshes come in
//! as vertex and index arrays (`scatterfit_io::mesh` reads OBJ and PLY), images go out as
//! [`scatterfit_imaging::ImageBuf`]. Parallel over image rows with rayon; every random stream is
//! keyed by (seed, pixel or sample row), so a render is identical for a seed on any thread count.

#![forbid(unsafe_code)]

pub mod bvh;
pub mod colour;
pub mod error;
pub mod figure;
pub mod mesh;
pub mod profile;
pub mod render;
mod rng;
pub mod scene;
pub mod scenes;
pub mod texture_space;
pub mod tonemap;
pub mod validation;

pub use error::{RenderError, Result};
pub use mesh::Mesh;
pub use profile::{Material, RdTable};
pub use render::{Method, RenderOptions, RenderStats, Rendered, Timings, render};
pub use scene::{Camera, Light, Projection, Scene};
pub use scenes::{Shape, studio, studio_lights};
