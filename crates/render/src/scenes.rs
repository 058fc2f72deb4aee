//! Built-in models and the default studio: camera framing and lights, so that `render` works with
//! no files.

use glam::DVec3;

use crate::error::Result;
use crate::mesh::Mesh;
use crate::scene::{Camera, Light, Scene};

/// The built-in models.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Shape {
    /// A sphere of radius 10 mm.
    #[cfg_attr(feature = "clap", value(help = "Sphere, 10 mm radius"))]
    Sphere,
    /// A 30 × 30 × 4 mm slab.
    #[cfg_attr(feature = "clap", value(help = "30 × 30 × 4 mm slab"))]
    Slab,
    /// The goblet-shaped statue, 40 mm tall, with a bowl wall under 1 mm ([`Mesh::statue`]).
    #[cfg_attr(
        feature = "clap",
        value(help = "Goblet-shaped statue 40 mm tall: thick base and stem, bowl wall under 1 mm")
    )]
    Statue,
}

impl Shape {
    /// The shape's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Shape::Sphere => "sphere",
            Shape::Slab => "slab",
            Shape::Statue => "statue",
        }
    }

    /// The mesh with about `triangles` triangles (at least a coarse minimum).
    ///
    /// # Errors
    /// Never for the built-in sizes; typed for symmetry with file meshes.
    pub fn mesh(self, triangles: usize) -> Result<Mesh> {
        match self {
            Shape::Sphere => {
                let seg = ((triangles as f64).sqrt().round() as usize).max(12);
                Mesh::sphere(10.0, seg)
            }
            Shape::Slab => Mesh::slab(30.0, 30.0, 4.0),
            Shape::Statue => {
                let seg = (((triangles as f64) / 4.0).sqrt().round() as usize).max(16);
                Mesh::statue(1.0, seg)
            }
        }
    }
}

/// The default lights: a key light from the upper front left (irradiance 1) and a back light from
/// behind on the right (irradiance 0.8) that shows light through thin parts.
pub fn studio_lights() -> Vec<Light> {
    vec![
        Light::Directional {
            direction: DVec3::new(-0.55, 0.7, 0.45).normalize(),
            irradiance: [1.0; 3],
        },
        Light::Directional {
            direction: DVec3::new(0.45, 0.35, -0.82).normalize(),
            irradiance: [0.8; 3],
        },
    ]
}

/// A scene of `mesh` with the studio lights and a 30° camera slightly above the front (+z),
/// framing the mesh's bounding sphere at 90 % of the image height. A slab is tilted towards the
/// camera so that its top shows.
///
/// # Errors
/// As [`Scene::new`].
pub fn studio(mesh: Mesh, lights: Vec<Light>) -> Result<Scene> {
    let b = mesh.bounds();
    let center = b.center();
    let radius = 0.5 * b.extent().length();
    let camera = Camera::framing(center, radius, DVec3::new(0.0, 0.45, 1.0), 30.0, 0.9);
    Scene::new(mesh, lights, camera)
}
