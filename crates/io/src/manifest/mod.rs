//! `sample.toml`: the manifest of a sample folder, the contract between the rig and the tool
//! (ARCHITECTURE.md, "The measurement, as files").
//!
//! ```toml
//! name = "pink plastic"
//!
//! [spectro]
//! file = "spectro.csv"          # header: wavelength_nm,sci,sce (fractions) or *_pct (percent)
//! # lab = [62.1, 35.2, 4.0]     # measured L*a*b* (D65), used for colour instead of the SCE spectrum
//! # lab_observer = 10           # 10 (the instrument default) or 2
//! # eta = 1.45                  # a known η instead of the one from SCI − SCE (matte samples)
//! # repeatability = 0.005       # relative standard deviation of a reading (default 0.5 %)
//! # aperture_mm = 8             # the measured area's diameter: corrects the port's edge loss
//! # illuminated_mm = 14         # the lit area's diameter (default: aperture_mm)
//!
//! [camera]
//! exposures = "exposures.csv"   # header: file,time_s ; or omit and read ExposureTime from EXIF
//! mm_per_pixel = 0.1            # image scale on the sample surface
//! # images = ["a.png", "b.png"] # the frames, when there is no exposures.csv (times from EXIF)
//! # hdr = "radiance.exr"        # alternatively an already merged radiance map
//! # response = "response.csv"   # optional known camera response (else recovered)
//! # dark = "dark.png"           # optional dark frame, subtracted before merging
//! # center_px = [512.3, 498.7]  # optional spot centre (else found)
//! # spot_diameter_mm = 1.0      # the light spot (default 1 mm, the paper's "under 1 mm")
//! # spot_profile = "disk"       # disk | gaussian (spot_diameter_mm is then the 1/e² diameter)
//! # spot_image = "spot.png"     # the spot on a thin opaque white target: the fit's kernel
//! # flat = "flat.png"           # a frame of a uniform target: vignetting divided out
//! # black_level = "auto"        # linear frames: auto (far corners) | none | DN | [r, g, b] DN
//! # background = "auto"        # veiling glare: auto (fitted beyond the profile) | none
//! # exposure_correction = "auto" # shutter times from the frames: auto | always | never
//! # saturation = 4095           # 16-bit/RAW frames: the code where the camera clips (default: the
//! #                             # plateau found in the frames, the RAW white level, or 65535)
//!
//! [fit]                         # every key optional, defaults shown
//! method = "proposed"           # proposed | existing
//! model = "mc"                  # mc (exact transport) | dipole (the paper's) | better-dipole | pbd
//! # albedo_model = "diffusion"  # diffusion | mc (default: mc for the mc model, else diffusion)
//! r_max_px = 300                # the paper's cut-off
//! # g = 0.85                    # Henyey–Greenstein g of the material, known or assumed (default 0),
//! #                             # or "fit": fitted per channel from the profile where it determines g
//! # g_range = [0.7, 0.95]       # the range g lies in: a "± g" term; with g = "fit" the search range
//! ```
//!
//! Paths are relative to the manifest's folder. Unknown keys are refused (a misspelt key would
//! otherwise be ignored silently); every error names the file, the key and what to do.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::escape::number as num;

mod syntax;
mod write;

use syntax::*;
pub use write::{manifest_to_toml, write_manifest};

/// A problem with a manifest.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ManifestError {
    /// The file could not be read.
    #[error("cannot read the sample manifest {}: {source}{hint}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
        /// What to do.
        hint: String,
    },
    /// Not valid TOML, an unknown key, or a value of the wrong type.
    #[error("{}: {message}", path.display())]
    Syntax {
        /// The file.
        path: PathBuf,
        /// The TOML parser's message (line, column, key).
        message: String,
    },
    /// A value outside its range, or keys that contradict each other.
    #[error("{}: `{key}` {problem}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The key, e.g. `camera.mm_per_pixel`.
        key: &'static str,
        /// What is wrong and what to do.
        problem: String,
    },
    /// The file is not text we read (binary data, UTF-16 without a byte-order mark, too large).
    #[error(transparent)]
    Text(crate::text::TextError),
    /// The manifest could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// The names of `[fit]`: the vocabulary's own types (one definition, in `scatterfit_optics`), read
/// and written as the same strings (`proposed`, `better-dipole`, `mc`, …).
pub use scatterfit_optics::{AlbedoModel, Method, ModelName};

/// `[spectro]`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpectroSection {
    /// The SCI/SCE CSV.
    pub file: Option<PathBuf>,
    /// Measured L\*a\*b\* (D65) for the colour instead of the SCE spectrum.
    #[serde(default, deserialize_with = "exact_array")]
    pub lab: Option<[f64; 3]>,
    /// Observer of `lab`: 10 (default) or 2.
    pub lab_observer: Option<u32>,
    /// A known η instead of the one from SCI − SCE.
    pub eta: Option<f64>,
    /// Relative standard deviation of a reading, the same factor on SCI and SCE at every
    /// wavelength (a re-placed sample, the calibration): what the uncertainties of η, α′ and,
    /// through them, σ′s and σa are propagated from. Default [`DEFAULT_SPECTRO_REPEATABILITY`].
    pub repeatability: Option<f64>,
    /// Diameter of the instrument's measured area \[mm\] (its port, e.g. 4, 8 or 25 mm). Given, the
    /// reading's edge loss (light that enters inside the lit area and leaves beyond the measured
    /// one) is corrected from the fitted profile (`scatterfit_optics::port`); absent, the
    /// reading is taken as loss-free and the result says so.
    pub aperture_mm: Option<f64>,
    /// Diameter of the illuminated area \[mm\] when the instrument lights a different area than it
    /// measures (default: `aperture_mm`). Only with `aperture_mm`.
    pub illuminated_mm: Option<f64>,
}

/// The default relative repeatability of a spectrophotometer reading (0.5 %): an assumption, to be
/// replaced by the spread of repeated readings of the user's own sample (re-placed each time).
pub const DEFAULT_SPECTRO_REPEATABILITY: f64 = 0.005;

/// The light spot's radial shape (`camera.spot_profile`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpotProfileName {
    /// Uniform irradiance over a disk of diameter `spot_diameter_mm` (the default).
    #[default]
    Disk,
    /// Gaussian irradiance exp(−2ρ²/w²), `spot_diameter_mm` = 2w (the 1/e² diameter).
    Gaussian,
}

impl SpotProfileName {
    /// The name as written.
    pub fn as_str(self) -> &'static str {
        match self {
            SpotProfileName::Disk => "disk",
            SpotProfileName::Gaussian => "gaussian",
        }
    }
}

/// `auto` or `none` (`camera.background`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AutoOrNone {
    /// Estimated from the data (the default).
    #[default]
    Auto,
    /// Not done.
    None,
}

/// When the exposure times are corrected from the frames (`camera.exposure_correction`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ExposureCorrection {
    /// Estimated always, applied when a frame's time is off by more than the threshold (default).
    #[default]
    Auto,
    /// Estimated and applied.
    Always,
    /// The times as given.
    Never,
}

/// `camera.black_level`: `"auto"`, `"none"`, one number of DN, or one per channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum BlackLevelSetting {
    /// `"auto"` (from a dark frame, the file's metadata, or the frames' far corners) or `"none"`.
    Mode(AutoOrNone),
    /// The same level \[DN\] for every channel.
    One(f64),
    /// A level \[DN\] per channel R, G, B.
    PerChannel([f64; 3]),
}

/// `[camera]`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSection {
    /// `exposures.csv` (file,time_s).
    pub exposures: Option<PathBuf>,
    /// The frames, when the times come from EXIF.
    pub images: Option<Vec<PathBuf>>,
    /// Image scale on the sample [mm per pixel].
    pub mm_per_pixel: Option<f64>,
    /// An already merged radiance map (EXR or HDR).
    pub hdr: Option<PathBuf>,
    /// A known camera response (CSV).
    pub response: Option<PathBuf>,
    /// A dark frame.
    pub dark: Option<PathBuf>,
    /// The spot centre [x, y] px.
    #[serde(default, deserialize_with = "exact_array")]
    pub center_px: Option<[f64; 2]>,
    /// Diameter of the light spot \[mm\].
    pub spot_diameter_mm: Option<f64>,
    /// The spot's radial shape (default disk).
    pub spot_profile: Option<SpotProfileName>,
    /// An image of the spot on a thin opaque white target, radially averaged into the fit's kernel.
    pub spot_image: Option<PathBuf>,
    /// A frame of a uniform target (vignetting and pixel response), divided out.
    pub flat: Option<PathBuf>,
    /// The black level of linear frames (default auto).
    pub black_level: Option<BlackLevelSetting>,
    /// Veiling glare / stray light (default auto: estimated and subtracted).
    pub background: Option<AutoOrNone>,
    /// Shutter times estimated from the frames (default auto).
    pub exposure_correction: Option<ExposureCorrection>,
    /// The code at which a 16-bit or RAW camera clips, in 2…65535 (e.g. 4095 for 12-bit data in
    /// 16-bit files whose clipped pixels do not all read 4095): overrides the plateau found in the
    /// frames and the RAW white level. Not for 8-bit frames (they clip at 255).
    pub saturation: Option<u16>,
}

/// The largest g a `[fit] g_range` may reach (the grid the `mc` tables are built for ends at 0.95).
pub const G_RANGE_MAX: f64 = 0.95;

/// `[fit] g`: a known or assumed Henyey–Greenstein g, or `"fit"`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GSetting {
    /// A known or assumed g in (−1, 1): the models are evaluated at it.
    Value(f64),
    /// `"fit"`: g fitted per channel from the profile (where the data determine it).
    Fit,
}

impl GSetting {
    /// The number, for a [`GSetting::Value`].
    pub fn value(self) -> Option<f64> {
        match self {
            GSetting::Value(g) => Some(g),
            GSetting::Fit => None,
        }
    }

    /// True for `"fit"`.
    pub fn is_fit(self) -> bool {
        self == GSetting::Fit
    }
}

/// `fit`, or a finite number (its range, (−1, 1), is checked where the setting is used, with
/// the range of g beside it). The error says what was given and what is expected.
impl std::str::FromStr for GSetting {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        let t = text.trim();
        if t == "fit" {
            return Ok(GSetting::Fit);
        }
        match t.parse::<f64>() {
            Ok(g) if g.is_finite() => Ok(GSetting::Value(g)),
            _ => Err(format!(
                "`{text}` is neither a Henyey–Greenstein g in (−1, 1) nor `fit`"
            )),
        }
    }
}

impl std::fmt::Display for GSetting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GSetting::Value(g) => write!(f, "{g}"),
            GSetting::Fit => f.write_str("\"fit\""),
        }
    }
}

impl Serialize for GSetting {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            GSetting::Value(g) => s.serialize_f64(*g),
            GSetting::Fit => s.serialize_str("fit"),
        }
    }
}

impl<'de> Deserialize<'de> for GSetting {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = GSetting;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(
                    "a Henyey–Greenstein g in (−1, 1) (e.g. 0.85) or \"fit\" (fit g from the profile)",
                )
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<GSetting, E> {
                Ok(GSetting::Value(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<GSetting, E> {
                Ok(GSetting::Value(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<GSetting, E> {
                Ok(GSetting::Value(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<GSetting, E> {
                if v == "fit" {
                    Ok(GSetting::Fit)
                } else {
                    Err(E::invalid_value(serde::de::Unexpected::Str(v), &self))
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// `[fit]`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitSection {
    /// proposed | existing.
    pub method: Option<Method>,
    /// mc (the default: exact transport) | dipole (the paper's) | better-dipole | pbd.
    pub model: Option<ModelName>,
    /// diffusion | mc: how α′ is obtained from the spectrophotometer's Rd (default: the physics of
    /// `model`: mc for the mc model, else diffusion).
    pub albedo_model: Option<AlbedoModel>,
    /// Outermost profile radius \[px\] (default 300, the paper's).
    pub r_max_px: Option<f64>,
    /// Innermost fitted radius \[mm\] (default: the spot diameter).
    pub r_min_mm: Option<f64>,
    /// Fix the profile's scale by the spectrophotometer (proposed method).
    pub normalise_with_spectro: Option<bool>,
    /// The material's Henyey–Greenstein asymmetry g, known or assumed: the forward model
    /// and the α′ inversion are evaluated at it (σs = σ′s/(1 − g)). Default 0 — isotropic
    /// scattering, what the paper and the diffusion models assume; the diffusion dipoles do
    /// not depend on g, photon beam diffusion and the `mc` tables do (the tables cover g 0–0.95;
    /// another g with `mc` is refused with the tables' coverage). Real translucent
    /// materials have g ≈ 0.7–0.95: assuming 0 for them biases σa high (BENCHMARKS.md, "The `mc`
    /// model over g").
    ///
    /// `g = "fit"` ([`GSetting::Fit`]) fits g per channel from the profile instead (a 1-D profile
    /// likelihood over g with the `mc` model, which it needs: `model = "mc"`), within `g_range`
    /// (default: what the `mc` tables cover at the sample's η), and prints it only where the data
    /// determine it; elsewhere the channel gets the range's "± g" term (ARCHITECTURE.md, "Fitting
    /// g").
    pub g: Option<GSetting>,
    /// The range `[lo, hi]` (0 ≤ lo ≤ hi ≤ 0.95) the material's g is known to lie in:
    /// propagated into σ′s, σa and α′ as a separate "g" uncertainty term beside "fit" and
    /// "spectro", from the g-aware `mc` model. With `g`, the values are computed at `g` (which must
    /// lie in the range) and the term is the largest change of the estimate over the range;
    /// without, the values are the middle of the estimates over the range and the term half their
    /// spread. Absent with `g` given: g is known, the term is 0. **Absent with `g` absent (the
    /// default): the values stay at g = 0 and the term is propagated over 0–0.95** — an unstated g
    /// is not known, and real materials span that range: a σa computed at g = 0 for a
    /// forward-scattering material is 5–25 % high, which the term then shows.
    #[serde(default, deserialize_with = "exact_array")]
    pub g_range: Option<[f64; 2]>,
}

/// A parsed, checked `sample.toml`. Paths are as written (relative to [`SampleManifest::dir`]).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SampleManifest {
    /// The sample's name (default: the folder's name).
    pub name: Option<String>,
    /// `[spectro]`.
    #[serde(default)]
    pub spectro: SpectroSection,
    /// `[camera]`.
    #[serde(default)]
    pub camera: CameraSection,
    /// `[fit]`.
    #[serde(default)]
    pub fit: FitSection,
    /// The folder the manifest was read from (not in the file).
    #[serde(skip)]
    pub dir: PathBuf,
    /// The manifest file as [`read_manifest`] read it: its path and the SHA-256 of its bytes (not
    /// in the file; `None` for a manifest made in memory or parsed from text).
    #[serde(skip)]
    pub read_from: Option<crate::digest::ReadFile>,
}

impl SampleManifest {
    /// A path of the manifest resolved against its folder.
    pub fn resolve(&self, p: &Path) -> PathBuf {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.dir.join(p)
        }
    }

    /// Every file the manifest names, with its key (`spectro.file`, `camera.flat`, …), as
    /// written: what the input path policy ([`crate::inputs::InputPolicy::resolve`]) checks, one
    /// list so that no key is forgotten.
    pub fn named_paths(&self) -> Vec<(&'static str, &Path)> {
        let c = &self.camera;
        let single = [
            ("spectro.file", self.spectro.file.as_deref()),
            ("camera.exposures", c.exposures.as_deref()),
            ("camera.hdr", c.hdr.as_deref()),
            ("camera.response", c.response.as_deref()),
            ("camera.dark", c.dark.as_deref()),
            ("camera.spot_image", c.spot_image.as_deref()),
            ("camera.flat", c.flat.as_deref()),
        ];
        let mut out: Vec<(&'static str, &Path)> = single
            .into_iter()
            .filter_map(|(k, p)| p.map(|p| (k, p)))
            .collect();
        out.extend(
            c.images
                .iter()
                .flatten()
                .map(|p| ("camera.images", p.as_path())),
        );
        out
    }

    /// The sample's name, or the folder's.
    pub fn display_name(&self) -> String {
        self.name.clone().unwrap_or_else(|| {
            self.dir
                .file_name()
                .map_or_else(|| "sample".into(), |n| n.to_string_lossy().into_owned())
        })
    }
}

/// An optional array of exactly `N` numbers. serde's fixed-size arrays take the first `N`
/// elements of a longer TOML array and drop the rest without a word (`center_px = [412, 300, 7]`
/// would be read as [412, 300]); a number too many or too few is a mistake to name instead.
fn exact_array<'de, D, const N: usize>(d: D) -> Result<Option<[f64; N]>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    let v: Option<Vec<f64>> = Option::deserialize(d)?;
    v.map(|v| {
        <[f64; N]>::try_from(v.as_slice()).map_err(|_| {
            serde::de::Error::custom(format!(
                "must be exactly {N} numbers, but {} are given (none is dropped silently); write \
                 [{}]",
                v.len(),
                vec!["…"; N].join(", ")
            ))
        })
    })
    .transpose()
}

/// Longest sample name accepted \[characters\]: a name is shown in tables, plots and exports.
pub const MAX_NAME_CHARS: usize = 200;

/// The manifest's file name in a sample folder.
pub const MANIFEST_NAME: &str = "sample.toml";

/// Reads and checks `dir/sample.toml` (or a manifest file given directly).
///
/// # Errors
/// [`ManifestError`] naming the file and the key.
pub fn read_manifest(path_or_dir: &Path) -> Result<SampleManifest, ManifestError> {
    let path = if path_or_dir.is_dir() {
        path_or_dir.join(MANIFEST_NAME)
    } else {
        path_or_dir.to_path_buf()
    };
    // Through the text reader every text file uses: a regular file of at most 64 MiB, UTF-8 (with or
    // without BOM), UTF-16 with BOM, or Windows-1252.
    let text = crate::text::read_text_file(&path).map_err(|e| match e {
        crate::text::TextError::Io { path, source } => ManifestError::Read {
            hint: if source.kind() == std::io::ErrorKind::NotFound {
                not_found_hint(&path)
            } else {
                String::new()
            },
            path,
            source,
        },
        other => ManifestError::Text(other),
    })?;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf();
    let mut manifest = parse_manifest(&text.text, &path, dir)?;
    manifest.read_from = Some(crate::digest::ReadFile {
        path,
        sha256: text.sha256,
    });
    Ok(manifest)
}

/// What to say when the manifest is not there: a file that looks like a misspelt one
/// (`Sample.toml`, `sample.TOML`, `sample.toml.txt`) is named; else what a sample folder holds.
fn not_found_hint(path: &Path) -> String {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let misspelt = std::fs::read_dir(dir).ok().and_then(|entries| {
        entries.flatten().map(|e| e.file_name()).find(|n| {
            let l = n.to_string_lossy().to_lowercase();
            n != MANIFEST_NAME
                && (l.starts_with("sample.toml")
                    || (l.starts_with("sample") && (l.ends_with(".toml") || l.ends_with(".tml"))))
        })
    });
    match misspelt {
        Some(n) => format!(
            " — the folder holds {}: rename it to exactly sample.toml (names are case-sensitive)",
            crate::escape::token(&n.to_string_lossy())
        ),
        None => " — a sample folder holds a sample.toml naming its spectro file and bracket (see \
                 `scatterfit synth` for a complete example folder)"
            .into(),
    }
}

/// Parses and checks manifest text; `path` names it in messages, `dir` resolves its paths.
///
/// # Errors
/// [`ManifestError`] naming the file and the key.
pub fn parse_manifest(
    text: &str,
    path: &Path,
    dir: PathBuf,
) -> Result<SampleManifest, ManifestError> {
    let mut m = parse_toml(text).map_err(|message| ManifestError::Syntax {
        path: path.to_path_buf(),
        message,
    })?;
    m.dir = dir;
    let invalid = |key: &'static str, problem: String| ManifestError::Invalid {
        path: path.to_path_buf(),
        key,
        problem,
    };
    if m.spectro.file.is_none() && m.spectro.lab.is_none() {
        return Err(invalid(
            "spectro.file",
            "is missing: name the spectrophotometer CSV (SCI, SCE), or give `spectro.lab` and \
             `spectro.eta`"
                .into(),
        ));
    }
    if m.spectro.file.is_none() && m.spectro.eta.is_none() {
        return Err(invalid(
            "spectro.eta",
            "is needed when there is no spectro file: η comes from SCI − SCE".into(),
        ));
    }
    if let Some([l, a, b]) = m.spectro.lab
        && !((0.0..=100.0).contains(&l) && a.is_finite() && b.is_finite())
    {
        return Err(invalid(
            "spectro.lab",
            format!(
                "= [{}, {}, {}]: L* must lie in 0..100 and a*, b* be finite",
                num(l),
                num(a),
                num(b)
            ),
        ));
    }
    if let Some(o) = m.spectro.lab_observer
        && o != 2
        && o != 10
    {
        return Err(invalid(
            "spectro.lab_observer",
            format!("= {o}: the observer is 2 or 10 (degrees)"),
        ));
    }
    if let Some(eta) = m.spectro.eta
        && !(eta.is_finite() && (1.0..=3.0).contains(&eta))
    {
        return Err(invalid(
            "spectro.eta",
            format!(
                "= {}: the relative refractive index must lie in [1, 3]",
                num(eta)
            ),
        ));
    }
    if let Some(r) = m.spectro.repeatability
        && !(r.is_finite() && (0.0..=0.2).contains(&r))
    {
        return Err(invalid(
            "spectro.repeatability",
            format!(
                "= {}: the relative standard deviation of a reading must lie in [0, 0.2] \
                 (0.005 is 0.5 %; 0 ignores the spectrophotometer's uncertainty)",
                num(r)
            ),
        ));
    }
    for (key, d) in [
        ("spectro.aperture_mm", m.spectro.aperture_mm),
        ("spectro.illuminated_mm", m.spectro.illuminated_mm),
    ] {
        if let Some(d) = d
            && !(d.is_finite() && (0.5..=100.0).contains(&d))
        {
            return Err(invalid(
                key,
                format!(
                    "= {}: a port diameter in mm must lie in [0.5, 100] (d/8 instruments use 4, 8 \
                     or 25 mm)",
                    num(d)
                ),
            ));
        }
    }
    if m.spectro.illuminated_mm.is_some() && m.spectro.aperture_mm.is_none() {
        return Err(invalid(
            "spectro.illuminated_mm",
            "is given without spectro.aperture_mm: give the measured area's diameter too (or \
             remove illuminated_mm to take the reading as loss-free)"
                .to_string(),
        ));
    }
    match m.camera.mm_per_pixel {
        None => {
            return Err(invalid(
                "camera.mm_per_pixel",
                "is missing: give the image scale on the sample in mm per pixel (photograph a \
                 ruler at the sample plane)"
                    .into(),
            ));
        }
        Some(v) if !(v.is_finite() && v > 0.0 && v < 100.0) => {
            return Err(invalid(
                "camera.mm_per_pixel",
                format!("= {}: must be a number in (0, 100) mm per pixel", num(v)),
            ));
        }
        Some(_) => {}
    }
    if let Some(name) = &m.name
        && name.chars().count() > MAX_NAME_CHARS
    {
        return Err(invalid(
            "name",
            format!(
                "is {} characters long; a sample's name is shown in tables, plots and exports — \
                 keep it within {MAX_NAME_CHARS}",
                name.chars().count()
            ),
        ));
    }
    if let Some(images) = &m.camera.images
        && images.len() > crate::bracket::MAX_FRAMES
    {
        return Err(invalid(
            "camera.images",
            format!(
                "lists {} frames; a bracket needs a dozen or so (each frame is decoded whole), at \
                 most {}",
                images.len(),
                crate::bracket::MAX_FRAMES
            ),
        ));
    }
    if m.camera.hdr.is_none() && m.camera.exposures.is_none() && m.camera.images.is_none() {
        return Err(invalid(
            "camera.exposures",
            "is missing: name the exposures CSV (file,time_s), list `camera.images` (times from \
             EXIF), or give a merged `camera.hdr`"
                .into(),
        ));
    }
    if m.camera.hdr.is_some()
        && (m.camera.exposures.is_some() || m.camera.images.is_some() || m.camera.dark.is_some())
    {
        return Err(invalid(
            "camera.hdr",
            "is given together with a bracket (exposures/images/dark): give one or the other"
                .into(),
        ));
    }
    if let Some(d) = m.camera.spot_diameter_mm
        && !(d.is_finite() && d > 0.0 && d <= 20.0)
    {
        return Err(invalid(
            "camera.spot_diameter_mm",
            format!("= {}: must be a number in (0, 20] mm", num(d)),
        ));
    }
    if m.camera.spot_image.is_some() && m.camera.spot_profile.is_some() {
        return Err(invalid(
            "camera.spot_image",
            "is given together with `camera.spot_profile`: the image is the spot's profile; give \
             one or the other"
                .into(),
        ));
    }
    match m.camera.black_level {
        Some(BlackLevelSetting::One(v)) if !(v.is_finite() && (0.0..65535.0).contains(&v)) => {
            return Err(invalid(
                "camera.black_level",
                format!(
                    "= {}: a black level is a raw value in [0, 65535) DN, or \"auto\"/\"none\"",
                    num(v)
                ),
            ));
        }
        Some(BlackLevelSetting::PerChannel(v))
            if v.iter()
                .any(|v| !(v.is_finite() && (0.0..65535.0).contains(v))) =>
        {
            return Err(invalid(
                "camera.black_level",
                format!("= {v:?}: each channel's black level must lie in [0, 65535) DN"),
            ));
        }
        _ => {}
    }
    if m.camera.hdr.is_some()
        && (m.camera.black_level.is_some()
            || m.camera.exposure_correction.is_some()
            || m.camera.saturation.is_some())
    {
        return Err(invalid(
            "camera.hdr",
            "is a merged radiance map: `black_level`, `exposure_correction` and `saturation` apply \
             to a bracket"
                .into(),
        ));
    }
    if let Some(s) = m.camera.saturation
        && s < 2
    {
        return Err(invalid(
            "camera.saturation",
            format!("= {s}: the code where the camera clips must lie in 2…65535"),
        ));
    }
    if let Some([x, y]) = m.camera.center_px
        && !(x.is_finite() && y.is_finite())
    {
        return Err(invalid(
            "camera.center_px",
            "must be two finite numbers [x, y]".into(),
        ));
    }
    if let Some(r) = m.fit.r_max_px
        && !(r.is_finite() && (2.0..=1e5).contains(&r))
    {
        return Err(invalid(
            "fit.r_max_px",
            format!("= {}: must be a number of pixels in [2, 100000]", num(r)),
        ));
    }
    if let Some(r) = m.fit.r_min_mm
        && !(r.is_finite() && r >= 0.0)
    {
        return Err(invalid(
            "fit.r_min_mm",
            format!("= {}: must be ≥ 0 mm", num(r)),
        ));
    }
    if let Some(g) = m.fit.g.and_then(GSetting::value)
        && !(g.is_finite() && g > -1.0 && g < 1.0)
    {
        return Err(invalid(
            "fit.g",
            format!(
                "= {}: the Henyey–Greenstein g must lie in (−1, 1) (0: isotropic; real translucent \
                 materials 0.7–0.95)",
                num(g)
            ),
        ));
    }
    if let Some([lo, hi]) = m.fit.g_range {
        if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo <= hi && hi <= G_RANGE_MAX) {
            return Err(invalid(
                "fit.g_range",
                format!(
                    "= [{}, {}]: must be [lo, hi] with 0 ≤ lo ≤ hi ≤ {G_RANGE_MAX} (the Henyey–Greenstein \
                     g of real translucent materials: about 0.7–0.95; leave it out for the default \
                     0–{G_RANGE_MAX})",
                    num(lo),
                    num(hi)
                ),
            ));
        }
        if let Some(g) = m.fit.g.and_then(GSetting::value)
            && !(lo..=hi).contains(&g)
        {
            return Err(invalid(
                "fit.g",
                format!(
                    "= {}: lies outside fit.g_range = [{}, {}]; give a g inside the range, or \
                     drop one of the two",
                    num(g),
                    num(lo),
                    num(hi)
                ),
            ));
        }
    }
    if m.fit.normalise_with_spectro == Some(true) && m.fit.method == Some(Method::Existing) {
        return Err(invalid(
            "fit.normalise_with_spectro",
            "applies to the proposed method only (the existing method has no α′)".into(),
        ));
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<SampleManifest, ManifestError> {
        parse_manifest(text, Path::new("s/sample.toml"), PathBuf::from("s"))
    }

    const GOOD: &str = r#"
name = "pink plastic"
[spectro]
file = "spectro.csv"
[camera]
exposures = "exposures.csv"
mm_per_pixel = 0.05
spot_diameter_mm = 1.0
[fit]
method = "existing"
model = "dipole"
r_max_px = 300
"#;

    /// Fixed-size arrays with a number too many or too few are refused (serde alone would drop
    /// the extra ones); an overlong name and more frames than a bracket has are refused.
    #[test]
    fn arrays_names_and_frame_lists_are_bounded() {
        for (key, line) in [
            ("center_px", "center_px = [320, 240, 7]"),
            ("center_px", "center_px = [320]"),
            ("g_range", "g_range = [0.1, 0.5, 0.9]"),
        ] {
            let text = if key == "g_range" {
                GOOD.replace("[fit]\n", &format!("[fit]\n{line}\n"))
            } else {
                GOOD.replace("[camera]\n", &format!("[camera]\n{line}\n"))
            };
            let e = parse(&text).unwrap_err().to_string();
            assert!(e.contains("exactly 2 numbers"), "{line}: {e}");
        }
        let lab = GOOD.replace("[spectro]\n", "[spectro]\nlab = [50, 10, 10, 99]\n");
        let e = parse(&lab).unwrap_err().to_string();
        assert!(e.contains("exactly 3 numbers"), "{e}");
        let ok = GOOD.replace("[camera]\n", "[camera]\ncenter_px = [320, 240]\n");
        assert_eq!(parse(&ok).unwrap().camera.center_px, Some([320.0, 240.0]));
        let long = GOOD.replace("pink plastic", &"x".repeat(MAX_NAME_CHARS + 1));
        let e = parse(&long).unwrap_err().to_string();
        assert!(e.contains("201 characters"), "{e}");
        let frames: Vec<String> = (0..=crate::bracket::MAX_FRAMES)
            .map(|i| format!("\"f{i}.png\""))
            .collect();
        let many = GOOD.replace(
            "exposures = \"exposures.csv\"",
            &format!("images = [{}]", frames.join(", ")),
        );
        let e = parse(&many).unwrap_err().to_string();
        assert!(
            e.contains("camera.images") && e.contains("65 frames"),
            "{e}"
        );
    }

    /// The documented example parses; what is written reads back the same, every `[fit]` key
    /// included — with values that differ from the defaults, so a writer that dropped one (and let
    /// the reader fall back to its default) would fail here.
    #[test]
    fn round_trip() {
        let m = parse(GOOD).unwrap();
        assert_eq!(m.fit.method, Some(Method::Existing));
        assert_eq!(
            m.resolve(Path::new("spectro.csv")),
            PathBuf::from("s/spectro.csv")
        );
        let mut m = m;
        m.spectro.repeatability = Some(0.01);
        m.spectro.aperture_mm = Some(8.0);
        m.spectro.illuminated_mm = Some(14.0);
        m.camera.center_px = Some([101.5, 99.25]);
        m.camera.saturation = Some(4095);
        m.fit = FitSection {
            method: Some(Method::Existing),
            model: Some(ModelName::Pbd),
            albedo_model: Some(AlbedoModel::Mc),
            r_max_px: Some(250.0),
            r_min_mm: Some(1.5),
            normalise_with_spectro: Some(false),
            g: Some(GSetting::Value(0.85)),
            g_range: Some([0.7, 0.95]),
        };
        // None of these is what an absent key means.
        assert_ne!(m.fit.model.unwrap(), ModelName::default());
        assert_ne!(m.fit.method.unwrap(), Method::default());
        assert_ne!(
            m.fit.albedo_model.unwrap(),
            AlbedoModel::default_for(m.fit.model.unwrap())
        );
        let text = manifest_to_toml(&m, "made by a test");
        let back = parse(&text).unwrap();
        assert_eq!(back.spectro, m.spectro);
        assert_eq!(back.camera, m.camera);
        assert_eq!(back.fit, m.fit, "{text}");
        assert_eq!(back.name, m.name);
        // `g = "fit"` too.
        let mut fitted = m.clone();
        fitted.fit.g = Some(GSetting::Fit);
        let text = manifest_to_toml(&fitted, "");
        assert!(text.contains("g = \"fit\""), "{text}");
        assert_eq!(parse(&text).unwrap().fit, fitted.fit);
        // Every model and albedo model survives the round trip.
        for model in ModelName::ALL {
            for albedo in AlbedoModel::ALL {
                m.fit.model = Some(model);
                m.fit.albedo_model = Some(albedo);
                let back = parse(&manifest_to_toml(&m, "")).unwrap();
                assert_eq!(
                    (back.fit.model, back.fit.albedo_model),
                    (Some(model), Some(albedo))
                );
            }
        }
    }

    /// Each mistake names the key and says what to do.
    #[test]
    fn mistakes_name_the_key() {
        let cases: [(&str, &str); 15] = [
            (
                &GOOD.replace("mm_per_pixel = 0.05", "mm_per_pixel = -1"),
                "camera.mm_per_pixel",
            ),
            (
                &GOOD.replace("mm_per_pixel = 0.05", ""),
                "camera.mm_per_pixel",
            ),
            (
                &GOOD.replace("mm_per_pixel = 0.05", "mm_per_pixel = \"0.05\""),
                "mm_per_pixel",
            ),
            (
                &GOOD.replace("method = \"existing\"", "method = \"proposd\""),
                "proposd",
            ),
            (
                &GOOD.replace("model = \"dipole\"", "modle = \"dipole\""),
                "modle",
            ),
            (&GOOD.replace("file = \"spectro.csv\"", ""), "spectro.file"),
            (
                &GOOD.replace("exposures = \"exposures.csv\"", ""),
                "camera.exposures",
            ),
            (
                &GOOD.replace("r_max_px = 300", "r_max_px = 0"),
                "fit.r_max_px",
            ),
            (
                &GOOD.replace("r_max_px = 300", "r_max_px = 300\ng = 1.0"),
                "fit.g",
            ),
            (
                &GOOD.replace("r_max_px = 300", "r_max_px = 300\ng = \"fitt\""),
                "`fit.g`: invalid value: string \"fitt\", expected a Henyey–Greenstein g in (−1, 1) (e.g. 0.85) or \"fit\"",
            ),
            (
                &GOOD.replace("r_max_px = 300", "r_max_px = 300\ng = true"),
                "or \"fit\"",
            ),
            (
                &GOOD.replace("r_max_px = 300", "r_max_px = 300\ng_range = [0.9, 0.7]"),
                "fit.g_range",
            ),
            (
                &GOOD.replace("r_max_px = 300", "r_max_px = 300\ng_range = [0.7, 0.99]"),
                "fit.g_range",
            ),
            (
                &GOOD.replace("r_max_px = 300", "r_max_px = 300\ng_range = [0.7]"),
                "g_range",
            ),
            (
                &GOOD.replace(
                    "r_max_px = 300",
                    "r_max_px = 300\ng = 0.5\ng_range = [0.7, 0.9]",
                ),
                "fit.g",
            ),
        ];
        for (text, key) in cases {
            let err = parse(text).unwrap_err().to_string();
            assert!(err.contains(key), "{key}: {err}");
            assert!(err.contains("sample.toml"), "{err}");
        }
    }

    /// The content rule: a file that is not a manifest (a password file, a TOML file of another
    /// program) is named with a line and column, and nothing of its content is shown.
    #[test]
    fn content_of_a_file_that_is_not_a_manifest_is_never_shown() {
        for (text, line) in [
            ("root:$6$SECRETHASH:19000:0:99999:7:::\nbin:*:1\n", 1),
            ("name = \"x\"\ntoken = \"SECRETVALUE\"\n", 2),
            ("[registry]\ntoken = \"SECRETVALUE\"\n", 1),
            ("SECRETKEY = 1\n", 1),
            ("a = \"SECRET\nVALUE\"\n", 2),
            ("\"SECRET\" = [1, 2\n", 1),
        ] {
            let err = parse(text).unwrap_err().to_string();
            assert!(!err.contains("SECRET"), "{text:?}: {err}");
            assert!(!err.contains("token") && !err.contains("registry"), "{err}");
            assert!(err.contains(&format!("line {line}, column")), "{err}");
            assert!(err.contains("s/sample.toml"), "{err}");
        }
    }

    /// A mistake under a table header that carries a comment (as `scatterfit synth` writes them:
    /// `[fit]   # every key optional`) is named by its dotted key, not by the header's line.
    #[test]
    fn a_commented_table_header_names_the_key() {
        let text = GOOD.replace(
            "[fit]",
            "[fit]                         # every key optional",
        );
        let err = parse(&text.replace("model = \"dipole\"", "model = \"mcx\""))
            .unwrap_err()
            .to_string();
        assert!(err.contains("`fit.model`"), "{err}");
        assert!(!err.contains("every key"), "{err}");
    }

    /// A recognised manifest's mistakes quote the key and value, shortened and escaped.
    #[test]
    fn recognised_mistakes_quote_short_escaped_tokens() {
        let long = "d".repeat(200);
        let err = parse(&GOOD.replace("model = \"dipole\"", &format!("model = \"{long}\"")))
            .unwrap_err()
            .to_string();
        assert!(err.contains(&format!("`{}…`", "d".repeat(40))), "{err}");
        assert!(!err.contains(&"d".repeat(41)), "{err}");
        assert!(err.contains("fit.model"), "{err}");
        let err = parse(&GOOD.replace("model = \"dipole\"", "model = \"\\u001b[31mred\""))
            .unwrap_err()
            .to_string();
        assert!(!err.contains('\u{1b}'), "{err:?}");
        // A number from the file is shown with at most 6 significant digits.
        let err = parse(&GOOD.replace("mm_per_pixel = 0.05", "mm_per_pixel = 1e300"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("= 1e300:"), "{err}");
        let err = parse(
            &GOOD
                .replace("eta", "x")
                .replace("[spectro]", "[spectro]\neta = 3.14159265358979"),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("= 3.14159:"), "{err}");
    }

    /// `sample.toml` in UTF-16 (with BOM) or Windows-1252 reads like every other text file.
    #[test]
    fn utf16_and_windows_1252_manifests_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let text = GOOD.replace("pink plastic", "Probe grün, 23 °C");
        let mut utf16 = vec![0xFF, 0xFE];
        for u in text.encode_utf16() {
            utf16.extend(u.to_le_bytes());
        }
        let latin1: Vec<u8> = text.chars().map(|c| c as u32 as u8).collect();
        for bytes in [utf16, latin1, text.as_bytes().to_vec()] {
            std::fs::write(dir.path().join(MANIFEST_NAME), &bytes).unwrap();
            let m = read_manifest(dir.path()).unwrap();
            assert_eq!(m.name.as_deref(), Some("Probe grün, 23 °C"));
            // The record names the file read and the hash of its bytes as they were read.
            let read = m.read_from.expect("read from a file");
            assert_eq!(read.path, dir.path().join(MANIFEST_NAME));
            assert_eq!(read.sha256, crate::digest::sha256_hex(&bytes));
        }
    }

    /// A manifest that is a FIFO or a device is refused at once, naming it.
    #[cfg(unix)]
    #[test]
    fn special_files_are_refused() {
        let e = read_manifest(Path::new("/dev/zero"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("character device"), "{e}");
    }
}
