//! Scene set-up for a render request: the object (a built-in shape, or a mesh file read through
//! `scatterfit_io::mesh` and scaled to mm) and the lighting, framed by the studio camera
//! ([`crate::scenes::studio`]).

use std::path::PathBuf;
use std::time::Instant;

use glam::DVec3;
use scatterfit_io::mesh::{MeshReport, read_mesh};

use crate::error::{RenderError, Result};
use crate::mesh::{Aabb, Mesh};
use crate::scene::{Light, Scene};
use crate::scenes::{Shape, studio, studio_lights};

/// The lighting of a render.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum LightRig {
    /// Key light from the upper front left (irradiance 1) and a back light from behind (0.8).
    #[default]
    Studio,
    /// The key light alone.
    Key,
    /// The back light alone (irradiance 1): light through thin parts.
    Back,
    /// A point light above the front left, giving irradiance 1 at the model's centre.
    Point,
    /// A collimated spot of 2 mm radius from the key light's direction, aimed at the model's
    /// centre (irradiance 1), like the measurement rig's.
    #[cfg_attr(
        feature = "clap",
        value(
            help = "A collimated spot of 2 mm radius from the key light's direction, aimed at the model's centre (irradiance 1), like the measurement rig's: light spreading under the surface"
        )
    )]
    Spot,
}

impl LightRig {
    /// The lights for an object with these bounds.
    pub fn lights(self, bounds: &Aabb) -> Vec<Light> {
        let studio = studio_lights();
        match self {
            LightRig::Studio => studio,
            LightRig::Key => vec![studio[0]],
            LightRig::Back => match studio[1] {
                Light::Directional { direction, .. } => vec![Light::Directional {
                    direction,
                    irradiance: [1.0; 3],
                }],
                other => vec![other],
            },
            LightRig::Point => {
                let c = bounds.center();
                let r = 0.5 * bounds.extent().length();
                let position = c + DVec3::new(-0.55, 0.7, 0.45).normalize() * (3.0 * r);
                let d2 = (position - c).length_squared();
                vec![Light::Point {
                    position,
                    intensity: [d2; 3],
                }]
            }
            LightRig::Spot => match studio[0] {
                Light::Directional { direction, .. } => vec![Light::Spot {
                    center: bounds.center(),
                    direction,
                    radius: 2.0,
                    irradiance: [1.0; 3],
                }],
                other => vec![other],
            },
        }
    }
}

/// The object to render.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshSource {
    /// A built-in shape with about this many triangles (the slab is stood up 35° towards the
    /// camera so that its top shows).
    Builtin {
        /// The shape.
        shape: Shape,
        /// Triangles of the sphere or statue (about).
        triangles: usize,
    },
    /// A mesh file (.obj or .ply) whose unit is `scale` mm.
    File {
        /// The file.
        path: PathBuf,
        /// mm per file unit.
        scale: f64,
    },
}

/// A mesh ready to light, with where it came from.
#[derive(Debug, Clone)]
pub struct LoadedMesh {
    /// The mesh \[mm\].
    pub mesh: Mesh,
    /// For people: the file's path, or "built-in statue".
    pub source: String,
    /// What reading the file found (open borders, inconsistent winding, dropped triangles); none
    /// for built-in shapes.
    pub report: Option<MeshReport>,
}

impl MeshSource {
    /// Reads or builds the mesh.
    ///
    /// # Errors
    /// The file's read error (`scatterfit_io::mesh`), [`RenderError::MeshFile`] for a mesh the
    /// renderer refuses, [`RenderError::InvalidMesh`] for a built-in size it cannot make.
    pub fn load(&self) -> Result<LoadedMesh> {
        match self {
            MeshSource::File { path, scale } => {
                let data = read_mesh(path)?;
                let mesh = Mesh::new(data.positions, data.normals, data.triangles)
                    .map_err(|e| RenderError::MeshFile {
                        path: path.clone(),
                        source: Box::new(e),
                    })?
                    .scaled(*scale);
                Ok(LoadedMesh {
                    mesh,
                    source: path.display().to_string(),
                    report: Some(data.report),
                })
            }
            MeshSource::Builtin { shape, triangles } => {
                let mut mesh = shape.mesh(*triangles)?;
                if *shape == Shape::Slab {
                    // Stand the slab up a little so that its top faces the camera's side.
                    mesh = tilt(&mesh, 35f64.to_radians())?;
                }
                Ok(LoadedMesh {
                    mesh,
                    source: format!("built-in {}", shape.name()),
                    report: None,
                })
            }
        }
    }
}

impl LoadedMesh {
    /// What reading the file found, as warnings and notes for people (none for built-in shapes):
    /// an open surface, inconsistent winding, dropped degenerate triangles.
    pub fn notes(&self) -> Vec<String> {
        let Some(r) = &self.report else {
            return Vec::new();
        };
        let path = &self.source;
        let mut notes = Vec::new();
        if r.boundary_edges > 0 {
            notes.push(format!(
                "warning: {path}: the surface is open ({} border edges); thickness through it is \
                 measured to the far side where there is one",
                r.boundary_edges
            ));
        }
        if r.inconsistent_edges > 0 {
            notes.push(format!(
                "warning: {path}: {} edges join triangles wound inconsistently; computed normals \
                 may be wrong there",
                r.inconsistent_edges
            ));
        }
        if r.degenerate_dropped > 0 {
            notes.push(format!(
                "note: {path}: dropped {} degenerate triangles",
                r.degenerate_dropped
            ));
        }
        notes
    }
}

/// `mesh` rotated about the x axis by `angle` \[rad\] (towards the camera at +z).
///
/// # Errors
/// Never for a valid mesh (a rotation keeps it valid); typed as [`Mesh::new`].
pub fn tilt(mesh: &Mesh, angle: f64) -> Result<Mesh> {
    let rot = glam::DMat3::from_rotation_x(angle);
    let positions = mesh
        .positions()
        .iter()
        .map(|p| (rot * *p).to_array())
        .collect();
    let normals = mesh
        .normals()
        .iter()
        .map(|n| (rot * *n).to_array())
        .collect();
    Mesh::new(positions, Some(normals), mesh.triangles().to_vec())
}

/// The object in the studio: lights, framing camera and BVH, with what it is.
#[derive(Debug)]
pub struct StudioScene {
    /// The scene.
    pub scene: Scene,
    /// Where the mesh came from, for people.
    pub source: String,
    /// Triangles.
    pub triangles: usize,
    /// Bounding-box size \[mm\].
    pub size_mm: [f64; 3],
    /// Wall time from reading the mesh to the built BVH \[s\] (`started` of [`StudioScene::new`]).
    pub build_s: f64,
}

impl StudioScene {
    /// `loaded` lit by `lights` and framed by the studio camera; `started` is when its reading
    /// began (for [`StudioScene::build_s`]).
    ///
    /// # Errors
    /// As [`Scene::new`].
    pub fn new(loaded: LoadedMesh, lights: LightRig, started: Instant) -> Result<Self> {
        let bounds = loaded.mesh.bounds();
        let triangles = loaded.mesh.triangles().len();
        let scene = studio(loaded.mesh, lights.lights(&bounds))?;
        Ok(Self {
            scene,
            source: loaded.source,
            triangles,
            size_mm: bounds.extent().to_array(),
            build_s: started.elapsed().as_secs_f64(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quarter turn about x takes +y to +z (towards the camera), and the normals turn with it.
    #[test]
    fn tilt_turns_towards_the_camera() {
        let slab = Mesh::slab(30.0, 30.0, 4.0).unwrap();
        let turned = tilt(&slab, std::f64::consts::FRAC_PI_2).unwrap();
        let (a, b) = (slab.bounds().extent(), turned.bounds().extent());
        assert!(
            (a.y - b.z).abs() < 1e-9 && (a.z - b.y).abs() < 1e-9,
            "{a:?} {b:?}"
        );
        for (n0, n1) in slab.normals().iter().zip(turned.normals()) {
            assert!((n0.y - n1.z).abs() < 1e-9 && (n0.z + n1.y).abs() < 1e-9);
        }
    }

    /// Every rig gives irradiance 1 at the model's centre from its first light (the point light
    /// by its inverse-square intensity).
    #[test]
    fn lights_are_normalised_at_the_centre() {
        let bounds = Mesh::sphere(10.0, 16).unwrap().bounds();
        for rig in [
            LightRig::Key,
            LightRig::Back,
            LightRig::Point,
            LightRig::Spot,
        ] {
            let lights = rig.lights(&bounds);
            assert_eq!(lights.len(), 1, "{rig:?}");
            let e = match lights[0] {
                Light::Directional { irradiance, .. } | Light::Spot { irradiance, .. } => {
                    irradiance[0]
                }
                Light::Point {
                    position,
                    intensity,
                } => intensity[0] / (position - bounds.center()).length_squared(),
            };
            assert!((e - 1.0).abs() < 1e-12, "{rig:?}: {e}");
        }
        assert_eq!(LightRig::Studio.lights(&bounds), studio_lights());
    }
}
