//! A render's settings as a user gives them (`scatterfit render`'s flags): the numbers no other
//! part checks, checked with the setting named by its command-line flag and the memory they size
//! checked against the budget before any work ([`RenderSettings::check`]); then the renderer's
//! options, validated ([`RenderSettings::options`]), and the tone curve
//! ([`RenderSettings::tone`]); and what its output files may be ([`check_output_kind`]).

use std::path::Path;

use scatterfit_io::budget::{OverBudget, check_memory};
use scatterfit_io::escape::number as show;

use crate::RenderError;
use crate::colour::ColourParams;
use crate::render::RenderOptions;
use crate::texture_space::{DipoleParams, Evaluation};
use crate::tonemap::ToneMap;

/// Why the settings cannot render.
#[derive(Debug, thiserror::Error)]
pub enum RenderSettingsError {
    /// A setting out of range: which, and the valid range.
    #[error("{0}")]
    Refused(String),
    /// The memory the settings size is beyond the budget.
    #[error(transparent)]
    OverBudget(#[from] OverBudget),
    /// The renderer refused a group of options.
    #[error("{what}")]
    Invalid {
        /// `shading coefficients` or `texture-space options`.
        what: &'static str,
        /// The renderer's reason.
        #[source]
        source: RenderError,
    },
}

/// Checks that an output file of a render (`-o`) is one it writes: `.png` (tone-mapped sRGB),
/// `.exr` (linear radiance), and with `profile` (the validation against the measured profile)
/// `.csv`.
///
/// # Errors
/// [`RenderSettingsError::Refused`], saying what to write.
pub fn check_output_kind(path: &Path, profile: bool) -> Result<(), RenderSettingsError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    match ext.as_str() {
        "png" | "exr" => Ok(()),
        "csv" if profile => Ok(()),
        "csv" => Err(RenderSettingsError::Refused(format!(
            "-o {}: a .csv output is the profile comparison; add --profile, or write .png/.exr",
            path.display()
        ))),
        _ => Err(RenderSettingsError::Refused(format!(
            "-o {}: write .png (tone-mapped sRGB) or .exr (linear radiance){}",
            path.display(),
            if profile { " or .csv" } else { "" }
        ))),
    }
}

/// The settings of a render.
#[derive(Debug, Clone)]
pub struct RenderSettings {
    /// Image size in pixels (width, height).
    pub size: (usize, usize),
    /// Camera samples per pixel, 1 to 4096.
    pub spp: usize,
    /// Seed of every random stream.
    pub seed: u64,
    /// The subsurface colour method's coefficients (eqs. 3–5).
    pub colour: ColourParams,
    /// Rays each light shoots for the irradiance, 1e3 to 1e8 (`None`: from the profile's width).
    pub light_rays: Option<usize>,
    /// Hierarchy threshold \[rad\].
    pub max_angle: f64,
    /// Eq. 6 as a direct sum (exact, slow).
    pub direct: bool,
    /// Interpolate the texture-space sum over every second pixel where the surface is smooth.
    pub interpolate: bool,
    /// mm per mesh-file unit, in (0, 1e6].
    pub mesh_scale: f64,
    /// Triangles of a built-in model, 1000 to 1e7.
    pub triangles: usize,
    /// Exposure \[EV\], in [−60, 60] (`None`: 0, or the profile's own with `--profile`).
    pub exposure: Option<f64>,
    /// Tone-curve white, in [1, 1e6].
    pub white: f64,
    /// Light-spot radius for the profile validation \[mm\], in (0, 10].
    pub spot_radius_mm: Option<f64>,
}

impl RenderSettings {
    /// Checks the numbers that no other part checks, then the memory of `panels` panels against
    /// `memory_budget` \[bytes\] ([`crate::request::memory_bytes`]), before any work.
    ///
    /// # Errors
    /// The first setting out of range, or the memory over the budget.
    pub fn check(&self, panels: usize, memory_budget: u64) -> Result<(), RenderSettingsError> {
        let ensure = |ok: bool, flag: &str, value: f64, rule: &str| {
            if ok {
                Ok(())
            } else {
                Err(RenderSettingsError::Refused(format!(
                    "{flag} {}: {rule}",
                    show(value)
                )))
            }
        };
        ensure(
            (1..=4096).contains(&self.spp),
            "--spp",
            self.spp as f64,
            "the samples per pixel must lie in 1–4096",
        )?;
        ensure(
            self.mesh_scale > 0.0 && self.mesh_scale <= 1e6,
            "--mesh-scale",
            self.mesh_scale,
            "the mesh scale must lie in (0, 1e6] mm per file unit",
        )?;
        if let Some(ev) = self.exposure {
            ensure(
                (-60.0..=60.0).contains(&ev),
                "--exposure",
                ev,
                "the exposure must lie in [−60, 60] EV",
            )?;
        }
        ensure(
            (1.0..=1e6).contains(&self.white),
            "--white",
            self.white,
            "the tone-curve white must lie in [1, 1e6]",
        )?;
        if let Some(r) = self.spot_radius_mm {
            ensure(
                r > 0.0 && r <= 10.0,
                "--spot-radius-mm",
                r,
                "the light spot's radius must lie in (0, 10] mm",
            )?;
        }
        let (w, h) = self.size;
        check_memory(
            &format!("rendering {panels} panel(s) of {w}×{h} px"),
            crate::request::memory_bytes(w, h, panels, self.triangles, self.light_rays),
            memory_budget,
        )?;
        if !(1000..=10_000_000).contains(&self.triangles) {
            return Err(RenderSettingsError::Refused(format!(
                "--triangles {} must lie in 1000–1e7",
                self.triangles
            )));
        }
        if let Some(n) = self.light_rays
            && !(1000..=100_000_000).contains(&n)
        {
            return Err(RenderSettingsError::Refused(format!(
                "--light-rays {n} must lie in 1e3–1e8"
            )));
        }
        Ok(())
    }

    /// The renderer's options, validated.
    ///
    /// # Errors
    /// A shading coefficient or a texture-space option the renderer refuses.
    pub fn options(&self) -> Result<RenderOptions, RenderSettingsError> {
        let options = RenderOptions {
            width: self.size.0,
            height: self.size.1,
            spp: self.spp,
            seed: self.seed,
            colour: self.colour,
            dipole: DipoleParams {
                light_rays: self.light_rays,
                evaluation: if self.direct {
                    Evaluation::Direct
                } else {
                    Evaluation::Hierarchical {
                        max_angle: self.max_angle,
                    }
                },
                specular: true,
                interpolate: self.interpolate,
            },
        };
        let invalid = |what| move |source| RenderSettingsError::Invalid { what, source };
        options
            .colour
            .validate()
            .map_err(invalid("shading coefficients"))?;
        options
            .dipole
            .validate()
            .map_err(invalid("texture-space options"))?;
        Ok(options)
    }

    /// The tone curve: the exposure (0 EV unless given) and the white.
    pub fn tone(&self) -> ToneMap {
        ToneMap {
            exposure_ev: self.exposure.unwrap_or(0.0),
            white: self.white,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> RenderSettings {
        RenderSettings {
            size: (64, 48),
            spp: 4,
            seed: 1,
            colour: ColourParams::default(),
            light_rays: None,
            max_angle: 0.5,
            direct: false,
            interpolate: true,
            mesh_scale: 1.0,
            triangles: 100_000,
            exposure: None,
            white: 4.0,
            spot_radius_mm: None,
        }
    }

    #[test]
    fn settings_become_options_and_a_tone_curve() {
        let s = RenderSettings {
            direct: true,
            exposure: Some(-2.0),
            ..settings()
        };
        s.check(2, 1 << 32).unwrap();
        let o = s.options().unwrap();
        assert_eq!((o.width, o.height, o.spp), (64, 48, 4));
        assert!(matches!(o.dipole.evaluation, Evaluation::Direct));
        assert!(o.dipole.interpolate && o.dipole.specular);
        let t = s.tone();
        assert_eq!((t.exposure_ev, t.white), (-2.0, 4.0));
        assert_eq!(settings().tone().exposure_ev, 0.0);
    }

    #[test]
    fn settings_out_of_range_are_refused_naming_the_flag() {
        let e = |s: RenderSettings| s.check(1, 1 << 32).unwrap_err().to_string();
        assert_eq!(
            e(RenderSettings {
                spp: 5000,
                ..settings()
            }),
            "--spp 5000: the samples per pixel must lie in 1–4096"
        );
        assert_eq!(
            e(RenderSettings {
                triangles: 10,
                ..settings()
            }),
            "--triangles 10 must lie in 1000–1e7"
        );
        assert_eq!(
            e(RenderSettings {
                light_rays: Some(10),
                ..settings()
            }),
            "--light-rays 10 must lie in 1e3–1e8"
        );
        let over = settings().check(1, 1024).unwrap_err().to_string();
        assert!(
            over.starts_with("rendering 1 panel(s) of 64×48 px needs"),
            "{over}"
        );
        let mut bad = settings();
        bad.colour.beta = 0.0;
        let e = bad.options().unwrap_err();
        assert_eq!(e.to_string(), "shading coefficients");
        assert!(std::error::Error::source(&e).is_some());
    }
}
