//! From linear radiance to what a screen shows: exposure, a tone curve on luminance, the sRGB
//! transfer function, 8 bits.
//!
//! - Exposure: radiance × π · 2^EV, so that at EV 0 a perfect white Lambertian surface facing a
//!   light of irradiance 1 has the value 1 (the renders' reference white).
//! - Tone curve: extended Reinhard on luminance Y (Reinhard et al. 2002, "Photographic Tone
//!   Reproduction for Digital Images", eq. 4): Y′ = Y(1 + Y/Yw²)/(1 + Y), with Yw the value mapped
//!   to 1; the linear RGB is scaled by Y′/Y, which keeps hue and saturation; a channel still above 1
//!   is clipped. Y = 0.2126 R + 0.7152 G + 0.0722 B (the second row of the sRGB → XYZ matrix,
//!   IEC 61966-2-1).
//! - Encoding: the sRGB transfer function (IEC 61966-2-1 F.6), rounded to 8 bits.

use scatterfit_imaging::ImageBuf;
use scatterfit_optics::colour::{linear_srgb_to_xyz, srgb_encode};

use crate::error::{Result, invalid};

/// Exposure and tone curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToneMap {
    /// Exposure in stops relative to the reference white (see the module docs). Default 0.
    pub exposure_ev: f64,
    /// Luminance (after exposure) that maps to display white, Yw ≥ 1. Default 4: the reference
    /// white shows at 62 % (sRGB code 207), highlights up to 4× brighter roll off smoothly.
    pub white: f64,
}

impl Default for ToneMap {
    fn default() -> Self {
        Self {
            exposure_ev: 0.0,
            white: 4.0,
        }
    }
}

/// Luminance weights of linear sRGB (D65): Y of `linear_srgb_to_xyz` for unit primaries.
pub fn luminance_weights() -> [f64; 3] {
    [
        linear_srgb_to_xyz([1.0, 0.0, 0.0]).y / 100.0,
        linear_srgb_to_xyz([0.0, 1.0, 0.0]).y / 100.0,
        linear_srgb_to_xyz([0.0, 0.0, 1.0]).y / 100.0,
    ]
}

/// The luminance of a linear RGB image as a one-channel image (the `--gray` output).
///
/// # Errors
/// [`crate::RenderError::InvalidOption`] if `img` does not have 3 channels.
pub fn luminance_image(img: &ImageBuf<f32>) -> Result<ImageBuf<f32>> {
    if img.channels() != 3 {
        return Err(invalid("channels", img.channels(), "need an RGB image"));
    }
    let w = luminance_weights();
    let data = img
        .data()
        .chunks_exact(3)
        .map(|p| (w[0] * p[0] as f64 + w[1] * p[1] as f64 + w[2] * p[2] as f64) as f32)
        .collect();
    Ok(ImageBuf::new(img.width(), img.height(), 1, data)?)
}

/// Tone maps a linear radiance image (1 or 3 channels) to 8-bit sRGB with the same channels.
///
/// # Errors
/// [`crate::RenderError::InvalidOption`] for Yw < 1, a non-finite exposure, or a channel count
/// other than 1 or 3.
pub fn tone_map(img: &ImageBuf<f32>, tm: &ToneMap) -> Result<ImageBuf<u8>> {
    if !(tm.white.is_finite() && tm.white >= 1.0) {
        return Err(invalid("tone-map white", tm.white, "must be ≥ 1"));
    }
    if !tm.exposure_ev.is_finite() || tm.exposure_ev.abs() > 64.0 {
        return Err(invalid(
            "exposure [EV]",
            tm.exposure_ev,
            "must lie in [−64, 64]",
        ));
    }
    let ch = img.channels();
    if ch != 1 && ch != 3 {
        return Err(invalid("channels", ch, "need 1 or 3"));
    }
    let k = std::f64::consts::PI * tm.exposure_ev.exp2();
    let w = luminance_weights();
    let inv_w2 = 1.0 / (tm.white * tm.white);
    let curve = |y: f64| y * (1.0 + y * inv_w2) / (1.0 + y);
    let encode = |v: f64| (255.0 * srgb_encode(v.clamp(0.0, 1.0))).round() as u8;
    let mut out = Vec::with_capacity(img.data().len());
    for p in img.data().chunks_exact(ch) {
        // Non-finite or negative radiance cannot come from the renderer; treat it as black.
        let v: Vec<f64> = p
            .iter()
            .map(|&x| {
                if x.is_finite() && x > 0.0 {
                    k * x as f64
                } else {
                    0.0
                }
            })
            .collect();
        let y = if ch == 3 {
            w[0] * v[0] + w[1] * v[1] + w[2] * v[2]
        } else {
            v[0]
        };
        let scale = if y > 0.0 { curve(y) / y } else { 0.0 };
        out.extend(v.iter().map(|&x| encode(x * scale)));
    }
    Ok(ImageBuf::new(img.width(), img.height(), ch, out)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_white_and_curve() {
        let w = luminance_weights();
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-4);
        assert!((w[1] - 0.7152).abs() < 1e-3);
        // A white Lambertian surface under irradiance 1: radiance 1/π → Y = 1 → Y′ = (1 + 1/16)/2.
        let img = ImageBuf::new(2, 1, 3, vec![std::f32::consts::FRAC_1_PI; 6]).unwrap();
        let out = tone_map(&img, &ToneMap::default()).unwrap();
        let expected = (255.0 * srgb_encode(0.5 * (1.0 + 1.0 / 16.0))).round() as u8;
        assert_eq!(out.data()[0], expected);
        // Yw maps to 1.
        let v = (4.0 / std::f64::consts::PI) as f32;
        let img = ImageBuf::new(1, 1, 3, vec![v; 3]).unwrap();
        assert_eq!(
            tone_map(&img, &ToneMap::default()).unwrap().data(),
            &[255; 3]
        );
        // NaN and negative values show black.
        let img = ImageBuf::new(2, 1, 1, vec![f32::NAN, -1.0]).unwrap();
        assert_eq!(tone_map(&img, &ToneMap::default()).unwrap().data(), &[0, 0]);
    }
}
