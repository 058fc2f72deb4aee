//! Colorimetry: reflectance spectra → CIE XYZ (ASTM E308 weighting), XYZ ↔ CIE L\*a\*b\*, Bradford
//! chromatic adaptation, and XYZ ↔ linear sRGB (IEC 61966-2-1).
//!
//! Scale: XYZ has Y = 100 for the perfect reflecting diffuser (the instrument convention); linear
//! sRGB values are reflectance fractions (1 = white). The D65 white points are the sums of the ASTM
//! E308 weighting factors of each observer (2°: 95.047, 100, 108.883; 10°: 94.811, 100, 107.305), so
//! a perfect white gives L\* = 100, a\* = b\* = 0 exactly with either observer. (ASTM E308 prints the
//! 10° white as 107.304; the weight sums round to 107.305 — a 1e-5 relative difference.)

use serde::{Deserialize, Serialize};

use crate::error::{OpticsError, Result};

/// A CIE standard colorimetric observer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Observer {
    /// CIE 1931 2° observer (sRGB is defined for it).
    #[serde(rename = "2")]
    TwoDegree,
    /// CIE 1964 10° observer (the default of most spectrophotometers, e.g. the CM-600d).
    #[serde(rename = "10")]
    TenDegree,
}

impl Observer {
    /// The observer for a field size in degrees (2 or 10).
    pub fn from_degrees(degrees: u32) -> Option<Self> {
        match degrees {
            2 => Some(Self::TwoDegree),
            10 => Some(Self::TenDegree),
            _ => None,
        }
    }

    /// The field size in degrees.
    pub fn degrees(self) -> u32 {
        match self {
            Self::TwoDegree => 2,
            Self::TenDegree => 10,
        }
    }

    /// The D65 white point of this observer: the sums of its weighting factors (Y = 100).
    pub fn d65_white(self) -> Xyz {
        let mut w = [0.0; 3];
        for row in &WEIGHTS_D65 {
            for (c, acc) in w.iter_mut().enumerate() {
                *acc += row[self.offset() + c];
            }
        }
        Xyz {
            x: w[0],
            y: w[1],
            z: w[2],
        }
    }

    fn offset(self) -> usize {
        match self {
            Self::TwoDegree => 0,
            Self::TenDegree => 3,
        }
    }
}

/// CIE XYZ tristimulus values (Y = 100 for the perfect white).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Xyz {
    /// X.
    pub x: f64,
    /// Y (luminance factor × 100).
    pub y: f64,
    /// Z.
    pub z: f64,
}

/// CIE 1976 L\*a\*b\*.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Lab {
    /// Lightness L\* (0–100).
    pub l: f64,
    /// Red–green a\*.
    pub a: f64,
    /// Yellow–blue b\*.
    pub b: f64,
}

/// First wavelength of the weighting table \[nm\].
pub const WEIGHTS_START_NM: f64 = 400.0;
/// Step of the weighting table \[nm\].
pub const WEIGHTS_STEP_NM: f64 = 10.0;

/// D65 tristimulus weighting factors at 400, 410, …, 700 nm for (x̄, ȳ, z̄) of the 2° observer followed
/// by the 10° observer, with the end wavelengths adjusted for data truncated to 400–700 nm as ASTM
/// E308-18 prescribes. Computed with colour-science 0.4.7 (ASTM E2022 method, then the E308
/// adjustment; docs/physics.md §6.3 says how), not copied from the printed tables. Σ W_Y = 100.
#[rustfmt::skip]
pub const WEIGHTS_D65: [[f64; 6]; 31] = [
    [0.130643, 0.003639, 0.618140, 0.143925, 0.015130, 0.643103],
    [0.375602, 0.010050, 1.788267, 0.675974, 0.069072, 3.109748],
    [1.199914, 0.035500, 5.765440, 1.603338, 0.167873, 7.626592],
    [2.396094, 0.098365, 11.697550, 2.450727, 0.300181, 12.094543],
    [3.417763, 0.226091, 17.150194, 3.418216, 0.553920, 17.537211],
    [3.698684, 0.417325, 19.505710, 3.698706, 0.890127, 19.888147],
    [3.227319, 0.664154, 18.520320, 3.064132, 1.290366, 17.695448],
    [2.148836, 0.997985, 14.136565, 1.932848, 1.838400, 12.999711],
    [1.042435, 1.501289, 8.849834, 0.802067, 2.519660, 7.699348],
    [0.332729, 2.163698, 4.855922, 0.156306, 3.226406, 3.938177],
    [0.045462, 3.352106, 2.802351, 0.039216, 4.319964, 2.045525],
    [0.098024, 5.129035, 1.601905, 0.346863, 5.621361, 1.049223],
    [0.636705, 7.076321, 0.791306, 1.070293, 6.907328, 0.543522],
    [1.666530, 8.707589, 0.419705, 2.170051, 8.059173, 0.278201],
    [2.883623, 9.473620, 0.202300, 3.397068, 8.668011, 0.121585],
    [4.250441, 9.751853, 0.085586, 4.732429, 8.854550, 0.034538],
    [5.625908, 9.419082, 0.036552, 6.069785, 8.581043, 0.000547],
    [6.987731, 8.721693, 0.019254, 7.311249, 7.951105, -0.000412],
    [8.213575, 7.801705, 0.014353, 8.290615, 7.105925, -0.000000],
    [8.729789, 6.441864, 0.009822, 8.633562, 6.004162, 0.000000],
    [9.014742, 5.351117, 0.006732, 8.672415, 5.078601, 0.000000],
    [8.491545, 4.262541, 0.003181, 7.930313, 4.064620, 0.000000],
    [7.050375, 3.145167, 0.001398, 6.445586, 2.999202, 0.000000],
    [5.124142, 2.112575, 0.000435, 4.668995, 2.041765, 0.000000],
    [3.515839, 1.373223, 0.000138, 3.095335, 1.289584, 0.000000],
    [2.167299, 0.817523, 0.000017, 1.859359, 0.746179, 0.000000],
    [1.252077, 0.462982, -0.000003, 1.055724, 0.416540, 0.000000],
    [0.678377, 0.248271, 0.000000, 0.569944, 0.223003, 0.000000],
    [0.340676, 0.123805, 0.000000, 0.274013, 0.106660, 0.000000],
    [0.153399, 0.055462, 0.000000, 0.121374, 0.047149, 0.000000],
    [0.150580, 0.054371, 0.000000, 0.110485, 0.042938, 0.000000],];

/// XYZ of a reflectance spectrum (fractions 0–1) under D65 for `observer`:
/// X = Σ_λ W_X(λ) R(λ), etc. (ASTM E308, weighting-factor method; docs/physics.md §6.3).
///
/// The spectrum must cover 400–700 nm with steps of at most 10 nm (e.g. 400–700 at 10 nm, or 360–780
/// at 5 nm). Values at 400, 410, …, 700 nm are taken directly when present, otherwise interpolated
/// linearly; wavelengths outside 400–700 nm are not used (the table's end weights already carry the
/// truncated tails, ASTM E308 §7.3.2).
///
/// # Errors
/// [`OpticsError::Spectrum`] if the lengths differ, the wavelengths are not strictly increasing, a
/// value is not finite, or the range 400–700 nm is not covered densely enough.
pub fn spectrum_to_xyz(
    wavelengths_nm: &[f64],
    reflectance: &[f64],
    observer: Observer,
) -> Result<Xyz> {
    let samples = resample_to_weight_grid(wavelengths_nm, reflectance)?;
    Ok(weighted_sum(&samples, observer))
}

/// XYZ from reflectances already on the weighting grid (400, 410, …, 700 nm).
pub fn weighted_sum(samples: &[f64; 31], observer: Observer) -> Xyz {
    let o = observer.offset();
    let mut xyz = [0.0; 3];
    for (row, &r) in WEIGHTS_D65.iter().zip(samples) {
        for (c, acc) in xyz.iter_mut().enumerate() {
            *acc += row[o + c] * r;
        }
    }
    Xyz {
        x: xyz[0],
        y: xyz[1],
        z: xyz[2],
    }
}

/// The spectrum's values at 400, 410, …, 700 nm (exact samples, or linear interpolation between the
/// neighbouring samples; steps above 10 nm are refused).
///
/// # Errors
/// As [`spectrum_to_xyz`].
pub fn resample_to_weight_grid(wavelengths_nm: &[f64], values: &[f64]) -> Result<[f64; 31]> {
    if wavelengths_nm.len() != values.len() {
        return Err(OpticsError::Spectrum(format!(
            "{} wavelengths but {} values",
            wavelengths_nm.len(),
            values.len()
        )));
    }
    if let Some(w) = wavelengths_nm
        .windows(2)
        .find(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
    {
        return Err(OpticsError::Spectrum(format!(
            "wavelengths must increase strictly ({} nm is followed by {} nm)",
            w[0], w[1]
        )));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(OpticsError::Spectrum(format!(
            "value at {} nm is not finite",
            wavelengths_nm[i]
        )));
    }
    const EPS: f64 = 1e-6;
    let (first, last) = match (wavelengths_nm.first(), wavelengths_nm.last()) {
        (Some(&f), Some(&l)) => (f, l),
        _ => return Err(OpticsError::Spectrum("no samples".into())),
    };
    if first > WEIGHTS_START_NM + EPS || last < 700.0 - EPS {
        return Err(OpticsError::Spectrum(format!(
            "samples span {first}–{last} nm but colour needs 400–700 nm; measure the full visible range"
        )));
    }
    let mut out = [0.0; 31];
    for (k, slot) in out.iter_mut().enumerate() {
        let lambda = WEIGHTS_START_NM + WEIGHTS_STEP_NM * k as f64;
        // First sample at or above λ.
        let j = wavelengths_nm.partition_point(|&w| w < lambda - EPS);
        if (wavelengths_nm[j] - lambda).abs() <= EPS {
            *slot = values[j];
            continue;
        }
        // j ≥ 1 because the first sample is ≤ 400 nm ≤ λ.
        let (w0, w1) = (wavelengths_nm[j - 1], wavelengths_nm[j]);
        if w1 - w0 > WEIGHTS_STEP_NM + EPS {
            return Err(OpticsError::Spectrum(format!(
                "gap of {} nm between {w0} and {w1} nm; colour needs samples at least every 10 nm",
                w1 - w0
            )));
        }
        let t = (lambda - w0) / (w1 - w0);
        *slot = values[j - 1] * (1.0 - t) + values[j] * t;
    }
    Ok(out)
}

/// CIE 1976 f(t) = t^(1/3) above (6/29)³, linear below (CIE 15:2004, eq. 8.3).
fn lab_f(t: f64) -> f64 {
    const D: f64 = 6.0 / 29.0;
    if t > D * D * D {
        t.cbrt()
    } else {
        t / (3.0 * D * D) + 4.0 / 29.0
    }
}

/// Inverse of [`lab_f`] (docs/physics.md §6.1).
fn lab_f_inv(t: f64) -> f64 {
    const D: f64 = 6.0 / 29.0;
    if t > D {
        t * t * t
    } else {
        3.0 * D * D * (t - 4.0 / 29.0)
    }
}

/// XYZ → L\*a\*b\* relative to `white` (CIE 15:2004, §8.2.1).
pub fn xyz_to_lab(xyz: Xyz, white: Xyz) -> Lab {
    let fx = lab_f(xyz.x / white.x);
    let fy = lab_f(xyz.y / white.y);
    let fz = lab_f(xyz.z / white.z);
    Lab {
        l: 116.0 * fy - 16.0,
        a: 500.0 * (fx - fy),
        b: 200.0 * (fy - fz),
    }
}

/// L\*a\*b\* → XYZ relative to `white` (inverse of CIE 15:2004 §8.2.1; docs/physics.md §6.1).
pub fn lab_to_xyz(lab: Lab, white: Xyz) -> Xyz {
    let fy = (lab.l + 16.0) / 116.0;
    let fx = fy + lab.a / 500.0;
    let fz = fy - lab.b / 200.0;
    Xyz {
        x: white.x * lab_f_inv(fx),
        y: white.y * lab_f_inv(fy),
        z: white.z * lab_f_inv(fz),
    }
}

/// The Bradford cone-response matrix (Lam 1985; as in ICC.1:2010 Annex E and CIE 15:2004 §8.1 notes).
const BRADFORD: [[f64; 3]; 3] = [
    [0.8951, 0.2664, -0.1614],
    [-0.7502, 1.7135, 0.0367],
    [0.0389, -0.0685, 1.0296],
];

fn mat_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// Inverse of a 3 × 3 matrix by cofactors (the matrices here are fixed and well conditioned).
fn mat_inv(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c =
        |r0: usize, c0: usize, r1: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let cof = [
        [c(1, 1, 2, 2), -c(1, 0, 2, 2), c(1, 0, 2, 1)],
        [-c(0, 1, 2, 2), c(0, 0, 2, 2), -c(0, 0, 2, 1)],
        [c(0, 1, 1, 2), -c(0, 0, 1, 2), c(0, 0, 1, 1)],
    ];
    let det = m[0][0] * cof[0][0] + m[0][1] * cof[0][1] + m[0][2] * cof[0][2];
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = cof[j][i] / det;
        }
    }
    inv
}

/// Bradford chromatic adaptation of `xyz` from white `from` to white `to` (von Kries scaling in the
/// Bradford cone space: M⁻¹ diag(ρ_to/ρ_from) M; Lam 1985, ICC.1:2010 Annex E).
pub fn bradford(xyz: Xyz, from: Xyz, to: Xyz) -> Xyz {
    let cone = |v: Xyz| mat_vec(&BRADFORD, [v.x, v.y, v.z]);
    let (src, dst, c) = (cone(from), cone(to), cone(xyz));
    let adapted = [
        c[0] * dst[0] / src[0],
        c[1] * dst[1] / src[1],
        c[2] * dst[2] / src[2],
    ];
    let out = mat_vec(&mat_inv(&BRADFORD), adapted);
    Xyz {
        x: out[0],
        y: out[1],
        z: out[2],
    }
}

/// XYZ (Y = 1 scale) → linear sRGB, IEC 61966-2-1:1999 eq. (F.7) with its 4-decimal matrix.
const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.2406, -1.5372, -0.4986],
    [-0.9689, 1.8758, 0.0415],
    [0.0557, -0.2040, 1.0570],
];

/// XYZ (Y = 100, D65, 2° observer) → linear sRGB reflectance (fractions; may fall outside [0, 1] for
/// colours outside the sRGB gamut — callers must not clamp silently).
pub fn xyz_to_linear_srgb(xyz: Xyz) -> [f64; 3] {
    mat_vec(&XYZ_TO_SRGB, [xyz.x / 100.0, xyz.y / 100.0, xyz.z / 100.0])
}

/// Linear sRGB reflectance → XYZ (Y = 100, D65, 2°): the exact inverse of [`xyz_to_linear_srgb`].
///
/// IEC 61966-2-1:1999 eq. (F.8) prints a 4-decimal matrix (0.4124, 0.3576, …) that inverts eq. (F.7)
/// only to ~1e-4; we invert (F.7) itself so that the two directions round-trip exactly (the synthetic
/// rig relies on it). The two agree to the printed decimals.
pub fn linear_srgb_to_xyz(rgb: [f64; 3]) -> Xyz {
    let v = mat_vec(&mat_inv(&XYZ_TO_SRGB), rgb);
    Xyz {
        x: 100.0 * v[0],
        y: 100.0 * v[1],
        z: 100.0 * v[2],
    }
}

/// The sRGB transfer function (IEC 61966-2-1:1999, eq. (F.6)): linear → encoded, both in [0, 1].
pub fn srgb_encode(linear: f64) -> f64 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// L\*a\*b\* (D65, measured with `observer`) → linear sRGB reflectance.
///
/// 2°: L\*a\*b\* → XYZ with the 2° white, then the sRGB matrix. 10°: L\*a\*b\* → XYZ with the 10°
/// white, Bradford-adapted to the 2° white, then the sRGB matrix (the choice recorded in
/// ARCHITECTURE.md; sRGB itself is defined for the 2° observer only).
pub fn lab_to_linear_srgb(lab: Lab, observer: Observer) -> [f64; 3] {
    let white2 = Observer::TwoDegree.d65_white();
    let xyz = match observer {
        Observer::TwoDegree => lab_to_xyz(lab, white2),
        Observer::TenDegree => {
            let white10 = Observer::TenDegree.d65_white();
            bradford(lab_to_xyz(lab, white10), white10, white2)
        }
    };
    xyz_to_linear_srgb(xyz)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    /// docs/physics.md §6.3: the weight sums reproduce the ASTM E308 white points.
    #[test]
    fn white_points_are_weight_sums() {
        let w2 = Observer::TwoDegree.d65_white();
        let w10 = Observer::TenDegree.d65_white();
        assert!(
            close(w2.x, 95.047, 2e-3) && close(w2.y, 100.0, 2e-3) && close(w2.z, 108.883, 2e-3)
        );
        assert!(
            close(w10.x, 94.811, 2e-3) && close(w10.y, 100.0, 2e-3) && close(w10.z, 107.305, 2e-3)
        );
    }

    /// docs/physics.md §6.2: Lab(60, 20, −30) with the ASTM E308 2° white.
    #[test]
    fn lab_to_xyz_and_srgb_reference_vectors() {
        let lab = Lab {
            l: 60.0,
            a: 20.0,
            b: -30.0,
        };
        let white = Xyz {
            x: 95.047,
            y: 100.0,
            z: 108.883,
        };
        let xyz = lab_to_xyz(lab, white);
        assert!(
            close(xyz.x, 31.9313, 1e-4)
                && close(xyz.y, 28.1233, 1e-4)
                && close(xyz.z, 56.8364, 1e-4)
        );
        let rgb = xyz_to_linear_srgb(xyz);
        for (got, want) in rgb.iter().zip([0.319066, 0.241743, 0.561175]) {
            assert!(close(*got, want, 2e-6), "{got} vs {want}");
        }
        let enc: Vec<f64> = rgb.iter().map(|&c| 255.0 * srgb_encode(c)).collect();
        for (got, want) in enc.iter().zip([153.11, 134.86, 197.45]) {
            assert!(close(*got, want, 0.01), "{got} vs {want}");
        }
        // Round trip.
        let back = xyz_to_lab(xyz, white);
        assert!(
            close(back.l, 60.0, 1e-10) && close(back.a, 20.0, 1e-10) && close(back.b, -30.0, 1e-10)
        );
    }

    /// docs/physics.md §6.2 last row: 10° Lab with the xy-derived whites, Bradford to the 2° white.
    #[test]
    fn bradford_reference_vector() {
        let lab = Lab {
            l: 60.0,
            a: 20.0,
            b: -30.0,
        };
        let w10 = Xyz {
            x: 94.8097,
            y: 100.0,
            z: 107.3051,
        };
        let w2 = Xyz {
            x: 95.0456,
            y: 100.0,
            z: 108.9058,
        };
        let xyz10 = lab_to_xyz(lab, w10);
        assert!(close(xyz10.x, 31.8515, 2e-4) && close(xyz10.z, 56.0128, 2e-4));
        let rgb = xyz_to_linear_srgb(bradford(xyz10, w10, w2));
        for (got, want) in rgb.iter().zip([0.320279, 0.241663, 0.561450]) {
            assert!(close(*got, want, 3e-5), "{got} vs {want}");
        }
        // Adapting the source white gives the destination white.
        let w = bradford(w10, w10, w2);
        assert!(close(w.x, w2.x, 1e-9) && close(w.y, w2.y, 1e-9) && close(w.z, w2.z, 1e-9));
    }

    /// The inverse matrix agrees with IEC 61966-2-1 eq. (F.8) to its printed 4 decimals and
    /// round-trips exactly.
    #[test]
    fn srgb_to_xyz_is_the_exact_inverse_and_matches_f8() {
        let f8 = [
            [0.4124, 0.3576, 0.1805],
            [0.2126, 0.7152, 0.0722],
            [0.0193, 0.1192, 0.9505],
        ];
        for (c, col) in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
            .iter()
            .enumerate()
        {
            let xyz = linear_srgb_to_xyz(*col);
            for (r, v) in [xyz.x, xyz.y, xyz.z].iter().enumerate() {
                assert!((v / 100.0 - f8[r][c]).abs() < 1.5e-4, "({r},{c}): {v}");
            }
        }
        let rgb = [0.2, 0.5, 0.9];
        let back = xyz_to_linear_srgb(linear_srgb_to_xyz(rgb));
        for (a, b) in rgb.iter().zip(back) {
            assert!((a - b).abs() < 1e-14);
        }
    }

    /// docs/physics.md §6.2 extras: a neutral grey and a saturated green (computed there with the
    /// xy-derived D65/2° white 0.950456, 1, 1.089058).
    #[test]
    fn extra_lab_vectors() {
        let white = Xyz {
            x: 95.0456,
            y: 100.0,
            z: 108.9058,
        };
        let grey = xyz_to_linear_srgb(lab_to_xyz(
            Lab {
                l: 50.0,
                a: 0.0,
                b: 0.0,
            },
            white,
        ));
        for c in grey {
            assert!(close(c, 0.18420, 2e-4), "{c}");
        }
        let green = xyz_to_linear_srgb(lab_to_xyz(
            Lab {
                l: 75.0,
                a: -40.0,
                b: 60.0,
            },
            white,
        ));
        for (got, want) in green.iter().zip([0.273002, 0.588765, 0.050929]) {
            assert!(close(*got, want, 2e-5), "{got} vs {want}");
        }
    }

    /// The ColorChecker "dark skin" spectrum (docs/physics.md §6.4).
    const DARK_SKIN: [f64; 31] = [
        0.061, 0.062, 0.062, 0.062, 0.062, 0.062, 0.062, 0.062, 0.062, 0.063, 0.065, 0.070, 0.076,
        0.079, 0.081, 0.084, 0.091, 0.103, 0.119, 0.134, 0.143, 0.147, 0.151, 0.158, 0.168, 0.179,
        0.188, 0.190, 0.186, 0.181, 0.182,
    ];

    fn grid() -> Vec<f64> {
        (0..31).map(|i| 400.0 + 10.0 * i as f64).collect()
    }

    /// docs/physics.md §6.4: XYZ and L*a*b* of "dark skin", both observers, Lab white = weight
    /// sums.
    #[test]
    fn dark_skin_reference_vector() {
        let wl = grid();
        let xyz2 = spectrum_to_xyz(&wl, &DARK_SKIN, Observer::TwoDegree).unwrap();
        assert!(
            close(xyz2.x, 11.1467, 6e-4)
                && close(xyz2.y, 10.0724, 6e-4)
                && close(xyz2.z, 6.8045, 6e-4)
        );
        let lab2 = xyz_to_lab(xyz2, Observer::TwoDegree.d65_white());
        assert!(
            close(lab2.l, 37.9721, 1e-3)
                && close(lab2.a, 12.1025, 1e-3)
                && close(lab2.b, 13.6879, 1e-3)
        );
        let xyz10 = spectrum_to_xyz(&wl, &DARK_SKIN, Observer::TenDegree).unwrap();
        assert!(
            close(xyz10.x, 10.8834, 6e-4)
                && close(xyz10.y, 9.8153, 6e-4)
                && close(xyz10.z, 6.6861, 6e-4)
        );
        let lab10 = xyz_to_lab(xyz10, Observer::TenDegree.d65_white());
        assert!(
            close(lab10.l, 37.5090, 1e-3)
                && close(lab10.a, 12.3576, 1e-3)
                && close(lab10.b, 12.9674, 1e-3)
        );
        // The reference's linear sRGB was computed from colour-science's native-range XYZ
        // (11.1475, 10.0728, 6.8040), 8e-4 away from the 400–700 nm truncation: hence 5e-5.
        let rgb = xyz_to_linear_srgb(xyz2);
        for (got, want) in rgb.iter().zip([0.172484, 0.083760, 0.057579]) {
            assert!(close(*got, want, 5e-5), "{got} vs {want}");
        }
    }

    /// A 5 nm spectrum over 360–780 nm gives the same XYZ as its 10 nm samples over 400–700 nm, and a
    /// flat white gives the white point.
    #[test]
    fn five_nm_and_wide_range_spectra_are_accepted() {
        let wl5: Vec<f64> = (0..=84).map(|i| 360.0 + 5.0 * i as f64).collect();
        let v5: Vec<f64> = wl5
            .iter()
            .map(|&w| 0.3 + 0.2 * ((w - 360.0) / 420.0))
            .collect();
        let wl10 = grid();
        let v10: Vec<f64> = wl10
            .iter()
            .map(|&w| 0.3 + 0.2 * ((w - 360.0) / 420.0))
            .collect();
        let a = spectrum_to_xyz(&wl5, &v5, Observer::TwoDegree).unwrap();
        let b = spectrum_to_xyz(&wl10, &v10, Observer::TwoDegree).unwrap();
        assert!(close(a.x, b.x, 1e-12) && close(a.y, b.y, 1e-12) && close(a.z, b.z, 1e-12));
        let white = spectrum_to_xyz(&wl10, &[1.0; 31], Observer::TenDegree).unwrap();
        let lab = xyz_to_lab(white, Observer::TenDegree.d65_white());
        assert!(close(lab.l, 100.0, 1e-12) && close(lab.a, 0.0, 1e-12) && close(lab.b, 0.0, 1e-12));
    }

    #[test]
    fn spectra_that_do_not_cover_the_range_are_refused() {
        let wl: Vec<f64> = (0..=28).map(|i| 420.0 + 10.0 * i as f64).collect();
        assert!(spectrum_to_xyz(&wl, &vec![0.5; wl.len()], Observer::TwoDegree).is_err());
        let coarse: Vec<f64> = (0..=15).map(|i| 400.0 + 20.0 * i as f64).collect();
        assert!(spectrum_to_xyz(&coarse, &vec![0.5; coarse.len()], Observer::TwoDegree).is_err());
        assert!(spectrum_to_xyz(&[400.0, 400.0], &[0.5, 0.5], Observer::TwoDegree).is_err());
    }
}
