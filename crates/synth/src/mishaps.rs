//! A careless session at the rig, made from a good twin's bracket: the spot near the frame's edge
//! or half outside it, a second spot (a reflection off the rig, a second light), the camera bumped
//! in the middle of the bracket, room light, hot pixels, linear data of fewer bits stored in 16-bit files. Each function
//! takes the frames of a [`crate::Bracket`] (the twin's 8-bit output) and returns what the rig would
//! have recorded had that gone wrong, so that a test can build the bad case from a good twin and
//! check that the tool notices (RELIABILITY.md, "Numbers that look right and are not").
//!
//! Everything here is exact pixel bookkeeping — crops and shifts move whole pixels — except where
//! light must be added or re-quantised: there the twin's own camera ([`CameraModel`]) is inverted
//! (its tone curve is known to the twin, never to the tool) and applied again.

use scatterfit_imaging::ImageBuf;

use crate::rig::CameraModel;

/// The window `[x0, x0 + w) × [y0, y0 + h)` of every frame. A spot at `c` in the frames is at
/// `c − (x0, y0)` in the result.
///
/// # Panics
/// If the window does not lie inside the frames (a test's mistake, not user input).
pub fn crop(
    frames: &[ImageBuf<u8>],
    x0: usize,
    y0: usize,
    w: usize,
    h: usize,
) -> Vec<ImageBuf<u8>> {
    frames.iter().map(|f| crop_one(f, x0, y0, w, h)).collect()
}

/// The camera bumped between frame `from - 1` and frame `from` (frames in time order): frames
/// from `from` on see the scene moved by `(dx, dy)` whole pixels (non-negative; the spot moves by
/// `−(dx, dy)` in them). All frames are cropped to the window both positions share, so the result
/// is `(w − dx) × (h − dy)`.
///
/// # Panics
/// If the shift is not smaller than the frames.
pub fn bump(frames: &[ImageBuf<u8>], from: usize, dx: usize, dy: usize) -> Vec<ImageBuf<u8>> {
    let (w, h) = (frames[0].width(), frames[0].height());
    frames
        .iter()
        .enumerate()
        .map(|(j, f)| {
            let (x0, y0) = if j >= from { (dx, dy) } else { (0, 0) };
            crop_one(f, x0, y0, w - dx, h - dy)
        })
        .collect()
}

/// A second spot: the scene's light shifted by `(dx, dy)` pixels (any sign, whole pixels) and
/// scaled by `strength`, added to every frame in the sensor's linear domain (electrons, through
/// the inverse of `camera`'s tone curve), then toned and quantised again. Where the shifted copy
/// falls outside the frame nothing is added.
pub fn second_spot(
    frames: &[ImageBuf<u8>],
    camera: &CameraModel,
    dx: isize,
    dy: isize,
    strength: f64,
) -> Vec<ImageBuf<u8>> {
    frames
        .iter()
        .map(|f| {
            let (w, h, ch) = (f.width(), f.height(), f.channels());
            let src = f.data();
            let mut out = src.to_vec();
            for y in 0..h {
                for x in 0..w {
                    let (sx, sy) = (x as isize - dx, y as isize - dy);
                    if sx < 0 || sy < 0 || sx >= w as isize || sy >= h as isize {
                        continue;
                    }
                    let (sx, sy) = (sx as usize, sy as usize);
                    for c in 0..ch {
                        let i = (y * w + x) * ch + c;
                        let j = (sy * w + sx) * ch + c;
                        let e = electrons(camera, src[i]) + strength * electrons(camera, src[j]);
                        out[i] = camera.code(e);
                    }
                }
            }
            ImageBuf::new(w, h, ch, out).expect("same shape")
        })
        .collect()
}

/// How linear data of fewer bits sit in a 16-bit file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Alignment {
    /// Values 0 … 2^bits − 1 (most 12- and 14-bit cameras' TIFFs and PNGs).
    Low,
    /// Values shifted to the top bits, 0 … (2^bits − 1)·2^(16 − bits).
    High,
}

/// The frames as a linear camera of `bits` bits would have recorded them: each 8-bit code turned
/// back into electrons through the twin's camera, scaled so that the full well is the top code
/// 2^bits − 1, rounded and clipped there, and stored in 16-bit words as `align` says.
/// A pixel clipped at 255 in the 8-bit frame is clipped at the top code here too.
///
/// # Panics
/// For `bits` outside 8..=16.
pub fn linear_u16(
    frames: &[ImageBuf<u8>],
    camera: &CameraModel,
    bits: u32,
    align: Alignment,
) -> Vec<ImageBuf<u16>> {
    assert!((8..=16).contains(&bits), "bits in 8..=16");
    let top = f64::from((1u32 << bits) - 1);
    let shift = match align {
        Alignment::Low => 0,
        Alignment::High => 16 - bits,
    };
    frames
        .iter()
        .map(|f| {
            let data = f
                .data()
                .iter()
                .map(|&z| {
                    let dn = if z == 255 {
                        top
                    } else {
                        (electrons(camera, z) / camera.full_well_e * top)
                            .round()
                            .clamp(0.0, top)
                    };
                    (dn as u16) << shift
                })
                .collect();
            ImageBuf::new(f.width(), f.height(), f.channels(), data).expect("same shape")
        })
        .collect()
}

/// 8-bit frames stored in 16-bit files by scaling (z · 257: 255 → 65535), as an image editor
/// converting a processed picture does.
pub fn scaled_to_u16(frames: &[ImageBuf<u8>]) -> Vec<ImageBuf<u16>> {
    frames
        .iter()
        .map(|f| {
            let data = f.data().iter().map(|&z| u16::from(z) * 257).collect();
            ImageBuf::new(f.width(), f.height(), f.channels(), data).expect("same shape")
        })
        .collect()
}

/// The camera's gain changed before frame `from` (frames in time order): from there on every
/// pixel's electrons are multiplied by `factor` (an ISO step, a gain set to auto), toned and
/// quantised again through `camera`.
pub fn gain(
    frames: &[ImageBuf<u8>],
    camera: &CameraModel,
    from: usize,
    factor: f64,
) -> Vec<ImageBuf<u8>> {
    relight(frames, camera, from, |e| e * factor)
}

/// Room light switched on before frame `from`: every pixel of the frames from there on gains
/// `electrons_per_s` × the frame's exposure time `times_s[j]` (a uniform glow over the sample, as
/// a lamp adds it), toned and quantised again through `camera`.
pub fn room_light(
    frames: &[ImageBuf<u8>],
    camera: &CameraModel,
    times_s: &[f64],
    from: usize,
    electrons_per_s: f64,
) -> Vec<ImageBuf<u8>> {
    let mut out = frames[..from.min(frames.len())].to_vec();
    for (j, f) in frames.iter().enumerate().skip(from) {
        let add = electrons_per_s * times_s[j];
        out.extend(relight(std::slice::from_ref(f), camera, 0, |e| e + add));
    }
    out
}

/// Room light switched on before frame `from` of a linear 16-bit bracket: every value of the frames
/// from there on gains `dn_per_s` × the frame's exposure time `times_s[j]` (a uniform glow, in the
/// camera's numbers), rounded and clipped at 65535. The glow's own shot noise is left out: the
/// change in the frames' means is what a check sees.
pub fn room_light_linear(
    frames: &[ImageBuf<u16>],
    times_s: &[f64],
    from: usize,
    dn_per_s: f64,
) -> Vec<ImageBuf<u16>> {
    frames
        .iter()
        .enumerate()
        .map(|(j, f)| {
            let mut f = f.clone();
            if j >= from {
                let add = dn_per_s * times_s[j];
                for v in f.data_mut() {
                    *v = (f64::from(*v) + add).round().clamp(0.0, 65535.0) as u16;
                }
            }
            f
        })
        .collect()
}

/// Hot pixels: each pixel of `pixels` (x, y) gains `electrons_per_s` × the frame's exposure time
/// `times_s[j]` in every channel of every frame (a sensor's dark current at a defect grows with the
/// exposure, as a lamp's glow does), toned and quantised again through `camera`. Isolated pixels
/// far from the spot lift the ring means they fall in, the more the fewer pixels the ring holds.
pub fn hot_pixels(
    frames: &[ImageBuf<u8>],
    camera: &CameraModel,
    times_s: &[f64],
    pixels: &[(usize, usize)],
    electrons_per_s: f64,
) -> Vec<ImageBuf<u8>> {
    frames
        .iter()
        .zip(times_s)
        .map(|(f, &t)| {
            let (w, ch) = (f.width(), f.channels());
            let mut data = f.data().to_vec();
            for &(x, y) in pixels {
                if x >= w || y >= f.height() {
                    continue;
                }
                for z in &mut data[(y * w + x) * ch..(y * w + x + 1) * ch] {
                    if *z != u8::MAX {
                        *z = camera.code(electrons(camera, *z) + electrons_per_s * t);
                    }
                }
            }
            ImageBuf::new(w, f.height(), ch, data).expect("same shape")
        })
        .collect()
}

fn relight(
    frames: &[ImageBuf<u8>],
    camera: &CameraModel,
    from: usize,
    change: impl Fn(f64) -> f64,
) -> Vec<ImageBuf<u8>> {
    frames
        .iter()
        .enumerate()
        .map(|(j, f)| {
            if j < from {
                return f.clone();
            }
            // Clipped codes stay clipped: the light behind them is unknown (and only grows).
            let data = f
                .data()
                .iter()
                .map(|&z| {
                    if z == u8::MAX {
                        z
                    } else {
                        camera.code(change(electrons(camera, z)))
                    }
                })
                .collect();
            ImageBuf::new(f.width(), f.height(), f.channels(), data).expect("same shape")
        })
        .collect()
}

/// Electrons behind an 8-bit code: the inverse of the camera's tone curve
/// T(s) = (1 + b)s/(s + b), s = bT/(1 + b − T), at T = z/255, times the full well.
pub fn electrons(camera: &CameraModel, z: u8) -> f64 {
    let t = f64::from(z) / 255.0;
    let b = camera.tone_knee;
    b * t / (1.0 + b - t) * camera.full_well_e
}

fn crop_one(f: &ImageBuf<u8>, x0: usize, y0: usize, w: usize, h: usize) -> ImageBuf<u8> {
    assert!(
        x0 + w <= f.width() && y0 + h <= f.height() && w > 0 && h > 0,
        "the window lies inside the frame"
    );
    let ch = f.channels();
    let mut data = Vec::with_capacity(w * h * ch);
    for y in y0..y0 + h {
        let row = f.row(y).expect("inside");
        data.extend_from_slice(&row[x0 * ch..(x0 + w) * ch]);
    }
    ImageBuf::new(w, h, ch, data).expect("w × h × channels")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(w: usize, h: usize) -> ImageBuf<u8> {
        let data = (0..w * h * 3).map(|i| (i % 251) as u8).collect();
        ImageBuf::new(w, h, 3, data).unwrap()
    }

    #[test]
    fn crops_and_bumps_move_whole_pixels() {
        let f = ramp(10, 8);
        let c = crop(std::slice::from_ref(&f), 2, 3, 5, 4);
        assert_eq!(c[0].pixel(0, 0), f.pixel(2, 3));
        assert_eq!(c[0].pixel(4, 3), f.pixel(6, 6));
        let b = bump(&[f.clone(), f.clone()], 1, 2, 1);
        assert_eq!((b[0].width(), b[0].height()), (8, 7));
        assert_eq!(b[0].pixel(3, 3), f.pixel(3, 3));
        assert_eq!(b[1].pixel(3, 3), f.pixel(5, 4));
    }

    #[test]
    fn the_tone_curve_inverts_to_within_a_code() {
        let cam = CameraModel::default();
        for z in 0..=255u8 {
            assert_eq!(cam.code(electrons(&cam, z)), z);
        }
        // No second spot of zero strength changes nothing.
        let f = ramp(6, 5);
        assert_eq!(
            second_spot(std::slice::from_ref(&f), &cam, 2, -1, 0.0)[0],
            f
        );
    }

    #[test]
    fn linear_frames_clip_at_their_top_code() {
        let cam = CameraModel::default();
        let f = ImageBuf::new(2, 1, 3, vec![0, 1, 128, 254, 255, 255]).unwrap();
        let low = linear_u16(std::slice::from_ref(&f), &cam, 12, Alignment::Low);
        assert_eq!(low[0].data()[4], 4095);
        assert!(low[0].data().iter().all(|&v| v <= 4095));
        let high = linear_u16(std::slice::from_ref(&f), &cam, 12, Alignment::High);
        assert_eq!(high[0].data()[5], 4095 << 4);
        assert!(high[0].data().iter().all(|&v| v % 16 == 0));
        assert_eq!(scaled_to_u16(std::slice::from_ref(&f))[0].data()[5], 65535);
    }
}
