//! Where an input named by a file may be: the input path policy.
//!
//! A manifest (`sample.toml`) names its spectro file, frames, response, dark frame or radiance map;
//! a frame list (`exposures.csv`) names frames; a `result.json` names its profile (`inputs.profile`,
//! which `render --profile` follows). Whoever can write such a file — a colleague, a drop folder's
//! other users — must not be able to make scatterfit read, hash and report on any file its user can
//! read (`/etc/shadow` when run as root, another project's data). So:
//!
//! - a path named in a file resolves **inside the folder of the file that names it** (the sample
//!   folder; the result's folder), after every symbolic link is followed: a link that leaves the
//!   folder counts as outside, as do `../x` and absolute paths that lead out;
//! - the user may allow otherwise for a run (`--allow-outside-paths`), e.g. for a shared dark frame
//!   kept beside the sample folders;
//! - paths given on the command line are the user's own choice and are not restricted.
//!
//! The check is made before any work, on the paths as they resolve then. (A file swapped for a link
//! between the check and the read — by someone writing into the folder during the run — is not
//! caught: that would need every reader to open beneath the folder, `openat2(RESOLVE_BENEATH)`.)

use std::path::{Path, PathBuf};

/// An input that resolves outside its folder, or a folder that cannot be resolved.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InputPathError {
    /// The path resolves outside the folder.
    #[error(
        "{}: {key} = {} resolves outside {} (to {}); files named by a manifest or result stay \
         inside its folder — symbolic links that leave it count as outside. Move or copy the file \
         into the folder, or pass --allow-outside-paths if you trust this file",
        named_in.display(),
        crate::escape::one_line(&path.to_string_lossy()),
        root.display(),
        resolved.display()
    )]
    Outside {
        /// The file that names the path (the manifest, the exposures CSV, the result).
        named_in: PathBuf,
        /// Where it is named, as shown: e.g. `` `spectro.file` ``, `` `inputs.profile` ``, `the frame
        /// on line 3 of exposures.csv`.
        key: String,
        /// The path as named.
        path: PathBuf,
        /// Where it leads.
        resolved: PathBuf,
        /// The folder it must stay in (resolved).
        root: PathBuf,
    },
    /// The folder itself cannot be resolved (it does not exist).
    #[error("cannot resolve the folder {}: {source}", root.display())]
    Root {
        /// The folder.
        root: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// The policy for one folder: its resolved path, and whether paths outside it are allowed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputPolicy {
    root: PathBuf,
    allow_outside: bool,
}

impl InputPolicy {
    /// The policy of `folder` (resolved now).
    ///
    /// # Errors
    /// [`InputPathError::Root`] when the folder cannot be resolved.
    pub fn new(folder: &Path, allow_outside: bool) -> Result<Self, InputPathError> {
        let folder = if folder.as_os_str().is_empty() {
            Path::new(".")
        } else {
            folder
        };
        let root = std::fs::canonicalize(folder).map_err(|source| InputPathError::Root {
            root: folder.to_path_buf(),
            source,
        })?;
        Ok(Self {
            root,
            allow_outside,
        })
    }

    /// The folder, resolved.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// True when paths outside the folder are allowed.
    pub fn allows_outside(&self) -> bool {
        self.allow_outside
    }

    /// Checks `path` (already joined to the folder if it was relative), named in `named_in` under
    /// `key`. A path that does not exist is left to its reader to report, unless the folder it
    /// would be in already lies outside.
    ///
    /// # Errors
    /// [`InputPathError::Outside`].
    pub fn check(&self, named_in: &Path, key: &str, path: &Path) -> Result<(), InputPathError> {
        if self.allow_outside {
            return Ok(());
        }
        let Some(resolved) = resolve(path) else {
            return Ok(());
        };
        if resolved.starts_with(&self.root) {
            return Ok(());
        }
        Err(InputPathError::Outside {
            named_in: named_in.to_path_buf(),
            key: key.to_string(),
            path: path.to_path_buf(),
            resolved,
            root: self.root.clone(),
        })
    }
}

/// `path` with every link followed: the file itself when it exists, else its folder joined with
/// its name (a dangling link resolves as far as its folder), else `None`.
fn resolve(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = std::fs::canonicalize(path) {
        return Some(p);
    }
    // A dangling symbolic link: where it points.
    if let Ok(target) = std::fs::read_link(path) {
        let base = path.parent().unwrap_or(Path::new("."));
        return resolve(&base.join(target));
    }
    let parent = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let dir = std::fs::canonicalize(parent).ok()?;
    Some(dir.join(path.file_name()?))
}

/// A path's identity for "is this one of the inputs?": the canonical path when it exists, else its
/// canonical folder joined with its name, else the path as given.
pub fn identity(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let parent = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    match (std::fs::canonicalize(parent), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => path.to_path_buf(),
    }
}

/// True when `a` and `b` are the same file: the same resolved path ([`identity`]), or, for files
/// that exist, the same device and inode (a hard link is the same file under another name).
pub fn same_file(a: &Path, b: &Path) -> bool {
    if identity(a) == identity(b) {
        return true;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return x.dev() == y.dev() && x.ino() == y.ino();
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    #[test]
    fn inside_is_fine_outside_is_refused_unless_allowed() {
        let top = tempfile::tempdir().unwrap();
        let sample = top.path().join("sample");
        fs::create_dir_all(sample.join("frames")).unwrap();
        fs::write(sample.join("spectro.csv"), b"x").unwrap();
        fs::write(sample.join("frames/a.png"), b"x").unwrap();
        fs::write(top.path().join("secret"), b"x").unwrap();
        let m = sample.join("sample.toml");
        let p = InputPolicy::new(&sample, false).unwrap();
        for inside in [
            "spectro.csv",
            "frames/a.png",
            "frames/../spectro.csv",
            "missing.csv",
        ] {
            p.check(&m, "k", &sample.join(inside)).unwrap();
        }
        for outside in ["../secret", "frames/../../secret", "/etc/passwd"] {
            let e = p
                .check(&m, "spectro.file", &sample.join(outside))
                .unwrap_err();
            let text = e.to_string();
            assert!(text.contains("--allow-outside-paths") && text.contains("spectro.file"));
        }
        // A missing file in a folder outside.
        assert!(p.check(&m, "k", &top.path().join("nowhere.csv")).is_err());
        let allowed = InputPolicy::new(&sample, true).unwrap();
        allowed.check(&m, "k", &sample.join("../secret")).unwrap();
    }

    /// Links that leave the folder count as outside — to a file, to a folder, dangling, chained;
    /// links that stay inside are fine.
    #[cfg(unix)]
    #[test]
    fn links_that_leave_the_folder_are_outside() {
        use std::os::unix::fs::symlink;
        let top = tempfile::tempdir().unwrap();
        let sample = top.path().join("sample");
        fs::create_dir(&sample).unwrap();
        fs::write(top.path().join("secret"), b"x").unwrap();
        fs::write(sample.join("real.csv"), b"x").unwrap();
        symlink(top.path().join("secret"), sample.join("file-link.csv")).unwrap();
        symlink(top.path(), sample.join("dir-link")).unwrap();
        symlink(top.path().join("not-yet"), sample.join("dangling.csv")).unwrap();
        symlink(sample.join("file-link.csv"), sample.join("chain.csv")).unwrap();
        symlink(sample.join("real.csv"), sample.join("inner-link.csv")).unwrap();
        let m = sample.join("sample.toml");
        let p = InputPolicy::new(&sample, false).unwrap();
        for bad in [
            "file-link.csv",
            "dir-link/secret",
            "dangling.csv",
            "chain.csv",
        ] {
            assert!(p.check(&m, "k", &sample.join(bad)).is_err(), "{bad}");
        }
        p.check(&m, "k", &sample.join("inner-link.csv")).unwrap();
        // A sample folder that is itself a link: its files are inside its target.
        let alias = top.path().join("alias");
        symlink(&sample, &alias).unwrap();
        let p = InputPolicy::new(&alias, false).unwrap();
        p.check(&m, "k", &alias.join("real.csv")).unwrap();
    }
}
