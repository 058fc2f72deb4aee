//! What a rig twin is made of, from a user's settings (`scatterfit synth`'s flags; the demo and
//! the study build theirs from published materials and the study's grid): the material, the rig
//! (its camera and a real rig's effects) and the spectrophotometer's port, each checked with the
//! setting named by its command-line flag; and [`synthesize_material`], the twin made with a
//! progress callback.

use std::path::Path;

use scatterfit_io::escape::number as show;
use scatterfit_io::manifest::G_RANGE_MAX;
use scatterfit_optics::materials::{self, PublishedMaterial};
use scatterfit_optics::port::Port;
use scatterfit_synth::rig::RigEffects;
use scatterfit_synth::{CameraModel, RigSpec, SynthError, SyntheticSample};

/// Why a twin cannot be made from the settings.
#[derive(Debug, thiserror::Error)]
pub enum TwinSettingsError {
    /// A setting missing, unknown or out of range: what to give instead.
    #[error("{0}")]
    Refused(String),
    /// The rig twin refused the settings, with what to check.
    #[error("{source}{hint}")]
    Rig {
        /// The twin's reason.
        source: SynthError,
        /// Which settings to check (may be empty).
        hint: &'static str,
    },
    /// The port's geometry.
    #[error(transparent)]
    Port(#[from] scatterfit_optics::OpticsError),
    /// Synthesis failed.
    #[error("synthesising {name}")]
    Synthesis {
        /// The material.
        name: String,
        /// Why.
        #[source]
        source: SynthError,
    },
}

impl From<SynthError> for TwinSettingsError {
    fn from(source: SynthError) -> Self {
        Self::Rig { source, hint: "" }
    }
}

fn refuse(ok: bool, text: impl FnOnce() -> String) -> Result<(), TwinSettingsError> {
    if ok {
        Ok(())
    } else {
        Err(TwinSettingsError::Refused(text()))
    }
}

/// A material to synthesise.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Name.
    pub name: String,
    /// σ′s per channel \[mm⁻¹\].
    pub sigma_s_prime: [f64; 3],
    /// σa per channel \[mm⁻¹\].
    pub sigma_a: [f64; 3],
    /// η.
    pub eta: f64,
}

impl From<&PublishedMaterial> for Material {
    fn from(m: &PublishedMaterial) -> Self {
        Self {
            name: m.name.into(),
            sigma_s_prime: m.sigma_s_prime,
            sigma_a: m.sigma_a,
            eta: m.eta,
        }
    }
}

/// The material's settings: a published material by name (its η replaced by `eta` when given), or
/// coefficients and η (also `scatterfit synth`'s flags, whose help texts are given with each field).
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct MaterialSettings {
    /// A published material (`scatterfit_optics::materials::by_name`).
    #[cfg_attr(feature = "clap", arg(long, value_name = "NAME", conflicts_with_all = ["sigma_s_prime", "sigma_a"], help = MATERIAL_HELP))]
    pub material: Option<String>,
    /// σ′s per channel \[mm⁻¹, each in (0, 100]\].
    #[cfg_attr(feature = "clap", arg(long, value_name = "R,G,B", value_parser = scatterfit_io::flags::parse_rgb, requires_all = ["sigma_a", "eta"], help = "Reduced scattering coefficient per channel R,G,B [mm⁻¹, each in (0, 100]]"))]
    pub sigma_s_prime: Option<[f64; 3]>,
    /// σa per channel \[mm⁻¹, each in (0, 100]\].
    #[cfg_attr(feature = "clap", arg(long, value_name = "R,G,B", value_parser = scatterfit_io::flags::parse_rgb, requires = "sigma_s_prime", help = "Absorption coefficient per channel R,G,B [mm⁻¹, each in (0, 100]]"))]
    pub sigma_a: Option<[f64; 3]>,
    /// η, in [1, 3].
    #[cfg_attr(feature = "clap", arg(long, value_parser = scatterfit_io::flags::parse_finite, help = "Relative refractive index η, in [1, 3] (overrides the material's)"))]
    pub eta: Option<f64>,
    /// The sample's name (default: the material's, or "synthetic").
    #[cfg_attr(
        feature = "clap",
        arg(long, help = "Sample name (default: the material's, or \"synthetic\")")
    )]
    pub name: Option<String>,
}

/// Help text of `--material`: the published materials by name.
#[cfg(feature = "clap")]
const MATERIAL_HELP: &str = "A built-in material: the seven of Choi et al. 2014 (pink-plastic, \
    blue-coating, brown-leather, nephrite, wood-tile, sulfur, red-aluminum) or Jensen et al. \
    2001's (apple, chicken1, chicken2, cream, ketchup, marble, potato, skimmilk, skin1, skin2, \
    wholemilk; η = 1.3)";

impl MaterialSettings {
    /// The material.
    ///
    /// # Errors
    /// An unknown material, a missing coefficient or η, or a value out of range.
    pub fn material(&self) -> Result<Material, TwinSettingsError> {
        let m = match (&self.material, self.sigma_s_prime, self.sigma_a) {
            (Some(name), _, _) => {
                let m = materials::by_name(name).ok_or_else(|| {
                    let names: Vec<&str> = materials::all().map(|m| m.name).collect();
                    TwinSettingsError::Refused(format!(
                        "--material {name}: unknown; built-in materials: {}",
                        names.join(", ")
                    ))
                })?;
                Material {
                    eta: self.eta.unwrap_or(m.eta),
                    ..Material::from(m)
                }
            }
            (None, Some(sp), Some(sa)) => Material {
                name: "synthetic".into(),
                sigma_s_prime: sp,
                sigma_a: sa,
                eta: self.eta.ok_or_else(|| {
                    TwinSettingsError::Refused("--eta is required with --sigma-s-prime".into())
                })?,
            },
            _ => {
                return Err(TwinSettingsError::Refused(
                    "say what to synthesise: --material NAME, or --sigma-s-prime R,G,B --sigma-a \
                     R,G,B --eta X"
                        .into(),
                ));
            }
        };
        for (what, v) in [
            ("--sigma-s-prime", m.sigma_s_prime),
            ("--sigma-a", m.sigma_a),
        ] {
            if let Some(x) = v.iter().find(|x| !(**x > 0.0 && **x <= 100.0)) {
                return Err(TwinSettingsError::Refused(format!(
                    "{what}: {} is outside (0, 100] mm⁻¹",
                    show(*x)
                )));
            }
        }
        refuse((1.0..=3.0).contains(&m.eta), || {
            format!("--eta {}: the rig twin takes η in [1, 3]", m.eta)
        })?;
        Ok(Material {
            name: self.name.clone().unwrap_or(m.name),
            ..m
        })
    }
}

/// Help text of `--photon-scale` (`scatterfit synth`, `study`): the twins' Monte Carlo photons × a
/// factor, and what it buys.
pub const PHOTON_SCALE_HELP: &str = "Monte Carlo photons of every twin channel × this factor, \
    0.01–1000 (default 1): a twin's own noise (its profile's and its reading's) falls as 1/√factor \
    at factor times its Monte Carlo time. At α′ ≥ 0.999 the paper rig's twins carry noise that \
    reaches σ′s and σa at 1–2.5 %, so a study that is to resolve the method's error there needs \
    10–20";

/// Parses `--photon-scale`: a finite number in [`scatterfit_synth::rig::PHOTON_SCALE_RANGE`].
///
/// # Errors
/// Not a number, or outside the range.
pub fn parse_photon_scale(text: &str) -> Result<f64, scatterfit_io::flags::FlagError> {
    let v = scatterfit_io::flags::parse_finite(text)?;
    let range = scatterfit_synth::rig::PHOTON_SCALE_RANGE;
    if range.contains(&v) {
        Ok(v)
    } else {
        Err(scatterfit_io::flags::FlagError(format!(
            "must lie in [{}, {}] (1 is the rig's own photon count)",
            range.start(),
            range.end()
        )))
    }
}

/// The rig's settings (also `scatterfit synth`'s flags, whose help is the field's text; the
/// effects' flags follow them on the command line and are set after parsing).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct RigSettings {
    /// A small fast sample (256 × 256 px at 0.1 mm/px, a tenth of the photons) for trying the tool
    /// and for tests; not for accuracy studies.
    #[cfg_attr(feature = "clap", arg(long))]
    pub quick: bool,
    /// Monte Carlo photons × this factor (`RigSpec::with_photon_scale`; [`PHOTON_SCALE_HELP`]).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FACTOR", default_value_t = 1.0, allow_negative_numbers = true, value_parser = parse_photon_scale, help = PHOTON_SCALE_HELP))]
    pub photon_scale: f64,
    /// The material's Henyey–Greenstein anisotropy g, in [0, 0.95] (default 0, isotropic): the
    /// profile and the spectrophotometer's reading are traced with it (σs = σ′s/(1 − g)). It goes
    /// into truth.json, never into the manifest: the twin plays a user who does not know g. A g of
    /// 0.9 traces about 10× the interactions of g = 0, 0.95 about 20×.
    #[cfg_attr(feature = "clap", arg(long, value_name = "G", default_value_t = 0.0, value_parser = scatterfit_io::flags::parse_finite))]
    pub g: f64,
    /// The twin's camera: naka-rushton (the default, 8-bit), linear, gamma22, srgb, log, s-curve
    /// (8-bit tone curves), linear16 (linear 16-bit PNG, black level 1024 DN) or dng (14-bit raw
    /// DNG files, black level 512, white 16383, exposure times in their metadata).
    #[cfg_attr(feature = "clap", arg(long, value_name = "NAME", value_parser = parse_camera, default_value = "naka-rushton"))]
    pub camera: Option<String>,
    /// Camera read noise [electrons, 0 to 1000] (default 3).
    #[cfg_attr(feature = "clap", arg(long, value_name = "E", value_parser = scatterfit_io::flags::parse_finite))]
    pub read_noise: Option<f64>,
    /// A real rig's effects.
    #[cfg_attr(feature = "clap", arg(skip))]
    pub effects: RigEffects,
}

/// Parses `--camera`: a camera of the twin ([`CameraModel::named`]).
///
/// # Errors
/// An unknown name, listing the twin's cameras.
pub fn parse_camera(s: &str) -> Result<String, scatterfit_io::flags::FlagError> {
    if CameraModel::named(s).is_some() {
        Ok(s.to_string())
    } else {
        Err(scatterfit_io::flags::FlagError(format!(
            "unknown camera `{s}`; the twin has: {}",
            CameraModel::NAMES.join(", ")
        )))
    }
}

impl RigSettings {
    /// The rig.
    ///
    /// # Errors
    /// A setting out of range, an unknown camera, or effects the twin cannot make.
    pub fn rig(&self) -> Result<RigSpec, TwinSettingsError> {
        let mut rig = if self.quick {
            RigSpec::quick()
        } else {
            RigSpec::paper()
        };
        refuse((0.0..=G_RANGE_MAX).contains(&self.g), || {
            format!(
                "--g {}: the twin's Henyey–Greenstein g must lie in [0, {G_RANGE_MAX}]",
                show(self.g)
            )
        })?;
        rig.g = self.g;
        let mut rig = rig.with_photon_scale(self.photon_scale)?;
        if let Some(name) = &self.camera {
            rig.camera = CameraModel::named(name)
                .ok_or_else(|| TwinSettingsError::Refused(format!("--camera {name}: unknown")))?;
        }
        if let Some(e) = self.read_noise {
            refuse((0.0..=1000.0).contains(&e), || {
                format!("--read-noise {}: 0 to 1000 electrons", show(e))
            })?;
            rig.camera.read_noise_e = e;
        }
        rig.effects = self.effects;
        rig.validate().map_err(|source| TwinSettingsError::Rig {
            source,
            hint: " (check --glare, --vignetting, --exposure-error)",
        })?;
        Ok(rig)
    }
}

/// The files a twin's sample folder gets on `rig` (`scatterfit_io::sample_folder::file_names`
/// with the truth), so that they can be checked before the Monte Carlo runs: the frames as `.dng`
/// when `dng` (the `dng` camera), `flat.png` with vignetting, `spot.png` with a spot image.
pub fn twin_files(rig: &RigSpec, dng: bool) -> Vec<String> {
    let mut names = scatterfit_io::sample_folder::file_names(rig.times_s.len(), true);
    if dng {
        for n in &mut names {
            if n.starts_with("frame_") {
                *n = n.replace(".png", ".dng");
            }
        }
    }
    if rig.effects.vignetting > 0.0 {
        names.push("flat.png".into());
    }
    if rig.effects.spot_image {
        names.push("spot.png".into());
    }
    names
}

/// The spectrophotometer's port: the aperture's diameter and the lit disc's (default: the
/// aperture's), each 1 to 100 mm; `None` without an aperture (a loss-free reading).
///
/// # Errors
/// A diameter out of range, or a port the optics refuse.
pub fn port(
    aperture_mm: Option<f64>,
    illuminated_mm: Option<f64>,
) -> Result<Option<Port>, TwinSettingsError> {
    let Some(aperture) = aperture_mm else {
        return Ok(None);
    };
    let lit = illuminated_mm.unwrap_or(aperture);
    for (flag, v) in [("--aperture-mm", aperture), ("--illuminated-mm", lit)] {
        refuse((1.0..=100.0).contains(&v), || {
            format!(
                "{flag} {}: a port diameter in millimetres, 1 to 100",
                show(v)
            )
        })?;
    }
    Ok(Some(Port::new(lit, aperture)?))
}

/// Synthesises `m` on `rig` (`scatterfit_synth::synthesize`), its profiles cached in `cache`;
/// `progress` gets the fraction of the Monte Carlo work done, 0 to 1.
///
/// # Errors
/// [`TwinSettingsError::Synthesis`], naming the material.
pub fn synthesize_material(
    m: &Material,
    rig: &RigSpec,
    seed: u64,
    cache: Option<&Path>,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<SyntheticSample, TwinSettingsError> {
    let done = std::sync::Mutex::new([0.0f64; 3]);
    scatterfit_synth::synthesize(
        &m.name,
        m.sigma_s_prime,
        m.sigma_a,
        m.eta,
        rig,
        seed,
        cache,
        &|c, d, t| {
            if let Ok(mut f) = done.lock() {
                f[c] = d as f64 / t.max(1) as f64;
                progress(f.iter().sum::<f64>() / 3.0);
            }
        },
    )
    .map_err(|source| TwinSettingsError::Synthesis {
        name: m.name.clone(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_material_by_name_or_by_coefficients() {
        let m = MaterialSettings {
            material: Some("Pink Plastic".into()),
            eta: Some(1.5),
            ..Default::default()
        }
        .material()
        .unwrap();
        let published = materials::by_name("pink-plastic").unwrap();
        assert_eq!(m.name, "pink-plastic");
        assert_eq!(m.sigma_s_prime, published.sigma_s_prime);
        assert_eq!(m.eta, 1.5);
        let m = MaterialSettings {
            sigma_s_prime: Some([1.0, 2.0, 3.0]),
            sigma_a: Some([0.1, 0.2, 0.3]),
            eta: Some(1.3),
            name: Some("mine".into()),
            ..Default::default()
        }
        .material()
        .unwrap();
        assert_eq!(
            m,
            Material {
                name: "mine".into(),
                sigma_s_prime: [1.0, 2.0, 3.0],
                sigma_a: [0.1, 0.2, 0.3],
                eta: 1.3
            }
        );
    }

    #[test]
    fn a_material_out_of_range_or_unknown_is_refused_naming_the_flag() {
        let e = |s: MaterialSettings| s.material().unwrap_err().to_string();
        assert!(
            e(MaterialSettings {
                material: Some("unobtainium".into()),
                ..Default::default()
            })
            .starts_with("--material unobtainium: unknown; built-in materials: pink-plastic,")
        );
        assert_eq!(
            e(MaterialSettings {
                sigma_s_prime: Some([1.0, 200.0, 3.0]),
                sigma_a: Some([0.1, 0.2, 0.3]),
                eta: Some(1.3),
                ..Default::default()
            }),
            "--sigma-s-prime: 200 is outside (0, 100] mm⁻¹"
        );
        assert!(e(MaterialSettings::default()).starts_with("say what to synthesise"));
    }

    #[test]
    fn a_rig_takes_its_camera_and_effects() {
        let mut s = RigSettings {
            quick: true,
            g: 0.5,
            photon_scale: 2.0,
            camera: Some("linear16".into()),
            read_noise: Some(7.0),
            effects: RigEffects {
                glare: 1e-4,
                ..RigEffects::default()
            },
        };
        let rig = s.rig().unwrap();
        assert_eq!(rig.g, 0.5);
        assert_eq!(rig.camera.read_noise_e, 7.0);
        assert_eq!(rig.effects.glare, 1e-4);
        assert_eq!(rig.width, RigSpec::quick().width);
        s.read_noise = Some(2000.0);
        assert_eq!(
            s.rig().unwrap_err().to_string(),
            "--read-noise 2000: 0 to 1000 electrons"
        );
        s.read_noise = None;
        s.effects.glare = 0.5;
        assert!(
            s.rig()
                .unwrap_err()
                .to_string()
                .ends_with(" (check --glare, --vignetting, --exposure-error)")
        );
        s.effects.glare = 0.0;
        s.g = 0.99;
        let e = s.rig().unwrap_err();
        assert!(e.to_string().starts_with("--g 0.99: "), "{e}");
    }

    #[test]
    fn a_port_from_its_diameters() {
        assert!(port(None, Some(14.0)).unwrap().is_none());
        let p = port(Some(8.0), Some(14.0)).unwrap().unwrap();
        assert_eq!((p.aperture_mm(), p.illuminated_mm()), (8.0, 14.0));
        assert_eq!(
            port(Some(0.5), None).unwrap_err().to_string(),
            "--aperture-mm 0.5: a port diameter in millimetres, 1 to 100"
        );
    }
}
