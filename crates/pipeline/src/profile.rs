//! Stage 3: the spot centre and the radial profile Rd(r) per channel (Choi et al. 2014, §3.2:
//! "pixels at the same distance from the focus point … averaged"), with each ring's detection
//! limit, as the fit takes them.

use std::path::PathBuf;

use scatterfit_fit::{ProfileData, Ring};
use scatterfit_imaging::{
    CLIPPED_HIGH, CenterOptions, ImageBuf, ProfileOptions, RadialProfile, SpotCenter,
    find_spot_center, radial_profile,
};
use scatterfit_io::manifest::AutoOrNone;
use scatterfit_io::profile_csv::{ProfileColumn, ProfileTable};
use scatterfit_optics::{Channel, Rgb};

pub use crate::camera::Background;
use serde::Serialize;

use crate::error::{PipelineError, Result};

/// Where the spot centre came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CenterSource {
    /// Found in the image.
    Found,
    /// Given by the user.
    Given,
}

/// The profile stage's result.
#[derive(Debug, Clone)]
pub struct ProfileStage {
    /// The spot centre.
    pub center: SpotCenter,
    /// Found or given.
    pub center_source: CenterSource,
    /// The rings.
    pub profile: RadialProfile,
    /// Detection limit per channel (NaN: unknown).
    pub detection_limit: Vec<f64>,
    /// Veiling glare per channel, estimated beyond the profile's near field (empty when not
    /// estimated); where subtracted, the rings' means are less its level and the detection limit
    /// is at least that level.
    pub background: Vec<Background>,
}

/// Options of the profile stage (and `scatterfit profile`'s flags: their help is the field's text;
/// [`ProfileSettings::check`] checks them).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct ProfileSettings {
    /// Image scale on the sample surface [mm per pixel], in (0, 100] (as the manifest's
    /// `camera.mm_per_pixel`).
    #[cfg_attr(feature = "clap", arg(long, value_name = "MM", value_parser = scatterfit_io::flags::parse_finite))]
    pub mm_per_pixel: f64,
    /// Spot centre `X,Y` in pixels (pixel centres at integers), inside the image; found
    /// automatically if omitted.
    #[cfg_attr(feature = "clap", arg(long = "center", value_name = "X,Y", value_parser = scatterfit_io::flags::parse_center))]
    pub center_px: Option<[f64; 2]>,
    /// Outer radius of the profile \[px\], in (0, 10⁶] (the paper's cut-off is 300); at most 10⁶
    /// rings (r_max / ring width).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 300.0, value_name = "PX", value_parser = scatterfit_io::flags::parse_finite))]
    pub r_max_px: f64,
    /// Ring width \[px\], > 0, with at most 10⁶ rings (r_max / ring width; 1 px gives the paper's
    /// profile).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 1.0, value_name = "PX", value_parser = scatterfit_io::flags::parse_finite))]
    pub ring_width_px: f64,
}

/// Why profile settings are refused ([`ProfileSettings::check`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ProfileSettingsError {
    /// A setting out of its range: the flag, the value, the rule.
    #[error("{0}")]
    Refused(String),
    /// The rings' memory is beyond the budget.
    #[error(transparent)]
    OverBudget(#[from] scatterfit_io::budget::OverBudget),
}

/// The largest ring radius accepted \[px\]: beyond any camera sensor's diagonal.
pub const MAX_R_PX: f64 = 1e6;

/// Memory per ring and channel of the profile and its CSV row \[bytes\] (the ring's statistics,
/// its share of the table, and the text), an upper bound.
const BYTES_PER_RING_CHANNEL: u64 = 160;

impl ProfileSettings {
    /// Checks every number before anything is read (`scatterfit profile`): the ranges, the ring
    /// count (at most [`scatterfit_imaging::MAX_RINGS`]), the `detection_limit` (each finite and
    /// ≥ 0) and the rings' memory against `memory_budget` \[bytes\].
    ///
    /// # Errors
    /// The first setting out of range, naming its flag; the memory over the budget.
    pub fn check(
        &self,
        detection_limit: Option<[f64; 3]>,
        memory_budget: u64,
    ) -> std::result::Result<(), ProfileSettingsError> {
        use scatterfit_io::escape::number as show;
        let range = |ok: bool, flag: &str, value: f64, rule: &str| {
            if ok {
                Ok(())
            } else {
                Err(ProfileSettingsError::Refused(format!(
                    "{flag} {}: {rule}",
                    show(value)
                )))
            }
        };
        range(
            self.mm_per_pixel > 0.0 && self.mm_per_pixel <= 100.0,
            "--mm-per-pixel",
            self.mm_per_pixel,
            "the image scale must lie in (0, 100] mm per pixel",
        )?;
        range(
            self.r_max_px > 0.0 && self.r_max_px <= MAX_R_PX,
            "--r-max-px",
            self.r_max_px,
            "the outer radius must lie in (0, 1e6] px (the paper's is 300)",
        )?;
        range(
            self.ring_width_px > 0.0,
            "--ring-width-px",
            self.ring_width_px,
            "the ring width must be > 0 px (1 px gives the paper's profile)",
        )?;
        let rings = (self.r_max_px / self.ring_width_px).ceil();
        range(
            rings <= scatterfit_imaging::MAX_RINGS as f64,
            "--ring-width-px",
            self.ring_width_px,
            &format!(
                "--r-max-px {} / --ring-width-px {} makes {rings:.3e} rings, more than 10⁶ — a \
                 light spot's profile needs hundreds; widen the rings or reduce r_max",
                show(self.r_max_px),
                show(self.ring_width_px)
            ),
        )?;
        if let Some(l) = detection_limit
            && let Some(bad) = l.iter().find(|v| !(v.is_finite() && **v >= 0.0))
        {
            return Err(ProfileSettingsError::Refused(format!(
                "--detection-limit: {} is not a radiance ≥ 0 (relative units, as `scatterfit \
                 merge` prints it)",
                show(*bad)
            )));
        }
        Ok(scatterfit_io::budget::check_memory(
            &format!("a profile of {rings} rings × 3 channels"),
            (rings as u64 + 1).saturating_mul(3 * BYTES_PER_RING_CHANNEL),
            memory_budget,
        )?)
    }
}

/// Finds the spot (unless given) and averages rings. Pixel-channels saturated in every exposure
/// (`clipped` with [`CLIPPED_HIGH`]) are left out; NaN pixels are skipped.
///
/// # Errors
/// [`PipelineError::Imaging`] when no spot is found (a failed measurement) or a given centre lies
/// outside the image, or for bad ring options.
pub fn profile_stage(
    radiance: &ImageBuf<f32>,
    clipped: Option<&ImageBuf<u8>>,
    detection_limit: &[f64],
    settings: &ProfileSettings,
) -> Result<ProfileStage> {
    profile_stage_with(
        radiance,
        clipped,
        detection_limit,
        settings,
        AutoOrNone::None,
    )
}

/// [`profile_stage`], and with `background = auto` the veiling glare per channel
/// ([`estimate_background`]) subtracted from the rings when it matters.
///
/// # Errors
/// As [`profile_stage`].
pub fn profile_stage_with(
    radiance: &ImageBuf<f32>,
    clipped: Option<&ImageBuf<u8>>,
    detection_limit: &[f64],
    settings: &ProfileSettings,
    background: AutoOrNone,
) -> Result<ProfileStage> {
    let (center, center_source) = match settings.center_px {
        Some([x, y]) => (
            SpotCenter::given(radiance, x, y).map_err(|source| PipelineError::Imaging {
                context: "the given spot centre".into(),
                source,
            })?,
            CenterSource::Given,
        ),
        None => (
            find_spot_center(radiance, &CenterOptions::default()).map_err(|source| {
                PipelineError::Imaging {
                    context: "finding the light spot (give its centre with center_px / --center \
                              X,Y if the image holds one)"
                        .into(),
                    source,
                }
            })?,
            CenterSource::Found,
        ),
    };
    let high_only = clipped.map(|m| {
        let data = m.data().iter().map(|&b| b & CLIPPED_HIGH).collect();
        ImageBuf::new(m.width(), m.height(), m.channels(), data).expect("same shape as the mask")
    });
    let opts =
        ProfileOptions::new(settings.ring_width_px, settings.r_max_px).map_err(|source| {
            PipelineError::Imaging {
                context: "the profile's rings (check the ring width and r_max)".into(),
                source,
            }
        })?;
    let profile = radial_profile(
        radiance,
        center.xy(),
        high_only.as_ref(),
        settings.mm_per_pixel,
        &opts,
    )
    .map_err(|source| PipelineError::Imaging {
        context: "computing the radial profile (check the ring width and r_max)".into(),
        source,
    })?;
    let mut limits = detection_limit.to_vec();
    limits.resize(profile.channels(), f64::NAN);
    let mut profile = profile;
    let background = match background {
        AutoOrNone::None => Vec::new(),
        AutoOrNone::Auto => {
            let bg = estimate_background(
                radiance,
                high_only.as_ref(),
                center.xy(),
                settings.mm_per_pixel,
                &profile,
                &limits,
            )?;
            for (c, b) in bg.iter().enumerate() {
                if b.subtracted {
                    for ring in &mut profile.rings {
                        ring.channels[c].mean -= b.level;
                    }
                    limits[c] = if limits[c].is_finite() {
                        limits[c].max(b.level)
                    } else {
                        b.level
                    };
                }
            }
            bg
        }
    };
    Ok(ProfileStage {
        center,
        center_source,
        profile,
        detection_limit: limits,
        background,
    })
}

/// Veiling glare and stray light: per channel, a constant level b under the profile, fitted with
/// the profile's far field, y(r) = b + A e^{−s r}/r^p ([`crate::camera::fit_background`]), on
/// 2-pixel rings from a third of the way to the frame's farthest corner out to that corner (the
/// rings the fit uses to r_max and beyond: a lens's glare is flat where the profile has fallen to
/// 10⁻⁵ of its peak). Marked for subtraction when significant: above 3 standard errors and above
/// the detection limit. A clear sample's real tail reaching the corners can look like a level of a
/// few 10⁻⁶ of the peak to this far-field model (3.5 % on σa of a quick-twin α′ = 0.99 sample when
/// subtracted at a tenth of the limit); a lens's glare at 10⁻⁴–10⁻³ is far above the limit. A tail
/// that reaches the corners can also read as a level above the limit: the measurement then lets
/// exact transport decide ([`crate::fit::background`]).
///
/// # Errors
/// [`PipelineError::Imaging`] when the rings cannot be made.
pub fn estimate_background(
    radiance: &ImageBuf<f32>,
    saturated: Option<&ImageBuf<u8>>,
    center: [f64; 2],
    mm_per_pixel: f64,
    profile: &RadialProfile,
    detection_limit: &[f64],
) -> Result<Vec<Background>> {
    let (w, h) = (radiance.width() as f64, radiance.height() as f64);
    let [cx, cy] = center;
    let far = [
        (0.0, 0.0),
        (w - 1.0, 0.0),
        (0.0, h - 1.0),
        (w - 1.0, h - 1.0),
    ]
    .iter()
    .map(|(x, y)| (x - cx).hypot(y - cy))
    .fold(0.0f64, f64::max);
    let opts = ProfileOptions::new(2.0, far.max(4.0)).map_err(|source| PipelineError::Imaging {
        context: "the background's rings".into(),
        source,
    })?;
    let rings =
        radial_profile(radiance, center, saturated, mm_per_pixel, &opts).map_err(|source| {
            PipelineError::Imaging {
                context: "the background's rings".into(),
                source,
            }
        })?;
    let peak: Vec<f64> = (0..profile.channels())
        .map(|c| {
            profile
                .rings
                .iter()
                .map(|r| r.channels[c].mean)
                .filter(|v| v.is_finite())
                .fold(0.0f64, f64::max)
        })
        .collect();
    let r_from = far / 3.0;
    Ok((0..rings.channels())
        .map(|c| {
            let pts: Vec<(f64, f64, f64)> = rings
                .rings
                .iter()
                .enumerate()
                .filter(|(_, r)| r.r_px >= r_from && r.channels[c].count >= 8)
                .filter_map(|(k, r)| {
                    let ch = &r.channels[c];
                    let r_mm = rings.r_mm(k)?;
                    (ch.mean.is_finite() && ch.std_err.is_finite() && r_mm > 0.0).then_some((
                        r_mm,
                        ch.mean,
                        ch.std_err.max(1e-30),
                    ))
                })
                .collect();
            let (level, stderr) =
                crate::camera::fit_background(&pts).unwrap_or((0.0, f64::INFINITY));
            let limit = detection_limit.get(c).copied().unwrap_or(f64::NAN);
            let subtracted = level > 3.0 * stderr && (!limit.is_finite() || level > limit);
            Background {
                level,
                stderr,
                relative_to_peak: if peak[c] > 0.0 {
                    level / peak[c]
                } else {
                    f64::NAN
                },
                subtracted,
            }
        })
        .collect())
}

impl ProfileStage {
    /// Channel `c`'s rings as the fit takes them (rings with no pixel at all are dropped; a grey
    /// profile has no channel but its one, read as R).
    ///
    /// # Errors
    /// [`PipelineError::Input`] if the ring radii are not increasing (cannot happen for a profile
    /// made here).
    pub fn channel_data(&self, c: Channel) -> Result<ProfileData> {
        // The image's channels are R, G, B in that order.
        let c = c.index();
        profile_data((0..self.profile.rings.len()).filter_map(|k| {
            let ring = &self.profile.rings[k];
            let ch = ring.channels.get(c)?;
            Some((
                self.profile.r_mm(k)?,
                ch.mean,
                ch.std_err,
                ch.count as u64,
                self.detection_limit.get(c).copied().unwrap_or(f64::NAN),
            ))
        }))
    }

    /// The stage with the background level added back to the rings of `channels` (each one's
    /// detection limit the merge's, `merge_limits`, again, and its level marked not subtracted):
    /// the profile as measured there ([`crate::fit::background`] decides).
    #[must_use]
    pub fn with_levels_restored(&self, channels: &[usize], merge_limits: &[f64]) -> ProfileStage {
        let mut stage = self.clone();
        for &c in channels {
            let Some(b) = stage.background.get_mut(c).filter(|b| b.subtracted) else {
                continue;
            };
            b.subtracted = false;
            let level = b.level;
            for ring in &mut stage.profile.rings {
                if let Some(ch) = ring.channels.get_mut(c) {
                    ch.mean += level;
                }
            }
            if let Some(limit) = stage.detection_limit.get_mut(c) {
                *limit = merge_limits.get(c).copied().unwrap_or(f64::NAN);
            }
        }
        stage
    }

    /// The three channels' rings as the fit takes them.
    ///
    /// # Errors
    /// [`PipelineError::Input`] for a profile that is not RGB (σ′s and σa per colour need RGB
    /// images), or as [`ProfileStage::channel_data`].
    pub fn rgb_data(&self) -> Result<Rgb<ProfileData>> {
        let channels = self.profile.channels();
        if channels != 3 {
            return Err(PipelineError::Input(format!(
                "the radiance map has {channels} channel(s); σ′s and σa per colour need RGB images"
            )));
        }
        Rgb::from_fn(|c| self.channel_data(c)).transpose()
    }

    /// The profile as the CSV table (`r_mm,r_px,value_c,stderr_c,count_c,limit_c`).
    pub fn to_table(&self) -> ProfileTable {
        let names: Vec<String> = match self.profile.channels() {
            1 => vec!["y".into()],
            3 => Channel::ALL.map(|c| c.key().to_string()).to_vec(),
            n => (0..n).map(|c| format!("c{c}")).collect(),
        };
        let rings = &self.profile.rings;
        ProfileTable {
            r_mm: (0..rings.len())
                .filter_map(|k| self.profile.r_mm(k))
                .collect(),
            r_px: rings.iter().map(|r| r.r_px).collect(),
            channels: names
                .into_iter()
                .enumerate()
                .map(|(c, name)| ProfileColumn {
                    name,
                    value: rings.iter().map(|r| r.channels[c].mean).collect(),
                    stderr: rings.iter().map(|r| r.channels[c].std_err).collect(),
                    count: rings.iter().map(|r| r.channels[c].count as u64).collect(),
                    limit: if self.detection_limit[c].is_finite() {
                        vec![self.detection_limit[c]; rings.len()]
                    } else {
                        Vec::new()
                    },
                })
                .collect(),
        }
    }
}

/// What the profile stage gave, as `scatterfit profile` prints it (`--json` serialises it as is).
#[derive(Debug, Clone, Serialize)]
pub struct ProfileSummary {
    /// The radiance map read.
    pub radiance: PathBuf,
    /// Spot centre `[x, y]` \[px\].
    pub center_px: [f64; 2],
    /// `found` or `given`.
    pub center_source: CenterSource,
    /// Pixels in the spot region (found centres only).
    pub spot_pixels: usize,
    /// Rings written.
    pub rings: usize,
    /// Rings with no valid pixel in some channel.
    pub empty_rings: usize,
    /// Image scale [mm/px].
    pub mm_per_pixel: f64,
    /// Outermost ring radius \[mm\].
    pub r_max_mm: f64,
    /// The CSV written.
    pub output: PathBuf,
    /// Ring width \[px\] (in the text, not the JSON).
    #[serde(skip)]
    pub ring_width_px: f64,
}

impl ProfileSummary {
    /// The summary of `stage`, made with `settings` from the radiance map `radiance` and written to
    /// `output`.
    pub fn new(
        stage: &ProfileStage,
        settings: &ProfileSettings,
        radiance: PathBuf,
        output: PathBuf,
    ) -> Self {
        let profile = &stage.profile;
        Self {
            radiance,
            center_px: stage.center.xy(),
            center_source: stage.center_source,
            spot_pixels: stage.center.spot_pixels(),
            rings: profile.rings.len(),
            empty_rings: profile
                .rings
                .iter()
                .filter(|r| r.channels.iter().any(|c| c.count == 0))
                .count(),
            mm_per_pixel: settings.mm_per_pixel,
            r_max_mm: (0..profile.rings.len())
                .filter_map(|k| profile.r_mm(k))
                .next_back()
                .unwrap_or(f64::NAN),
            output,
            ring_width_px: settings.ring_width_px,
        }
    }

    /// The summary as `scatterfit profile` prints it: the centre, the rings, the file written.
    pub fn text(&self) -> String {
        let source = match self.center_source {
            CenterSource::Found => format!("found ({} spot pixels)", self.spot_pixels),
            CenterSource::Given => "given".into(),
        };
        format!(
            "centre   ({:.3}, {:.3}) px, {source}\nrings    {} × {} px, out to {:.3} mm ({} with an \
             empty channel)\nwrote    {}\n",
            self.center_px[0],
            self.center_px[1],
            self.rings,
            self.ring_width_px,
            self.r_max_mm,
            self.empty_rings,
            self.output.display()
        )
    }
}

/// The three channels of a profile CSV (`value_r`, `value_g`, `value_b`, …) as the fit takes them.
///
/// # Errors
/// [`PipelineError::Input`] naming the first channel that is not in the table.
pub fn rgb_from_table(table: &ProfileTable) -> Result<Rgb<ProfileData>> {
    Rgb::from_fn(|c| channel_from_table(table, c.key())).transpose()
}

/// A channel of a profile CSV as the fit takes it.
///
/// # Errors
/// [`PipelineError::Input`] naming the channel when it is not in the table.
pub fn channel_from_table(table: &ProfileTable, name: &str) -> Result<ProfileData> {
    let col = table
        .channels
        .iter()
        .find(|c| c.name.eq_ignore_ascii_case(name))
        .ok_or_else(|| {
            PipelineError::Input(format!(
                "the profile has no channel `{name}` (it has {})",
                table
                    .channels
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
    profile_data((0..table.r_mm.len()).map(|k| {
        (
            table.r_mm[k],
            col.value[k],
            col.stderr[k],
            col.count[k],
            col.limit.get(k).copied().unwrap_or(f64::NAN),
        )
    }))
}

fn profile_data(rings: impl Iterator<Item = (f64, f64, f64, u64, f64)>) -> Result<ProfileData> {
    ProfileData::new(
        rings
            .filter(|&(r, ..)| r.is_finite())
            .map(|(r_mm, value, stderr, count, detection_limit)| Ring {
                r_mm,
                value,
                stderr,
                count,
                detection_limit,
            })
            .collect(),
    )
    .map_err(|e| PipelineError::Input(e.to_string()))
}
