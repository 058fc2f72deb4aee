//! The medium: a stack of plane-parallel layers (a slab, or a half-space when the last layer is
//! infinitely thick) between two outside media.

use serde::{Deserialize, Serialize};

use crate::error::{Result, check};

/// One homogeneous layer. Coefficients in mm⁻¹, thickness in mm.
///
/// Built only through [`Layer::new`] or [`Layer::from_reduced`]; JSON is read through the same
/// checks (`#[serde(try_from)]`). An infinite thickness is written as `null` (JSON has no infinity).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawLayer", into = "RawLayer")]
pub struct Layer {
    sigma_a: f64,
    sigma_s: f64,
    g: f64,
    n: f64,
    thickness: f64,
}

/// The unchecked shape of [`Layer`] in files; `thickness: null` is a half-space.
#[derive(Clone, Copy, Serialize, Deserialize)]
struct RawLayer {
    sigma_a: f64,
    sigma_s: f64,
    g: f64,
    n: f64,
    thickness: Option<f64>,
}

impl TryFrom<RawLayer> for Layer {
    type Error = crate::McError;
    fn try_from(raw: RawLayer) -> Result<Self> {
        Self::new(
            raw.sigma_a,
            raw.sigma_s,
            raw.g,
            raw.n,
            raw.thickness.unwrap_or(f64::INFINITY),
        )
    }
}

impl From<Layer> for RawLayer {
    fn from(l: Layer) -> Self {
        Self {
            sigma_a: l.sigma_a,
            sigma_s: l.sigma_s,
            g: l.g,
            n: l.n,
            thickness: l.thickness.is_finite().then_some(l.thickness),
        }
    }
}

impl Layer {
    /// A layer from its absorption coefficient σa [mm⁻¹], scattering coefficient σs [mm⁻¹],
    /// Henyey–Greenstein asymmetry g ∈ (−1, 1), refractive index n > 0 (absolute: the outside media
    /// have their own indices) and thickness \[mm\] (`f64::INFINITY` for a half-space).
    ///
    /// # Errors
    /// `InvalidParameter` for negative or non-finite coefficients, σa + σs = 0 (a clear layer is not
    /// supported), g outside (−1, 1), n ≤ 0, or a thickness that is not positive.
    pub fn new(sigma_a: f64, sigma_s: f64, g: f64, n: f64, thickness: f64) -> Result<Self> {
        check(
            sigma_a.is_finite() && sigma_a >= 0.0,
            "sigma_a",
            sigma_a,
            "the absorption coefficient must be finite and ≥ 0 (mm⁻¹)",
        )?;
        check(
            sigma_s.is_finite() && sigma_s >= 0.0,
            "sigma_s",
            sigma_s,
            "the scattering coefficient must be finite and ≥ 0 (mm⁻¹)",
        )?;
        check(
            sigma_a + sigma_s > 0.0,
            "sigma_t",
            sigma_a + sigma_s,
            "σa + σs must be > 0: clear layers (glass slides) are not supported yet; MCML's \
             treatment (R_sp with the slide's multiple reflections, launch below the slide) is not \
             implemented (a slide is not equivalent to changing n_above, which also moves the \
             critical angle of the light leaving the sample)",
        )?;
        check(
            g.is_finite() && g > -1.0 && g < 1.0,
            "g",
            g,
            "the Henyey–Greenstein asymmetry must lie in (−1, 1)",
        )?;
        check(
            n.is_finite() && n > 0.0,
            "n",
            n,
            "the refractive index must be finite and > 0",
        )?;
        check(
            thickness > 0.0 && !thickness.is_nan(),
            "thickness",
            thickness,
            "the thickness must be > 0 mm (f64::INFINITY for a half-space)",
        )?;
        Ok(Self {
            sigma_a,
            sigma_s,
            g,
            n,
            thickness,
        })
    }

    /// A layer from graphics parameters: reduced scattering σ′s [mm⁻¹], σa [mm⁻¹], g and n; the
    /// scattering coefficient is σs = σ′s / (1 − g) (the similarity relation, docs/physics.md conventions).
    ///
    /// # Errors
    /// As [`Layer::new`]; σ′s is checked before the division.
    pub fn from_reduced(
        sigma_s_prime: f64,
        sigma_a: f64,
        g: f64,
        n: f64,
        thickness: f64,
    ) -> Result<Self> {
        check(
            sigma_s_prime.is_finite() && sigma_s_prime >= 0.0,
            "sigma_s_prime",
            sigma_s_prime,
            "the reduced scattering coefficient must be finite and ≥ 0 (mm⁻¹)",
        )?;
        check(
            g.is_finite() && g > -1.0 && g < 1.0,
            "g",
            g,
            "the Henyey–Greenstein asymmetry must lie in (−1, 1)",
        )?;
        Self::new(sigma_a, sigma_s_prime / (1.0 - g), g, n, thickness)
    }

    /// Absorption coefficient σa [mm⁻¹].
    pub fn sigma_a(&self) -> f64 {
        self.sigma_a
    }
    /// Scattering coefficient σs [mm⁻¹].
    pub fn sigma_s(&self) -> f64 {
        self.sigma_s
    }
    /// Henyey–Greenstein asymmetry g.
    pub fn g(&self) -> f64 {
        self.g
    }
    /// Refractive index n.
    pub fn n(&self) -> f64 {
        self.n
    }
    /// Thickness \[mm\] (infinite for a half-space).
    pub fn thickness(&self) -> f64 {
        self.thickness
    }
}

/// A stack of layers, top (z = 0, where light enters) to bottom, with the indices of the media above
/// and below. Built only through [`Sample::new`] or [`Sample::slab`]; JSON is read through the same
/// checks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawSample")]
pub struct Sample {
    layers: Vec<Layer>,
    n_above: f64,
    n_below: f64,
}

/// The unchecked shape of [`Sample`] in files.
#[derive(Deserialize)]
struct RawSample {
    layers: Vec<Layer>,
    n_above: f64,
    n_below: f64,
}

impl TryFrom<RawSample> for Sample {
    type Error = crate::McError;
    fn try_from(raw: RawSample) -> Result<Self> {
        Self::new(raw.layers, raw.n_above, raw.n_below)
    }
}

impl Sample {
    /// A stack of `layers` between a medium of index `n_above` (where the light comes from) and one of
    /// index `n_below`.
    ///
    /// # Errors
    /// `InvalidParameter` for an empty stack, an infinite layer that is not the last one, or an
    /// outside index that is not finite and > 0.
    pub fn new(layers: Vec<Layer>, n_above: f64, n_below: f64) -> Result<Self> {
        check(
            !layers.is_empty(),
            "layers",
            0.0,
            "a sample needs at least one layer",
        )?;
        for (i, layer) in layers.iter().enumerate() {
            check(
                layer.thickness.is_finite() || i + 1 == layers.len(),
                "thickness",
                layer.thickness,
                "only the last layer may be infinitely thick",
            )?;
        }
        for (name, n) in [("n_above", n_above), ("n_below", n_below)] {
            check(
                n.is_finite() && n > 0.0,
                name,
                n,
                "the outside refractive index must be finite and > 0",
            )?;
        }
        Ok(Self {
            layers,
            n_above,
            n_below,
        })
    }

    /// One layer with the same outside index on both faces (usually 1, air).
    ///
    /// # Errors
    /// As [`Sample::new`].
    pub fn slab(layer: Layer, n_outside: f64) -> Result<Self> {
        Self::new(vec![layer], n_outside, n_outside)
    }

    /// The layers, top to bottom.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }
    /// Index of the medium above (the light's side).
    pub fn n_above(&self) -> f64 {
        self.n_above
    }
    /// Index of the medium below.
    pub fn n_below(&self) -> f64 {
        self.n_below
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::McError;

    /// JSON goes through the constructors: a stack round-trips (a half-space's infinite thickness
    /// as `null`), and invalid layers or stacks in a file are refused.
    #[test]
    fn json_round_trip_goes_through_the_checks() {
        let top = Layer::new(0.2, 5.0, 0.8, 1.5, 0.3).unwrap();
        let bottom = Layer::new(0.05, 2.0, 0.0, 1.33, f64::INFINITY).unwrap();
        let sample = Sample::new(vec![top, bottom], 1.0, 1.2).unwrap();
        let json = serde_json::to_string(&sample).unwrap();
        assert!(json.contains("\"thickness\":null"), "{json}");
        assert_eq!(serde_json::from_str::<Sample>(&json).unwrap(), sample);
        for bad in [
            r#"{"sigma_a":-1,"sigma_s":1,"g":0,"n":1.4,"thickness":1}"#,
            r#"{"sigma_a":0,"sigma_s":0,"g":0,"n":1.4,"thickness":1}"#,
            r#"{"sigma_a":0.1,"sigma_s":1,"g":1,"n":1.4,"thickness":1}"#,
            r#"{"sigma_a":0.1,"sigma_s":1,"g":0,"n":1.4,"thickness":0}"#,
        ] {
            assert!(serde_json::from_str::<Layer>(bad).is_err(), "{bad}");
        }
        let infinite_on_top = json.replace("\"thickness\":0.3", "\"thickness\":null");
        assert!(serde_json::from_str::<Sample>(&infinite_on_top).is_err());
        assert!(
            serde_json::from_str::<Sample>(r#"{"layers":[],"n_above":1,"n_below":1}"#).is_err()
        );
    }

    /// A clear layer (σa = σs = 0, a glass slide) is refused with a typed error naming σt, not traced.
    #[test]
    fn clear_layer_is_refused() {
        let e = Layer::new(0.0, 0.0, 0.0, 1.5, 1.0).unwrap_err();
        assert!(
            matches!(
                e,
                McError::Optics(scatterfit_optics::OpticsError::InvalidParameter {
                    name: "sigma_t",
                    ..
                })
            ),
            "{e:?}"
        );
        assert!(e.to_string().contains("glass"), "{e}");
    }
}
