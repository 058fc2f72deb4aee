//! The spectrophotometer stage's report, as `scatterfit spectro` prints it: the JSON document
//! ([`SpectroReport`]) and the text summary ([`spectro_text`]): η and where it came from, η per
//! channel, the SCE colour, Rd and α′ per channel, problems and warnings.

use std::fmt::Write as _;
use std::path::Path;

use scatterfit_optics::Channel;
use scatterfit_optics::colour::Lab;
use scatterfit_optics::spectro::{ColourSource, EtaSource, SpectroAnalysis, SpectroReading};
use serde::Serialize;

/// The JSON document of one analysed reading.
#[derive(Debug, Serialize)]
pub struct SpectroReport<'a> {
    /// The input file.
    pub file: String,
    /// The L*a*b* given instead of the SCE spectrum's colour, if any.
    pub lab: Option<Lab>,
    /// Observer of `lab` \[degrees\]: 2 or 10.
    pub lab_observer: Option<u32>,
    /// The analysis.
    #[serde(flatten)]
    pub analysis: &'a SpectroAnalysis,
    /// scatterfit's version.
    pub version: &'static str,
}

impl<'a> SpectroReport<'a> {
    /// The report of `analysis` of the reading in `file`, with the L*a*b* and its observer when
    /// one was given.
    pub fn new(file: &Path, lab: Option<(Lab, u32)>, analysis: &'a SpectroAnalysis) -> Self {
        Self {
            file: file.display().to_string(),
            lab: lab.map(|(l, _)| l),
            lab_observer: lab.map(|(_, o)| o),
            analysis,
            version: env!("CARGO_PKG_VERSION"),
        }
    }
}

/// The summary of `a`, the analysis of `reading` read from `file`, as `scatterfit spectro` prints
/// it; one line each, ending in a newline.
pub fn spectro_text(file: &Path, reading: &SpectroReading, a: &SpectroAnalysis) -> String {
    let mut s = String::new();
    let wl = reading.wavelengths_nm();
    let _ = writeln!(
        s,
        "{}: {} wavelengths, {}–{} nm",
        file.display(),
        wl.len(),
        wl.first().copied().unwrap_or(0.0),
        wl.last().copied().unwrap_or(0.0)
    );
    let _ = match a.eta_source {
        EtaSource::Given => writeln!(s, "η = {:.4} (given)", a.eta),
        EtaSource::SchlickSciMinusSce => writeln!(
            s,
            "η = {:.4}  (Schlick at 8° from SCI − SCE = {:.5}, luminance-weighted; exact Fresnel: {})",
            a.eta,
            a.specular_mean,
            a.eta_exact_fresnel
                .map_or("—".into(), |e| format!("{e:.4}"))
        ),
    };
    let eta = |e: Option<f64>| e.map_or("—".into(), |e| format!("{e:.4}"));
    let [r, g, b] = a.channels.each_ref().map(|c| eta(c.eta_channel));
    let dispersion = if a.dispersion_significant {
        "significant"
    } else {
        "not significant"
    };
    let _ = writeln!(
        s,
        "η per channel: R {r}  G {g}  B {b}  (dispersion {dispersion})"
    );
    let (l2, l10, x2, x10) = (a.lab_2deg, a.lab_10deg, a.xyz_2deg, a.xyz_10deg);
    let _ = writeln!(
        s,
        "SCE colour: L*a*b* D65/2° {:.3} {:.3} {:.3}   D65/10° {:.3} {:.3} {:.3}",
        l2.l, l2.a, l2.b, l10.l, l10.a, l10.b
    );
    let _ = writeln!(
        s,
        "            XYZ 2° {:.4} {:.4} {:.4}   10° {:.4} {:.4} {:.4}",
        x2.x, x2.y, x2.z, x10.x, x10.y, x10.z
    );
    let source = match a.colour_source {
        ColourSource::SceSpectrum => "SCE spectrum",
        ColourSource::Lab2 => "given L*a*b* (2°)",
        ColourSource::Lab10 => "given L*a*b* (10°, Bradford to 2°)",
    };
    let _ = writeln!(
        s,
        "\nchannel  Rd (linear sRGB, from {source})   α′ (dipole, η = {:.4})",
        a.eta
    );
    for (ch, c) in Channel::ALL.iter().zip(&a.channels) {
        let name = ch.name();
        let albedo = c.albedo_prime.map_or("—".to_owned(), |v| format!("{v:.6}"));
        let _ = writeln!(s, "{name:<8} {:<38.6} {albedo}", c.rd_total);
    }
    for c in &a.channels {
        if let Some(p) = &c.problem {
            let _ = writeln!(s, "problem: {p}");
        }
    }
    for w in &a.warnings {
        let _ = writeln!(s, "warning: {w}");
    }
    s
}
