//! The view model of the HTML pages: everything they show of a result, read from
//! `scatterfit_io::result_json::MeasurementResult` in this one module (and nowhere else in
//! `html`), so that a change of the result's field shapes is a change here only.

use scatterfit_io::quality::Verdict;
use scatterfit_io::result_json::{ChannelResult, ChannelStatus, MeasurementResult};
use scatterfit_io::result_table::sig4;
use scatterfit_optics::Estimate;

/// The channel names in R, G, B order, as the tables write them.
pub(crate) const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// A value of the result as the pages show it: the file's record of the value and its
/// uncertainty terms ([`Estimate`]), or none (a failed channel).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Valued(pub Option<Estimate>);

impl Valued {
    /// The value, `None` where there is none.
    pub fn value(&self) -> Option<f64> {
        self.0.map(|e| e.value)
    }

    /// The fit's term, `None` where unknown.
    pub fn fit(&self) -> Option<f64> {
        self.0.and_then(|e| e.fit)
    }

    /// The value in four significant figures, or `—`.
    pub fn value_text(&self) -> String {
        self.value().map_or("—".into(), sig4)
    }

    /// `± fit (fit) ± spectro (spectro) ± g (g) ± model (model)`, the known terms only, or empty.
    pub fn error_text(&self) -> String {
        let Some(e) = self.0 else {
            return String::new();
        };
        [
            (e.fit, "fit"),
            (e.spectro, "spectro"),
            (e.g, "g"),
            (e.model, "model"),
        ]
        .into_iter()
        .filter_map(|(v, name)| v.map(|v| format!("± {} ({name})", sig4(v))))
        .collect::<Vec<_>>()
        .join(" ")
    }

    /// The total uncertainty ([`Estimate::total`]).
    pub fn total_error(&self) -> Option<f64> {
        self.0.and_then(|e| e.total())
    }
}

/// One finding of the data checks.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ReasonView {
    /// `ok`, `suspect` or `failed`.
    pub severity: &'static str,
    /// What was found (from the checks; escaped when written).
    pub message: String,
}

/// One channel of a result.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ChannelView {
    /// `R`, `G`, `B`.
    pub name: &'static str,
    /// `ok`, `suspect` or `failed`: the checks' verdict, else from the fit's status.
    pub verdict: &'static str,
    /// The checks' reasons, and the fit's problem note.
    pub reasons: Vec<ReasonView>,
    /// σ′s \[mm⁻¹\].
    pub sigma_s_prime: Valued,
    /// σa \[mm⁻¹\].
    pub sigma_a: Valued,
    /// α′ (the reading's term; the fit's too behind a spectrophotometer port).
    pub albedo_prime: Valued,
    /// Total diffuse reflectance of the channel from the spectrophotometer (linear sRGB).
    pub rd_total: Option<f64>,
    /// MSE \[mm⁻⁴\].
    pub mse: Option<f64>,
    /// RMS of ln(measured/model).
    pub rms_log_residual: Option<f64>,
    /// χ² per degree of freedom.
    pub chi2_reduced: Option<f64>,
    /// Rings used, inside the spot, below detection, invalid.
    pub rings: [usize; 4],
    /// Iterations and the solver's reason to stop.
    pub solver: String,
    /// Fit time \[s\].
    pub fit_time_s: f64,
}

/// A file the result was made from.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FileView {
    /// What it is (`manifest`, `spectro`, `frame`, `radiance map`).
    pub role: &'static str,
    /// The path as the result gives it.
    pub path: String,
    /// SHA-256, hex.
    pub sha256: String,
}

/// What a page shows of one result.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ResultView {
    /// The sample's name.
    pub name: String,
    /// η.
    pub eta: Valued,
    /// Where η came from.
    pub eta_source: String,
    /// `proposed` / `existing`.
    pub method: String,
    /// The forward model.
    pub model: String,
    /// How α′ was found.
    pub albedo_model: String,
    /// R, G, B.
    pub channels: [ChannelView; 3],
    /// The worst verdict of the three channels.
    pub verdict: &'static str,
    /// The input files with their hashes.
    pub files: Vec<FileView>,
    /// The sample folder.
    pub sample_dir: String,
    /// mm per pixel, spot radius \[mm\], centre \[px\].
    pub mm_per_pixel: Option<f64>,
    /// Radius of the light spot \[mm\].
    pub spot_radius_mm: Option<f64>,
    /// The options as given, pretty JSON.
    pub options: String,
    /// The scatterfit version that wrote the result.
    pub version: String,
    /// The port correction, as a sentence, when one was made.
    pub port: Option<String>,
    /// How g entered, as a sentence, when the result records it.
    pub g: Option<String>,
}

fn verdict_of(c: &ChannelResult) -> Verdict {
    match (&c.quality, c.status) {
        (Some(q), _) => q.verdict,
        (None, ChannelStatus::Ok) => Verdict::Ok,
        (None, ChannelStatus::Unconstrained) => Verdict::Suspect,
        (None, _) => Verdict::Failed,
    }
}

fn channel(name: &'static str, c: &ChannelResult) -> ChannelView {
    let mut reasons: Vec<ReasonView> = c
        .quality
        .iter()
        .flat_map(|q| &q.reasons)
        .map(|r| ReasonView {
            severity: r.severity.name(),
            message: r.message.clone(),
        })
        .collect();
    if let Some(p) = &c.problem
        && !reasons.iter().any(|r| r.message.contains(p.as_str()))
    {
        reasons.push(ReasonView {
            severity: "note",
            message: p.clone(),
        });
    }
    ChannelView {
        name,
        verdict: verdict_of(c).name(),
        reasons,
        sigma_s_prime: Valued(c.sigma_s_prime),
        sigma_a: Valued(c.sigma_a),
        albedo_prime: Valued(c.albedo_prime),
        rd_total: c.rd_total,
        mse: c.mse,
        rms_log_residual: c.rms_log_residual,
        chi2_reduced: c.chi2_reduced,
        rings: [
            c.rings_used,
            c.rings_inside_spot,
            c.rings_below_detection,
            c.rings_invalid,
        ],
        solver: format!("{} iterations, {}", c.iterations, c.termination),
        fit_time_s: c.fit_time_s,
    }
}

impl ResultView {
    /// The view of `r`.
    pub fn new(r: &MeasurementResult) -> Self {
        let [cr, cg, cb] = [&r.channels.r, &r.channels.g, &r.channels.b];
        let channels = [
            channel(CHANNELS[0], cr),
            channel(CHANNELS[1], cg),
            channel(CHANNELS[2], cb),
        ];
        let verdict = [cr, cg, cb]
            .iter()
            .map(|c| verdict_of(c))
            .max()
            .unwrap_or_default()
            .name();
        let i = &r.inputs;
        let mut files = Vec::new();
        let mut push = |role, f: &scatterfit_io::result_json::FileRef| {
            files.push(FileView {
                role,
                path: f.path.clone(),
                sha256: f.sha256.clone(),
            });
        };
        if let Some(f) = &i.manifest {
            push("manifest", f);
        }
        if let Some(f) = &i.spectro {
            push("spectro", f);
        }
        if let Some(f) = &i.hdr {
            push("radiance map", f);
        }
        for f in &i.frames {
            push("frame", f);
        }
        let port = r.spectro_port.as_ref().map(|p| {
            format!(
                "port correction: aperture {} mm, illuminated {} mm; the reading's Rd (R, G, B) \
                 {}, {}, {} was corrected for the light lost beyond the port's edge",
                sig4(p.aperture_mm),
                sig4(p.illuminated_mm),
                sig4(p.rd_read.r),
                sig4(p.rd_read.g),
                sig4(p.rd_read.b)
            )
        });
        Self {
            name: r.name.clone(),
            eta: Valued(Some(r.eta_estimate())),
            eta_source: r.eta_source.map_or_else(|| "—".into(), |e| e.name().into()),
            method: r.method.to_string(),
            model: r.model.to_string(),
            albedo_model: r
                .albedo_model
                .map_or_else(|| "—".into(), |a| a.name().into()),
            channels,
            verdict,
            files,
            sample_dir: i.sample_dir.clone(),
            mm_per_pixel: i.mm_per_pixel,
            spot_radius_mm: i.spot_radius_mm,
            options: serde_json::to_string_pretty(&i.options).unwrap_or_default(),
            version: r.version.clone(),
            port,
            g: r.g_uncertainty.as_ref().map(|g| g.describe()),
        }
    }

    /// The spectrophotometer's colour: the channels' Rd (linear sRGB) as 8-bit sRGB, `None` when a
    /// channel has none.
    pub fn spectro_colour(&self) -> Option<[u8; 3]> {
        let mut out = [0u8; 3];
        for (o, c) in out.iter_mut().zip(&self.channels) {
            *o = srgb8(c.rd_total?);
        }
        Some(out)
    }

    /// The per-channel (σ′s, σa) when every channel has both.
    pub fn coefficients(&self) -> Option<[(f64, f64); 3]> {
        let mut out = [(0.0, 0.0); 3];
        for (o, c) in out.iter_mut().zip(&self.channels) {
            *o = (c.sigma_s_prime.value()?, c.sigma_a.value()?);
        }
        Some(out)
    }
}

/// A linear value in \[0, 1\] as an 8-bit sRGB code (IEC 61966-2-1, `optics::colour::srgb_encode`).
pub(crate) fn srgb8(linear: f64) -> u8 {
    let s = scatterfit_optics::colour::srgb_encode(linear.clamp(0.0, 1.0));
    (s * 255.0).round().clamp(0.0, 255.0) as u8
}
