//! Validation on the measurement's own geometry (Choi et al. 2014, §4.4, Figure 6, Table 2): a flat
//! slab lit at normal incidence by a collimated spot of radius a, seen from straight above by an
//! orthographic camera whose pixels are the measurement's (mm per pixel); the rendered image's radial
//! profile in absolute units, and its mean squared difference from a measured profile.
//!
//! **Units of the rendered profile.** The texture-space method gives L(r) = Ft(η, 0°)·B(r)/π with
//! B(r) = Ft(η, 0°) E ∫_spot Rd(‖x − y‖) dA(y) for incident irradiance E. We report
//! Rd_render(r) = π L(r) / (Ft(η, 0°)² · E · π a²) [mm⁻²]: the model's Rd(r) averaged over the spot
//! (Rd(r) itself as a → 0), the quantity that `measure` fits as measured/k (the fit's spot
//! convolution).

use glam::DVec3;
use scatterfit_imaging::{ProfileOptions, radial_profile};
use scatterfit_optics::fresnel::fresnel_dielectric;

use crate::error::{Result, invalid};
use crate::mesh::Mesh;
use crate::profile::Material;
use crate::render::{Method, RenderOptions, Rendered, render};
use crate::scene::{Camera, Light, Projection, Scene};
use crate::texture_space::DipoleParams;
use crate::tonemap::{ToneMap, luminance_weights};
use scatterfit_optics::{Channel, Rgb};

/// The measurement geometry to reproduce.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpotSetup {
    /// Image scale [mm per pixel].
    pub mm_per_pixel: f64,
    /// Outer radius of the profile \[mm\].
    pub r_max_mm: f64,
    /// Radius of the light spot \[mm\].
    pub spot_radius_mm: f64,
}

impl SpotSetup {
    /// Checks the values.
    ///
    /// # Errors
    /// [`crate::RenderError::InvalidOption`] for a non-positive value or an image over 4001 pixels
    /// across.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("mm per pixel", self.mm_per_pixel),
            ("profile radius [mm]", self.r_max_mm),
            ("spot radius [mm]", self.spot_radius_mm),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "must be a positive number"));
            }
        }
        if self.r_max_mm / self.mm_per_pixel > 2000.0 {
            return Err(invalid(
                "profile radius / mm per pixel",
                self.r_max_mm / self.mm_per_pixel,
                "at most 2000 pixels (a 4001-pixel image)",
            ));
        }
        Ok(())
    }

    /// Image size (square, odd, so that the spot centre is the centre of a pixel).
    pub fn image_size(&self) -> usize {
        2 * (self.r_max_mm / self.mm_per_pixel).ceil() as usize + 1
    }

    /// Pixel coordinates of the spot centre (pixel centres at integer coordinates, as in
    /// `scatterfit_imaging`).
    pub fn center_px(&self) -> [f64; 2] {
        let c = (self.image_size() / 2) as f64;
        [c, c]
    }
}

/// The slab scene: a 50 mm thick slab larger than the view, its top at y = 0, a spot of irradiance 1
/// at the origin along +y, and an orthographic camera looking straight down (image x along +x,
/// image y along +z).
///
/// # Errors
/// As [`SpotSetup::validate`].
pub fn spot_scene(setup: &SpotSetup) -> Result<Scene> {
    setup.validate()?;
    let n = setup.image_size();
    let view = n as f64 * setup.mm_per_pixel;
    let slab = Mesh::slab(view + 20.0, view + 20.0, 50.0)?;
    let camera = Camera {
        eye: DVec3::new(0.0, 100.0, 0.0),
        target: DVec3::ZERO,
        up: DVec3::NEG_Z,
        projection: Projection::Orthographic { height_mm: view },
    };
    let light = Light::Spot {
        center: DVec3::ZERO,
        direction: DVec3::Y,
        radius: setup.spot_radius_mm,
        irradiance: [1.0; 3],
    };
    Scene::new(slab, vec![light], camera)
}

/// A rendered radial profile in mm⁻² (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct RenderedProfile {
    /// Ring radius (mean pixel distance) \[mm\].
    pub r_mm: Vec<f64>,
    /// Rd_render per channel and ring [mm⁻²].
    pub rd: [Vec<f64>; 3],
    /// Standard error of the ring mean over its pixels [mm⁻²] (spread within the ring, not the
    /// render's noise between seeds).
    pub stderr: [Vec<f64>; 3],
}

/// Renders the spot on the slab by the texture-space method (`opts.width/height` are replaced by
/// the setup's image size, the specular term is left out and B evaluated at every pixel) and takes its radial profile (1-pixel
/// rings).
///
/// # Errors
/// As [`spot_scene`] and [`render`].
pub fn render_spot_profile(
    material: &Material,
    setup: &SpotSetup,
    opts: &RenderOptions,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<(Rendered, RenderedProfile)> {
    let scene = spot_scene(setup)?;
    let n = setup.image_size();
    // No specular term: the profile is the subsurface light (the fit skips the spot itself).
    let opts = RenderOptions {
        width: n,
        height: n,
        dipole: DipoleParams {
            specular: false,
            interpolate: false,
            ..opts.dipole
        },
        ..*opts
    };
    let rendered = render(&scene, material, Method::Dipole, &opts, progress)?;
    let profile = radial_profile(
        &rendered.image,
        setup.center_px(),
        None,
        setup.mm_per_pixel,
        &ProfileOptions::new(1.0, setup.r_max_mm / setup.mm_per_pixel)?,
    )?;
    let norm = rd_per_radiance(material.eta(), setup.spot_radius_mm);
    let r_mm = (0..profile.rings.len())
        .map(|k| profile.r_mm(k).unwrap_or(f64::NAN))
        .collect();
    let column = |c: usize, f: fn(&scatterfit_imaging::RingChannel) -> f64| -> Vec<f64> {
        profile
            .rings
            .iter()
            .map(|r| f(&r.channels[c]) * norm)
            .collect()
    };
    let rd = [0, 1, 2].map(|c| column(c, |s| s.mean));
    let stderr = [0, 1, 2].map(|c| column(c, |s| s.std_err));
    Ok((rendered, RenderedProfile { r_mm, rd, stderr }))
}

/// Rd_render per unit of rendered radiance: π / (Ft(η, 0°)² · E · π a²) with E = 1 (see the module
/// docs) [mm⁻² per radiance unit].
pub fn rd_per_radiance(eta: f64, spot_radius_mm: f64) -> f64 {
    let ft = 1.0 - fresnel_dielectric(1.0, eta);
    std::f64::consts::PI / (ft * ft * std::f64::consts::PI * spot_radius_mm.powi(2))
}

/// A measured profile to validate against (read by [`crate::measured`]): the rings and their
/// values, the fitted scale k per channel that puts them in mm⁻², and the measurement's geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredProfile {
    /// The profile's file (for messages).
    pub file: std::path::PathBuf,
    /// Ring radius \[mm\].
    pub r_mm: Vec<f64>,
    /// Measured value per channel and ring (the profile's units: k × mm⁻²).
    pub values: Rgb<Vec<f64>>,
    /// The fitted scale k per channel (finite, > 0).
    pub scales: Rgb<f64>,
    /// The fit's own MSE per channel, for reference [mm⁻⁴].
    pub fit_mse: Rgb<Option<f64>>,
    /// Image scale [mm per pixel].
    pub mm_per_pixel: f64,
    /// Light-spot radius \[mm\].
    pub spot_radius_mm: f64,
}

impl MeasuredProfile {
    /// The largest finite ring radius \[mm\].
    pub fn r_max_mm(&self) -> f64 {
        self.r_mm
            .iter()
            .copied()
            .filter(|r| r.is_finite())
            .fold(0.0, f64::max)
    }

    /// The geometry to render: the measurement's scale and spot, one pixel beyond the last ring.
    pub fn setup(&self) -> SpotSetup {
        SpotSetup {
            mm_per_pixel: self.mm_per_pixel,
            r_max_mm: self.r_max_mm() + self.mm_per_pixel,
            spot_radius_mm: self.spot_radius_mm,
        }
    }
}

/// A validation against a measured profile (§4.4, Table 2): the slab render, its profile and the
/// comparison per channel.
#[derive(Debug, Clone)]
pub struct ProfileValidation {
    /// The slab render.
    pub rendered: Rendered,
    /// Its radial profile [mm⁻²].
    pub profile: RenderedProfile,
    /// The geometry rendered.
    pub setup: SpotSetup,
    /// Table 2's quantities per channel.
    pub channels: Rgb<ProfileComparison>,
    /// Rd_render per unit of rendered radiance ([`rd_per_radiance`] of the material's η and the
    /// spot).
    pub rd_per_radiance: f64,
    /// Wall time of the render and its profile \[s\].
    pub render_s: f64,
}

/// Renders the measurement's slab and spot with `material` (one sample per pixel) and compares the
/// profile with `measured`/k at every measured ring outside the spot (Table 2's MSE, §4.4).
/// `progress` is called with rows finished.
///
/// # Errors
/// As [`SpotSetup::validate`] (named as the measurement geometry) and [`render_spot_profile`];
/// [`crate::RenderError::Measurement`] when a channel has no ring to compare outside the spot.
pub fn validate_profile(
    material: &Material,
    measured: &MeasuredProfile,
    opts: &RenderOptions,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<ProfileValidation> {
    let setup = measured.setup();
    setup
        .validate()
        .map_err(|e| crate::RenderError::Geometry(Box::new(e)))?;
    let t0 = std::time::Instant::now();
    let opts = RenderOptions { spp: 1, ..*opts };
    let (rendered, profile) = render_spot_profile(material, &setup, &opts, progress)?;
    let rd_per_radiance = rd_per_radiance(material.eta(), measured.spot_radius_mm);
    let render_s = t0.elapsed().as_secs_f64();
    let spot = measured.spot_radius_mm;
    let channels = Rgb::from_array([0, 1, 2].map(|c| {
        compare_profiles(
            &profile.r_mm,
            &profile.rd[c],
            &measured.r_mm,
            &measured.values[Channel::ALL[c]],
            measured.scales[Channel::ALL[c]],
            spot,
        )
        .ok_or_else(|| crate::RenderError::Measurement {
            file: measured.file.clone(),
            detail: format!(
                "no ring outside the spot ({spot} mm) with a positive value in channel {}",
                Channel::ALL[c].key()
            ),
        })
    }))
    .transpose()?;
    Ok(ProfileValidation {
        rendered,
        profile,
        setup,
        channels,
        rd_per_radiance,
        render_s,
    })
}

impl ProfileValidation {
    /// The comparison at the measured rings as CSV: `r_mm`, the render interpolated there and
    /// measured/k per channel (empty cells where either is missing).
    pub fn comparison_csv(&self, measured: &MeasuredProfile) -> String {
        let mut text = String::from(
            "r_mm,rendered_r,rendered_g,rendered_b,measured_over_k_r,measured_over_k_g,\
             measured_over_k_b\n",
        );
        let cell = |v: Option<f64>| {
            v.filter(|v| v.is_finite())
                .map_or(String::new(), |v| v.to_string())
        };
        for (k, &r) in measured.r_mm.iter().enumerate() {
            let rendered =
                [0, 1, 2].map(|c| cell(interpolate(&self.profile.r_mm, &self.profile.rd[c], r)));
            let over_k = Channel::ALL
                .map(|c| cell(measured.values[c].get(k).map(|v| v / measured.scales[c])));
            text.push_str(&format!(
                "{r},{},{},{},{},{},{}\n",
                rendered[0], rendered[1], rendered[2], over_k[0], over_k[1], over_k[2]
            ));
        }
        text
    }

    /// `tone` exposed so that the glow at twice the spot radius shows as white (the slab picture's
    /// default exposure), clamped to ±60 EV; EV 0 where the render is black there.
    pub fn glow_exposure(&self, tone: &ToneMap) -> ToneMap {
        let w = luminance_weights();
        let norm = self.rd_per_radiance;
        let k = ((2.0 * self.setup.spot_radius_mm / self.setup.mm_per_pixel) as usize)
            .min(self.profile.r_mm.len() - 1);
        let y: f64 = (0..3).map(|c| w[c] * self.profile.rd[c][k]).sum::<f64>() / norm;
        ToneMap {
            exposure_ev: if y > 0.0 {
                (tone.white / (std::f64::consts::PI * y))
                    .log2()
                    .clamp(-60.0, 60.0)
            } else {
                0.0
            },
            ..*tone
        }
    }
}

/// Table 2's quantity for one channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileComparison {
    /// Mean over the compared rings of (Rd_render − measured/k)² [mm⁻⁴].
    pub mse: f64,
    /// Root mean square of ln(Rd_render / (measured/k)) over the same rings (dimensionless).
    pub rms_log: f64,
    /// Rings compared.
    pub rings: usize,
}

/// Compares a rendered profile with a measured one: at each measured ring with r > `r_min_mm`, a
/// finite positive value and a rendered value available (linear interpolation in r of the rendered
/// rings), the squared difference between the rendered Rd and measured/`scale`. None when no ring
/// qualifies.
pub fn compare_profiles(
    rendered_r: &[f64],
    rendered: &[f64],
    measured_r: &[f64],
    measured: &[f64],
    scale: f64,
    r_min_mm: f64,
) -> Option<ProfileComparison> {
    let mut sq = 0.0;
    let mut lg = 0.0;
    let mut n = 0usize;
    for (&r, &m) in measured_r.iter().zip(measured) {
        if !(r > r_min_mm && m.is_finite() && m > 0.0) {
            continue;
        }
        let Some(v) = interpolate(rendered_r, rendered, r) else {
            continue;
        };
        let target = m / scale;
        sq += (v - target).powi(2);
        if v > 0.0 {
            lg += (v / target).ln().powi(2);
        }
        n += 1;
    }
    (n > 0).then(|| ProfileComparison {
        mse: sq / n as f64,
        rms_log: (lg / n as f64).sqrt(),
        rings: n,
    })
}

/// Linear interpolation of (xs, ys) at x (xs increasing; non-finite entries skipped); None outside.
pub fn interpolate(xs: &[f64], ys: &[f64], x: f64) -> Option<f64> {
    let pts: Vec<(f64, f64)> = xs
        .iter()
        .zip(ys)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(&a, &b)| (a, b))
        .collect();
    let k = pts.partition_point(|p| p.0 < x);
    if k < pts.len() && pts[k].0 == x {
        return Some(pts[k].1);
    }
    if k == 0 || k == pts.len() {
        return None;
    }
    let (a, b) = (pts[k - 1], pts[k]);
    Some(a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comparison_of_a_scaled_copy_is_exact() {
        let r: Vec<f64> = (1..50).map(|i| 0.1 * i as f64).collect();
        let rd: Vec<f64> = r.iter().map(|x| (-x).exp()).collect();
        let measured: Vec<f64> = rd.iter().map(|v| 3.0 * v).collect();
        let c = compare_profiles(&r, &rd, &r, &measured, 3.0, 0.5).unwrap();
        assert!(c.mse < 1e-30 && c.rms_log < 1e-12);
        assert_eq!(c.rings, 44); // r = 0.6 … 4.9 (0.5 itself is not > 0.5)
        // A 10 % offset gives MSE = mean (0.1 v)².
        let off: Vec<f64> = rd.iter().map(|v| 1.1 * 3.0 * v).collect();
        let c = compare_profiles(&r, &rd, &r, &off, 3.0, 0.0).unwrap();
        let expected = rd.iter().map(|v| (0.1 * v).powi(2)).sum::<f64>() / rd.len() as f64;
        assert!((c.mse / expected - 1.0).abs() < 1e-9);
        assert!((c.rms_log - 1.1f64.ln()).abs() < 1e-12);
        // Between rings: interpolated.
        assert!((interpolate(&[0.0, 1.0], &[0.0, 2.0], 0.25).unwrap() - 0.5).abs() < 1e-15);
        assert_eq!(interpolate(&[0.0, 1.0], &[0.0, 2.0], 1.5), None);
    }
}
