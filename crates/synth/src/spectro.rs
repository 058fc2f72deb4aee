//! A synthetic d/8 spectrophotometer reading for a material of known diffuse colour and η.
//!
//! - SCE(λ): a smooth reflectance spectrum whose linear sRGB (D65, 2°, ASTM E308 weights) equals the
//!   wanted per-channel diffuse reflectance Rd. It is a combination of three smooth basis spectra
//!   (a long-wave logistic step, a Gaussian at 540 nm and a short-wave logistic step) whose weights
//!   solve the 3 × 3 linear system XYZ(Σ cₖbₖ) = XYZ(Rd) exactly.
//! - SCI(λ) = SCE(λ) + R(8°; η): the specular reflection at the d/8 viewing angle from the exact
//!   Fresnel equations (not Schlick, so that the pipeline's Schlick inversion is tested honestly).

use scatterfit_optics::colour::{self, Observer};
use scatterfit_optics::fresnel::{D8_VIEWING_ANGLE_DEG, fresnel_dielectric};
use scatterfit_optics::spectro::SpectroReading;

/// The colour cannot be made by the smooth basis with reflectances in [0, 1].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "linear sRGB Rd ({r:.4}, {g:.4}, {b:.4}) needs reflectances outside [0, 1] \
     (min {min:.4}, max {max:.4}) with the smooth three-band basis"
)]
pub struct OutOfGamut {
    /// Wanted red.
    pub r: f64,
    /// Wanted green.
    pub g: f64,
    /// Wanted blue.
    pub b: f64,
    /// Smallest reflectance the solution needed.
    pub min: f64,
    /// Largest reflectance the solution needed.
    pub max: f64,
}

/// Basis spectrum `k` with the red step at `red_nm` and the blue step at `blue_nm`.
fn basis(k: usize, lambda: f64, red_nm: f64, blue_nm: f64) -> f64 {
    match k {
        0 => 1.0 / (1.0 + (-(lambda - red_nm) / 20.0).exp()),
        1 => (-0.5 * ((lambda - 540.0) / 40.0).powi(2)).exp(),
        _ => 1.0 / (1.0 + ((lambda - blue_nm) / 20.0).exp()),
    }
}

/// Step positions tried in turn (nm): the first set whose spectrum stays in [0, 1] wins, preferring
/// the smoothest (the list runs from wide overlap to narrow).
const STEPS_NM: [(f64, f64); 9] = [
    (590.0, 490.0),
    (575.0, 500.0),
    (560.0, 510.0),
    (600.0, 480.0),
    (550.0, 520.0),
    (610.0, 470.0),
    (580.0, 480.0),
    (600.0, 500.0),
    (540.0, 530.0),
];

/// A reading at 400, 410, …, 700 nm whose SCE has linear sRGB `rd` and whose SCI adds the exact
/// Fresnel reflectance of a surface with index `eta` at 8°.
///
/// # Errors
/// [`OutOfGamut`] if the colour needs reflectances outside [0, 1] with the smooth basis.
pub fn reading_for(rd: [f64; 3], eta: f64) -> Result<SpectroReading, OutOfGamut> {
    let wavelengths: Vec<f64> = (0..31).map(|i| 400.0 + 10.0 * i as f64).collect();
    let specular = fresnel_dielectric(D8_VIEWING_ANGLE_DEG.to_radians().cos(), eta);
    let mut best: Option<(Vec<f64>, f64, f64)> = None;
    for &(red_nm, blue_nm) in &STEPS_NM {
        let sce = sce_for(&wavelengths, rd, red_nm, blue_nm);
        let (min, max) = sce
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        if min >= 0.0 && max + specular <= 1.0 {
            let sci = sce.iter().map(|s| s + specular).collect();
            // In [0, 1] by the test above, so the reading is valid; were it not, the nearest
            // reading below is reported as out of gamut.
            if let Ok(r) = SpectroReading::new(wavelengths.clone(), sci, sce.clone()) {
                return Ok(r);
            }
        }
        let excess = (-min).max(max + specular - 1.0);
        if best
            .as_ref()
            .is_none_or(|b| excess < (-b.1).max(b.2 + specular - 1.0))
        {
            best = Some((sce, min, max));
        }
    }
    let (_, min, max) = best.unwrap_or_default();
    Err(OutOfGamut {
        r: rd[0],
        g: rd[1],
        b: rd[2],
        min,
        max,
    })
}

/// The SCE spectrum with linear sRGB `rd` for one choice of basis steps.
fn sce_for(wavelengths: &[f64], rd: [f64; 3], red_nm: f64, blue_nm: f64) -> Vec<f64> {
    // XYZ (2°) of each basis spectrum: the columns of the 3 × 3 system.
    let columns: Vec<[f64; 3]> = (0..3)
        .map(|k| {
            let samples: [f64; 31] =
                std::array::from_fn(|i| basis(k, wavelengths[i], red_nm, blue_nm));
            let xyz = colour::weighted_sum(&samples, Observer::TwoDegree);
            [xyz.x, xyz.y, xyz.z]
        })
        .collect();
    let target = colour::linear_srgb_to_xyz(rd);
    let c = solve3(
        [
            [columns[0][0], columns[1][0], columns[2][0]],
            [columns[0][1], columns[1][1], columns[2][1]],
            [columns[0][2], columns[1][2], columns[2][2]],
        ],
        [target.x, target.y, target.z],
    );
    wavelengths
        .iter()
        .map(|&l| (0..3).map(|k| c[k] * basis(k, l, red_nm, blue_nm)).sum())
        .collect()
}

/// Solves a 3 × 3 linear system by Cramer's rule (the basis matrix is fixed and well conditioned).
fn solve3(m: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    std::array::from_fn(|k| {
        let mut mk = m;
        for (row, &bv) in mk.iter_mut().zip(&b) {
            row[k] = bv;
        }
        det(&mk) / d
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use scatterfit_optics::dipole::rd_total;
    use scatterfit_optics::materials::CHOI_2014;

    /// The synthetic SCE reproduces the wanted linear sRGB through the independent colour pipeline,
    /// and SCI − SCE is the exact Fresnel reflectance, for every material of the demo.
    #[test]
    fn readings_reproduce_colour_and_specular() {
        for m in &CHOI_2014 {
            let a = m.albedo_prime();
            let rd: [f64; 3] = std::array::from_fn(|c| rd_total(a[c], m.eta));
            let r = reading_for(rd, m.eta).unwrap_or_else(|e| panic!("{}: {e}", m.name));
            let xyz =
                colour::spectrum_to_xyz(r.wavelengths_nm(), r.sce(), Observer::TwoDegree).unwrap();
            let rgb = colour::xyz_to_linear_srgb(xyz);
            for c in 0..3 {
                // The 4-decimal sRGB matrices are inverses only to ~1e-4.
                assert!(
                    (rgb[c] - rd[c]).abs() < 3e-4,
                    "{} channel {c}: {} vs {}",
                    m.name,
                    rgb[c],
                    rd[c]
                );
            }
            let spec = r.sci()[0] - r.sce()[0];
            assert!((spec - scatterfit_optics::fresnel::r0_from_eta(m.eta)).abs() < 1e-4);
        }
    }

    #[test]
    fn impossible_colours_are_refused() {
        assert!(reading_for([1.5, 0.0, 0.0], 1.5).is_err());
    }
}
