//! Triangle meshes in millimetres, and the built-in models (sphere, slab, statue).
//!
//! World coordinates: right-handed, **y up**, lengths in mm. Triangles wind counter-clockwise seen
//! from outside, so that the geometric normal (v1 − v0) × (v2 − v0) points out of the object.

use glam::DVec3;

use crate::error::{RenderError, Result};

/// An axis-aligned box \[mm\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: DVec3,
    /// Upper corner.
    pub max: DVec3,
}

impl Aabb {
    /// The empty box (grows from nothing).
    pub const EMPTY: Self = Self {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// The box grown to hold `p`.
    #[inline]
    pub fn grow(self, p: DVec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The union of two boxes.
    #[inline]
    pub fn union(self, o: Self) -> Self {
        Self {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// Centre of the box.
    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Edge lengths.
    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }

    /// Surface area (0 for the empty box).
    #[inline]
    pub fn area(&self) -> f64 {
        let e = (self.max - self.min).max(DVec3::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}

/// A triangle mesh: positions \[mm\], unit vertex normals (shading), and triangles as vertex indices.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// A mesh from positions \[mm\], optional per-vertex normals (computed as area-weighted averages of
    /// the adjacent faces' normals when `None`) and triangles.
    ///
    /// # Errors
    /// [`RenderError::InvalidMesh`] for no triangle, an index out of range, a non-finite coordinate
    /// or normal, or a normal count that differs from the vertex count.
    pub fn new(
        positions: Vec<[f64; 3]>,
        normals: Option<Vec<[f64; 3]>>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Self> {
        if triangles.is_empty() {
            return Err(RenderError::InvalidMesh("the mesh has no triangle".into()));
        }
        if let Some(i) = positions
            .iter()
            .position(|p| !p.iter().all(|v| v.is_finite()))
        {
            return Err(RenderError::InvalidMesh(format!(
                "vertex {i} has a non-finite coordinate {:?}",
                positions[i]
            )));
        }
        let n = positions.len();
        if let Some((t, tri)) = triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&i| i as usize >= n))
        {
            return Err(RenderError::InvalidMesh(format!(
                "triangle {t} refers to vertex {tri:?}, but there are only {n} vertices"
            )));
        }
        let positions: Vec<DVec3> = positions.into_iter().map(DVec3::from).collect();
        let normals = match normals {
            Some(nrm) => {
                if nrm.len() != n {
                    return Err(RenderError::InvalidMesh(format!(
                        "{} normals for {n} vertices",
                        nrm.len()
                    )));
                }
                let mut out = Vec::with_capacity(n);
                for (i, v) in nrm.into_iter().enumerate() {
                    let v = DVec3::from(v);
                    let len = v.length();
                    if !(len.is_finite() && len > 0.0) {
                        return Err(RenderError::InvalidMesh(format!(
                            "normal {i} {v:?} is zero or not finite"
                        )));
                    }
                    out.push(v / len);
                }
                out
            }
            None => vertex_normals(&positions, &triangles),
        };
        Ok(Self {
            positions,
            normals,
            triangles,
        })
    }

    /// Vertex positions \[mm\].
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Unit vertex normals.
    pub fn normals(&self) -> &[DVec3] {
        &self.normals
    }

    /// Triangles (vertex indices, counter-clockwise seen from outside).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The three corners of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// The bounding box \[mm\].
    pub fn bounds(&self) -> Aabb {
        self.positions.iter().fold(Aabb::EMPTY, |b, &p| b.grow(p))
    }

    /// Total surface area \[mm²\].
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Enclosed volume \[mm³\] by the divergence theorem (positive for outward winding; meaningful for
    /// closed meshes).
    pub fn signed_volume(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// The mesh scaled by `factor` (e.g. mm per file unit) about the origin.
    pub fn scaled(mut self, factor: f64) -> Self {
        for p in &mut self.positions {
            *p *= factor;
        }
        self
    }

    /// The mesh translated by `offset` \[mm\].
    pub fn translated(mut self, offset: DVec3) -> Self {
        for p in &mut self.positions {
            *p += offset;
        }
        self
    }

    fn flipped(mut self) -> Self {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
        for n in &mut self.normals {
            *n = -*n;
        }
        self
    }

    /// A UV sphere of `radius` \[mm\] centred at the origin, with `segments` around and `segments/2`
    /// rings (about `segments²` triangles).
    ///
    /// # Errors
    /// [`RenderError::InvalidOption`] for a non-positive radius or fewer than 6 segments.
    pub fn sphere(radius: f64, segments: usize) -> Result<Self> {
        positive("sphere radius [mm]", radius)?;
        if segments < 6 {
            return Err(crate::error::invalid(
                "sphere segments",
                segments,
                "need at least 6",
            ));
        }
        let rings = (segments / 2).max(3);
        let profile: Vec<[f64; 2]> = (0..=rings)
            .map(|i| {
                let th = std::f64::consts::PI * i as f64 / rings as f64;
                // Exact zeros at the poles (sin π is 1.2e-16, not 0).
                let r = if i == 0 || i == rings {
                    0.0
                } else {
                    radius * th.sin()
                };
                [r, -radius * th.cos()]
            })
            .collect();
        Ok(revolve(&profile, segments, |_, _, r| r))
    }

    /// A box slab: `width` (x) × `depth` (z) × `thickness` (y) \[mm\], its top face at y = 0 facing +y,
    /// centred on the y axis. Faces have their own vertices (flat normals).
    ///
    /// # Errors
    /// [`RenderError::InvalidOption`] for a non-positive dimension.
    pub fn slab(width: f64, depth: f64, thickness: f64) -> Result<Self> {
        positive("slab width [mm]", width)?;
        positive("slab depth [mm]", depth)?;
        positive("slab thickness [mm]", thickness)?;
        let (hx, hz) = (0.5 * width, 0.5 * depth);
        let lo = DVec3::new(-hx, -thickness, -hz);
        let hi = DVec3::new(hx, 0.0, hz);
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        let mut triangles = Vec::new();
        // Each face: normal, and two tangent axes u, v with u × v = normal.
        let faces = [
            (DVec3::Y, DVec3::Z, DVec3::X),
            (DVec3::NEG_Y, DVec3::X, DVec3::Z),
            (DVec3::X, DVec3::Y, DVec3::Z),
            (DVec3::NEG_X, DVec3::Z, DVec3::Y),
            (DVec3::Z, DVec3::X, DVec3::Y),
            (DVec3::NEG_Z, DVec3::Y, DVec3::X),
        ];
        let c = 0.5 * (lo + hi);
        let h = 0.5 * (hi - lo);
        for (n, u, v) in faces {
            let base = positions.len() as u32;
            for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let p = c + n * h + su * u * h + sv * v * h;
                positions.push(p.to_array());
                normals.push(n.to_array());
            }
            triangles.push([base, base + 1, base + 2]);
            triangles.push([base, base + 2, base + 3]);
        }
        Self::new(positions, Some(normals), triangles)
    }

    /// The statue: a goblet 40 mm tall (× `scale`) standing on y = 0 — a thick fluted base and a
    /// stem with a knot, carrying a bowl whose wall is 0.6–1 mm thin (where the subsurface colour
    /// method shows light through the material) and thick at its foot. A closed surface of
    /// revolution with `segments` around and about `2·segments` profile points: ≈ 4·segments²
    /// triangles (158 segments ≈ 100k).
    ///
    /// # Errors
    /// [`RenderError::InvalidOption`] for a non-positive scale or fewer than 8 segments.
    pub fn statue(scale: f64, segments: usize) -> Result<Self> {
        positive("statue scale", scale)?;
        if segments < 8 {
            return Err(crate::error::invalid(
                "statue segments",
                segments,
                "need at least 8",
            ));
        }
        // Profile (r, y) in mm from the bottom centre, out along the base, up the outside, over the
        // rim and down the inside of the bowl to its centre. Smoothed by Catmull-Rom.
        const CONTROL: [[f64; 2]; 27] = [
            [0.0, 0.0],
            [7.0, 0.0],
            [12.5, 0.0],
            [13.8, 0.5],
            [14.0, 1.6],
            [13.2, 2.6],
            [9.5, 3.4],
            [5.5, 4.4],
            [3.4, 6.0],
            [3.1, 7.8],
            [5.2, 9.6],
            [5.2, 10.8],
            [3.0, 12.6],
            [2.6, 15.5],
            [3.2, 18.0],
            [6.5, 20.0],
            [11.0, 23.0],
            [14.0, 27.0],
            [15.4, 32.0],
            [15.7, 37.0],
            [15.6, 39.6],
            [15.25, 40.0],
            [14.9, 39.6],
            [14.9, 37.0],
            [14.5, 32.0],
            [8.0, 22.8],
            [0.0, 21.0],
        ];
        let samples = 2 * segments;
        let profile = smooth_profile(&CONTROL, samples);
        let mesh = revolve(&profile, segments, |k, theta, r| {
            // Fluting on the base's top and the knot (profile samples below the bowl): 12 grooves.
            let y = profile[k][1];
            let amp = if (2.8..=11.5).contains(&y) { 0.06 } else { 0.0 };
            r * (1.0 + amp * (12.0 * theta).cos())
        });
        Ok(mesh.scaled(scale))
    }
}

fn positive(name: &'static str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(crate::error::invalid(name, v, "must be a positive number"))
    }
}

/// Area-weighted vertex normals (each face's unnormalised cross product summed at its corners).
/// A vertex of only degenerate faces gets +y.
pub fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut acc = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            acc[i as usize] += n;
        }
    }
    acc.into_iter()
        .map(|n| n.try_normalize().unwrap_or(DVec3::Y))
        .collect()
}

/// Catmull-Rom spline through `control` (centripetal parametrisation is unnecessary: the points are
/// roughly evenly spaced), resampled to `samples` points evenly spaced in arc length; the ends stay
/// on the axis.
fn smooth_profile(control: &[[f64; 2]], samples: usize) -> Vec<[f64; 2]> {
    let p = |i: isize| {
        let i = i.clamp(0, control.len() as isize - 1) as usize;
        glam::DVec2::from(control[i])
    };
    let mut dense = Vec::new();
    const PER: usize = 32;
    for i in 0..control.len() as isize - 1 {
        let (p0, p1, p2, p3) = (p(i - 1), p(i), p(i + 1), p(i + 2));
        for k in 0..PER {
            let t = k as f64 / PER as f64;
            let (t2, t3) = (t * t, t * t * t);
            dense.push(
                0.5 * (2.0 * p1
                    + (p2 - p0) * t
                    + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
                    + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3),
            );
        }
    }
    dense.push(p(control.len() as isize - 1));
    let mut cum = vec![0.0];
    for w in dense.windows(2) {
        cum.push(cum.last().unwrap() + (w[1] - w[0]).length());
    }
    let total = *cum.last().unwrap();
    let mut out = Vec::with_capacity(samples + 1);
    let mut j = 0;
    for k in 0..=samples {
        let s = total * k as f64 / samples as f64;
        while j + 1 < cum.len() - 1 && cum[j + 1] < s {
            j += 1;
        }
        let f = ((s - cum[j]) / (cum[j + 1] - cum[j]).max(1e-300)).clamp(0.0, 1.0);
        let q = dense[j].lerp(dense[j + 1], f);
        // The spline may overshoot the axis or the floor (y = 0) slightly: clamp.
        out.push([q.x.max(0.0), q.y.max(0.0)]);
    }
    out[0][0] = 0.0;
    out[samples][0] = 0.0;
    out
}

/// Revolves a profile of (r, y) points about the y axis with `segments` steps. Points with r = 0
/// (the ends) become single pole vertices with triangle fans. `radius(k, θ, r)` may modulate the
/// radius of profile point k at azimuth θ. Normals are area-weighted; the winding is made outward
/// (positive signed volume).
fn revolve(profile: &[[f64; 2]], segments: usize, radius: impl Fn(usize, f64, f64) -> f64) -> Mesh {
    let mut positions: Vec<DVec3> = Vec::new();
    let mut ring_start = Vec::with_capacity(profile.len());
    for (k, &[r, y]) in profile.iter().enumerate() {
        ring_start.push(positions.len() as u32);
        if r <= 0.0 {
            positions.push(DVec3::new(0.0, y, 0.0));
        } else {
            for j in 0..segments {
                let th = std::f64::consts::TAU * j as f64 / segments as f64;
                let rr = radius(k, th, r);
                positions.push(DVec3::new(rr * th.cos(), y, -rr * th.sin()));
            }
        }
    }
    let seg = segments as u32;
    let mut triangles = Vec::new();
    for k in 0..profile.len() - 1 {
        let (a0, b0) = (ring_start[k], ring_start[k + 1]);
        let a_pole = profile[k][0] <= 0.0;
        let b_pole = profile[k + 1][0] <= 0.0;
        for j in 0..seg {
            let j1 = (j + 1) % seg;
            match (a_pole, b_pole) {
                (true, true) => {}
                (true, false) => triangles.push([a0, b0 + j, b0 + j1]),
                (false, true) => triangles.push([a0 + j, b0, a0 + j1]),
                (false, false) => {
                    triangles.push([a0 + j, b0 + j, b0 + j1]);
                    triangles.push([a0 + j, b0 + j1, a0 + j1]);
                }
            }
        }
    }
    let normals = vertex_normals(&positions, &triangles);
    let mesh = Mesh {
        positions,
        normals,
        triangles,
    };
    if mesh.signed_volume() < 0.0 {
        let mut m = mesh.flipped();
        m.normals = vertex_normals(&m.positions, &m.triangles);
        m
    } else {
        mesh
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Every undirected edge is shared by exactly two triangles that traverse it in opposite
    /// directions: closed, manifold and consistently oriented.
    fn assert_closed_oriented(m: &Mesh) {
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for t in m.triangles() {
            for e in 0..3 {
                *directed.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1, "edge {a}->{b} used {n} times in the same direction");
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}-{b} is a border");
        }
    }

    #[test]
    fn sphere_area_and_volume_converge() {
        let r = 10.0;
        let m = Mesh::sphere(r, 128).unwrap();
        assert_closed_oriented(&m);
        let pi = std::f64::consts::PI;
        // Inscribed polyhedron: area and volume approach 4πr², 4/3πr³ from below, error O(1/n²).
        assert!((m.area() / (4.0 * pi * r * r) - 1.0).abs() < 2e-3);
        assert!((m.signed_volume() / (4.0 / 3.0 * pi * r.powi(3)) - 1.0).abs() < 2e-3);
        // Outward normals: a vertex normal points along its position.
        for (p, n) in m.positions().iter().zip(m.normals()) {
            assert!(p.normalize().dot(*n) > 0.99);
        }
    }

    #[test]
    fn slab_is_a_closed_box() {
        let m = Mesh::slab(20.0, 10.0, 5.0).unwrap();
        assert!((m.signed_volume() - 1000.0).abs() < 1e-9);
        assert!((m.area() - 2.0 * (200.0 + 100.0 + 50.0)).abs() < 1e-9);
        // Split vertices: positions repeat, so check orientation through the face normals instead.
        for t in 0..m.triangles().len() {
            let [a, b, c] = m.corners(t);
            let n = (b - a).cross(c - a).normalize();
            let vn = m.normals()[m.triangles()[t][0] as usize];
            assert!((n - vn).length() < 1e-12);
        }
        assert_eq!(m.bounds().max.y, 0.0);
    }

    #[test]
    fn statue_is_closed_with_a_thin_bowl() {
        let m = Mesh::statue(1.0, 64).unwrap();
        assert_closed_oriented(&m);
        assert!(m.signed_volume() > 0.0);
        let b = m.bounds();
        assert!(
            (b.max.y - 40.0).abs() < 0.5 && b.min.y.abs() < 1e-9,
            "{b:?}"
        );
        // About 4·segments² triangles.
        let n = m.triangles().len();
        assert!((15_000..18_000).contains(&n), "{n}");
    }

    #[test]
    fn bad_meshes_are_refused() {
        assert!(Mesh::new(vec![[0.0; 3]; 3], None, vec![]).is_err());
        let e = Mesh::new(vec![[0.0; 3]; 3], None, vec![[0, 1, 3]]).unwrap_err();
        assert!(e.to_string().contains("only 3 vertices"), "{e}");
        let e = Mesh::new(
            vec![[0.0, f64::NAN, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            None,
            vec![[0, 1, 2]],
        )
        .unwrap_err();
        assert!(e.to_string().contains("non-finite"), "{e}");
    }
}
