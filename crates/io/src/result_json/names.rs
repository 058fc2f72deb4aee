//! The named values of a result file (`eta_source`, `albedo_model`, `response`): enums read
//! leniently (case, spaces, older spellings) and written as the strings the files always had.

use super::*;

/// Where a result's η came from (`eta_source`: `"spectro"` or `"given"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EtaSource {
    /// Measured: SCI − SCE of the spectrophotometer's reading (Schlick at 8°): `spectro`.
    Spectro,
    /// Given by the user (manifest `spectro.eta`, `--eta`): `given`.
    Given,
}

impl EtaSource {
    /// Both, in the order of the docs.
    pub const ALL: [EtaSource; 2] = [EtaSource::Spectro, EtaSource::Given];

    /// The name in `result.json`.
    pub fn name(self) -> &'static str {
        match self {
            EtaSource::Spectro => "spectro",
            EtaSource::Given => "given",
        }
    }
}

impl From<scatterfit_optics::spectro::EtaSource> for EtaSource {
    fn from(s: scatterfit_optics::spectro::EtaSource) -> Self {
        match s {
            scatterfit_optics::spectro::EtaSource::Given => EtaSource::Given,
            _ => EtaSource::Spectro,
        }
    }
}

/// Where a result's α′ came from (`albedo_model`): the spectrophotometer's Rd inverted by an
/// [`AlbedoModel`] (`"diffusion"`, `"mc"`), or given by the user (`"given"`, `scatterfit fit
/// --albedo`). The existing method fits its own α′ and records the albedo model it was run with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AlbedoSource {
    /// The reading's Rd inverted by this model's total Rd(α′, η).
    Model(AlbedoModel),
    /// Given by the user.
    Given,
}

impl AlbedoSource {
    /// The name in `result.json`: the albedo model's name, or `given`.
    pub fn name(self) -> &'static str {
        match self {
            AlbedoSource::Model(m) => m.name(),
            AlbedoSource::Given => "given",
        }
    }
}

impl From<AlbedoModel> for AlbedoSource {
    fn from(m: AlbedoModel) -> Self {
        AlbedoSource::Model(m)
    }
}

/// How the bracket became radiance (`inputs.options.response`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum ResponseKind {
    /// 8-bit frames, the camera response recovered from the bracket (Debevec & Malik 1997).
    Recovered,
    /// 8-bit frames, a known response from a CSV (`camera.response`).
    Given,
    /// 16-bit frames merged as linear data.
    Linear,
    /// An already merged radiance map (`camera.hdr`): no bracket.
    Merged,
}

impl ResponseKind {
    /// Every kind, in the order of the docs.
    pub const ALL: [ResponseKind; 4] = [
        ResponseKind::Recovered,
        ResponseKind::Given,
        ResponseKind::Linear,
        ResponseKind::Merged,
    ];

    /// The name in `result.json` and in `scatterfit merge`'s output.
    pub fn name(self) -> &'static str {
        match self {
            ResponseKind::Recovered => "recovered",
            ResponseKind::Given => "given",
            ResponseKind::Linear => "linear",
            ResponseKind::Merged => "merged",
        }
    }
}

/// One of `all` by its `name`, or an [`OpticsError::UnknownName`] listing the valid names.
pub(super) fn parse_name<T: Copy>(
    all: &[T],
    name: fn(T) -> &'static str,
    text: &str,
    what: &'static str,
    expected: &'static str,
) -> Result<T, OpticsError> {
    all.iter()
        .copied()
        .find(|v| name(*v) == text)
        .ok_or_else(|| OpticsError::UnknownName {
            what,
            given: text.to_string(),
            expected,
        })
}

/// `Display` as the name in files.
macro_rules! display_name {
    ($($t:ty),*) => {$(
        impl fmt::Display for $t {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }
    )*};
}

display_name!(EtaSource, AlbedoSource, ResponseKind);

impl FromStr for EtaSource {
    type Err = OpticsError;
    fn from_str(s: &str) -> Result<Self, OpticsError> {
        parse_name(&Self::ALL, Self::name, s, "η source", "spectro, given")
    }
}

impl FromStr for AlbedoSource {
    type Err = OpticsError;
    fn from_str(s: &str) -> Result<Self, OpticsError> {
        let all = [
            AlbedoSource::Model(AlbedoModel::Diffusion),
            AlbedoSource::Model(AlbedoModel::Mc),
            AlbedoSource::Given,
        ];
        parse_name(&all, Self::name, s, "albedo source", "diffusion, mc, given")
    }
}

impl FromStr for ResponseKind {
    type Err = OpticsError;
    fn from_str(s: &str) -> Result<Self, OpticsError> {
        parse_name(
            &Self::ALL,
            Self::name,
            s,
            "response kind",
            "recovered, given, linear, merged",
        )
    }
}

impl Serialize for AlbedoSource {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for AlbedoSource {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

/// The names of a result read as `render` always read its model: surrounding blanks and ASCII
/// case ignored (`" Dipole "` is `dipole`); anything else refused naming the valid names.
pub(super) mod lenient {
    use std::str::FromStr;

    use serde::{Deserialize, Deserializer};

    fn normalise(text: &str) -> String {
        text.trim().to_ascii_lowercase()
    }

    /// A required name.
    pub fn name<'de, D, T>(d: D) -> Result<T, D::Error>
    where
        D: Deserializer<'de>,
        T: FromStr,
        T::Err: std::fmt::Display,
    {
        let text = String::deserialize(d)?;
        normalise(&text).parse().map_err(serde::de::Error::custom)
    }

    /// An optional name: missing, `null` or `""` (an empty field of an older writer) is `None`.
    pub fn optional<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
    where
        D: Deserializer<'de>,
        T: FromStr,
        T::Err: std::fmt::Display,
    {
        match Option::<String>::deserialize(d)? {
            None => Ok(None),
            Some(text) if text.trim().is_empty() => Ok(None),
            Some(text) => normalise(&text)
                .parse()
                .map(Some)
                .map_err(serde::de::Error::custom),
        }
    }

    /// The model name as `parse_result_json` checks it before the typed read.
    pub fn model(text: &str) -> Option<scatterfit_optics::ModelName> {
        normalise(text).parse().ok()
    }
}
