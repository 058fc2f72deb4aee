//! Forward models of the radial profile: what the fit compares the measurement with.
//!
//! A model is a `scatterfit_optics::ModelFamily`: it maps optical properties to Rd(r) [mm⁻²] and its
//! derivatives in σ′s and σa at a set of radii (`ModelFamily::eval`, the solver's hot path), and
//! gives the total diffuse reflectance Rd(α′, η) of the same physics and its inverse (the
//! spectrophotometer's α′ "by the same physics"). The classical dipole of Jensen et al. 2001 is the
//! paper's model (`scatterfit_optics::DiffusionModel::Dipole`); the better dipole (d'Eon 2012) and
//! photon beam diffusion (Habel et al. 2013, as pbrt-v4) are the other diffusion models, and the
//! Monte Carlo tables are `scatterfit_mc`'s family (`scatterfit_mc::family` turns a name into any of
//! them). A model that cannot evaluate a parameter set (η or α′ outside its range) fills the profile
//! with NaN, which the solver treats as a point it may not visit. This module adds the light spot:
//! [`Spot`], and [`model_profile`] for the curve drawn beside a measurement.

use scatterfit_optics::{ModelFamily, OpticalProperties, ProfileSample};

use crate::spot::SpotKernel;

/// How the light spot enters the model.
// `Radial` holds its disks inline (≈ 0.5 KB) so that the fit's options stay `Copy`; they are copied
// once per fit, not per iteration.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spot {
    /// A point of incidence: the model as it stands (the paper's treatment).
    Point,
    /// A uniform disk of this radius \[mm\]: the model convolved with it ([`crate::spot`]).
    Disk {
        /// Radius \[mm\].
        radius_mm: f64,
    },
    /// A radial spot of any shape (Gaussian, measured) as a mixture of disks
    /// ([`crate::radial_spot`]).
    Radial(crate::radial_spot::RadialSpot),
}

/// The model's profile at `radii_mm` for `props`, convolved with the spot when it is a disk: the
/// curve to draw beside a measurement (in mm⁻²).
///
/// # Errors
/// As [`SpotKernel::new`].
pub fn model_profile(
    model: &dyn ModelFamily,
    props: &OpticalProperties,
    spot: Spot,
    radii_mm: &[f64],
) -> crate::Result<Vec<f64>> {
    Ok(
        model_profiles(model, std::slice::from_ref(props), spot, radii_mm)?
            .pop()
            .expect("one profile per property set"),
    )
}

/// [`model_profile`] for several property sets (a sample's channels) at the same radii and spot:
/// the spot's convolution map is built once and applied to each.
///
/// # Errors
/// As [`SpotKernel::new`].
pub fn model_profiles(
    model: &dyn ModelFamily,
    props: &[OpticalProperties],
    spot: Spot,
    radii_mm: &[f64],
) -> crate::Result<Vec<Vec<f64>>> {
    let zero = ProfileSample::ZERO;
    let kernel = spot_kernel(spot, radii_mm)?;
    let at = kernel.as_ref().map_or(radii_mm, SpotKernel::nodes);
    let mut samples = vec![zero; at.len()];
    Ok(props
        .iter()
        .map(|p| {
            model.eval(p, at, &mut samples);
            let values: Vec<f64> = samples.iter().map(|s| s.rd).collect();
            match &kernel {
                None => values,
                Some(k) => {
                    let mut out = vec![0.0; radii_mm.len()];
                    k.apply(&values, &mut out);
                    out
                }
            }
        })
        .collect())
}

/// The spot's convolution map for rings at `radii_mm` (`None` for a point of incidence): a disk's
/// with node spacing [`node_spacing`], a radial spot's as its mixture of disks with the spacing of
/// its equivalent disk.
///
/// # Errors
/// As [`SpotKernel::new`].
pub fn spot_kernel(spot: Spot, radii_mm: &[f64]) -> crate::Result<Option<SpotKernel>> {
    Ok(match spot {
        Spot::Point => None,
        Spot::Disk { radius_mm } => Some(SpotKernel::new(
            radius_mm,
            radii_mm,
            node_spacing(radius_mm, radii_mm),
        )?),
        Spot::Radial(s) => Some(SpotKernel::from_disks(
            &s,
            radii_mm,
            node_spacing(s.equivalent_radius_mm(), radii_mm),
        )?),
    })
}

/// The node spacing used for a disk of radius a and these rings: a/8, or the median ring spacing
/// if that is finer (the model then varies little between nodes; see [`crate::spot`]).
pub fn node_spacing(radius_mm: f64, radii_mm: &[f64]) -> f64 {
    let mut gaps: Vec<f64> = radii_mm
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|g| *g > 0.0)
        .collect();
    let coarse = radius_mm / 8.0;
    if gaps.is_empty() {
        return coarse;
    }
    let mid = gaps.len() / 2;
    let (_, median, _) = gaps.select_nth_unstable_by(mid, f64::total_cmp);
    coarse.min(*median)
}
