//! The merged radiance map ([`HdrImage`]): radiance, the clipping mask and what fills a
//! pixel-channel clipped in every frame; the checks of a dark frame and of the valid fraction.

use crate::ImageBuf;
use crate::error::{ImagingError, Result};

/// Mask bit: the pixel-channel was at the low clip (code 0, or not above the dark frame) in some
/// exposure and has no usable sample.
pub const CLIPPED_LOW: u8 = 1;

/// Mask bit: the pixel-channel was saturated (the maximum code) in some exposure and has no usable
/// sample.
pub const CLIPPED_HIGH: u8 = 2;

/// The least fraction of a channel's pixels that must have a radiance estimate (and, with a dark
/// frame, rise above it in the longest exposure) for a merge to count as a measurement: 0.1 %, a disc
/// of 87 px radius in a 24-MP frame. Below it the merge is refused
/// ([`ImagingError::NoValidRadiance`], [`ImagingError::DarkFrameAboveSignal`]) instead of returning
/// a map of NaN that looks like a result.
pub const MIN_VALID_FRACTION: f64 = 1e-3;

/// The least number of pixels out of `total` that [`MIN_VALID_FRACTION`] asks for (at least 1).
pub(super) fn min_valid(total: usize) -> usize {
    ((MIN_VALID_FRACTION * total as f64).ceil() as usize).max(1)
}

/// Refuses a dark frame at or above the signal: per channel, fewer than [`min_valid`] pixels of the
/// longest exposure above the dark frame.
pub(super) fn check_dark<T: Copy + PartialOrd>(
    frames: &[ImageBuf<T>],
    times_s: &[f64],
    dark: &ImageBuf<T>,
) -> Result<()> {
    let longest = (0..frames.len())
        .max_by(|&a, &b| times_s[a].total_cmp(&times_s[b]))
        .unwrap_or(0);
    let (f, ch) = (&frames[longest], dark.channels());
    let total = f.width() * f.height();
    for channel in 0..ch {
        let above = f
            .data()
            .iter()
            .zip(dark.data())
            .skip(channel)
            .step_by(ch)
            .filter(|(v, d)| v > d)
            .count();
        if above < min_valid(total) {
            return Err(ImagingError::DarkFrameAboveSignal {
                channel,
                above,
                total,
            });
        }
    }
    Ok(())
}

/// Refuses a merge in which (nearly) every pixel of a channel is clipped in every exposure.
fn check_valid(mask: &ImageBuf<u8>) -> Result<()> {
    let ch = mask.channels();
    let total = mask.width() * mask.height();
    for channel in 0..ch {
        let (mut valid, mut saturated, mut dark) = (0usize, 0usize, 0usize);
        for &m in mask.data().iter().skip(channel).step_by(ch) {
            match m {
                0 => valid += 1,
                m if m & CLIPPED_HIGH != 0 => saturated += 1,
                _ => dark += 1,
            }
        }
        if valid < min_valid(total) {
            return Err(ImagingError::NoValidRadiance {
                channel,
                valid,
                total,
                saturated,
                dark,
                advice: if saturated >= dark {
                    "the bracket is overexposed: add shorter exposures (or dim the light) so that \
                     every pixel is below saturation in at least one frame"
                } else {
                    "the bracket is too dark: add longer exposures (or more light), and check that \
                     the dark frame is darker than the scene"
                },
            });
        }
    }
    Ok(())
}

/// The radiance given to a pixel-channel that is clipped in every exposure (always also flagged).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum ClippedFill {
    /// NaN: downstream code (the radial profile, the spot finder) skips it, and it survives a round
    /// trip through a float file without a separate mask. The default.
    #[default]
    Nan,
    /// The largest radiance the data prove it has: for a saturated pixel, the radiance that would
    /// give the highest unclipped code in the shortest saturated exposure
    /// (exp(g(254) − ln Δt) for 8-bit); for a pixel dark in every frame, 0.
    LowerBound,
}

/// A merged radiance map and its clipping mask.
#[derive(Debug, Clone, PartialEq)]
pub struct HdrImage {
    /// Relative radiance E per pixel and channel (linear, not log).
    pub radiance: ImageBuf<f32>,
    /// Per pixel and channel: 0 if the radiance is an estimate, else [`CLIPPED_LOW`] |
    /// [`CLIPPED_HIGH`] bits saying why there is none.
    pub clipped: ImageBuf<u8>,
    /// Number of flagged pixel-channels (non-zero entries of `clipped`).
    pub clipped_count: usize,
}

impl HdrImage {
    /// A merge's radiance and clipping mask (`w × h × ch`, interleaved) as the map, refused when
    /// (nearly) every pixel of a channel is clipped in every exposure ([`MIN_VALID_FRACTION`]).
    pub(super) fn from_parts(
        (w, h, ch): (usize, usize, usize),
        radiance: Vec<f32>,
        mask: Vec<u8>,
        clipped_count: usize,
    ) -> Result<Self> {
        let clipped = ImageBuf::new(w, h, ch, mask)?;
        check_valid(&clipped)?;
        Ok(Self {
            radiance: ImageBuf::new(w, h, ch, radiance)?,
            clipped,
            clipped_count,
        })
    }

    /// True if pixel-channel `(x, y, c)` has a radiance estimate (not clipped everywhere).
    pub fn is_valid(&self, x: usize, y: usize, c: usize) -> bool {
        self.clipped
            .pixel(x, y)
            .and_then(|p| p.get(c))
            .is_some_and(|&m| m == 0)
    }
}
