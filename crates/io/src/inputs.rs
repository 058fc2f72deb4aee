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

use std::path::{Component, Path, PathBuf};

/// Why a named path is refused (the same words for every key).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum OutsideReason {
    /// The path is absolute.
    Absolute,
    /// The path goes up with `..` (or names a drive or root).
    GoesUp,
    /// A symbolic link on the way leads out of the folder (or cannot be followed).
    Link,
}

impl std::fmt::Display for OutsideReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Absolute => "it is an absolute path",
            Self::GoesUp => "it goes up with `..`",
            Self::Link => "a symbolic link on its way leads outside the folder",
        })
    }
}

/// An input that resolves outside its folder, or a folder that cannot be resolved.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InputPathError {
    /// The path is not a relative path beneath the folder. The message is decided from the path's
    /// text and the links inside the folder only, never from whether a file outside exists.
    #[error(
        "{}: {key} = {} is refused: {reason}. Files named by a manifest, an exposures list or a \
         result are relative paths inside its folder {} (no absolute path, no `..`, no symbolic \
         link that leads outside). Move or copy the file into the folder, or pass \
         --allow-outside-paths if you trust this file",
        named_in.display(),
        crate::escape::token(&path.to_string_lossy()),
        root.display()
    )]
    Outside {
        /// The file that names the path (the manifest, the exposures CSV, the result).
        named_in: PathBuf,
        /// Where it is named, as shown: e.g. `` `spectro.file` ``, `` `inputs.profile` ``, `the frame
        /// on line 3 of exposures.csv`.
        key: String,
        /// The path as named.
        path: PathBuf,
        /// Why it is refused.
        reason: OutsideReason,
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

    /// The one resolver of every path a file names: `named` (as written in `named_in` under
    /// `key`) joined to `base` (the folder of the file that names it, itself inside the policy's
    /// folder). Refused unless `named` is relative, has no `..`, and no symbolic link on its way
    /// leads out of the folder — decided from the text and the links only, so the refusal is the
    /// same whether or not a file outside exists (no existence oracle). A missing file inside is
    /// left to its reader to report.
    ///
    /// # Errors
    /// [`InputPathError::Outside`].
    pub fn resolve(
        &self,
        named_in: &Path,
        key: &str,
        base: &Path,
        named: &Path,
    ) -> Result<PathBuf, InputPathError> {
        let joined = base.join(named);
        if self.allow_outside {
            return Ok(joined);
        }
        let refuse = |reason| InputPathError::Outside {
            named_in: named_in.to_path_buf(),
            key: key.to_string(),
            path: named.to_path_buf(),
            reason,
            root: self.root.clone(),
        };
        if named.is_absolute() || named.has_root() {
            return Err(refuse(OutsideReason::Absolute));
        }
        if named
            .components()
            .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
        {
            return Err(refuse(OutsideReason::GoesUp));
        }
        match self.check(named_in, key, &joined) {
            Err(InputPathError::Outside { reason, .. }) => Err(refuse(reason)),
            other => other.map(|()| joined),
        }
    }

    /// Checks `path` (already joined to its folder; given on the command line or built by
    /// scatterfit, so `..` and absolute spellings are allowed) for symbolic links that lead out of
    /// the folder, named in `named_in` under `key`.
    ///
    /// # Errors
    /// [`InputPathError::Outside`].
    pub fn check(&self, named_in: &Path, key: &str, path: &Path) -> Result<(), InputPathError> {
        if self.allow_outside {
            return Ok(());
        }
        if resolve(path, 0).is_some_and(|r| r.starts_with(&self.root)) {
            return Ok(());
        }
        let reason = if path.is_absolute() && !path.starts_with(&self.root) && !is_link_on_way(path)
        {
            OutsideReason::Absolute
        } else {
            OutsideReason::Link
        };
        Err(InputPathError::Outside {
            named_in: named_in.to_path_buf(),
            key: key.to_string(),
            path: path.to_path_buf(),
            reason,
            root: self.root.clone(),
        })
    }
}

/// True when some prefix of `path` is a symbolic link.
fn is_link_on_way(path: &Path) -> bool {
    path.ancestors()
        .any(|p| std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_symlink()))
}

/// Links followed before giving up (Linux's own limit).
const MAX_LINKS: u32 = 40;

/// Where `path` leads with every symbolic link followed, whether or not it exists: the longest
/// prefix that exists is resolved (a dangling link by reading it), the rest appended as named.
/// `None` when it cannot be followed (a loop of links, a link's target that goes up from a
/// folder that does not exist).
fn resolve(path: &Path, links: u32) -> Option<PathBuf> {
    if links > MAX_LINKS {
        return None;
    }
    if let Ok(p) = std::fs::canonicalize(path) {
        return Some(p);
    }
    let mut existing = path.to_path_buf();
    let mut rest: Vec<std::ffi::OsString> = Vec::new();
    loop {
        if existing.as_os_str().is_empty() {
            existing = PathBuf::from(".");
        }
        match std::fs::symlink_metadata(&existing) {
            Ok(meta) if meta.file_type().is_symlink() => {
                // A dangling link (or one leading into a folder that lacks the rest): follow it
                // by hand.
                let target = std::fs::read_link(&existing).ok()?;
                let base = existing.parent().unwrap_or(Path::new("."));
                let mut next = base.join(target);
                next.extend(rest.iter().rev());
                return resolve(&next, links + 1);
            }
            Ok(_) => {
                let mut p = std::fs::canonicalize(&existing).ok()?;
                p.extend(rest.iter().rev());
                return Some(p);
            }
            Err(_) => {
                // Only plain names are carried over; a missing folder followed by `..` is
                // refused (where it leads cannot be told).
                match existing.components().next_back()? {
                    Component::Normal(name) => rest.push(name.to_os_string()),
                    Component::CurDir => {}
                    _ => return None,
                }
                if !existing.pop() {
                    return None;
                }
            }
        }
    }
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
            "./frames/a.png",
            "missing.csv",
        ] {
            let r = p.resolve(&m, "k", &sample, Path::new(inside)).unwrap();
            assert_eq!(r, sample.join(inside));
        }
        let secret = top.path().join("secret");
        let inside_abs = sample.join("spectro.csv");
        for (outside, reason) in [
            ("../secret", OutsideReason::GoesUp),
            ("frames/../../secret", OutsideReason::GoesUp),
            ("frames/../spectro.csv", OutsideReason::GoesUp),
            ("/etc/passwd", OutsideReason::Absolute),
            (secret.to_str().unwrap(), OutsideReason::Absolute),
            (inside_abs.to_str().unwrap(), OutsideReason::Absolute),
        ] {
            let e = p
                .resolve(&m, "`spectro.file`", &sample, Path::new(outside))
                .unwrap_err();
            let text = e.to_string();
            assert!(
                text.contains("--allow-outside-paths") && text.contains("spectro.file"),
                "{text}"
            );
            assert!(matches!(e, InputPathError::Outside { reason: r, .. } if r == reason));
        }
        let allowed = InputPolicy::new(&sample, true).unwrap();
        let r = allowed
            .resolve(&m, "k", &sample, Path::new("../secret"))
            .unwrap();
        assert_eq!(r, sample.join("../secret"));
    }

    /// The refusal of a path outside is the same text whether or not the file (or its folder)
    /// exists: no existence oracle.
    #[cfg(unix)]
    #[test]
    fn a_refusal_does_not_tell_whether_a_file_exists() {
        use std::os::unix::fs::symlink;
        let top = tempfile::tempdir().unwrap();
        let sample = top.path().join("sample");
        fs::create_dir(&sample).unwrap();
        fs::create_dir(top.path().join("there")).unwrap();
        fs::write(top.path().join("there/secret"), b"x").unwrap();
        symlink(top.path(), sample.join("up")).unwrap();
        let m = sample.join("sample.toml");
        let p = InputPolicy::new(&sample, false).unwrap();
        let message = |named: &str| {
            p.resolve(&m, "`camera.flat`", &sample, Path::new(named))
                .unwrap_err()
                .to_string()
                .replace(named, "NAMED")
        };
        for (exists, missing) in [
            ("../there/secret", "../there/missing"),
            ("../there/secret", "../nowhere/missing"),
            ("up/there/secret", "up/there/missing"),
            ("up/there/secret", "up/nowhere/missing"),
        ] {
            assert_eq!(message(exists), message(missing), "{exists} / {missing}");
        }
        let abs = top.path().join("there/secret");
        let abs_missing = top.path().join("nowhere/missing");
        assert_eq!(
            message(abs.to_str().unwrap()),
            message(abs_missing.to_str().unwrap())
        );
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
            "dir-link/missing/deeper",
            "dangling.csv",
            "chain.csv",
        ] {
            let e = p.resolve(&m, "k", &sample, Path::new(bad)).unwrap_err();
            assert!(
                matches!(
                    e,
                    InputPathError::Outside {
                        reason: OutsideReason::Link,
                        ..
                    }
                ),
                "{bad}"
            );
        }
        p.resolve(&m, "k", &sample, Path::new("inner-link.csv"))
            .unwrap();
        // A sample folder that is itself a link: its files are inside its target.
        let alias = top.path().join("alias");
        symlink(&sample, &alias).unwrap();
        let p = InputPolicy::new(&alias, false).unwrap();
        p.check(&m, "k", &alias.join("real.csv")).unwrap();
    }
}
