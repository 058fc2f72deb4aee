//! The samples of a run: finding sample folders among the paths a user gives ([`sample_dirs`]) and
//! resolving one sample's manifest and input files once ([`sample_inputs`]), before any pixel work.

use std::path::{Path, PathBuf};

use scatterfit_io::manifest::{SampleManifest, read_manifest};

use crate::error::Result;

/// A sample's manifest and every file a measurement of it reads, resolved once
/// ([`sample_inputs`]): what [`crate::measure_inputs`] measures and what a caller checks its
/// outputs against.
#[derive(Debug, Clone)]
pub struct SampleInputs {
    /// The manifest.
    pub manifest: SampleManifest,
    /// Every input file with where it is named (`sample.toml`, `spectro.file`, `camera.images`,
    /// `exposures.csv line 3`, …), resolved against the sample folder.
    pub files: Vec<(String, PathBuf)>,
    /// The bracket's frames as the measurement will read them (`camera.images`, else the frames
    /// the exposures CSV lists; none for a radiance map or a CSV that cannot be read).
    pub frames: Vec<PathBuf>,
}

impl SampleInputs {
    /// The measurement's peak memory \[bytes\], estimated from the images' headers (not their
    /// pixels): the decoded bracket, and as much again for the radiance map, its mask and the
    /// decoders' copies, plus the dark frame, flat frame and spot image; for a radiance map file,
    /// 6 × its size (a float map decodes to ≈ 3 × the file, plus the copy made on reading). 0 when
    /// unknown (the measurement reports what is wrong).
    pub fn peak_memory_bytes(&self) -> u64 {
        let m = &self.manifest;
        if let Some(hdr) = &m.camera.hdr {
            return std::fs::metadata(m.resolve(hdr)).map_or(0, |md| md.len().saturating_mul(6));
        }
        let (total, _, _) =
            scatterfit_io::bracket::decoded_size(self.frames.iter().map(PathBuf::as_path));
        // The other images read whole (dark, flat, spot image), from their headers too.
        let others = self
            .files
            .iter()
            .filter(|(key, _)| {
                ["`camera.dark`", "`camera.flat`", "`camera.spot_image`"].contains(&key.as_str())
            })
            .map(|(_, p)| p.as_path());
        let (extra, _, _) = scatterfit_io::bracket::decoded_size(others);
        total.saturating_mul(2).saturating_add(extra)
    }
}

/// Reads the manifest of the sample `dir` (a folder, or a manifest file) and lists every file a
/// measurement reads — the manifest, the files it names, the frames its exposures CSV lists — each
/// checked against the input path policy (`scatterfit_io::inputs`: inside the sample folder, links
/// that leave it counting as outside, unless `allow_outside`). Cheap: no image is decoded. What
/// `measure_sample` starts with, and what the CLI checks its outputs against before any work.
///
/// # Errors
/// [`crate::PipelineError::InputPath`] for a file outside the folder; the manifest's errors. (An exposures
/// CSV that cannot be read lists no frame; the measurement reports it.)
pub fn sample_inputs(dir: &Path, allow_outside: bool) -> Result<SampleInputs> {
    let manifest_path = if dir.is_dir() {
        dir.join(scatterfit_io::manifest::MANIFEST_NAME)
    } else {
        dir.to_path_buf()
    };
    let folder = manifest_path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let policy = scatterfit_io::inputs::InputPolicy::new(folder, allow_outside)?;
    // The manifest itself: a link that leaves the folder is refused before it is read.
    policy.check(&manifest_path, "the manifest", &manifest_path)?;
    let manifest = read_manifest(dir)?;
    let mut files = vec![("the manifest".to_string(), manifest_path.clone())];
    let m = &manifest;
    let mut frames = Vec::new();
    // One resolver for every key: relative paths beneath the sample folder only.
    for (key, named) in m.named_paths() {
        let key = format!("`{key}`");
        let path = policy.resolve(&manifest_path, &key, &m.dir, named)?;
        if key == "`camera.images`" {
            frames.push(path.clone());
        }
        files.push((key, path));
    }
    if m.camera.hdr.is_none()
        && m.camera.images.as_ref().is_none_or(Vec::is_empty)
        && let Some(csv) = &m.camera.exposures
    {
        let csv = m.resolve(csv);
        let csv_dir = csv.parent().unwrap_or(Path::new("."));
        // An exposures CSV that cannot be read names no frame that could be read; the bracket
        // stage reports it in its turn (after the spectrophotometer's errors, as before).
        let listed = scatterfit_io::bracket::read_exposures_csv(&csv).unwrap_or_default();
        for e in listed {
            let key = format!(
                "the frame on line {} of {}",
                e.line,
                csv.file_name().unwrap_or_default().to_string_lossy()
            );
            let path = policy.resolve(&csv, &key, csv_dir, &e.named)?;
            frames.push(path.clone());
            files.push((key, path));
        }
    }
    Ok(SampleInputs {
        manifest,
        files,
        frames,
    })
}

/// The sample folders found by [`sample_dirs`], and what it did not measure.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SampleDirs {
    /// The sample folders, each once, in the order given (a folder of samples expands to its
    /// sub-folders that hold a `sample.toml`, sorted).
    pub dirs: Vec<PathBuf>,
    /// Paths naming a folder already in `dirs` under another spelling (`a`, `./a`, `a/`, a link to
    /// it): `(path, the one kept)`. Each folder is measured once.
    pub duplicates: Vec<(PathBuf, PathBuf)>,
    /// Folders without a `sample.toml` but with a file that looks like a misspelt one
    /// (`Sample.toml`, `sample.TOML`, `sample.toml.txt`): `(folder, the file)`. Not measured;
    /// to be reported.
    pub misspelt: Vec<(PathBuf, PathBuf)>,
    /// Sub-folders of a folder of samples that are symbolic links leading out of it: `(the link,
    /// the folder given)`. Never followed (results would be written where the link points); to be
    /// reported.
    pub links_out: Vec<(PathBuf, PathBuf)>,
}

/// A file in `dir` whose name looks like a misspelt `sample.toml`.
pub fn misspelt_manifest(dir: &Path) -> Option<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .ok()?
        .flatten()
        .filter(|e| {
            let name = e.file_name().to_string_lossy().to_lowercase();
            let exact = e.file_name() == scatterfit_io::manifest::MANIFEST_NAME;
            !exact
                && (name == "sample.toml"
                    || name.starts_with("sample.toml")
                    || (name.starts_with("sample")
                        && (name.ends_with(".toml") || name.ends_with(".tml"))))
        })
        .map(|e| e.path())
        .collect();
    found.sort();
    found.into_iter().next()
}

/// The sample folders among `paths`: each path that holds a `sample.toml`, or, for a folder that
/// does not, its immediate sub-folders that do (so `batch samples/` works on a folder of samples).
pub fn sample_dirs(paths: &[PathBuf]) -> SampleDirs {
    let manifest = scatterfit_io::manifest::MANIFEST_NAME;
    let mut candidates: Vec<PathBuf> = Vec::new();
    let mut misspelt = Vec::new();
    let mut links_out = Vec::new();
    for p in paths {
        if p.join(manifest).is_file() || !p.is_dir() {
            candidates.push(p.clone());
            continue;
        }
        let mut subs: Vec<PathBuf> = std::fs::read_dir(p)
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path())
            .filter(|d| d.is_dir())
            .collect();
        subs.sort();
        let top = std::fs::canonicalize(p).unwrap_or_else(|_| p.clone());
        let mut found = Vec::new();
        let links_before = links_out.len();
        for d in subs {
            let leaves = std::fs::canonicalize(&d).map_or(true, |c| !c.starts_with(&top));
            if leaves {
                if d.join(manifest).is_file() || misspelt_manifest(&d).is_some() {
                    links_out.push((d, p.clone()));
                }
                continue;
            }
            if d.join(manifest).is_file() {
                found.push(d);
            } else if let Some(f) = misspelt_manifest(&d) {
                misspelt.push((d, f));
            }
        }
        if found.is_empty() && links_out.len() > links_before {
            // A folder of samples whose samples are all links that leave it: reported, not
            // measured as a sample itself.
            continue;
        }
        if found.is_empty() {
            // Not a folder of samples: measured as given (and its error reported), unless its
            // manifest is misspelt.
            match misspelt_manifest(p) {
                Some(f) => misspelt.push((p.clone(), f)),
                None => candidates.push(p.clone()),
            }
        } else {
            candidates.extend(found);
        }
    }
    let mut out = SampleDirs {
        misspelt,
        links_out,
        ..SampleDirs::default()
    };
    let mut seen: Vec<(PathBuf, PathBuf)> = Vec::new();
    for c in candidates {
        let id = std::fs::canonicalize(&c).unwrap_or_else(|_| c.clone());
        if let Some((_, kept)) = seen.iter().find(|(i, _)| *i == id) {
            out.duplicates.push((c, kept.clone()));
        } else {
            seen.push((id, c.clone()));
            out.dirs.push(c);
        }
    }
    out
}

/// SHA-256 of a file's bytes, lower-case hex (`None` when it cannot be read: missing, not a
/// regular file, larger than the memory budget): for a file that is not otherwise read, such as
/// `batch`'s check of a sample's inputs against the hashes its `result.json` recorded. A
/// measurement's own inputs are hashed as they are read (`Measurement::to_result`).
pub fn hash_file(path: &Path) -> Option<String> {
    let bytes =
        scatterfit_safefs::read::read_limited(path, scatterfit_io::budget::memory_budget_bytes())
            .ok()?;
    Some(scatterfit_io::digest::sha256_hex(&bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One folder named four ways is one sample; misspelt manifests are reported, not skipped.
    #[test]
    fn sample_dirs_measures_each_folder_once_and_reports_misspelt_manifests() {
        let top = tempfile::tempdir().unwrap();
        let t = top.path();
        for (d, m) in [
            ("a", "sample.toml"),
            ("b", "Sample.toml"),
            ("c", "sample.TOML"),
            ("d", "sample.toml.txt"),
            ("e", "notes.txt"),
        ] {
            std::fs::create_dir(t.join(d)).unwrap();
            std::fs::write(t.join(d).join(m), b"").unwrap();
        }
        let a = t.join("a");
        let mut given = vec![
            a.clone(),
            t.join("./a"),
            PathBuf::from(format!("{}/", a.display())),
        ];
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&a, t.join("link-to-a")).unwrap();
            given.push(t.join("link-to-a"));
        }
        given.push(t.to_path_buf());
        let found = sample_dirs(&given);
        assert_eq!(found.dirs, vec![a.clone()]);
        // Every other spelling (and the folder of samples, which holds `a` and the link) is a
        // duplicate of the first.
        assert!(found.duplicates.len() >= given.len() - 1, "{found:?}");
        assert!(found.duplicates.iter().all(|(_, kept)| *kept == a));
        let mut misspelt: Vec<String> = found
            .misspelt
            .iter()
            .map(|(_, f)| f.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        misspelt.sort();
        assert_eq!(misspelt, ["Sample.toml", "sample.TOML", "sample.toml.txt"]);
        // A folder given directly whose manifest is misspelt is reported too.
        let found = sample_dirs(&[t.join("b")]);
        assert!(
            found.dirs.is_empty() && found.misspelt.len() == 1,
            "{found:?}"
        );
    }
}
