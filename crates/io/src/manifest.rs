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
//!
//! [fit]                         # every key optional, defaults shown
//! method = "proposed"           # proposed | existing
//! model = "dipole"              # dipole | better-dipole | pbd | mc
//! # albedo_model = "diffusion"  # diffusion | mc (default: mc for the mc model, else diffusion)
//! r_max_px = 300                # the paper's cut-off
//! ```
//!
//! Paths are relative to the manifest's folder. Unknown keys are refused (a misspelt key would
//! otherwise be ignored silently); every error names the file, the key and what to do.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

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
        hint: &'static str,
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
    /// The manifest could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// The fitting method named in a manifest.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MethodName {
    /// Choi, Lee & Chin 2014: α′ from the spectrophotometer, σ′s (and the scale) fitted.
    #[default]
    Proposed,
    /// Jensen et al. 2001: σ′s, σa (and the scale) fitted.
    Existing,
}

/// The forward model named in a manifest.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModelName {
    /// The classical dipole, Jensen et al. 2001.
    #[default]
    Dipole,
    /// d'Eon 2012, "A better dipole".
    BetterDipole,
    /// Photon beam diffusion, Habel et al. 2013.
    Pbd,
    /// Monte Carlo profile tables.
    Mc,
}

/// How α′ is obtained from the spectrophotometer's diffuse reflectance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AlbedoModelName {
    /// The diffusion model's own total Rd(α′, η) inverted (the dipole's closed form for the paper).
    Diffusion,
    /// The Monte Carlo tables' total Rd(α′, η) inverted ("by the Monte Carlo method", exactly).
    Mc,
}

impl AlbedoModelName {
    /// The name as written.
    pub fn as_str(self) -> &'static str {
        match self {
            AlbedoModelName::Diffusion => "diffusion",
            AlbedoModelName::Mc => "mc",
        }
    }
}

impl MethodName {
    /// The name as written.
    pub fn as_str(self) -> &'static str {
        match self {
            MethodName::Proposed => "proposed",
            MethodName::Existing => "existing",
        }
    }
}

impl ModelName {
    /// The name as written.
    pub fn as_str(self) -> &'static str {
        match self {
            ModelName::Dipole => "dipole",
            ModelName::BetterDipole => "better-dipole",
            ModelName::Pbd => "pbd",
            ModelName::Mc => "mc",
        }
    }
}

/// `[spectro]`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpectroSection {
    /// The SCI/SCE CSV.
    pub file: Option<PathBuf>,
    /// Measured L\*a\*b\* (D65) for the colour instead of the SCE spectrum.
    pub lab: Option<[f64; 3]>,
    /// Observer of `lab`: 10 (default) or 2.
    pub lab_observer: Option<u32>,
    /// A known η instead of the one from SCI − SCE.
    pub eta: Option<f64>,
    /// Relative standard deviation of a reading, the same factor on SCI and SCE at every
    /// wavelength (a re-placed sample, the calibration): what the uncertainties of η, α′ and,
    /// through them, σ′s and σa are propagated from. Default [`DEFAULT_SPECTRO_REPEATABILITY`].
    pub repeatability: Option<f64>,
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
    /// The same level [DN] for every channel.
    One(f64),
    /// A level [DN] per channel R, G, B.
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
    pub center_px: Option<[f64; 2]>,
    /// Diameter of the light spot [mm].
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
}

/// `[fit]`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitSection {
    /// proposed | existing.
    pub method: Option<MethodName>,
    /// dipole | better-dipole | pbd | mc.
    pub model: Option<ModelName>,
    /// diffusion | mc: how α′ is obtained from the spectrophotometer's Rd (default: the physics of
    /// `model`: mc for the mc model, else diffusion).
    pub albedo_model: Option<AlbedoModelName>,
    /// Outermost profile radius [px] (default 300, the paper's).
    pub r_max_px: Option<f64>,
    /// Innermost fitted radius [mm] (default: the spot diameter).
    pub r_min_mm: Option<f64>,
    /// Fix the profile's scale by the spectrophotometer (proposed method).
    pub normalise_with_spectro: Option<bool>,
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

    /// The sample's name, or the folder's.
    pub fn display_name(&self) -> String {
        self.name.clone().unwrap_or_else(|| {
            self.dir
                .file_name()
                .map_or_else(|| "sample".into(), |n| n.to_string_lossy().into_owned())
        })
    }
}

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
    let text = std::fs::read_to_string(&path).map_err(|source| ManifestError::Read {
        hint: if source.kind() == std::io::ErrorKind::NotFound {
            " — a sample folder holds a sample.toml naming its spectro file and bracket (see \
             `scatterfit synth` for a complete example folder)"
        } else {
            ""
        },
        path: path.clone(),
        source,
    })?;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf();
    parse_manifest(&text, &path, dir)
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
    let mut m: SampleManifest = toml::from_str(text).map_err(|e| ManifestError::Syntax {
        path: path.to_path_buf(),
        message: e.to_string().trim_end().replace('\n', "\n  "),
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
            format!("= [{l}, {a}, {b}]: L* must lie in 0..100 and a*, b* be finite"),
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
            format!("= {eta}: the relative refractive index must lie in [1, 3]"),
        ));
    }
    if let Some(r) = m.spectro.repeatability
        && !(r.is_finite() && (0.0..=0.2).contains(&r))
    {
        return Err(invalid(
            "spectro.repeatability",
            format!(
                "= {r}: the relative standard deviation of a reading must lie in [0, 0.2] \
                 (0.005 is 0.5 %; 0 ignores the spectrophotometer's uncertainty)"
            ),
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
                format!("= {v}: must be a number in (0, 100) mm per pixel"),
            ));
        }
        Some(_) => {}
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
            format!("= {d}: must be a number in (0, 20] mm"),
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
                    "= {v}: a black level is a raw value in [0, 65535) DN, or \"auto\"/\"none\""
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
        && (m.camera.black_level.is_some() || m.camera.exposure_correction.is_some())
    {
        return Err(invalid(
            "camera.hdr",
            "is a merged radiance map: `black_level` and `exposure_correction` apply to a bracket"
                .into(),
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
            format!("= {r}: must be a number of pixels in [2, 100000]"),
        ));
    }
    if let Some(r) = m.fit.r_min_mm
        && !(r.is_finite() && r >= 0.0)
    {
        return Err(invalid("fit.r_min_mm", format!("= {r}: must be ≥ 0 mm")));
    }
    if m.fit.normalise_with_spectro == Some(true) && m.fit.method == Some(MethodName::Existing) {
        return Err(invalid(
            "fit.normalise_with_spectro",
            "applies to the proposed method only (the existing method has no α′)".into(),
        ));
    }
    Ok(m)
}

fn toml_string(s: &str) -> String {
    // A TOML basic string: JSON's escaping is a subset TOML accepts.
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".into())
}

fn toml_path(p: &Path) -> String {
    toml_string(&p.to_string_lossy())
}

/// The manifest as TOML with the comments of the format's documentation, for a folder a person
/// will read (e.g. one written by `scatterfit synth`). `extra_comment` lines go at the top.
pub fn manifest_to_toml(m: &SampleManifest, extra_comment: &str) -> String {
    let mut t = String::new();
    for line in extra_comment.lines() {
        t.push_str(&format!("# {line}\n"));
    }
    if let Some(n) = &m.name {
        t.push_str(&format!("name = {}\n", toml_string(n)));
    }
    t.push_str("\n[spectro]\n");
    if let Some(f) = &m.spectro.file {
        t.push_str(&format!(
            "file = {}          # header: wavelength_nm,sci,sce (fractions 0..1)\n",
            toml_path(f)
        ));
    }
    if let Some([l, a, b]) = m.spectro.lab {
        t.push_str(&format!("lab = [{l:.2}, {a:.2}, {b:.2}]\n"));
    }
    if let Some(o) = m.spectro.lab_observer {
        t.push_str(&format!("lab_observer = {o}\n"));
    }
    if let Some(e) = m.spectro.eta {
        t.push_str(&format!("eta = {e}\n"));
    }
    if let Some(r) = m.spectro.repeatability {
        t.push_str(&format!("repeatability = {r}\n"));
    }
    t.push_str("\n[camera]\n");
    if let Some(f) = &m.camera.exposures {
        t.push_str(&format!(
            "exposures = {}   # header: file,time_s\n",
            toml_path(f)
        ));
    }
    if let Some(list) = &m.camera.images {
        let items: Vec<String> = list.iter().map(|p| toml_path(p)).collect();
        t.push_str(&format!("images = [{}]\n", items.join(", ")));
    }
    if let Some(v) = m.camera.mm_per_pixel {
        t.push_str(&format!(
            "mm_per_pixel = {v}            # image scale on the sample surface\n"
        ));
    }
    for (key, p) in [
        ("hdr", &m.camera.hdr),
        ("response", &m.camera.response),
        ("dark", &m.camera.dark),
    ] {
        if let Some(p) = p {
            t.push_str(&format!("{key} = {}\n", toml_path(p)));
        }
    }
    if let Some([x, y]) = m.camera.center_px {
        t.push_str(&format!("center_px = [{x}, {y}]\n"));
    }
    if let Some(d) = m.camera.spot_diameter_mm {
        t.push_str(&format!(
            "spot_diameter_mm = {d}        # the light spot on the sample\n"
        ));
    }
    if let Some(p) = m.camera.spot_profile {
        t.push_str(&format!("spot_profile = \"{}\"\n", p.as_str()));
    }
    for (key, p) in [
        ("spot_image", &m.camera.spot_image),
        ("flat", &m.camera.flat),
    ] {
        if let Some(p) = p {
            t.push_str(&format!("{key} = {}\n", toml_path(p)));
        }
    }
    match m.camera.black_level {
        Some(BlackLevelSetting::Mode(AutoOrNone::Auto)) => {
            t.push_str("black_level = \"auto\"\n");
        }
        Some(BlackLevelSetting::Mode(AutoOrNone::None)) => {
            t.push_str("black_level = \"none\"\n");
        }
        Some(BlackLevelSetting::One(v)) => t.push_str(&format!("black_level = {v}\n")),
        Some(BlackLevelSetting::PerChannel([r, g, b])) => {
            t.push_str(&format!("black_level = [{r}, {g}, {b}]\n"));
        }
        None => {}
    }
    if let Some(b) = m.camera.background {
        t.push_str(&format!(
            "background = \"{}\"\n",
            if b == AutoOrNone::Auto {
                "auto"
            } else {
                "none"
            }
        ));
    }
    if let Some(e) = m.camera.exposure_correction {
        t.push_str(&format!(
            "exposure_correction = \"{}\"\n",
            match e {
                ExposureCorrection::Auto => "auto",
                ExposureCorrection::Always => "always",
                ExposureCorrection::Never => "never",
            }
        ));
    }
    t.push_str("\n[fit]                         # every key optional\n");
    t.push_str(&format!(
        "method = \"{}\"           # proposed | existing\n",
        m.fit.method.unwrap_or_default().as_str()
    ));
    t.push_str(&format!(
        "model = \"{}\"              # dipole | better-dipole | pbd | mc\n",
        m.fit.model.unwrap_or_default().as_str()
    ));
    t.push_str(&format!(
        "r_max_px = {}                # the paper's cut-off\n",
        m.fit.r_max_px.unwrap_or(300.0)
    ));
    if let Some(r) = m.fit.r_min_mm {
        t.push_str(&format!("r_min_mm = {r}\n"));
    }
    if let Some(a) = m.fit.albedo_model {
        t.push_str(&format!("albedo_model = \"{}\"\n", a.as_str()));
    }
    if let Some(b) = m.fit.normalise_with_spectro {
        t.push_str(&format!("normalise_with_spectro = {b}\n"));
    }
    t
}

/// Writes [`manifest_to_toml`] atomically to `path`.
///
/// # Errors
/// [`ManifestError::Write`].
pub fn write_manifest(
    path: &Path,
    m: &SampleManifest,
    extra_comment: &str,
) -> Result<(), ManifestError> {
    crate::atomic::write_atomic(path, manifest_to_toml(m, extra_comment).as_bytes()).map_err(
        |source| ManifestError::Write {
            path: path.to_path_buf(),
            source,
        },
    )
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

    /// The documented example parses, and what is written reads back the same.
    #[test]
    fn round_trip() {
        let m = parse(GOOD).unwrap();
        assert_eq!(m.fit.method, Some(MethodName::Existing));
        assert_eq!(
            m.resolve(Path::new("spectro.csv")),
            PathBuf::from("s/spectro.csv")
        );
        let back = parse(&manifest_to_toml(&m, "made by a test")).unwrap();
        assert_eq!(back.spectro, m.spectro);
        assert_eq!(back.camera, m.camera);
        assert_eq!(back.fit.method, m.fit.method);
        assert_eq!(back.name, m.name);
    }

    /// Each mistake names the key and says what to do.
    #[test]
    fn mistakes_name_the_key() {
        let cases: [(&str, &str); 8] = [
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
        ];
        for (text, key) in cases {
            let err = parse(text).unwrap_err().to_string();
            assert!(err.contains(key), "{key}: {err}");
            assert!(err.contains("sample.toml"), "{err}");
        }
    }
}
