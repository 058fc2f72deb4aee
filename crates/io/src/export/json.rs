//! The renderer-neutral JSON export ([`Format::Json`](super::Format::Json)): [`RendererParameters`]
//! serialised as it is, every derived quantity per channel in the scene's unit.

use super::RendererParameters;

/// Identifies the renderer-neutral JSON ([`RendererParameters::format`]).
pub const JSON_FORMAT_TAG: &str = "scatterfit-renderer-parameters";
/// Version of the renderer-neutral JSON layout.
pub const JSON_FORMAT_VERSION: u32 = 1;

/// The renderer-neutral JSON text (pretty, newline-terminated).
pub fn json(params: &RendererParameters) -> String {
    // A struct of finite numbers, strings and options always serialises.
    let mut text = serde_json::to_string_pretty(params).unwrap_or_default();
    text.push('\n');
    text
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{SA, SP, close, marble};
    use super::super::{Format, SceneUnit, export};
    use super::*;

    /// The JSON round-trips and its quantities are consistent: σt = σa + σs, albedo = σs/σt,
    /// mfp = 1/σt, σtr = √(3σaσt); metres are ×1000 per length⁻¹.
    #[test]
    fn json_is_consistent_and_round_trips() {
        let r = marble();
        let text = export(&r, Format::Json, SceneUnit::Metre).unwrap().text;
        let p: RendererParameters = serde_json::from_str(&text).unwrap();
        assert_eq!(p.format, JSON_FORMAT_TAG);
        assert_eq!(p.unit, SceneUnit::Metre);
        assert!(text.contains("\"unit\": \"m\""));
        for (c, ch) in p.channels.as_array().iter().enumerate() {
            assert!(close(ch.sigma_a, SA[c] * 1000.0, 1e-12));
            assert!(close(ch.sigma_s, SP[c] * 1000.0, 1e-12));
            assert!(close(ch.sigma_t, ch.sigma_a + ch.sigma_s, 1e-12));
            assert!(close(ch.albedo, SP[c] / (SP[c] + SA[c]), 1e-12));
            assert!(close(ch.mfp * ch.sigma_t, 1.0, 1e-12));
            assert!(close(
                ch.sigma_tr,
                (3.0 * ch.sigma_a * ch.sigma_t).sqrt(),
                1e-12
            ));
        }
        // docs/physics.md §1.5: the marble's 1/σtr is 8.509, 5.566, 3.951 mm.
        let (mm, _) = RendererParameters::from_result(&r, SceneUnit::Millimetre).unwrap();
        for (ch, want) in mm.channels.as_array().iter().zip([8.509, 5.566, 3.951]) {
            assert!((ch.diffusion_length.unwrap() - want).abs() < 5e-4);
        }
    }
}
