//! Forward models of the radial profile: what the fit compares the measurement with.
//!
//! A model maps optical properties to Rd(r) [mm⁻²] and its derivatives in σ′s and σa at a set of
//! radii, and gives the total diffuse reflectance Rd(α′, η) of the same physics (used by the
//! spectrophotometer's α′ inversion and by `--normalise-with-spectro`). The classical dipole of
//! Jensen et al. 2001 is the paper's model; others plug in through [`ProfileModel`].

use scatterfit_optics::OpticalProperties;
use scatterfit_optics::dipole::{Dipole, ProfileSample};

use crate::spot::SpotKernel;

/// A forward model of the radial profile of a semi-infinite medium lit by a pencil beam.
pub trait ProfileModel: Sync {
    /// Short name, as written in results (`dipole`, …).
    fn name(&self) -> &'static str;

    /// Rd(r) and ∂Rd/∂σ′s, ∂Rd/∂σa at every radius of `radii_mm` (written to `out`, same length).
    fn eval(&self, props: &OpticalProperties, radii_mm: &[f64], out: &mut [ProfileSample]);

    /// Total diffuse reflectance ∫2πr Rd(r) dr at reduced albedo α′ and index η.
    fn rd_total(&self, albedo_prime: f64, eta: f64) -> f64;
}

/// The classical dipole, Jensen, Marschner, Levoy & Hanrahan 2001, eq. 4 (the forward model of
/// Choi, Lee & Chin 2014), with analytic derivatives ([`Dipole::profile_with_derivatives_into`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DipoleModel;

impl ProfileModel for DipoleModel {
    fn name(&self) -> &'static str {
        "dipole"
    }

    fn eval(&self, props: &OpticalProperties, radii_mm: &[f64], out: &mut [ProfileSample]) {
        Dipole::new(props).profile_with_derivatives_into(radii_mm, out);
    }

    fn rd_total(&self, albedo_prime: f64, eta: f64) -> f64 {
        scatterfit_optics::dipole::rd_total(albedo_prime, eta)
    }
}

/// How the light spot enters the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spot {
    /// A point of incidence: the model as it stands (the paper's treatment).
    Point,
    /// A uniform disk of this radius [mm]: the model convolved with it ([`crate::spot`]).
    Disk {
        /// Radius [mm].
        radius_mm: f64,
    },
}

/// The model's profile at `radii_mm` for `props`, convolved with the spot when it is a disk: the
/// curve to draw beside a measurement (in mm⁻²).
///
/// # Errors
/// As [`SpotKernel::new`].
pub fn model_profile(
    model: &dyn ProfileModel,
    props: &OpticalProperties,
    spot: Spot,
    radii_mm: &[f64],
) -> crate::Result<Vec<f64>> {
    let zero = ProfileSample {
        rd: 0.0,
        d_sigma_s_prime: 0.0,
        d_sigma_a: 0.0,
    };
    match spot {
        Spot::Point => {
            let mut out = vec![zero; radii_mm.len()];
            model.eval(props, radii_mm, &mut out);
            Ok(out.iter().map(|s| s.rd).collect())
        }
        Spot::Disk { radius_mm } => {
            let h = node_spacing(radius_mm, radii_mm);
            let kernel = SpotKernel::new(radius_mm, radii_mm, h)?;
            let mut nodes = vec![zero; kernel.nodes().len()];
            model.eval(props, kernel.nodes(), &mut nodes);
            let values: Vec<f64> = nodes.iter().map(|s| s.rd).collect();
            let mut out = vec![0.0; radii_mm.len()];
            kernel.apply(&values, &mut out);
            Ok(out)
        }
    }
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
