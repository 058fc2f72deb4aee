//! What the HDR and profile stages found and corrected of a real camera, as a result records it
//! (`inputs.options.camera`): the black level, the exposure times estimated from the frames, the
//! flat frame, the frames left out for carrying no signal, and the constant level under the
//! profile per channel. The fields are in the file's key order (alphabetical, as the untyped map
//! that wrote them before sorted them), so a file reads back to the same bytes.

use serde::{Deserialize, Deserializer, Serialize};

/// The camera's record.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct CameraRecord {
    /// Per channel (R, G, B), the constant level found under the profile (veiling glare, stray
    /// light); empty when it was not estimated (`camera.background = "none"`).
    pub background: Vec<BackgroundLevel>,
    /// What the HDR stage corrected.
    pub corrections: CameraCorrections,
}

/// A channel's constant level under the profile, fitted with the profile's far field.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct BackgroundLevel {
    /// The level \[relative radiance, the radiance map's units\].
    #[serde(deserialize_with = "number_or_nan")]
    pub level: f64,
    /// The level over the profile's peak (the glare's size as a lens maker gives it); NaN (null
    /// in the file) without a positive peak.
    #[serde(deserialize_with = "number_or_nan")]
    pub relative_to_peak: f64,
    /// Its standard error; infinite (null in the file) when the far field could not be fitted.
    #[serde(deserialize_with = "number_or_nan")]
    pub stderr: f64,
    /// True when it was subtracted from the rings (significant: above 3 standard errors and the
    /// detection limit).
    pub subtracted: bool,
}

/// What the HDR stage corrected of a real camera.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct CameraCorrections {
    /// The black level subtracted from linear frames \[DN per channel\] and where it came from
    /// (`dark frame`, `metadata`, `given`, `far corners`); `None` when none was.
    pub black_level: Option<(Vec<f64>, String)>,
    /// The exposure times estimated from the frames.
    pub exposure: Option<ExposureRecord>,
    /// True when the estimated times replaced the nominal ones.
    pub exposure_applied: bool,
    /// The flat frame divided out (its path as the manifest gives it) and its smoothed fall-off
    /// (the divisor's minimum and maximum).
    pub flat: Option<(String, f64, f64)>,
    /// The frames (indices by exposure time, shortest first) left out of the merge because they
    /// carry no signal.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub no_signal: Vec<usize>,
}

/// Exposure times estimated from the frames themselves.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct ExposureRecord {
    /// Per frame (shortest first), the estimated true time over the nominal one (geometric mean
    /// 1).
    pub factor: Vec<f64>,
    /// The largest |factor − 1|.
    pub max_correction: f64,
    /// Per adjacent pair of frames, the number of well-exposed pixel values the ratio came from.
    pub pairs: Vec<usize>,
}

/// A number, or `null` read as NaN (JSON has no NaN or infinity; serde_json writes them as null).
fn number_or_nan<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// The camera record of a file, or `None` where the file holds something this reader does not
/// know as one (a file from another version): the rest of the options still read.
pub(super) fn lenient_camera<'de, D: Deserializer<'de>>(
    d: D,
) -> Result<Option<CameraRecord>, D::Error> {
    let value = Option::<serde_json::Value>::deserialize(d)?;
    Ok(value.and_then(|v| serde_json::from_value(v).ok()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record as `measure` wrote it before the type existed (an untyped map, keys sorted, NaN
    /// as null) reads into the type and writes back to the same text.
    #[test]
    fn a_record_written_as_a_map_reads_back_to_the_same_text() {
        let text = r#"{"background":[{"level":-0.0127,"relative_to_peak":null,"stderr":0.00054,"subtracted":false},{"level":0.5,"relative_to_peak":0.000074,"stderr":null,"subtracted":true}],"corrections":{"black_level":[[1024.0,1023.5,1024.2],"far corners"],"exposure":{"factor":[1.0008,0.9992],"max_correction":0.0008,"pairs":[2300]},"exposure_applied":false,"flat":["flat.png",0.81,1.0],"no_signal":[0]}}"#;
        let r: CameraRecord = serde_json::from_str(text).unwrap();
        assert!(r.background[0].relative_to_peak.is_nan());
        assert!(r.background[1].stderr.is_nan());
        assert_eq!(r.corrections.no_signal, [0]);
        assert_eq!(
            r.corrections.black_level.as_ref().map(|b| b.1.as_str()),
            Some("far corners")
        );
        assert_eq!(serde_json::to_string(&r).unwrap(), text);
    }

    /// Something else where the record belongs is no record, not an error.
    #[test]
    fn an_unknown_shape_is_no_record() {
        #[derive(Deserialize)]
        struct Holder {
            #[serde(default, deserialize_with = "lenient_camera")]
            camera: Option<CameraRecord>,
        }
        let h: Holder = serde_json::from_str(r#"{"camera":{"background":"none"}}"#).unwrap();
        assert_eq!(h.camera, None);
        let h: Holder = serde_json::from_str(r#"{"camera":{}}"#).unwrap();
        assert_eq!(h.camera, Some(CameraRecord::default()));
    }
}
