//! Camera, lights and the scene (mesh + BVH + lights + camera). Lengths in mm; light quantities in
//! relative radiometric units (an irradiance of 1 on a surface facing a light is the reference).

use glam::DVec3;

use crate::bvh::{Bvh, Hit, Ray};
use crate::error::{Result, invalid};
use crate::mesh::Mesh;

/// How the camera projects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Pinhole camera with a vertical field of view \[degrees\].
    Perspective {
        /// Vertical field of view \[degrees\], in (0, 180).
        fov_y_deg: f64,
    },
    /// Parallel projection showing `height_mm` vertically (pixels are square).
    Orthographic {
        /// Height of the view \[mm\].
        height_mm: f64,
    },
}

/// A camera looking from `eye` at `target`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Position \[mm\].
    pub eye: DVec3,
    /// The point at the image centre \[mm\].
    pub target: DVec3,
    /// Approximate up direction (the image's up is this made orthogonal to the view).
    pub up: DVec3,
    /// Projection.
    pub projection: Projection,
}

impl Camera {
    /// A perspective camera looking at the bounding sphere (centre `center`, `radius` \[mm\]) from
    /// direction `from` (towards the camera), framed so that the sphere fills `fill` of the image
    /// height.
    pub fn framing(center: DVec3, radius: f64, from: DVec3, fov_y_deg: f64, fill: f64) -> Self {
        let half = (0.5 * fov_y_deg).to_radians();
        let dist = radius / (fill * half.tan()).atan().sin();
        Self {
            eye: center + from.normalize() * dist,
            target: center,
            up: DVec3::Y,
            projection: Projection::Perspective { fov_y_deg },
        }
    }

    /// The width of one pixel's footprint \[mm\] at distance `t` along a camera ray, for an image
    /// `height` pixels tall.
    pub fn pixel_footprint(&self, t: f64, height: usize) -> f64 {
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                2.0 * t * (0.5 * fov_y_deg).to_radians().tan() / height as f64
            }
            Projection::Orthographic { height_mm } => height_mm / height as f64,
        }
    }

    /// The primary ray through image position (x, y) [pixels, continuous: pixel (i, j) spans
    /// [i, i+1) × [j, j+1), y down] of a `width × height` image.
    pub fn ray(&self, x: f64, y: f64, width: usize, height: usize) -> Ray {
        let forward = (self.target - self.eye).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        let (w, h) = (width as f64, height as f64);
        // Screen coordinates in [-aspect, aspect] × [-1, 1], y up.
        let sx = (2.0 * x / w - 1.0) * (w / h);
        let sy = 1.0 - 2.0 * y / h;
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                let t = (0.5 * fov_y_deg).to_radians().tan();
                Ray {
                    origin: self.eye,
                    dir: (forward + right * (sx * t) + up * (sy * t)).normalize(),
                }
            }
            Projection::Orthographic { height_mm } => {
                let half = 0.5 * height_mm;
                Ray {
                    origin: self.eye + right * (sx * half) + up * (sy * half),
                    dir: forward,
                }
            }
        }
    }
}

/// A light. Colours are linear sRGB.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    /// Parallel light from `direction` (towards the light) with `irradiance` on a surface facing it.
    Directional {
        /// Unit vector towards the light.
        direction: DVec3,
        /// Irradiance on a surface facing the light, per channel.
        irradiance: [f64; 3],
    },
    /// Isotropic point light: irradiance I·cos θ/d² at distance d.
    Point {
        /// Position \[mm\].
        position: DVec3,
        /// Radiant intensity per channel [irradiance units · mm²].
        intensity: [f64; 3],
    },
    /// A collimated beam of circular cross-section (the measurement rig's light spot): parallel light
    /// from `direction` inside the cylinder of `radius` around the axis through `center`.
    Spot {
        /// A point on the beam's axis \[mm\] (where it meets the sample).
        center: DVec3,
        /// Unit vector towards the light.
        direction: DVec3,
        /// Beam radius \[mm\].
        radius: f64,
        /// Irradiance across the beam, per channel.
        irradiance: [f64; 3],
    },
}

/// Light arriving at a point: direction towards the light, distance to it (∞ for parallel light),
/// and irradiance on a surface facing it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Incident {
    /// Unit vector towards the light.
    pub l: DVec3,
    /// Distance to the light \[mm\] (∞ for parallel light).
    pub dist: f64,
    /// Irradiance on a surface facing the light, per channel.
    pub e: [f64; 3],
}

impl Light {
    /// The light arriving at `x` (ignoring occlusion), or None where it sends none.
    pub fn incident(&self, x: DVec3) -> Option<Incident> {
        match *self {
            Light::Directional {
                direction,
                irradiance,
            } => Some(Incident {
                l: direction,
                dist: f64::INFINITY,
                e: irradiance,
            }),
            Light::Point {
                position,
                intensity,
            } => {
                let d = position - x;
                let d2 = d.length_squared();
                (d2 > 0.0).then(|| Incident {
                    l: d / d2.sqrt(),
                    dist: d2.sqrt(),
                    e: intensity.map(|i| i / d2),
                })
            }
            Light::Spot {
                center,
                direction,
                radius,
                irradiance,
            } => {
                let off = x - center;
                let radial = off - direction * off.dot(direction);
                (radial.length_squared() <= radius * radius).then_some(Incident {
                    l: direction,
                    dist: f64::INFINITY,
                    e: irradiance,
                })
            }
        }
    }

    /// Checks the light's parameters.
    ///
    /// # Errors
    /// [`crate::RenderError::InvalidOption`] for a zero direction, a negative or non-finite
    /// irradiance, or a non-positive spot radius.
    pub fn validate(&self) -> Result<()> {
        let (dir, power, radius) = match *self {
            Light::Directional {
                direction,
                irradiance,
            } => (Some(direction), irradiance, 1.0),
            Light::Point { intensity, .. } => (None, intensity, 1.0),
            Light::Spot {
                direction,
                radius,
                irradiance,
                ..
            } => (Some(direction), irradiance, radius),
        };
        if let Some(d) = dir
            && ((d.length() - 1.0).abs() >= 1e-9 || !d.is_finite())
        {
            return Err(invalid("light direction", d, "must be a unit vector"));
        }
        if !power.iter().all(|p| p.is_finite() && *p >= 0.0) {
            return Err(invalid(
                "light power",
                format!("{power:?}"),
                "must be finite and ≥ 0",
            ));
        }
        if !(radius.is_finite() && radius > 0.0) {
            return Err(invalid("spot radius [mm]", radius, "must be > 0"));
        }
        Ok(())
    }
}

/// What a render sees: a mesh with its BVH, lights and a camera.
#[derive(Debug, Clone)]
pub struct Scene {
    mesh: Mesh,
    bvh: Bvh,
    lights: Vec<Light>,
    camera: Camera,
    eps: f64,
}

/// A surface point seen along a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Position \[mm\].
    pub p: DVec3,
    /// Geometric (face) normal, unit, outward.
    pub ng: DVec3,
    /// Shading normal (interpolated vertex normals), unit, on the same side as `ng`.
    pub ns: DVec3,
    /// Origin for shadow rays: the point lifted onto the smooth surface the vertex normals describe
    /// (Hanika 2021, "Hacking the Shadow Terminator", Ray Tracing Gems II ch. 4), so that coarse
    /// meshes do not show faceted shadow terminators; `p` where the surface is locally concave.
    pub p_shadow: DVec3,
}

impl Scene {
    /// A scene; builds the BVH.
    ///
    /// # Errors
    /// [`crate::RenderError::InvalidOption`] for an invalid light.
    pub fn new(mesh: Mesh, lights: Vec<Light>, camera: Camera) -> Result<Self> {
        for l in &lights {
            l.validate()?;
        }
        let bvh = Bvh::new(&mesh);
        let b = mesh.bounds();
        let eps = 1e-7 * b.extent().max_element().max(1.0) + 1e-9;
        Ok(Self {
            mesh,
            bvh,
            lights,
            camera,
            eps,
        })
    }

    /// The mesh.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The lights.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// The camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The BVH.
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// Ray offset used against self-intersection \[mm\].
    pub fn eps(&self) -> f64 {
        self.eps
    }

    /// Nearest hit along `ray` up to `t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        self.bvh.intersect(ray, self.eps, t_max)
    }

    /// Whether the segment from `p` along `dir` up to `t_max` is blocked.
    #[inline]
    pub fn occluded(&self, p: DVec3, dir: DVec3, t_max: f64) -> bool {
        self.bvh.occluded(&Ray { origin: p, dir }, self.eps, t_max)
    }

    /// The surface point of a hit: position, geometric and shading normals.
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> SurfacePoint {
        let t = hit.triangle as usize;
        let [a, b, c] = self.mesh.corners(t);
        let ng = (b - a).cross(c - a).normalize_or(DVec3::Y);
        let [ia, ib, ic] = self.mesh.triangles()[t];
        let n = self.mesh.normals();
        let w = 1.0 - hit.u - hit.v;
        let (na, nb, nc) = (n[ia as usize], n[ib as usize], n[ic as usize]);
        let mut ns = (na * w + nb * hit.u + nc * hit.v).normalize_or(ng);
        if ns.dot(ng) < 0.0 {
            ns = ng;
        }
        let p = ray.origin + ray.dir * hit.t;
        // Hanika 2021: project p onto each vertex's tangent plane, interpolate barycentrically.
        let lift = |v: DVec3, nv: DVec3| p - nv * (p - v).dot(nv);
        let q = lift(a, na) * w + lift(b, nb) * hit.u + lift(c, nc) * hit.v;
        let p_shadow = if (q - p).dot(ng) > 0.0 { q } else { p };
        SurfacePoint {
            p,
            ng,
            ns,
            p_shadow,
        }
    }
}
