//! Whether a sample's result files can stand for measuring it again (`scatterfit batch` without
//! `--force`): one complete result set whose result.json records the SHA-256 its input files still
//! have, made with the options the caller asks for.

use std::path::Path;

use scatterfit_io::result_json::MeasurementResult;
use scatterfit_io::result_set::{SetStatus, verify};

use crate::Overrides;

/// The result in `dir` when it can be reused: the result set (result.json, profile.csv) complete,
/// every input it names (manifest, spectro file, radiance map, frames) with the SHA-256 it records,
/// and every option `o` gives equal to the one it was made with. A g range or a g fit asked for in
/// `o` is not recorded in a result: such runs measure every sample (`None`).
pub fn reusable_result(dir: &Path, o: &Overrides) -> Option<MeasurementResult> {
    if o.g.is_some_and(|p| p.range.is_some() || p.fit) {
        return None;
    }
    let given_g = o.g.and_then(|p| p.g);
    if !matches!(
        verify(dir, &["result.json", "profile.csv"]),
        Ok(SetStatus::Complete(_))
    ) {
        return None;
    }
    let r = scatterfit_io::result_json::read_result_json(&dir.join("result.json")).ok()?;
    let inputs = &r.inputs;
    let manifest = inputs.manifest.as_ref()?;
    let refs = std::iter::once(manifest)
        .chain(inputs.spectro.as_ref())
        .chain(inputs.hdr.as_ref())
        .chain(&inputs.frames);
    for f in refs {
        if crate::samples::hash_file(&dir.join(&f.path)).as_deref() != Some(&f.sha256) {
            return None;
        }
    }
    let opt = &inputs.options;
    let same = |given: bool, ok: bool| !given || ok;
    (same(o.method.is_some(), opt.method == o.method)
        && same(o.model.is_some(), opt.model == o.model)
        && same(o.albedo_model.is_some(), opt.albedo_model == o.albedo_model)
        && same(given_g.is_some(), opt.g == given_g)
        && same(o.eta.is_some(), Some(r.eta) == o.eta)
        && same(
            o.normalise_with_spectro.is_some(),
            opt.normalise_with_spectro == o.normalise_with_spectro,
        ))
    .then_some(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_without_a_complete_result_set_is_measured() {
        let dir = tempfile::tempdir().unwrap();
        assert!(reusable_result(dir.path(), &Overrides::default()).is_none());
        // A result.json alone (no profile.csv, no set record) is not a complete set.
        std::fs::write(dir.path().join("result.json"), "{}").unwrap();
        assert!(reusable_result(dir.path(), &Overrides::default()).is_none());
    }
}
