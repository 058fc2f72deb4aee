//! The light spot photographed on a white target (`camera.spot_image`), linearised as the bracket
//! was, as the fit's spot kernel.

use std::path::Path;

use scatterfit_imaging::ImageBuf;
use scatterfit_io::image_files::{CameraFrame, read_camera_frame};

use super::{HdrStage, linearise_u8};
use crate::error::{PipelineError, Result};

/// How far a spot image's light may reach (the radius holding 99 % of its power) beyond the stated
/// spot's radius: a Gaussian spot reaches 1.52× its 1/e² radius, a disk 1.0×, a white target's own
/// blur adds a little; a frame of the sample reaches many times further (the material's glow).
pub const SPOT_IMAGE_MAX_REACH: f64 = 3.0;

/// The fit's spot kernel from `camera.spot_image` ([`crate::camera::spot_from_image`]): the image
/// linearised as the bracket was (8-bit through the bracket's response; linear data less the
/// black level found for the bracket). `stated_diameter_mm` is the manifest's spot diameter: an
/// image whose light reaches more than [`SPOT_IMAGE_MAX_REACH`] times its radius is not a
/// photograph of that spot.
///
/// # Errors
/// [`PipelineError::Input`] naming the file and what is wrong with it.
pub fn spot_kernel_from_image(
    path: &Path,
    stage: &HdrStage,
    mm_per_pixel: f64,
    stated_diameter_mm: f64,
) -> Result<scatterfit_fit::RadialSpot> {
    let bad = |what: String| {
        PipelineError::Input(format!(
            "{} (camera.spot_image): {what}; it is a photograph of the light spot on a thin \
             opaque white target (paper, a white tile) with the bracket's camera and scale",
            path.display()
        ))
    };
    let frame = read_camera_frame(path)
        .map_err(|e| bad(e.to_string()))?
        .frame;
    let linear: Vec<f32> = match (&frame, &stage.response) {
        (CameraFrame::U8(f), Some(r)) => linearise_u8(f, r),
        (CameraFrame::U8(f), None) => f.data().iter().map(|&z| f32::from(z)).collect(),
        (CameraFrame::U16(f), _) => {
            let ch = f.channels();
            let black = stage.corrections.black_level.as_ref();
            f.data()
                .iter()
                .enumerate()
                .map(|(i, &v)| {
                    (f64::from(v) - black.map_or(0.0, |(b, _)| b[(i % ch).min(b.len() - 1)])) as f32
                })
                .collect()
        }
    };
    let buf = ImageBuf::new(frame.width(), frame.height(), frame.channels(), linear)
        .map_err(|e| bad(e.to_string()))?;
    let spot = crate::camera::spot_from_image(&buf, mm_per_pixel).map_err(bad)?;
    let (reach, stated) = (spot.radius_enclosing(0.99), 0.5 * stated_diameter_mm);
    if reach > SPOT_IMAGE_MAX_REACH * stated {
        return Err(bad(format!(
            "its light reaches {reach:.3} mm from its centre (99 % of its power), {:.1}× the \
             stated spot's radius ({stated} mm, camera.spot_diameter_mm) where a photographed \
             spot reaches at most about {SPOT_IMAGE_MAX_REACH}×: is it a frame of the sample (the \
             material's glow around the spot), or taken at another image scale?",
            reach / stated
        )));
    }
    Ok(spot)
}
