//! Writing a complete sample folder — `sample.toml`, `spectro.csv`, the bracket's PNG frames with
//! `exposures.csv`, and an optional `truth.json` — exactly as the rig would leave it (the rig twin
//! and the demo use it; `scatterfit measure` reads it back).

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use scatterfit_imaging::ImageBuf;
use scatterfit_optics::spectro::SpectroReading;

use crate::image_files::{CameraFrame, ImageFileError};
use crate::manifest::{CameraSection, FitSection, ManifestError, SampleManifest, SpectroSection};
use crate::spectro::SpectroCsvError;

/// Why a sample folder could not be written. Each names the file (or the setting) and what to do.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SampleFolderError {
    /// A setting the folder cannot be written with (no frames, times that do not match them, a
    /// missing or non-positive image scale…).
    #[error("sample folder `{name}`: {field}: {detail}")]
    Invalid {
        /// The sample's name.
        name: String,
        /// The setting, as its builder method is named (`bracket`, `mm_per_pixel`, …).
        field: &'static str,
        /// What was wrong and what to do.
        detail: String,
    },
    /// The folder could not be created.
    #[error("cannot create {}: {source}", path.display())]
    CreateDir {
        /// The folder.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The spectrophotometer CSV could not be written.
    #[error(transparent)]
    Spectro(#[from] SpectroCsvError),
    /// A frame could not be encoded or written.
    #[error(transparent)]
    Frame(#[from] ImageFileError),
    /// The manifest could not be written.
    #[error(transparent)]
    Manifest(#[from] ManifestError),
}

/// What goes into a sample folder. Build it with [`SampleFiles::new`] and the setters, then
/// [`SampleFiles::write`]:
///
/// ```no_run
/// # fn demo(reading: &scatterfit_optics::spectro::SpectroReading,
/// #         frames: &[scatterfit_imaging::ImageBuf<u8>], times: &[f64])
/// #         -> Result<(), scatterfit_io::sample_folder::SampleFolderError> {
/// use scatterfit_io::sample_folder::SampleFiles;
///
/// let written = SampleFiles::new("pink plastic", reading)
///     .bracket(frames, times) // 8-bit RGB frames, shortest exposure first; shutter times [s]
///     .mm_per_pixel(0.1)
///     .spot_diameter_mm(1.0)
///     .provenance("measured on the lab rig, 2026-11-24")
///     .write(std::path::Path::new("samples/pink-plastic"))?;
/// # Ok(()) }
/// ```
#[derive(Debug, Clone)]
pub struct SampleFiles<'a> {
    /// The sample's name.
    pub name: &'a str,
    /// The spectrophotometer reading.
    pub reading: &'a SpectroReading,
    /// The instrument's L\*a\*b\* (D65, 10°), written to the manifest as a comment (the SCE
    /// spectrum is the colour used; the comment shows how to use the instrument's Lab instead).
    pub lab10: Option<[f64; 3]>,
    /// 8-bit RGB frames, shortest exposure first.
    pub frames: &'a [ImageBuf<u8>],
    /// Their shutter times \[s\].
    pub times_s: &'a [f64],
    /// Image scale \[mm per pixel\].
    pub mm_per_pixel: f64,
    /// The light spot's diameter \[mm\].
    pub spot_diameter_mm: f64,
    /// `truth.json` content, when the sample is synthetic.
    pub truth_json: Option<&'a str>,
    /// A line saying where the folder came from (top of the manifest and the spectro CSV).
    pub provenance: &'a str,
    /// The manifest's `[fit]` (default: every key at its default).
    pub fit: FitSection,
}

impl<'a> SampleFiles<'a> {
    /// A sample named `name` with its spectrophotometer reading; give the bracket
    /// ([`SampleFiles::bracket`]) and the image scale ([`SampleFiles::mm_per_pixel`]) before
    /// writing. The spot diameter defaults to 1 mm (the manifest's default), `[fit]` to its
    /// defaults, the rest to none.
    #[must_use]
    pub fn new(name: &'a str, reading: &'a SpectroReading) -> Self {
        Self {
            name,
            reading,
            lab10: None,
            frames: &[],
            times_s: &[],
            mm_per_pixel: f64::NAN,
            spot_diameter_mm: 1.0,
            truth_json: None,
            provenance: "",
            fit: FitSection::default(),
        }
    }

    /// The exposure bracket: 8-bit RGB frames, shortest exposure first, and their shutter times
    /// \[s\].
    #[must_use]
    pub fn bracket(self, frames: &'a [ImageBuf<u8>], times_s: &'a [f64]) -> Self {
        Self {
            frames,
            times_s,
            ..self
        }
    }

    /// The image scale on the sample surface \[mm per pixel\].
    #[must_use]
    pub fn mm_per_pixel(self, mm_per_pixel: f64) -> Self {
        Self {
            mm_per_pixel,
            ..self
        }
    }

    /// The light spot's diameter \[mm\].
    #[must_use]
    pub fn spot_diameter_mm(self, spot_diameter_mm: f64) -> Self {
        Self {
            spot_diameter_mm,
            ..self
        }
    }

    /// The instrument's L\*a\*b\* (D65, 10°), noted in the manifest.
    #[must_use]
    pub fn lab10(self, lab: [f64; 3]) -> Self {
        Self {
            lab10: Some(lab),
            ..self
        }
    }

    /// `truth.json`'s content (a synthetic sample's parameters).
    #[must_use]
    pub fn truth_json(self, truth: &'a str) -> Self {
        Self {
            truth_json: Some(truth),
            ..self
        }
    }

    /// Where the folder came from (a comment on top of the manifest and the spectro CSV).
    #[must_use]
    pub fn provenance(self, provenance: &'a str) -> Self {
        Self { provenance, ..self }
    }

    /// The manifest's `[fit]` section.
    #[must_use]
    pub fn fit(self, fit: FitSection) -> Self {
        Self { fit, ..self }
    }

    /// Writes the folder ([`write_sample_folder`]).
    ///
    /// # Errors
    /// As [`write_sample_folder`].
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, SampleFolderError> {
        write_sample_folder(dir, self)
    }

    /// Refuses settings the folder cannot be written with, before any file is written.
    fn check(&self, frames: usize) -> Result<(), SampleFolderError> {
        let invalid = |field, detail: String| SampleFolderError::Invalid {
            name: crate::escape::token(self.name),
            field,
            detail,
        };
        if frames < 2 {
            return Err(invalid(
                "bracket",
                format!("{frames} frame(s): a bracket needs at least two exposures"),
            ));
        }
        if frames != self.times_s.len() {
            return Err(invalid(
                "bracket",
                format!(
                    "{frames} frames but {} shutter times: give one time per frame",
                    self.times_s.len()
                ),
            ));
        }
        if let Some(t) = self.times_s.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
            return Err(invalid(
                "bracket",
                format!(
                    "shutter time {}: must be a positive number of seconds",
                    crate::escape::number(*t)
                ),
            ));
        }
        if !(self.mm_per_pixel.is_finite() && self.mm_per_pixel > 0.0) {
            return Err(invalid(
                "mm_per_pixel",
                format!(
                    "{}: give the image scale on the sample, a positive number of mm per pixel",
                    crate::escape::number(self.mm_per_pixel)
                ),
            ));
        }
        if !(self.spot_diameter_mm.is_finite() && self.spot_diameter_mm > 0.0) {
            return Err(invalid(
                "spot_diameter_mm",
                format!(
                    "{}: the light spot's diameter must be a positive number of mm",
                    crate::escape::number(self.spot_diameter_mm)
                ),
            ));
        }
        Ok(())
    }
}

/// The files a sample folder holds, in the order written.
pub fn file_names(frames: usize, truth: bool) -> Vec<String> {
    let mut v = vec!["spectro.csv".to_string()];
    v.extend((0..frames).map(|j| format!("frame_{j:02}.png")));
    v.push("exposures.csv".into());
    if truth {
        v.push("truth.json".into());
    }
    v.push(crate::manifest::MANIFEST_NAME.into());
    v
}

/// What a real rig adds to a sample folder: linear frames instead of the 8-bit ones, a flat frame,
/// a spot image and the `[camera]` keys that name them, and the spectrophotometer's port. Default:
/// nothing.
#[derive(Debug, Clone, Default)]
pub struct CameraFiles {
    /// Linear 16-bit frames (written instead of [`SampleFiles::frames`] when not empty), shortest
    /// first, at [`SampleFiles::times_s`].
    pub frames_u16: Vec<ImageBuf<u16>>,
    /// Write `frames_u16` as DNG files (with these black and white levels and each frame's
    /// exposure time in the metadata) instead of 16-bit PNG.
    pub dng_levels: Option<([u16; 3], u16)>,
    /// A flat frame (`flat.png`, `camera.flat`).
    pub flat: Option<CameraFrame>,
    /// The spot on a thin opaque white target (`spot.png`, `camera.spot_image`).
    pub spot_image: Option<CameraFrame>,
    /// `camera.spot_profile` (e.g. "gaussian").
    pub spot_profile: Option<crate::manifest::SpotProfileName>,
    /// The spectrophotometer's port, [lit disc, aperture] diameters \[mm\]: written as
    /// `spectro.illuminated_mm` and `spectro.aperture_mm` (the reading was made through it).
    pub spectro_port_mm: Option<[f64; 2]>,
}

/// The frame files of a bracket of `frames` frames: `frame_NN.png`, or `.dng`.
fn frame_names(frames: usize, dng: bool) -> Vec<String> {
    let ext = if dng { "dng" } else { "png" };
    (0..frames).map(|j| format!("frame_{j:02}.{ext}")).collect()
}

/// Writes the folder (created if missing). Every file is written atomically; the manifest last, so
/// a folder with a `sample.toml` is complete.
///
/// # Errors
/// [`SampleFolderError::Invalid`] for settings it cannot be written with (checked before any
/// file is written); otherwise the first file that could not be written, named.
pub fn write_sample_folder(
    dir: &Path,
    s: &SampleFiles<'_>,
) -> Result<Vec<PathBuf>, SampleFolderError> {
    write_sample_folder_with(dir, s, &CameraFiles::default())
}

/// [`write_sample_folder`] with a real camera's files ([`CameraFiles`]).
///
/// # Errors
/// As [`write_sample_folder`].
pub fn write_sample_folder_with(
    dir: &Path,
    s: &SampleFiles<'_>,
    extra: &CameraFiles,
) -> Result<Vec<PathBuf>, SampleFolderError> {
    let frame_count = if extra.frames_u16.is_empty() {
        s.frames.len()
    } else {
        extra.frames_u16.len()
    };
    s.check(frame_count)?;
    std::fs::create_dir_all(dir).map_err(|source| SampleFolderError::CreateDir {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut written = Vec::new();
    let spectro = dir.join("spectro.csv");
    crate::spectro::write_spectro_csv(&spectro, s.reading, s.provenance)?;
    written.push(spectro);
    let names: Vec<String> = if extra.frames_u16.is_empty() {
        let names = frame_names(s.frames.len(), false);
        s.frames.par_iter().zip(&names).try_for_each(|(f, name)| {
            crate::image_files::write_camera_frame(&dir.join(name), &CameraFrame::U8(f.clone()))
        })?;
        names
    } else {
        let names = frame_names(extra.frames_u16.len(), extra.dng_levels.is_some());
        extra
            .frames_u16
            .par_iter()
            .zip(&names)
            .zip(s.times_s)
            .try_for_each(|((f, name), &t)| match extra.dng_levels {
                Some((black, white)) => crate::raw::write_dng(
                    &dir.join(name),
                    f,
                    &crate::raw::DngInfo {
                        black_level: black,
                        white_level: white,
                        exposure_time_s: t,
                    },
                ),
                None => crate::image_files::write_camera_frame(
                    &dir.join(name),
                    &CameraFrame::U16(f.clone()),
                ),
            })?;
        names
    };
    written.extend(names.iter().map(|n| dir.join(n)));
    for (name, frame) in [("flat.png", &extra.flat), ("spot.png", &extra.spot_image)] {
        if let Some(f) = frame {
            let path = dir.join(name);
            crate::image_files::write_camera_frame(&path, f)?;
            written.push(path);
        }
    }
    let exposures = dir.join("exposures.csv");
    let entries: Vec<(String, f64)> = names
        .iter()
        .cloned()
        .zip(s.times_s.iter().copied())
        .collect();
    crate::bracket::write_exposures_csv(&exposures, &entries).map_err(|source| {
        SampleFolderError::Write {
            path: exposures.clone(),
            source,
        }
    })?;
    written.push(exposures);
    if let Some(truth) = s.truth_json {
        let path = dir.join("truth.json");
        crate::atomic::write_atomic(&path, truth.as_bytes()).map_err(|source| {
            SampleFolderError::Write {
                path: path.clone(),
                source,
            }
        })?;
        written.push(path);
    }
    let manifest = SampleManifest {
        name: Some(s.name.to_string()),
        spectro: SpectroSection {
            file: Some("spectro.csv".into()),
            illuminated_mm: extra.spectro_port_mm.map(|p| p[0]),
            aperture_mm: extra.spectro_port_mm.map(|p| p[1]),
            ..Default::default()
        },
        camera: CameraSection {
            exposures: Some("exposures.csv".into()),
            mm_per_pixel: Some(s.mm_per_pixel),
            spot_diameter_mm: Some(s.spot_diameter_mm),
            flat: extra.flat.as_ref().map(|_| "flat.png".into()),
            spot_image: extra.spot_image.as_ref().map(|_| "spot.png".into()),
            spot_profile: extra.spot_profile,
            ..Default::default()
        },
        fit: s.fit.clone(),
        dir: dir.to_path_buf(),
        read_from: None,
    };
    let mut comment = s.provenance.to_string();
    if let Some([l, a, b]) = s.lab10 {
        comment.push_str(&format!(
            "\nThe instrument's L*a*b* (D65, 10°): [{l:.2}, {a:.2}, {b:.2}]. To use it for the colour \
             instead of the SCE spectrum, add under [spectro]:\n  lab = [{l:.2}, {a:.2}, {b:.2}]\n  lab_observer = 10"
        ));
    }
    let path = dir.join(crate::manifest::MANIFEST_NAME);
    crate::manifest::write_manifest(&path, &manifest, &comment)?;
    written.push(path);
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reading() -> SpectroReading {
        let wl: Vec<f64> = (40..=70).map(|k| 10.0 * f64::from(k)).collect();
        let sce = vec![0.5; wl.len()];
        let sci = vec![0.54; wl.len()];
        SpectroReading::new(wl, sci, sce).unwrap()
    }

    /// The builder's folder is what a manifest reader reads back (scale, spot, `[fit]`, the
    /// bracket through exposures.csv), and the files are listed in the order written.
    #[test]
    fn builder_writes_a_folder_the_reader_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let reading = reading();
        let frames = vec![ImageBuf::filled(8, 6, 3, 10u8).unwrap(); 3];
        let times = [0.01, 0.1, 1.0];
        let fit = FitSection {
            model: Some(scatterfit_optics::ModelName::Mc),
            ..FitSection::default()
        };
        let written = SampleFiles::new("a sample", &reading)
            .bracket(&frames, &times)
            .mm_per_pixel(0.25)
            .spot_diameter_mm(0.8)
            .provenance("test")
            .fit(fit.clone())
            .write(dir.path())
            .unwrap();
        let names: Vec<String> = written
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, file_names(3, false));
        let m = crate::manifest::read_manifest(dir.path()).unwrap();
        assert_eq!(m.name.as_deref(), Some("a sample"));
        assert_eq!(m.camera.mm_per_pixel, Some(0.25));
        assert_eq!(m.camera.spot_diameter_mm, Some(0.8));
        assert_eq!(m.fit.model, fit.model);
        let listed = crate::bracket::read_exposures_csv(&dir.path().join("exposures.csv")).unwrap();
        let listed_times: Vec<f64> = listed.iter().map(|e| e.time_s).collect();
        assert_eq!(listed_times, times);
    }

    /// Settings the folder cannot be written with are typed errors naming the setting, and
    /// nothing is written.
    #[test]
    fn bad_settings_are_refused_before_writing() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("s");
        let reading = reading();
        let frames = vec![ImageBuf::filled(4, 4, 3, 10u8).unwrap(); 2];
        let field = |r: Result<Vec<PathBuf>, SampleFolderError>| match r {
            Err(SampleFolderError::Invalid { field, .. }) => field,
            other => panic!("{other:?}"),
        };
        let base = SampleFiles::new("s", &reading).bracket(&frames, &[0.1, 1.0]);
        assert_eq!(field(base.clone().write(&target)), "mm_per_pixel");
        assert_eq!(
            field(
                base.clone()
                    .mm_per_pixel(0.1)
                    .spot_diameter_mm(0.0)
                    .write(&target)
            ),
            "spot_diameter_mm"
        );
        assert_eq!(
            field(
                base.clone()
                    .bracket(&frames, &[0.1])
                    .mm_per_pixel(0.1)
                    .write(&target)
            ),
            "bracket"
        );
        assert_eq!(
            field(
                SampleFiles::new("s", &reading)
                    .mm_per_pixel(0.1)
                    .write(&target)
            ),
            "bracket"
        );
        let err = base.write(&target).unwrap_err().to_string();
        assert!(err.contains("mm_per_pixel") && err.contains("`s`"), "{err}");
        assert!(!target.exists());
    }
}
