//! A merged radiance map given in place of a bracket (the manifest's `camera.hdr`).

use std::path::Path;
use std::time::Instant;

use scatterfit_imaging::{HdrImage, ImageBuf};

use super::{Corrections, HdrStage};
use crate::error::{PipelineError, Result};
use crate::hdr::ResponseKind;

/// A radiance map read from a file (the manifest's `camera.hdr`): no bracket, no detection limit;
/// the stage records the file with the hash of the bytes decoded ([`HdrStage::radiance_file`]).
///
/// # Errors
/// [`PipelineError::Image`].
pub fn read_radiance_map(path: &Path) -> Result<HdrStage> {
    let t0 = Instant::now();
    let budget = scatterfit_io::budget::memory_budget_bytes();
    let bytes = scatterfit_io::image_files::read_image_bytes(path, budget)?;
    let radiance = scatterfit_io::image_files::decode_radiance(&bytes, path, budget)?;
    let radiance_file = scatterfit_io::digest::ReadFile::of(path, &bytes);
    drop(bytes);
    let (w, h, ch) = (radiance.width(), radiance.height(), radiance.channels());
    let clipped = ImageBuf::filled(w, h, ch, 0u8).map_err(|e| {
        PipelineError::Input(format!("{}: inconsistent image size ({e})", path.display()))
    })?;
    Ok(HdrStage {
        hdr: HdrImage {
            radiance,
            clipped,
            clipped_count: 0,
        },
        response: None,
        response_kind: ResponseKind::Merged,
        rms: Vec::new(),
        frames: Vec::new(),
        radiance_file: Some(radiance_file),
        image: format!("{w}×{h} {}", if ch == 1 { "grey" } else { "RGB" }),
        detection_limit: vec![f64::NAN; ch],
        dropped_alpha: Vec::new(),
        read_s: t0.elapsed().as_secs_f64(),
        merge_s: 0.0,
        corrections: Corrections::default(),
        thumbnails: Vec::new(),
    })
}
