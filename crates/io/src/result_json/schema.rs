//! The file's schema version and the reading of earlier versions.
//!
//! Version 2 keeps each measured value as one record, `{value, fit, spectro, g, model, total}`
//! ([`scatterfit_optics::Estimate`]), the shape every consumer (the report, the export, the
//! Python binding) reads. Version 1 (files without `schema_version`, written until 2026-11-28)
//! spelled the terms as flat keys beside the value (`sigma_s_prime`, `sigma_s_prime_stderr`,
//! `sigma_s_prime_stderr_spectro`, …; α′'s spectrophotometer term as `albedo_prime_stderr`); such a
//! file is rewritten into version 2 before it is read, so every reader sees one shape.

use serde_json::{Map, Value};

/// The version [`super::write_result_json`] writes, and the newest [`super::read_result_json`]
/// reads.
pub const SCHEMA_VERSION: u32 = 2;

/// A version-1 channel's flat keys for each value: (value key, [(flat key, term)]).
const V1_TERMS: [(&str, [(&str, &str); 4]); 3] = [
    (
        "sigma_s_prime",
        [
            ("sigma_s_prime_stderr", "fit"),
            ("sigma_s_prime_stderr_spectro", "spectro"),
            ("sigma_s_prime_stderr_g", "g"),
            ("sigma_s_prime_stderr_model", "model"),
        ],
    ),
    (
        "sigma_a",
        [
            ("sigma_a_stderr", "fit"),
            ("sigma_a_stderr_spectro", "spectro"),
            ("sigma_a_stderr_g", "g"),
            ("sigma_a_stderr_model", "model"),
        ],
    ),
    (
        "albedo_prime",
        [
            ("albedo_prime_stderr_fit", "fit"),
            ("albedo_prime_stderr", "spectro"),
            ("albedo_prime_stderr_g", "g"),
            ("albedo_prime_stderr_model", "model"),
        ],
    ),
];

/// Brings a parsed file to [`SCHEMA_VERSION`] in place.
///
/// # Errors
/// A description of what is wrong with `schema_version` (not a whole number, or newer than this
/// scatterfit reads).
pub(crate) fn upgrade(file: &mut Map<String, Value>) -> Result<(), String> {
    let version = match file.get("schema_version") {
        None => 1,
        Some(v) => match v.as_u64() {
            Some(v @ 1..) => v,
            _ => {
                return Err(format!(
                    "`schema_version` must be a whole number ≥ 1 (this scatterfit writes \
                     {SCHEMA_VERSION})"
                ));
            }
        },
    };
    if version > u64::from(SCHEMA_VERSION) {
        return Err(format!(
            "`schema_version` = {version}: written by a newer scatterfit than this one, which \
             reads up to version {SCHEMA_VERSION}; update scatterfit to read it"
        ));
    }
    if version == 1
        && let Some(Value::Object(channels)) = file.get_mut("channels")
    {
        for channel in channels.values_mut() {
            if let Value::Object(c) = channel {
                upgrade_channel_v1(c);
            }
        }
    }
    file.insert("schema_version".into(), Value::from(SCHEMA_VERSION));
    Ok(())
}

/// One version-1 channel: each value and its flat terms become one record; a value that is not a
/// number (`null`, or something the typed read will refuse) is left as it is.
fn upgrade_channel_v1(c: &mut Map<String, Value>) {
    for (key, terms) in V1_TERMS {
        let flat: Vec<(&str, Option<Value>)> =
            terms.iter().map(|&(k, term)| (term, c.remove(k))).collect();
        let Some(value) = c.get(key).filter(|v| v.is_number()).cloned() else {
            continue;
        };
        let mut record = Map::new();
        record.insert("value".into(), value);
        for (term, v) in flat {
            record.insert(term.into(), v.unwrap_or(Value::Null));
        }
        c.insert(key.into(), Value::Object(record));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// A version-1 channel's flat keys land in the record's terms, α′'s `albedo_prime_stderr` as
    /// its spectrophotometer term; a missing term is null; a failed channel's nulls stay null.
    #[test]
    fn version_1_channels_become_records() {
        let mut file = json!({
            "channels": {
                "r": { "sigma_s_prime": 1.5, "sigma_s_prime_stderr": 0.01,
                       "sigma_s_prime_stderr_spectro": 0.02, "sigma_s_prime_stderr_g": 0.0,
                       "sigma_a": 0.1, "sigma_a_stderr": 0.001,
                       "albedo_prime": 0.9, "albedo_prime_stderr": 0.003,
                       "albedo_prime_stderr_fit": 0.004, "rd_total": 0.5 },
                "b": { "sigma_s_prime": null, "sigma_s_prime_stderr": null, "sigma_a": null }
            }
        });
        let map = file.as_object_mut().unwrap();
        upgrade(map).unwrap();
        assert_eq!(map["schema_version"], json!(2));
        let r = &map["channels"]["r"];
        assert_eq!(
            r["sigma_s_prime"],
            json!({"value": 1.5, "fit": 0.01, "spectro": 0.02, "g": 0.0, "model": null})
        );
        assert_eq!(
            r["sigma_a"],
            json!({"value": 0.1, "fit": 0.001, "spectro": null, "g": null, "model": null})
        );
        assert_eq!(
            r["albedo_prime"],
            json!({"value": 0.9, "fit": 0.004, "spectro": 0.003, "g": null, "model": null})
        );
        assert_eq!(r["rd_total"], json!(0.5));
        assert!(r.get("sigma_s_prime_stderr").is_none());
        assert_eq!(
            map["channels"]["b"],
            json!({"sigma_s_prime": null, "sigma_a": null})
        );
    }

    /// A version-2 file is left as it is; a newer one, or a version that is no whole number, is
    /// refused with what to do.
    #[test]
    fn versions_are_checked() {
        let v2 = json!({"schema_version": 2, "channels": {"r": {"sigma_a": {"value": 1.0}}}});
        let mut same = v2.clone();
        upgrade(same.as_object_mut().unwrap()).unwrap();
        assert_eq!(same, v2);
        let mut newer = json!({"schema_version": 3, "channels": {}});
        let e = upgrade(newer.as_object_mut().unwrap()).unwrap_err();
        assert!(
            e.contains("newer scatterfit") && e.contains("update"),
            "{e}"
        );
        for bad in [json!(0), json!(1.5), json!("2"), json!(-1)] {
            let mut f = json!({"schema_version": bad, "channels": {}});
            assert!(upgrade(f.as_object_mut().unwrap()).is_err());
        }
    }
}
