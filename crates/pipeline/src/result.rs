//! The result file's content from a finished measurement ([`Measurement::to_result`]): the
//! values per channel with their terms and verdicts, the inputs with the hashes of the bytes that
//! were measured, the options, and how g entered.

use std::path::Path;

use scatterfit_io::result_json::{
    AlbedoSource, CameraCorrections, CameraRecord, ExposureRecord, FileRef, Inputs,
    MeasurementResult, RunOptions,
};
use scatterfit_optics::Rgb;

use crate::anisotropy::plan::{GPlan, known_g_record};
use crate::anisotropy::record::GFit;
use crate::fit::channel_result;
use crate::fit::outcome::ChannelOutcome;
use crate::hdr::Corrections;
use crate::measurement::Measurement;
use crate::settings::FitSettings;

impl Measurement {
    /// The result file's content. `profile_file` is the profile CSV's name as written beside the
    /// result (recorded in `inputs.profile`). The inputs' SHA-256 hashes are those the stages
    /// recorded of the bytes they read and measured (the manifest, the spectrophotometer file, the
    /// radiance map, each frame); no file is read here, so a file replaced after the measurement
    /// is recorded as it was measured.
    pub fn to_result(&self, profile_file: Option<&str>) -> MeasurementResult {
        let m = &self.manifest;
        let record = |path: &Path, sha256: Option<&String>| -> Option<FileRef> {
            sha256.map(|sha256| FileRef {
                path: path.to_string_lossy().into_owned(),
                sha256: sha256.clone(),
            })
        };
        // Paths relative to the sample folder, as the manifest names them.
        let relative = |p: &Path| p.strip_prefix(&m.dir).unwrap_or(p).to_path_buf();
        let manifest_ref = m
            .read_from
            .as_ref()
            .and_then(|f| record(&relative(&f.path), Some(&f.sha256)));
        let spectro_ref = m
            .spectro
            .file
            .as_deref()
            .and_then(|p| record(p, self.spectro.file_sha256.as_ref()));
        let hdr_ref = m
            .camera
            .hdr
            .as_deref()
            .and_then(|p| record(p, self.hdr.radiance_file.as_ref().map(|f| &f.sha256)));
        let frames: Vec<FileRef> = self
            .hdr
            .frames
            .iter()
            .filter_map(|f| record(&relative(&f.file), Some(&f.sha256)))
            .collect();
        let quality = crate::checks::quality(self);
        let channels = self.fits.as_ref().map_with_channel(|c, outcome| {
            let mut r = channel_result(outcome, &self.spectro, c);
            r.quality = Some(quality[c].clone());
            r
        });
        let s = &self.settings;
        MeasurementResult {
            schema_version: scatterfit_io::result_json::SCHEMA_VERSION,
            name: m.display_name(),
            eta: self.spectro.eta,
            eta_source: Some(self.spectro.eta_source),
            eta_stderr: self.spectro.uncertainty.eta_stderr,
            spectro_repeatability: Some(self.spectro.uncertainty.repeatability),
            method: s.method,
            model: s.model,
            albedo_model: Some(AlbedoSource::Model(s.albedo_model)),
            channels,
            inputs: Inputs {
                sample_dir: m.dir.to_string_lossy().into_owned(),
                manifest: manifest_ref,
                spectro: spectro_ref,
                frames,
                hdr: hdr_ref,
                profile: profile_file.map(str::to_string),
                mm_per_pixel: m.camera.mm_per_pixel,
                spot_radius_mm: Some(self.settings.spot_radius_mm),
                center_px: Some(self.profile.center.xy()),
                options: RunOptions {
                    method: Some(s.method),
                    model: Some(s.model),
                    albedo_model: Some(s.albedo_model),
                    normalise_with_spectro: Some(s.normalise_with_spectro),
                    g: Some(s.g),
                    r_min_mm: Some(s.r_min_mm()),
                    r_max_px: Some(m.fit.r_max_px.unwrap_or(300.0)),
                    spot_radius_mm: Some(s.spot_radius_mm),
                    response: Some(self.hdr.response_kind),
                    // JSON has no NaN: an unknown limit is null.
                    detection_limit: Some(
                        self.profile
                            .detection_limit
                            .iter()
                            .map(|v| v.is_finite().then_some(*v))
                            .collect(),
                    ),
                    camera: Some(CameraRecord {
                        background: self.profile.background.clone(),
                        corrections: corrections_record(&self.hdr.corrections),
                    }),
                },
            },
            version: env!("CARGO_PKG_VERSION").into(),
            // The spectrum as the port let the instrument read it, corrected like the channels.
            rd_spectrum: rd_spectrum(self.spectro.analysis.as_ref()).map(|s| {
                self.port
                    .as_ref()
                    .and_then(|p| crate::port::correct_spectrum(&s, &p.reading_fraction))
                    .unwrap_or(s)
            }),
            g_uncertainty: Some(g_record(s, &self.fits)),
            spectro_port: self
                .port
                .as_ref()
                .map(|p| scatterfit_io::result_json::PortResult {
                    aperture_mm: p.aperture_mm,
                    illuminated_mm: p.illuminated_mm,
                    rd_read: p.read.rd,
                    reading_fraction: p.reading_fraction,
                    problems: p.problems.clone(),
                }),
        }
    }
}

/// The result's record of how g entered ([`scatterfit_io::result_json::GUncertainty`]), with
/// each channel's fit of g for `g = "fit"` (from `fits`).
pub fn g_record(
    settings: &FitSettings,
    fits: &Rgb<ChannelOutcome>,
) -> scatterfit_io::result_json::GUncertainty {
    match GPlan::new(&settings.g_prior, settings.g) {
        Ok(Some(plan)) => {
            let mut record = plan.record(&settings.g_prior);
            if settings.g_prior.fit {
                record.fitted = Some(
                    fits.as_ref()
                        .map(|f| f.fit().and_then(|f| f.g_fit.as_ref()).map(GFit::record)),
                );
            }
            record
        }
        Ok(None) => known_g_record(settings.g),
        // No plan: the range, nothing evaluated (the channels' notes say why).
        Err(e) => scatterfit_io::result_json::GUncertainty {
            source: settings.g_prior.source(),
            g: Some(settings.g),
            range: settings.g_prior.propagated_range(),
            evaluated: Vec::new(),
            not_covered: Some(e.to_string()),
            fitted: None,
        },
    }
}

/// The SCE spectrum the channels' Rd came from (spectral renderers need it), when the
/// colour came from the spectrum rather than a measured L*a*b*.
fn rd_spectrum(
    analysis: Option<&scatterfit_optics::spectro::SpectroAnalysis>,
) -> Option<scatterfit_io::result_json::RdSpectrum> {
    let a = analysis?;
    (a.colour_source == scatterfit_optics::spectro::ColourSource::SceSpectrum).then(|| {
        scatterfit_io::result_json::RdSpectrum {
            wavelength_nm: a.spectral.iter().map(|p| p.wavelength_nm).collect(),
            rd: a.spectral.iter().map(|p| p.sce).collect(),
        }
    })
}

/// What the HDR stage corrected, as the result records it (the parts a reader of the file needs;
/// the checks' working values stay in the measurement).
fn corrections_record(c: &Corrections) -> CameraCorrections {
    CameraCorrections {
        black_level: c
            .black_level
            .as_ref()
            .map(|(dn, source)| (dn.clone(), (*source).to_string())),
        exposure: c.exposure.as_ref().map(|e| ExposureRecord {
            factor: e.factor.clone(),
            max_correction: e.max_correction,
            pairs: e.pairs.clone(),
        }),
        exposure_applied: c.exposure_applied,
        flat: c
            .flat
            .as_ref()
            .map(|(path, lo, hi)| (path.to_string_lossy().into_owned(), *lo, *hi)),
        no_signal: c.no_signal.clone(),
    }
}
