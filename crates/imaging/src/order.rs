//! Is the bracket's order right? A camera's output rises with exposure, so in a bracket sorted by
//! time each frame must be brighter than the one before — pixel by pixel, wherever both frames
//! carry signal. A bracket whose times were reversed, shuffled or given to the wrong files, or in
//! which one frame was listed twice, fails this test directly, before any response is recovered
//! (a recovered response that dips is no evidence of a wrong order — noise at low codes does it
//! too — so the response recovery does not judge the order; this does).
//!
//! Only values that carry signal are evidence: a value at or below its frame's *noise floor* (the
//! black pedestal plus its noise, [`BracketSignal::floor`]) or at the clip says nothing about
//! order — the darkest frames of Debevec's memorial (1/1024 s, 1/512 s) sit at codes 13–20 almost
//! everywhere, the film's pedestal, which drifts by a code from frame to frame; compared value by
//! value they look out of order by noise alone.

use rayon::prelude::*;

use crate::ImageBuf;
use crate::error::{ImagingError, Result, check_bracket};

/// The share of a bracket's pixels (the darkest by their summed codes over every frame, pixels at
/// the low clip in every frame left out) whose codes give each frame's noise floor: 2 %.
pub const FLOOR_DARKEST_FRACTION: f64 = 0.02;

/// The quantile of the darkest pixels' codes in a frame taken for its noise floor: 0.99, so that
/// noise lifts a value without signal above the floor once in a hundred.
pub const FLOOR_QUANTILE: f64 = 0.99;

/// The least share of a frame's values above its noise floor and below the clip for the frame to
/// carry signal: 0.1 % (the merge's [`crate::MIN_VALID_FRACTION`]). Frames below it are black
/// (lens capped, far too short) or clipped all over. A frame with fewer (all black,
/// or all clipped) is left out of the merge with a note, not a reason to refuse the bracket.
pub const MIN_SIGNAL_FRACTION: f64 = 1e-3;

/// The least number of values carrying signal in both frames of a pair for the pair to be judged
/// at all (fewer: no evidence either way).
pub const MIN_ORDER_EVIDENCE: usize = 100;

/// What each frame of a bracket carries above its noise floor ([`bracket_signal`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BracketSignal {
    /// Per frame (as given) and channel, the noise floor: the [`FLOOR_QUANTILE`] of the frame's
    /// values over the [`FLOOR_DARKEST_FRACTION`] darkest pixels of the scene (by their codes
    /// summed over the bracket's other frames, which rises with radiance whatever the times say
    /// and is independent of this frame's noise). A value at or below it may be noise about the
    /// black level.
    pub floor: Vec<Vec<f64>>,
    /// Per frame, the share of its (subsampled) values above the floor and below the clip.
    pub signal_fraction: Vec<f64>,
    /// Per frame, whether that share reaches [`MIN_SIGNAL_FRACTION`].
    pub has_signal: Vec<bool>,
}

/// The regular subsample of value indices that the order check reads: at most about 200 000 values
/// per channel.
fn subsample(n_pixels: usize) -> usize {
    (n_pixels / 200_000).max(1)
}

/// The pixels [`bracket_signal`] measures the noise floors and the frames' signal on: every s-th
/// pixel in raster order, s the smallest step that leaves at most this many (every pixel of a
/// smaller frame). The floor is a quantile (0.99) of the 2 % darkest pixels' codes: over 65 536
/// pixels that is 1 311 values per frame and channel, its rank known to ±0.3 % of them.
pub const FLOOR_PIXELS: usize = 65_536;

/// The step of [`FLOOR_PIXELS`]'s subsample for frames of `n_pixels` pixels.
fn floor_step(n_pixels: usize) -> usize {
    n_pixels.div_ceil(FLOOR_PIXELS).max(1)
}

/// Each frame's noise floor per channel and whether it carries signal (see [`BracketSignal`]).
/// `max` is the clip value (255 for 8-bit, the saturation for linear data).
///
/// # Errors
/// Bracket errors.
pub fn bracket_signal<T>(frames: &[ImageBuf<T>], times_s: &[f64], max: T) -> Result<BracketSignal>
where
    T: Copy + PartialOrd + Default + Sync + Into<f64>,
{
    check_bracket(frames, times_s)?;
    let ch = frames[0].channels();
    let n_px = frames[0].width() * frames[0].height();
    let step = floor_step(n_px);
    let p = frames.len();
    let zero = T::default();
    // The values the checks read (every `step`-th pixel's samples), and per value its codes summed
    // over the bracket and whether any frame holds it above the low clip: one pass per frame
    // (frames in order, so each sum is formed as a pixel-by-pixel loop over the frames forms it).
    let sampled: Vec<usize> = (0..n_px)
        .step_by(step)
        .flat_map(|i| i * ch..(i + 1) * ch)
        .collect();
    let (sums, lit) = {
        let mut sums = vec![0.0f64; sampled.len()];
        let mut lit = vec![false; sampled.len()];
        // One parallel pass: each chunk of values summed over the frames in order.
        sums.par_chunks_mut(16_384)
            .zip(lit.par_chunks_mut(16_384))
            .zip(sampled.par_chunks(16_384))
            .for_each(|((s, l), ks)| {
                for f in frames {
                    let data = f.data();
                    for ((s, l), &k) in s.iter_mut().zip(l.iter_mut()).zip(ks) {
                        let v = data[k];
                        *l |= v > zero;
                        *s += v.into();
                    }
                }
            });
        (sums, lit)
    };
    // Per channel, per frame (in parallel: every frame's floor is a selection over the channel's
    // pixels).
    let by_channel: Vec<Vec<f64>> = (0..ch)
        .into_par_iter()
        .map(|c| {
            // Pixels with some value above the low clip, and their summed codes.
            let (mut idx, mut total) = (Vec::new(), Vec::new());
            for pos in (c..sampled.len()).step_by(ch) {
                if lit[pos] {
                    idx.push(sampled[pos]);
                    total.push(sums[pos]);
                }
            }
            if idx.is_empty() {
                return vec![0.0; p];
            }
            let take =
                ((FLOOR_DARKEST_FRACTION * idx.len() as f64).ceil() as usize).clamp(1, idx.len());
            // Every key (the others' sum) is a whole number; when they are small (8-bit codes:
            // at most 255 · P) the darkest are found by counting keys, otherwise by selection.
            let max_key = total.iter().copied().fold(0.0f64, f64::max);
            let whole = max_key <= COUNTED_KEYS as f64 && total.iter().all(|t| t.fract() == 0.0);
            let total_u32: Vec<u32> = if whole {
                total.iter().map(|&t| t as u32).collect()
            } else {
                Vec::new()
            };
            frames
                .par_iter()
                .map(|f| {
                    let v = if whole {
                        darkest_by_counting(f.data(), &idx, &total_u32, max_key as usize, take)
                    } else {
                        darkest_by_selection(f.data(), &idx, &total, take)
                    };
                    quantile_of(v)
                })
                .collect()
        })
        .collect();
    let floor: Vec<Vec<f64>> = (0..p)
        .map(|j| by_channel.iter().map(|f| f[j]).collect())
        .collect();
    let signal_fraction: Vec<f64> = frames
        .par_iter()
        .zip(&floor)
        .map(|(f, fl)| {
            let (mut above, mut total) = (0usize, 0usize);
            for i in (0..n_px).step_by(step) {
                for (c, fl) in fl.iter().enumerate() {
                    let v = f.data()[i * ch + c];
                    total += 1;
                    if v.into() > *fl && v < max {
                        above += 1;
                    }
                }
            }
            above as f64 / total.max(1) as f64
        })
        .collect();
    // Kept generously: noise alone lifts up to 1 − FLOOR_QUANTILE of a dark frame's values above
    // its floor, so a frame of pure noise counts as one with signal (and is merged, harmlessly);
    // a short frame whose only signal is a small bright spot — the only unclipped reading of the
    // spot's peak — must never be dropped (judged against noise's share, the twin's s-curve
    // camera at 15 e⁻ lost such a frame and its profile by 33 %).
    let has_signal = signal_fraction
        .iter()
        .map(|&s| s >= MIN_SIGNAL_FRACTION)
        .collect();
    Ok(BracketSignal {
        floor,
        signal_fraction,
        has_signal,
    })
}

/// Keys (sums of a pixel's codes over the bracket's other frames) up to this value are selected by
/// counting ([`darkest_by_counting`]): every 8-bit bracket of up to 257 frames.
const COUNTED_KEYS: usize = 1 << 16;

/// The key of the candidate at `pos` for frame `data`: the sum of its codes over the *other*
/// frames (`total` less this frame's code), so that the frame's own noise does not choose the
/// darkest pixels (which would pull its floor low).
#[inline]
fn others_key<T: Copy + Into<f64>>(data: &[T], idx: &[usize], total: &[f64], pos: usize) -> u64 {
    let own: f64 = data[idx[pos]].into();
    ((total[pos] - own).max(0.0) as u64).min(u64::from(u32::MAX))
}

/// Frame `data`'s values at the `take` darkest candidates by [`others_key`], equal keys taken in
/// raster order, found by selection on the key and the position packed into one integer.
fn darkest_by_selection<T: Copy + Into<f64>>(
    data: &[T],
    idx: &[usize],
    total: &[f64],
    take: usize,
) -> Vec<f64> {
    let mut keyed: Vec<u64> = (0..idx.len())
        .map(|pos| (others_key(data, idx, total, pos) << 32) | pos as u64)
        .collect();
    keyed.select_nth_unstable(take - 1);
    keyed[..take]
        .iter()
        .map(|&key| data[idx[(key & u64::from(u32::MAX)) as usize]].into())
        .collect()
}

/// [`darkest_by_selection`]'s values (the same set) by counting the keys, all at most `max_key`
/// (≤ [`COUNTED_KEYS`]; the codes whole numbers, so the key is the others' sum in integers): the
/// key K at which the count reaches `take`, then every candidate below K and the first in raster
/// order at K.
fn darkest_by_counting<T: Copy + Into<f64>>(
    data: &[T],
    idx: &[usize],
    total: &[u32],
    max_key: usize,
    take: usize,
) -> Vec<f64> {
    let key = |pos: usize| -> u32 {
        let own: f64 = data[idx[pos]].into();
        total[pos].saturating_sub(own as u32)
    };
    let mut count = vec![0u32; max_key + 1];
    for pos in 0..idx.len() {
        count[key(pos) as usize] += 1;
    }
    let (mut below, mut cut) = (0usize, 0u32);
    for (k, &n) in count.iter().enumerate() {
        if below + n as usize >= take {
            cut = k as u32;
            break;
        }
        below += n as usize;
    }
    let mut at_cut = take - below;
    let mut v = Vec::with_capacity(take);
    for pos in 0..idx.len() {
        let k = key(pos);
        if k < cut || (k == cut && at_cut > 0) {
            if k == cut {
                at_cut -= 1;
            }
            v.push(data[idx[pos]].into());
        }
    }
    v
}

/// The [`FLOOR_QUANTILE`] of `v` (the value at rank round(q · (n − 1)) in ascending order), `v`
/// not empty.
fn quantile_of(mut v: Vec<f64>) -> f64 {
    let q = ((FLOOR_QUANTILE * (v.len() - 1) as f64).round() as usize).min(v.len() - 1);
    *v.select_nth_unstable_by(q, f64::total_cmp).1
}

/// Checks that the frames of a bracket brighten with their exposure times: for each pair of frames
/// adjacent in time among those that carry signal ([`bracket_signal`]), over the values above
/// both frames' noise floors and below the clip `max` in both (the only values that are evidence
/// of order), the summed change Σ(y − x) from the shorter frame x to the longer y in units of its
/// noise, z = Σ(y − x)/√Σ(y − x)² (noise moves a value either way, so over values without signal z
/// stays within a few units of 0; values with signal add to it). Refused when z < −3 over at least
/// [`MIN_ORDER_EVIDENCE`] such values (the longer frame is clearly darker: times reversed or
/// shuffled), or when two frames adjacent in time are identical value for value (one frame
/// listed twice). A pair with less evidence is not judged. A frame shot twice and listed under two
/// times differs from its twin by noise only and is not refused here; the HDR stage's exposure
/// estimate finds it (`ImagingError::ExposureMismatch`). The message gives how many values got
/// darker and brighter.
///
/// At most about 200 000 pixels per channel are compared (a regular subsample).
///
/// # Errors
/// Bracket errors, [`ImagingError::BracketOutOfOrder`].
pub fn check_bracket_order<T>(frames: &[ImageBuf<T>], times_s: &[f64], max: T) -> Result<()>
where
    T: Copy + PartialOrd + PartialEq + Default + Sync + Into<f64>,
    [T]: PartialEq,
{
    let signal = bracket_signal(frames, times_s, max)?;
    check_bracket_order_with_signal(frames, times_s, max, &signal)
}

/// [`check_bracket_order`] with the frames' [`bracket_signal`] already measured (on the same
/// frames and times; a caller that needs both measures it once).
///
/// # Errors
/// Bracket errors, [`ImagingError::InvalidOption`] for a signal of another bracket,
/// [`ImagingError::BracketOutOfOrder`].
pub fn check_bracket_order_with_signal<T>(
    frames: &[ImageBuf<T>],
    times_s: &[f64],
    max: T,
    signal: &BracketSignal,
) -> Result<()>
where
    T: Copy + PartialOrd + PartialEq + Default + Sync + Into<f64>,
    [T]: PartialEq,
{
    check_bracket(frames, times_s)?;
    if signal.floor.len() != frames.len() || signal.has_signal.len() != frames.len() {
        return Err(ImagingError::InvalidOption {
            name: "signal",
            value: signal.floor.len() as f64,
            reason: "the bracket signal must be measured on the same frames (one floor per frame)",
        });
    }
    let mut order: Vec<usize> = (0..frames.len()).collect();
    order.sort_by(|&a, &b| times_s[a].total_cmp(&times_s[b]));
    let zero = T::default();
    // One frame listed twice: identical value for value (any two frames adjacent in time).
    for pair in order.windows(2) {
        let (s, l) = (pair[0], pair[1]);
        let (a, b) = (frames[s].data(), frames[l].data());
        if a == b && a.iter().any(|&v| v != zero && v != max) {
            return Err(out_of_order(
                "the two frames are identical (one frame listed twice?)",
                (s, l),
                times_s,
                (0, 0, 0),
            ));
        }
    }
    let ch = frames[0].channels();
    let n_px = frames[0].width() * frames[0].height();
    let step = subsample(n_px);
    let with_signal: Vec<usize> = order
        .iter()
        .copied()
        .filter(|&j| signal.has_signal[j])
        .collect();
    // Each pair's evidence (in parallel), then judged in order of time.
    let per_pair: Vec<(usize, usize, usize, f64, f64)> = with_signal
        .par_windows(2)
        .map(|pair| {
            let (s, l) = (pair[0], pair[1]);
            let (a, b) = (frames[s].data(), frames[l].data());
            let (fa, fb) = (&signal.floor[s], &signal.floor[l]);
            let (mut darker, mut brighter, mut evidence) = (0usize, 0usize, 0usize);
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for i in (0..n_px).step_by(step) {
                for c in 0..ch {
                    let k = i * ch + c;
                    let (x, y) = (a[k], b[k]);
                    let (xf, yf): (f64, f64) = (x.into(), y.into());
                    if xf <= fa[c] || yf <= fb[c] || x >= max || y >= max {
                        continue;
                    }
                    evidence += 1;
                    let d = yf - xf;
                    sum += d;
                    sum2 += d * d;
                    if d < 0.0 {
                        darker += 1;
                    } else if d > 0.0 {
                        brighter += 1;
                    }
                }
            }
            (darker, brighter, evidence, sum, sum2)
        })
        .collect();
    for (pair, &(darker, brighter, evidence, sum, sum2)) in with_signal.windows(2).zip(&per_pair) {
        let (s, l) = (pair[0], pair[1]);
        if evidence < MIN_ORDER_EVIDENCE {
            continue;
        }
        // z: the summed change in units of its noise (noise moves each value either way).
        let z = if sum2 > 0.0 { sum / sum2.sqrt() } else { 0.0 };
        if z < -3.0 {
            return Err(out_of_order(
                "the longer exposure is darker",
                (s, l),
                times_s,
                (darker + brighter, darker, brighter),
            ));
        }
    }
    Ok(())
}

fn out_of_order(
    what: &'static str,
    (shorter, longer): (usize, usize),
    times_s: &[f64],
    (compared, darker, brighter): (usize, usize, usize),
) -> ImagingError {
    ImagingError::BracketOutOfOrder {
        what,
        shorter,
        longer,
        t_shorter: times_s[shorter],
        t_longer: times_s[longer],
        compared,
        darker,
        brighter,
    }
}
