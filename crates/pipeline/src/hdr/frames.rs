//! What the HDR stage measures of its frames as it merges them: the codes 16-bit frames use (and
//! their clipping plateau), where the spot is in each frame, and a stated black level against the
//! bracket's far corners. The verdicts on them (`checks`) read these records; the stage itself
//! uses them to set its saturation and to say why a bracket is refused.

use crate::hdr::BlackLevelCheck;

/// The codes 16-bit frames use: the largest, the clipping plateau found below the nominal
/// saturation, and the bits that implies. A camera of 12 bits writing 16-bit files (values
/// 0…4095, or shifted to the top bits) clips at 4095 (or 65520), where a 65535 saturation would
/// take clipped pixels for light.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct CodeRange {
    /// The largest code in any frame.
    pub max_code: u16,
    /// Samples at `max_code` in the frame holding most of them.
    pub at_max: usize,
    /// Bits the codes span: ⌈log2(max_code + 1)⌉ (after removing a common power-of-two factor).
    pub bits: u32,
    /// The saturation the merge uses: the nominal one, or the plateau found below it.
    pub saturation: u16,
    /// True when the plateau replaced the nominal saturation.
    pub plateau_found: bool,
}

/// Samples at one code below the nominal saturation that make it a clipping plateau: at least
/// this many, and at least 10⁻⁴ of a frame's samples (a linear sensor's unclipped maximum is held
/// by a handful of samples; a clipped spot by hundreds).
pub const PLATEAU_MIN_SAMPLES: usize = 16;

/// Finds the codes 16-bit frames use ([`CodeRange`]).
///
/// # Errors
/// [`crate::PipelineError::Input`] for 8-bit frames scaled into 16 bits (every code a multiple of 257,
/// as an image editor converts): their tone curve is not linear, and merging them as linear data
/// would give wrong radiances.
pub fn code_range(
    frames: &[scatterfit_imaging::ImageBuf<u16>],
    saturation: u16,
) -> crate::Result<CodeRange> {
    let mut max_code = 0u16;
    let mut all_257 = true;
    let mut or_bits = 0u16;
    for f in frames {
        for &v in f.data() {
            max_code = max_code.max(v);
            all_257 &= v % 257 == 0;
            or_bits |= v;
        }
    }
    if all_257 && max_code > 255 {
        return Err(crate::PipelineError::Input(
            "the 16-bit frames hold 8-bit codes scaled by 257 (every value a multiple of 257: an \
             image editor's conversion): their tone curve is not linear and cannot be merged as \
             16-bit linear data — give the camera's 8-bit frames (or its 16-bit linear ones)"
                .into(),
        ));
    }
    let at_max = frames
        .iter()
        .map(|f| f.data().iter().filter(|&&v| v == max_code).count())
        .max()
        .unwrap_or(0);
    let samples = frames.first().map_or(0, |f| f.data().len());
    let plateau_found = max_code < saturation
        && max_code > 0
        && at_max >= PLATEAU_MIN_SAMPLES.max(samples / 10_000);
    let shift = or_bits.trailing_zeros().min(15);
    let bits = 16 - (max_code >> shift).leading_zeros();
    Ok(CodeRange {
        max_code,
        at_max,
        bits,
        saturation: if plateau_found { max_code } else { saturation },
        plateau_found,
    })
}

/// Where the spot is in each frame of a bracket, to see whether the camera moved.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Registration {
    /// Per frame (shortest first), the centroid [x, y] px of the pixels at least half the
    /// saturation (a radially symmetric spot's half-saturated disk is centred on the spot in every
    /// frame); `None` where fewer than [`REGISTRATION_MIN_PIXELS`] pixels are, or the disk touches
    /// the frame's edge.
    pub centroids: Vec<Option<[f64; 2]>>,
    /// The largest shift between two frames' centroids \[px\].
    pub max_shift_px: f64,
}

/// Pixels a frame's half-saturated disk needs for its centroid to count.
pub const REGISTRATION_MIN_PIXELS: usize = 12;

/// The spot's centroid in each frame ([`Registration`]); `level(j, i)` is sample `i` of frame `j`
/// as a fraction of its saturation, `w × h` pixels of `ch` channels.
pub fn registration(
    frames: usize,
    w: usize,
    h: usize,
    ch: usize,
    level: &(dyn Fn(usize, usize) -> f64 + Sync),
) -> Registration {
    let mean_level = |j: usize, i: usize| (0..ch).map(|c| level(j, i + c)).sum::<f64>() / ch as f64;
    registration_where(frames, w, h, ch, |j, i| mean_level(j, i) >= 0.5)
}

/// [`registration`] of 8-bit frames (saturation 255), the half-saturation test in whole codes:
/// 2 Σ_c z_c against 255 · channels, the fractions' mean taken only at equality (where rounding
/// could tip it), so each pixel is judged as [`registration`] judges it.
pub fn registration_8bit(frames: &[scatterfit_imaging::ImageBuf<u8>]) -> Registration {
    let Some(f0) = frames.first() else {
        return registration_where(0, 0, 0, 1, |_, _| false);
    };
    let (w, h, ch) = (f0.width(), f0.height(), f0.channels());
    let full = 255 * ch as u32;
    registration_where(frames.len(), w, h, ch, |j, i| {
        let px = &frames[j].data()[i..i + ch];
        let twice = 2 * px.iter().map(|&z| u32::from(z)).sum::<u32>();
        if twice == full {
            px.iter().map(|&z| f64::from(z) / 255.0).sum::<f64>() / ch as f64 >= 0.5
        } else {
            twice > full
        }
    })
}

/// The centroids of the pixels for which `bright(j, i)` holds (frame `j`, the pixel's first
/// sample at `i`), frame by frame in parallel, and their largest shift ([`Registration`]).
fn registration_where(
    frames: usize,
    w: usize,
    h: usize,
    ch: usize,
    bright: impl Fn(usize, usize) -> bool + Sync,
) -> Registration {
    use rayon::prelude::*;
    // The frames in parallel.
    let centroids: Vec<Option<[f64; 2]>> = (0..frames)
        .into_par_iter()
        .map(|j| {
            let (mut n, mut sx, mut sy) = (0usize, 0.0, 0.0);
            let mut edge = false;
            for y in 0..h {
                for x in 0..w {
                    if bright(j, (y * w + x) * ch) {
                        n += 1;
                        sx += x as f64;
                        sy += y as f64;
                        edge |= x == 0 || y == 0 || x + 1 == w || y + 1 == h;
                    }
                }
            }
            (n >= REGISTRATION_MIN_PIXELS && !edge).then(|| [sx / n as f64, sy / n as f64])
        })
        .collect();
    let found: Vec<[f64; 2]> = centroids.iter().flatten().copied().collect();
    let mut max_shift_px = 0.0f64;
    for a in &found {
        for b in &found {
            max_shift_px = max_shift_px.max((a[0] - b[0]).hypot(a[1] - b[1]));
        }
    }
    Registration {
        centroids,
        max_shift_px,
    }
}

/// A stated black level may lie this far from the far corners' intercept, as a fraction of the
/// full scale, beyond five of the intercept's standard errors: 0.05 % (33 DN at 16 bits, 8 DN at
/// 14). A level off by 0.2 % of full scale moves σ′s and σa of the rig twin's linear camera by
/// about 9 %; one off by this much, by about 2 %.
pub const MAX_BLACK_LEVEL_OFFSET: f64 = 5e-4;

impl BlackLevelCheck {
    /// What is wrong when the stated level and the far corners' intercept at Δt = 0 differ, in
    /// some channel, by more than five standard errors and [`MAX_BLACK_LEVEL_OFFSET`] of the full
    /// scale (naming each such channel's numbers and what to check); `None` when they agree, the
    /// corners clip at 0 (no pedestal to read) or have no intercept.
    pub fn disagreement(&self) -> Option<String> {
        if self.clipped_at_zero {
            return None;
        }
        let off: Vec<String> = self
            .stated
            .iter()
            .zip(&self.corners)
            .zip(&self.corners_stderr)
            .enumerate()
            .filter(|(_, ((stated, corners), se))| {
                se.is_finite()
                    && (*stated - *corners).abs()
                        > (5.0 * **se).max(MAX_BLACK_LEVEL_OFFSET * self.saturation)
            })
            .map(|(c, ((stated, corners), se))| {
                format!(
                    "{} {stated:.0} DN against {corners:.0} ± {se:.1} DN",
                    ["R", "G", "B", "A"].get(c).copied().unwrap_or("?")
                )
            })
            .collect();
        if off.is_empty() {
            return None;
        }
        let what = match self.source {
            "dark frame" => "the dark frame's level (its far corners' mean)",
            "metadata" => "the RAW file's black level",
            "none" => "camera.black_level = \"none\" (no pedestal)",
            _ => "camera.black_level",
        };
        Some(format!(
            "{what} disagrees with the level the bracket's far corners show at zero exposure \
                 time ({}; more than 5 standard errors and {:.2} % of the full scale {:.0} DN apart): \
                 every dim ring is off by the difference — check the black level (or the dark frame \
                 was taken at other camera settings)",
            off.join(", "),
            100.0 * MAX_BLACK_LEVEL_OFFSET,
            self.saturation,
        ))
    }
}
