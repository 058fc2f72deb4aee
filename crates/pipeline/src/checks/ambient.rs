//! Light that is not the spot's: the far field of each frame against the next longer frame's.
//!
//! The spot lights the sample; far from it (the frame's corners) a dark room leaves a profile that
//! has fallen by orders of magnitude, read at the camera's floor by the short frames and a few codes
//! by the longest. Room light switched on during the bracket reaches only the frames taken after it,
//! and only those frames see the far field, so the merge follows them there and every well-exposed
//! part of every frame still agrees with it ([`super::frame_agreement`] compares codes 40–230
//! only). Between two frames of a static scene, Debevec & Malik's relation (1997, eq. 2:
//! g(Z_ij) = ln E_i + ln Δt_j) holds with the same E_i, so the longer frame's codes predict the
//! shorter one's: g(Z_ij) = g(Z_i,j+1) + ln(Δt_j / Δt_{j+1}). Where the light came on between
//! them, the longer frame's far corners predict tens of codes where the shorter one reads the
//! floor. A static scene cannot do that. Light in every frame (a constant glow) keeps the relation
//! and is not found here: it looks like veiling glare, which the profile stage subtracts
//! (RELIABILITY.md, "The evidence behind ok").

use super::frames::short;
use super::*;

/// A frame's far-field samples: those at least this fraction of the way from the spot to the
/// frame's farthest corner (the corners; on a square frame with the spot at its centre, the part
/// beyond 1.06 × the inscribed circle).
pub const FAR_FIELD_FRACTION: f64 = 0.75;

/// Far-field samples a frame needs for its comparison to be judged.
pub const FAR_FIELD_MIN_SAMPLES: usize = 30;

/// A frame's far field may read this many 8-bit codes from what the next longer frame predicts
/// (in the median over its far samples), besides five standard errors of that median. The toe of
/// the response is least certain, one code there a large step in log exposure, and a JPEG's 8 × 8
/// blocks move it by a code or two: the good quick twin agrees within 0.24 codes, its JPEG q85 and
/// q95 brackets (and those of brown leather, nephrite, wood tile) within 1; no frame of the camera
/// sweep's brackets (five tone curves, 3 and 15 e⁻ read noise) or of the real brackets
/// (`real_brackets`) disagrees ([`FarField::disagrees`], asserted there). Room light switched on
/// for the last three frames of the quick twin leaves the frame before them 14 codes below the
/// prediction at 200 e⁻/s and 29 at 2000 e⁻/s (10–14× less light); from the sixth-last frame at
/// 2000 e⁻/s, B 6.8 codes at the floor (R 9.4 codes, but only 1.6× less light).
pub const MAX_FAR_FIELD_CODES: f64 = 6.0;

/// A frame whose far field reads darker than the next longer frame predicts must hold less than
/// 1/this of the predicted light to disagree: between two frames of a real scene a recovered
/// response's error reaches 15 % in exposure, 8–11 codes at mid codes (`real_brackets`:
/// piccante_room 55 against 68, ln ratio 0.14; scene2 176 against 181, 0.04), while a frame taken
/// before room light came on reads its far field at the floor (the quick twin's: code 1 against
/// 14 predicted at 200 e⁻/s).
pub const MIN_FAR_FIELD_RATIO: f64 = 2.0;

/// A linear bracket's frame whose far-corner mean lies more than this many of its standard errors
/// off the straight line in exposure time that the other frames' corners follow
/// ([`crate::camera::CornerDeparture`]) …
pub const MAX_CORNER_Z: f64 = 8.0;

/// … and by more than this fraction of the line's time-proportional part there, is light that
/// changed during the bracket. The fraction is beyond any shutter's error the bracket check lets
/// through (an exposure time off by f leaves f of that part); the standard errors are the corner
/// means' own, from thousands of pixels. Measured on quick twins of the `linear16` camera
/// (pink plastic, and dipole profiles with and without glare 3·10⁻⁴): clean brackets stay within
/// 3 standard errors, light on in every frame within 4 (a straight line: it reads as glare); room
/// light switched on for the last three frames reads 97–4600 standard errors and 0.8–41× the
/// time-proportional part at 200–2000 DN/s, and 7–48 standard errors and 0.1–1.4× at 20 DN/s (a
/// fiftieth of the black level's read noise per second; not always caught).
pub const MIN_CORNER_RELATIVE: f64 = 0.3;

/// One frame's far field against the next longer frame's ([`far_field_agreement`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FarField {
    /// The shorter frame's index (shortest first); the longer one is the next.
    pub frame: usize,
    /// The channel.
    pub channel: usize,
    /// Far-field samples compared.
    pub samples: usize,
    /// The median code the frame reads there.
    pub observed: f64,
    /// The median code the next longer frame predicts there (g⁻¹ of its log exposure at this
    /// frame's time, interpolated).
    pub predicted: f64,
    /// The median of observed − predicted per sample \[codes\].
    pub difference: f64,
    /// Its standard error (1.2533 × 1.4826 × the median absolute deviation / √samples).
    pub stderr: f64,
    /// ln of the exposure the predicted median code stands for over the observed one's, through
    /// the response (g interpolated between codes): how many times more light the longer frame
    /// says this one should have held.
    pub ln_ratio: f64,
}

impl FarField {
    /// True when the frame's far field reads darker than the next one's predicts, by more than
    /// [`MAX_FAR_FIELD_CODES`] and five standard errors, and by more than
    /// [`MIN_FAR_FIELD_RATIO`] in exposure: light the longer frames saw and this one did not.
    /// Only that direction: the far field of the profile comes from the longer frames, so light
    /// they saw enters its tail, while light only the shorter frames saw (switched off during the
    /// bracket) adds to the short frames' far field, which the merge barely uses.
    pub fn disagrees(&self) -> bool {
        -self.difference > MAX_FAR_FIELD_CODES.max(5.0 * self.stderr)
            && self.ln_ratio > MIN_FAR_FIELD_RATIO.ln()
    }
}

/// The response's log exposure at a fractional code (g interpolated between codes).
fn log_exposure(g: &[f64], z: f64) -> f64 {
    let last = g.len() - 1;
    let z = z.clamp(0.0, last as f64);
    let lo = (z.floor() as usize).min(last - 1);
    g[lo] + (z - lo as f64) * (g[lo + 1] - g[lo])
}

/// The code a response predicts for log exposure `ln_x`: g⁻¹ interpolated between codes, 0 below
/// g(0) and 255 above g(255).
fn predicted_code(g: &[f64], ln_x: f64) -> f64 {
    let last = g.len() - 1;
    if ln_x.is_nan() || ln_x <= g[0] {
        return 0.0;
    }
    if ln_x >= g[last] {
        return last as f64;
    }
    // The first code whose g exceeds ln_x (g increases).
    let hi = g.partition_point(|&v| v <= ln_x).clamp(1, last);
    let (a, b) = (g[hi - 1], g[hi]);
    (hi - 1) as f64 + if b > a { (ln_x - a) / (b - a) } else { 0.0 }
}

/// Per pair of consecutive frames and channel, the far field's codes in the shorter frame against
/// those the longer frame's codes predict at the shorter time (ln X = g(z) + ln(Δt_j / Δt_{j+1}),
/// through the bracket's response), on the frames' thumbnails (as [`super::frame_agreement`]).
/// Frame against frame, not against the merge: in the far field the merge follows whichever
/// frames it weighs most, and a JPEG's block errors at the toe move it by a few codes. A flat
/// frame divides both frames alike and does not enter; a dark frame (an offset not proportional
/// to the time) would, so with one given the comparison is not made. Only 8-bit brackets with
/// their response; `None` otherwise.
pub fn far_field_agreement(m: &Measurement) -> Option<Vec<FarField>> {
    if m.manifest.camera.dark.is_some() {
        return None;
    }
    far_field_agreement_in(&m.hdr, m.profile.center.xy())
}

/// [`far_field_agreement`] of a merged bracket with its spot centred at `center` \[px\] (no dark
/// frame).
pub fn far_field_agreement_in(
    hdr: &crate::hdr::HdrStage,
    center: [f64; 2],
) -> Option<Vec<FarField>> {
    let response = hdr.response.as_ref()?;
    if hdr.thumbnails.len() != hdr.frames.len() {
        return None;
    }
    let radiance = &hdr.hdr.radiance;
    let (w, h) = (radiance.width(), radiance.height());
    let step = w.max(h).div_ceil(crate::hdr::THUMBNAIL_SIDE).max(1);
    let ch = radiance.channels().min(3);
    let tables = response.tables();
    let [cx, cy] = center;
    let farthest = [
        (0.0, 0.0),
        (w as f64, 0.0),
        (0.0, h as f64),
        (w as f64, h as f64),
    ]
    .iter()
    .map(|&(x, y)| (x - cx).hypot(y - cy))
    .fold(0.0f64, f64::max);
    let r_far = FAR_FIELD_FRACTION * farthest;
    let factors = hdr
        .corrections
        .exposure
        .as_ref()
        .filter(|_| hdr.corrections.exposure_applied)
        .map(|e| e.factor.clone());
    let time = |j: usize| {
        hdr.frames[j].time_s
            * factors
                .as_ref()
                .and_then(|f| f.get(j))
                .copied()
                .unwrap_or(1.0)
    };
    let median = |v: &mut Vec<f64>| -> f64 {
        let mid = v.len() / 2;
        *v.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    let thumbs = &hdr.thumbnails;
    let mut out = Vec::new();
    for j in 0..thumbs.len().saturating_sub(1) {
        let (short, long) = (&thumbs[j], &thumbs[j + 1]);
        let ratio = time(j) / time(j + 1);
        if !(ratio.is_finite() && ratio > 0.0)
            || (short.width(), short.height()) != (long.width(), long.height())
        {
            continue;
        }
        for c in 0..ch {
            let g = &tables[c.min(tables.len() - 1)];
            let (mut obs, mut pred, mut diff) = (Vec::new(), Vec::new(), Vec::new());
            for ty in 0..short.height() {
                let y = (ty * step + step / 2).min(h - 1);
                for tx in 0..short.width() {
                    let x = (tx * step + step / 2).min(w - 1);
                    if (x as f64 - cx).hypot(y as f64 - cy) < r_far {
                        continue;
                    }
                    let (Some(zs), Some(zl)) = (short.pixel(tx, ty), long.pixel(tx, ty)) else {
                        continue;
                    };
                    let (zs, zl) = (zs[c.min(zs.len() - 1)], zl[c.min(zl.len() - 1)]);
                    // A clipped longer frame says only that the light is at least this much.
                    if zl == u8::MAX {
                        continue;
                    }
                    let p = predicted_code(g, g[usize::from(zl)] + ratio.ln());
                    obs.push(f64::from(zs));
                    pred.push(p);
                    diff.push(f64::from(zs) - p);
                }
            }
            let n = diff.len();
            if n < FAR_FIELD_MIN_SAMPLES {
                continue;
            }
            let difference = median(&mut diff);
            let mut dev: Vec<f64> = diff.iter().map(|d| (d - difference).abs()).collect();
            let mad = median(&mut dev);
            let (observed, predicted) = (median(&mut obs), median(&mut pred));
            out.push(FarField {
                frame: j,
                channel: c,
                samples: n,
                observed,
                predicted,
                difference,
                stderr: 1.2533 * 1.4826 * mad / (n as f64).sqrt(),
                ln_ratio: log_exposure(g, predicted) - log_exposure(g, observed),
            });
        }
    }
    Some(out)
}

/// A linear bracket whose far corners do not grow in a straight line with the exposure time
/// ([`MAX_CORNER_Z`], [`MIN_CORNER_RELATIVE`]): one reason naming the frame, for every channel.
fn linear_corner_reasons(m: &Measurement) -> Vec<Reason> {
    let Some(est) = &m.hdr.corrections.corners else {
        return Vec::new();
    };
    let worst = est
        .departure
        .iter()
        .enumerate()
        .filter_map(|(c, d)| d.map(|d| (c, d)))
        .filter(|(_, d)| d.z.abs() > MAX_CORNER_Z && d.relative.abs() > MIN_CORNER_RELATIVE)
        .max_by(|a, b| a.1.z.abs().total_cmp(&b.1.z.abs()));
    let Some((c, d)) = worst else {
        return Vec::new();
    };
    let name = m.hdr.frames.get(d.frame).map_or_else(String::new, |f| {
        f.file
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    });
    vec![suspect(
        ReasonKind::AmbientLight,
        format!(
            "the far corners of {} ({} s, {} channel) read {:.1} DN {} the straight line in \
             exposure time that the other frames' corners follow ({:.0} standard errors, {:.1}× \
             what grows with the time there): light reached the sample in some frames and not in \
             others (room light or daylight switched on or off during the bracket), which also \
             moves the black level read from the corners — switch off the room light or shade the \
             sample, and shoot the bracket again",
            scatterfit_io::escape::one_line(&name),
            short(d.time_s),
            ["R", "G", "B"].get(c).copied().unwrap_or("the"),
            d.residual_dn.abs(),
            if d.residual_dn < 0.0 {
                "below"
            } else {
                "above"
            },
            d.z.abs(),
            d.relative.abs(),
        ),
    )]
}

/// Light that is not the spot's and changed during the bracket: for 8-bit frames, frames whose
/// far field the next longer frame does not predict ([`far_field_agreement`]); for linear
/// frames, the far corners off their straight line in exposure time. One reason naming the
/// frames and the largest disagreement, for every channel.
pub fn ambient_light_reasons(m: &Measurement) -> Vec<Reason> {
    let linear = linear_corner_reasons(m);
    if !linear.is_empty() {
        return linear;
    }
    let Some(fields) = far_field_agreement(m) else {
        return Vec::new();
    };
    let bad: Vec<&FarField> = fields.iter().filter(|f| f.disagrees()).collect();
    let Some(worst) = bad
        .iter()
        .min_by(|a, b| a.difference.total_cmp(&b.difference))
    else {
        return Vec::new();
    };
    let mut frames: Vec<usize> = bad.iter().map(|f| f.frame).collect();
    frames.sort_unstable();
    frames.dedup();
    let name = |j: usize| {
        m.hdr.frames[j]
            .file
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    };
    let listed: Vec<String> = frames
        .iter()
        .map(|&j| {
            format!(
                "{} ({} s)",
                scatterfit_io::escape::one_line(&name(j)),
                short(m.hdr.frames[j].time_s)
            )
        })
        .collect();
    let direction = "darker than the next longer frames say: light reached the sample in the \
                     later frames that it did not in these (room light or daylight switched on \
                     during the bracket, a lamp or a monitor turned on)";
    vec![suspect(
        ReasonKind::AmbientLight,
        format!(
            "the far corners of frame {} ({} channel) read code {:.0} where frame {}'s read at \
             this exposure time predicts {:.0}; far corners of {} read {direction} — the merge \
             takes the far field from the frames with that light, so the profile's tail carries \
             it: switch off the room light or shade the sample, and shoot the bracket again",
            worst.frame,
            ["R", "G", "B"][worst.channel.min(2)],
            worst.observed,
            worst.frame + 1,
            worst.predicted,
            listed.join(", "),
        ),
    )]
}

#[cfg(test)]
mod tests {
    use super::{log_exposure, predicted_code};

    #[test]
    fn the_predicted_code_inverts_the_response() {
        // g(z) = ln(z + 1): a code's own exposure gives the code back, between codes the
        // interpolation, beyond the ends the ends.
        let g: Vec<f64> = (0..256).map(|z| f64::from(z + 1).ln()).collect();
        assert_eq!(predicted_code(&g, g[100]), 100.0);
        assert!((predicted_code(&g, 0.5 * (g[40] + g[41])) - 40.5).abs() < 1e-12);
        assert_eq!(predicted_code(&g, -5.0), 0.0);
        assert_eq!(predicted_code(&g, 99.0), 255.0);
        assert_eq!(predicted_code(&g, f64::NAN), 0.0);
        assert_eq!(log_exposure(&g, 100.0), g[100]);
        assert!((log_exposure(&g, 40.5) - 0.5 * (g[40] + g[41])).abs() < 1e-12);
        assert_eq!(log_exposure(&g, 300.0), g[255]);
    }
}
