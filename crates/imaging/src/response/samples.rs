//! How many sample pixels a response recovery takes, and which.

use super::curve::LEVELS;
use crate::ImageBuf;
use crate::error::{ImagingError, Result, check_bracket};

/// Most sample pixels per channel [`recover_response`](crate::response::recover_response) and [`gsolve`](crate::response::gsolve) accept: 10× the default. The
/// dense system has N·P + 255 rows of 256 doubles (1000 samples × 13 frames: 27 MB, well under a
/// second to solve); more samples add nothing that 1000 do not already give.
pub const MAX_RESPONSE_SAMPLES: usize = 1000;

/// The fewest sample pixels per channel for a bracket of `frames` exposures: N·(P − 1) ≥ 256, so that
/// the data rows alone (once each pixel's ln E is eliminated) outnumber the 256 unknowns g(z)
/// (Debevec & Malik 1997, §2.1: "N(P − 1) > (Z_max − Z_min)"). 256 for 2 frames, 22 for 13.
pub fn min_response_samples(frames: usize) -> usize {
    LEVELS.div_ceil(frames.saturating_sub(1).max(1))
}

/// A sample pixel chosen for response recovery.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SamplePixel {
    /// Column.
    pub x: usize,
    /// Row.
    pub y: usize,
}

/// Chooses `n` sample pixels of channel `c` for response recovery, deterministically.
///
/// Candidates lie on a regular grid (about 40 000 of them) away from the border. A candidate is
/// rejected if it is clipped (0 or 255) in every frame. Its *brightness key* is the sum of its code
/// values over the frames ordered by exposure time — monotonic in scene radiance — and its *flatness*
/// the sum over frames of its absolute central differences in x and y. The key range is split into `n`
/// equal strata; from each the flattest candidate is taken (ties to the first in raster order), so the
/// samples span the radiance range and avoid edges. Strata left empty are filled with the next
/// flattest candidates of the most populated strata.
///
/// # Errors
/// Bracket errors, [`ImagingError::InvalidOption`] for `n == 0` or a bad channel,
/// [`ImagingError::NotEnoughSamples`] if fewer than 2 usable candidates exist.
pub fn select_samples(
    frames: &[ImageBuf<u8>],
    times_s: &[f64],
    c: usize,
    n: usize,
) -> Result<Vec<SamplePixel>> {
    check_bracket(frames, times_s)?;
    let (w, h, ch) = (frames[0].width(), frames[0].height(), frames[0].channels());
    if c >= ch {
        return Err(ImagingError::InvalidOption {
            name: "channel",
            value: c as f64,
            reason: "no such channel",
        });
    }
    if n == 0 || n > MAX_RESPONSE_SAMPLES {
        return Err(ImagingError::SampleCount {
            samples: n,
            frames: frames.len(),
            min: 1,
            max: MAX_RESPONSE_SAMPLES,
        });
    }
    // Candidate grid with a 1-pixel border (for central differences) where possible.
    let target = 40_000usize;
    let step = (((w * h) as f64 / target as f64).sqrt().floor() as usize).max(1);
    let (x0, x1) = if w >= 3 { (1, w - 1) } else { (0, w) };
    let (y0, y1) = if h >= 3 { (1, h - 1) } else { (0, h) };
    let at = |f: &ImageBuf<u8>, x: usize, y: usize| i32::from(f.data()[(y * w + x) * ch + c]);
    struct Cand {
        key: u32,
        grad: u32,
        x: usize,
        y: usize,
    }
    let mut cands = Vec::new();
    let mut y = y0 + step / 2;
    while y < y1 {
        let mut x = x0 + step / 2;
        while x < x1 {
            let (mut key, mut grad, mut all_clipped) = (0u32, 0u32, true);
            for f in frames {
                let v = at(f, x, y);
                key += v as u32;
                if v > 0 && v < 255 {
                    all_clipped = false;
                }
                if w >= 3 {
                    grad += (at(f, x + 1, y) - at(f, x - 1, y)).unsigned_abs();
                }
                if h >= 3 {
                    grad += (at(f, x, y + 1) - at(f, x, y - 1)).unsigned_abs();
                }
            }
            if !all_clipped {
                cands.push(Cand { key, grad, x, y });
            }
            x += step;
        }
        y += step;
    }
    let needed = 2;
    if cands.len() < needed {
        return Err(ImagingError::NotEnoughSamples {
            channel: c,
            found: cands.len(),
            needed,
        });
    }
    let kmin = cands.iter().map(|c| c.key).min().unwrap_or(0);
    let kmax = cands.iter().map(|c| c.key).max().unwrap_or(0);
    let span = u64::from(kmax - kmin) + 1;
    let mut strata: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, cand) in cands.iter().enumerate() {
        let s = (u64::from(cand.key - kmin) * n as u64 / span) as usize;
        strata[s.min(n - 1)].push(i);
    }
    for s in &mut strata {
        // Stable sort keeps raster order among equal gradients.
        s.sort_by_key(|&i| cands[i].grad);
    }
    let mut picked = Vec::with_capacity(n);
    let mut next = vec![0usize; n];
    for (s, list) in strata.iter().enumerate() {
        if let Some(&i) = list.first() {
            picked.push(i);
            next[s] = 1;
        }
    }
    // Fill empty strata from the most populated ones.
    while picked.len() < n.min(cands.len()) {
        let best = (0..n)
            .filter(|&s| next[s] < strata[s].len())
            .max_by_key(|&s| (strata[s].len() - next[s], n - s));
        let Some(s) = best else { break };
        picked.push(strata[s][next[s]]);
        next[s] += 1;
    }
    Ok(picked
        .into_iter()
        .map(|i| SamplePixel {
            x: cands[i].x,
            y: cands[i].y,
        })
        .collect())
}
