//! Dividing out a flat frame, within the peak and floor it may have.

use super::*;

/// Divides the radiance by a flat frame's smoothed, median-normalised linear values
/// ([`flat_divisor`]); returns the file and the divisor's range.
/// A flat frame's smoothed light may peak at most this many times its median: the brightest
/// middle of a lens vignetted to 10 % at the corners (the twin's strongest, `--vignetting 0.9`)
/// is about 1.6 × the median.
pub const FLAT_MAX_PEAK: f64 = 3.0;

/// A flat frame's smoothed light may fall to no less than this fraction of its median anywhere:
/// darker, the division multiplies the noise there by more than 20.
pub const FLAT_MIN_LOW: f64 = 0.05;

pub(super) fn divide_flat(
    hdr: &mut HdrImage,
    path: &Path,
    w: usize,
    h: usize,
    ch: usize,
    linear: Vec<f32>,
) -> Result<(PathBuf, f64, f64)> {
    let bad = || {
        PipelineError::Input(format!(
            "{}: the flat frame has no light (a frame of a uniform white target, exposed to \
             mid-range, is needed)",
            path.display()
        ))
    };
    let buf = ImageBuf::new(w, h, ch, linear).map_err(|_| bad())?;
    let div = flat_divisor(&buf).ok_or_else(bad)?;
    // A flat frame is a uniform white target seen through the lens: its smoothed light falls off
    // smoothly from the middle by the lens's vignetting, within a few times its median. A frame
    // that holds the spot (a frame of a bracket, another sample's picture) peaks far above it,
    // and one that is dark over part of the frame would divide that part by almost nothing.
    let peak = div.data().iter().copied().fold(0.0f32, f32::max);
    let low = div.data().iter().copied().fold(f32::INFINITY, f32::min);
    if f64::from(peak) > FLAT_MAX_PEAK || f64::from(low) < FLAT_MIN_LOW {
        return Err(PipelineError::Input(format!(
            "{}: not a flat frame — its light, smoothed, ranges from {:.3} to \
             {:.3} × its median, where a uniform white target seen through the lens stays within \
             {FLAT_MIN_LOW}–{FLAT_MAX_PEAK} × (vignetting falls off smoothly from the middle): \
             is it a frame of the bracket, of the spot, or of another scene? Photograph a \
             uniform white target at the bracket's lens settings, or drop camera.flat",
            path.display(),
            low,
            peak,
        )));
    }
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    let floor = 1e-3f32;
    let data: Vec<f32> = hdr
        .radiance
        .data()
        .iter()
        .zip(div.data())
        .map(|(&v, &d)| {
            lo = lo.min(f64::from(d));
            hi = hi.max(f64::from(d));
            v / d.max(floor)
        })
        .collect();
    if lo.is_nan() || lo <= 0.0 {
        return Err(bad());
    }
    hdr.radiance = ImageBuf::new(w, h, ch, data).map_err(|_| bad())?;
    Ok((path.to_path_buf(), lo, hi))
}
