//! Stage 3: the spot centre and the radial profile Rd(r) per channel (Choi et al. 2014, §3.2:
//! "pixels at the same distance from the focus point … averaged"), with each ring's detection
//! limit, as the fit takes them.

use scatterfit_fit::{ProfileData, Ring};
use scatterfit_imaging::{
    CLIPPED_HIGH, CenterOptions, ImageBuf, ProfileOptions, RadialProfile, SpotCenter,
    find_spot_center, radial_profile,
};
use scatterfit_io::profile_csv::{ProfileColumn, ProfileTable};
use scatterfit_optics::{Channel, Rgb};
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
}

/// Options of the profile stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileSettings {
    /// Image scale on the sample [mm per pixel].
    pub mm_per_pixel: f64,
    /// Outermost ring [px] (the paper's 300).
    pub r_max_px: f64,
    /// Ring width [px].
    pub ring_width_px: f64,
    /// A given spot centre [x, y] px.
    pub center_px: Option<[f64; 2]>,
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
    Ok(ProfileStage {
        center,
        center_source,
        profile,
        detection_limit: limits,
    })
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
