//! A merged bracket as `scatterfit merge` reports it: the radiance map's range and dynamic range,
//! what was clipped in every exposure, the frames and the response ([`MergeSummary`]), in JSON and
//! as text; and shutter times as people write them ([`shutter`]).
//!
//! The merge itself is [`crate::hdr`]'s; this module only looks at its outcome.

use std::path::PathBuf;

use serde::Serialize;

use crate::hdr::{FrameInfo, HdrStage};

/// The weighting's name as `--weighting` spells it, or one per channel (comma-separated) when the
/// channels were merged differently; `None` when the merge had none (linear frames).
fn weighting_name(weights: &[scatterfit_imaging::Weighting]) -> Option<String> {
    let name = |w: &scatterfit_imaging::Weighting| match w {
        scatterfit_imaging::Weighting::DebevecHat => "debevec-hat",
        _ => "noise-optimal",
    };
    let first = weights.first()?;
    Some(if weights.iter().all(|w| w == first) {
        name(first).to_string()
    } else {
        weights.iter().map(name).collect::<Vec<_>>().join(", ")
    })
}

/// What a merge gave, as `scatterfit merge` prints it (`--json` serialises it as is).
#[derive(Debug, Clone, Serialize)]
pub struct MergeSummary {
    /// The frames, shortest exposure first.
    pub frames: Vec<FrameInfo>,
    /// Image size and kind, e.g. `6000×4000 RGB 8-bit`.
    pub image: String,
    /// Width \[px\].
    pub width: usize,
    /// Height \[px\].
    pub height: usize,
    /// `recovered`, `given` (file) or `linear` (16-bit).
    pub response: String,
    /// RMS residual of the response fit per channel (recovered responses only).
    pub response_rms_residual: Vec<f64>,
    /// Smallest positive finite radiance of the pixels not clipped everywhere (relative units);
    /// NaN when there is none.
    pub radiance_min: f64,
    /// Largest finite radiance of those pixels; NaN when there is none.
    pub radiance_max: f64,
    /// Dynamic range radiance_max / radiance_min, in stops (log2); NaN without a range.
    pub dynamic_range_stops: f64,
    /// Pixel-channels clipped in every exposure (flagged, stored per the clipped fill).
    pub clipped_everywhere_samples: usize,
    /// Pixels with at least one channel clipped in every exposure.
    pub clipped_everywhere_pixels: usize,
    /// The radiance map written.
    pub output: PathBuf,
    /// The response CSV written (none for a linear 16-bit merge, or a given response not saved).
    pub response_out: Option<PathBuf>,
    /// Wall time for reading the frames \[s\].
    pub read_s: f64,
    /// Wall time for response recovery and merge \[s\].
    pub merge_s: f64,
    /// 8-bit merges: the sample weighting used (`noise-optimal` or `debevec-hat`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weighting: Option<String>,
    /// 8-bit merges: the RMS difference in code values between every well-exposed code (10 < z <
    /// 245) of every frame and the code the merged radiance and the response predict at the
    /// frame's stated time ([`scatterfit_imaging::self_consistency`]); per channel after it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub self_consistency: Option<f64>,
    /// Per frame (shortest first), the factor on its stated time the merge used when times
    /// estimated from the frames were applied (empty when the stated times were used).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub time_corrections: Vec<f64>,
    /// When times estimated from the frames were judged (8-bit frames): the decimated bracket's
    /// self-consistency merged at the stated times and at the corrected ones, each at its own
    /// times \[code values\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exposure_judged: Option<[f64; 2]>,
    /// When the recovered response was refitted to the merged map: the self-consistency of the
    /// decimated frames' merge before and after \[code values\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub response_refit: Option<[f64; 2]>,
    /// The same per channel.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub self_consistency_per_channel: Vec<f64>,
    /// Per frame merged (shortest first), the exposure the map implies over the stated one.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub implied_time_factor: Vec<f64>,
    /// Frames left out of the merge because they carry no signal (all at the noise floor or
    /// clipped).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub frames_without_signal: Vec<PathBuf>,
}

impl MergeSummary {
    /// The summary of `stage`, written to `output` (and its response to `response_out`).
    pub fn new(stage: &HdrStage, output: PathBuf, response_out: Option<PathBuf>) -> Self {
        let hdr = &stage.hdr;
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for (&v, &m) in hdr.radiance.data().iter().zip(hdr.clipped.data()) {
            let v = f64::from(v);
            if m == 0 && v.is_finite() && v > 0.0 {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        let clipped_pixels = hdr
            .clipped
            .data()
            .chunks_exact(hdr.clipped.channels())
            .filter(|p| p.iter().any(|&m| m != 0))
            .count();
        let range = lo.is_finite() && hi > 0.0;
        Self {
            frames: stage.frames.clone(),
            image: stage.image.clone(),
            width: hdr.radiance.width(),
            height: hdr.radiance.height(),
            response: stage.response_kind.to_string(),
            response_rms_residual: stage.rms.clone(),
            radiance_min: if lo.is_finite() { lo } else { f64::NAN },
            radiance_max: if hi > 0.0 { hi } else { f64::NAN },
            dynamic_range_stops: if range { (hi / lo).log2() } else { f64::NAN },
            clipped_everywhere_samples: hdr.clipped_count,
            clipped_everywhere_pixels: clipped_pixels,
            output,
            response_out,
            read_s: stage.read_s,
            merge_s: stage.merge_s,
            weighting: weighting_name(&stage.corrections.weighting),
            self_consistency: stage.corrections.self_consistency.as_ref().map(|c| c.rms),
            response_refit: stage.corrections.response_refit,
            time_corrections: match (
                &stage.corrections.exposure,
                stage.corrections.exposure_applied,
            ) {
                (Some(e), true) => e.factor.clone(),
                _ => Vec::new(),
            },
            exposure_judged: stage.corrections.exposure_judged,
            self_consistency_per_channel: stage
                .corrections
                .self_consistency
                .as_ref()
                .map_or_else(Vec::new, |c| c.per_channel.clone()),
            implied_time_factor: stage
                .corrections
                .self_consistency
                .as_ref()
                .map_or_else(Vec::new, |c| c.implied_time_factor.clone()),
            frames_without_signal: stage
                .corrections
                .no_signal
                .iter()
                .filter_map(|&j| stage.frames.get(j).map(|f| f.file.clone()))
                .collect(),
        }
    }

    /// The summary as `scatterfit merge` prints it: frames and times, response, radiance range,
    /// clipping, the files written; one line each, ending in a newline.
    pub fn text(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let t_min = self.frames.first().map_or(f64::NAN, |f| f.time_s);
        let t_max = self.frames.last().map_or(f64::NAN, |f| f.time_s);
        let (n, image, read_s) = (self.frames.len(), &self.image, self.read_s);
        let _ = writeln!(s, "frames        {n} × {image} ({read_s:.3} s read)");
        let _ = writeln!(
            s,
            "times         {} s … {} s",
            shutter(t_min),
            shutter(t_max)
        );
        for f in &self.frames {
            let _ = writeln!(s, "  {:>10} s  {}", shutter(f.time_s), f.file.display());
        }
        if !self.time_corrections.is_empty() {
            let lo = self
                .time_corrections
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min);
            let hi = self.time_corrections.iter().copied().fold(0.0f64, f64::max);
            let why = self
                .exposure_judged
                .map_or(String::new(), |[stated, corrected]| {
                    format!(
                        "; they explain the frames better: {corrected:.2} code values RMS against \
                     {stated:.2} at the stated times"
                    )
                });
            let _ = writeln!(
                s,
                "              merged at times estimated from the frames (×{lo:.3} … ×{hi:.3} the \
                 stated){why}"
            );
        } else if let Some([stated, corrected]) = self.exposure_judged {
            let _ = writeln!(
                s,
                "              merged at the stated times: the times estimated from the frames \
                 explain them no better ({corrected:.2} code values RMS against {stated:.2})"
            );
        }
        let rms = if self.response_rms_residual.is_empty() {
            String::new()
        } else {
            let v: Vec<String> = self
                .response_rms_residual
                .iter()
                .map(|r| format!("{r:.3}"))
                .collect();
            format!(" (weighted RMS residual {})", v.join(", "))
        };
        let _ = writeln!(s, "response      {}{rms}", self.response);
        if let Some([before, after]) = self.response_refit {
            let _ = writeln!(
                s,
                "              refitted to the merged map: every pixel's codes against its log \
                 exposure (self-consistency {before:.2} → {after:.2} code values on the frames \
                 decimated)"
            );
        }
        for f in &self.frames_without_signal {
            let _ = writeln!(
                s,
                "note          {} carries no signal (all at its noise floor or clipped): left out \
                 of the merge",
                f.display()
            );
        }
        let _ = writeln!(s, "merge         {:.3} s", self.merge_s);
        if let (Some(w), Some(rms)) = (&self.weighting, self.self_consistency) {
            let per: Vec<String> = self
                .self_consistency_per_channel
                .iter()
                .map(|r| format!("{r:.2}"))
                .collect();
            let _ = writeln!(
                s,
                "consistency   {rms:.2} code values RMS ({}) between the frames' well-exposed codes \
                 and what the map and response predict at the stated times; weighting {w}",
                per.join(", ")
            );
        }
        let _ = writeln!(
            s,
            "radiance      {:.4e} … {:.4e} (relative), dynamic range {:.1} stops ({:.1} decades)",
            self.radiance_min,
            self.radiance_max,
            self.dynamic_range_stops,
            self.dynamic_range_stops * std::f64::consts::LOG10_2
        );
        let _ = writeln!(
            s,
            "clipped       {} pixels ({} pixel-channels) clipped in every exposure{}",
            self.clipped_everywhere_pixels,
            self.clipped_everywhere_samples,
            if self.clipped_everywhere_samples > 0 {
                " — flagged, not estimated"
            } else {
                ""
            }
        );
        let _ = writeln!(s, "wrote         {}", self.output.display());
        if let Some(r) = &self.response_out {
            let _ = writeln!(s, "wrote         {}", r.display());
        }
        s
    }
}

/// A shutter time \[s\] as people write it: `1/600` for short times that are whole fractions, else
/// 4 significant digits (`0.2500`, `3.000`), scientific notation beyond 1 ms … 10⁴ s.
pub fn shutter(t: f64) -> String {
    if t < 0.5 && t > 0.0 {
        let inv = 1.0 / t;
        if (inv - inv.round()).abs() < 1e-6 * inv {
            return format!("1/{}", inv.round());
        }
    }
    if (1e-3..1e4).contains(&t) {
        let decimals = (3 - t.log10().floor() as i32).max(0) as usize;
        format!("{t:.decimals$}")
    } else {
        format!("{t:.3e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ResponseKind;
    use crate::hdr::Corrections;
    use scatterfit_imaging::{HdrImage, ImageBuf};

    /// A 2 × 2 RGB map with radiances 0.5 … 8 and one pixel-channel clipped at 1000: the range is
    /// that of the unclipped values (4 stops, 16 × 0.5 = 8), one pixel holds a clipped channel.
    #[test]
    fn range_and_clipping_leave_out_clipped_pixels() {
        let radiance = vec![
            0.5f32, 1.0, 2.0, 4.0, 8.0, 1000.0, 1.0, 1.0, 1.0, 0.0, 1.0, 1.0,
        ];
        let mut mask = vec![0u8; 12];
        mask[5] = 1;
        let stage = HdrStage {
            hdr: HdrImage {
                radiance: ImageBuf::new(2, 2, 3, radiance).unwrap(),
                clipped: ImageBuf::new(2, 2, 3, mask).unwrap(),
                clipped_count: 1,
            },
            response: None,
            response_kind: ResponseKind::Linear,
            rms: Vec::new(),
            frames: Vec::new(),
            radiance_file: None,
            image: "2×2 RGB 16-bit".into(),
            detection_limit: Vec::new(),
            dropped_alpha: Vec::new(),
            read_s: 0.0,
            merge_s: 0.0,
            corrections: Corrections::default(),
            thumbnails: Vec::new(),
        };
        let s = MergeSummary::new(&stage, "m.exr".into(), None);
        assert_eq!((s.radiance_min, s.radiance_max), (0.5, 8.0));
        assert_eq!(s.dynamic_range_stops, 4.0);
        assert_eq!(
            (s.clipped_everywhere_pixels, s.clipped_everywhere_samples),
            (1, 1)
        );
        assert_eq!((s.width, s.height, s.response.as_str()), (2, 2, "linear"));
        assert!(s.text().contains("4.0 stops (1.2 decades)"), "{}", s.text());
    }

    /// Camera shutter speeds read as the camera shows them; other times keep 4 significant digits.
    #[test]
    fn shutter_times_read_as_cameras_write_them() {
        assert_eq!(shutter(1.0 / 600.0), "1/600");
        assert_eq!(shutter(0.25), "1/4");
        assert_eq!(shutter(0.3), "0.3000");
        assert_eq!(shutter(3.0), "3.000");
        assert_eq!(shutter(12.5), "12.50");
        assert_eq!(shutter(1e-5), "1/100000");
        assert_eq!(shutter(2e4), "2.000e4");
    }
}
