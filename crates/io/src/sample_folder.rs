//! Writing a complete sample folder — `sample.toml`, `spectro.csv`, the bracket's PNG frames with
//! `exposures.csv`, and an optional `truth.json` — exactly as the rig would leave it (the rig twin
//! and the demo use it; `scatterfit measure` reads it back).

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use scatterfit_imaging::ImageBuf;
use scatterfit_optics::spectro::SpectroReading;

use crate::image_files::CameraFrame;
use crate::manifest::{CameraSection, FitSection, SampleManifest, SpectroSection};

/// What goes into a sample folder.
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
    /// Their shutter times [s].
    pub times_s: &'a [f64],
    /// Image scale [mm per pixel].
    pub mm_per_pixel: f64,
    /// The light spot's diameter [mm].
    pub spot_diameter_mm: f64,
    /// `truth.json` content, when the sample is synthetic.
    pub truth_json: Option<&'a str>,
    /// A line saying where the folder came from (top of the manifest and the spectro CSV).
    pub provenance: &'a str,
    /// The manifest's `[fit]` (default: every key at its default).
    pub fit: FitSection,
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

/// What a real camera adds to a sample folder (issue 16): linear frames instead of the 8-bit ones, a
/// flat frame, a spot image, and the `[camera]` keys that name them. Default: nothing.
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
/// The first I/O or encoding error, naming the file.
pub fn write_sample_folder(dir: &Path, s: &SampleFiles<'_>) -> Result<Vec<PathBuf>, String> {
    write_sample_folder_with(dir, s, &CameraFiles::default())
}

/// [`write_sample_folder`] with a real camera's files ([`CameraFiles`]).
///
/// # Errors
/// The first I/O or encoding error, naming the file.
pub fn write_sample_folder_with(
    dir: &Path,
    s: &SampleFiles<'_>,
    extra: &CameraFiles,
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let mut written = Vec::new();
    let spectro = dir.join("spectro.csv");
    crate::spectro::write_spectro_csv(&spectro, s.reading, s.provenance)
        .map_err(|e| e.to_string())?;
    written.push(spectro);
    let names: Vec<String> = if extra.frames_u16.is_empty() {
        let names = frame_names(s.frames.len(), false);
        s.frames.par_iter().zip(&names).try_for_each(|(f, name)| {
            crate::image_files::write_camera_frame(&dir.join(name), &CameraFrame::U8(f.clone()))
                .map_err(|e| e.to_string())
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
                )
                .map_err(|e| e.to_string()),
                None => crate::image_files::write_camera_frame(
                    &dir.join(name),
                    &CameraFrame::U16(f.clone()),
                )
                .map_err(|e| e.to_string()),
            })?;
        names
    };
    written.extend(names.iter().map(|n| dir.join(n)));
    for (name, frame) in [("flat.png", &extra.flat), ("spot.png", &extra.spot_image)] {
        if let Some(f) = frame {
            let path = dir.join(name);
            crate::image_files::write_camera_frame(&path, f).map_err(|e| e.to_string())?;
            written.push(path);
        }
    }
    let exposures = dir.join("exposures.csv");
    let entries: Vec<(String, f64)> = names
        .iter()
        .cloned()
        .zip(s.times_s.iter().copied())
        .collect();
    crate::bracket::write_exposures_csv(&exposures, &entries).map_err(|e| e.to_string())?;
    written.push(exposures);
    if let Some(truth) = s.truth_json {
        let path = dir.join("truth.json");
        crate::atomic::write_atomic(&path, truth.as_bytes())
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        written.push(path);
    }
    let manifest = SampleManifest {
        name: Some(s.name.to_string()),
        spectro: SpectroSection {
            file: Some("spectro.csv".into()),
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
    };
    let mut comment = s.provenance.to_string();
    if let Some([l, a, b]) = s.lab10 {
        comment.push_str(&format!(
            "\nThe instrument's L*a*b* (D65, 10°): [{l:.2}, {a:.2}, {b:.2}]. To use it for the colour \
             instead of the SCE spectrum, add under [spectro]:\n  lab = [{l:.2}, {a:.2}, {b:.2}]\n  lab_observer = 10"
        ));
    }
    let path = dir.join(crate::manifest::MANIFEST_NAME);
    crate::manifest::write_manifest(&path, &manifest, &comment).map_err(|e| e.to_string())?;
    written.push(path);
    Ok(written)
}
