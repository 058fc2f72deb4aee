//! Forward models of the radial profile: what the fit compares the measurement with.
//!
//! A model maps optical properties to Rd(r) [mm⁻²] and its derivatives in σ′s and σa at a set of
//! radii, and gives the total diffuse reflectance Rd(α′, η) of the same physics and its inverse
//! (the spectrophotometer's α′ "by the same physics", and `--normalise-with-spectro`). The
//! classical dipole of Jensen et al. 2001 is the paper's model ([`DipoleModel`]); the better dipole
//! (d'Eon 2012) and photon beam diffusion (Habel et al. 2013, as pbrt-v4) come from
//! `scatterfit_optics::model` ([`Diffusion`]), the Monte Carlo tables from `scatterfit_mc`
//! ([`McModel`]). A model that cannot evaluate a parameter set (η or α′ outside its range) fills
//! the profile with NaN, which the solver treats as a point it may not visit.

use std::sync::OnceLock;

use scatterfit_mc::{McProfile, McTableSet};
use scatterfit_optics::OpticalProperties;
use scatterfit_optics::dipole::{Dipole, ProfileSample};
use scatterfit_optics::model::{DiffusionModel, ProfileModel as OpticsProfile};

use crate::spot::SpotKernel;

/// A forward model of the radial profile of a semi-infinite medium lit by a pencil beam.
pub trait ProfileModel: Sync {
    /// Short name, as written in results (`dipole`, …).
    fn name(&self) -> &'static str;

    /// Rd(r) and ∂Rd/∂σ′s, ∂Rd/∂σa at every radius of `radii_mm` (written to `out`, same length).
    fn eval(&self, props: &OpticalProperties, radii_mm: &[f64], out: &mut [ProfileSample]);

    /// Total diffuse reflectance ∫2πr Rd(r) dr at reduced albedo α′ and index η (NaN where the
    /// model does not cover them).
    fn rd_total(&self, albedo_prime: f64, eta: f64) -> f64;

    /// The reduced albedo α′ whose total diffuse reflectance is `rd` at η: the inverse of
    /// [`ProfileModel::rd_total`].
    ///
    /// # Errors
    /// Why not (Rd outside what the model can produce, η outside its range), for people.
    fn albedo_from_rd(&self, rd: f64, eta: f64) -> std::result::Result<f64, String>;
}

const NAN_SAMPLE: ProfileSample = ProfileSample {
    rd: f64::NAN,
    d_sigma_s_prime: f64::NAN,
    d_sigma_a: f64::NAN,
};

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

    fn albedo_from_rd(&self, rd: f64, eta: f64) -> std::result::Result<f64, String> {
        scatterfit_optics::dipole::albedo_from_rd(rd, eta).map_err(|e| e.to_string())
    }
}

/// A diffusion model of `scatterfit_optics::model` by name: the classical dipole, the better
/// dipole (d'Eon 2012, physics.md §3) or photon beam diffusion (Habel et al. 2013, physics.md §2),
/// each with its own total Rd(α′, η) and inverse.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Diffusion(pub DiffusionModel);

impl ProfileModel for Diffusion {
    fn name(&self) -> &'static str {
        self.0.name()
    }

    fn eval(&self, props: &OpticalProperties, radii_mm: &[f64], out: &mut [ProfileSample]) {
        match self.0.profile(props) {
            Ok(m) => m.profile_with_derivatives_into(radii_mm, out),
            Err(_) => out.fill(NAN_SAMPLE),
        }
    }

    fn rd_total(&self, albedo_prime: f64, eta: f64) -> f64 {
        self.0.rd_total(albedo_prime, eta).unwrap_or(f64::NAN)
    }

    fn albedo_from_rd(&self, rd: f64, eta: f64) -> std::result::Result<f64, String> {
        self.0.albedo_from_rd(rd, eta).map_err(|e| e.to_string())
    }
}

/// The Monte Carlo forward model: Rd(r) from MCML-physics tables by similarity scaling, smooth in
/// α′, η and r with analytic derivatives of the interpolant (`scatterfit_mc::McProfile`), and the
/// tables' total Rd and its inverse (α′ "by the Monte Carlo method", done exactly).
#[derive(Debug, Clone)]
pub struct McModel {
    set: McTableSet,
}

impl McModel {
    /// The model on a table set (e.g. one built for another g with `McTableSet::load_or_build`).
    pub fn new(set: McTableSet) -> Self {
        Self { set }
    }

    /// The model on the tables shipped with scatterfit (g = 0, η 1.0–2.5, α′ 0.02–0.9999), parsed
    /// once per process.
    ///
    /// # Errors
    /// The tables do not parse (a build defect), as text.
    pub fn bundled() -> std::result::Result<&'static McModel, String> {
        static MODEL: OnceLock<std::result::Result<McModel, String>> = OnceLock::new();
        MODEL
            .get_or_init(|| {
                McTableSet::bundled()
                    .map(McModel::new)
                    .map_err(|e| e.to_string())
            })
            .as_ref()
            .map_err(Clone::clone)
    }

    /// The table set.
    pub fn tables(&self) -> &McTableSet {
        &self.set
    }
}

impl ProfileModel for McModel {
    fn name(&self) -> &'static str {
        "mc"
    }

    fn eval(&self, props: &OpticalProperties, radii_mm: &[f64], out: &mut [ProfileSample]) {
        match McProfile::new(&self.set, props) {
            Ok(m) => m.profile_with_derivatives_into(radii_mm, out),
            Err(_) => out.fill(NAN_SAMPLE),
        }
    }

    fn rd_total(&self, albedo_prime: f64, eta: f64) -> f64 {
        self.set.rd_total(albedo_prime, eta).unwrap_or(f64::NAN)
    }

    fn albedo_from_rd(&self, rd: f64, eta: f64) -> std::result::Result<f64, String> {
        self.set
            .albedo_from_rd_total(rd, eta)
            .map_err(|e| e.to_string())
    }
}

/// How the light spot enters the model.
// `Radial` holds its disks inline (≈ 0.5 KB) so that the fit's options stay `Copy`; they are copied
// once per fit, not per iteration.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spot {
    /// A point of incidence: the model as it stands (the paper's treatment).
    Point,
    /// A uniform disk of this radius [mm]: the model convolved with it ([`crate::spot`]).
    Disk {
        /// Radius [mm].
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
        Spot::Disk { .. } | Spot::Radial(_) => {
            let kernel = spot_kernel(spot, radii_mm)?.expect("not a point");
            let mut nodes = vec![zero; kernel.nodes().len()];
            model.eval(props, kernel.nodes(), &mut nodes);
            let values: Vec<f64> = nodes.iter().map(|s| s.rd).collect();
            let mut out = vec![0.0; radii_mm.len()];
            kernel.apply(&values, &mut out);
            Ok(out)
        }
    }
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
