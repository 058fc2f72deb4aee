//! The rig twin's camera: sensor (full well, read noise, gain), tone curve and output bit depth
//! (`CameraModel`, `ToneCurve`, `SensorOutput`).

use scatterfit_optics::numerics::roots::bisect;

use super::*;

/// The camera of the twin: a linear sensor counted in electrons, then a tone curve and 8 bits.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CameraModel {
    /// Full-well capacity \[electrons\]: the linear signal's 1.
    pub full_well_e: f64,
    /// Read noise, one standard deviation \[electrons\].
    pub read_noise_e: f64,
    /// Knee b of the tone curve T(s) = (1 + b)s/(s + b) (see [`CameraModel::tone`]).
    pub tone_knee: f64,
    /// The tone curve (default: the Naka–Rushton curve with knee `tone_knee`).
    #[serde(default, skip_serializing_if = "ToneCurve::is_default")]
    pub curve: ToneCurve,
    /// What the camera writes: 8-bit tone-mapped codes (default) or linear 16-bit raw values.
    #[serde(default, skip_serializing_if = "SensorOutput::is_default")]
    pub output: SensorOutput,
}

/// The twin camera's tone curve, from linear signal s ∈ [0, 1] (electrons / full well) to display
/// value [0, 1]: the curves a lab's cameras use (the camera sweep's). Each is monotone with T(0) = 0,
/// T(1) = 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ToneCurve {
    /// T(s) = (1 + b)s/(s + b), b = [`CameraModel::tone_knee`] (the twin's default camera).
    #[default]
    NakaRushton,
    /// T(s) = s (a machine-vision camera with gamma off).
    Linear,
    /// T(s) = s^(1/2.2).
    Gamma22,
    /// The sRGB transfer function (IEC 61966-2-1): 12.92 s below 0.0031308, 1.055 s^(1/2.4) − 0.055
    /// above.
    Srgb,
    /// A log curve (cine "log" profiles): T(s) = ln(1 + 500 s)/ln 501.
    Log,
    /// A filmic S-curve with a toe and a shoulder: Narkowicz's 2015 fit of the ACES reference
    /// rendering transform, A(x) = x(2.51x + 0.03)/(x(2.43x + 0.59) + 0.14), at x = 4s, scaled so
    /// T(1) = 1 (flat at black, compressed toward white).
    SCurve,
}

impl ToneCurve {
    /// Every curve, in the order of [`ToneCurve::name`]'s list.
    pub const ALL: [ToneCurve; 6] = [
        ToneCurve::NakaRushton,
        ToneCurve::Linear,
        ToneCurve::Gamma22,
        ToneCurve::Srgb,
        ToneCurve::Log,
        ToneCurve::SCurve,
    ];

    fn is_default(&self) -> bool {
        *self == ToneCurve::default()
    }

    /// The name `synth --camera` takes.
    pub fn name(self) -> &'static str {
        match self {
            ToneCurve::NakaRushton => "naka-rushton",
            ToneCurve::Linear => "linear",
            ToneCurve::Gamma22 => "gamma22",
            ToneCurve::Srgb => "srgb",
            ToneCurve::Log => "log",
            ToneCurve::SCurve => "s-curve",
        }
    }

    /// T(s) for s ∈ [0, 1] (clamped), with knee `b` for the Naka–Rushton curve.
    pub fn apply(self, s: f64, b: f64) -> f64 {
        let s = s.clamp(0.0, 1.0);
        match self {
            ToneCurve::NakaRushton => (1.0 + b) * s / (s + b),
            ToneCurve::Linear => s,
            ToneCurve::Gamma22 => s.powf(1.0 / 2.2),
            ToneCurve::Srgb => {
                if s <= 0.003_130_8 {
                    12.92 * s
                } else {
                    1.055 * s.powf(1.0 / 2.4) - 0.055
                }
            }
            ToneCurve::Log => (500.0 * s).ln_1p() / 501f64.ln(),
            ToneCurve::SCurve => {
                let aces = |x: f64| x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
                aces(4.0 * s) / aces(4.0)
            }
        }
    }
}

/// What the twin camera writes.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum SensorOutput {
    /// 8-bit codes through the tone curve (a JPEG/PNG camera).
    #[default]
    Tone8,
    /// Linear raw values: `black_level` (per channel, DN) plus electrons × (`white_level` −
    /// black)/full well, clipped at `white_level`; no tone curve. Written as 16-bit PNG (values as
    /// they are) or DNG (with the levels in its metadata).
    Linear {
        /// The sensor's black level per channel \[DN\] (what a raw file's pixels read in the dark).
        black_level: [f64; 3],
        /// The clip level \[DN\] (16383 for a 14-bit sensor, 65535 for full 16-bit).
        white_level: f64,
    },
}

impl SensorOutput {
    fn is_default(&self) -> bool {
        *self == SensorOutput::default()
    }
}

impl Default for CameraModel {
    /// A small-pixel CMOS camera at ISO 400 (the paper's setting): 20 000 e⁻ full well, 3 e⁻ read
    /// noise, tone knee 0.08 (slope 13.5 at black, like sRGB's 12.92, then compressive).
    fn default() -> Self {
        Self {
            full_well_e: 20_000.0,
            read_noise_e: 3.0,
            tone_knee: 0.08,
            curve: ToneCurve::NakaRushton,
            output: SensorOutput::Tone8,
        }
    }
}

impl CameraModel {
    /// The tone curve from linear signal s ∈ [0, 1] (electrons / full well) to display value
    /// [0, 1]: T(s) = (1 + b)s/(s + b), a Michaelis–Menten (Naka–Rushton) curve — monotone, smooth,
    /// linear at black and compressive towards white, T(0) = 0, T(1) = 1. Deliberately not a gamma
    /// or an sRGB curve: the tool must recover it (Debevec & Malik 1997), not assume it.
    ///
    /// With another [`ToneCurve`] in `curve`, that curve.
    pub fn tone(&self, s: f64) -> f64 {
        self.curve.apply(s, self.tone_knee)
    }

    /// The camera's true 8-bit response as ln(relative exposure) per code: the midpoint of each
    /// code's interval of linear signal under [`CameraModel::tone`] (inverted by bisection) — what
    /// Debevec & Malik's g(Z) recovers, for tests that separate response errors from the merge's.
    pub fn true_log_response(&self) -> [f64; 256] {
        let inv = |v: f64| {
            let (lo, hi) = bisect(0.0, 1.0, 60, |s| self.tone(s) < v);
            0.5 * (lo + hi)
        };
        std::array::from_fn(|z| {
            let a = inv(((z as f64 - 0.5) / 255.0).max(0.0));
            let b = inv(((z as f64 + 0.5) / 255.0).min(1.0));
            (0.5 * (a + b)).max(1e-9).ln()
        })
    }

    /// A named camera of `synth --camera NAME`: a [`ToneCurve`] name (8-bit, the default camera's
    /// sensor), `linear16` (linear 16-bit PNG, black level 1024 DN, white 65535) or `dng` (14-bit
    /// raw, black level 512 DN, white 16383, written as DNG).
    pub fn named(name: &str) -> Option<Self> {
        let base = Self::default();
        if let Some(curve) = ToneCurve::ALL.iter().find(|c| c.name() == name) {
            return Some(Self {
                curve: *curve,
                ..base
            });
        }
        match name {
            "linear16" => Some(Self {
                output: SensorOutput::Linear {
                    black_level: [1024.0; 3],
                    white_level: 65535.0,
                },
                ..base
            }),
            "dng" => Some(Self {
                output: SensorOutput::Linear {
                    black_level: [512.0; 3],
                    white_level: 16383.0,
                },
                ..base
            }),
            _ => None,
        }
    }

    /// The names [`CameraModel::named`] takes.
    pub const NAMES: [&'static str; 8] = [
        "naka-rushton",
        "linear",
        "gamma22",
        "srgb",
        "log",
        "s-curve",
        "linear16",
        "dng",
    ];

    /// The linear raw value of `electrons` ([`SensorOutput::Linear`]; for 8-bit cameras the 16-bit
    /// scale with no black level), rounded and clipped to [0, white].
    pub fn raw_value(&self, electrons: f64, c: usize) -> u16 {
        let (black, white) = match self.output {
            SensorOutput::Linear {
                black_level,
                white_level,
            } => (black_level[c], white_level),
            SensorOutput::Tone8 => (0.0, 65535.0),
        };
        let e = electrons.min(self.full_well_e);
        (black + e * (white - black) / self.full_well_e)
            .round()
            .clamp(0.0, white) as u16
    }

    /// The 8-bit code of `electrons` (clipped at the full well and at 0).
    pub fn code(&self, electrons: f64) -> u8 {
        let s = electrons / self.full_well_e;
        (255.0 * self.tone(s)).round().clamp(0.0, 255.0) as u8
    }
}
