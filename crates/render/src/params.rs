//! Where a render's parameters come from: a `result.json` of `scatterfit measure` (read through
//! `scatterfit_io::result_json`'s checked reader), or one of Choi et al.'s published sets by name
//! (`scatterfit_optics::materials`: Table 1, and the existing method's values quoted with Figure 5).
//! The material the renderer shades with is made by the one name → model factory,
//! `scatterfit_mc::family`, with the model the parameters were fitted with unless the caller
//! overrides it.
//!
//! This module and [`crate::measured`] are the crate's file-reading edge: the renderer itself takes
//! arrays and typed values only.

use std::path::{Path, PathBuf};

use scatterfit_io::result_json::{
    MeasurementResult, ResultJsonError, read_result_json, read_result_json_assuming,
};
use scatterfit_optics::materials::{PublishedSet, choi_2014_set, choi_2014_sets};
use scatterfit_optics::{ModelName, Rgb};

use crate::error::{RenderError, Result};
use crate::profile::Material;

/// Where a parameter set came from.
#[derive(Debug, Clone)]
pub enum ParamOrigin {
    /// One of Choi et al.'s published sets.
    Published(PublishedSet),
    /// A result file, read whole, and the folder it is in (its `inputs.profile` is relative to it).
    Result {
        /// The result as read.
        result: Box<MeasurementResult>,
        /// The file.
        path: PathBuf,
        /// Its folder (`.` for a bare file name).
        folder: PathBuf,
    },
}

/// One parameter set to render, wherever it came from.
#[derive(Debug, Clone)]
pub struct ParameterSet {
    /// Display name (the sample's, or the published material's with spaces).
    pub name: String,
    /// The forward model the parameters were fitted with (`dipole` for published ones).
    pub model: ModelName,
    /// `proposed`, `existing`, or the result's method.
    pub method: scatterfit_optics::Method,
    /// Where it came from, for people: the path, or "published: Choi et al. 2014, Table 1".
    pub source: String,
    /// Relative refractive index η.
    pub eta: f64,
    /// (σ′s, σa) per channel [mm⁻¹].
    pub coefficients: Rgb<(f64, f64)>,
    /// The origin, with the result when read from one.
    pub origin: ParamOrigin,
}

impl ParameterSet {
    /// Loads `spec`: a result file when a file of that name exists (a folder: its `result.json`),
    /// else a published set's name
    /// (`pink-plastic`, `pink-plastic-existing`, …). `model` is the caller's override of the fitted
    /// model: it also lets a result fitted with a model this version does not know be rendered.
    ///
    /// # Errors
    /// [`RenderError::UnknownParameters`] (neither a file nor a published name),
    /// [`RenderError::ResultJson`] (an unreadable result), [`RenderError::UnknownModel`],
    /// [`RenderError::FailedChannel`] (a channel without σ′s or σa: a failed measurement).
    pub fn load(spec: &str, model: Option<ModelName>) -> Result<Self> {
        let given = Path::new(spec);
        // A folder (a sample folder, e.g. the demo's `pink-plastic/` beside the published set of
        // that name) stands for its result.json; one without a result is not a result file.
        let in_folder;
        let path = if given.is_dir() {
            in_folder = given.join("result.json");
            if !in_folder.is_file() {
                return Self::published(spec);
            }
            in_folder.as_path()
        } else {
            given
        };
        if !path.exists() {
            return Self::published(spec);
        }
        // A model this version does not know is the caller's to replace (`model`), else refused.
        let read = match model {
            Some(m) => read_result_json_assuming(path, m),
            None => read_result_json(path),
        };
        let result = match read {
            Err(ResultJsonError::UnknownModel { found, .. }) => {
                return Err(RenderError::UnknownModel {
                    spec: spec.to_owned(),
                    model: scatterfit_io::escape::token(&found).to_string(),
                });
            }
            r => r?,
        };
        let fitted = result.model();
        let coefficients = result.coefficients().map_err(|ch| {
            let c = &result.channels[ch];
            RenderError::FailedChannel {
                spec: spec.to_owned(),
                channel: ch.key(),
                status: format!("{:?}", c.status),
                problem: c.problem.clone(),
            }
        })?;
        let folder = path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        Ok(Self {
            model: fitted,
            name: result.name.clone(),
            method: result.method,
            source: path.display().to_string(),
            eta: result.eta,
            coefficients,
            origin: ParamOrigin::Result {
                result: Box::new(result),
                path: path.to_path_buf(),
                folder,
            },
        })
    }

    /// A published set by name.
    fn published(spec: &str) -> Result<Self> {
        let Some(set) = choi_2014_set(spec) else {
            let (proposed, existing): (Vec<_>, Vec<_>) =
                choi_2014_sets().partition(|s| s.method == scatterfit_optics::Method::Proposed);
            let keys = |v: Vec<PublishedSet>| v.iter().map(|s| s.key()).collect::<Vec<_>>();
            return Err(RenderError::UnknownParameters {
                spec: spec.to_owned(),
                published: keys(proposed),
                existing: keys(existing),
            });
        };
        let m = set.material;
        Ok(Self {
            model: ModelName::Dipole,
            name: m.name.replace('-', " "),
            method: set.method,
            source: format!("published: {}", set.citation()),
            eta: m.eta,
            coefficients: Rgb::from_array(std::array::from_fn(|c| {
                (m.sigma_s_prime[c], m.sigma_a[c])
            })),
            origin: ParamOrigin::Published(set),
        })
    }

    /// The model the texture-space method renders with: `model` when given, else the fitted one.
    pub fn model_or(&self, model: Option<ModelName>) -> ModelName {
        model.unwrap_or(self.model)
    }

    /// The renderer's material for these parameters with the profile model `model_or(model)`,
    /// made by `scatterfit_mc::family`; g = 0 (measured parameters carry none).
    ///
    /// # Errors
    /// [`RenderError::Mc`] when the Monte Carlo tables are unavailable; [`RenderError::Material`]
    /// naming the set, with [`Material::new`]'s error.
    pub fn material(&self, model: Option<ModelName>) -> Result<Material> {
        let named = |source: RenderError| RenderError::Material {
            name: self.name.clone(),
            source: Box::new(source),
        };
        let family = scatterfit_mc::family(self.model_or(model))?;
        Material::new(family, self.coefficients, self.eta, 0.0).map_err(named)
    }

    /// The result the set was read from, with its file and folder.
    pub fn result(&self) -> Option<(&MeasurementResult, &Path, &Path)> {
        match &self.origin {
            ParamOrigin::Result {
                result,
                path,
                folder,
            } => Some((result, path, folder)),
            ParamOrigin::Published(_) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_sets_by_name() {
        let p = ParameterSet::load("pink-plastic-existing", None).unwrap();
        assert_eq!(p.name, "pink plastic");
        assert_eq!(p.method, scatterfit_optics::Method::Existing);
        assert_eq!(p.model, ModelName::Dipole);
        // The paper's sentence for Figure 5 (a1)/(a3): G: (1.522, 0.4515); η of Table 1.
        assert_eq!(p.coefficients.g, (1.522, 0.4515));
        assert_eq!(p.eta, 1.2886);
        assert!(p.source.contains("Figure 5"));
        let t = ParameterSet::load("Wood Tile", None).unwrap();
        assert_eq!(t.coefficients.b, (1.461, 0.13836));
        assert!(t.source.contains("Table 1") && t.result().is_none());
        let err = ParameterSet::load("unobtainium", None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("not a published material") && err.contains("sulfur"));
        assert!(err.contains("brown-leather-existing"), "{err}");
    }
}
