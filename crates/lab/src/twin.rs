//! A rig twin written as a sample folder: what `scatterfit synth`, the demo, the bias study and the
//! tests hand the measurement, in the same files a user's rig leaves (`sample.toml`, the spectro
//! file, the bracket, and where the twin has them a flat frame, a spot image, a port).

use std::path::{Path, PathBuf};

use scatterfit_io::image_files::CameraFrame;
use scatterfit_io::manifest::{FitSection, SpotProfileName};
use scatterfit_io::sample_folder::{
    CameraFiles, SampleFiles, SampleFolderError, write_sample_folder_with,
};
use scatterfit_synth::SyntheticSample;
use scatterfit_synth::rig::{Frame, SensorOutput};

/// How to write a twin's folder.
#[derive(Debug, Clone, Default)]
pub struct TwinFolder {
    /// The manifest's `[fit]` (the twin's g is never written into it: what the user states is the
    /// caller's choice).
    pub fit: FitSection,
    /// The manifest's first comment line: where the folder came from.
    pub provenance: String,
    /// Also write `truth.json`, the twin's parameters (the demo and `synth` do; a study's twin,
    /// standing for a user's rig, does not).
    pub with_truth: bool,
}

impl TwinFolder {
    /// A folder with `fit` as its `[fit]`, this provenance, and no truth.json.
    pub fn new(fit: FitSection, provenance: impl Into<String>) -> Self {
        Self {
            fit,
            provenance: provenance.into(),
            with_truth: false,
        }
    }

    /// The same, with truth.json.
    #[must_use]
    pub fn with_truth(self) -> Self {
        Self {
            with_truth: true,
            ..self
        }
    }
}

/// The provenance line `scatterfit synth` and the demo write.
pub fn synth_provenance(s: &SyntheticSample) -> String {
    format!(
        "synthetic sample `{}` made by `scatterfit synth` (Monte Carlo rig twin, seed {}); \
         truth.json holds the parameters",
        s.truth.name, s.truth.seed
    )
}

/// Writes the twin `s` into `dir` as a sample folder: its reading, its bracket (8-bit, or the
/// linear 16-bit / DNG frames of its camera with their levels), its flat frame, spot image and
/// spectrophotometer port where it has them, and `truth.json` when asked.
///
/// # Errors
/// The folder cannot be written ([`SampleFolderError`]).
pub fn write_twin_folder(
    dir: &Path,
    s: &SyntheticSample,
    how: &TwinFolder,
) -> Result<Vec<PathBuf>, SampleFolderError> {
    let truth = if how.with_truth {
        Some(
            serde_json::to_string_pretty(&s.truth).map_err(|e| SampleFolderError::Invalid {
                name: s.truth.name.clone(),
                field: "truth_json",
                detail: e.to_string(),
            })?,
        )
    } else {
        None
    };
    let frame = |f: &Frame| match f {
        Frame::U8(b) => CameraFrame::U8(b.clone()),
        Frame::U16(b) => CameraFrame::U16(b.clone()),
    };
    let rig = &s.truth.rig;
    let extra = CameraFiles {
        frames_u16: s.bracket.frames_u16.clone(),
        dng_levels: match rig.camera.output {
            SensorOutput::Linear {
                black_level,
                white_level,
            } if white_level < 65535.0 => Some((
                black_level.map(|b| b.round() as u16),
                white_level.round() as u16,
            )),
            _ => None,
        },
        flat: s.bracket.flat.as_ref().map(frame),
        spot_image: s.bracket.spot_image.as_ref().map(frame),
        spot_profile: (rig.effects.gaussian_spot && s.bracket.spot_image.is_none())
            .then_some(SpotProfileName::Gaussian),
        spectro_port_mm: s
            .truth
            .port
            .as_ref()
            .map(|p| [p.illuminated_mm, p.aperture_mm]),
    };
    write_sample_folder_with(
        dir,
        &SampleFiles {
            name: &s.truth.name,
            reading: &s.reading,
            lab10: Some([s.lab10.l, s.lab10.a, s.lab10.b]),
            frames: &s.bracket.frames,
            times_s: &s.bracket.times_s,
            mm_per_pixel: rig.mm_per_pixel,
            spot_diameter_mm: 2.0 * rig.spot_radius_mm,
            truth_json: truth.as_deref(),
            provenance: &how.provenance,
            fit: how.fit.clone(),
        },
        &extra,
    )
}

/// What `scatterfit synth` reports of a twin written into `output_dir` (its JSON: the folder and
/// the truth; its text: [`SynthSummary::text`]).
#[derive(Debug, serde::Serialize)]
pub struct SynthSummary<'a> {
    /// The sample folder written.
    pub output_dir: &'a Path,
    /// What the tool should find.
    pub truth: &'a scatterfit_synth::Truth,
}

impl SynthSummary<'_> {
    /// The summary printed: the folder and its bracket on `rig`, the truth (η, the port's reading
    /// fraction, g, and per channel σ′s, σa, α′ and the Monte Carlo Rd), and how to measure it.
    pub fn text(&self, sample: &SyntheticSample, rig: &scatterfit_synth::RigSpec) -> String {
        use scatterfit_pipeline::radiance::shutter;
        use std::fmt::Write as _;
        let mut t = String::new();
        let times = &sample.bracket.times_s;
        let _ = writeln!(
            t,
            "wrote {} ({} exposures {}–{} s, {}×{} px at {} mm/px, spot ⌀ {} mm)",
            self.output_dir.display(),
            times.len(),
            shutter(times[0]),
            shutter(*times.last().unwrap_or(&0.0)),
            rig.width,
            rig.height,
            rig.mm_per_pixel,
            2.0 * rig.spot_radius_mm
        );
        let _ = writeln!(t, "truth    η = {:.4}", self.truth.eta);
        if let Some(p) = &self.truth.port {
            let f = p.reading_fraction;
            let _ = writeln!(
                t,
                "port     {} mm aperture lit over {} mm reads F = {:.4} / {:.4} / {:.4} of Rd \
                 (R/G/B; named in the manifest's [spectro], so measure corrects it)",
                p.aperture_mm, p.illuminated_mm, f[0], f[1], f[2]
            );
        }
        if self.truth.g != 0.0 {
            let _ = writeln!(
                t,
                "         g = {} (in truth.json only: the manifest does not state it)",
                self.truth.g
            );
        }
        for (name, c) in ["R", "G", "B"].iter().zip(&self.truth.channels) {
            let _ = writeln!(
                t,
                "  {name}  σ′s = {:<8} σa = {:<10} α′ = {:.5}  Rd(MC) = {:.4} ± {:.4}  ({} photons)",
                c.sigma_s_prime,
                c.sigma_a,
                c.albedo_prime,
                c.rd_total,
                c.rd_total_stderr,
                c.photons
            );
        }
        let _ = writeln!(
            t,
            "measure it with: scatterfit measure {}",
            self.output_dir.display()
        );
        t
    }
}
